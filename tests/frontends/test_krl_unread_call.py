"""A call of a routine olp did not read (another module's, an EXT one) may set the tool, base or
speeds and may move the robot. The motions after it that rely on those settings run with the
controller's (the KRL output writes none of olp's before them: it used to write its own, which
overrode what the routine set, with only a warning); the settings olp absorbed before the call
are written before it (the routine may move with them; they used to move after it); a _REL
motion after it is relative to where the routine left the robot; the next motion's path is not
checked. A user can vouch for routines that leave all that alone (``calls_keep_settings``)."""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir
from olp.errors import ParseError
from olp.frontends.bundled import KrlOptions

STATION = Path(__file__).resolve().parents[2] / "stations" / "kr6_milling_cell.yaml"

CELL = """DEF cell( )
EXT SetFrames(INT:IN, INT:IN)
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
$VEL.CP = 0.2
SetFrames(1, 2)
PTP {A1 10, A2 -90, A3 90, A4 0, A5 45, A6 0}
LIN {X 500, Y 0, Z 600, A 0, B 90, C 0}
LIN_REL {Z 50}
END
"""

SETTLED = """DEF cell( )
$BASE = BASE_DATA[1]
$TOOL = TOOL_DATA[1]
$VEL.CP = 0.2
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
Gripper(1)
$BASE = BASE_DATA[1]
$TOOL = TOOL_DATA[1]
$VEL.CP = 0.2
$ORI_TYPE = #VAR
BAS(#VEL_PTP, 50)
BAS(#ACC_PTP, 50)
LIN {X 500, Y 0, Z 400, A 0, B 90, C 0}
END
"""

OWN = """DEF cell( )
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
$VEL.CP = 0.2
Settle( )
LIN {X 500, Y 0, Z 600, A 0, B 90, C 0}
END
DEF Settle( )
WAIT SEC 0.2
END
"""


def _build(
    tmp_path: Path, text: str, post: str = "kuka", keeps: tuple[str, ...] = ()
) -> olp.BuildResult:
    source = tmp_path / "cell.src"
    source.write_text(text)
    options = KrlOptions(calls_keep_settings=keeps)
    station = olp.load_station(STATION)
    return olp.build(station, source, post=post, program_options=options, collisions=None)


def _written(result: olp.BuildResult) -> list[str]:
    return [line.strip() for line in result.files["cell.src"].splitlines()]


def test_the_motions_after_an_unread_routine_run_with_the_controller_settings(
    tmp_path: Path,
) -> None:
    result = _build(tmp_path, CELL)
    assert result.ok, [d.format() for d in result.diagnostics]
    moves = [n for n in result.compiled.program if isinstance(n, ir.RuntimeMove)]
    assert [(m.span.line, m.motion, m.controller_settings) for m in moves] == [
        (6, "joint", True),
        (7, "linear", True),
        (8, "linear", True),
    ]
    assert all("SetFrames at line 5" in m.reason for m in moves)
    assert moves[2].relative == "base"  # from where the routine left the robot
    lines = _written(result)
    call = lines.index("SetFrames(1, 2)")
    assert lines[call - 1] == "$VEL.CP = 0.2"  # the routine may move with it
    after = lines[call + 1 :]
    assert after[:3] == [
        "PTP {A1 10, A2 -90, A3 90, A4 0, A5 45, A6 0}",
        "LIN {X 500, Y 0, Z 600, A 0, B 90, C 0}",
        "LIN_REL {Z 50}",
    ]
    assert not any(line.startswith(("$BASE", "$TOOL", "$VEL")) for line in after)


def test_a_motion_that_sets_what_it_uses_is_modelled_but_its_start_is_unknown(
    tmp_path: Path,
) -> None:
    """Tool, base, speeds and orientation type set again after the call: a modelled motion
    (its target checked), whose start is where the routine left the robot, so its path is
    not."""
    result = _build(tmp_path, SETTLED)
    assert result.ok, [d.format() for d in result.diagnostics]
    assert [m.span.line for m in result.compiled.program.motions()] == [5, 13]
    (start,) = [d for d in result.diagnostics if d.kind == "unknown_start"]
    assert start.span is not None and start.span.line == 13
    assert "call of Gripper at line 6" in start.message


def test_a_vouched_routine_leaves_settings_and_position_alone(tmp_path: Path) -> None:
    result = _build(tmp_path, CELL.replace("LIN_REL {Z 50}\n", ""), keeps=("set*",))
    assert result.ok, [d.format() for d in result.diagnostics]
    assert [n for n in result.compiled.program if isinstance(n, ir.RuntimeMove)] == []
    assert [m.span.line for m in result.compiled.program.motions()] == [3, 6, 7]
    assert not [d for d in result.diagnostics if d.kind == "unknown_start"]


