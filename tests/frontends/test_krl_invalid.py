"""Text that is not KRL (the controller refuses it too) gets a targeted, located error marked
``invalid_krl``; KRL that olp cannot read yet keeps the grammar's error, unmarked."""

from __future__ import annotations

import pytest

from olp.errors import INVALID_KRL, ParseError
from olp.frontends.krl import parse_dat, parse_krl


def program(*body: str) -> str:
    """A DEF around ``body``: its first statement is on line 2."""
    return "\n".join(["DEF t ( )", *body, "END", ""])


def error_of(text: str) -> ParseError:
    with pytest.raises(ParseError) as info:
        parse_krl(text, "t.src")
    return info.value


# (text, line, column, message): each a program of the kind real backups hold
INVALID = {
    "a bare name": (
        program("   TODO", "   PTP HOME"),
        2,
        4,
        "a bare name is not a KRL statement: a subroutine call needs parentheses, TODO()",
    ),
    "a bare name with a comment": (
        program("lbReady ; to do"),
        2,
        1,
        "a bare name is not a KRL statement: a subroutine call needs parentheses, lbReady()",
    ),
    "END closing a DEFFCT": (
        "DEF t( )\nEND\n\nDEFFCT INT Twice(n:IN)\n  INT n\n  RETURN 2 * n\nEND\n",
        7,
        1,
        "END closes a DEF; this DEFFCT (line 4) ends with ENDFCT",
    ),
    "ENDFCT closing a DEF": (
        "DEF t( )\n  HALT\nENDFCT\n",
        3,
        1,
        "ENDFCT closes a DEFFCT; this DEF (line 1) ends with END",
    ),
    "ENDFCT of a commented-out DEFFCT": (
        "DEF t( )\nEND\n\n;DEFFCT INT Pick()\n   ;RETURN 1\nENDFCT\n",
        6,
        1,
        "ENDFCT closes a DEFFCT, and no DEFFCT is open here: the DEFFCT of line 4 is in a comment",
    ),
    "an END too many": (
        "DEF t( )\nEND\nEND\n",
        3,
        1,
        "END closes a DEF, and no DEF is open here (the routine before it ends at line 2)",
    ),
    "two assignments joined by a comma": (
        program("INT a, b", "a=0,b=0"),
        3,
        4,
        "one statement per line: a ',' does not join assignments in KRL; write 'b=0' on a "
        "line of its own",
    ),
    "'=' in an IF": (
        program("BOOL bSkip", "IF (bSkip = TRUE) THEN", "  HALT", "ENDIF"),
        3,
        11,
        "'=' assigns; the condition of IF compares with '=='",
    ),
    "'=' in a WAIT FOR": (
        program("WAIT FOR $IN[3] = TRUE"),
        2,
        17,
        "'=' assigns; the condition of WAIT FOR compares with '=='",
    ),
    "'=' in an UNTIL": (
        program("INT n", "REPEAT", "  n = n + 1", "UNTIL n = 3"),
        5,
        9,
        "'=' assigns; the condition of UNTIL compares with '=='",
    ),
    "'=' in an interrupt's condition": (
        program("INTERRUPT DECL 20 WHEN $IN[7] = FALSE DO Stop()"),
        2,
        31,
        "'=' assigns; the condition of INTERRUPT ... WHEN compares with '=='",
    ),
    "a '(' not closed": (
        program("IF NOT (InRange(1, 2) THEN", "  HALT", "ENDIF"),
        2,
        8,
        "the '(' at column 8 is not closed: a ')' is missing before 'THEN'",
    ),
    "a ')' too many": (
        program("INT n", "n = (1 + 2))"),
        3,
        12,
        "this ')' closes no '('",
    ),
    "a TRIGGER without DELAY": (
        program("TRIGGER WHEN PATH = 0 ONSTART DO $OUT[1] = TRUE", "LIN {X 1,Y 2,Z 3}"),
        2,
        31,
        "a TRIGGER needs DELAY = time (ms) before DO",
    ),
    "a DEFFCT defined twice": (
        "DEF t( )\nEND\n\nDEFFCT INT Edge( )\n  RETURN 1\nENDFCT\n\n"
        "GLOBAL DEFFCT INT edge( )\n  RETURN 2\nENDFCT\n",
        8,
        1,
        "DEFFCT edge is defined twice (lines 4 and 8)",
    ),
}


@pytest.mark.parametrize("case", INVALID, ids=list(INVALID))
def test_invalid_krl_is_told_precisely(case: str) -> None:
    text, line, column, message = INVALID[case]
    error = error_of(text)
    assert error.code == INVALID_KRL
    assert error.message.startswith(message)
    assert error.span is not None and (error.span.line, error.span.column) == (line, column)
    assert error.format().startswith(f"t.src:{line}:{column}: parse error[invalid_krl]: ")


def test_struc_members_without_a_comma_in_a_data_list() -> None:
    text = "DEFDAT parts\nGLOBAL STRUC PART_T E_SIDE_T eSide INT nCount\nENDDAT\n"
    with pytest.raises(ParseError) as info:
        parse_dat(text, "parts.dat")
    assert info.value.code == INVALID_KRL
    assert info.value.message.startswith("a ',' is missing before 'INT': the members of a STRUC")
    assert info.value.span is not None and info.value.span.column == 36


@pytest.mark.parametrize(
    "body",
    [
        ("ASYSTOP",),  # a KRL statement of one word olp does not read
        ("LIN {X 1,Y 2 Z 3}",),  # the grammar's own error, nothing KRL-specific to say
        ("FOR i = 1 TO 3 STEP", "ENDFOR"),
    ],
)
def test_other_syntax_errors_are_not_marked_invalid(body: tuple[str, ...]) -> None:
    error = error_of(program("INT i", *body))
    assert error.code is None
    assert error.message.startswith("unexpected")
    assert "parse error: unexpected" in error.format()
