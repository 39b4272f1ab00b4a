"""Checks and timing see each routine's body at every call (olp.ir.Program.expanded): a RETURN in
a routine leaves the routine, not the program, and a routine's labels are its own at each call."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.passes.flow import START, motion_predecessors
from olp.passes.pipeline import BuildOptions
from olp.passes.timing.conditions import parse_assumptions
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
TOOL_FORWARD = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
IN1 = ir.DigitalInput(index=1)


def span(line: int) -> ir.SourceSpan:
    return ir.SourceSpan("t.src", line, 3)


def lin(line: int, y_mm: float, z_mm: float = 300.0) -> ir.LinearMove:
    pose = np.eye(4)
    pose[:3, :3] = TOOL_FORWARD
    pose[:3, 3] = [0.5, y_mm / 1000, z_mm / 1000]
    return ir.LinearMove(target=ir.CartesianTarget(pose=pose), span=span(line))


def start() -> ir.JointMove:
    pose = lin(1, -400).target.pose
    return ir.JointMove(target=ir.CartesianTarget(pose=pose), span=span(1))


def leave_early() -> ir.Routine:
    """Moves to -300; returns there when input 1 is on, else goes on to -150."""
    early = ir.If(branches=(ir.Branch(condition=IN1, body=(ir.Return(span=span(12)),)),))
    return ir.Routine(name="Part", body=(lin(11, -300), early, lin(13, -150)), span=span(10))


def calling(*routines: ir.Routine) -> ir.Program:
    call = ir.RoutineCall(name="Part", span=span(2))
    nodes = (start(), call, lin(3, -250, 350))
    return ir.Program(name="t", instructions=nodes, source="t.src", routines=routines)


def test_a_return_in_a_routine_flows_to_after_its_call() -> None:
    preds = motion_predecessors(calling(leave_early()).expanded())
    # 0 start, 1 LIN -300, 2 RETURN, 3 LIN -150, 4 the caller's LIN after the call
    assert preds == {0: {START}, 1: {0}, 3: {1}, 4: {1, 3}}


def test_labels_of_a_routine_are_its_own_at_each_call() -> None:
    """Two calls of a routine that jumps back to its label: a GOTO of the second call never
    reaches the label of the first."""
    body = (
        ir.Label(name="again", span=span(11)),
        lin(12, -300),
        ir.If(branches=(ir.Branch(condition=IN1, body=(ir.Goto(label="again", span=span(13)),)),)),
    )
    routine = ir.Routine(name="Part", body=body, span=span(10))
    calls = [ir.RoutineCall(name="Part", span=span(n)) for n in (2, 3)]
    prog = ir.Program(name="t", instructions=(start(), *calls), routines=(routine,))
    preds = motion_predecessors(prog.expanded())
    # 0 start, 1 label, 2 LIN (first call), 3 goto, 4 label, 5 LIN (second call), 6 goto
    assert preds == {0: {START}, 2: {0, 2}, 5: {2, 5}}


@pytest.fixture(scope="module")
def station() -> Station:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def test_path_times_end_a_routine_at_its_return(station: Station) -> None:
    """The range is the two straight programs: returning after -300 (input 1 on), or going on
    to -150 first; the caller's last move is timed after both (a RETURN that ended the program
    would leave it out of the short one)."""
    options = BuildOptions(collisions=None, assume=parse_assumptions(()))
    compiled = olp.compile(calling(leave_early()), station, options)
    assert compiled.ok and compiled.paths is not None
    paths = compiled.paths
    assert paths.shortest is not None and paths.longest is not None

    def straight(*nodes: ir.Node) -> float:
        prog = ir.Program(name="s", instructions=nodes, source="t.src")
        return olp.compile(prog, station, collisions=None).cycle_time

    short = straight(start(), lin(11, -300), lin(3, -250, 350))
    long = straight(start(), lin(11, -300), lin(13, -150), lin(3, -250, 350))
    assert (paths.shortest.seconds, paths.longest.seconds) == pytest.approx((short, long), rel=1e-4)
