"""A routine of a module that no call of the program runs (a library's: other modules or the PLC
call it) and that moves the robot is written, entered from a context olp does not know: every
motion setting held by the controller, the robot where olp does not know, the module's variables
known only where nothing assigns them. So a plain motion in it runs with the controller's
settings (KUKA writes it as written, other posts refuse it), and one whose settings the routine
sets itself (an inline form) is modelled: its target checked, its path from the unknown start
not. It used to be left out with a warning ("is never called and is not written")."""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir

STATION = Path(__file__).resolve().parents[2] / "stations" / "kr6_milling_cell.yaml"

MAIN = """DEF cell( )
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
END
"""

PUT_DOWN = """
DEF PutDown( )
;FOLD PTP P1 Vel=100 % PDAT1 Tool[1] Base[0];%{PE}
PDAT_ACT=PPDAT1
FDAT_ACT=FP1
BAS(#PTP_PARAMS,100)
PTP XP1
;ENDFOLD
LIN {X 500, Y 0, Z 600, A 0, B 90, C 0}
END
"""  # the PTP at line 10, the LIN at line 12

DAT = """DEFDAT cell
DECL E6POS XP1={{X {x},Y 100,Z 700,A 0,B 90,C 0,S 2,T 35,E1 0,E2 0,E3 0,E4 0,E5 0,E6 0}}
DECL FDAT FP1={{TOOL_NO 1,BASE_NO 0,IPO_FRAME #BASE,POINT2[] " "}}
DECL PDAT PPDAT1={{VEL 100,ACC 100,APO_DIST 100}}
ENDDAT
"""


def _build(
    tmp_path: Path, text: str, post: str = "kuka", x: float = 500, dat: str = DAT
) -> olp.BuildResult:
    source = tmp_path / "cell.src"
    source.write_text(text)
    (tmp_path / "cell.dat").write_text(dat.format(x=x))
    station = olp.load_station(STATION)
    return olp.build(station, source, post=post, collisions=None)


def _routine(result: olp.BuildResult, name: str) -> ir.Routine:
    return next(r for r in result.compiled.program.routines if r.name == name)


def test_an_uncalled_routine_that_moves_is_written_with_both_motions(tmp_path: Path) -> None:
    result = _build(tmp_path, MAIN + PUT_DOWN)
    assert result.ok, [d.format() for d in result.diagnostics]
    body = [
        n for n in _routine(result, "PutDown").body if ir.is_motion(n) or n.kind == "runtime_move"
    ]
    assert [(n.kind, n.span.line) for n in body] == [("joint", 10), ("runtime_move", 12)]
    lin = body[1]
    assert isinstance(lin, ir.RuntimeMove) and lin.controller_settings
    lines = [line.strip() for line in result.files["cell.src"].splitlines()]
    head, end = lines.index("DEF PutDown()"), len(lines) - 1 - lines[::-1].index("END")
    routine = lines[head:end]
    assert any(line.startswith("PTP {X 500.000,Y 100.000,Z 700.000") for line in routine)
    assert routine[-1] == "LIN {X 500, Y 0, Z 600, A 0, B 90, C 0}"  # as written, no settings
    (note,) = [d for d in result.diagnostics if d.kind == "krl_note" and d.span.line == 5]
    assert note.severity != "error" and "PutDown is never called" in note.message
    assert not [d for d in result.diagnostics if d.kind == "ignored"]


def test_its_modelled_target_is_checked_from_an_unknown_start(tmp_path: Path) -> None:
    result = _build(tmp_path, MAIN + PUT_DOWN)
    (start,) = [d for d in result.diagnostics if d.kind == "unknown_start"]
    assert start.span is not None and start.span.line == 10
    assert "unknown caller of PutDown" in start.message
    unreachable = _build(tmp_path, MAIN + PUT_DOWN, x=5000)
    errors = [d for d in unreachable.diagnostics if d.severity == "error"]
    assert errors and {d.span.line for d in errors if d.span is not None} == {10}
    assert unreachable.files == {}


def test_it_is_no_part_of_the_program_s_run(tmp_path: Path) -> None:
    """The program's cycle time and text are those without the routine: it is not called."""
    twice = PUT_DOWN.replace("PTP XP1\n", "PTP XP1\nPTP XP2\n")  # the second one is timed
    dat = DAT.replace(
        "ENDDAT", "DECL E6POS XP2={{X 500,Y 100,Z 650,A 0,B 90,C 0,S 2,T 35}}\nENDDAT"
    )
    alone = _build(tmp_path, MAIN)
    both = _build(tmp_path, MAIN + twice, dat=dat)
    assert alone.ok and both.ok, [d.format() for d in both.diagnostics]
    assert sum(s.duration for s in both.compiled.steps if s.instruction.span.line > 4) > 0
    assert both.compiled.paths is not None and both.compiled.paths.longest is not None
    assert both.compiled.paths.longest.seconds == alone.compiled.cycle_time
    main = both.files["cell.src"].split("END")[0]
    assert "PutDown" not in main


