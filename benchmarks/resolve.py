"""Resolve speed on a long toolpath: batched linear runs vs the per-move path, same process.

A helix of N linear moves (tool down) on the bundled KR 6 milling cell; prints points/s for the
batched resolve (default) and for the per-move reference (every move sampled and solved alone).

    python -m benchmarks.resolve [N]
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from olp import ir
from olp.passes import resolve as resolve_module
from olp.station.loader import load_station

REPO = Path(__file__).resolve().parents[1]


def helix_program(count: int) -> ir.Program:
    station = load_station(REPO / "stations" / "kr6_milling_cell.yaml")
    tool, frame = station.tools["spindle"], station.frames["table"]
    t = np.linspace(0.0, 1.0, count)
    poses = np.repeat(np.eye(4)[None], count, axis=0)
    poses[:, :3, :3] = np.diag([-1.0, 1.0, -1.0])
    poses[:, 0, 3] = 0.1 + 0.15 * np.cos(20 * np.pi * t)
    poses[:, 1, 3] = 0.15 + 0.15 * np.sin(20 * np.pi * t)
    poses[:, 2, 3] = 0.02 + 0.05 * t
    speed = ir.Speed(linear=0.05)
    moves: list[ir.Instruction] = [
        ir.JointMove(target=ir.CartesianTarget(pose=poses[0]), tool=tool, frame=frame)
    ]
    moves += [
        ir.LinearMove(target=ir.CartesianTarget(pose=p), tool=tool, frame=frame, speed=speed)
        for p in poses[1:]
    ]
    return ir.Program(name="helix", instructions=moves)


def main() -> None:
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
    station = load_station(REPO / "stations" / "kr6_milling_cell.yaml")
    program = helix_program(count)
    start = time.perf_counter()
    compiled = resolve_module.resolve(program, station)
    batched = time.perf_counter() - start
    assert compiled.ok, compiled.diagnostics[:3]
    reference = min(count, 5_000)
    small = ir.Program(name="ref", instructions=program.instructions[:reference])
    original = resolve_module._linear_run
    resolve_module._linear_run = lambda *_: []  # type: ignore[assignment]
    try:
        start = time.perf_counter()
        resolve_module.resolve(small, station)
        per_move = time.perf_counter() - start
    finally:
        resolve_module._linear_run = original
    print(f"resolve_batched_seconds: {batched:.3f} s ({count} points)")
    print(f"resolve_batched: {count / batched:.4g} points/s")
    print(f"resolve_per_move: {reference / per_move:.4g} points/s ({reference} points)")
    print(f"resolve_speedup: {(count / batched) / (reference / per_move):.1f} x")


if __name__ == "__main__":
    main()
