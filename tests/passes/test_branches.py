"""Cycle time per path of a program with control flow (olp.passes.timing.branches).

Every expected time is the cycle time of a straight program written out by hand: the path the
branch choices, loop counts or assumptions name, instruction by instruction.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.errors import UsageError
from olp.passes.pipeline import BuildOptions
from olp.passes.timing.branches import PathTimes
from olp.passes.timing.conditions import parse_assumptions
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]

TOOL_FORWARD = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
"""KUKA A 0, B 90, C 0: the tool along the base's x axis (reachable all over the test area)."""

IN1, IN2 = ir.DigitalInput(index=1), ir.DigitalInput(index=2)

TOL = 1e-4
"""Relative tolerance against the straight program: a linear move resolved from a start that
differs by 1e-15 rad (the same pose reached along another path) may get one more sample, which
changes its time by ~6e-6 (measured); the branches here differ by 10% and more."""


def span(line: int) -> ir.SourceSpan:
    return ir.SourceSpan("t.src", line, 3)


def pose(y_mm: float, z_mm: float = 300.0) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = TOOL_FORWARD
    out[:3, 3] = [0.5, y_mm / 1000, z_mm / 1000]
    return out


def start(line: int = 1) -> ir.JointMove:
    return ir.JointMove(target=ir.CartesianTarget(pose=pose(-400)), span=span(line))


def lin(line: int, y_mm: float, z_mm: float = 300.0) -> ir.LinearMove:
    return ir.LinearMove(target=ir.CartesianTarget(pose=pose(y_mm, z_mm)), span=span(line))


def program(*nodes: ir.Node) -> ir.Program:
    return ir.Program(name="t", instructions=nodes, source="t.src")


@pytest.fixture(scope="module")
def station() -> Station:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def paths_of(station: Station, prog: ir.Program, *assume: str) -> PathTimes:
    options = BuildOptions(collisions=None, assume=parse_assumptions(assume))
    compiled = olp.compile(prog, station, options)
    assert compiled.ok, [d.format() for d in compiled.diagnostics]
    assert compiled.paths is not None
    return compiled.paths


def straight(station: Station, *nodes: ir.Node) -> float:
    compiled = olp.compile(program(*nodes), station, collisions=None)
    assert compiled.ok and compiled.paths is None
    return compiled.cycle_time


def ends(paths: PathTimes) -> tuple[float, float]:
    assert paths.shortest is not None and paths.longest is not None
    return paths.shortest.seconds, paths.longest.seconds


def described(paths: PathTimes) -> tuple[list[str], list[str]]:
    assert paths.shortest is not None and paths.longest is not None
    return (
        [c.describe() for c in paths.shortest.choices],
        [c.describe() for c in paths.longest.choices],
    )


def if_else(near: ir.Node, far: ir.Node) -> ir.If:
    return ir.If(branches=(ir.Branch(condition=IN1, body=(near,)),), orelse=(far,), span=span(2))


def test_if_else_ranges_over_the_two_straight_programs(station: Station) -> None:
    # THEN moves 100 mm, ELSE 250 mm; the move after the join starts from either end.
    prog = program(start(), if_else(lin(3, -300), lin(5, -150)), lin(7, -250, 350))
    short = straight(station, start(), lin(3, -300), lin(7, -250, 350))
    long = straight(station, start(), lin(5, -150), lin(7, -250, 350))
    assert short < long - 0.1
    paths = paths_of(station, prog)
    assert ends(paths) == pytest.approx((short, long), rel=TOL)
    assert described(paths) == (["IF at t.src:2 taken"], ["IF at t.src:2 not taken"])
    assert not paths.decided
    # The text in order times the ELSE move from the THEN move's end: no run does that.
    text = olp.compile(prog, station, collisions=None).cycle_time
    assert text != pytest.approx(short) and text != pytest.approx(long)


def test_assume_names_each_branch(station: Station) -> None:
    prog = program(start(), if_else(lin(3, -300), lin(5, -150)), lin(7, -250, 350))
    taken = paths_of(station, prog, "in1=true")
    assert taken.decided and taken.assumed == ("in1=true",)
    assert ends(taken)[0] == pytest.approx(
        straight(station, start(), lin(3, -300), lin(7, -250, 350)), rel=TOL
    )
    other = paths_of(station, prog, "$IN[1]=FALSE")
    assert other.decided
    assert ends(other)[0] == pytest.approx(
        straight(station, start(), lin(5, -150), lin(7, -250, 350)), rel=TOL
    )


