"""KRL motions whose target is known only at run time (issue "Real KUKA programs"): lowered to
:class:`olp.ir.RuntimeMove` with the expression and the settings in effect, never guessed."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from olp import ir
from olp.errors import ParseError
from olp.frontends.krl import KrlData, KrlResult, load_config_dat, parse_krl
from olp.ir_flow import leaves_and_blocks

REPO = Path(__file__).resolve().parents[2]
CONFIG = REPO / "examples" / "robot_config.dat"
HOME = "PTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}"
SETUP = ("$BASE = BASE_DATA[1]", "$TOOL = TOOL_DATA[1]", "$VEL.CP = 0.2", "$APO.CDIS = 5", HOME)
AGAIN = (
    "$BASE = BASE_DATA[1]",
    "$TOOL = TOOL_DATA[1]",
    "BAS (#VEL_PTP, 50)",
    "BAS (#ACC_PTP, 50)",
    "$APO.CDIS = 5",
    HOME,
)
"""Every setting a BAS #PTP_PARAMS sets, set again (as the next inline form does)."""


@pytest.fixture(scope="module")
def config() -> KrlData:
    return load_config_dat(CONFIG)


def lower(*body: str, config: KrlData | None = None, routines: str = "") -> KrlResult:
    text = "\n".join(["DEF t( )", *body, "END", routines])
    return parse_krl(text, "t.src", config=config)


def runtime(result: KrlResult) -> list[ir.RuntimeMove]:
    nodes = leaves_and_blocks(result.program.instructions)
    found = [n for n in nodes if isinstance(n, ir.RuntimeMove)]
    for routine in result.program.routines:
        found += [n for n in leaves_and_blocks(routine.body) if isinstance(n, ir.RuntimeMove)]
    return found


def test_a_path_element_indexed_by_a_run_time_value(config: KrlData) -> None:
    """``LIN xPath[i] C_DIS`` with ``i`` read from an input: the target is the expression
    ``xPath[i]``, the settings are those in effect (tool, base, speed, the $APO.CDIS zone)."""
    body = ("DECL E6POS xPath[3]", "DECL INT i", *SETUP, "i = $IN[3]", "LIN xPath[i] C_DIS")
    (lin,) = runtime(lower(*body, config=config))
    assert lin.motion == "linear" and lin.span.line == 10
    assert isinstance(lin.target, ir.Index) and lin.target.base == ir.Name(
        name="xPath", span=lin.target.base.span
    )
    assert lin.zone.radius == pytest.approx(0.005) and lin.speed.linear == pytest.approx(0.2)
    assert lin.tool.number == 1 and lin.frame.number == 1
    assert "'i' is not constant" in lin.reason


def test_a_function_result_and_a_routine_parameter(config: KrlData) -> None:
    """``PTP fnGetPos()`` (a function of the module) and ``LIN pTarget`` in a routine whose
    parameter the call gives a run-time value: both motions to run-time targets."""
    routines = (
        "DEFFCT E6POS fnGetPos( )\nDECL E6POS p\np = $POS_ACT\nRETURN p\nENDFCT\n"
        "DEF Place(pTarget:IN)\nDECL E6POS pTarget\nLIN pTarget\nEND\n"
    )
    body = ("DECL E6POS pNow", *SETUP, "PTP fnGetPos( )", "pNow = $POS_ACT", "Place(pNow)")
    moves = runtime(lower(*body, config=config, routines=routines))
    kinds = sorted((m.motion, type(m.target).__name__) for m in moves)
    assert ("joint", "FunctionCall") in kinds and ("linear", "Name") in kinds


def test_a_circ_to_run_time_points_keeps_both_and_its_arc_settings(config: KrlData) -> None:
    body = ("DECL E6POS xPath[3]", "DECL INT i", *SETUP, "i = $IN[2]", "CIRC xPath[i], xPath[3]")
    (arc,) = runtime(lower(*body, config=config))
    assert arc.motion == "circular" and arc.via is not None
    assert arc.orientation is ir.ArcOrientation.INTERPOLATE


