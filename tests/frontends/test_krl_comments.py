"""KRL comments and pendant folds are kept in place (issue 15: "identity: a KRL program
transpiled to KRL keeps every statement, comments and folds included"), at every level, on
both reading paths; the pendant's INI fold and $BWDSTART are kept for the KRL post alone."""

from __future__ import annotations

from pathlib import Path

import pytest

from olp import ir
from olp.frontends.krl import parse_krl
from olp.ir_flow import leaves_and_blocks

EVERY_LEVEL = """&ACCESS RVP
&REL 1
; before the DEF
DEF Levels( ) ; on the DEF line
; top
DECL INT i
i = 1 ; trailing, after an assignment
IF i == 1 THEN ; on the IF line
  ; in THEN
  $OUT[1] = TRUE
ELSE
  ; in ELSE
ENDIF ; after ENDIF
SWITCH i
  ; before the first CASE
  CASE 1
    ; in CASE 1
    WAIT SEC 0.1
  CASE 2, 3
    ; in CASE 2
  DEFAULT
    ; in DEFAULT
ENDSWITCH
WHILE i < 3
  ; in WHILE
  i = i + 1
ENDWHILE
LOOP
  ; in LOOP
  EXIT
ENDLOOP
REPEAT
  ; in REPEAT
  i = i - 1
UNTIL i <= 0
FOR i = 1 TO 2
  ; in FOR
ENDFOR
FOR i = 1 TO n
  ; in a FOR kept as a loop
  $OUT[3] = TRUE
ENDFOR
;FOLD my fold
$OUT[2] = TRUE
;ENDFOLD
MsgDone("a;b") ; the ; in the string is not a comment
Helper( )
; before END
END ; on the END line
; between the routines
DEF Helper( )
  ; in the helper
  WAIT SEC 0.2
END
; after the last routine
"""
"""A program of the author's own with a comment at every level a body has."""


def _comments(nodes: tuple[ir.Node, ...]) -> list[tuple[str, int]]:
    return [(n.text, n.span.line) for n in leaves_and_blocks(nodes) if isinstance(n, ir.Comment)]


def _with_comments(nodes: tuple[ir.Node, ...]) -> list[str]:
    """Kinds in order, a comment as its text: where each comment stands among the statements."""
    return [f";{n.text}" if isinstance(n, ir.Comment) else n.kind for n in leaves_and_blocks(nodes)]


@pytest.fixture(scope="module", params=[True, False], ids=["fast", "grammar"])
def levels(request: pytest.FixtureRequest) -> ir.Program:
    return parse_krl(EVERY_LEVEL, "levels.src", fast_path=request.param).program


def test_every_comment_is_kept_in_source_order(levels: ir.Program) -> None:
    main = _comments(levels.instructions)
    (helper,) = levels.routines
    found = main + _comments(helper.body)
    source = [
        (line.split(";", 1)[1].strip(), number)
        for number, line in enumerate(EVERY_LEVEL.splitlines(), start=1)
        if ";" in line and not line.startswith("MsgDone")
    ]
    source.append(
        (
            "the ; in the string is not a comment",
            EVERY_LEVEL.count("\n", 0, EVERY_LEVEL.index("MsgDone")) + 1,
        )
    )
    assert sorted(found, key=lambda c: c[1]) == sorted(source, key=lambda c: c[1])
    kept = [n for n in leaves_and_blocks(levels.instructions) if isinstance(n, ir.Comment)]
    assert all(n.from_source for n in kept)


def test_each_comment_is_in_its_body(levels: ir.Program) -> None:
    assert _with_comments(levels.instructions) == [
        ";before the DEF",
        ";on the DEF line",
        ";top",
        "declare",
        "assign",
        ";trailing, after an assignment",
        "if",
        ";on the IF line",
        ";in THEN",
        "set_output",
        ";in ELSE",
        ";after ENDIF",
        "switch",
        ";before the first CASE",
        ";in CASE 1",
        "wait",
        ";in CASE 2",
        ";in DEFAULT",
        "while",
        ";in WHILE",
        "assign",
        "loop",
        ";in LOOP",
        "exit",
        "repeat",
        ";in REPEAT",
        "assign",
        "for",
        ";in FOR",
        "for",
        ";in a FOR kept as a loop",
        "set_output",
        ";FOLD my fold",
        "set_output",
        ";ENDFOLD",
        "call",
        ";the ; in the string is not a comment",
        "routine_call",
        ";before END",
        ";on the END line",
    ]
    branch = next(n for n in levels.instructions if isinstance(n, ir.If))
    assert _comments(branch.branches[0].body) == [("on the IF line", 8), ("in THEN", 9)]
    assert _comments(branch.orelse) == [("in ELSE", 12)]
    switch = next(n for n in levels.instructions if isinstance(n, ir.Switch))
    assert [_comments(c.body) for c in switch.cases] == [
        [("before the first CASE", 15), ("in CASE 1", 17)],
        [("in CASE 2", 20)],
    ]
    assert _comments(switch.default) == [("in DEFAULT", 22)]
    assert _with_comments(levels.routines[0].body) == [
        ";between the routines",
        ";in the helper",
        "wait",
        ";after the last routine",
    ]