def test_rapid_refuses_the_motion_with_the_controller_s_settings(tmp_path: Path) -> None:
    result = _build(tmp_path, MAIN + PUT_DOWN, post="abb")
    refused = [
        d
        for d in result.diagnostics
        if d.severity == "error" and "controller's settings" in d.message
    ]
    assert [d.span.line for d in refused if d.span is not None] == [12]
    assert refused[0].hint


@pytest.mark.parametrize("change", ["XP1.Z = 650", "Measure(XP1)"])
def test_a_variable_the_module_changes_is_known_only_at_run_time_there(
    tmp_path: Path, change: str
) -> None:
    """The program assigns XP1, or gives it to a routine olp did not read (by reference):
    where an unknown caller enters PutDown, XP1 may hold that or anything another routine left,
    so the PTP to it is a run-time motion, not one checked with the data list's value."""
    main = MAIN.replace("END", f"{change}\nEND")
    result = _build(tmp_path, main + PUT_DOWN)
    assert result.ok, [d.format() for d in result.diagnostics]
    ptp = next(n for n in _routine(result, "PutDown").body if n.span.line == 11)
    assert isinstance(ptp, ir.RuntimeMove) and "XP1 is assigned in the module" in ptp.reason


def test_an_interrupt_routine_that_moves_relative_to_where_it_stops_is_written(
    tmp_path: Path,
) -> None:
    """An interrupt handler that brakes and backs off (``LIN_REL`` first: from where the
    interrupt stopped the robot) was left out ("no earlier Cartesian target")."""
    text = (
        "DEF cell( )\n"
        "INTERRUPT DECL 12 WHEN $IN[3] == TRUE DO BackOff( )\n"
        "INTERRUPT ON 12\n"
        "PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}\n"
        "INTERRUPT OFF 12\n"
        "END\n"
        "DEF BackOff( )\n"
        "BRAKE F\n"
        "LIN_REL {Z 20}\n"
        "RESUME\n"
        "END\n"
    )
    result = _build(tmp_path, text)
    assert result.ok, [d.format() for d in result.diagnostics]
    lines = [line.strip() for line in result.files["cell.src"].splitlines()]
    head = lines.index("DEF BackOff()")
    assert lines[head + 1 : head + 5] == ["BRAKE F", "LIN_REL {Z 20}", "RESUME", "END"]


def test_a_routine_each_call_runs_with_the_controller_s_settings_is_one_routine(
    tmp_path: Path,
) -> None:
    """Each call follows a call of a routine olp did not read: the plain LIN in Place runs
    with the controller's settings at both, for reasons that name another line; one text holds
    both (it was written out at each call with a warning)."""
    text = (
        "DEF cell( )\n"
        "EXT Pattern(INT:IN)\n"
        "PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}\n"
        "Pattern(1)\n"
        "Place( )\n"  # 5
        "Pattern(2)\n"
        "Place( )\n"  # 7
        "END\n"
        "DEF Place( )\n"
        "LIN {X 500, Y 0, Z 600, A 0, B 90, C 0}\n"  # 10
        "END\n"
    )
    result = _build(tmp_path, text)
    assert result.ok, [d.format() for d in result.diagnostics]
    assert not [d for d in result.diagnostics if d.kind == "ignored"]
    calls = [n for n in result.compiled.program.instructions if isinstance(n, ir.Expanded)]
    assert [c.span.line for c in calls] == [5, 7]
    (lin,) = _routine(result, "Place").body
    assert isinstance(lin, ir.RuntimeMove) and lin.controller_settings
    assert "at each of its calls (lines 5, 7)" in lin.reason
    lines = [line.strip() for line in result.files["cell.src"].splitlines()]
    assert lines.count("Place()") == 2 and lines.count("DEF Place()") == 1


SIGNALS = """DEF cell( )
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
END

GLOBAL DEF ResetPanel( )
bLamp = FALSE
bStart = FALSE
END
"""

SIGNALS_DAT = "DEFDAT cell\nSIGNAL bLamp $OUT[7]\nSIGNAL bStart $IN[3]\nENDDAT\n"


@pytest.mark.parametrize("post", ["kuka", "abb"])
def test_a_signal_the_module_switches_stays_a_signal_where_an_unknown_caller_enters(
    tmp_path: Path, post: str
) -> None:
    """A module's variables that it assigns are run-time values in a routine no call runs;
    a SIGNAL is no variable: ``bLamp = FALSE`` stays an output switched (every post writes
    it), ``bStart = FALSE`` an assignment to an input (KRL only, with a warning). A signal
    taken as a run-time variable made RAPID refuse an undeclared name."""
    src = tmp_path / "cell.src"
    src.write_text(SIGNALS)
    (tmp_path / "cell.dat").write_text(SIGNALS_DAT)
    result = olp.build(olp.load_station(STATION), src, post=post, collisions=None)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    (routine,) = result.compiled.program.routines
    kinds = [(n.kind, n.span.line) for n in routine.body if n.kind != "comment"]
    assert kinds == [("set_output", 6), ("verbatim", 7)]
