# Several robots: every robot of the station welds a square seam in front of it, with the
# same synchronisation points, one program per robot (MakeProgram on each). An olp station
# holds one robot, so run the script on each robot's station:
#     olp build stations/robodk_kr6_cell.yaml examples/robodk/several_robots.py --post kuka
#     olp build stations/fanuc_m20ia_weld_cell.yaml examples/robodk/several_robots.py --post fanuc
#     olp build stations/ur5e_screw_cell.yaml examples/robodk/several_robots.py --post ur
from robodk.robolink import *
from robodk.robomath import *

RDK = Robolink()
robots = RDK.ItemList(ITEM_TYPE_ROBOT)
print('Robots: %s' % [r.Name() for r in robots])

SIDE = 100  # mm
for robot in robots:
    tool = robot.Childs()[0]
    base = robot.Parent()
    program = RDK.AddProgram('Weld_' + robot.Name().split()[0], robot)
    program.setPoseFrame(base)
    program.setPoseTool(tool)

    # The seam lies 100 mm below the tool at the robot's home position (robot base frame)
    robot.setPoseFrame(base)
    robot.setPoseTool(tool)
    robot.setJoints(robot.JointsHome())
    start = transl(0, 0, -100) * robot.Pose()
    corners = [transl(x, y, 0) * start for x, y in [(0, 0), (SIDE, 0), (SIDE, SIDE), (0, SIDE), (0, 0)]]

    program.setSpeed(250, 60)
    program.MoveJ(robot.JointsHome())
    program.RunInstruction('SyncPoint(1)', INSTRUCTION_CALL_PROGRAM)
    program.MoveJ(corners[0])
    program.setSpeed(25)
    program.RunInstruction('ArcStart(1)', INSTRUCTION_CALL_PROGRAM)
    for corner in corners[1:]:
        program.MoveL(corner)
    program.RunInstruction('ArcEnd', INSTRUCTION_CALL_PROGRAM)
    program.setSpeed(250)
    program.RunInstruction('SyncPoint(2)', INSTRUCTION_CALL_PROGRAM)
    program.MoveJ(robot.JointsHome())
    program.MakeProgram()
