"""Checks over every path of a program with control flow (olp.passes.flow)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.passes.flow import START, motion_predecessors

REPO = Path(__file__).resolve().parents[2]


def span(line: int) -> ir.SourceSpan:
    return ir.SourceSpan("t.src", line, 1)


def ptp(line: int, *degrees: float) -> ir.JointMove:
    return ir.JointMove(target=ir.JointTarget(joints=np.radians(degrees)), span=span(line))


def lin(line: int, x: float = 0.5, y: float = -0.4, z: float = 0.3) -> ir.LinearMove:
    pose = np.eye(4)
    pose[:3, :3] = np.diag([1.0, -1.0, -1.0])  # tool down
    pose[:3, 3] = [x, y, z]
    return ir.LinearMove(target=ir.CartesianTarget(pose=pose), span=span(line))


IN1 = ir.DigitalInput(index=1)


def program(*nodes: ir.Node) -> ir.Program:
    return ir.Program(name="t", instructions=nodes, source="t.src")


def test_the_motion_after_a_branch_join_has_every_branch_end_before_it() -> None:
    branches = ir.If(branches=(ir.Branch(condition=IN1, body=(lin(2),)),), orelse=(lin(4),))
    preds = motion_predecessors(program(lin(1), branches, lin(5)))
    assert preds == {0: {START}, 1: {0}, 2: {0}, 3: {1, 2}}


def test_loops_reach_their_fixpoint() -> None:
    loop = ir.While(condition=IN1, body=(lin(2), lin(3)))
    assert motion_predecessors(program(lin(1), loop, lin(4))) == {
        0: {START},
        1: {0, 2},  # the first motion of the body: from before the loop or its last pass
        2: {1},
        3: {0, 2},  # after the loop: not entered, or after a pass
    }
    endless = ir.Loop(
        body=(lin(2), ir.If(branches=(ir.Branch(condition=IN1, body=(ir.Exit(),)),)), lin(3))
    )
    assert motion_predecessors(program(endless, lin(4))) == {0: {START, 2}, 2: {0}, 3: {0}}
    repeat = ir.Repeat(body=(lin(2),), until=IN1)
    assert motion_predecessors(program(lin(1), repeat, lin(3))) == {0: {START}, 1: {0, 1}, 2: {1}}


def test_jumps_back_and_forward() -> None:
    nodes = (
        lin(1),
        ir.Label(name="retry"),
        lin(3),
        ir.If(branches=(ir.Branch(condition=IN1, body=(ir.Goto(label="RETRY"),)),)),
        ir.Goto(label="done"),
        lin(6),  # never reached
        ir.Label(name="done"),
        lin(8),
    )
    preds = motion_predecessors(program(*nodes))
    assert preds == {0: {START}, 2: {0, 2}, 5: set(), 7: {2}}


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def test_a_linear_move_is_checked_from_every_start_a_path_gives_it(station: object) -> None:
    turned = ir.If(
        branches=(ir.Branch(condition=IN1, body=(ptp(3, 150, -90, 90, 0, 45, 0),)),),
        orelse=(ptp(5, 0, -90, 90, 0, 45, 0),),
        span=span(2),
    )
    flat = program(ptp(1, 0, -90, 90, 0, 45, 0), ptp(5, 0, -90, 90, 0, 45, 0), lin(7))
    assert olp.compile(flat, station, collisions=None).ok  # from the text's start: fine
    compiled = olp.compile(program(ptp(1, 0, -90, 90, 0, 45, 0), turned, lin(7)), station)
    errors = [d for d in compiled.diagnostics if d.severity == "error"]
    assert [(d.kind, d.index, d.span.line if d.span else 0) for d in errors] == [
        ("joint_limit", 3, 7)
    ]
    assert errors[0].message.endswith("(when it starts from the motion at line 3)")
    kinds = {d.kind for d in compiled.diagnostics}
    assert "flow_paths" in kinds and "flow_timing" not in kinds  # with errors: not timed
