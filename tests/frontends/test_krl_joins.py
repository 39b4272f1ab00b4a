"""Motions after a join whose paths set a motion setting differently (issue 15).

Each CASE of a SWITCH sets its own ``$TOOL`` and ``$BASE``; a LOOP's body moves, then sets the
tool for the next pass. The programs are valid: the controller runs the motion after the join
with whichever value the path that ran set. olp keeps each path's statement as written where
it stands (the output writes settings only before the motions that use them) and the motion
runs with the controller's settings: the KRL output writes none of olp's before it, other
posts refuse it. Where every path agrees, the motion stays modelled and checked.

The programs are olp's own, in the style of the KR C4 programs where the stops were found.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir
from olp.errors import ParseError
from olp.frontends.krl import parse_krl
from olp.ir_flow import leaves

STATION = Path(__file__).resolve().parents[2] / "stations" / "kr6_milling_cell.yaml"

TOOLS = """DEF tools( )
DECL INT nCommand
$VEL.CP = 0.2
$TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}
$BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
LIN {X 100, Y -100, Z 150, A 0, B 90, C 0}
SWITCH nCommand
  CASE 1
    $TOOL = {X 0, Y 0, Z 150, A 0, B 0, C 0}
    $BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}
  CASE 2
    $TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}
    $BASE = {X 500, Y 100, Z 300, A 0, B 0, C 0}
  DEFAULT
ENDSWITCH
LIN {X 100, Y -100, Z 100, A 0, B 90, C 0}
END
"""

SAME_TOOL = """DEF tools( )
DECL FRAME tGrip
tGrip = {X 0, Y 0, Z 150, A 0, B 0, C 0}
$VEL.CP = 0.2
$BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
SWITCH nCommand
  CASE 1
    $TOOL = tGrip
  CASE 2
    $TOOL = tGrip
    WAIT SEC 1
  DEFAULT
    $TOOL = tGrip
ENDSWITCH
LIN {X 100, Y -100, Z 100, A 0, B 90, C 0}
END
"""

FIRST_LIN = "LIN {X 100, Y -100, Z 150, A 0, B 90, C 0}\n"
"""The motion before the loop (after which the output has written ``$VEL.CP``)."""

PALLET = """DEF pallet( )
$VEL.CP = 0.2
$TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}
$BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
LIN {X 100, Y -100, Z 150, A 0, B 90, C 0}
LOOP
  LIN {X 100, Y -100, Z 100, A 0, B 90, C 0}
  $TOOL = {X 0, Y 0, Z 150, A 0, B 0, C 0}
  $BASE = {X 600, Y 0, Z 300, A 0, B 0, C 0}
