"""The corpus benchmark (``benchmarks/krl_corpus.py``) counts a file that is not KRL apart from
one olp cannot read, and a statement written with its numbers otherwise spelt as rewritten."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from benchmarks.krl_corpus import STATION, TextCount, count_text, run
from olp import ir

SOURCE = """\
DEF cell( )
   INT nPart, nTool
   WAIT SEC 0
   $VEL.CP=2
   $OUT[12]=TRUE
   MSG("Box 1")
END
"""


def written(text: str) -> SimpleNamespace:
    """A build result that wrote ``text`` as cell.src and lowered none of the source's lines."""
    program = ir.Program(name="cell", instructions=())
    return SimpleNamespace(files={"cell.src": text}, compiled=SimpleNamespace(program=program))


def test_numbers_and_declarations_in_another_spelling_are_rewritten_not_lost() -> None:
    out = "DEF cell( )\nDECL INT nPart\nDECL INT nTool\nWAIT SEC 0.000\n$VEL.CP = 2.0\nEND\n"
    count = TextCount()
    count_text(SOURCE, "cell.src", written(out), count)
    assert count.statements == 5
    assert sum(count.rewritten.values()) == 3  # the declaration, WAIT SEC and $VEL.CP
    assert dict(count.lost) == {"$OUT[12]=TRUE": 1, 'MSG("BOX1")': 1}


def test_a_number_inside_a_string_is_not_respelt() -> None:
    out = SOURCE.replace('"Box 1"', '"Box 1.0"')
    count = TextCount()
    count_text(SOURCE, "cell.src", written(out), count)
    assert count.found == 4
    assert dict(count.lost) == {'MSG("BOX1")': 1}


def test_an_until_written_without_its_parentheses_is_rewritten_and_an_absent_one_lost() -> None:
    source = "DEF cell( )\nREPEAT\nWAIT SEC 1\nUNTIL ($IN[1]==TRUE)\nUNTIL ($IN[2])\nEND\n"
    out = "DEF cell( )\nREPEAT\nWAIT SEC 1\nUNTIL $IN[1] == TRUE\nEND\n"
    count = TextCount()
    count_text(source, "cell.src", written(out), count)
    assert sum(count.rewritten.values()) == 1
    assert dict(count.lost) == {"UNTIL($IN[2])": 1}
    assert count.where_lost == ["cell.src:5: UNTIL ($IN[2])"]


def test_a_file_that_is_not_krl_is_counted_apart(tmp_path: Path) -> None:
    (tmp_path / "todo.src").write_text("DEF todo( )\n   TODO\nEND\n", encoding="latin-1")
    (tmp_path / "unread.src").write_text("DEF unread( )\n   ASYSTOP\nEND\n", encoding="latin-1")
    tally = run(tmp_path, STATION, None, "kuka", verbose=False)
    assert tally.classes["invalid"] == 1
    assert tally.classes["syntax"] == 1
    assert tally.constructs["invalid KRL: a bare name is not a KRL statement"] == 1