def test_a_for_with_constant_bounds_runs_its_count(station: Station) -> None:
    body = (lin(4, -300, 350), lin(5, -300))
    loop = ir.For(
        variable="i",
        start=ir.Constant(value=1),
        stop=ir.Constant(value=4),
        body=body,
        span=span(3),
    )
    paths = paths_of(station, program(start(), lin(2, -300), loop))
    expected = straight(station, start(), lin(2, -300), *(body * 4))
    assert paths.decided and ends(paths)[0] == pytest.approx(expected, rel=TOL)
    assert paths.notes == ()


def test_a_while_runs_the_passes_assumed_else_one(station: Station) -> None:
    body = (lin(4, -300, 350), lin(5, -300))
    loop = ir.While(condition=IN2, body=body, span=span(3))
    prog = program(start(), lin(2, -300), loop)
    three = paths_of(station, prog, "loop:3=3")
    assert three.decided
    assert ends(three)[0] == pytest.approx(
        straight(station, start(), lin(2, -300), *(body * 3)), rel=TOL
    )
    once = paths_of(station, prog)
    assert ends(once)[0] == pytest.approx(straight(station, start(), lin(2, -300), *body), rel=TOL)
    assert once.notes == (
        "WHILE at t.src:3 counted as 1 pass (its count is not known: --assume loop:3=N)",
    )
    assert ends(paths_of(station, prog, "loop:T.SRC:3=3")) == ends(three)
    with pytest.raises(UsageError, match=r"no loop of the program is on line 3 of u\.src"):
        paths_of(station, prog, "loop:u.src:3=3")
    never = paths_of(station, prog, "in2=false")  # the condition is known false: no pass
    assert ends(never)[0] == pytest.approx(straight(station, start(), lin(2, -300)), rel=TOL)


def test_a_loop_named_by_its_label(station: Station) -> None:
    loop = ir.Repeat(body=(lin(4, -300, 350), lin(5, -300)), until=IN2, span=span(3))
    prog = program(start(), lin(2, -300), ir.Label(name="Again"), loop)
    with pytest.raises(UsageError, match="the REPEAT at line 3 runs at least once"):
        paths_of(station, prog, "loop:again=0")
    twice = paths_of(station, prog, "loop:again=2")
    body = (lin(4, -300, 350), lin(5, -300))
    assert ends(twice)[0] == pytest.approx(
        straight(station, start(), lin(2, -300), *(body * 2)), rel=TOL
    )


def test_a_switch_ranges_over_its_cases_and_a_value_picks_one(station: Station) -> None:
    cases = (
        ir.Case(values=(ir.Constant(value=1),), body=(lin(4, -350),)),
        ir.Case(values=(ir.Constant(value=2), ir.Constant(value=3)), body=(lin(6, -100),)),
    )
    switch = ir.Switch(
        subject=ir.Name(name="mode"), cases=cases, default=(lin(8, -250),), span=span(3)
    )
    prog = program(start(), switch)
    times = {
        y: straight(station, start(), lin(4, y)) for y in (-350, -100, -250)
    }  # 50, 300 and 150 mm from the start
    paths = paths_of(station, prog)
    assert ends(paths) == pytest.approx((times[-350], times[-100]), rel=TOL)
    assert described(paths) == (["SWITCH at t.src:3 CASE 1"], ["SWITCH at t.src:3 CASE 2,3"])
    assert ends(paths_of(station, prog, "MODE=3"))[0] == pytest.approx(times[-100], rel=TOL)
    default = paths_of(station, prog, "mode=7")
    assert default.decided and ends(default)[0] == pytest.approx(times[-250], rel=TOL)


