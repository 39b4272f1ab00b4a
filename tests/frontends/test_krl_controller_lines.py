"""KRL -> KRL keeps every statement (issue 15): what only a KUKA controller models (its timers,
flags and message texts, ``EXT`` declarations, the payload lines of the pendant's spline
forms, code a GOTO jumps over) reaches the KRL output in place, as written; other posts stop
on it or leave it out with a warning, never without a word."""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir
from olp.frontends.krl import parse_krl
from olp.posts import find_post
from tests.krl_notes import own_notes

REPO = Path(__file__).resolve().parents[2]
STATION = REPO / "stations" / "kr6_milling_cell.yaml"
HOME = "PTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}"
AWAY = "PTP {A1 20,A2 -90,A3 90,A4 0,A5 30,A6 0}"

BELT = f"""DEF belt( )
DECL INT nRun
nRun = 3
$TIMER_STOP[2] = TRUE ; the belt runs nRun seconds
$TIMER[2] = (-nRun*1000)
$TIMER_STOP[2] = FALSE
{HOME}
IF $TIMER_FLAG[2] THEN
  $OUT[4] = TRUE
ENDIF
$FLAG[7] = TRUE
$MSG_T.VALID = FALSE
END
"""
BELT_KEPT = [
    "$TIMER_STOP[2] = TRUE",
    "$TIMER[2] = (-nRun*1000)",
    "$TIMER_STOP[2] = FALSE",
    "$FLAG[7] = TRUE",
    "$MSG_T.VALID = FALSE",
]

JUMP = f"""DEF jump( )
DECL INT nPart
nPart = 1
{HOME}
GOTO done
IF nPart == 1 THEN ; never runs
  LIN {{X 9000,Y 0,Z 0,A 0,B 0,C 0}}
  MsgNotify("skip; not reached")
ENDIF
{AWAY}
done:
{HOME}
END
"""
DEAD = [
    "IF nPart == 1 THEN",
    "LIN {X 9000,Y 0,Z 0,A 0,B 0,C 0}",
    'MsgNotify("skip; not reached")',
    "ENDIF",
    AWAY,
]


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(STATION)


def build(station: object, tmp_path: Path, text: str, post: object = "kuka") -> olp.api.BuildResult:
    path = tmp_path / "prog.src"
    path.write_text(text)
    return olp.build(station, path, post=post, collisions=None)  # type: ignore[arg-type]


def written_lines(result: olp.api.BuildResult) -> list[str]:
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    (src,) = [text for name, text in result.files.items() if name.endswith(".src")]
    return [line.strip() for line in src.splitlines()]


def in_declarations(lines: list[str], at: int) -> bool:
    """Whether line ``at`` comes before the first statement of the first routine: only the
    DEF, comments and declarations come before it."""
    start = next(k for k, line in enumerate(lines) if line.startswith("DEF"))
    head = ("DEF", ";", "DECL", "EXT")
    return start < at and all(not line or line.startswith(head) for line in lines[start:at])


def in_order(wanted: list[str], lines: list[str]) -> bool:
    """Whether ``wanted`` are among ``lines`` in this order, each once."""
    at = [lines.index(w) for w in wanted if lines.count(w) == 1]
    return len(at) == len(wanted) and at == sorted(at)


def said_at(result: olp.api.BuildResult, line: int) -> list[str]:
    """The severities of what the build says about ``line`` of the program."""
    return [d.severity for d in result.diagnostics if d.span and d.span.line == line]


# ---- system variables -----------------------------------------------------------------------


def test_a_conveyor_timer_and_flags_are_kept_as_written() -> None:
    program = parse_krl(BELT, "belt.src").program
    kept = [(n.text, n.span.line) for n in program if isinstance(n, ir.Verbatim)]
    assert kept == list(zip(BELT_KEPT, (4, 5, 6, 11, 12), strict=True))


def test_the_krl_output_starts_the_timer_it_reads(station: object, tmp_path: Path) -> None:
    lines = written_lines(build(station, tmp_path, BELT))
    assert in_order([*BELT_KEPT[:3], "IF $TIMER_FLAG[2] THEN", *BELT_KEPT[3:]], lines)


def test_another_post_stops_on_the_timer_naming_its_line(station: object, tmp_path: Path) -> None:
    """A timer changes what the program does: leaving it out is not a choice olp makes."""
    body = BELT.replace("IF $TIMER_FLAG[2] THEN\n  $OUT[4] = TRUE\nENDIF\n", "")
    result = build(station, tmp_path, body, "abb")
    assert not result.ok
    stopped = {d.span.line for d in result.diagnostics if d.kind == "verbatim" and d.span}
    assert stopped == {4, 5, 6, 8, 9}
    dropped = build(station, tmp_path, body, find_post("abb", {"foreign_verbatim": "drop"}))
    assert dropped.ok
    left_out = {d.span.line for d in dropped.diagnostics if d.kind == "verbatim_dropped" and d.span}
    assert left_out == {4, 5, 6, 8, 9}


