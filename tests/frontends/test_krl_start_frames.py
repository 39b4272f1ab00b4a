"""A KRL module's motions before it sets its tool and base: the source runs them with the
tool and base the controller holds when the module starts (its caller's, the last program's);
olp checks them with the flange and the world and the output sets those, so each gets a
warning on the first such motion (once per program), never silence."""

from __future__ import annotations

import pytest

import olp
from olp.frontends.krl import parse_krl

LIN = "LIN {X 500,Y 0,Z 600,A 0,B 90,C 0}"
TOOL = "$TOOL = {X 0,Y 0,Z 120,A 0,B 0,C 0}"


def notes_on(*body: str) -> list[tuple[int, str]]:
    text = "DEF cell( )\n$VEL.CP = 0.2\n" + "\n".join(body) + "\nEND\n"
    result = parse_krl(text, "cell.src")
    return [
        (n.span.line, n.message.split(":")[0])
        for n in result.notes
        if "before any $TOOL" in n.message or "before any $BASE" in n.message
    ]


def test_a_motion_before_the_tool_and_base_are_set_is_warned_once_each() -> None:
    assert notes_on(LIN, LIN) == [(3, "LIN before any $BASE"), (3, "LIN before any $TOOL")]


def test_tool_and_base_set_first_give_no_warning() -> None:
    assert notes_on(TOOL, "$BASE = $NULLFRAME", LIN) == []


def test_a_tool_set_on_one_path_only_is_still_warned_after_the_join() -> None:
    # (the flange on that path: a tool that differed would make the motion ambiguous)
    body = ("$BASE = $NULLFRAME", "IF $IN[1] THEN", "$TOOL = $NULLFRAME", "ENDIF", LIN)
    assert notes_on(*body) == [(7, "LIN before any $TOOL")]


def test_many_rows_are_warned_once_and_all_lowered() -> None:
    rows = [f"LIN {{X {500 + k},Y 0,Z 600,A 0,B 90,C 0}}" for k in range(50)]
    text = "DEF cell( )\n$VEL.CP = 0.2\n" + "\n".join(rows) + "\nEND\n"
    result = parse_krl(text, "cell.src")
    assert len(list(result.program.motions())) == 50
    starts = [n for n in result.notes if "before any $" in n.message and "$VEL" not in n.message]
    assert [n.span.line for n in starts] == [3, 3]


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station("stations/kr6_milling_cell.yaml")


def test_the_warning_says_what_the_output_writes(station: object, tmp_path: object) -> None:
    from pathlib import Path

    src = Path(str(tmp_path)) / "cell.src"
    src.write_text("DEF cell( )\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 45,A6 0}\nEND\n")
    result = olp.build(station, src, post="kuka", collisions=None)
    assert result.ok
    text = result.files["cell.src"]
    assert "$TOOL = $NULLFRAME" in text and "$BASE = $NULLFRAME" in text
    warned = [d for d in result.diagnostics if "before any $TOOL" in d.message]
    assert len(warned) == 1 and warned[0].severity == "warning"


def test_a_tool_given_in_a_with_is_that_motions_only() -> None:
    """A WITH's $TOOL holds for its motion only: the plain LIN after it still runs with the
    controller's tool in the source, so it gets the warning."""
    spline = "SLIN {X 500,Y 0,Z 650,A 0,B 90,C 0} WITH $TOOL = {X 0,Y 0,Z 120,A 0,B 0,C 0}"
    assert notes_on("$BASE = $NULLFRAME", spline, LIN) == [(5, "LIN before any $TOOL")]
