# Cycle time: make a program, ask Update() for its estimated cycle time, and build a table of
# cycle times over a sweep of linear speeds x joint speeds. The program is then kept at the
# speeds of the last row (MakeProgram).
from robodk.robolink import *
from robodk.robomath import *

RDK = Robolink()
robot = RDK.Item('', ITEM_TYPE_ROBOT)
frame = RDK.Item('Table', ITEM_TYPE_FRAME)
tool = RDK.Item('Torch', ITEM_TYPE_TOOL)
start = RDK.Item('Line Start')
end = RDK.Item('Line End')
approach = RDK.Item('Approach')

program = RDK.AddProgram('CycleTime', robot)


def make_program(speed_linear, speed_joints):
    """Fill the program: joint moves between the approach and a square of linear moves."""
    while program.InstructionCount() > 0:
        program.InstructionDelete(0)
    program.setPoseFrame(frame)
    program.setPoseTool(tool)
    program.setSpeed(speed_linear, speed_joints)
    program.setRounding(5)
    program.MoveJ(approach)
    program.MoveL(start)
    program.MoveL(end)
    program.MoveJ(approach)


print('Linear speed (mm/s) | Joint speed (deg/s) | Cycle time (s)')
for speed_linear in [100, 250, 500]:
    for speed_joints in [30, 90]:
        make_program(speed_linear, speed_joints)
        valid, cycle_time, distance, ratio, message = program.Update()
        print('%19.0f | %19.0f | %14.2f   (%s, %.0f mm)'
              % (speed_linear, speed_joints, cycle_time, message, distance))

program.MakeProgram()
