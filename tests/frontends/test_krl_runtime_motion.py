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


def test_a_rel_motion_by_run_time_offsets_stays_as_written(config: KrlData) -> None:
    """A _REL motion is relative to where the robot is: RuntimeMove holds absolute targets,
    so LIN_REL by run-time offsets is kept as written, as before."""
    body = ("DECL E6POS pOff", *SETUP, "LIN {X 500,Y 0,Z 400,A 0,B 90,C 0}", "pOff = $POS_ACT")
    result = lower(*body, "LIN_REL pOff", config=config)
    kept = [n for n in result.program if isinstance(n, ir.Verbatim)]
    assert [n.text for n in kept] == ["LIN_REL pOff"] and runtime(result) == []


def test_the_motion_right_after_a_run_time_bas_runs_with_the_controller_settings(
    config: KrlData,
) -> None:
    """BAS with a run-time value changes the settings behind the output's back: the motion
    right after it runs with them (a run-time motion with ``controller_settings``: nothing is
    written between the BAS and it); a second motion still relying on them is an error."""
    body = ("DECL REAL v", "DECL E6POS xPath[2]", "DECL INT i", *SETUP, "v = $OV_PRO")
    result = lower(*body, "i = $IN[1]", "BAS(#PTP_PARAMS, v)", "PTP xPath[i]", config=config)
    (ptp,) = runtime(result)
    assert ptp.controller_settings and "BAS(#PTP_PARAMS, v)" in ptp.reason
    with pytest.raises(ParseError, match=r"BAS\(#PTP_PARAMS\) at line 12 sets them"):
        lower(*body, "i = $IN[1]", "BAS(#PTP_PARAMS, v)", "PTP xPath[i]", HOME, config=config)


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
    assert "$config.dat" in home.reason and "BAS (#PTP_PARAMS,100 )" in home.reason
    kept = [n for n in result.program if isinstance(n, ir.Verbatim)]
    assert [n.text for n in kept] == ["BAS (#PTP_PARAMS,100 )", "$H_POS=XHOME"]
    assigned = [n for n in result.program if isinstance(n, ir.Assign)]
    assert [n.target for n in assigned] == [
        ir.Name(name="PDAT_ACT", span=assigned[0].target.span),
        ir.Name(name="FDAT_ACT", span=assigned[1].target.span),
    ]
    with pytest.raises(ParseError, match="cannot tell which motion settings"):
        lower(*PENDANT_HOME, HOME)


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
