"""Values only the run knows, as real KR C4 programs use them (issue 15): motions to positions
computed from $POS_ACT, BAS with variables, PTP ... C_DIS, open array declarations. What olp
cannot know offline is kept (a motion to a run-time target as :class:`olp.ir.RuntimeMove`, a
statement as written) with a warning, never dropped and never guessed."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import olp
from olp import ir
from olp.errors import ParseError
from olp.frontends.bundled import KrlOptions
from olp.frontends.krl import KrlData, KrlResult, load_config_dat, parse_dat, parse_krl
from olp.ir_flow import leaves_and_blocks

REPO = Path(__file__).resolve().parents[2]
STATION = REPO / "stations" / "kr6_milling_cell.yaml"
BACKUP_CONFIG = REPO / "tests" / "corpus" / "krc" / "R1" / "System" / "$config.dat"
CONFIG = REPO / "examples" / "robot_config.dat"
HOME = "PTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}"
FRAMES = ("$BASE = BASE_DATA[1]", "$TOOL = TOOL_DATA[1]")
LIN = "LIN {X 500,Y 0,Z 400,A 0,B 90,C 0}"


@pytest.fixture(scope="module")
def config() -> KrlData:
    return load_config_dat(CONFIG)


def parse(config: KrlData, *body: str) -> KrlResult:
    return parse_krl("\n".join(["DEF t( )", *body, "END", ""]), "t.src", config=config)


def kept(result: KrlResult) -> list[ir.Verbatim]:
    return [n for n in leaves_and_blocks(result.program.instructions) if isinstance(n, ir.Verbatim)]


def runtime(result: KrlResult) -> list[ir.RuntimeMove]:
    nodes = leaves_and_blocks(result.program.instructions)
    return [n for n in nodes if isinstance(n, ir.RuntimeMove)]


OFFSET = (
    "DEF lift( )\nDECL E6POS above\nPTP XHOME\nabove = $POS_ACT\n"
    "above.Z = above.Z + 50\nPTP above\nPTP XHOME\nEND\n"
)


def test_a_motion_to_an_offset_of_the_current_position_is_a_run_time_motion(
    config: KrlData,
) -> None:
    """``p = $POS_ACT`` then ``p.Z = p.Z + 50`` and ``LIN p``: the target is where the robot
    happens to stand, plus 50 mm: a :class:`~olp.ir.RuntimeMove` to the expression ``above``
    with the settings in effect, and the motions after it are still lowered."""
    result = parse(
        config,
        "DECL E6POS above",
        *FRAMES,
        "$VEL.CP = 0.2",
        HOME,
        "LIN {X 500,Y 0,Z 400,A 0,B 90,C 0}",
        "above = $POS_ACT",
        "above.Z = above.Z + 50",
        "LIN above",
        HOME,
    )
    assert kept(result) == []
    (lin,) = runtime(result)
    assert (lin.span.line, lin.motion) == (10, "linear")
    assert lin.target == ir.Name(name="above", span=lin.target.span)
    assert "$POS_ACT" in lin.reason and lin.speed.linear == pytest.approx(0.2)
    assert lin.tool.name == "TOOL_DATA[1]" or lin.tool.number == 1
    assert [m.span.line for m in result.program.motions()] == [6, 7, 11]


@pytest.mark.parametrize(
    ("before", "check"),
    [
        ((HOME,), lambda m: m.speed.linear == pytest.approx(0.2)),
        (("LIN {X 500,Y 0,Z 400,A 0,B 90,C 0}", "$VEL.CP = 0.1"), lambda m: m.speed.linear == 0.1),
        (
            ("LIN {X 500,Y 0,Z 400,A 0,B 90,C 0}", "$BASE = BASE_DATA[2]"),
            lambda m: m.frame.number == 2,
        ),
        # another module's routine may set any setting: the controller's hold
        (("LIN {X 500,Y 0,Z 400,A 0,B 90,C 0}", "Foo()"), lambda m: m.controller_settings),
        (("IF $IN[1] THEN", "LIN {X 500,Y 0,Z 400,A 0,B 90,C 0}", "ENDIF"), lambda m: True),
    ],
)
def test_a_run_time_motion_runs_with_the_settings_in_effect_wherever_it_stands(
    config: KrlData, before: tuple[str, ...], check: Any
) -> None:
    """A run-time motion carries the tool, base, speed and approximation in effect, like any
    motion, so the posts write them before it: after another kind of motion, other settings,
    a call or a block it is lowered (before, olp stopped there, because it kept the line as
    written and the posts wrote settings only before the motions they modelled)."""
    here = ["p = $POS_ACT", "p.Z = p.Z + 10"]
    body = ["DECL E6POS p", *FRAMES, "$VEL.CP = 0.2", HOME, *before, *here, "LIN p"]
    (lin,) = runtime(parse(config, *body))
    assert lin.span.line == len(body) + 1 and check(lin)


@pytest.mark.parametrize(
    ("post", "refused"),
    [("kuka", None), ("abb", "RAPID"), ("ur", "URScript"), ("fanuc", "LS")],
)
def test_the_kuka_post_writes_a_run_time_motion_back_and_the_others_refuse_it(
    tmp_path: Path, post: str, refused: str | None
) -> None:
    path = tmp_path / "lift.src"
    path.write_text(OFFSET)
    station = olp.load_station(STATION)
    options = KrlOptions(config_dat=BACKUP_CONFIG)
    result = olp.build(station, path, post=post, program_options=options, collisions=None)
    errors = [d for d in result.diagnostics if d.severity == "error"]
    if refused is None:
        assert result.ok and not errors
        assert "PTP above" in result.files["lift.src"].splitlines()
    else:  # none of them can read where the robot stands ($POS_ACT, line 4)
        assert not result.ok and not result.files
        assert any(d.span is not None and d.span.line == 4 for d in errors)
        assert all(d.kind in ("flow", "runtime_target") for d in errors)


def test_a_name_declared_nowhere_is_still_an_error(config: KrlData) -> None:
    """A typing error is not a run-time value: ``LIN pUnknown`` names nothing when every file
    where the controller would find it was given (the module's .dat and ``$config.dat``)."""
    text = "\n".join(["DEF t( )", *FRAMES, HOME, "LIN pUnknown", "END", ""])
    with pytest.raises(ParseError, match="pUnknown"):
        parse_krl(text, "t.src", dat=parse_dat("DEFDAT t\nENDDAT\n", "t.dat"), config=config)


def test_a_local_position_never_given_a_value_is_still_an_error(config: KrlData) -> None:
    """KRL leaves a local E6POS without a value until it is assigned: moving to it stops the
    controller, so olp stops too instead of keeping it."""
    with pytest.raises(ParseError, match="without a value"):
        parse(config, "DECL E6POS p", *FRAMES, HOME, "PTP p")


def test_a_ptp_approximated_by_distance(config: KrlData) -> None:
    """``PTP ... C_DIS`` (KSS 8.2+ inline forms): the PTP zone is ``$APO.CDIS``, as for LIN."""
    result = parse(
        config,
        *FRAMES,
        HOME,
        "$APO.CDIS = 5",
        "PTP {A1 10,A2 -90,A3 90,A4 0,A5 30,A6 0} C_DIS",
        HOME,
    )
    first, second, _home = result.program.motions()
    assert second.span.line == 6
    assert second.zone is not None and second.zone.radius == pytest.approx(0.005)
    assert first.zone is not None and first.zone.radius == 0.0


def test_ptp_with_an_unknown_approximation_is_refused(config: KrlData) -> None:
    with pytest.raises(ParseError):
        parse(config, *FRAMES, HOME, "PTP {A1 10,A2 -90,A3 90,A4 0,A5 30,A6 0} C_VEL")


def test_bas_with_a_run_time_value_is_kept_and_the_next_motion_asks_for_settings(
    config: KrlData,
) -> None:
    """``BAS(#PTP_PARAMS, v)`` with ``v`` known only at run time: the call is kept as written;
    the motion right after it (``$BASE``/``$TOOL`` set in between, kept as written too) runs
    with the speeds it made, a run-time motion olp does not check; so does a second one that
    runs with them (before: an error)."""
    body = ("DECL REAL v", "v = $OV_PRO", "BAS(#PTP_PARAMS, v)")
    (bas,) = kept(parse(config, *body))
    assert bas.text == "BAS(#PTP_PARAMS, v)" and "run time" in bas.reason
    result = parse(config, *body, *FRAMES, HOME)
    assert [n.text for n in kept(result)] == ["BAS(#PTP_PARAMS, v)", *FRAMES]
    (home,) = [n for n in result.program if isinstance(n, ir.RuntimeMove)]
    assert home.controller_settings and home.span.line == 7
    moves = [n for n in parse(config, *body, *FRAMES, HOME, HOME).program]
    again = [n for n in moves if isinstance(n, ir.RuntimeMove)]
    assert [(m.span.line, m.controller_settings) for m in again] == [(7, True), (8, True)]
    assert "BAS(#PTP_PARAMS) at line 4" in again[1].reason


def _inline_data() -> KrlData:
    return parse_dat(
        "\n".join(
            [
                "DEFDAT t PUBLIC",
                "DECL E6AXIS XP1={A1 10,A2 -90,A3 90,A4 0,A5 30,A6 0}",
                'DECL FDAT FP1={TOOL_NO 1,BASE_NO 1,IPO_FRAME #BASE,POINT2[] " ",TQ_STATE FALSE}',
                "DECL PDAT PPDAT1={VEL 100.0,ACC 100.0,APO_DIST 100.0,APO_MODE #CDIS}",
                "ENDDAT",
                "",
            ]
        ),
        "t.dat",
    )


INLINE_PTP = ["PDAT_ACT = PPDAT1", "FDAT_ACT = FP1", "BAS(#PTP_PARAMS, 100)", "PTP XP1"]


def test_bas_with_a_run_time_value_then_an_inline_form_after_its_block(config: KrlData) -> None:
    """The next inline form (FDAT_ACT, PDAT_ACT, BAS with a constant) sets them all again; after
    the block that held the kept BAS, the output writes every setting of the next motion."""
    body = ["DECL REAL v", "v = $OV_PRO", "IF $IN[1] THEN", "BAS(#PTP_PARAMS, v)", "ENDIF"]
    text = "\n".join(["DEF t( )", *body, *INLINE_PTP, "END", ""])
    result = parse_krl(text, "t.src", dat=_inline_data(), config=config)
    assert [m.span.line for m in result.program.motions()] == [10]


def test_a_motion_in_the_same_stretch_as_a_kept_bas_is_refused(config: KrlData) -> None:
    """In the same straight stretch, the output would write only the settings that differ from
    the motion before, while the kept BAS changed them on the controller: an error."""
    body = ["DECL REAL v", "v = $OV_PRO", "BAS(#PTP_PARAMS, v)"]
    text = "\n".join(["DEF t( )", *body, *INLINE_PTP, "END", ""])
    with pytest.raises(ParseError, match=r"follows BAS\(#PTP_PARAMS, v\) \(line 4\)") as info:
        parse_krl(text, "t.src", dat=_inline_data(), config=config)
    assert info.value.span.line == 8


def test_an_array_declared_with_open_dimensions(config: KrlData) -> None:
    """``DECL INT n[,]``, as a routine declares an array parameter whose sizes the caller's
    array gives: it parses (the sizes are left out) and moves nothing."""
    result = parse(config, "DECL INT n[,]", *FRAMES, HOME)
    assert [m.span.line for m in result.program.motions()] == [5]


def test_held_measured_axes_are_no_motion(config: KrlData) -> None:
    """``a = $AXIS_ACT_MEAS`` then ``PTP a`` with nothing moving in between: where the robot
    already is, like ``$AXIS_ACT``."""
    result = parse(config, "DECL E6AXIS a", *FRAMES, HOME, "a = $AXIS_ACT_MEAS", "PTP a")
    (ptp,) = kept(result)
    assert ptp.span.line == 7 and "no motion" in ptp.reason


def test_a_constant_for_loop_over_run_time_positions_stays_one_loop(
    config: KrlData,
) -> None:
    """A constant FOR loop whose body holds a target that is the run's whatever the counter
    stays one loop (unrolling it would only repeat the run-time motion, 30,000 times in a
    real milling cell's program): the PTP is a run-time motion in the FOR's body."""
    result = parse(
        config,
        "DECL E6POS p",
        "DECL INT i",
        *FRAMES,
        HOME,
        "p = $POS_ACT",
        "FOR i = 1 TO 2",
        "  p.Z = p.Z + 10",
        "  PTP p",
        "ENDFOR",
        HOME,
    )
    ptps = runtime(result)
    assert [(n.span.line, n.motion) for n in ptps] == [(10, "joint")]
    (loop,) = [n for n in result.program.instructions if isinstance(n, ir.For)]
    assert ptps[0] in loop.body
    assert [m.span.line for m in result.program.motions()] == [6, 12]


def test_an_unrolled_pass_sets_the_counter_a_kept_statement_reads(config: KrlData) -> None:
    """A FOR loop olp unrolls (its targets depend on the counter) writes its passes one after
    the other without the FOR: a statement kept as written that reads the counter (``r[i] =
    $OV_PRO``, ``LIN xPath[i]`` to a run-time target) gets ``i = <pass>`` before it, so that
    the controller reads the value the loop would have given it."""
    data = parse_dat(
        "\n".join(
            [
                "DEFDAT t PUBLIC",
                "DECL E6AXIS corner[2]",
                "corner[1]={A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}",
                "corner[2]={A1 10,A2 -90,A3 90,A4 0,A5 30,A6 0}",
                "ENDDAT",
                "",
            ]
        ),
        "t.dat",
    )
    body = ["DECL INT i", "DECL REAL r[2]", *FRAMES, "FOR i = 1 TO 2"]
    loop = ["  r[i] = $OV_PRO", "  PTP corner[i]", "ENDFOR"]
    text = "\n".join(["DEF t( )", *body, *loop, "END", ""])
    result = parse_krl(text, "t.src", dat=data, config=config)
    flat = [n for n in result.program.instructions if n.kind != "declare"]
    assert [n.kind for n in flat] == ["assign", "assign", "joint"] * 2
    counts = [n for n in flat if isinstance(n, ir.Assign) and n.span.line == 6]
    assert [(n.target, n.value) for n in counts] == [
        (ir.Name(name="i", span=n.span), ir.Constant(value=k, span=n.span))
        for n, k in zip(counts, (1, 2), strict=True)
    ]


def test_an_unrolled_pass_that_does_not_read_the_counter_is_written_as_before(
    config: KrlData,
) -> None:
    data = parse_dat(
        "DEFDAT t PUBLIC\nDECL E6AXIS corner[2]\ncorner[1]={A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}\n"
        "corner[2]={A1 10,A2 -90,A3 90,A4 0,A5 30,A6 0}\nENDDAT\n",
        "t.dat",
    )
    text = "\n".join(["DEF t( )", "DECL INT i", *FRAMES, "FOR i = 1 TO 2", "  PTP corner[i]"])
    result = parse_krl(text + "\nENDFOR\nEND\n", "t.src", dat=data, config=config)
    assert [n.kind for n in result.program.instructions] == ["declare", "joint", "joint"]


SPLINE_FORM = (
    "SPTP XP1 WITH $VEL_AXIS[1] = SVEL_JOINT(100.0), $TOOL = STOOL2(FP1), "
    "$BASE = SBASE(FP1.BASE_NO), $ACC_AXIS[1] = SACC_JOINT(PPDAT1)"
)
"""A spline inline form: its WITH sets every setting a PTP runs with, for that motion."""


def test_a_spline_form_after_an_unread_call_sets_its_own_settings(config: KrlData) -> None:
    """After a call of a routine olp did not read, every setting is the controller's; a WITH
    that sets all a PTP uses makes it a modelled motion (its own WITH items are not ambiguous
    for it). The plain PTP after it still runs with the controller's settings (the WITH's
    values hold for that motion only)."""
    text = "\n".join(["DEF t( )", "Foo()", SPLINE_FORM, "PTP XP1", "END", ""])
    result = parse_krl(text, "t.src", dat=_inline_data(), config=config)
    assert [m.span.line for m in result.program.motions()] == [3]
    (after,) = [n for n in result.program if isinstance(n, ir.RuntimeMove)]
    assert after.span.line == 4 and after.controller_settings
