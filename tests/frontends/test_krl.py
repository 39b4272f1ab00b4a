"""KRL frontend: job 5 end to end, lowering rules, located errors, and fuzzing."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from olp import ir
from olp.errors import ParseError, UsageError
from olp.frontends.krl import DEFAULT_VEL_CP, KrlResult, StatusTurn, load_krl, parse_krl
from olp.resources import data_path
from olp.vendors.kuka import frame_to_pose
from tests.krl_notes import own_notes

REPO = Path(__file__).resolve().parents[2]
MILLING = REPO / "examples" / "milling.src"

# The Cartesian targets of examples/milling.src: (line, X, Y, Z, A, B, C).
MILLING_LINS = [
    (6, -0.000, -0.000, 6.350, -180.000, 0.000, -180.000),
    (8, 276.225, 0.000, 6.350, 180.000, 0.000, -180.000),
    (9, 276.225, 323.850, 6.350, -160.000, 0.000, 180.000),
    (10, -0.000, 323.850, 6.350, -180.000, -0.000, -180.000),
    (11, -0.000, -0.000, 6.350, -180.000, 0.000, -180.000),
    (13, -0.000, -0.000, 106.350, -180.000, 0.000, -180.000),
]
MILLING_AXES = [107.78457, -44.95260, 141.64681, 107.66839, -87.93467, 6.37710]
FULL = "{X 1,Y 2,Z 3,A 0,B 0,C 0}"


def program(*body: str) -> str:
    """A DEF around ``body``: its first statement is on line 2."""
    return "\n".join(["DEF t ( )", *body, "END", ""])


def parse(*body: str) -> KrlResult:
    return parse_krl(program(*body), "t.src")


def pose_of(instruction: ir.Instruction) -> np.ndarray:
    """The target pose of a Cartesian motion."""
    assert isinstance(instruction, ir.MOTION_TYPES)
    assert isinstance(instruction.target, ir.CartesianTarget)
    return instruction.target.pose


def without_span(instruction: ir.Instruction) -> ir.Instruction:
    return dataclasses.replace(instruction, span=ir.GENERATED)


def parse_error(*body: str) -> ParseError:
    with pytest.raises(ParseError) as info:
        parse(*body)
    return info.value


# ---- job 5: the Milling program ---------------------------------------------------------------


@pytest.fixture(scope="module")
def milling() -> KrlResult:
    return load_krl(MILLING)


def test_grammar_is_found_through_data_path() -> None:
    assert data_path("grammars", "krl.lark").is_file()


def test_milling_is_one_ptp_then_six_lins(milling: KrlResult) -> None:
    kinds = [type(i) for i in milling.program]
    assert kinds == [ir.JointMove] + [ir.LinearMove] * 6
    assert milling.program.name == "Milling"
    assert milling.program.source == str(MILLING)
    assert milling.ignored == () and milling.notes == () and milling.status_turn == ()


def test_milling_speeds_follow_vel_cp(milling: KrlResult) -> None:
    speeds = [m.speed.linear for m in milling.program.motions()]
    assert speeds == [1.0, 1.0, 0.02117, 0.02117, 0.02117, 0.02117, 1.0]
    assert all(m.speed.joint == 1.0 and m.zone == ir.FINE for m in milling.program.motions())


def test_milling_tool_and_base_in_metres(milling: KrlResult) -> None:
    for motion in milling.program.motions():
        assert motion.tool.name == "tool_l3" and motion.frame.name == "base_l2"
        assert motion.tool.pose is not None and motion.frame.pose is not None
        np.testing.assert_allclose(motion.tool.pose[:3, 3], [0.466604, -0.004165, 0.109636])
        expected = frame_to_pose([466.604, -4.165, 109.636, -0.0, 90.0, 0.0])
        np.testing.assert_allclose(motion.tool.pose, expected, atol=1e-12)
        base = np.eye(4)
        base[1, 3] = -1.0  # Y -1000 mm
        np.testing.assert_allclose(motion.frame.pose, base, atol=1e-15)


def test_milling_targets_and_spans(milling: KrlResult) -> None:
    ptp, *lins = milling.program.motions()
    assert isinstance(ptp.target, ir.JointTarget)
    np.testing.assert_allclose(ptp.target.joints, np.radians(MILLING_AXES), atol=1e-12)
    assert ptp.span == ir.SourceSpan(str(MILLING), 5, 1, 5, 82)
    for motion, (line, *xyzabc) in zip(lins, MILLING_LINS, strict=True):
        assert isinstance(motion.target, ir.CartesianTarget)
        np.testing.assert_allclose(motion.target.pose, frame_to_pose(xyzabc), rtol=0, atol=1e-9)
        assert (motion.span.line, motion.span.column) == (line, 1)


def test_keywords_are_case_insensitive(milling: KrlResult) -> None:
    text = MILLING.read_text()
    for variant in (text.lower(), text.upper(), text.swapcase()):
        result = parse_krl(variant, str(MILLING))
        assert result.program.instructions == milling.program.instructions


def test_headers_folds_comments_whitespace_and_crlf(milling: KrlResult) -> None:
    header = "&ACCESS RVP\n&REL 3\n&PARAM EDITMASK = *\n;FOLD header;%{PE}%V3.2\n\n;ENDFOLD\n"
    body = MILLING.read_text().splitlines()
    messy = [
        body[0] + "   ; the program",
        ";FOLD frames",
        *("\t " + line + "  ;c" for line in body[1:3]),
        ";ENDFOLD",
        "",
        "   ",
        *body[3:],
    ]
    text = header + "\r\n".join(messy)  # CRLF endings, no final line break
    result = parse_krl(text, "messy.src")
    assert [m.span.line for m in result.program.motions()] == [15, 16, 18, 19, 20, 21, 23]
    for ours, theirs in zip(result.program.motions(), milling.program.motions(), strict=True):
        assert ours.target == theirs.target and ours.speed == theirs.speed
        assert (ours.tool.name, ours.frame.name) == ("tool_l10", "base_l9")
        assert ours.tool.pose is not None and theirs.tool.pose is not None
        np.testing.assert_array_equal(ours.tool.pose, theirs.tool.pose)


def test_names_that_start_with_keywords_are_names() -> None:
    result = parse(
        "LINE = 1",
        "PTPX = 2",
        "endless = 3",
        "FOR i = 1 TO TOTAL",
        "ENDFOR",
        "LIN_ON()",
        "WAIT SEC LINE + PTPX + endless",
    )
    assert not result.ignored  # assignments are kept (and evaluated), the FOR is a block
    assert [i.kind for i in result.program.instructions] == ["assign"] * 3 + ["for", "call", "wait"]
    assert [without_span(i) for i in result.program if i.kind in ("call", "wait")] == [
        ir.Call(name="LIN_ON", may_move=True),  # another module's: it may move the robot
        ir.Wait(seconds=6.0),
    ]


@pytest.mark.parametrize(
    ("text", "mm"),
    [
        ("1", 1.0),
        ("-0.000", -0.0),
        ("+2.5", 2.5),
        ("- 2.5", -2.5),
        ("1e3", 1000.0),
        ("1.5E-3", 0.0015),
        (".5", 0.5),
        ("12.", 12.0),
        ("-7", -7.0),
    ],
)
def test_numbers(text: str, mm: float) -> None:
    result = parse(f"LIN {{X {text},Y 0,Z 0,A 0,B 0,C 0}}", f"WAIT SEC {text.strip('-')}")
    assert pose_of(result.program.instructions[0])[0, 3] == pytest.approx(mm / 1000)
    wait = result.program.instructions[1]
    assert isinstance(wait, ir.Wait) and wait.seconds == pytest.approx(abs(mm))


def test_load_krl_falls_back_to_cp1252(tmp_path: Path) -> None:
    path = tmp_path / "umlaut.src"
    text = program("; Bahn für Fräser, 5 €", "PTP {A1 1,A2 2,A3 3,A4 4,A5 5,A6 6}")
    path.write_bytes(text.encode("cp1252"))
    comment, move = load_krl(path).program.instructions  # the comment is kept, decoded
    assert comment == ir.Comment(
        text="Bahn für Fräser, 5 €", span=comment.span, from_source=True
    ) and isinstance(move, ir.JointMove)
    bom = tmp_path / "bom.src"
    bom.write_bytes(b"\xef\xbb\xbf" + program("WAIT SEC 1").encode())
    wait = ir.Wait(seconds=1.0, span=ir.SourceSpan(str(bom), 2, 1, 2, 11))
    assert load_krl(bom).program.instructions == (wait,)


def test_load_krl_missing_file() -> None:
    with pytest.raises(UsageError):
        load_krl(REPO / "does-not-exist.src")


# ---- lowering rules ---------------------------------------------------------------------------


def test_partial_cartesian_target_takes_previous_components() -> None:
    result = parse(f"LIN {FULL}", "LIN {Z 100}", "LIN {X 5,C 90}")
    poses = [pose_of(m) for m in result.program.motions()]
    np.testing.assert_allclose(poses[1], frame_to_pose([1, 2, 100, 0, 0, 0]))
    np.testing.assert_allclose(poses[2], frame_to_pose([5, 2, 100, 0, 0, 90]))


@pytest.mark.parametrize(
    ("body", "because"),
    [
        (["LIN {Z 100}"], "no earlier Cartesian target"),
        ([f"LIN {FULL}", "PTP {A1 0,A2 0,A3 0,A4 0,A5 0,A6 0}", "LIN {Z 1}"], "axis values"),
        ([f"LIN {FULL}", "$BASE = BASE_DATA[1]", "LIN {Z 1}"], "$BASE changed at line 3"),
        ([f"LIN {FULL}", "$TOOL = {X 1}", "LIN {Z 1}"], "$TOOL changed at line 3"),
    ],
)
def test_partial_target_without_known_start_is_an_error(body: list[str], because: str) -> None:
    error = parse_error(*body)
    assert "leaves out" in error.message and because in error.message
    assert error.span is not None and error.span.line == len(body) + 1


def test_frames_and_tools_by_number_and_null() -> None:
    result = parse(
        "$BASE = BASE_DATA[3]",
        "$TOOL = TOOL_DATA[2]",
        f"LIN {FULL}",
        "$BASE = $NULLFRAME",
        "$TOOL = $NULLFRAME",
        f"LIN {FULL}",
        "BAS(#TOOL, 4)",
        "BAS (#BASE,0)",
        f"LIN {FULL}",
    )
    first, second, third = result.program.motions()
    assert first.frame == ir.Frame(name="BASE_DATA[3]", number=3)
    assert first.tool == ir.Tool(name="TOOL_DATA[2]", number=2)
    assert (second.frame, second.tool) == (ir.WORLD, ir.FLANGE)
    assert (third.frame, third.tool) == (ir.WORLD, ir.Tool(name="TOOL_DATA[4]", number=4))


def test_inline_frame_with_missing_components_and_type_prefix() -> None:
    result = parse("$BASE = {x 10, c 90}", "$tool={FRAME: Z 50}", f"LIN {FULL}")
    motion = next(result.program.motions())
    assert motion.frame.name == "base_l2" and motion.tool.name == "tool_l3"
    assert motion.frame.pose is not None and motion.tool.pose is not None
    np.testing.assert_allclose(motion.frame.pose, frame_to_pose([10, 0, 0, 0, 0, 90]))
    np.testing.assert_allclose(motion.tool.pose, frame_to_pose([0, 0, 50, 0, 0, 0]))


def test_speed_state() -> None:
    result = parse(
        "BAS(#VEL_PTP, 80)",
        "$VEL_AXIS[2] = 40",
        "$ACC_AXIS[1] = 25",
        "$VEL.CP = 0.5",
        "PTP {A1 0,A2 0,A3 0,A4 0,A5 0,A6 0}",
        "$VEL = {CP 0.25, ORI1 100}",
        f"LIN {FULL}",
    )
    ptp, lin = result.program.motions()
    assert ptp.speed == ir.Speed(linear=0.5, joint=0.4, joint_acceleration=0.25)
    assert lin.speed == ir.Speed(linear=0.25, joint=0.4, joint_acceleration=0.25)
    assert [(i.span.line, i.reason) for i in result.ignored] == [
        (7, "$VEL component(s) ORI1 not lowered yet")
    ]


def test_default_linear_speed_is_noted_once() -> None:
    result = parse(f"LIN {FULL}", f"LIN {FULL}")
    assert all(m.speed.linear == DEFAULT_VEL_CP for m in result.program.motions())
    assert [n.span.line for n in own_notes(result.notes)] == [2]
    assert "$VEL.CP" in own_notes(result.notes)[0].message


def test_approximation_uses_apo_cdis() -> None:
    result = parse(
        "$VEL.CP = 1",
        f"LIN {FULL} C_DIS",
        "$APO.CDIS = 5",
        f"LIN {FULL} c_dis",
        "PTP {A1 0,A2 0,A3 0,A4 0,A5 0,A6 0} C_PTP",
        "PTP {A1 0,A2 0,A3 0,A4 0,A5 0,A6 0} C_PTP C_DIS",
        f"LIN {FULL} C_VEL",
        f"LIN {FULL}",
    )
    zones = [m.zone.radius for m in result.program.motions()]
    assert zones == [0.0, 0.005, 0.005, 0.005, 0.005, 0.0]
    # no CDIS yet; C_VEL approximated
    assert [n.span.line for n in own_notes(result.notes)] == [3, 8]


@pytest.mark.parametrize(
    "motion",
    [f"LIN {FULL} C_PTP", f"LIN {FULL} C_DIS C_VEL", "PTP {A1 0,A2 0,A3 0,A4 0,A5 0,A6 0} C_VEL"],
)
def test_invalid_approximation(motion: str) -> None:
    assert "invalid approximation" in parse_error(motion).message


def test_circ() -> None:
    result = parse("$VEL.CP = 0.1", f"LIN {FULL}", "CIRC {X 2,Y 3}, {X 3,Y 2}")
    circ = result.program.instructions[-1]
    assert isinstance(circ, ir.CircularMove)
    np.testing.assert_allclose(circ.via.pose, frame_to_pose([2, 3, 3, 0, 0, 0]))
    np.testing.assert_allclose(pose_of(circ), frame_to_pose([3, 2, 3, 0, 0, 0]))


def test_io_waits_and_calls() -> None:
    result = parse(
        "WAIT SEC 0.25",
        "$OUT[3] = TRUE",
        "$out[4]=false",
        "WAIT FOR $IN[1]",
        "WAIT FOR NOT $IN[2]",
        "WAIT FOR $IN[3] == FALSE",
        "SprayOn()",
        'TCP_On(1, "a, b", #X)',
    )
    simplified = [without_span(i) for i in result.program]
    assert simplified == [
        ir.Wait(seconds=0.25),
        ir.SetOutput(index=3, value=True),
        ir.SetOutput(index=4, value=False),
        ir.WaitInput(index=1, value=True),
        ir.WaitInput(index=2, value=False),
        ir.WaitInput(index=3, value=False),
        ir.Call(name="SprayOn", may_move=True),
        ir.Call(name="TCP_On", args=("1", '"a, b"', "#X"), may_move=True),
    ]
    assert [i.span.line for i in result.program] == list(range(2, 10))


def test_status_and_turn_are_recorded() -> None:
    result = parse("PTP {E6POS: X 1,Y 2,Z 3,A 0,B 90,C 0,S 'B010',T 35,E1 0}")
    ptp = result.program.instructions[0]
    assert isinstance(ptp, ir.JointMove) and isinstance(ptp.target, ir.CartesianTarget)
    assert result.status_turn == (StatusTurn(ptp.span, 2, 35),)


def test_unlowered_statements_are_listed_with_their_lines() -> None:
    result = parse(
        "DECL INT i",  # 2
        "GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )",
        "INTERRUPT ON 3",
        "BAS (#INITMOV,0 )",  # 5
        "$ADVANCE = 3",
        "i = i + 1",
        "IF $IN[1] == TRUE THEN",  # 8
        "  i = 2",
        "ENDIF",
        f"LIN {FULL}",  # 11
        "HALT",
        "RETURN",
        f"LIN {FULL}",  # 14, unreachable
    )
    lines = [(i.span.line, i.text) for i in result.ignored]
    assert lines == [(13, "RETURN"), (14, f"LIN {FULL}")]
    assert all(i.reason for i in result.ignored)
    kinds = [(i.kind, i.span.line) for i in result.program.instructions]
    assert kinds == [
        ("declare", 2),
        ("verbatim", 3),  # the pendant's INI lines: kept for the KRL post alone
        ("verbatim", 4),
        ("verbatim", 5),
        ("verbatim", 6),  # $ADVANCE is a controller setting: kept as written
        ("assign", 7),
        ("if", 8),
        ("linear", 11),
        ("verbatim", 12),  # HALT
    ]
    block = result.program.instructions[6]
    assert isinstance(block, ir.If) and [i.kind for i in block.branches[0].body] == ["assign"]


def test_other_routines_are_listed() -> None:
    routines = "\nDEF helper ( )\n  PTP HOME\nEND\nDEFFCT INT f()\nRETURN 1\nENDFCT\n"
    result = parse_krl(program(f"LIN {FULL}") + routines)
    assert result.ignored == ()
    helper, function = result.program.routines  # a function without motions is kept
    # never called: written, its PTP with the controller's settings (an unknown caller's)
    assert [(n.kind, n.span.line) for n in helper.body] == [("runtime_move", 6)]
    assert (function.name, function.returns, [n.kind for n in function.body]) == (
        "f",
        "INT",
        ["return"],
    )


# ---- errors -----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("line", "column", "found"),
    [
        ("LIN {X 1,Y 2,Z}", 15, "'}'"),
        ("PTP {A1 abc}", 9, "'abc'"),
        ("FOO BAR", 5, "'BAR'"),  # not a declaration: FOO is no type declared without DECL
        ("FOO BAR BAZ", 9, "'BAZ'"),
        ("WAIT SEC", 9, "end of line"),
        ("x = 1 ? 2", 7, "'?'"),
        ("  LIN {X 1,Y 2,Z 3,A 0,B 0,C 0} C_FOO", 33, "'C_FOO'"),
        ("PTP {A1 1,A2 2}", 5, "A3, A4, A5, A6"),
        ("LIN {X 1,Y 2,Z 3,A 0,B 0,C 0,Q 1}", 30, "'Q'"),
        ("LIN {X 1,X 1,Y 2,Z 3,A 0,B 0,C 0}", 10, "twice"),
        ("$VEL.CP = 0", 11, "> 0"),
        ("$VEL.CP = TRUE", 11, "'TRUE'"),  # (a run-time value is kept as written)
        ("$VEL_AXIS[1] = 150", 16, "150"),
        ("WAIT SEC -1", 10, ">= 0"),
        ("LIN {X 1e999,Y 2,Z 3,A 0,B 0,C 0}", 8, "out of range"),
        ("GOTO somewhere", 1, "GOTO"),
        ("SPL {X 1}", 1, "SPL"),
    ],
)
def test_error_location_and_text(line: str, column: int, found: str) -> None:
    error = parse_error("$VEL.CP = 1", line)
    assert error.span is not None
    assert (error.span.file, error.span.line, error.span.column) == ("t.src", 3, column)
    assert found in error.message
    assert error.source_line == line
    assert error.format().splitlines()[2].index("^") == 4 + column - 1


def test_motion_settings_that_differ_between_paths_are_an_error_at_the_motion() -> None:
    """Where a path's value cannot be put on the controller (set in a routine olp inlined and
    wrote out already, no motion of which runs with it), the speed after the join is neither
    known nor the controller's: the motion that runs with it stops the reading. (A path that
    ends with the setting keeps it as written and the speed is the controller's:
    tests/frontends/test_krl_joins.py.)"""
    text = program("IF $IN[1] THEN", "  Slow( )", "ENDIF", f"LIN {FULL}")
    with pytest.raises(ParseError) as info:
        parse_krl(text + "DEF Slow( )\n  $VEL.CP = 0.5\nEND\n", "t.src")
    error = info.value
    assert error.span is not None and (error.span.line, error.span.column) == (5, 1)
    assert "the speed differs between the paths of the IF at line 2" in error.message
    settled = parse("IF $IN[1] THEN", "  $VEL.CP = 0.5", "ENDIF", "$VEL.CP = 0.2", f"LIN {FULL}")
    assert [m.speed.linear for m in settled.program.motions()] == [0.2]


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        ("", 1, "no DEF"),
        ("DEF a()\n", 1, "expected a statement or 'END'"),
        ("DEFDAT a PUBLIC\nDECL INT i\nENDDAT\n", 1, "DEFDAT a is not supported"),
        ("DEF a()\nEND\nLIN {X 1}\n", 3, "unexpected 'LIN'"),
    ],
)
def test_file_level_errors(text: str, line: int, message: str) -> None:
    with pytest.raises(ParseError) as info:
        parse_krl(text)
    assert info.value.span is not None and info.value.span.line == line
    assert message in info.value.message


# ---- fuzzing: only a located ParseError may escape -------------------------------------------

SAMPLES = [
    MILLING.read_text(),
    program(
        "&ACCESS RVP",
        "BAS(#INITMOV, 0)",
        "$APO.CDIS = 2",
        f"LIN {FULL} C_DIS",
        "CIRC {X 2,Y 3}, {X 3,Y 2}",
        "IF $IN[1] THEN",
        "  WAIT FOR $IN[2]",
        "ENDIF",
        "$OUT[1] = TRUE",
        "SprayOn(1, #A)",
        "PTP {E6POS: X 1,Y 2,Z 3,A 0,B 90,C 0,S 'B010',T 35}",
    ),
]
FRAGMENTS = [
    *"{}[](),.:;=+-*/#&'\"\n\t\r \x00é$",
    *("0", "1", "9", "1e999", "-0.0", ".5", "X", "Y", "Z", "A", "B", "C", "S", "T", "A1", "E1"),
    *("PTP ", "LIN ", "CIRC ", "C_DIS", "C_PTP", "C_VEL", "END", "DEF ", "DEFDAT ", "IF "),
    *("THEN", "ELSE", "ENDIF", "FOR ", " TO ", "ENDFOR", "WAIT SEC ", "WAIT FOR ", "TRUE"),
    *("$VEL.CP", "$APO.CDIS", "$BASE", "$TOOL", "$OUT[1]", "$IN[1]", "NOT ", "BAS", "GOTO"),
    *("RETURN", "{FRAME: ", "'B01'", "BASE_DATA[", "\nEND\n", "\nDEF x()\n", "(" * 40, "-" * 40),
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
            text = text[:at] + text[at : at + 30] + text[at:]
    return text


def check_only_located_parse_errors(text: str) -> None:
    try:
        parse_krl(text, "fuzz.src")
    except ParseError as error:
        assert error.span is not None and error.span.line >= 1 and error.span.column >= 1
        assert error.format()


FUZZ = settings(max_examples=1500, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@FUZZ
@given(st.lists(st.sampled_from(FRAGMENTS), max_size=40).map("".join))
def test_fuzz_random_text(text: str) -> None:
    check_only_located_parse_errors(text)
    check_only_located_parse_errors(program(text))


@FUZZ
@given(st.data())
def test_fuzz_mutated_programs(data: st.DataObject) -> None:
    check_only_located_parse_errors(mutate(data.draw(st.sampled_from(SAMPLES)), data))


def test_nesting_too_deep_is_a_parse_error() -> None:
    deep = parse("x = " + "(" * 3000 + "1" + ")" * 3000, "WAIT SEC x")  # parentheses add no depth
    assert [without_span(i) for i in deep.program][1:] == [ir.Wait(seconds=1.0)]
    error = parse_error("x = " + "-" * 3000 + "1")
    assert error.span is not None and error.span.line == 1
    assert "nested too deeply" in error.message


def test_a_lone_carriage_return_inside_a_kept_statement_is_a_located_error() -> None:
    """Found by test_fuzz_random_text: ``$OUT[1]=<CR>$`` reached :class:`olp.ir.Verbatim`,
    which refuses a line break, as a FlowError traceback instead of a located error."""
    with pytest.raises(ParseError, match="not one clean line") as caught:
        parse_krl("DEF t( )\n$OUT[1]=\r$\nEND\n", "t.src")
    assert caught.value.span is not None and caught.value.span.line == 2
