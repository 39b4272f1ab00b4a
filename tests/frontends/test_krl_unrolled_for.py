"""The counter after a FOR loop olp unrolls (issue "Real KUKA programs").

olp writes a FOR loop out pass by pass where what it does depends on its counter, with
``counter = n`` before the passes whose output reads it. After the loop, KRL leaves a value in
the counter (one step past the end, as olp recalls the KSS manual; not verified against a
stored copy) that the written program never assigns: a statement after the loop that read it
was written as it stood and read another value on the controller. Now that read is an error on
the statement; a counter given a value again before it is read, and a second loop over the
same counter, are not.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from olp import ir
from olp.errors import ParseError
from olp.frontends.krl import load_krl
from olp.ir_flow import leaves

HEAD = """DEF cell( )
DECL INT i
DECL INT nLast
$VEL.CP = 0.2
$TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}
$BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
"""
LOOP = """FOR i = 1 TO 3
  LIN {X 100, Y -100, Z 100, A 0, B 90, C 0}
  $OUT[i] = TRUE
  $VEL.CP = 0.1 * i
ENDFOR
"""
"""Unrolled: a motion setting depends on the counter (lines 8-12 after HEAD)."""


def load(tmp_path: Path, after: str, before: str = "") -> ir.Program:
    path = tmp_path / "cell.src"
    path.write_text(HEAD + before + LOOP + after + "END\n")
    return load_krl(path).program


def test_a_read_after_the_unrolled_loop_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(ParseError, match="i is read after the FOR loop at line 8") as info:
        load(tmp_path, "nLast = i\n")
    assert info.value.span is not None and info.value.span.line == 13


def test_a_read_on_one_path_after_the_loop_is_an_error(tmp_path: Path) -> None:
    """The loop on one branch of an IF, the read after the IF; and a read at the top of an
    enclosing loop, which its next pass reaches after the FOR."""
    before = "IF $IN[1] THEN\n"
    with pytest.raises(ParseError, match="read after the FOR loop at line 9"):
        load(tmp_path, "ENDIF\nnLast = i\n", before)
    before = "WHILE $IN[1]\nnLast = i + 1\n"
    with pytest.raises(ParseError, match="read after the FOR loop at line 10"):
        load(tmp_path, "ENDWHILE\n", before)


def test_a_counter_set_again_or_counted_again_is_read_as_written(tmp_path: Path) -> None:
    program = load(tmp_path, "i = 7\nnLast = i\n" + LOOP)
    assigns = [n for n in leaves(program.instructions) if isinstance(n, ir.Assign)]
    last = [n for n in assigns if isinstance(n.target, ir.Name) and n.target.name == "nLast"]
    assert len(last) == 1
    counts = [n for n in assigns if isinstance(n.target, ir.Name) and n.target.name == "i"]
    assert [n.value.value for n in counts] == [7]  # type: ignore[attr-defined]
    outputs = [n.index for n in leaves(program.instructions) if isinstance(n, ir.SetOutput)]
    assert outputs == [1, 2, 3, 1, 2, 3]  # both loops unrolled


def test_a_component_or_text_named_like_the_counter_is_not_a_read(tmp_path: Path) -> None:
    """``FOR X = 1 TO 6`` (a pallet cell's axis loop), then ``pStack.X = pStack.X + 100`` and a
    text ``'X'``: the component X and the text are not the counter (before, any string that
    spelt the counter's name counted as a read)."""
    head = HEAD.replace("DECL INT i", "DECL INT X\nDECL E6POS pStack\nDECL CHAR sAxis[2]")
    path = tmp_path / "cell.src"
    loop = "FOR X = 1 TO 6\n  $VEL_AXIS[X] = 85\nENDFOR\n"
    after = 'pStack = $POS_ACT\npStack.X = pStack.X + 100\nsAxis[] = "X"\nLIN pStack\n'
    path.write_text(head + loop + after + "END\n")
    program = load_krl(path).program
    assigned = [n for n in leaves(program.instructions) if isinstance(n, ir.Assign)]
    assert [type(n.target).__name__ for n in assigned][-2:] == ["Member", "Index"]