def test_xhome_without_config_dat_names_the_missing_file_and_is_not_guessed() -> None:
    """Without ``$config.dat`` XHOME has no value olp may use: a motion to a run-time target,
    and the motion after it is still lowered; with ``$config.dat`` it is an axis target."""
    (home,) = runtime(lower("PTP XHOME", HOME))
    assert "XHOME is declared in the controller's $config.dat" in home.reason
    with_config = lower("PTP XHOME", HOME, config=load_config_dat(CONFIG))
    assert runtime(with_config) == []
    first = next(with_config.program.motions())
    assert isinstance(first.target, ir.JointTarget) and first.target.name == "XHOME"
    np.testing.assert_allclose(first.target.joints, np.radians([0, -90, 90, 0, 30, 0]))


def test_a_rel_motion_by_run_time_offsets_is_a_run_time_relative_motion(
    config: KrlData,
) -> None:
    """A _REL motion by run-time offsets is a run-time motion whose target refers to its start
    (``relative``: a base offset here), written back as ``LIN_REL pOff`` by the KRL post
    (before RuntimeMove had ``relative`` it was kept as written)."""
    body = ("DECL E6POS pOff", *SETUP, "LIN {X 500,Y 0,Z 400,A 0,B 90,C 0}", "pOff = $POS_ACT")
    result = lower(*body, "LIN_REL pOff", config=config)
    assert not [n for n in result.program if isinstance(n, ir.Verbatim)]
    (move,) = runtime(result)
    assert (move.motion, move.relative) == ("linear", "base")


def test_the_motions_after_a_run_time_bas_run_with_the_controller_settings(
    config: KrlData,
) -> None:
    """BAS with a run-time value changes the settings behind the output's back: the motions
    after it that rely on them run with them (run-time motions with ``controller_settings``:
    the output writes no setting of olp's before them), the second too (before: an error,
    the rule covered only the motion right after the BAS)."""
    body = ("DECL REAL v", "DECL E6POS xPath[2]", "DECL INT i", *SETUP, "v = $OV_PRO")
    result = lower(*body, "i = $IN[1]", "BAS(#PTP_PARAMS, v)", "PTP xPath[i]", config=config)
    (ptp,) = runtime(result)
    assert ptp.controller_settings and "BAS(#PTP_PARAMS) at line 12" in ptp.reason
    again = lower(*body, "i = $IN[1]", "BAS(#PTP_PARAMS, v)", "PTP xPath[i]", HOME, config=config)
    first, second = runtime(again)
    assert first.controller_settings and second.controller_settings
    assert second.span.line == 14 and "BAS(#PTP_PARAMS) at line 12" in second.reason
    assert not list(again.program.motions())[1:]  # only SETUP's HOME is modelled


PENDANT_HOME = (
    "PDAT_ACT=PDEFAULT",
    "FDAT_ACT=FHOME",
    "BAS (#PTP_PARAMS,100 )",
    "$H_POS=XHOME",
    "PTP  XHOME",
)
"""The pendant's PTP HOME inline form: BAS reads FHOME and PDEFAULT of ``$config.dat``."""


def test_the_pendant_home_without_config_dat_runs_with_the_controller_settings() -> None:
    """Without ``$config.dat`` the BAS's tool, base and speeds are the cell's: the BAS is kept
    as written (with the data assignments it reads), and ``PTP XHOME`` right after it is a
    run-time motion with the controller's settings (the KRL post writes none before it). A
    motion after it that sets its own settings is lowered as before; one that does not is
    still an error (its settings are the BAS's, unknown)."""
    result = lower(*PENDANT_HOME, *AGAIN)
    (home,) = runtime(result)
    assert home.controller_settings and home.motion == "joint" and home.span.line == 6
    assert "$config.dat" in home.reason and "BAS(#PTP_PARAMS) at line 4" in home.reason
    kept = [n for n in result.program if isinstance(n, ir.Verbatim)]
    assert [n.text for n in kept] == ["BAS (#PTP_PARAMS,100 )", "$H_POS=XHOME"]
    assigned = [n for n in result.program if isinstance(n, ir.Assign)]
    assert [n.target for n in assigned] == [
        ir.Name(name="PDAT_ACT", span=assigned[0].target.span),
        ir.Name(name="FDAT_ACT", span=assigned[1].target.span),
    ]
    (_, second) = runtime(lower(*PENDANT_HOME, HOME))  # (before: an error)
    assert second.controller_settings and "BAS(#PTP_PARAMS) at line 4" in second.reason


def test_with_config_dat_the_pendant_home_is_modelled() -> None:
    result = lower(*PENDANT_HOME, *AGAIN, config=load_config_dat(CONFIG))
    assert runtime(result) == [] and len(list(result.program.motions())) == 2


