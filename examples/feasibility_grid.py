"""USERS.md job 6: test move feasibility on a grid of targets around a reference.

For each target of a ROWS x COLS grid (STEP mm apart, centred on the reference, tool pointing
down): is it reachable at all; can a linear move reach it from the last target (no
configuration change, no singularity, no joint limit); else can a joint move; else skip it and
say why (a warning at this file's line). Collisions are not checked yet.

    olp build stations/kr6_milling_cell.yaml examples/feasibility_grid.py --set STEP=150

The questions go to olp's own resolve pass, so every move the program keeps is one that
``olp build`` accepts.
"""

from olp.dsl import INSTRUCTION_COMMENT, Offset, Pose, param, robot, warn

ROWS = param("ROWS", 5)
COLS = param("COLS", 5)
STEP = param("STEP", 200.0)

robot.setPoseFrame("table")
reference = Pose(150, 160, 50, 180, 0, 180)

robot.setSpeed(200, 90)
robot.MoveJ("home")
moved = {"linear": 0, "joint": 0, "skipped": 0}
for row in range(ROWS):
    for col in range(COLS):
        dx = (col - (COLS - 1) / 2) * STEP
        dy = (row - (ROWS - 1) / 2) * STEP
        target = Offset(reference, dx, dy, 0)
        name = f"target ({row}, {col}) at {dx:+.0f}, {dy:+.0f} mm"
        reach = robot.canReach(target)
        linear = robot.canMoveL(target) if reach else reach
        if linear:
            robot.MoveL(target)
            moved["linear"] += 1
        elif reach and robot.canMoveJ(target):
            robot.MoveJ(target)
            moved["joint"] += 1
        else:
            why = reach.reason if not reach else robot.canMoveJ(target).reason
            warn(f"{name} skipped: {why}")
            moved["skipped"] += 1

robot.RunInstruction(
    f"{moved['linear']} linear, {moved['joint']} joint, {moved['skipped']} skipped",
    INSTRUCTION_COMMENT,
)
robot.MoveJ("home")
