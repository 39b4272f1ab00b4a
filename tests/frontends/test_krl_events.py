"""Interrupts and path triggers in the IR (issue 15): the KRL frontend lowers ``INTERRUPT
DECL``, ``INTERRUPT ON/OFF/ENABLE/DISABLE`` and ``TRIGGER WHEN DISTANCE/PATH`` to
:class:`olp.ir.InterruptDecl`, :class:`olp.ir.InterruptSwitch` and :class:`olp.ir.PathTrigger`
instead of dropping them."""

from __future__ import annotations

from pathlib import Path

import pytest

from olp import ir
from olp.frontends.krl import load_krl, parse_krl
from olp.frontends.krl.native import is_ini_line
from olp.ir_flow import leaves_and_blocks

REPO = Path(__file__).resolve().parents[2]
CORPUS = REPO / "tests" / "corpus" / "krc" / "R1"
CONFIG = CORPUS / "System" / "$config.dat"
FULL = "{X 20.0,Y -110.0,Z 300.0,A -90.0,B 0.0,C 180.0,S 2,T 2}"


def events(path: Path) -> list[ir.Node]:
    program = load_krl(path, CONFIG).program
    kinds = ("interrupt_decl", "interrupt", "trigger", "verbatim")
    nodes = leaves_and_blocks(program.instructions)
    return [n for n in nodes if n.kind in kinds and not is_ini_line(n)]  # (the source's INI)


def program_file(tmp_path: Path, *lines: str) -> Path:
    path = tmp_path / "p.src"
    path.write_text("DEF p( )\n" + "\n".join(lines) + "\nEND\n")
    return path


def test_the_corpus_program_lowers_every_interrupt_and_trigger() -> None:
    program = load_krl(CORPUS / "Program" / "trigger_dispense.src", CONFIG).program
    ini = [n for n in leaves_and_blocks(program.instructions) if is_ini_line(n)]
    assert [(n.text, n.span.line) for n in ini] == [  # its INI fold's, for the KRL post only
        ("GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )", 7),
        ("INTERRUPT ON 3", 8),
        ("BAS (#INITMOV,0 )", 9),
    ]
    found = events(CORPUS / "Program" / "trigger_dispense.src")
    assert [(n.kind, n.span.line) for n in found] == [
        ("interrupt_decl", 12),
        ("interrupt_decl", 14),
        ("interrupt", 19),
        ("interrupt", 20),
        ("trigger", 22),
        ("interrupt", 24),
        ("trigger", 25),
        ("trigger", 26),
        ("trigger", 28),
        ("interrupt", 30),
        ("interrupt", 31),
    ]
    pressure, valve = found[0], found[1]
    assert isinstance(pressure, ir.InterruptDecl) and isinstance(valve, ir.InterruptDecl)
    assert (pressure.priority, pressure.exported) == (12, True)
    assert pressure.condition == ir.BinaryOp(
        op="==",
        left=ir.DigitalInput(index=31, span=pressure.condition.left.span),  # type: ignore[union-attr]
        right=ir.Constant(value=False, span=pressure.condition.right.span),  # type: ignore[union-attr]
        span=pressure.condition.span,
    )
    assert pressure.handler.name == "PRESSURE_LOST"
    assert [a.value for a in pressure.handler.args] == [2, "STOP"]  # type: ignore[union-attr]
    assert (valve.priority, valve.exported, valve.handler.args) == (14, False, ())
    switches = [(n.action, n.priority) for n in found if isinstance(n, ir.InterruptSwitch)]
    assert switches == [("on", None), ("disable", 14), ("enable", 14), ("off", 12), ("off", None)]


def test_triggers_are_in_si_units_and_keep_their_reference_point() -> None:
    found = [n for n in events(CORPUS / "Program" / "trigger_dispense.src") if n.kind == "trigger"]
    opening, logging, onstart, closing = found
    assert (opening.at, opening.path, opening.delay) == ("start", None, pytest.approx(0.02))
    assert isinstance(opening.action, ir.Assign)
    assert (logging.at, logging.path, logging.delay) == (
        None,
        pytest.approx(-0.0155),
        pytest.approx(-0.04),
    )
    assert isinstance(logging.action, ir.FunctionCall) and logging.priority == -1
    assert (onstart.path, onstart.from_start) == (pytest.approx(0.005), True)
    assert (closing.at, closing.priority) == ("end", None)


def test_the_pendants_stop_message_interrupt_is_kept_for_the_krl_post(tmp_path: Path) -> None:
    """The pendant's stop-message interrupt 3 and its INTERRUPT ON are KUKA's own lines: kept
    as written for the KRL post alone, wherever they stand (the KUKA post writes no INI of its
    own for a KRL program); another interrupt 3 (other condition) is the program's own,
    modelled."""
    path = program_file(
        tmp_path,
        "GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )",
        "INTERRUPT ON 3",
        "INTERRUPT DECL 3 WHEN $IN[4] DO OWN_STOP()",
        "INTERRUPT ON 3",
    )
    found = events(path)
    assert [(n.kind, n.span.line) for n in found] == [("interrupt_decl", 4), ("interrupt", 5)]
    program = load_krl(path, CONFIG).program
    kept = [(n.span.line, n.native_only) for n in program if isinstance(n, ir.Verbatim)]
    assert kept == [(2, True), (3, True)]


