# Offline programming: weld a hexagon around a reference target.
# The robot goes home, approaches 'Target 1', traces a polygon around it with 10 mm
# rounding while the torch is on, and comes back home. Run it on olp with:
#     olp build stations/robodk_kr6_cell.yaml examples/robodk/offline_programming.py --post kuka
from robodk.robolink import *  # RoboDK API
from robodk.robomath import *  # robot toolbox

RDK = Robolink()

# Get the robot, the torch and the reference target by name
robot = RDK.Item('', ITEM_TYPE_ROBOT)
torch = RDK.Item('Torch', ITEM_TYPE_TOOL)
home = RDK.Item('Home', ITEM_TYPE_TARGET)
target = RDK.Item('Target 1', ITEM_TYPE_TARGET)
if not robot.Valid() or not target.Valid():
    raise Exception('The station needs a robot and a target called Target 1')

# The polygon lies in the frame of the reference target
robot.setPoseFrame(target.Parent())
robot.setPoseTool(torch)
RDK.setRunMode(RUNMODE_MAKE_ROBOTPROG)
RDK.ProgramStart('WeldHexagon')

pose_ref = target.Pose()
n_sides = 6
radius = 80  # mm

robot.setSpeed(300, 90)  # mm/s, deg/s
robot.setRounding(-1)
robot.MoveJ(home)
robot.MoveJ(pose_ref * transl(0, 0, -100))  # 100 mm back along the torch
robot.MoveL(pose_ref * transl(radius, 0, 0))
robot.RunInstruction('ArcStart(1)', INSTRUCTION_CALL_PROGRAM)
robot.setSpeed(20)
robot.setRounding(10)
for i in range(1, n_sides + 1):
    angle = i * 2 * pi / n_sides
    pose_i = pose_ref * rotz(angle) * transl(radius, 0, 0) * rotz(-angle)
    if i == n_sides:
        robot.setRounding(-1)  # stop exactly where the seam closes
    robot.MoveL(pose_i)
robot.RunInstruction('ArcEnd', INSTRUCTION_CALL_PROGRAM)
robot.setSpeed(300)
robot.MoveL(pose_ref * transl(0, 0, -100))
robot.MoveJ(home)
print('Hexagon done')