PDAT = "DECL PDAT pMine={VEL 100.0,ACC 35.0,APO_DIST 500.0,APO_MODE #CDIS,GEAR_JERK 100.0}"


def test_a_known_record_a_kept_bas_reads_is_written_before_it() -> None:
    """``PDAT_ACT = pMine`` (known: the module declares it) beside ``FDAT_ACT = FHOME`` (no
    ``$config.dat``): the BAS is kept as written and reads both records, so the known one's
    assignment, which olp absorbs into the motions elsewhere, is written before it (before: it
    was left out and the BAS read whatever PDAT_ACT the controller held)."""
    body = (PDAT, "PDAT_ACT=pMine", "FDAT_ACT=FHOME", "BAS (#PTP_PARAMS,100 )", "PTP  XHOME")
    result = lower(*body, *AGAIN)
    nodes = list(result.program)
    bas = next(i for i, n in enumerate(nodes) if isinstance(n, ir.Verbatim))
    before = [n.target for n in nodes[:bas] if isinstance(n, ir.Assign)]
    assert [t.name for t in before if isinstance(t, ir.Name)] == ["FDAT_ACT", "PDAT_ACT"]
    pdat = next(n for n in nodes[:bas] if isinstance(n, ir.Assign) and n.span.line == 3)
    assert pdat.value == ir.Name(name="pMine", span=pdat.value.span)


def test_a_known_record_set_member_by_member_before_a_kept_bas_is_an_error() -> None:
    body = (PDAT, "PDAT_ACT=pMine", "PDAT_ACT.VEL=50", "FDAT_ACT=FHOME")
    with pytest.raises(ParseError, match="this BAS reads PDAT_ACT, whose value olp knows"):
        lower(*body, "BAS (#PTP_PARAMS,100 )", "PTP  XHOME")


HOME_FOLD = (
    "$H_POS=XHOME",
    "PDAT_ACT=PDEFAULT",
    "BAS (#PTP_DAT )",
    "BAS (#VEL_PTP,80 )",
    "FDAT_ACT=FHOME",
    "BAS (#FRAMES )",
    "PTP  XHOME",
)
"""A HOME fold written as separate BAS commands (the form KSS writes too: PDAT, then the frames,
then the speed), a known one (``#VEL_PTP``) between two that read ``$config.dat``."""


def test_a_home_fold_of_several_bas_runs_with_the_controller_settings() -> None:
    """Without ``$config.dat`` both ``BAS (#PTP_DAT )`` and ``BAS (#FRAMES )`` are kept; the
    PTP after them runs with the controller's settings, and ``BAS (#VEL_PTP,80 )``, which olp
    would otherwise write only as ``$VEL_AXIS`` before a modelled motion, is kept where it
    stands (before: an error, the rule covered one BAS right before the motion)."""
    result = lower(*HOME_FOLD, *AGAIN)
    (home,) = runtime(result)
    assert home.controller_settings and home.span.line == 8
    texts = [
        n.text if isinstance(n, ir.Verbatim) else type(n).__name__
        for n in result.program
        if isinstance(n, ir.Verbatim | ir.Assign | ir.RuntimeMove)
    ]
    assert texts == [
        "$H_POS=XHOME",
        "Assign",
        "BAS (#PTP_DAT )",
        "BAS (#VEL_PTP,80 )",
        "Assign",
        "BAS (#FRAMES )",
        "RuntimeMove",
    ]
    after = runtime(lower(*HOME_FOLD, "PTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0} C_PTP"))
    assert [m.controller_settings for m in after] == [True, True]
    assert "BAS(#FRAMES) at line 7" in after[1].reason


CP_FORM = (
    "DECL LDAT LCPDAT4={VEL 2.0,ACC 100.0,APO_DIST 20.0,APO_FAC 50.0,ORI_TYP #VAR}",
    "DECL FDAT FPick={TOOL_NO 1,BASE_NO 1,IPO_FRAME #BASE}",
    "DECL E6POS XPick={X 480,Y 20,Z 350,A 0,B 90,C 0,S 6,T 27}",
)
LIN_FORM = ("LDAT_ACT=LCPDAT4", "FDAT_ACT=FPick", "BAS(#CP_PARAMS,0.5)", "LIN XPick C_DIS C_DIS")
"""A LIN inline form whose data the module declares: it sets every setting a LIN uses."""