@pytest.mark.parametrize(
    ("line", "why"),
    [
        ("TRIGGER WHEN DISTANCE=0 DELAY=nDelay DO $OUT[2]=TRUE", "DELAY"),
        ("TRIGGER WHEN DISTANCE=2 DELAY=0 DO $OUT[2]=TRUE", "DISTANCE is 0"),
        ("TRIGGER WHEN PATH=0 DELAY=0 DO $OUT[2]=TRUE PRIO=-1", "PRIO after an assignment"),
        ("INTERRUPT DECL nPrio WHEN $IN[2] DO STOP_IT()", "interrupt number"),
        ("INTERRUPT DECL 20 WHEN $IN[2] DO nCount=1", "subprogram call"),
    ],
)
def test_what_the_ir_cannot_hold_is_kept_verbatim(tmp_path: Path, line: str, why: str) -> None:
    path = program_file(tmp_path, "DECL INT nDelay", "DECL INT nPrio", "DECL INT nCount", line)
    (kept,) = events(path)
    assert isinstance(kept, ir.Verbatim) and kept.text == line and why in kept.reason


def test_a_trigger_makes_the_variable_it_sets_unknown(tmp_path: Path) -> None:
    """The action runs while the next motion moves: after the TRIGGER line olp no longer knows
    the variable's value (a motion reading it must not use the old one)."""
    path = program_file(
        tmp_path,
        "DECL REAL rZ",
        "rZ = 300.0",
        "TRIGGER WHEN DISTANCE=1 DELAY=0 DO rZ=200.0",
        f"LIN {FULL}",
        "LIN {X 20.0,Y -110.0,Z rZ,A -90.0,B 0.0,C 180.0,S 2,T 2}",
    )
    with pytest.raises(Exception, match="rZ"):
        load_krl(path, CONFIG)


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (
            lambda: ir.InterruptDecl(
                priority=0, condition=ir.Constant(value=True), handler=ir.FunctionCall(name="A")
            ),
            "priority",
        ),
        (lambda: ir.InterruptSwitch(action="toggle"), "action"),
        (lambda: ir.PathTrigger(action=ir.FunctionCall(name="A")), "exactly one"),
        (
            lambda: ir.PathTrigger(action=ir.FunctionCall(name="A"), at="start", path=0.1),
            "exactly one",
        ),
        (lambda: ir.PathTrigger(action=ir.FunctionCall(name="A"), path=float("nan")), "finite"),
        (
            lambda: ir.PathTrigger(action=ir.FunctionCall(name="A"), at="start", from_start=True),
            "from_start",
        ),
    ],
)
def test_event_nodes_refuse_values_they_cannot_hold(make: object, message: str) -> None:
    with pytest.raises(ir.FlowError, match=message):
        make()  # type: ignore[operator]


def test_a_handler_routine_of_the_module_is_kept_as_a_routine() -> None:
    """The handler is not called where the interrupt is declared; it does not move the robot,
    so it is a routine of the program (it was a warning naming it missing from the output)."""
    result = load_krl(CORPUS / "Program" / "interrupt_watch.src", CONFIG)
    assert not [i for i in result.ignored if "CURTAIN_STOP" in i.reason]
    (handler,) = result.program.routines
    assert (handler.name, handler.span.line) == ("CURTAIN_STOP", 24)
    kinds = [n.kind for n in handler.body]
    assert kinds == ["verbatim", "set_output", "wait_input", "set_output", "verbatim"]


def test_a_handler_that_moves_the_robot_is_written_from_an_unknown_caller() -> None:
    """Where a handler runs is unknown: it is lowered from the controller's settings (a plain
    PTP runs with them) and written, with a note (it was left out with a warning)."""
    source = (
        "DEF p( )\nINTERRUPT DECL 20 WHEN $IN[3] DO Away()\nINTERRUPT ON 20\nWAIT SEC 1\nEND\n"
        "DEF Away( )\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 0,A6 0}\nEND\n"
    )
    result = parse_krl(source)
    assert not [i for i in result.ignored if "Away" in i.reason]
    (away,) = result.program.routines
    (ptp,) = away.body
    assert isinstance(ptp, ir.RuntimeMove) and ptp.controller_settings
    (note,) = [n for n in result.notes if n.span.line == 6]
    assert "runs from the interrupt at line 2" in note.message


def test_interrupts_and_triggers_take_no_time() -> None:
    """Passes time the declarations and switches as instant and do not time a trigger's
    action: the cycle time never includes what an interrupt or a trigger runs."""
    import olp
    from olp.frontends.bundled import KrlOptions

    station = olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")
    result = olp.build(
        station,
        CORPUS / "Program" / "trigger_dispense.src",
        post="kuka",
        program_options=KrlOptions(config_dat=CONFIG),
        collisions=None,
    )
    kinds = ("interrupt_decl", "interrupt", "trigger")
    steps = [s for s in result.compiled.flat().steps if s.instruction.kind in kinds]
    assert len(steps) == 11 and all(s.duration == 0.0 for s in steps)
