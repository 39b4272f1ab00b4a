# CSV to program (XYZWPR): x, y, z in mm, rotations W, P, R in degrees (Euler Z->Y'->X'', as
# xyzrpw_2_pose reads them), the 7th column an index. The robot simulates every move; a target
# it cannot reach raises TargetReachError and is skipped and reported by its index.
import os

from robodk.robolink import *
from robodk.robomath import *
from robodk.robofileio import *

RDK = Robolink()

CSV_FILE = os.path.join(os.path.dirname(__file__), 'targets_xyzwpr.csv')
SKIP_UNREACHABLE = True

robot = RDK.Item('', ITEM_TYPE_ROBOT)
robot.setPoseFrame(RDK.Item('Table', ITEM_TYPE_FRAME))
robot.setPoseTool(RDK.Item('Torch', ITEM_TYPE_TOOL))
RDK.ProgramStart('ImportXYZWPR')
robot.setSpeed(200)

robot.MoveJ(RDK.Item('Home'))
skipped = []
for row in LoadList(CSV_FILE):
    x, y, z, w, p, r = row[0:6]
    index = int(row[6])
    pose = xyzrpw_2_pose([x, y, z, w, p, r])
    try:
        robot.MoveJ(pose)
    except TargetReachError:
        if not SKIP_UNREACHABLE:
            raise
        skipped.append(index)
        print('Target %i skipped: not reachable' % index)

robot.MoveJ(RDK.Item('Home'))
print('Skipped targets: %s' % skipped)
