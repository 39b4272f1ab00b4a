"""Cycle time per path (olp.passes.timing.branches): what the walk over a program's blocks costs.

Run from the repository root: ``python -m benchmarks.timing_branches [--ifs N] [--passes P]``.

* N ``IF ... ELSE`` blocks in a row (default 40: 2^40 paths), each branch one linear move on the
  KR 6 milling cell: the walk keeps one state per robot position, so its cost grows with N, not
  with the number of paths.
* A ``FOR`` of P passes (default 1,000,000) around such an ``IF`` and a move: the passes are
  added up once they repeat, not walked.

Each figure is the best of ``--repeats`` runs of :func:`path_times` alone (the program compiled
once before). The last lines are the headline figures, one per line as ``name: value unit``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import olp
from olp import ir
from olp.compiled import CompiledProgram
from olp.passes.pipeline import BuildOptions
from olp.passes.timing.branches import path_times

REPO = Path(__file__).resolve().parents[1]
TOOL_FORWARD = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])


def target(y_mm: float, z_mm: float) -> ir.CartesianTarget:
    pose = np.eye(4)
    pose[:3, :3] = TOOL_FORWARD
    pose[:3, 3] = [0.5, y_mm / 1000, z_mm / 1000]
    return ir.CartesianTarget(pose=pose)


def lin(y_mm: float, z_mm: float = 300.0) -> ir.LinearMove:
    return ir.LinearMove(target=target(y_mm, z_mm))


def choice(k: int) -> ir.If:
    near, far = lin(-300, 350), lin(-300, 450 + k % 3 * 20)
    condition = ir.DigitalInput(index=k + 1)
    return ir.If(branches=(ir.Branch(condition=condition, body=(near,)),), orelse=(far,))


def compiled(*nodes: ir.Node) -> CompiledProgram:
    station = olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")
    first = ir.JointMove(target=target(-300, 300))
    program = ir.Program(name="bench", instructions=(first, *nodes))
    result = olp.compile(program, station, collisions=None)
    assert result.ok, [d.format() for d in result.diagnostics]
    return result


def best(program: CompiledProgram, repeats: int) -> tuple[float, float, float]:
    """Best seconds of :func:`path_times` over ``repeats`` runs, and the range it found."""
    seconds = []
    for _ in range(repeats):
        began = time.perf_counter()
        paths = path_times(program, BuildOptions(collisions=None))
        seconds.append(time.perf_counter() - began)
    assert paths.shortest is not None and paths.longest is not None
    return min(seconds), paths.shortest.seconds, paths.longest.seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ifs", type=int, default=40)
    parser.add_argument("--passes", type=int, default=1_000_000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    chain = compiled(*(node for k in range(args.ifs) for node in (choice(k), lin(-300))))
    walk, lo, hi = best(chain, args.repeats)
    print(f"{args.ifs} IF/ELSE in a row: range {lo:.3f} .. {hi:.3f} s")
    one = ir.Constant(value=1)
    loop = ir.For(
        variable="i",
        start=one,
        stop=ir.Constant(value=args.passes),
        body=(choice(0), lin(-300)),
    )
    looped, lo_loop, hi_loop = best(compiled(loop), args.repeats)
    print(f"FOR of {args.passes} passes: range {lo_loop:.1f} .. {hi_loop:.1f} s")
    print(f"walk_{args.ifs}_ifs: {walk * 1000:.1f} ms")
    print(f"walk_for_{args.passes}_passes: {looped * 1000:.1f} ms")


if __name__ == "__main__":
    main()