ENDLOOP
END
"""


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(STATION)


def _build(station: object, folder: Path, text: str, post: str = "kuka") -> olp.BuildResult:
    path = folder / "cell.src"
    path.write_text(text)
    return olp.build(station, path, post=post, collisions=None)  # type: ignore[arg-type]


def _lines(result: olp.BuildResult) -> list[str]:
    errors = [d.format() for d in result.diagnostics if d.severity == "error"]
    assert not errors, errors
    (text,) = [t for name, t in result.files.items() if name.endswith(".src")]
    return [line.strip() for line in text.splitlines()]


def test_a_motion_after_cases_that_set_their_own_tool_runs_with_the_controllers(
    station: object, tmp_path: Path
) -> None:
    lines = _lines(_build(station, tmp_path, TOOLS))
    switch = lines[lines.index("SWITCH nCommand") : lines.index("ENDSWITCH") + 2]
    assert switch == [
        "SWITCH nCommand",
        "CASE 1",
        "$TOOL = {X 0, Y 0, Z 150, A 0, B 0, C 0}",
        "$BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}",
        "CASE 2",
        "$TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}",
        "$BASE = {X 500, Y 100, Z 300, A 0, B 0, C 0}",
        "DEFAULT",  # the source's, empty
        "ENDSWITCH",
        "LIN {X 100, Y -100, Z 100, A 0, B 90, C 0}",  # none of olp's settings before it
    ]


def test_the_motion_after_the_join_is_not_checked_and_says_why() -> None:
    program = parse_krl(TOOLS, "tools.src").program
    (move,) = [n for n in leaves(program.instructions) if isinstance(n, ir.RuntimeMove)]
    assert move.controller_settings and move.span.line == 17
    assert "$TOOL differs between the paths of the SWITCH at line 8" in move.reason
    assert "$BASE differs between the paths of the SWITCH at line 8" in move.reason
    assert [m.span.line for m in program.motions()] == [6, 7]


def test_another_language_refuses_the_motion_after_the_join(
    station: object, tmp_path: Path
) -> None:
    result = _build(station, tmp_path, TOOLS, post="abb")
    refused = [d for d in result.diagnostics if "with the controller's settings" in d.message]
    assert [(d.severity, d.kind, d.span.line if d.span else None) for d in refused] == [
        ("error", "runtime_target", 17)
    ]
    assert "$TOOL differs between the paths of the SWITCH at line 8" in refused[0].message
    assert refused[0].hint is not None
    assert not result.files


def test_a_tool_every_path_sets_alike_stays_modelled_and_checked(
    station: object, tmp_path: Path
) -> None:
    result = _build(station, tmp_path, SAME_TOOL)
    lines = _lines(result)
    motions = list(result.compiled.program.motions())
    assert [(m.kind, m.span.line) for m in motions] == [("joint", 6), ("linear", 16)]
    assert motions[1].tool.pose[2, 3] == pytest.approx(0.150)  # type: ignore[attr-defined]
    assert not [n for n in result.compiled.program if isinstance(n, ir.RuntimeMove)]
    lin = next(k for k, line in enumerate(lines) if line.startswith("LIN "))
    assert any(line.startswith("$TOOL = ") for line in lines[lin - 4 : lin])  # olp's own


def test_a_loop_that_sets_the_tool_for_its_next_pass(station: object, tmp_path: Path) -> None:
    """The first pass runs with the tool set before the loop, later ones with the body's: the
    LIN runs with the controller's, and the body's settings stay where they stand."""
    result = _build(station, tmp_path, PALLET)
    lines = _lines(result)
    assert lines[lines.index("LOOP") : lines.index("ENDLOOP") + 1] == [
        "LOOP",
        "LIN {X 100, Y -100, Z 100, A 0, B 90, C 0}",
        "$TOOL = {X 0, Y 0, Z 150, A 0, B 0, C 0}",
        "$BASE = {X 600, Y 0, Z 300, A 0, B 0, C 0}",
        "ENDLOOP",
    ]
    (move,) = [n for n in result.compiled.program if isinstance(n, ir.RuntimeMove)]
    assert move.controller_settings and "LOOP at line 7" in move.reason


def test_settings_only_a_ptp_passed_are_kept_for_the_motion_after_the_join(
    station: object, tmp_path: Path
) -> None:
    """``$VEL.CP`` and ``$ORI_TYPE`` set before a PTP, which the output writes before a LIN or
    CIRC only: the LIN in the loop runs with the controller's settings (none written before
    it), so they are kept as written where they stand."""
    text = PALLET.replace("$VEL.CP = 0.2\n", "$VEL.CP = 0.2\n$ORI_TYPE = #CONSTANT\n")
    lines = _lines(_build(station, tmp_path, text.replace(FIRST_LIN, "")))
    ptp = next(k for k, line in enumerate(lines) if line.startswith("PTP "))
    before = lines[:ptp]
    assert before.index("$VEL.CP = 0.2") < before.index("$ORI_TYPE = #CONSTANT")
    assert lines[ptp + 1 : ptp + 3] == ["LOOP", "LIN {X 100, Y -100, Z 100, A 0, B 90, C 0}"]


def test_a_setting_olp_cannot_put_on_the_controller_stops_the_motion_after_the_join() -> None:
    """The motion after the join runs with the controller's settings (none of olp's written
    before it), so the ones olp knows must be on the controller too: ``$VEL.CP`` set in a
    routine olp wrote out already, with no motion that uses it, is not. An error naming it,
    not a motion run with another speed."""
    text = PALLET.replace("$VEL.CP = 0.2\n", "Slow( )\n")
    text = text.replace(FIRST_LIN, "") + "DEF Slow( )\n$VEL.CP = 0.2\nEND\n"
    with pytest.raises(ParseError, match=r"with the speed as the program set it") as info:
        parse_krl(text, "pallet.src")
    assert info.value.span is not None and info.value.span.line == 7
