"""USERS.md job 2: a program from a line of N points, keeping the tool orientation.

Each point is first tested as a linear move from where the robot is (``MoveL_Test``, RoboDK's
name and codes: 0 feasible, -1 reachable but not on a straight line, -2 unreachable). Where a
linear move is impossible the point becomes a joint move; a point no move reaches is skipped
with a warning. The default line passes over the robot's base, where axis 1 would have to spin
(a shoulder singularity), so two of its points become joint moves.

    olp build stations/kr6_milling_cell.yaml examples/points_to_program.py --set N=21

Parameters: the line's ends START_X/Y/Z and END_X/Y/Z (mm, world frame), N (points).
"""

from olp.dsl import Pose, param, robot, warn

START = [param("START_X", 400.0), param("START_Y", -400.0), param("START_Z", 300.0)]
END = [param("END_X", -400.0), param("END_Y", -400.0), param("END_Z", 300.0)]
N = param("N", 11)

if N < 2:
    raise ValueError("N must be at least 2")

# The spindle points straight down all along the line.
orientation = Pose(0, 0, 0, 180, 0, 180)

robot.setSpeed(100, 90)
robot.MoveJ("home")
for i in range(N):
    t = i / (N - 1)
    target = orientation.copy().setPos([a + (b - a) * t for a, b in zip(START, END, strict=True)])
    code = robot.MoveL_Test(robot.Joints(), target)
    if code == 0 and i > 0:
        robot.MoveL(target)
    elif robot.canMoveJ(target):
        robot.MoveJ(target)
    else:
        warn(f"point {i} skipped: no move reaches it (MoveL_Test gave {code})")
