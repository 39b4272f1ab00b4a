# Pick and place with a multi-cup gripper: one TCP per suction cup (AddTool), parts picked
# from a box pallet on Pallet A, top layer first, and stacked as a pyramid on Pallet B.
# TCP_On(i) / TCP_Off(i) switch cup i.
from robodk.robolink import *
from robodk.robomath import *

RDK = Robolink()
robot = RDK.Item('', ITEM_TYPE_ROBOT)
pallet_a = RDK.Item('Pallet A', ITEM_TYPE_FRAME)
pallet_b = RDK.Item('Pallet B', ITEM_TYPE_FRAME)
home = RDK.Item('Home')

CUPS = 2
PART = 40  # mm, cubic parts
ROWS, COLS, LAYERS = 2, 2, 2
CLEARANCE = 80  # mm above a part

# The gripper's cups sit 50 mm apart along the tool's Y axis
gripper = RDK.Item('Gripper', ITEM_TYPE_TOOL).PoseTool()
cups = [robot.AddTool(gripper * transl(0, (i - (CUPS - 1) / 2) * 50, 0), 'Cup %i' % (i + 1))
        for i in range(CUPS)]

RDK.setRunMode(RUNMODE_MAKE_ROBOTPROG)
RDK.ProgramStart('PickAndPlace')


def box_pallet():
    """Part tops on Pallet A (x, y, z), top layer first."""
    return [(col * PART * 1.5, row * PART * 1.5, (layer + 1) * PART)
            for layer in reversed(range(LAYERS)) for row in range(ROWS) for col in range(COLS)]


def pyramid(count):
    """Part tops on Pallet B: rows of a pyramid, each one part shorter and half a part in."""
    spots, layer, width = [], 0, 1
    while width * (width + 1) // 2 < count:
        width += 1
    while len(spots) < count:
        for k in range(width - layer):
            spots.append(((k + layer / 2) * PART * 1.05, 0, (layer + 1) * PART))
        layer += 1
    return spots[:count]


def visit(frame, spot, cup, call):
    """Approach above the spot, go down, switch the cup and come back up."""
    robot.setPoseFrame(frame)
    robot.setPoseTool(cups[cup])
    target = transl(spot[0], spot[1], spot[2]) * rotx(pi)
    above = transl(0, 0, CLEARANCE) * target
    robot.MoveJ(above)
    robot.setSpeed(50)
    robot.MoveL(target)
    robot.RunInstruction('%s(%i)' % (call, cup + 1), INSTRUCTION_CALL_PROGRAM)
    robot.Pause(200)  # ms: let the vacuum build up or break down
    robot.MoveL(above)
    robot.setSpeed(250)


picks = box_pallet()
places = pyramid(len(picks))
robot.setSpeed(250, 120)
robot.MoveJ(home)
for first in range(0, len(picks), CUPS):
    batch = range(first, min(first + CUPS, len(picks)))
    for cup, part in enumerate(batch):
        visit(pallet_a, picks[part], cup, 'TCP_On')
    for cup, part in enumerate(batch):
        visit(pallet_b, places[part], cup, 'TCP_Off')
robot.MoveJ(home)
