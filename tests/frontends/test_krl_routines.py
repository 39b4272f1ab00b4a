"""The KRL frontend keeps the module's own DEF/DEFFCT routines as routines of the IR (issue 15):
calls stay calls, parameters keep their direction and type, functions their result; checks see
every routine's body at each of its calls (``Program.expanded``)."""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir
from olp.errors import ParseError
from olp.frontends.krl import load_krl, parse_krl

REPO = Path(__file__).resolve().parents[2]
PALLETISE = REPO / "tests" / "routines" / "palletise.src"
FULL = "{X 100, Y -100, Z 100, A 0, B 90, C 0}"
SETUP = (
    "$VEL.CP = 0.2\n$APO.CDIS = 5\n$TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}\n"
    "$BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}\n"
)


@pytest.fixture(scope="module")
def palletise() -> ir.Program:
    return load_krl(PALLETISE).program


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def test_the_modules_routines_are_kept_with_their_calls(palletise: ir.Program) -> None:
    names = [r.name for r in palletise.routines]
    assert names == ["PickPart", "PlacePart", "Gripper", "PalletFull", "NextLayer", "CurtainStop"]
    calls = [n for n in palletise if isinstance(n, ir.RoutineCall)]
    assert [(c.name, c.span.line) for c in calls] == [
        ("Gripper", 21),
        ("PickPart", 22),
        ("PlacePart", 23),
        ("PickPart", 24),
        ("PlacePart", 25),
    ]
    place = calls[2]
    assert place.args == (
        ir.Name(name="nLayer", span=place.args[0].span),  # type: ignore[union-attr]
        ir.Name(name="nDone", span=place.args[1].span),  # type: ignore[union-attr]
    )
    assert not any(ir.is_motion(i) for i in palletise if i.span.line > 31)  # nothing inlined


def test_parameters_keep_their_direction_and_type(palletise: ir.Program) -> None:
    place = palletise.routine("placepart")
    assert place is not None
    params = [(p.name, p.type_name, p.direction, p.by_reference) for p in place.params]
    assert params == [("nLevel", "INT", "in", False), ("nCount", "INT", "out", True)]
    assert [d.name for d in place.declarations] == ["rHeight"]  # the parameters' DECL is theirs
    assert [n.kind for n in place.body][:2] == ["assign", "linear"]
    unmarked = parse_krl("DEF p( )\nDECL INT k\nbump(k)\nEND\nDEF bump(n)\nn = n + 1\nEND\n")
    (bump,) = unmarked.program.routines
    assert bump.params[0].direction == "out"  # KRL passes a parameter without :IN by reference


def test_functions_return_values_and_keep_global(palletise: ir.Program) -> None:
    full, layer = palletise.routine("PalletFull"), palletise.routine("NextLayer")
    assert full is not None and layer is not None
    assert (full.returns, full.exported, layer.returns, layer.exported) == (
        "BOOL",
        False,
        "INT",
        True,
    )
    block, last = full.body
    assert isinstance(block, ir.If) and isinstance(last, ir.Return)
    assert last.value == ir.Constant(value=False, span=last.value.span)  # type: ignore[union-attr]
    (back,) = layer.body
    assert isinstance(back, ir.Return) and isinstance(back.value, ir.BinaryOp)
    call = palletise.instructions[-3]  # bFull = PalletFull(nDone)
    assert isinstance(call, ir.Assign) and isinstance(call.value, ir.FunctionCall)


def test_an_interrupt_handler_is_a_routine(palletise: ir.Program) -> None:
    handler = palletise.routine("CurtainStop")
    assert handler is not None and not handler.params
    kinds = [n.kind for n in handler.body]
    assert kinds == ["verbatim", "set_output", "wait_input", "set_output", "verbatim"]
    (decl,) = [n for n in palletise if isinstance(n, ir.InterruptDecl)]
    assert decl.handler.name == "CurtainStop"


