# Points to program: a line of points between two targets becomes a program.
# Each point gets its own target; a linear move is tested first (MoveL_Test) and the
# point becomes a joint move where a linear move is impossible.
from robodk.robolink import *
from robodk.robomath import *

RDK = Robolink()
RDK.Render(False)  # faster: no rendering while the program is made

robot = RDK.ItemUserPick('Select a robot', ITEM_TYPE_ROBOT)
start = RDK.Item('Line Start', ITEM_TYPE_TARGET)
end = RDK.Item('Line End', ITEM_TYPE_TARGET)
frame = start.Parent()
tool = RDK.Item('Torch', ITEM_TYPE_TOOL)

N_POINTS = 12
p0 = start.Pose().Pos()
p1 = end.Pose().Pos()
orientation = start.Pose()  # every point keeps the orientation of the first one

program = RDK.AddProgram('PointsToProgram', robot)
program.setPoseFrame(frame)
program.setPoseTool(tool)
program.setSpeed(150)
robot.setPoseFrame(frame)
robot.setPoseTool(tool)

program.MoveJ(RDK.Item('Home'))
robot.setJoints(RDK.Item('Home').Joints())
last_joints = robot.Joints()
for i in range(N_POINTS):
    t = i / (N_POINTS - 1)
    xyz = [p0[k] + t * (p1[k] - p0[k]) for k in range(3)]
    pose = orientation.copy()
    pose.setPos(xyz)
    target = RDK.AddTarget('P%i' % (i + 1), frame, robot)
    target.setPose(pose)
    if i > 0 and robot.MoveL_Test(last_joints, pose) == 0:
        program.MoveL(target)
    else:
        program.MoveJ(target)
        robot.setJoints(target.Joints())
    last_joints = robot.Joints()

program.MoveJ(RDK.Item('Home'))
RDK.Render(True)
print('Program %s: %i instructions' % (program.Name(), program.InstructionCount()))
