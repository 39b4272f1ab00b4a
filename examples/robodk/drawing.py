# Drawing: paths (polylines in mm, as an SVG file would give them) drawn with a pen on the
# table: an approach and a retract per path and a colour call per path.
from robodk.robolink import *
from robodk.robomath import *

RDK = Robolink()
robot = RDK.Item('', ITEM_TYPE_ROBOT)
origin = RDK.Item('Drawing Origin', ITEM_TYPE_TARGET)
pen = RDK.Item('Pen', ITEM_TYPE_TOOL)

APPROACH = 30  # mm above the paper
SIZE = 60  # mm, height of the letters

# The letters O, L and P as polylines in a unit box (x right, y up)
O = [(0.5 + 0.5 * cos(a * pi / 8), 0.5 + 0.5 * sin(a * pi / 8)) for a in range(17)]
L = [(0, 1), (0, 0), (0.7, 0)]
P = [(0, 0), (0, 1), (0.6, 1), (0.8, 0.85), (0.8, 0.65), (0.6, 0.5), (0, 0.5)]
PATHS = [(O, 1), (L, 2), (P, 3)]  # polyline, colour

RDK.ProgramStart('DrawOLP')
robot.setPoseFrame(origin.Parent())
robot.setPoseTool(pen)
robot.setSpeed(100)
robot.setRounding(1)
robot.MoveJ(RDK.Item('Home'))

paper = origin.Pose()
for letter, (path, colour) in enumerate(PATHS):
    shift = letter * SIZE * 1.2
    points = [paper * transl(shift + x * SIZE, y * SIZE, 0) for x, y in path]
    robot.RunInstruction('SetColour(%i)' % colour, INSTRUCTION_CALL_PROGRAM)
    robot.MoveJ(points[0] * transl(0, 0, -APPROACH))
    for point in points:
        robot.MoveL(point)
    robot.MoveL(points[-1] * transl(0, 0, -APPROACH))
robot.MoveJ(RDK.Item('Home'))
