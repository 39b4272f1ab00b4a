"""USERS.md job 11: pick and place with a multi-cup gripper.

Parts stand on table A in a box pallet (ROWS x COLS x LAYERS, picked top layer first) and are
stacked on table B as a pyramid. The gripper has CUPS suction cups, each its own TCP: the robot
picks one part per cup (``TCP_On(i)``), then places them one by one (``TCP_Off(i)``).

    olp build stations/kr6_milling_cell.yaml examples/pick_and_place.py --set CUPS=3

Parameters: CUPS, ROWS, COLS, LAYERS, PART (edge length of the cubic parts, mm), SPEED (mm/s).
"""

from olp.dsl import AddFrame, Offset, Pose, param, robot

CUPS = param("CUPS", 2)
ROWS, COLS, LAYERS = param("ROWS", 2), param("COLS", 3), param("LAYERS", 1)
PART = param("PART", 50.0)
SPEED = param("SPEED", 500.0)
CLEARANCE = 100.0  # mm above a part for the approach

# One TCP per cup, 60 mm apart. KUKA's flange X axis points out of the flange, so each cup's Z
# axis (its suction direction) is the flange's X axis: a 90 degree turn about Y.
cups = [
    robot.AddTool(Pose(180, (i - (CUPS - 1) / 2) * 60, 0, 0, 90, 0), f"cup{i + 1}")
    for i in range(CUPS)
]
table_a = AddFrame("table_a", Pose(350, -800, 0, 0, 0, 0))
table_b = AddFrame("table_b", Pose(350, -100, 0, 0, 0, 90))


def box_pallet():
    """Part centres (x, y, top z) on table A, top layer first."""
    return [
        (col * PART * 1.5, row * PART * 1.5, (layer + 1) * PART)
        for layer in reversed(range(LAYERS))
        for row in range(ROWS)
        for col in range(COLS)
    ]


def pyramid(count):
    """Part centres on table B: rows of a pyramid, each row one part shorter and half a part in."""
    spots, layer, width = [], 0, 1
    while width * (width + 1) // 2 < count:
        width += 1
    while len(spots) < count:
        for k in range(width - layer):
            x = (k + layer / 2) * PART * 1.02
            spots.append((x, 0.0, (layer + 1) * PART))
        layer += 1
    return spots[:count]


def down(spot):
    """The part-top target at ``spot`` (x, y, z in mm) with the cup pointing down."""
    x, y, z = spot
    return Pose(x, y, z, 180, 0, 180)


def visit(frame, spot, cup, call):
    """Approach above ``spot``, go down, call ``call(cup)`` and come back up."""
    robot.setPoseFrame(frame)
    robot.setPoseTool(cups[cup])
    target = down(spot)
    above = Offset(target, 0, 0, CLEARANCE)
    robot.MoveJ(above)
    robot.setSpeed(SPEED / 5)
    robot.MoveL(target)
    robot.RunInstruction(f"{call}({cup + 1})")
    robot.Pause(200)  # let the vacuum build up or break down
    robot.MoveL(above)
    robot.setSpeed(SPEED)


picks = box_pallet()
places = pyramid(len(picks))
robot.setSpeed(SPEED, 120)
robot.MoveJ("home")
for first in range(0, len(picks), CUPS):
    batch = range(first, min(first + CUPS, len(picks)))
    for cup, part in enumerate(batch):
        visit(table_a, picks[part], cup, "TCP_On")
    for cup, part in enumerate(batch):
        visit(table_b, places[part], cup, "TCP_Off")
robot.MoveJ("home")
