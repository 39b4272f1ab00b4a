"""What running a Python program in a child process costs: a small DSL build, same run.

Run from the repository root: ``python -m benchmarks.dsl_child [--repeats R]``.

``olp build`` runs a ``.py`` program in a fresh interpreter with a time limit
(:mod:`olp.frontends.dsl_process`). This times, on ``examples/weld_polygon.py`` and the
KR 6 milling cell, best of R runs each:

* reference, in process: :func:`olp.frontends.dsl.run_dsl` on the file's bytes, which is what
  ``olp build`` did before the child process;
* child: :func:`olp.frontends.dsl.load_dsl` (start the interpreter, import olp's DSL, unpickle
  the station, run, pickle the program back);
* both as a whole build (:func:`olp.build`: parse, resolve, collisions, timing, KRL text, no
  files written), the number a user feels.

The last lines give the child's fixed cost (child minus reference) and the ratios.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from olp.api import build, load_station
from olp.frontends.dsl import load_dsl, run_dsl

ROOT = Path(__file__).resolve().parents[1]
PROGRAM = ROOT / "examples" / "weld_polygon.py"
STATION = ROOT / "stations" / "kr6_milling_cell.yaml"
T = TypeVar("T")


def best_of(repeats: int, fn: Callable[[], T]) -> tuple[float, T]:
    """The shortest of ``repeats`` runs of ``fn`` in seconds, and its last result."""
    best, result = float("inf"), fn()
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - start)
    return best, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    station = load_station(STATION)
    source = PROGRAM.read_bytes()
    name = str(PROGRAM)
    inside_s, inside = best_of(args.repeats, lambda: run_dsl(source, name, station))
    child_s, child = best_of(args.repeats, lambda: load_dsl(PROGRAM, station))
    assert len(inside.program) == len(child.program) > 0
    build_inside_s, _ = best_of(
        args.repeats, lambda: build(station, run_dsl(source, name, station).program)
    )
    build_child_s, _ = best_of(args.repeats, lambda: build(station, PROGRAM))
    print(f"dsl_program: {PROGRAM.name}, {len(child.program)} instructions")
    print(f"dsl_in_process_seconds: {inside_s:.3f} s (reference: run_dsl)")
    print(f"dsl_child_seconds: {child_s:.3f} s (load_dsl)")
    print(f"dsl_build_in_process_seconds: {build_inside_s:.3f} s (reference)")
    print(f"dsl_build_child_seconds: {build_child_s:.3f} s")
    print(f"dsl_child_fixed_cost: {child_s - inside_s:.3f} s")
    print(f"dsl_child_ratio: {child_s / inside_s:.1f} x (parse only)")
    print(f"dsl_build_child_ratio: {build_child_s / build_inside_s:.2f} x (whole build)")


if __name__ == "__main__":
    main()
