# Drawing: paths (polylines and circles in mm, as an SVG file would give them) drawn with a pen
# on the table: an approach and a retract per path and a colour call per path. Circles are two
# MoveC half circles.
from robodk.robolink import *
from robodk.robomath import *

RDK = Robolink()
robot = RDK.Item('', ITEM_TYPE_ROBOT)
origin = RDK.Item('Drawing Origin', ITEM_TYPE_TARGET)
pen = RDK.Item('Pen', ITEM_TYPE_TOOL)

APPROACH = 30  # mm above the paper
SIZE = 60  # mm, height of the letters

# The letters O, L and P in a unit box (x right, y up): O a circle, L and P polylines
O = 'circle'
L = [(0, 1), (0, 0), (0.7, 0)]
P = [(0, 0), (0, 1), (0.6, 1), (0.8, 0.85), (0.8, 0.65), (0.6, 0.5), (0, 0.5)]
PATHS = [(O, 1), (L, 2), (P, 3)]  # path, colour

RDK.ProgramStart('DrawOLP')
robot.setPoseFrame(origin.Parent())
robot.setPoseTool(pen)
robot.setSpeed(100)
robot.setRounding(1)
robot.MoveJ(RDK.Item('Home'))

paper = origin.Pose()
for letter, (path, colour) in enumerate(PATHS):
    shift = letter * SIZE * 1.2

    def at(x, y):
        return paper * transl(shift + x * SIZE, y * SIZE, 0)

    robot.RunInstruction('SetColour(%i)' % colour, INSTRUCTION_CALL_PROGRAM)
    if path == 'circle':
        robot.MoveJ(at(1, 0.5) * transl(0, 0, -APPROACH))
        robot.MoveL(at(1, 0.5))
        robot.setRounding(-1)  # an exact stop between the halves: URScript blends no movec pair
        robot.MoveC(at(0.5, 1), at(0, 0.5))
        robot.MoveC(at(0.5, 0), at(1, 0.5))
        robot.setRounding(1)
        robot.MoveL(at(1, 0.5) * transl(0, 0, -APPROACH))
        continue
    robot.MoveJ(at(*path[0]) * transl(0, 0, -APPROACH))
    for x, y in path:
        robot.MoveL(at(x, y))
    robot.MoveL(at(*path[-1]) * transl(0, 0, -APPROACH))
robot.MoveJ(RDK.Item('Home'))
