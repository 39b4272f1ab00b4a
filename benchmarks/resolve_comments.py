"""Resolve on programs of many non-motion instructions: today's code against the old code path,
in one process.

Two joint moves with N comments between them on the bundled KR 6 milling cell. Resolve looked
for a run of linear moves at every instruction with ``instructions[start:]``, which copies the
rest of the program each time: quadratic in N (the issue measured 70 s for 200,000 comments).
Today it walks by index. The old function is kept below and swapped in for the reference.

    python -m benchmarks.resolve_comments [--comments N] [--reference-comments R]

The reference runs at R and R / 2 comments (its time grows ~4x per doubling); today's code at N
and N / 10. The collision check and the timing pass, which walk the same steps, are measured at
N and N / 10 too. Prints ``name: value unit`` lines; ``*_scaling`` is the time ratio of a 10x
(or 2x) larger program: ~10 (or ~2) is linear, ~100 (or ~4) quadratic.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from olp import ir
from olp.passes import resolve as resolve_module
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[1]


def program(comments: int) -> ir.Program:
    start = ir.JointMove(target=ir.JointTarget(joints=np.radians([0, -90, 90, 0, 30, 0])))
    end = ir.JointMove(target=ir.JointTarget(joints=np.radians([10, -90, 90, 0, 30, 0])))
    middle = [ir.Comment(text=f"comment {i}") for i in range(comments)]
    return ir.Program(name="comments", instructions=[start, *middle, end])


def _slicing_linear_run(
    instructions: tuple[ir.Instruction, ...], start: int, station: Station
) -> list[tuple[ir.LinearMove, ir.Tool, ir.Frame]]:
    """The old ``_linear_run`` (before issue 10), verbatim but for its docstring."""
    run: list[tuple[ir.LinearMove, ir.Tool, ir.Frame]] = []
    first_tool: ir.Tool | None = None
    for ins in instructions[start:]:
        if not (isinstance(ins, ir.LinearMove) and isinstance(ins.target, ir.CartesianTarget)):
            break
        tool = ins.tool if ins.tool.pose is not None else station.tool(ins.tool)
        frame = ins.frame if ins.frame.pose is not None else station.frame(ins.frame)
        if tool is None or frame is None or (first_tool is not None and tool != first_tool):
            break
        first_tool = tool
        run.append((ins, tool, frame))
    return run


def _seconds(station: Station, comments: int) -> float:
    prog = program(comments)
    start = time.perf_counter()
    compiled = resolve_module.resolve(prog, station)
    elapsed = time.perf_counter() - start
    assert compiled.ok and len(compiled.steps) == comments + 2
    return elapsed


def _later_passes(station: Station, comments: int) -> tuple[float, float]:
    """Seconds of the collision check and of the timing pass on the resolved program."""
    from olp.passes.collide import CollisionOptions, check_collisions
    from olp.passes.timing import time_program

    compiled = resolve_module.resolve(program(comments), station)
    start = time.perf_counter()
    found = check_collisions(compiled, CollisionOptions())
    collide = time.perf_counter() - start
    start = time.perf_counter()
    timed = time_program(compiled)
    timing = time.perf_counter() - start
    assert not found and timed.ok
    return collide, timing


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--comments", type=int, default=200_000)
    parser.add_argument("--reference-comments", type=int, default=20_000)
    args = parser.parse_args()
    station = load_station(REPO / "stations" / "kr6_milling_cell.yaml")
    n, r = args.comments, args.reference_comments
    today, today_small = _seconds(station, n), _seconds(station, n // 10)
    today_ref = _seconds(station, r)
    current = resolve_module._linear_run
    resolve_module._linear_run = _slicing_linear_run  # type: ignore[assignment]
    try:
        old, old_half = _seconds(station, r), _seconds(station, r // 2)
    finally:
        resolve_module._linear_run = current
    exponent = np.log2(old / old_half)
    _later_passes(station, 10)  # imports and first-call set-up out of the figures
    (collide, timing), (collide_small, timing_small) = (
        _later_passes(station, n),
        _later_passes(station, n // 10),
    )
    print(f"resolve_comments_seconds: {today:.3f} s ({n} comments)")
    print(f"resolve_comments_scaling: {today / today_small:.1f} x ({n // 10} -> {n} comments)")
    print(f"resolve_comments_old_seconds: {old:.3f} s ({r} comments)")
    print(f"resolve_comments_old_scaling: {old / old_half:.1f} x ({r // 2} -> {r} comments)")
    print(f"resolve_comments_speedup: {old / today_ref:.1f} x (old / today at {r} comments)")
    print(f"collide_comments_seconds: {collide:.3f} s ({n} comments)")
    print(f"collide_comments_scaling: {collide / collide_small:.1f} x ({n // 10} -> {n} comments)")
    print(f"timing_comments_seconds: {timing:.3f} s ({n} comments)")
    print(f"timing_comments_scaling: {timing / timing_small:.1f} x ({n // 10} -> {n} comments)")
    # The old path at n comments, extrapolated with its measured growth (not run: minutes).
    print(f"resolve_comments_old_extrapolated: {old * (n / r) ** exponent:.1f} s ({n} comments)")


if __name__ == "__main__":
    main()