def test_a_constant_declaration_decides_like_an_assumption(station: Station) -> None:
    declared = ir.Declare(name="Mode", type_name="INT", value=ir.Constant(value=1))
    cases = (ir.Case(values=(ir.Constant(value=1),), body=(lin(4, -350),)),)
    switch = ir.Switch(
        subject=ir.Name(name="mode"), cases=cases, default=(lin(8, -100),), span=span(3)
    )
    paths = paths_of(station, program(declared, start(), switch))
    assert paths.decided
    assert ends(paths)[0] == pytest.approx(straight(station, start(), lin(4, -350)), rel=TOL)
    assigned = ir.Assign(target=ir.Name(name="MODE"), value=ir.Constant(value=2))
    changed = paths_of(station, program(declared, start(), assigned, switch))
    assert changed.decided  # the assignment on the way decides it (CASE 1 no longer)
    assert ends(changed)[0] == pytest.approx(straight(station, start(), lin(8, -100)), rel=TOL)
    maybe = ir.If(branches=(ir.Branch(condition=IN1, body=(assigned,)),), span=span(2))
    open_ = paths_of(station, program(declared, start(), maybe, switch))
    assert not open_.decided  # assigned on one path only: both cases stay open


def test_nested_blocks_count_choices_per_pass(station: Station) -> None:
    inner = ir.If(
        branches=(ir.Branch(condition=IN1, body=(lin(5, -300, 350),)),),
        orelse=(lin(7, -300, 450),),
        span=span(4),
    )
    loop = ir.For(
        variable="i",
        start=ir.Constant(value=1),
        stop=ir.Constant(value=3),
        body=(inner, lin(8, -300)),
        span=span(3),
    )
    paths = paths_of(station, program(start(), lin(2, -300), loop))
    near = (lin(5, -300, 350), lin(8, -300))
    far = (lin(7, -300, 450), lin(8, -300))
    assert ends(paths) == pytest.approx(
        (
            straight(station, start(), lin(2, -300), *(near * 3)),
            straight(station, start(), lin(2, -300), *(far * 3)),
        ),
        rel=TOL,
    )
    assert described(paths) == (["IF at t.src:4 taken (x3)"], ["IF at t.src:4 not taken (x3)"])
    mixed = paths_of(station, program(start(), lin(2, -300), loop), "in1=true")
    assert mixed.decided and ends(mixed)[0] == pytest.approx(ends(paths)[0], rel=TOL)


def test_exit_leaves_a_loop_during_its_pass(station: Station) -> None:
    leave = ir.If(branches=(ir.Branch(condition=IN1, body=(ir.Exit(),)),), span=span(4))
    loop = ir.Loop(body=(lin(3, -300), leave, lin(5, -300, 400)), span=span(2))
    prog = program(start(), loop, lin(7, -200))
    paths = paths_of(station, prog)
    assert ends(paths) == pytest.approx(
        (
            straight(station, start(), lin(3, -300), lin(7, -200)),
            straight(station, start(), lin(3, -300), lin(5, -300, 400), lin(7, -200)),
        ),
        rel=TOL,
    )
    assert "LOOP at t.src:2 counted as 1 pass" in paths.notes[0]


def test_a_long_loop_is_added_up_not_walked(station: Station) -> None:
    def loop(count: int) -> ir.For:
        return ir.For(
            variable="i",
            start=ir.Constant(value=1),
            stop=ir.Constant(value=count),
            body=(lin(4, -300, 350), lin(5, -300)),
            span=span(3),
        )

    ten = ends(paths_of(station, program(start(), lin(2, -300), loop(10))))[0]
    eleven = ends(paths_of(station, program(start(), lin(2, -300), loop(11))))[0]
    began = time.perf_counter()
    many = ends(paths_of(station, program(start(), lin(2, -300), loop(1_000_000))))[0]
    assert time.perf_counter() - began < 30  # walked pass by pass, it would take hours
    assert many == pytest.approx(ten + (1_000_000 - 10) * (eleven - ten), rel=1e-9)


def test_a_program_that_jumps_gets_no_path_time(station: Station) -> None:
    prog = program(start(), ir.Label(name="top"), if_else(lin(3, -300), lin(5, -150)))
    assert paths_of(station, prog).shortest is not None
    jumping = program(
        start(),
        ir.Label(name="top"),
        if_else(lin(3, -300), lin(5, -150)),
        ir.Goto(label="top", span=span(6)),
    )
    paths = paths_of(station, jumping)
    assert paths.shortest is None and "GOTO at t.src:6" in paths.reason
    notes = [
        d.message for d in olp.compile(jumping, station).diagnostics if d.kind == "flow_timing"
    ]
    assert notes == [
        "the program has control flow (first: label at line 0): olp does not time the paths of "
        "a program that jumps (GOTO at t.src:6): its cycle time times every instruction once, "
        "in the order of the text"
    ]


