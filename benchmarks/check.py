"""Reach + motion checks + collisions on a 100k-point toolpath, with references from the same run.

The toolpath: a joint move above the workpiece, a linear plunge, then a helix of N linear moves
(150 mm radius, 10 turns, 50 mm rise) around the centre of the workpiece of the bundled
``stations/kr6_milling_collision_cell.yaml``: the spindle housing passes 25 mm from four clamps
the whole way round, so the collision check has real work. Prints, as ``name: value unit``:

* ``resolve_seconds``: reach, joint limits and singularities (the resolve pass);
* ``collide_seconds``: collisions by conservative advancement, between samples included;
* ``check_seconds`` and ``check_points_per_second``: the two together (the target: under 10 s);
* references: ``samples_seconds``, the same pairs checked at every resolve sample only — a
  fine fixed step (the helix's moves are 0.094 mm long, one sample each) that still proves
  nothing between samples — timed on the first ``--reference`` points and scaled to the whole
  path; its ratio to ``collide_seconds`` and to the resolve time;
* ``chord_deviation_mm``: the largest distance, over all linear-move segments, between the
  joint-space chord midpoint and the true Cartesian-line midpoint, in link-point motion (what
  the guarantee of :mod:`olp.passes.collide` does not cover for linear moves).

    python -m benchmarks.check [N] [--reference R]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from olp import ir
from olp.compiled import CompiledProgram
from olp.geometry import transl
from olp.passes.collide import CollisionOptions, check_collisions_with_stats
from olp.passes.resolve import resolve
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[1]
STATION = REPO / "stations" / "kr6_milling_collision_cell.yaml"


def helix_program(station: Station, count: int) -> ir.Program:
    """Approach, plunge and a helix of ``count`` linear moves (tool down) in the workpiece frame."""
    tool, frame = station.tools["spindle"], station.frames["workpiece"]
    t = np.linspace(0.0, 1.0, count)
    poses = np.repeat(np.eye(4)[None], count, axis=0)
    poses[:, :3, :3] = np.diag([-1.0, 1.0, -1.0])
    poses[:, 0, 3] = 0.15 * np.cos(20 * np.pi * t)
    poses[:, 1, 3] = 0.15 * np.sin(20 * np.pi * t)
    poses[:, 2, 3] = 0.02 + 0.05 * t
    speed = ir.Speed(linear=0.05)
    above = transl(0, 0, 0.2) @ poses[0]
    moves: list[ir.Instruction] = [
        ir.JointMove(target=ir.CartesianTarget(pose=above), tool=tool, frame=frame),
        ir.LinearMove(target=ir.CartesianTarget(pose=poses[0]), tool=tool, frame=frame),
    ]
    moves += [
        ir.LinearMove(target=ir.CartesianTarget(pose=p), tool=tool, frame=frame, speed=speed)
        for p in poses[1:]
    ]
    return ir.Program(name="helix", instructions=moves)


def chord_deviation_m(compiled: CompiledProgram) -> float:
    """Largest midpoint gap (m of point motion) between the linear moves' joint chords and their
    Cartesian lines (:func:`olp.collision.chord.chord_deviation`)."""
    from olp.collision.chord import chord_deviation
    from olp.collision.scene import PairRules, Placed, build_scene

    station = compiled.station
    spindle = Placed("spindle", "tool", np.eye(4), station.tool_bodies["spindle"].shapes)
    scene = build_scene(station.robot, spindle, [], [], PairRules(self_collision=False))
    paths = [
        s.path
        for s in compiled.steps
        if isinstance(s.instruction, ir.LinearMove) and s.path is not None
    ]
    tool = station.tools["spindle"].pose
    assert tool is not None
    return float(np.max(chord_deviation(station.robot, scene, paths, tool)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("count", nargs="?", type=int, default=100_000)
    parser.add_argument("--reference", type=int, default=10_000)
    args = parser.parse_args()
    station = load_station(STATION)
    program = helix_program(station, args.count)
    import coal  # noqa: F401  (imports are not what is measured)
    import pinocchio  # noqa: F401

    start = time.perf_counter()
    compiled = resolve(program, station)
    resolved = time.perf_counter() - start
    assert compiled.ok, [d.format() for d in compiled.diagnostics[:3]]
    start = time.perf_counter()
    found, stats = check_collisions_with_stats(compiled)
    collided = time.perf_counter() - start
    assert not found, [d.format() for d in found[:3]]

    small = resolve(
        ir.Program(name="ref", instructions=program.instructions[: args.reference]), station
    )
    start = time.perf_counter()
    _, ref_stats = check_collisions_with_stats(small, CollisionOptions(mode="samples"))
    sampled = (time.perf_counter() - start) * stats.rows / ref_stats.rows
    sample_evaluations = ref_stats.evaluations * stats.rows // ref_stats.rows

    total = resolved + collided
    print(f"points: {args.count} moves ({stats.rows} joint-path rows, {stats.pairs} pairs)")
    print(f"resolve_seconds: {resolved:.3f} s")
    print(f"collide_seconds: {collided:.3f} s ({stats.evaluations} distance evaluations)")
    print(f"check_seconds: {total:.3f} s")
    print(f"check_points_per_second: {args.count / total:.4g} points/s")
    print(
        f"samples_seconds: {sampled:.3f} s ({sample_evaluations} distance evaluations, "
        f"scaled from {args.reference} points)"
    )
    print(f"collide_vs_samples: {sampled / collided:.1f} x faster")
    print(f"collide_vs_resolve: {collided / resolved:.2f} x the resolve time")
    print(f"chord_deviation_mm: {chord_deviation_m(compiled) * 1000:.2g} mm")


if __name__ == "__main__":
    main()
