"""Timing speed on long toolpaths: the fast paths against the reference, in one process.

A helix of N linear moves (tool down, 50 mm/s, as ``benchmarks.resolve``) on the bundled KR 6
milling cell, timed as

* **blended** (zone 2 mm: one chain of N blended moves, one time-law problem): olp's default
  (TOPPRA's reachability analysis vectorised in numpy) against the toppra package's TOPPRA on
  the same grid;
* **fine** (every move stops: N stop-to-stop problems): olp's default (closed-form laws on
  straight joint lines, vectorised over the moves) against the toppra package per move;
* **fine_coarse**: the same on a helix of N / 5 moves (0.5 mm instead of 0.1 mm).

The reference (``TimingOptions(solver="toppra", straight_lines=False)``, the path olp took
before) runs on the first ``--reference-moves`` moves, the default on all N and on that prefix.
On the prefix the cycle times are compared with the reference and with the reachability solver
on a grid 8x finer (the converged optimum), all three acceleration-limited (the reference has
no jerk-limited laws). On all N the default (jerk-limited path moves) is also compared with the
acceleration-limited model (``path_jerk=False``, the model before jerk on path moves): its
time and cycle time, and the ratios. Run from the repository root::

    python -m benchmarks.timing_long [--moves N] [--reference-moves R]

Prints ``name: value unit`` lines.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time
from pathlib import Path

import numpy as np

from benchmarks.resolve import helix_program
from olp import ir
from olp.compiled import CompiledProgram
from olp.passes.resolve import resolve
from olp.passes.timing import TimingOptions, time_program
from olp.station.loader import load_station
from olp.trajectory import LineTimeLaw

REPO = Path(__file__).resolve().parents[1]
REFERENCE = TimingOptions(solver="toppra", straight_lines=False, path_jerk=False)
"""The toppra package on every path problem, no closed-form lines: the path olp took before."""
CONVERGED = TimingOptions(
    grid_per_sample=16,
    max_grid_step_rad=math.radians(0.0625),
    max_grid_turn_rad=math.radians(0.125),
    refine_points=96,
    straight_lines=False,
    path_jerk=False,
)
"""The reachability solver on a grid 8x finer than the default in every respect."""
ACCEL_ONLY = TimingOptions(path_jerk=False)
"""The default without jerk on path moves (the model the references compare with)."""


def _zoned(program: ir.Program, zone: float) -> ir.Program:
    moves = [
        dataclasses.replace(ins, zone=ir.Zone(zone)) if isinstance(ins, ir.LinearMove) else ins
        for ins in program.instructions
    ]
    return ir.Program(name=program.name, instructions=moves)


def _timed(compiled: CompiledProgram, options: TimingOptions) -> tuple[float, CompiledProgram]:
    start = time.perf_counter()
    timed = time_program(compiled, options=options)
    return time.perf_counter() - start, timed


def _failed(compiled: CompiledProgram) -> set[int]:
    return {d.index for d in compiled.diagnostics if d.severity == "error" and d.index is not None}


def _difference(ours: CompiledProgram, other: CompiledProgram) -> str:
    """Relative difference of the summed durations and the largest per move, over the moves
    (not the first PTP) that both timed without error."""
    keep = [i for i in range(1, len(ours.steps)) if i not in _failed(ours) | _failed(other)]
    if not keep:
        return "n/a (no move timed by both)"
    a = np.array([ours.steps[i].duration for i in keep])
    b = np.array([other.steps[i].duration for i in keep])
    worst = np.max(np.abs(a / b - 1))
    return f"{(a.sum() / b.sum() - 1) * 100:+.4f} % (largest move {worst * 100:.4f} %)"


def _case(name: str, program: ir.Program, reference_moves: int) -> None:
    station = load_station(REPO / "stations" / "kr6_milling_cell.yaml")
    moves = len(program.instructions) - 1
    start = time.perf_counter()
    compiled = resolve(program, station)
    print(f"{name}_resolve_time: {time.perf_counter() - start:.2f} s ({moves} moves)")
    fast_s, fast = _timed(compiled, TimingOptions())
    assert fast.ok, [d.message for d in fast.diagnostics[:3]]
    lines = sum(isinstance(s.trajectory.law, LineTimeLaw) for s in fast.steps if s.trajectory)
    print(f"{name}_time: {fast_s:.2f} s ({moves} moves)")
    print(f"{name}_rate: {moves / fast_s:.0f} moves/s")
    print(f"{name}_closed_form_moves: {lines / moves * 100:.1f} %")
    print(f"{name}_cycle_time: {fast.cycle_time:.3f} s")
    accel_s, accel_only = _timed(compiled, ACCEL_ONLY)
    print(f"{name}_acceleration_limited_time: {accel_s:.2f} s")
    print(f"{name}_time_ratio_vs_acceleration_limited: {fast_s / accel_s:.2f} x")
    print(f"{name}_acceleration_limited_cycle_time: {accel_only.cycle_time:.3f} s")
    ratio = fast.cycle_time / accel_only.cycle_time
    print(f"{name}_cycle_time_ratio_vs_acceleration_limited: {ratio:.4f} x")

    prefix = ir.Program(name="prefix", instructions=program.instructions[: reference_moves + 1])
    small = resolve(prefix, station)
    small_s, small_fast = _timed(small, ACCEL_ONLY)
    ref_s, ref = _timed(small, REFERENCE)
    converged = _timed(small, CONVERGED)[1]
    print(f"{name}_reference_rate: {reference_moves / ref_s:.0f} moves/s ({reference_moves} moves)")
    print(f"{name}_default_rate_same_moves: {reference_moves / small_s:.0f} moves/s")
    print(f"{name}_speedup_same_moves: {ref_s / small_s:.1f} x")
    ratio = (moves / fast_s) / (reference_moves / ref_s)
    print(f"{name}_speedup_rate_all_vs_reference: {ratio:.1f} x")
    print(f"{name}_reference_failures: {len(_failed(ref))} moves (no time law found)")
    print(f"{name}_cycle_time_vs_reference: {_difference(small_fast, ref)}")
    print(f"{name}_cycle_time_vs_converged: {_difference(small_fast, converged)}")
    print(f"{name}_reference_vs_converged: {_difference(ref, converged)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--moves", type=int, default=100_000)
    parser.add_argument("--reference-moves", type=int, default=2_000)
    parser.add_argument("--zone", type=float, default=0.002, help="blend zone, m")
    args = parser.parse_args()
    program = helix_program(args.moves + 1)
    _case("blended", _zoned(program, args.zone), args.reference_moves)
    _case("fine", program, args.reference_moves)
    # The toppra package finds no time law on the 0.1 mm moves of a 100,000-point helix; on the
    # 0.5 mm moves of a 5x coarser one it does, and the closed form is compared with it there.
    coarse = helix_program(args.moves // 5 + 1)
    _case("fine_coarse", coarse, args.reference_moves)


if __name__ == "__main__":
    main()
