"""A CSV toolpath of a million points up to the resolve pass: the dense toolpath node
(``ir.LinearPath``) against the per-move IR (one ``LinearMove`` per row, as olp built it before).

Each variant runs in a fresh interpreter so that its memory is its own: the peak resident memory
(Linux's VmHWM) above what the interpreter and olp's imports already hold, and the wall time
from reading the file to the compiled program the resolve pass starts from
(``CompiledProgram.start``).

    python benchmarks/dense_toolpath.py [POINTS]

Last lines: ``name: value unit``.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"

CHILD = r"""
import json, sys, time
import numpy as np
import olp
from olp import ir
from olp.compiled import CompiledProgram
from olp.frontends.bundled import CsvOptions

def rss_mb():
    # the high-water mark of this process's memory (ru_maxrss would carry the parent's over exec)
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024

station = olp.load_station(sys.argv[1])
options = CsvOptions(frame="table", orientation=(180.0, 0.0, 180.0))
olp.parse(sys.argv[3], station=station, options=options)  # warm the imports on a tiny file
base = rss_mb()
start = time.perf_counter()
program = olp.parse(sys.argv[2], station=station, options=options).program
if sys.argv[4] == "per-move":
    # what the CSV frontend built before the dense node: one validated LinearMove per row
    rows = [m for node in program.instructions[1:] for m in node]
    moves = [
        ir.LinearMove(
            target=ir.CartesianTarget(pose=np.array(m.target.pose)),
            speed=ir.Speed(linear=m.speed.linear),
            zone=ir.Zone(m.zone.radius),
            tool=m.tool,
            frame=m.frame,
            span=m.span,
        )
        for m in rows
    ]
    program = program.replace_instructions([program.instructions[0], *moves])
    del rows, moves
compiled = CompiledProgram.start(program, station)
seconds = time.perf_counter() - start
found = {"seconds": seconds, "mb": rss_mb() - base, "base": base, "count": len(compiled.steps)}
print(json.dumps(found))
"""


def _helix(points: int) -> str:
    t = np.linspace(0.0, 1.0, points)
    xyz = np.column_stack(
        [100 + 80 * np.cos(40 * np.pi * t), 150 + 80 * np.sin(40 * np.pi * t), 20 + 30 * t]
    )
    lines = [f"{x:.3f},{y:.3f},{z:.3f}" for x, y, z in xyz]
    return "x,y,z\n" + "\n".join(lines) + "\n"


def _run(variant: str, big: Path, small: Path) -> dict[str, float]:
    out = subprocess.run(
        [sys.executable, "-c", CHILD, str(CELL), str(big), str(small), variant],
        capture_output=True,
        text=True,
        check=True,
    )
    result: dict[str, float] = json.loads(out.stdout.strip().splitlines()[-1])
    return result


def main() -> None:
    points = int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000
    with tempfile.TemporaryDirectory() as folder:
        big, small = Path(folder) / "helix.csv", Path(folder) / "small.csv"
        big.write_text(_helix(points))
        small.write_text(_helix(10))
        dense = _run("dense", big, small)
        per_move = _run("per-move", big, small)
    assert dense["count"] == per_move["count"] == points
    print(f"points: {points}")
    print(f"dense to resolve: {dense['seconds']:.2f} s")
    print(f"dense memory: {dense['mb']:.0f} MB (base {dense['base']:.0f} MB)")
    print(f"per-move to resolve: {per_move['seconds']:.2f} s")
    print(f"per-move memory: {per_move['mb']:.0f} MB")
    print(f"time ratio per-move/dense: {per_move['seconds'] / dense['seconds']:.1f} x")
    print(f"memory ratio per-move/dense: {per_move['mb'] / max(dense['mb'], 1.0):.1f} x")


if __name__ == "__main__":
    main()