def test_another_language_refuses_what_the_controller_holds_and_says_how_to_vouch(
    tmp_path: Path,
) -> None:
    result = _build(tmp_path, CELL.replace("LIN_REL {Z 50}\n", ""), post="abb")
    refused = [d for d in result.diagnostics if d.severity == "error"]
    assert refused and all(d.kind == "runtime_target" for d in refused)
    assert "SetFrames at line 5" in refused[0].message
    assert refused[0].hint is not None and "--call-keeps-settings" in refused[0].hint


def test_a_call_of_the_modules_own_routine_holds_nothing(tmp_path: Path) -> None:
    result = _build(tmp_path, OWN)
    assert result.ok, [d.format() for d in result.diagnostics]
    assert [n for n in result.compiled.program if isinstance(n, ir.RuntimeMove)] == []
    assert not [d for d in result.diagnostics if d.kind == "unknown_start"]


def test_a_setting_in_a_block_before_an_unread_call_is_kept_in_its_path(tmp_path: Path) -> None:
    """``$VEL.CP`` set inside an IF with no motion in it, then a call of an unread routine:
    olp writes settings only before its motions, and the call runs with the controller's, so
    the setting is kept as written at the end of its path (it used to be a located error: the
    IF was lowered already when the call came)."""
    text = CELL.replace(
        "SetFrames(1, 2)\n", "IF $IN[1] THEN\n$VEL.CP = 0.1\nENDIF\nSetFrames(1, 2)\n"
    )
    result = _build(tmp_path, text)
    assert result.ok, [d.format() for d in result.diagnostics]
    lines = _written(result)
    call = lines.index("SetFrames(1, 2)")
    assert lines[call - 4 : call + 1] == [
        "$VEL.CP = 0.2",
        "IF $IN[1] THEN",
        "$VEL.CP = 0.1",
        "ENDIF",
        "SetFrames(1, 2)",
    ]


def test_a_setting_a_called_routine_ends_with_before_an_unread_call_is_an_error(
    tmp_path: Path,
) -> None:
    """A routine of the module that only sets ``$VEL.CP``, then a call of an unread routine:
    the routine's body is lowered already, so olp cannot keep the setting where the call needs
    it; a located error, not a silent drop."""
    text = CELL.replace("SetFrames(1, 2)\n", "Slow( )\nSetFrames(1, 2)\n")
    text += "DEF Slow( )\n$VEL.CP = 0.1\nEND\n"
    with pytest.raises(ParseError, match="no motion of which runs with them") as err:
        _build(tmp_path, text)
    assert err.value.span is not None and err.value.span.line == 12


APPROXIMATED = """DEF cell( )
EXT SetFrames(INT:IN, INT:IN)
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
SetFrames(1, 2)
PTP {A1 10, A2 -90, A3 90, A4 0, A5 45, A6 0} C_PTP C_DIS
LIN {X 500, Y 0, Z 600, A 0, B 90, C 0} c_dis
LIN {X 500, Y 0, Z 650, A 0, B 90, C 0}
END
"""


def test_a_motion_with_the_controllers_settings_keeps_its_approximation(tmp_path: Path) -> None:
    """The controller holds the approximation distances too, so the KRL output approximates
    where the source did (it used to write an exact stop, another path than the source's)."""
    src = tmp_path / "cell.src"
    src.write_text(APPROXIMATED)
    result = olp.build(olp.load_station(STATION), src, post="kuka", collisions=None)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    moves = [n for n in result.compiled.program.instructions if isinstance(n, ir.RuntimeMove)]
    assert [m.approximated for m in moves] == [("C_PTP", "C_DIS"), ("C_DIS",), ()]
    lines = result.files["cell.src"].splitlines()
    assert [line for line in lines if line.startswith(("PTP {A1 10", "LIN"))] == [
        "PTP {A1 10, A2 -90, A3 90, A4 0, A5 45, A6 0} C_PTP C_DIS",
        "LIN {X 500, Y 0, Z 600, A 0, B 90, C 0} C_DIS",
        "LIN {X 500, Y 0, Z 650, A 0, B 90, C 0}",
    ]


@pytest.mark.parametrize(
    ("fields", "problem"),
    [
        ({"approximated": ("C_DIS",)}, "controller_settings"),
        ({"approximated": ("C_DIS\nHALT",), "controller_settings": True}, "a word"),
    ],
)
def test_approximation_words_are_checked_when_made(fields: dict, problem: str) -> None:
    with pytest.raises(ir.IRError, match=problem):
        ir.RuntimeMove(motion="linear", target=ir.Name(name="xP1"), **fields)


