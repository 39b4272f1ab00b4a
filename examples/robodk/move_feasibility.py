# Move feasibility: a grid of targets around a reference. For each target: can it be reached;
# can a linear move get there from the last one (MoveL_Test: no configuration change, no
# singularity, no joint limit, no collision when collision checking is on); else can a joint
# move (MoveJ_Test); else skip it and say why.
from robodk.robolink import *
from robodk.robomath import *

RDK = Robolink()
RDK.setCollisionActive(COLLISION_ON)

robot = RDK.Item('', ITEM_TYPE_ROBOT)
reference = RDK.Item('Target 1', ITEM_TYPE_TARGET)
tool = RDK.Item('Torch', ITEM_TYPE_TOOL)
robot.setPoseFrame(reference.Parent())
robot.setPoseTool(tool)

program = RDK.AddProgram('FeasibilityGrid', robot)
program.setPoseFrame(reference.Parent())
program.setPoseTool(tool)
program.setSpeed(200, 90)

GRID = 4
STEP = 150  # mm
pose_ref = reference.Pose()
home = RDK.Item('Home')
program.MoveJ(home)
robot.setJoints(home.Joints())
joints_last = robot.Joints()

count = {'linear': 0, 'joint': 0, 'skipped': 0}
for row in range(GRID):
    for col in range(GRID):
        dx = (col - (GRID - 1) / 2) * STEP
        dy = (row - (GRID - 1) / 2) * STEP
        pose = transl(dx, dy, 0) * pose_ref
        name = 'Grid %i-%i' % (row, col)
        joints = robot.SolveIK(pose, joints_last, robot.PoseTool(), robot.PoseFrame())
        if len(joints.list()) < 6:
            print('%s: not reachable, skipped' % name)
            count['skipped'] += 1
            continue
        target = RDK.AddTarget(name, reference.Parent(), robot)
        target.setPose(pose)
        if robot.MoveL_Test(joints_last, pose) == 0:
            program.MoveL(target)
            count['linear'] += 1
        elif robot.MoveJ_Test(joints_last, joints) == 0:
            target.setAsJointTarget()
            target.setJoints(joints)
            program.MoveJ(target)
            count['joint'] += 1
        else:
            print('%s: no linear or joint move gets there, skipped' % name)
            count['skipped'] += 1
            continue
        joints_last = robot.Joints()

program.RunInstruction('%(linear)i linear, %(joint)i joint, %(skipped)i skipped' % count,
                       INSTRUCTION_COMMENT)
program.MoveJ(home)
print(count)
