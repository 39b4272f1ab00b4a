"""Motion settings set from values only the run knows (issue 15): ``$VEL.CP = rProbeSpeed``,
``$ACC.CP = acceleration`` (a parameter), ``$BASE = BASE_DATA[nBase]``. Such an assignment is
kept as written (another post refuses it) and holds its setting: a motion that runs with it
before the program sets it again runs with the controller's settings (the KUKA post writes it
as written and none of olp's settings before it; olp checks nothing of it). The speed's parts
are held one by one: setting ``$ACC.CP`` does not make olp know a run-time ``$VEL.CP``.

The programs have no .dat beside them: a name they do not declare is a value of the run."""

from __future__ import annotations

from pathlib import Path

import olp
from olp import ir
from olp.frontends.krl import KrlResult, parse_krl
from olp.ir_flow import leaves_and_blocks

STATION = Path(__file__).resolve().parents[2] / "stations" / "kr6_milling_cell.yaml"
HOME = "PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}"
LIN = "LIN {X 500, Y 0, Z 600, A 0, B 90, C 0}"
LIN2 = "LIN {X 500, Y 100, Z 600, A 0, B 90, C 0}"
INLINE_FORM = (  # the pendant's LIN fold, its records given inline
    "LDAT_ACT = {VEL 2, ACC 100, APO_DIST 100}",
    "FDAT_ACT = {TOOL_NO 0, BASE_NO 0, IPO_FRAME #BASE}",
    "BAS(#CP_PARAMS, 0.3)",
)


def parse(*body: str) -> KrlResult:
    return parse_krl("\n".join(["DEF t( )", *body, "END", ""]), "t.src")


def nodes(result: KrlResult) -> list[ir.Node]:
    return list(leaves_and_blocks(result.program.instructions))


def build(tmp_path: Path, *body: str, post: str = "kuka") -> olp.BuildResult:
    path = tmp_path / "cell.src"
    path.write_text("\n".join(["DEF cell( )", *body, "END", ""]))
    station = olp.load_station(STATION)
    return olp.build(station, path, post=post, collisions=None)


def written(result: olp.BuildResult) -> list[str]:
    return [line.strip() for line in result.files["cell.src"].splitlines()]


RUNTIME_SPEED = ("$VEL.CP = 0.2", HOME, LIN, "$VEL.CP = rProbeSpeed", LIN2)


def test_a_plain_lin_after_a_run_time_speed_runs_with_the_controller_settings(
    tmp_path: Path,
) -> None:
    result = build(tmp_path, *RUNTIME_SPEED)
    assert result.ok, [d.format() for d in result.diagnostics]
    last = list(result.compiled.program)[-1]
    assert isinstance(last, ir.RuntimeMove) and last.controller_settings
    assert "line 5" in last.reason and "rprobespeed" in last.reason.lower()
    lines = written(result)
    at = lines.index("$VEL.CP = rProbeSpeed")
    assert lines[at + 1].startswith("LIN {X 500")  # as it stood, nothing of olp's between
    assert "$VEL.CP = 0.20000" in lines[:at]  # the checked LIN's, before it


def test_another_post_refuses_the_run_time_speed_naming_its_line(tmp_path: Path) -> None:
    result = build(tmp_path, *RUNTIME_SPEED, post="abb")
    errors = [d for d in result.diagnostics if d.severity == "error"]
    assert not result.ok and not result.files
    assert any(d.span is not None and d.span.line == 5 for d in errors)


def test_setting_the_acceleration_leaves_a_run_time_path_speed_held() -> None:
    result = parse("$VEL.CP = rProbeSpeed", "$ACC.CP = 2.0", LIN)
    (move,) = [n for n in nodes(result) if isinstance(n, ir.RuntimeMove | ir.LinearMove)]
    assert isinstance(move, ir.RuntimeMove) and move.controller_settings


def test_setting_the_acceleration_after_an_unread_call_leaves_its_path_speed_held() -> None:
    """The defect the per-part hold fixes: any change of the speed used to end the hold of a
    call of a routine olp did not read, so olp wrote its own $VEL.CP over the routine's."""
    frames = ("$BASE = $NULLFRAME", "$TOOL = $NULLFRAME", "$ORI_TYPE = #VAR")
    result = parse("$VEL.CP = 0.2", HOME, "SetSpeeds( )", *frames, "$ACC.CP = 2.0", LIN)
    moves = [n for n in nodes(result) if isinstance(n, ir.RuntimeMove | ir.LinearMove)]
    assert len(moves) == 1 and isinstance(moves[0], ir.RuntimeMove)
    assert moves[0].controller_settings


def test_a_ptp_does_not_run_with_a_run_time_path_speed() -> None:
    result = parse("$VEL.CP = rProbeSpeed", HOME)
    assert [type(n) for n in nodes(result)] == [ir.Verbatim, ir.JointMove]