@pytest.mark.parametrize(
    ("motion", "spline", "words", "written"),
    [
        ("joint", False, ("c_ptp", "C_DIS"), " C_PTP C_DIS"),
        ("linear", False, ("C_DIS",), " C_DIS"),
        ("linear", True, ("C_SPL",), " C_SPL"),
        ("linear", False, ("C_FAST",), None),
        ("linear", False, ("C_PTP",), None),  # a LIN has no C_PTP
        ("joint", False, ("C_PTP", "C_PTP"), None),
        ("linear", False, ("C_SPL",), None),  # C_SPL is a spline motion's
    ],
)
def test_the_krl_post_writes_only_the_approximation_krl_takes_for_the_motion(
    motion: str, spline: bool, words: tuple[str, ...], written: str | None
) -> None:
    from olp.errors import PostError
    from olp.posts.kuka_flow import krl_approximation

    move = ir.RuntimeMove(
        motion=motion,  # type: ignore[arg-type]
        target=ir.Name(name="xP1"),
        controller_settings=True,
        approximated=words,
        spline=spline,
    )
    if written is None:
        with pytest.raises(PostError, match="cannot write the approximation"):
            krl_approximation(move)
    else:
        assert krl_approximation(move) == written


def _distance_program(first_approximates: bool) -> str:
    """``BAS(#PTP_DAT)`` sets the axis speeds and the approximation distance; the PTP after it
    writes the speeds and, where it approximates, ``$APO.CDIS`` too (else the BAS's distance
    never reaches the controller: the BAS is absorbed)."""
    first = " C_DIS" if first_approximates else ""
    return f"""DEF cell(rSpeed:IN)
DECL REAL rSpeed
$TOOL = $NULLFRAME
$BASE = $NULLFRAME
$VEL.CP = 0.2
PDAT_ACT = {{VEL 100, ACC 100, APO_DIST 5}}
BAS(#PTP_DAT)
PTP {{A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}}
LIN {{X 500, Y 0, Z 600, A 0, B 90, C 0}}{first}
$VEL.CP = rSpeed
LIN {{X 500, Y 0, Z 650, A 0, B 90, C 0}} C_DIS
LIN {{X 500, Y 0, Z 700, A 0, B 90, C 0}}
END
"""


@pytest.mark.parametrize("first_approximates", [True, False])
def test_an_approximation_keeps_its_words_only_where_its_distance_is_on_the_controller(
    tmp_path: Path, first_approximates: bool
) -> None:
    """The LIN after a run-time ``$VEL.CP`` runs with the controller's settings and keeps its
    C_DIS where the output wrote the program's ``$APO.CDIS`` before (an approximated LIN did);
    where no motion wrote it and no statement that sets it can be kept any more, the controller
    would approximate with another distance, so the motion is an exact stop with a note."""
    src = tmp_path / "cell.src"
    src.write_text(_distance_program(first_approximates))
    result = olp.build(olp.load_station(STATION), src, post="kuka", collisions=None)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    (move, _) = [n for n in result.compiled.program.instructions if isinstance(n, ir.RuntimeMove)]
    assert move.approximated == (("C_DIS",) if first_approximates else ())
    noted = [d for d in result.diagnostics if "written as an exact stop" in d.message]
    assert len(noted) == (0 if first_approximates else 1)


def test_an_approximation_krl_does_not_take_is_a_located_error_after_an_unread_call(
    tmp_path: Path,
) -> None:
    """A motion with the controller's settings has its approximation checked like a modelled
    one's: a located error at its line, never a PostError without one when it is written."""
    text = APPROXIMATED.replace("} c_dis\n", "} C_PTP\n")
    with pytest.raises(ParseError, match="invalid approximation 'C_PTP'") as err:
        _build(tmp_path, text)
    assert err.value.span is not None and err.value.span.line == 6


def test_a_ptp_approximated_with_c_dis_written_twice_is_kept(tmp_path: Path) -> None:
    """``PTP x C_DIS C_DIS`` (the doubled keyword of the inline forms, as for a LIN) is read
    and written back as it stands."""
    text = APPROXIMATED.replace("} C_PTP C_DIS\n", "} C_DIS C_DIS\n")
    src = tmp_path / "cell.src"
    src.write_text(text)
    result = olp.build(olp.load_station(STATION), src, post="kuka", collisions=None)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    assert "PTP {A1 10, A2 -90, A3 90, A4 0, A5 45, A6 0} C_DIS C_DIS" in result.files["cell.src"]