def test_a_fold_line_is_a_fold_comment_kept_as_written() -> None:
    text = (
        "DEF f( )\n"
        ";FOLD PTP P1 CONT Vel=100 % PDAT1;%{PE}%R 8.3.31,%MKUKATPBASIS,%CMOVE\n"
        "$OUT[1] = TRUE\n"
        ";ENDFOLD\n"
        "; FOLD with a blank is a plain comment\n"
        ";fold lower case\n"
        ";endfold (lower)\n"
        "END\n"
    )
    comments = [n for n in parse_krl(text, "f.src").program if isinstance(n, ir.Comment)]
    assert [(c.fold, c.text, c.title) for c in comments] == [
        (
            "open",
            "FOLD PTP P1 CONT Vel=100 % PDAT1;%{PE}%R 8.3.31,%MKUKATPBASIS,%CMOVE",
            "PTP P1 CONT Vel=100 % PDAT1",
        ),
        ("close", "ENDFOLD", ""),
        (None, "FOLD with a blank is a plain comment", "FOLD with a blank is a plain comment"),
        ("open", "fold lower case", "lower case"),
        ("close", "endfold (lower)", "(lower)"),
    ]


def test_a_fold_comment_is_one_line_starting_with_its_keyword() -> None:
    with pytest.raises(ir.IRError, match="starts with FOLD"):
        ir.Comment(text="PTP P1", fold="open")
    with pytest.raises(ir.IRError, match="one line"):
        ir.Comment(text="FOLD a\nLIN {X 0}", fold="open")
    assert ir.Comment(text="ENDFOLD", fold="close").title == ""


def test_a_comment_with_a_control_character_is_one_printable_line() -> None:
    program = parse_krl("DEF c( )\n; bell\x07 here\nEND\n", "c.src").program
    (comment,) = program.instructions
    assert isinstance(comment, ir.Comment) and comment.text == "bell? here"


def test_bwdstart_and_the_ini_fold_are_kept_for_the_krl_post_alone() -> None:
    text = (
        "DEF p( )\n"
        ";FOLD INI;%{PE}\n"
        "  GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )\n"
        "  INTERRUPT ON 3\n"
        "  BAS (#INITMOV,0 )\n"
        ";ENDFOLD (INI)\n"
        "$BWDSTART = FALSE\n"
        "PTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}\n"
        "BAS (#INITMOV,0 )\n"  # outside the INI fold, after a motion: left out, as before
        "END\n"
    )
    result = parse_krl(text, "p.src")
    kept = [(n.text, n.native_only) for n in result.program if isinstance(n, ir.Verbatim)]
    assert kept == [
        ("GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )", True),
        ("INTERRUPT ON 3", True),
        ("BAS (#INITMOV,0 )", True),
        ("$BWDSTART = FALSE", True),
    ]
    assert [(i.span.line, i.text) for i in result.ignored] == [(9, "BAS (#INITMOV,0 )")]


def test_a_comment_that_names_an_unrolled_counter_does_not_read_it() -> None:
    """An unrolled FOR writes ``i = n`` before a pass whose output reads the counter; a
    comment naming it reads nothing."""
    text = "DEF u( )\nDECL INT i\nFOR i = 1 TO 2\n; moves by i\nWAIT SEC i\nENDFOR\nEND\n"
    program = parse_krl(text, "u.src").program
    assert [n.kind for n in program if n.kind != "declare"] == [
        "comment",
        "wait",
        "comment",
        "wait",
    ]


def test_comments_break_no_toolpath_reading(tmp_path: Path) -> None:
    """A comment between CAM rows is kept between them; the rows around it stay rows."""
    rows = [f"LIN {{X {i}.000,Y 0.000,Z 5.000,A 0.000,B 90.000,C 0.000}} C_DIS" for i in range(4)]
    text = "\n".join(["DEF t( )", "; header", *rows[:2], "; middle", *rows[2:], "END", ""])
    fast = parse_krl(text, "t.src").program
    assert fast == parse_krl(text, "t.src", fast_path=False).program
    assert [n.kind for n in fast] == ["comment", "linear", "linear", "comment", "linear", "linear"]