def test_an_input_is_never_set() -> None:
    """The controller sets its inputs: an assignment to one (a SIGNAL of an input, or $IN[n])
    models nothing. It is kept as written for the KRL post (KRL to KRL keeps every statement;
    it used to be left out), with a warning; olp does not know whether the KRL compiler
    refuses it, so it does not stop. Another post leaves it out with a warning."""
    text = "DEF io( )\nSIGNAL bStart $IN[3]\nbStart = FALSE\n$IN[4] = TRUE\nEND\n"
    result = parse_krl(text, "io.src")
    kept = [(n.text, n.native_only) for n in result.program if isinstance(n, ir.Verbatim)]
    assert kept == [
        ("SIGNAL bStart $IN[3]", True),
        ("bStart = FALSE", True),
        ("$IN[4] = TRUE", True),
    ]
    assert result.ignored == ()
    assert [(n.span.line, n.message.split(":")[0]) for n in result.notes] == [
        (3, "bStart is an input ($IN) and cannot be set by the program"),
        (4, "$IN is an input ($IN) and cannot be set by the program"),
    ]


# ---- EXT --------------------------------------------------------------------------------------

EXT = f"""DEF cell( )
DECL INT nCycle
EXT belt_start( )
EXTFCT INT belt_speed(nBelt :IN)
nCycle = 0
{HOME}
END
"""


def test_an_ext_declaration_is_written_with_the_declarations(
    station: object, tmp_path: Path
) -> None:
    """KRL takes EXT only before the routine's first statement: the KRL post writes it with
    the DECL lines (the source has no INI fold, so none is written)."""
    program = parse_krl(EXT, "cell.src").program
    kept = [(n.text, n.span.line) for n in program if isinstance(n, ir.Verbatim)]
    assert kept == [("EXT belt_start( )", 3), ("EXTFCT INT belt_speed(nBelt :IN)", 4)]
    lines = written_lines(build(station, tmp_path, EXT))
    ext = lines.index("EXT belt_start( )")
    assert lines[ext + 1] == "EXTFCT INT belt_speed(nBelt :IN)"
    assert lines.count("EXT belt_start( )") == 1
    assert in_declarations(lines, ext) and ext < lines.index("nCycle = 0")


def test_an_ext_of_a_routine_written_at_each_call_is_declared_once(
    station: object, tmp_path: Path
) -> None:
    """A routine whose motion depends on its parameter is written out at each call: its EXT
    comes with it each time, and KRL wants a name declared once."""
    text = (
        f"DEF cell( )\n{HOME}\nfeed(10)\nfeed(20)\nEND\n\nDEF feed(nA :IN)\nDECL INT nA\n"
        f"DECL E6AXIS aAt\nEXT belt_start( )\naAt = {HOME[4:]}\naAt.A1 = nA\nPTP aAt\n"
        "belt_start()\nEND\n"
    )
    lines = written_lines(build(station, tmp_path, text))
    assert lines.count("EXT belt_start( )") == 1 and lines.count("belt_start()") == 2
    assert in_declarations(lines, lines.index("EXT belt_start( )"))


def test_another_post_says_what_it_leaves_of_an_ext(station: object, tmp_path: Path) -> None:
    result = build(station, tmp_path, EXT, "abb")
    assert said_at(result, 3) and said_at(result, 4)


# ---- code a GOTO jumps over -------------------------------------------------------------------


def test_dead_code_is_kept_line_by_line_and_not_lowered() -> None:
    result = parse_krl(JUMP, "jump.src")
    dead = [(n.text, n.span.line) for n in result.program if isinstance(n, ir.Verbatim)]
    assert dead == list(zip(DEAD, range(6, 11), strict=True))
    assert [m.span.line for m in result.program.motions()] == [4, 12]
    assert not result.ignored
    assert [n.span.line for n in result.notes if "never reached" in n.message] == [6]


def test_dead_code_stays_where_the_goto_jumps_over_it(station: object, tmp_path: Path) -> None:
    """The LIN out of reach is neither checked nor timed: the build is the one without it."""
    result = build(station, tmp_path, JUMP)
    lines = written_lines(result)
    assert in_order(["GOTO done", *DEAD, "done:"], lines)
    dead = {"IF nPart == 1 THEN ; never runs", '  MsgNotify("skip; not reached")', AWAY}
    dead |= {"  LIN {X 9000,Y 0,Z 0,A 0,B 0,C 0}", "ENDIF"}
    live = "\n".join(line for line in JUMP.split("\n") if line not in dead)
    without = build(station, tmp_path, live)
    assert result.compiled.cycle_time == without.compiled.cycle_time


def test_another_post_says_what_it_leaves_of_dead_code(station: object, tmp_path: Path) -> None:
    result = build(station, tmp_path, JUMP, "abb")
    assert all(said_at(result, line) for line in range(6, 11))


def test_a_label_a_goto_targets_ends_the_dead_code() -> None:
    text = (
        f"DEF jump2( )\n{HOME}\nIF $IN[1] THEN\n  GOTO second\nENDIF\nGOTO first\n"
        f"$OUT[1] = TRUE\nsecond:\n{AWAY}\nfirst:\nEND\n"
    )
    program = parse_krl(text, "jump2.src").program
    assert [(n.text, n.span.line) for n in program if isinstance(n, ir.Verbatim)] == [
        ("$OUT[1] = TRUE", 7)
    ]
    assert [m.span.line for m in program.motions()] == [2, 9]


def test_the_program_override_is_kept_and_its_timing_noted() -> None:
    result = parse_krl(f"DEF slow( )\n$OV_PRO = 30\n{HOME}\nEND\n", "slow.src")
    assert [(n.kind, n.span.line) for n in result.program] == [("verbatim", 2), ("joint", 3)]
    assert [(n.span.line, "100 %" in n.message) for n in own_notes(result.notes)] == [(2, True)]
