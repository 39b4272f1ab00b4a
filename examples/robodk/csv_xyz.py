# CSV to program (XYZ): one point per row in mm, an optional 4th column is the speed in mm/s.
# The orientation comes from a reference target; the first move is a joint move, the rest are
# linear, and a speed instruction is added only where the speed changes.
import os

from robodk.robolink import *
from robodk.robomath import *
from robodk.robofileio import *

RDK = Robolink()

CSV_FILE = os.path.join(os.path.dirname(__file__), 'points_xyz.csv')

robot = RDK.Item('', ITEM_TYPE_ROBOT)
reference = RDK.Item('Target 1', ITEM_TYPE_TARGET)
frame = RDK.Item('Table', ITEM_TYPE_FRAME)

robot.setPoseFrame(frame)
robot.setPoseTool(RDK.Item('Pen', ITEM_TYPE_TOOL))
RDK.setRunMode(RUNMODE_MAKE_ROBOTPROG)
RDK.ProgramStart(getFileName(CSV_FILE))

orientation = reference.Pose()
data = LoadList(CSV_FILE)
print('Loaded %i points from %s' % (len(data), getBaseName(CSV_FILE)))

robot.MoveJ(RDK.Item('Home'))
speed_last = None
for i, row in enumerate(data):
    x, y, z = row[0], row[1], row[2]
    if len(row) > 3 and row[3] != speed_last:
        speed_last = row[3]
        robot.setSpeed(speed_last)
    pose = orientation.copy()
    pose.setPos([x, y, z])
    if i == 0:
        robot.MoveJ(pose)
    else:
        robot.MoveL(pose)
robot.MoveJ(RDK.Item('Home'))