def test_assumptions_that_name_nothing_are_usage_errors(station: Station) -> None:
    prog = program(start(), if_else(lin(3, -300), lin(5, -150)))
    for bad, words in (
        ("in4=true", "in4=...: no condition of the program reads it"),
        ("speed=2", "speed=...: no condition"),
        ("loop:9=2", "no loop of the program is on line 9"),
    ):
        with pytest.raises(UsageError, match=words.replace("(", r"\(").replace(".", r"\.")):
            paths_of(station, prog, bad)
    with pytest.raises(UsageError, match="no branches or loops"):
        paths_of(station, program(start(), lin(3, -300)), "in1=true")


def test_a_straight_program_has_no_paths(station: Station) -> None:
    compiled = olp.compile(program(start(), lin(2, -300)), station, collisions=None)
    assert compiled.paths is None and compiled.cycle_time > 0


def test_declarations_alone_leave_the_text_as_the_only_path(station: Station) -> None:
    declared = ir.Declare(name="n", type_name="INT", value=ir.Constant(value=1))
    prog = program(declared, start(), lin(2, -300))
    compiled = olp.compile(prog, station, collisions=None)
    assert prog.has_flow and compiled.paths is None
    assert compiled.cycle_time == straight(station, start(), lin(2, -300))
    assert "flow_timing" not in {d.kind for d in compiled.diagnostics}


def test_a_blend_into_a_block_is_timed_as_a_stop(station: Station) -> None:
    corner = ir.LinearMove(
        target=ir.CartesianTarget(pose=pose(-300)), zone=ir.Zone(0.02), span=span(2)
    )
    fine = ir.LinearMove(target=ir.CartesianTarget(pose=pose(-300)), span=span(2))
    inside = ir.If(branches=(ir.Branch(condition=IN1, body=(lin(4, -300, 400),)),), span=span(3))
    prog = program(start(), corner, inside, lin(6, -200, 400))
    text = olp.compile(prog, station, collisions=None).cycle_time  # blends into line 4
    taken = ends(paths_of(station, prog, "in1=true"))[0]
    stopped = straight(station, start(), fine, lin(4, -300, 400), lin(6, -200, 400))
    assert taken == pytest.approx(stopped, rel=TOL) and text < stopped - 0.01
    skipped = ends(paths_of(station, prog, "in1=false"))[0]
    assert skipped == pytest.approx(straight(station, start(), fine, lin(6, -200, 400)), rel=TOL)


def test_a_loop_left_in_its_first_pass_needs_no_count(station: Station) -> None:
    leave = ir.If(branches=(ir.Branch(condition=IN1, body=(ir.Exit(),)),), span=span(4))
    loop = ir.Loop(body=(lin(3, -300), leave, lin(5, -300, 400)), span=span(2))
    left = paths_of(station, program(start(), loop), "in1=true")
    assert left.decided and left.notes == ()
    assert ends(left)[0] == pytest.approx(straight(station, start(), lin(3, -300)), rel=TOL)


def test_a_toolpath_inside_a_branch_is_timed_from_each_start(station: Station) -> None:
    ys = np.linspace(-300, -200, 21)
    poses = np.stack([pose(y) for y in ys])
    zones = np.full(ys.size, 0.002)
    zones[-1] = 0.0
    toolpath = ir.LinearPath(
        poses=poses,
        speeds=np.full(ys.size, 0.1),
        zones=zones,
        lines=np.arange(ys.size) + 10,
    )
    branch = ir.If(
        branches=(ir.Branch(condition=IN1, body=(toolpath,)),),
        orelse=(lin(5, -350),),
        span=span(2),
    )
    prog = program(start(), branch, lin(7, -250, 350))
    paths = paths_of(station, prog, "in1=true")
    expected = straight(station, start(), toolpath, lin(7, -250, 350))
    assert paths.decided and ends(paths)[0] == pytest.approx(expected, rel=TOL)
    other = paths_of(station, prog, "in1=false")  # the move after the join from line 5
    expected = straight(station, start(), lin(5, -350), lin(7, -250, 350))
    assert ends(other)[0] == pytest.approx(expected, rel=TOL)