def test_checks_see_every_routine_body_at_each_call(palletise: ir.Program) -> None:
    """The analysis view holds the body at each call: PickPart's three LINs twice, and
    PlacePart's at both calls, in the order they run."""
    lines = [m.span.line for m in palletise.expanded().motions()]
    assert lines == [18, 34, 35, 37, 44, 45, 47, 34, 35, 37, 44, 45, 47, 30]
    assert len(list(palletise.motions())) == 2  # the program's own body: the two PTPs


def test_a_motion_in_a_routine_is_reported_at_every_call(station: object) -> None:
    far = "{X 100, Y -100, Z 900, A 0, B 90, C 0}"
    source = f"DEF p( )\n{SETUP}Reach()\nReach()\nEND\nDEF Reach( )\nLIN {far}\nEND\n"
    result = olp.compile(parse_krl(source).program, station, collisions=None)
    errors = [d for d in result.diagnostics if d.severity == "error"]
    assert [(d.span.line, d.index) for d in errors if d.span] == [(10, 0), (10, 1)]


def test_out_parameters_reach_the_callers_variable() -> None:
    """``bump(k)`` changes the caller's ``k``: the value after two calls is known (3) where
    the program uses it, and the parameter stays by reference."""
    text = "DEF p( )\nDECL INT k\nk = 1\nbump(k)\nbump(k)\nWAIT SEC k\nEND\n"
    result = parse_krl(text + "DEF bump(n :OUT)\nn = n + 1\nEND\n")
    (wait,) = [i for i in result.program if isinstance(i, ir.Wait)]
    assert wait.seconds == 3.0
    (bump,) = result.program.routines
    assert bump.params[0].by_reference


def test_a_parameter_that_only_numbers_an_output_keeps_the_routine() -> None:
    """``$OUT[7] = bOpen`` is a numbered output at each call (TRUE, then FALSE), but written
    once with the parameter it is one routine text: kept, the statement as written."""
    source = (
        "DEF p( )\nGripper(TRUE)\nGripper(FALSE)\nEND\n"
        "DEF Gripper(bOpen:IN)\nDECL BOOL bOpen\n$OUT[7] = bOpen\nEND\n"
    )
    result = parse_krl(source)
    (gripper,) = result.program.routines
    (kept,) = gripper.body
    assert isinstance(kept, ir.Verbatim) and kept.text == "$OUT[7] = bOpen"
    assert not result.ignored


def test_calls_that_move_to_other_points_are_written_out_with_a_warning() -> None:
    """``LIN pGoal`` goes to another point at each call: the IR holds one target per motion, so
    the routine is written out at each call and a warning names the line and both calls."""
    source = (
        f"DEF p( )\n{SETUP}Go({FULL})\nGo({{X 100, Y 100, Z 100, A 0, B 90, C 0}})\nEND\n"
        "DEF Go(pGoal:IN)\nDECL E6POS pGoal\nLIN pGoal\nEND\n"
    )
    result = parse_krl(source)
    assert not result.program.routines
    assert [m.span.line for m in result.program.motions()] == [11, 11]
    (warning,) = result.ignored
    assert warning.span.line == 9
    assert "line 11 differs between the calls at lines 6 and 7" in warning.reason


def test_the_same_point_at_every_call_keeps_the_routine() -> None:
    source = (
        f"DEF p( )\n{SETUP}Go({FULL})\nGo({FULL})\nEND\n"
        "DEF Go(pGoal:IN)\nDECL E6POS pGoal\nLIN pGoal\nEND\n"
    )
    result = parse_krl(source)
    (go,) = result.program.routines
    assert [m.span.line for m in result.program.expanded().motions()] == [11, 11]
    assert not result.ignored and go.params[0].type_name == "E6POS"


def test_recursion_is_a_located_error() -> None:
    source = "DEF p( )\nA()\nEND\nDEF A( )\nB()\nEND\nDEF B( )\nA()\nEND\n"
    with pytest.raises(ParseError, match="recursive call of A") as info:
        parse_krl(source)
    assert info.value.span is not None and info.value.span.line == 8