def test_an_inline_form_lin_after_a_run_time_speed_is_modelled_and_checked(
    tmp_path: Path,
) -> None:
    result = build(tmp_path, "$VEL.CP = rProbeSpeed", "$ACC.CP = 2.0", HOME, *INLINE_FORM, LIN)
    assert result.ok, [d.format() for d in result.diagnostics]
    move = list(result.compiled.program)[-1]
    assert isinstance(move, ir.LinearMove)
    assert (move.speed.linear, move.speed.linear_acceleration) == (0.3, 2.0)
    lines = written(result)
    at = lines.index("$VEL.CP = rProbeSpeed")
    speed = lines.index("$VEL.CP = 0.30000", at)  # written again after the kept line
    assert lines[speed + 1 : speed + 3] == ["$ACC.CP = 2.0000", lines[-2]]
    assert lines[-2].startswith("LIN {X 500.000,Y 0.000,Z 600.000")


def test_a_run_time_setting_on_one_path_is_held_after_the_join() -> None:
    result = parse(
        "$VEL.CP = 0.2", HOME, "IF $IN[1] THEN", "  $APO.CDIS = nBlend", "ENDIF", f"{LIN} C_DIS"
    )
    move = nodes(result)[-1]
    assert isinstance(move, ir.RuntimeMove) and move.controller_settings
    assert "$APO.CDIS is set at line 5" in move.reason
    exact = parse("$VEL.CP = 0.2", HOME, "IF $IN[1] THEN", "  $APO.CDIS = nBlend", "ENDIF", LIN)
    assert isinstance(nodes(exact)[-1], ir.LinearMove)  # an exact stop: no approximation


def test_axis_speeds_are_held_axis_by_axis() -> None:
    one = parse("$VEL_AXIS[2] = nPercent", "$VEL_AXIS[1] = 50", HOME)
    assert isinstance(nodes(one)[-1], ir.RuntimeMove)
    every = parse("$VEL_AXIS[2] = nPercent", "BAS(#VEL_PTP, 50)", "BAS(#ACC_PTP, 50)", HOME)
    assert isinstance(nodes(every)[-1], ir.JointMove)


def test_a_loop_setting_every_axis_from_a_run_time_value_stays_a_loop() -> None:
    result = parse("DECL INT i", "FOR i = 1 TO 6", "  $VEL_AXIS[i] = rScale * 100", "ENDFOR", HOME)
    loop = result.program.instructions[-2]
    assert isinstance(loop, ir.For) and isinstance(loop.body[0], ir.Verbatim)
    assert isinstance(result.program.instructions[-1], ir.RuntimeMove)


def test_a_base_from_a_run_time_number_is_kept_and_held() -> None:
    result = parse("$VEL.CP = 0.2", "$BASE = BASE_DATA[nBase]", LIN)
    speed, kept, move = nodes(result)  # (the speed olp absorbed, kept before the motion)
    assert isinstance(speed, ir.Verbatim) and speed.text == "$VEL.CP = 0.2"
    assert isinstance(kept, ir.Verbatim) and not kept.native_only
    assert kept.text == "$BASE = BASE_DATA[nBase]"
    assert isinstance(move, ir.RuntimeMove) and move.controller_settings


def test_a_routine_that_only_sets_run_time_speeds_is_written(tmp_path: Path) -> None:
    path = tmp_path / "speeds.src"
    path.write_text(
        "DEF speeds( )\nEND\n"
        "DEF set_cart_vel(velocity :IN)\nDECL REAL velocity\n$VEL.CP = velocity\nEND\n"
        "DEF set_cart_acc(acceleration :IN)\nDECL REAL acceleration\n"
        "$ACC.CP = acceleration\nEND\n"
    )
    result = olp.build(olp.load_station(STATION), path, post="kuka", collisions=None)
    assert result.ok, [d.format() for d in result.diagnostics]
    text = [line.strip() for line in result.files["speeds.src"].splitlines()]
    assert text.index("$VEL.CP = velocity") > text.index("DEF set_cart_vel(velocity:IN)")
    assert text.index("$ACC.CP = acceleration") > text.index("DEF set_cart_acc(acceleration:IN)")


def test_a_routine_called_only_from_one_olp_leaves_out_is_written_on_its_own(
    tmp_path: Path,
) -> None:
    """``broken`` calls ``set_v`` and is left out (with a warning): ``set_v`` was marked as
    called by that try and left out too, without a word."""
    path = tmp_path / "speeds.src"
    path.write_text(
        "DEF speeds( )\nEND\n"
        "DEF broken( )\nset_v(0.2)\nGOTO nowhere\nEND\n"
        "DEF set_v(v :IN)\nDECL REAL v\n$VEL.CP = v\nEND\n"
    )
    result = olp.build(olp.load_station(STATION), path, post="kuka", collisions=None)
    assert result.ok, [d.format() for d in result.diagnostics]
    text = [line.strip() for line in result.files["speeds.src"].splitlines()]
    assert text.index("$VEL.CP = v") > text.index("DEF set_v(v:IN)")
    assert any("DEF broken" in d.message for d in result.diagnostics)
