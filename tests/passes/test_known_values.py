"""Path timing follows the program's own assignments (olp.passes.timing.known).

Each expected time is the cycle time of the straight program the assignments select, written
out by hand; each rule that makes a value unknown is shown by a program where following the
assignment anyway would give a different (wrong) path.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir
from olp.passes.pipeline import BuildOptions
from olp.passes.timing.branches import PathTimes
from olp.passes.timing.conditions import parse_assumptions
from olp.station.model import Station
from tests.passes.flow_programs import lin, program, span, start

REPO = Path(__file__).resolve().parents[2]
IN1 = ir.DigitalInput(index=1)
TOL = 1e-4  # as in test_branches.py
BODY_LINES = (4, 5)


BODY = (lin(4, -300, 350), lin(5, -300))


def name(text: str) -> ir.Name:
    return ir.Name(name=text)


def const(value: bool | int | float) -> ir.Constant:
    return ir.Constant(value=value)


def assign(target: str, value: ir.Expr) -> ir.Assign:
    return ir.Assign(target=name(target), value=value, span=span(2))


def declare(var: str, type_name: str = "INT", exported: bool = False) -> ir.Declare:
    return ir.Declare(name=var, type_name=type_name, exported=exported)


def for_to(stop: ir.Expr, body: tuple[ir.Node, ...] = BODY) -> ir.For:
    return ir.For(variable="i", start=const(1), stop=stop, body=body, span=span(3))


@pytest.fixture(scope="module")
def station() -> Station:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


@pytest.fixture(scope="module")
def passes(station: Station) -> dict[int, float]:
    """Cycle time of the straight program with the body 0..5 times."""
    out = {}
    for k in range(6):
        compiled = olp.compile(
            program(start(), lin(2, -300), *(BODY * k)), station, collisions=None
        )
        assert compiled.ok
        out[k] = compiled.cycle_time
    return out


def paths_of(station: Station, prog: ir.Program, *assume: str) -> PathTimes:
    options = BuildOptions(collisions=None, assume=parse_assumptions(assume))
    compiled = olp.compile(prog, station, options)
    assert compiled.ok, [d.format() for d in compiled.diagnostics]
    assert compiled.paths is not None
    return compiled.paths


def one(paths: PathTimes) -> float:
    assert paths.decided and paths.shortest is not None
    return paths.shortest.seconds


def by_rule(paths: PathTimes) -> bool:
    return any("counted as 1 pass" in n for n in paths.notes)


def test_an_assigned_count_runs_its_passes(station: Station, passes: dict[int, float]) -> None:
    prog = program(declare("n"), start(), lin(2, -300), assign("n", const(3)), for_to(name("N")))
    assert one(paths_of(station, prog)) == pytest.approx(passes[3], rel=TOL)
    # Arithmetic over known values folds too.
    twice = assign("m", ir.BinaryOp(op="*", left=name("n"), right=const(2)))
    prog = program(
        declare("n"),
        declare("m"),
        start(),
        lin(2, -300),
        assign("n", const(2)),
        twice,
        for_to(name("m")),
    )
    assert one(paths_of(station, prog)) == pytest.approx(passes[4], rel=TOL)


def test_a_value_known_after_a_branch_only_where_the_arms_agree(
    station: Station, passes: dict[int, float]
) -> None:
    def arms(a: int, b: int) -> ir.If:
        return ir.If(
            branches=(ir.Branch(condition=IN1, body=(assign("n", const(a)),)),),
            orelse=(assign("n", const(b)),),
            span=span(2),
        )

    agree = program(declare("n"), start(), lin(2, -300), arms(2, 2), for_to(name("n")))
    both = paths_of(station, agree)  # the IF stays an open choice; either way two passes
    assert both.shortest is not None and both.longest is not None and not by_rule(both)
    assert both.shortest.seconds == pytest.approx(passes[2], rel=TOL)
    assert both.longest.seconds == pytest.approx(passes[2], rel=TOL)
    differ = paths_of(
        station, program(declare("n"), start(), lin(2, -300), arms(2, 4), for_to(name("n")))
    )
    assert by_rule(differ)  # 2 or 4: unknown, not the last arm's 4
    # An input named by --assume picks the arm, and its value follows.
    picked = program(declare("n"), start(), lin(2, -300), arms(2, 4), for_to(name("n")))
    assert one(paths_of(station, picked, "in1=false")) == pytest.approx(passes[4], rel=TOL)


def test_a_counter_loop_runs_its_count(station: Station, passes: dict[int, float]) -> None:
    step = assign("i", ir.BinaryOp(op="+", left=name("i"), right=const(1)))
    below = ir.BinaryOp(op="<", left=name("i"), right=const(3))
    loop = ir.While(condition=below, body=(*BODY, step), span=span(3))
    prog = program(declare("i"), start(), lin(2, -300), assign("i", const(0)), loop)
    assert one(paths_of(station, prog)) == pytest.approx(passes[3], rel=TOL)
    done = ir.BinaryOp(op=">=", left=name("i"), right=const(2))
    repeat = ir.Repeat(body=(*BODY, step), until=done, span=span(3))
    prog = program(declare("i"), start(), lin(2, -300), assign("i", const(0)), repeat)
    assert one(paths_of(station, prog)) == pytest.approx(passes[2], rel=TOL)
    # The counter also changed inside a nested block: not a counter, one pass by rule.
    extra = ir.If(branches=(ir.Branch(condition=IN1, body=(step,)),), span=span(6))
    nested = ir.While(condition=below, body=(*BODY, step, extra), span=span(3))
    paths = paths_of(
        station, program(declare("i"), start(), lin(2, -300), assign("i", const(0)), nested)
    )
    assert by_rule(paths)


def test_a_loop_forgets_what_its_body_assigns(station: Station, passes: dict[int, float]) -> None:
    grow = assign("n", ir.BinaryOp(op="+", left=name("n"), right=const(1)))
    loop = ir.While(condition=IN1, body=(grow,), span=span(6))
    prog = program(
        declare("n"), start(), lin(2, -300), assign("n", const(2)), loop, for_to(name("n"))
    )
    assert by_rule(paths_of(station, prog))  # 2 + any number of passes


def test_calls_forget_what_they_may_change(station: Station, passes: dict[int, float]) -> None:
    call = ir.Call(name="ReadRecipe", span=span(2))
    # A local variable survives a call that is not given it ...
    local = program(
        declare("n"), start(), lin(2, -300), assign("n", const(3)), call, for_to(name("n"))
    )
    assert one(paths_of(station, local)) == pytest.approx(passes[3], rel=TOL)
    # ... but not one passed to it (an OUT parameter), nor an exported or undeclared one.
    given = ir.Call(name="ReadRecipe", args=("n",), span=span(2))
    for prog in (
        program(
            declare("n"), start(), lin(2, -300), assign("n", const(3)), given, for_to(name("n"))
        ),
        program(
            declare("n", exported=True),
            start(),
            lin(2, -300),
            assign("n", const(3)),
            call,
            for_to(name("n")),
        ),
        program(start(), lin(2, -300), assign("n", const(3)), call, for_to(name("n"))),
    ):
        assert by_rule(paths_of(station, prog))
    # A verbatim statement may change anything, a local variable too.
    verbatim = ir.Verbatim(text="n = n + 1", language="krl", span=span(2))
    prog = program(
        declare("n"), start(), lin(2, -300), assign("n", const(3)), verbatim, for_to(name("n"))
    )
    assert by_rule(paths_of(station, prog))


def test_values_fit_the_declared_type(station: Station, passes: dict[int, float]) -> None:
    # KRL rounds a REAL assigned to an INT; olp does not guess how: unknown.
    prog = program(declare("n"), start(), lin(2, -300), assign("n", const(2.5)), for_to(name("n")))
    assert by_rule(paths_of(station, prog))
    whole = program(declare("n"), start(), lin(2, -300), assign("n", const(2.0)), for_to(name("n")))
    assert one(paths_of(station, whole)) == pytest.approx(passes[2], rel=TOL)


def test_an_assumption_wins_over_an_assignment(station: Station, passes: dict[int, float]) -> None:
    prog = program(declare("n"), start(), lin(2, -300), assign("n", const(3)), for_to(name("n")))
    assert one(paths_of(station, prog, "n=1")) == pytest.approx(passes[1], rel=TOL)


def test_an_interrupt_stops_the_following(station: Station, passes: dict[int, float]) -> None:
    handler = ir.FunctionCall(name="OnStop")
    interrupt = ir.InterruptDecl(priority=3, condition=IN1, handler=handler, span=span(2))
    prog = program(
        declare("n"), interrupt, start(), lin(2, -300), assign("n", const(3)), for_to(name("n"))
    )
    assert by_rule(paths_of(station, prog))


def test_system_variables_are_never_learned(station: Station) -> None:
    prog = program(
        start(), lin(2, -300), assign("$tmp_count", const(3)), for_to(name("$tmp_count"))
    )
    assert by_rule(paths_of(station, prog))


def test_a_global_value_is_not_fixed_by_its_declaration(
    station: Station, passes: dict[int, float]
) -> None:
    def declared(**flags: bool) -> ir.Declare:
        return ir.Declare(name="n", type_name="INT", value=const(2), **flags)

    own = program(declared(), start(), lin(2, -300), for_to(name("n")))
    assert one(paths_of(station, own)) == pytest.approx(passes[2], rel=TOL)
    # GLOBAL: another module may assign it between runs, so its declared value is not known.
    shared = program(declared(exported=True), start(), lin(2, -300), for_to(name("n")))
    assert by_rule(paths_of(station, shared))
    constant = program(
        declared(exported=True, constant=True), start(), lin(2, -300), for_to(name("n"))
    )
    assert one(paths_of(station, constant)) == pytest.approx(passes[2], rel=TOL)