def test_a_lin_form_after_the_home_fold_sets_all_it_uses_and_is_modelled() -> None:
    """After the HOME fold the axis speeds and accelerations stay the run-time BAS's; a LIN
    does not run with them (``$VEL_AXIS``/``$ACC_AXIS`` are PTP settings), and its inline form
    set its tool, base, path speed and distance: an ordinary linear move (before: an error
    naming ``BAS(#PTP_PARAMS)``). A PTP after it still runs with the unknown axis speeds: the
    controller's."""
    result = lower(*CP_FORM, *PENDANT_HOME, *LIN_FORM)
    (lin,) = [m for m in result.program.motions() if isinstance(m, ir.LinearMove)]
    assert lin.speed.linear == pytest.approx(0.5) and lin.zone.radius == pytest.approx(0.02)
    assert lin.tool.number == 1 and lin.frame.number == 1
    ptp = runtime(lower(*CP_FORM, *PENDANT_HOME, *LIN_FORM, "PTP XPick"))[-1]
    assert ptp.controller_settings and ptp.span.line == 14
    assert "BAS(#PTP_PARAMS) at line 7" in ptp.reason


def test_a_lin_after_the_home_fold_that_sets_nothing_runs_with_the_controller_settings() -> None:
    *_, lin = runtime(lower(*CP_FORM, *PENDANT_HOME, "LIN XPick C_DIS"))
    assert lin.motion == "linear" and lin.controller_settings and lin.zone == ir.FINE
    assert "BAS(#PTP_PARAMS) at line 7" in lin.reason


@pytest.mark.parametrize(
    ("motion", "relative"),
    [
        ("LIN_REL {Z 50}", "base"),
        ("LIN_REL {Z 50} #BASE", "base"),
        ("LIN_REL {X -10,C 5} #TOOL", "tool"),
        ("PTP_REL {A6 15}", "axes"),
        ("LIN {Z 400} C_DIS", "start"),
        ("PTP {Z 400,A 10}", "start"),
    ],
)
def test_a_motion_relative_to_a_run_time_start_is_a_run_time_motion(
    config: KrlData, motion: str, relative: str
) -> None:
    """The start of a _REL motion, or of a target that leaves components out, is where the
    motion to a run-time target before it ends: its target is known only at run time too, a
    :class:`~olp.ir.RuntimeMove` saying how it refers to the start (before: an error that olp
    cannot know the start). The motion after it starts unknown in turn."""
    body = ("DECL E6POS xPath[3]", "DECL INT i", *SETUP, "i = $IN[3]", "LIN xPath[i]")
    result = lower(*body, motion, "LIN_REL {Z -50}", config=config)
    first, rel, again = runtime(result)
    assert first.relative is None and rel.relative == relative and again.relative == "base"
    assert isinstance(rel.target, ir.Aggregate) and rel.span.line == 11
    assert "relative to the start position" in rel.reason or "leaves out" in rel.reason
    assert "the LIN at line 10 goes to a run-time target" in rel.reason


def test_a_relative_motion_whose_start_is_unknown_for_another_reason_is_still_an_error() -> None:
    with pytest.raises(ParseError, match="there is no earlier Cartesian target"):
        lower("LIN_REL {Z 50}")
    with pytest.raises(ParseError, match="the motion at line 2 went to axis values"):
        lower(HOME, "LIN {Z 400}")


def test_a_known_record_between_two_kept_bas_is_written_once() -> None:
    """``FDAT_ACT=FPick`` (known) after ``BAS (#PTP_DAT )`` (run-time PDEFAULT) is written
    before the kept ``BAS (#PTP_PARAMS,100 )`` that reads it; the motion after them, which
    keeps the statements absorbed since the first BAS, does not write it a second time."""
    body = (*CP_FORM, "PDAT_ACT=PDEFAULT", "BAS (#PTP_DAT )", "FDAT_ACT=FPick")
    result = lower(*body, "BAS (#PTP_PARAMS,100 )", "PTP  XHOME")
    (home,) = runtime(result)
    assert home.controller_settings
    lines = [n.span.line for n in result.program if isinstance(n, ir.Assign | ir.Verbatim)]
    assert lines == sorted(set(lines)) and 7 in lines
