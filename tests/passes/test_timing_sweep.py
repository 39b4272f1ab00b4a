"""Speed sweeps of a program with control flow (olp.passes.timing.sweep): the program with
other speeds keeps its blocks, so each path is timed as the program runs it (before, the sweep
rebuilt the program from its flat list of steps and ran every branch one after the other)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.ir_flow import leaves_and_blocks
from olp.passes.pipeline import BuildOptions
from olp.passes.timing import override_speeds, path_sweep, time_program
from olp.passes.timing.branches import path_times
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
TOOL_FORWARD = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
"""KUKA A 0, B 90, C 0: the tool along the base's x axis (reachable all over the test area)."""


def pose(y_mm: float) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = TOOL_FORWARD
    out[:3, 3] = [0.5, y_mm / 1000, 0.3]
    return out


def start() -> ir.JointMove:
    return ir.JointMove(target=ir.CartesianTarget(pose=pose(-400)))


def lin(y_mm: float, speed: float = 0.1) -> ir.LinearMove:
    return ir.LinearMove(target=ir.CartesianTarget(pose=pose(y_mm)), speed=ir.Speed(linear=speed))


@pytest.fixture(scope="module")
def station() -> Station:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def test_a_sweep_keeps_the_if_and_times_each_path(station: Station) -> None:
    taken = [lin(-200), lin(-400)]
    branch = ir.If(
        branches=(ir.Branch(condition=ir.DigitalInput(index=1), body=tuple(taken)),),
        orelse=(ir.Wait(seconds=0.5),),
    )
    prog = ir.Program(name="t", instructions=(start(), branch), source="t.src")
    compiled = olp.compile(prog, station, collisions=None)
    assert compiled.ok, [d.format() for d in compiled.diagnostics]

    faster = time_program(override_speeds(compiled, linear=0.4, joint=0.5))
    (block,) = [n for n in faster.program.instructions if isinstance(n, ir.If)]
    (arm,) = block.branches
    assert [m.speed.linear for m in arm.body] == [0.4, 0.4]  # type: ignore[union-attr]
    assert block.orelse == (ir.Wait(seconds=0.5),)
    assert len(list(leaves_and_blocks(faster.program.instructions))) == 5

    paths = path_times(faster, BuildOptions(collisions=None))
    assert paths.shortest is not None and paths.longest is not None
    straight = olp.compile(
        ir.Program(name="t", instructions=(start(), lin(-200, 0.4), lin(-400, 0.4))),
        station,
        collisions=None,
    )
    moving = time_program(override_speeds(straight, joint=0.5)).cycle_time
    waiting = time_program(
        override_speeds(
            olp.compile(
                ir.Program(name="t", instructions=(start(), ir.Wait(seconds=0.5))),
                station,
                collisions=None,
            ),
            joint=0.5,
        )
    ).cycle_time
    assert paths.longest.seconds == pytest.approx(moving, rel=1e-4)
    assert paths.shortest.seconds == pytest.approx(waiting, rel=1e-4)
    assert paths.shortest.seconds < paths.longest.seconds < moving + 0.5


def test_a_path_sweep_gives_both_ends_per_speed(station: Station) -> None:
    branch = ir.If(
        branches=(ir.Branch(condition=ir.DigitalInput(index=1), body=(lin(-200), lin(-400))),),
        orelse=(ir.Wait(seconds=0.5),),
    )
    prog = ir.Program(name="t", instructions=(start(), branch), source="t.src")
    compiled = olp.compile(prog, station, collisions=None)
    options = BuildOptions(collisions=None)
    ends = path_sweep(compiled, [0.1, 0.4], [None], options)
    assert ends.shape == (2, 1, 2)
    for row, linear in zip(ends[:, 0], [0.1, 0.4], strict=True):
        paths = path_times(time_program(override_speeds(compiled, linear=linear)), options)
        assert paths.shortest is not None and paths.longest is not None
        assert row.tolist() == [paths.shortest.seconds, paths.longest.seconds]
    assert ends[1, 0, 1] < ends[0, 0, 1]  # the branch that moves is faster at 0.4 m/s
    assert ends[1, 0, 0] == pytest.approx(ends[0, 0, 0])  # the one that waits is not


def test_olp_time_sweeps_a_program_with_branches_per_path(
    capsys: pytest.CaptureFixture[str],
) -> None:
    from olp.cli import main

    cell = REPO / "tests" / "corpus" / "krc" / "R1"
    args = [
        "time",
        str(REPO / "stations" / "kr6_milling_cell.yaml"),
        str(cell / "Program" / "pick_part.src"),
        "--config-dat",
        str(cell / "System" / "$config.dat"),
        "--no-collisions",
        "--sweep-linear",
        "250,500",
    ]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "shortest path: cycle time (s)" in out and "longest path: cycle time (s)" in out
