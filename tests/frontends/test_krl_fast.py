"""The fast path for simple motion lines gives exactly what the full grammar gives; milling
programs; fuzzing of programs with data lists and of the data-list reader."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from olp import ir
from olp.errors import ParseError
from olp.frontends.krl import KrlData, KrlResult, load_config_dat, parse_dat, parse_krl
from olp.frontends.krl.ast import FastMotion, LinRows, Source
from olp.frontends.krl.fast import materialise, row_motions, scan_line
from olp.frontends.krl.parse import parse_module

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
MILLING = EXAMPLES / "facing_mill.src"


def program(*body: str) -> str:
    return "\n".join(["DEF t ( )", "$VEL.CP = 0.5", "$APO.CDIS = 1", *body, "END", ""])


def outcome(text: str, fast: bool, **data: KrlData) -> KrlResult | tuple[str, object, str]:
    """The result, or the error as (message, span, formatted text) to compare."""
    try:
        return parse_krl(text, "t.src", fast_path=fast, **data)
    except ParseError as error:
        return error.message, error.span, error.format()


def assert_same_both_ways(text: str, **data: KrlData) -> None:
    assert outcome(text, True, **data) == outcome(text, False, **data)


def test_a_simple_line_is_taken_by_the_fast_path() -> None:
    line = "  lin {x 1.5,Y -0.000, z +2 ,A 1e3,B .5,C 12.} C_DIS ; note\r"
    fast = scan_line(line, 7, "t.src")
    assert fast == FastMotion(
        "LIN",
        None,
        ("X", "Y", "Z", "A", "B", "C"),
        (1.5, -0.0, 2.0, 1000.0, 0.5, 12.0),
        ("C_DIS",),
        ir.SourceSpan("t.src", 7, 3, 7, 53),
        line,
    )
    assert str(fast.values[1]) == "-0.0"


@pytest.mark.parametrize(
    "line",
    [
        "LIN {X1.5}",  # the name is X1
        "LIN {X - 5,Y 0,Z 0,A 0,B 0,C 0}",  # blank after the sign: left to the grammar
        "LIN {TO 1}",  # a keyword as member name
        "LIN {X 1e,Y 0}",
        "LIN {X 1.5.3}",
        "LIN {X 1} C_DISC_DIS",
        "LIN {X 1} #TOOL",
        "LIN XP1",
        "LIN {POS: X 1}",
        "LIN {PTP: X 1}",
        "LIN_REL {X 1}",
        "LIN {X 'B01'}",
        "LIN {}",
        "PTP {X 1} C_DIS C_DIS C_VEL",
    ],
)
def test_lines_the_fast_path_leaves_to_the_grammar(line: str) -> None:
    if scan_line(line, 1, "t.src") is not None:
        assert line in ("LIN {POS: X 1}", "PTP {X 1} C_DIS C_DIS C_VEL")
    assert_same_both_ways(program(line))


def statements(text: str, fast: bool) -> list[object]:
    module = parse_module(Source.of(text, "t.src"), fast=fast)
    body = module.items[0].body
    flat = [m for s in body for m in (row_motions(s) if isinstance(s, LinRows) else (s,))]
    return [materialise(s) if isinstance(s, FastMotion) else s for s in flat]


KEYWORDS = ["PTP", "LIN", "ptp", "Lin", "SPTP", "slin", "LIN_REL", "CIRC"]
NAMES = ["X", "Y", "Z", "A", "B", "C", "x", "A1", "a6", "E1", "S", "T", "X1", "TO", "Q"]
NUMBERS = ["0", "-0.000", "+2.5", "- 2.5", "1e3", "1.5E-3", ".5", "12.", "1e", "7", "'B010'"]
BLANKS = ["", " ", "\t", "  "]
SUFFIXES = ["", " C_DIS", " C_DIS C_DIS", " c_ptp", " C_PTP C_VEL", " C_SPL", "C_DIS", " #TOOL"]


@st.composite
def motion_lines(draw: st.DrawFn) -> str:
    blank = st.sampled_from(BLANKS)
    members = draw(
        st.lists(
            st.tuples(st.sampled_from(NAMES), blank, st.sampled_from(NUMBERS), blank),
            min_size=1,
            max_size=7,
        )
    )
    body = ",".join(f"{b1}{n}{b2}{v}{b3}" for n, b2, v, b3 in members for b1 in [draw(blank)])
    prefix = draw(st.sampled_from(["", "E6POS: ", "FRAME:", "axis :", "PTP:"]))
    keyword = draw(st.sampled_from(KEYWORDS))
    suffix = draw(st.sampled_from(SUFFIXES)) + draw(st.sampled_from(["", " ;c", ";x\r", "\r"]))
    return f"{draw(blank)}{keyword}{draw(blank)}{{{prefix}{body}}}{suffix}"


SETTINGS = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@SETTINGS
@given(st.lists(motion_lines(), min_size=1, max_size=4))
def test_fast_path_equals_the_grammar(lines: list[str]) -> None:
    text = program("PTP {A1 1,A2 2,A3 3,A4 4,A5 5,A6 6}", *lines, "LIN {Z 1}")
    assert_same_both_ways(text)
    try:
        slow = statements(text, fast=False)
    except ParseError:
        return
    assert statements(text, fast=True) == slow


@pytest.mark.parametrize(
    "text",
    [
        "LIN {X 1,Y 2,Z 3,A 0,B 0,C 0}\nDEF t()\nEND\n",  # before any DEF
        "DEF t()\nEND\nLIN {X 1,Y 2,Z 3,A 0,B 0,C 0}\n",  # after END
        "DEF t()\nSWITCH 1\nLIN {X 1}\nCASE 1\nENDSWITCH\nEND\n",  # where no statement may be
        "DEF t()\n$VEL.CP=1\nFOR i=1 TO 2\n  LIN {X 1,Y 2,Z 3,A 0,B 0,C 0}\n"
        "  LIN {Z 4}\nENDFOR\nEND\n",
        "DEF t()\nIF $IN[1] THEN\nLIN {X 1,Y 2,Z 3,A 0,B 0,C 0}\nENDIF\nEND\n",
        "DEF t()\nLIN {X 1,Y 2,Z 3,A 0,B 0,C 0}\x00\nEND\n",
    ],
)
def test_fast_lines_in_every_context(text: str) -> None:
    assert_same_both_ways(text)


def test_syntax_error_deep_in_a_long_program_is_located_exactly() -> None:
    lines = [f"LIN {{X {i}.5,Y 0,Z 0,A 0,B 0,C 0}} C_DIS" for i in range(3000)]
    lines[2500] = "LIN {X 2500.5,Y 0,,Z 0,A 0,B 0,C 0} C_DIS"
    with pytest.raises(ParseError) as info:
        parse_krl(program(*lines), "t.src")
    error = info.value
    assert error.span is not None and (error.span.line, error.span.column) == (2504, 19)
    assert "unexpected ','" in error.message and error.source_line == lines[2500]


def test_value_error_in_a_fast_line_is_located_exactly() -> None:
    lines = [f"LIN {{X {i},Y 0,Z 0,A 0,B 0,C 0}}" for i in range(100)]
    lines[60] = "LIN {X 1,Y 0,Z 0,A 0,B 0,C 0,X 2}"
    with pytest.raises(ParseError) as info:
        parse_krl(program(*lines), "t.src")
    assert info.value.span == ir.SourceSpan("t.src", 64, 30, 64, 33)
    assert "given twice" in info.value.message


# ---- a long milling program -------------------------------------------------------------------


@pytest.fixture(scope="module")
def milling() -> KrlResult:
    return parse_krl(MILLING.read_text(), "facing_mill.src")


def test_milling_program(milling: KrlResult) -> None:
    motions = list(milling.program.motions())
    assert len(motions) == 2335 and isinstance(motions[0], ir.JointMove)
    assert all(isinstance(m, ir.LinearMove) for m in motions[1:-1])
    cutting = [m for m in motions if m.speed.linear == 0.04]
    assert len(cutting) == 3 * 31 * 25 and all(m.zone.radius == 0.0005 for m in cutting)
    assert {m.tool.name for m in motions} == {"tool_l10"}
    assert milling.ignored == ()
    assert {m.speed.linear_acceleration for m in cutting} == {2.0}
    kept = [(i.span.line, i.text, i.native_only) for i in milling.program if i.kind == "verbatim"]
    # $ACC.CP is a motion parameter olp models: lowered, not kept; the INI fold's BAS is kept
    # for the KRL post alone (it writes the source's INI instead of its own)
    assert kept == [(5, "BAS (#INITMOV,0 )", True)]
    assert milling.notes == ()


def test_milling_program_is_the_same_without_the_fast_path(milling: KrlResult) -> None:
    assert parse_krl(MILLING.read_text(), "facing_mill.src", fast_path=False) == milling


def test_partial_targets_in_milling_take_the_previous_components(milling: KrlResult) -> None:
    short = next(m for m in milling.program.motions() if m.span.line == 24)  # LIN {X 40,Y 0}
    assert isinstance(short.target, ir.CartesianTarget)
    assert [round(v * 1000, 6) for v in short.target.pose[:3, 3]] == [40.0, 0.0, 5.35]


# ---- fuzzing with data lists --------------------------------------------------------------------

DAT_SAMPLES = [
    (EXAMPLES / "pendant_pick.dat").read_text(),
    (EXAMPLES / "robot_config.dat").read_text(),
]
FRAGMENTS = [
    *"{}[](),.:;=+-*/#&'\"\n\t\r \x00$",
    *("DECL ", "E6POS ", "FDAT ", "XP1", "={X 1,Y 2}", "TOOL_DATA[1]", "[1,]", "SIGNAL "),
    *("$OUT[1]", " TO ", "STRUC ", "ENUM ", "GLOBAL ", "ENDDAT", "DEFDAT x\n", "PTP XP1\n"),
    *("1e999", "-", "'B01'", "#BASE", '"txt"', "DECL INT i=1/0\n", "XP1.Z=", "BAS("),
]


def mutate(text: str, data: st.DataObject) -> str:
    for _ in range(data.draw(st.integers(1, 4))):
        at = data.draw(st.integers(0, len(text)))
        action = data.draw(st.sampled_from(["delete", "insert", "duplicate"]))
        if action == "delete":
            text = text[:at] + text[at + data.draw(st.integers(1, 12)) :]
        elif action == "insert":
            text = text[:at] + data.draw(st.sampled_from(FRAGMENTS)) + text[at:]
        else:
            text = text[:at] + text[at : at + 40] + text[at:]
    return text


FUZZ = settings(max_examples=250, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@FUZZ
@given(st.data())
def test_fuzz_dat_reader(data: st.DataObject) -> None:
    text = mutate(data.draw(st.sampled_from(DAT_SAMPLES)), data)
    try:
        parse_dat(text, "fuzz.dat")
    except ParseError as error:
        assert error.span is not None and error.span.file == "fuzz.dat"
        assert error.span.line >= 1 and error.span.column >= 1 and error.format()


@pytest.fixture(scope="module")
def data_lists() -> dict[str, tuple[KrlData, KrlData]]:
    config = load_config_dat(EXAMPLES / "robot_config.dat")
    return {
        name: (parse_dat((EXAMPLES / f"{name}.dat").read_text(), f"{name}.dat"), config)
        for name in ("pendant_pick", "pendant_glue")
    }


@FUZZ
@given(st.data())
def test_fuzz_pendant_program_with_its_data(
    data_lists: dict[str, tuple[KrlData, KrlData]], data: st.DataObject
) -> None:
    name = data.draw(st.sampled_from(sorted(data_lists)))
    text = mutate((EXAMPLES / f"{name}.src").read_text(), data)
    dat, config = data_lists[name]
    try:
        parse_krl(text, "fuzz.src", dat=dat, config=config)
    except ParseError as error:
        assert error.span is not None and error.span.line >= 1 and error.span.column >= 1
        assert error.format()
