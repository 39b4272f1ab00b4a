"""``$IN[n]`` in an assigned value (issue 15): ``bFlag = $IN[5]`` reads input 5 as
:class:`olp.ir.DigitalInput`, as conditions do, so every post writes it as an input (before, it
was a plain variable named ``$IN`` that RAPID and URScript refused)."""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir
from olp.frontends.krl import parse_krl

REPO = Path(__file__).resolve().parents[2]
SOURCE = (
    "DEF flag( )\nDECL BOOL bFlag, bOther\nSIGNAL DOOR $IN[7]\nbOther = FALSE\n"
    "bFlag = $IN[5]\nbFlag = $IN[5] AND bOther\nbFlag = NOT DOOR\n"
    "PTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}\nEND\n"
)


def _values() -> list[ir.Expr]:
    program = parse_krl(SOURCE, "flag.src").program
    return [i.value for i in program.instructions if isinstance(i, ir.Assign)]


def test_an_input_in_an_assigned_value_is_a_digital_input() -> None:
    _, plain, both, signal = _values()
    assert plain == ir.DigitalInput(index=5, span=plain.span)
    assert isinstance(both, ir.BinaryOp) and both.op == "and"
    assert isinstance(both.left, ir.DigitalInput) and both.left.index == 5
    assert isinstance(both.right, ir.Name) and both.right.name == "bOther"
    assert isinstance(signal, ir.UnaryOp) and isinstance(signal.operand, ir.DigitalInput)
    assert signal.operand.index == 7


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


WRITTEN = {
    "kuka": ("bFlag = $IN[5]", "bFlag = $IN[5] AND bOther", "bFlag = NOT $IN[7]"),
    "abb": ("bFlag := (di5 = 1);", "bFlag := (di5 = 1) AND bOther;", "bFlag := NOT (di7 = 1);"),
    "ur": ("bFlag = get_digital_in(5)", "bFlag = get_digital_in(5) and bOther"),
}


@pytest.mark.parametrize("post", sorted(WRITTEN))
def test_posts_write_the_input(station: object, post: str) -> None:
    program = parse_krl(SOURCE, "flag.src").program
    result = olp.build(station, program, post=post, collisions=None)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    (text,) = [t for f, t in result.files.items() if not f.endswith(".dat")]
    lines = [line.strip() for line in text.splitlines()]
    for expected in WRITTEN[post]:
        assert expected in lines, (expected, text)


def test_fanuc_names_the_line_it_cannot_write(station: object) -> None:
    """LS writes a BOOL variable only TRUE, FALSE or another BOOL (the LS post's rule): an input
    is refused at its line as such, no longer as an unknown system variable."""
    program = parse_krl(SOURCE, "flag.src").program
    result = olp.build(station, program, post="fanuc", collisions=None)
    errors = [d for d in result.diagnostics if d.severity == "error"]
    assert [d.span.line for d in errors] == [5, 6, 7]
    assert not any("$IN" in d.message for d in errors)
    assert not result.files
