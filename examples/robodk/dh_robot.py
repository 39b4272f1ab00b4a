# A robot from DH parameters: the station defines the arm by its DH table; this script looks at
# its per-joint frames (forward kinematics), then moves through joint targets and a small
# Cartesian square solved by the arm's own inverse kinematics.
from robodk.robolink import *
from robodk.robomath import *

RDK = Robolink()
robot = RDK.Item('', ITEM_TYPE_ROBOT)
print('Robot %s, %i axes' % (robot.Name(), len(robot.JointsHome().list())))

joints = RDK.Item('Ready').Joints()
for i, pose in enumerate(robot.JointPoses(joints)):
    print('Frame %i: %s' % (i, [round(v, 1) for v in pose.Pos()]))
flange = robot.SolveFK(joints)
print('Flange at Ready: %s' % [round(v, 1) for v in Pose_2_TxyzRxyz(flange)[:3]])

robot.setPoseTool(RDK.Item('Probe', ITEM_TYPE_TOOL))
robot.setPoseFrame(robot.Parent())
RDK.ProgramStart('DHArm')
robot.setSpeed(100, 60)
robot.MoveJ(RDK.Item('Home'))
robot.MoveJ(RDK.Item('Ready'))
corner = robot.Pose()
for x, y in [(50, 0), (50, 50), (0, 50), (0, 0)]:
    pose = transl(x, y, 0) * corner
    joints = robot.SolveIK(pose, robot.Joints(), robot.PoseTool(), robot.PoseFrame())
    if len(joints.list()) < 6:
        raise TargetReachError('corner %s is out of reach' % [x, y])
    robot.MoveL(pose)
robot.MoveJ(RDK.Item('Home'))
