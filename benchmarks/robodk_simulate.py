"""What RoboDK's simulate mode costs on olp: a script of N robot moves run three ways.

Each ``robot.MoveL`` of a RoboDK script in ``RUNMODE_SIMULATE`` runs olp's resolve pass from
the simulated joints before it is recorded (:mod:`olp.compat.robodk.robolink`), and with
``setCollisionActive(COLLISION_ON)`` the collision check too; ``RUNMODE_MAKE_ROBOTPROG`` only
records. The moves: a zig-zag of N linear moves 2 mm apart over the table of
``stations/robodk_kr6_cell.yaml``, the script run in this process. Prints, as
``name: value unit``: ``record_ms_per_move``, ``simulate_ms_per_move`` and
``simulate_collisions_ms_per_move``.

    python -m benchmarks.robodk_simulate [N]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from olp.frontends.dsl import run_dsl
from olp.station.loader import load_station

REPO = Path(__file__).resolve().parents[1]
STATION = REPO / "stations" / "robodk_kr6_cell.yaml"

SCRIPT = """
from robolink import *
from robodk import *
RDK = Robolink()
RDK.setRunMode({mode})
RDK.setCollisionActive({collisions})
robot = RDK.Item('', ITEM_TYPE_ROBOT)
robot.setPoseFrame(RDK.Item('Table'))
robot.setPoseTool(RDK.Item('Torch'))
start = RDK.Item('Target 1').Pose()
robot.MoveJ(start)
for i in range({n}):
    robot.MoveL(transl(2 * (i % 50), 2 * (i // 50), 0) * start)
"""


def per_move_ms(n: int, mode: str, collisions: str) -> float:
    station = load_station(STATION)
    text = SCRIPT.format(mode=mode, collisions=collisions, n=n)
    begin = time.perf_counter()
    result = run_dsl(text, "bench.py", station)
    elapsed = time.perf_counter() - begin
    assert len(result.program.instructions) == n + 1, "every move was recorded"
    return 1000.0 * elapsed / n


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("n", nargs="?", type=int, default=500)
    args = parser.parse_args()
    per_move_ms(10, "RUNMODE_SIMULATE", "COLLISION_OFF")  # imports and first calls
    record = per_move_ms(args.n, "RUNMODE_MAKE_ROBOTPROG", "COLLISION_OFF")
    simulate = per_move_ms(args.n, "RUNMODE_SIMULATE", "COLLISION_OFF")
    collide = per_move_ms(args.n, "RUNMODE_SIMULATE", "COLLISION_ON")
    print(f"moves: {args.n}")
    print(f"record_ms_per_move: {record:.3f} ms")
    print(f"simulate_ms_per_move: {simulate:.3f} ms")
    print(f"simulate_collisions_ms_per_move: {collide:.3f} ms")


if __name__ == "__main__":
    main()
