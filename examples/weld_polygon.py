"""USERS.md job 1: weld a polygon around a reference target.

A port of RoboDK's classic "weld a hexagon" macro: move home, approach the reference target,
trace an n-sided polygon at weld speed with 10 mm rounding, switch the torch on and off through
program calls, retract, go home.

    olp build stations/kr6_milling_cell.yaml examples/weld_polygon.py --set SIDES=8 --set SPEED=30

Parameters: NAME (program name), SPEED (weld speed, mm/s), SIDES, RADIUS (mm), DRY_RUN (true:
no torch calls). olp predefines the names of olp.dsl in a program; importing them is optional and
helps editors and linters.
"""

from olp.dsl import AddTarget, Pose, param, pi, robot, rotz, transl

NAME = param("NAME", "WeldPolygon")
SPEED = param("SPEED", 20.0)
SIDES = param("SIDES", 6)
RADIUS = param("RADIUS", 100.0)
DRY_RUN = param("DRY_RUN", False)

robot.ProgramStart(NAME)
# The torch tip sits 250 mm out of the flange, pointing along it (KUKA's flange X axis points out
# of the flange, so the tool's Z axis is the flange's X axis: a 90 degree turn about Y).
robot.AddTool(Pose(250, 0, 0, 0, 90, 0), "torch")
robot.setPoseFrame("table")

# The reference target: the polygon's centre on the table, torch pointing down.
reference = AddTarget("reference", Pose(150, 160, 20, 180, 0, 180))
approach = reference.Pose() * transl(0, 0, -100)  # 100 mm back along the torch axis


def corner(i):
    """The i-th corner of the polygon, keeping the torch orientation of the reference."""
    angle = i * 2 * pi / SIDES
    return reference.Pose() * rotz(angle) * transl(RADIUS, 0, 0) * rotz(-angle)


robot.setSpeed(250, 90)  # mm/s for linear moves, deg/s for joint moves
robot.setRounding(-1)  # exact stops until the torch burns
robot.MoveJ("home")
robot.MoveJ(approach)
robot.MoveL(corner(0))
if not DRY_RUN:
    robot.RunInstruction("SprayOn")
robot.setSpeed(SPEED)
robot.setRounding(10)
for i in range(1, SIDES):
    robot.MoveL(corner(i))
robot.setRounding(-1)  # stop exactly where the seam closes, before the torch goes off
robot.MoveL(corner(SIDES))
if not DRY_RUN:
    robot.RunInstruction("SprayOff")
robot.setSpeed(250)
robot.MoveL(approach)
robot.MoveJ("home")
