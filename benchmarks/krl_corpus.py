"""olp over a folder of KRL programs, as a new user would run it: what builds and what stops why.

Run from the repository root::

    python -m benchmarks.krl_corpus [FOLDER] [--station S] [--config-dat P] [--post P]
                                    [--backups] [-v]

FOLDER defaults to olp's own corpus ``tests/corpus/krc`` (programs written for olp in the style
of KR C4 controller backups); point it at a backup's ``KRC`` folder to measure real cells. The
controller's ``$config.dat`` is found in FOLDER (any case; the first in sorted order) unless
``--config-dat`` names one, and the ``PUBLIC`` data lists under FOLDER are shared, as
``--data-lists-from FOLDER`` does. With ``--backups`` each folder directly under FOLDER is a
backup of its own (its own ``$config.dat`` and data lists; a corpus of many cells), and the
figures are given per backup and in all. Every ``.src`` (any case) is built with ``olp.build``
on the station (default: the bundled KR 6 milling cell) through the post (default ``kuka``),
collisions off
(they are a property of the cell, not of the program's syntax), nothing written.

Each file lands in one class:

* ``build``: no error diagnostic;
* ``program``: stopped on program-level diagnostics only (unreachable, limits, ...);
* ``invalid``: stopped on an :class:`olp.errors.OlpError` whose ``code`` is
  :data:`olp.errors.INVALID_KRL`: the file is not KRL (a bare name, END closing a DEFFCT,
  ``=`` in a condition, ...), the controller refuses it too; counted by its message;
* ``syntax``: stopped on any other :class:`olp.errors.OlpError` (olp cannot read or lower
  something), counted by construct (the keyword at the error, or the block it sits in);
* ``post``: read, but the post cannot write something the program says (control flow, a line
  kept verbatim for another language), counted by the post's diagnostic kind;
* ``crash``: any other exception (a bug in olp).

The summary gives ``build_or_program`` (the share of files that build or stop only for
program-level reasons) and ``build_program_or_invalid`` (the same with the files that are not
KRL: olp told the user precisely what is wrong, and no reader of KRL could do more).

Besides, it counts statements of the ``.src`` olp read but did not put in the output and
reported only at ``info`` level (``silent_drops``: "nothing dropped silently" wants 0), and, for
the files that build, where each statement of the ``.src`` went: ``kept`` (a node of the
program's IR carries its line, so the KRL post writes it), ``absorbed`` into the motions' speeds,
zones, tools and bases (inline-form data, BAS, ``$VEL``/``$ACC``/``$TOOL``/``$BASE``/``$APO``/
``$ORI_TYPE``) when a motion of the module comes after it, an
``inlined`` call of the module's own DEF, ``warned`` (reported as not in the output), or
``unaccounted`` (the figure that must be 0: listed). With the KUKA post it also reads the
written ``.src`` again and compares its statements with the source's, in order
(``krl_round_trip_differs``: "KRL -> KRL keeps every statement" wants 0; comments apart,
and the INI lines the post writes from its template where the source has none), and counts the
source's comments and fold lines the written ``.src`` lacks (``comments_lost``: "KRL -> KRL
keeps comments and folds" wants 0; ``comments_warned``: those of a routine olp leaves out
with a warning at its head).

With the KUKA post it also counts by text (:func:`count_text`): each statement of the source
``.src`` (a line of code: not blank, not only a comment or a fold line, not an ``&`` header;
DEF/DEFFCT/END/ENDFCT lines apart, ``routine_lines_*``) against the written ``.src``'s,
matched by normalised text (upper case, blanks removed) as a multiset.
``statements_text_found_krl``: written as read; ``statements_rewritten_krl``: olp lowered it
and the post writes it in its own spelling (a motion to ``XP1`` as ``PTP {A1 ..}``, an
expression with other parentheses, ``DECL INT a, b`` as two lines, and the inline forms'
``PDAT_ACT=PPDAT1``, ``FDAT_ACT=FP1``, ``BAS(#PTP_PARAMS,100)``, which become the
``$VEL_AXIS[i]``, ``$ACC_AXIS[i]``, ``$VEL.CP``, ``$APO.CDIS``, ``$TOOL`` and ``$BASE`` lines
before the motion that runs with them; and a statement the written ``.src`` says with its
numbers otherwise spelt, ``WAIT SEC 0`` as ``WAIT SEC 0.000``, ``$VEL.CP=2`` as
``$VEL.CP = 2.0``, or a declaration item by item, ``INT a, b`` as ``DECL INT a`` and ``DECL INT
b``); ``statements_lost_krl``: the rest, not in the output in any spelling (with ``-v``: the
texts lost most often, and the rewritten ones by kind; with ``--lost``: each lost one as
``file:line: text``).

The last lines are ``name: value unit``.
"""

from __future__ import annotations

import argparse
import collections
import re
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
CORPUS = REPO / "tests" / "corpus" / "krc"
STATION = REPO / "stations" / "kr6_milling_cell.yaml"

_KEYWORD_TEXT = (
    "IF ELSE SWITCH CASE DEFAULT WHILE REPEAT UNTIL LOOP FOR GOTO EXIT HALT RETURN RESUME BRAKE "
    "INTERRUPT TRIGGER DEFFCT DEF DECL STRUC ENUM SIGNAL EXT EXTFCT WAIT PTP LIN CIRC SPTP SLIN "
    "SCIRC PTP_REL LIN_REL SPTP_REL SLIN_REL SCIRC_REL SPLINE ON_ERROR_PROCEED CONTINUE GLOBAL "
    "CONST FRAME E6AXIS E6POS POS AXIS INT REAL BOOL CHAR"
)
_KEYWORDS = frozenset(_KEYWORD_TEXT.split())
POST_KINDS = frozenset(
    {"control_flow", "verbatim", "unsupported", "call_argument", "call_name", "flow"}
)
"""Errors of a post that cannot write what the program says: not the program's fault."""
_INSIDE = re.compile(r"inside the (\w+) at line")
_WORD = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]*")


@dataclass
class Tally:
    """Counts over the corpus."""

    classes: collections.Counter[str] = field(default_factory=collections.Counter)
    constructs: collections.Counter[str] = field(default_factory=collections.Counter)
    crashes: list[str] = field(default_factory=list)
    silent_drops: int = 0
    warned_drops: int = 0
    statements_in: int = 0
    kept: int = 0
    absorbed: int = 0
    inlined: int = 0
    warned: int = 0
    unaccounted: list[str] = field(default_factory=list)
    round_trip_differs: list[str] = field(default_factory=list)
    text: TextCount = field(default_factory=lambda: TextCount())
    comments_in: int = 0
    comments_lost: list[str] = field(default_factory=list)
    comments_warned: int = 0


@dataclass
class TextCount:
    """The source's statements against the written ``.src``'s, by text (see
    :func:`count_text`): ``found`` in the output as written, ``rewritten`` (olp lowered the
    statement, and the post writes it in its own spelling), ``lost``; ``routine_lines`` (DEF,
    END, ...) apart. The counters of rewritten and lost statements are by normalised text."""

    statements: int = 0
    found: int = 0
    rewritten: collections.Counter[str] = field(default_factory=collections.Counter)
    lost: collections.Counter[str] = field(default_factory=collections.Counter)
    routine_lines: int = 0
    routine_lines_lost: collections.Counter[str] = field(default_factory=collections.Counter)
    where_lost: list[str] = field(default_factory=list)  # ``file:line: text`` of each lost one


def construct_of(message: str, source_line: str | None) -> str:
    """The construct an :class:`~olp.errors.OlpError` stopped on: ``undeclared name`` (a name
    that a data list or the controller's $config.dat would declare), else the block a statement
    sits in, else the first keyword of the offending line, else the message's first words."""
    if "is not declared" in message:  # a data list or the controller's $config.dat is missing
        return "undeclared name"
    inside = _INSIDE.search(message)
    if inside:
        return inside.group(1).upper()
    words = _WORD.findall(source_line or "")
    for word in words[:3]:
        if word.upper() in _KEYWORDS:
            return word.upper()
    if words and "=" in (source_line or ""):
        return "assignment " + words[0].upper()
    return "other: " + " ".join(message.split()[:5])


_STRUCTURE = re.compile(
    r"(?i)((GLOBAL\s+)?(DEF|DEFFCT)|END|ENDFCT|ELSE|ENDIF|ENDWHILE|ENDLOOP|ENDFOR|ENDSWITCH|CASE|"
    r"DEFAULT|UNTIL)\b"
)
_ABSORBED = re.compile(
    r"(?i)(BAS\s*\(|(PDAT_ACT|LDAT_ACT|FDAT_ACT)\s*=|\$(VEL|VEL_AXIS|ACC|ACC_AXIS|APO|TOOL|BASE|"
    r"H_POS|IPO_MODE|ORI_TYPE|CIRC_TYPE)\b)"
)
_ROUTINE = re.compile(r"(?i)(GLOBAL\s+)?(DEF|DEFFCT)\b")
_CALL = re.compile(r"\s*([A-Za-z_][A-Za-z0-9_]*)\s*\(")


def statement_lines(text: str) -> dict[int, str]:
    """Line number -> text of the lines that hold a statement (not blank, not only a comment,
    not a header, not a line that only opens, divides or closes a routine or a block)."""
    found = {}
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split(";", 1)[0].strip()
        if line and not line.startswith("&") and not _STRUCTURE.match(line):
            found[number] = line
    return found


def account(text: str, src: str, result: object, tally: Tally) -> None:
    """Where every statement of the program went: kept (an IR node has its line), absorbed
    into the motions (inline-form data, BAS, $VEL/$TOOL/... settings), an inlined call, a
    warning, or unaccounted (lost without a word: the figure that must be 0)."""
    from olp.ir import RuntimeMove, is_motion
    from olp.ir_flow import leaves_and_blocks

    program = result.compiled.program  # type: ignore[attr-defined]

    def is_motion_with_settings(node: object) -> bool:  # a run-time motion's are written too
        runtime = isinstance(node, RuntimeMove) and not node.controller_settings
        return runtime or is_motion(node)  # type: ignore[arg-type]

    lines = statement_lines(text)
    nodes = [*program.params, *leaves_and_blocks(program.instructions)]
    kept = {n.span.line for n in nodes if n.span.file == src}
    nodes = list(leaves_and_blocks(program.instructions))
    motions = [n.span.line for n in nodes if is_motion_with_settings(n) and n.span.file == src]
    for routine in program.routines:  # the module's routines the program keeps, written out too
        nodes = [*routine.params, *routine.declarations, *leaves_and_blocks(routine.body)]
        kept.update(n.span.line for n in nodes if n.span.file == src)
        motions.extend(
            n.span.line for n in nodes if is_motion_with_settings(n) and n.span.file == src
        )
    # a setting is in the output only through a motion that runs with it (the posts write
    # $BASE, $VEL, ... before the motions): one after the module's last motion is lost
    last_motion = max(motions, default=0)
    warned = {
        d.span.line
        for d in result.diagnostics  # type: ignore[attr-defined]
        if d.span is not None and d.span.file == src and d.severity in ("warning", "error")
    }
    routines = {
        m.group(1).upper() for m in re.finditer(r"(?im)^\s*(?:GLOBAL\s+)?DEF\s+(\w+)", text)
    }
    starts = [n for n, raw in enumerate(text.splitlines(), start=1) if _ROUTINE.match(raw.strip())]
    # a warning at a routine's head covers its statements only when none of them is written
    written = {max((s for s in starts if s <= n), default=0) for n in kept}
    for number, line in lines.items():
        head = max((n for n in starts if n <= number), default=0)
        if head in warned and head not in written:  # a routine olp does not write at all
            warned.add(number)
        call = _CALL.match(line)
        tally.statements_in += 1
        if number in kept:
            tally.kept += 1
        elif _ABSORBED.match(line) and number < last_motion:
            tally.absorbed += 1
        elif call is not None and call.group(1).upper() in routines:
            tally.inlined += 1
        elif number in warned:
            tally.warned += 1
        else:
            tally.unaccounted.append(f"{src}:{number}: {line}")


_ROUTINE_LINE = re.compile(r"(?i)((GLOBAL\s+)?(DEF|DEFFCT)\b|(END|ENDFCT)$)")
_REWRITTEN = re.compile(
    r"(?i)(BAS\s*\(|(PDAT_ACT|LDAT_ACT|FDAT_ACT)\s*=|\$(VEL|VEL_AXIS|ACC|ACC_AXIS|APO|TOOL|BASE|"
    r"IPO_MODE|ORI_TYPE|CIRC_TYPE)\b)"
)
"""Statements olp absorbs into the motions' settings: the KUKA post writes ``$VEL_AXIS[i]``,
``$ACC_AXIS[i]``, ``$VEL.CP``, ``$ACC.CP``, ``$APO.CDIS``, ``$TOOL``, ``$BASE`` (and
``$ORI_TYPE``/``$CIRC_TYPE``) before the motion that runs with them instead of the inline
forms' ``PDAT_ACT=PPDAT1``, ``FDAT_ACT=FP1`` and ``BAS(#PTP_PARAMS,100)``."""
_MOTION = re.compile(r"(?i)(S?PTP|S?LIN|S?CIRC)(_REL)?\b")
_CODE = re.compile(r"""([^;"']|"[^"]*"|'[^']*')*""")
"""A line's code: up to a ``;`` outside a string or character constant."""


def normalised(line: str) -> str:
    """A statement's text as the count compares it: upper case, without blanks."""
    return re.sub(r"\s+", "", line).upper()


def text_statements(text: str) -> list[tuple[int, str]]:
    """(line number, text without its comment) of each line of a ``.src`` that holds code:
    not blank, not only a comment (fold lines are comments), not an ``&`` header."""
    found = []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = _CODE.match(raw).group(0).strip()  # type: ignore[union-attr]
        if line and not line.startswith("&"):
            found.append((number, line))
    return found


def lowered_lines(program: object, src: str) -> set[int]:
    """The lines of ``src`` that an IR node other than a kept line carries (a motion, an
    assignment, a block, the rows of a toolpath): the post writes them in its own spelling."""
    from olp.ir_flow import leaves_and_blocks

    nodes = list(leaves_and_blocks(program.instructions))  # type: ignore[attr-defined]
    for routine in program.routines:  # type: ignore[attr-defined]
        nodes.extend([*routine.params, *routine.declarations, *leaves_and_blocks(routine.body)])
    lines: set[int] = set()
    for node in nodes:
        if getattr(node, "kind", "") == "verbatim" or node.span.file != src:
            continue
        rows = getattr(node, "lines", None)  # a toolpath's rows carry a line each
        lines.update([node.span.line] if rows is None else (int(n) for n in rows))
    return lines


def count_text(text: str, src: str, result: object, count: TextCount) -> None:
    """KRL -> KRL by text: each statement of the source ``.src`` is ``found`` when the written
    ``.src`` holds a statement of the same normalised text (a multiset: each written statement
    matches once), else ``rewritten`` when olp lowered it (:func:`lowered_lines`, motions,
    :data:`_REWRITTEN`) or when written statements left over say the same in another spelling
    (numbers: ``WAIT SEC 0`` as ``WAIT SEC 0.000``, :func:`same_numbers`; a declaration:
    ``INT a, b`` as ``DECL INT a`` and ``DECL INT b``, :func:`declared_items`), else ``lost``.
    DEF/DEFFCT/END/ENDFCT lines are counted apart."""
    written: collections.Counter[str] = collections.Counter()
    spelt: dict[str, str] = {}  # normalised text -> with its numbers in one spelling
    files = result.files  # type: ignore[attr-defined]
    for name in (n for n in files if n.lower().endswith(".src")):
        for _, line in text_statements(files[name]):
            written[normalised(line)] += 1
            spelt.setdefault(normalised(line), same_numbers(line))
    lowered = lowered_lines(result.compiled.program, src)  # type: ignore[attr-defined]
    unmatched = []
    for number, line in text_statements(text):  # first what is written as read
        key = normalised(line)
        routine = _ROUTINE_LINE.match(line) is not None
        count.routine_lines += routine
        count.statements += not routine
        if written[key] > 0:
            written[key] -= 1
            count.found += not routine
        elif routine:
            count.routine_lines_lost[key] += 1
            count.where_lost.append(f"{src}:{number}: {line.strip()[:100]}")
        else:
            unmatched.append((number, line))
    # then what the post writes in its own spelling, from the written statements left over
    numbers: collections.Counter[str] = collections.Counter()
    for key, left in written.items():
        numbers[spelt[key]] += left
    untils = collections.Counter(_bare(k) for k, n in numbers.items() for _ in range(n))
    for number, line in unmatched:
        lowered_here = number in lowered or _REWRITTEN.match(line) or _MOTION.match(line)
        until = _UNTIL.match(line) is not None and _take(untils, [_bare(same_numbers(line))])
        if lowered_here or until or _respelt(numbers, line):
            count.rewritten[_kind(line)] += 1
        else:
            count.lost[normalised(line)] += 1
            count.where_lost.append(f"{src}:{number}: {line.strip()[:100]}")


_UNTIL = re.compile(r"(?i)\s*UNTIL\b")


def _bare(key: str) -> str:
    """A REPEAT's condition without parentheses: the post writes the condition it parsed with
    the parentheses its operators need (``UNTIL (a==TRUE)`` as ``UNTIL a == TRUE``), and the
    UNTIL line carries no span of its own in the IR (the REPEAT's is the block's)."""
    return key.replace("(", "").replace(")", "")


def _respelt(left: collections.Counter[str], line: str) -> bool:
    """Whether statements ``left`` over in the written file say ``line`` in another spelling
    (they are taken): its numbers otherwise written, or its declaration item by item."""
    return _take(left, [same_numbers(line)]) or _take(left, declared_items(line))


def _take(left: collections.Counter[str], keys: list[str]) -> bool:
    """Take one of each of ``keys`` from ``left`` if all are there (and not none)."""
    need = collections.Counter(keys)
    if not need or any(left[key] < number for key, number in need.items()):
        return False
    left.subtract(need)
    return True


_DECLARATION = re.compile(r"(?i)\s*(?:DECL\s+)?((?:GLOBAL\s+|CONST\s+)*[A-Za-z_$][\w$]*)\s+(.+)")
_TOP_COMMA = re.compile(r",(?![^\[]*\])")
"""A comma outside brackets: between a declaration's items, not in ``a[2,3]``."""


def declared_items(line: str) -> list[str]:
    """A declaration of items without values (``INT a, b``, ``DECL E6POS p1, p2``) as the
    one-item declarations that say the same, in :func:`same_numbers` text (``DECL INT a``,
    ``DECL INT b``); [] for any other line."""
    match = _DECLARATION.fullmatch(line.strip())
    if match is None or "=" in line or "{" in line:
        return []
    items = [item.strip() for item in _TOP_COMMA.split(match.group(2))]
    return [same_numbers(f"DECL {match.group(1)} {item}") for item in items if item]


_NUMBER = re.compile(r"(?i)(?<![\w$.])(\d+\.?\d*|\.\d+)(e[+-]?\d+)?(?![\w$.])")
_QUOTED = re.compile(r'("[^"]*")')


def same_numbers(line: str) -> str:
    """:func:`normalised` text with each number in one spelling (``0.000`` and ``0`` as ``0``,
    ``2.0`` as ``2``), strings left as they are: two statements that differ only in how their
    numbers are written get the same text."""
    parts = _QUOTED.split(line)
    for index in range(0, len(parts), 2):  # the even parts are outside strings
        parts[index] = _NUMBER.sub(lambda m: f"{float(m.group(0)):.12g}", parts[index])
    return normalised("".join(parts))


def _kind(line: str) -> str:
    """What a rewritten statement is, for the listing: its first word (``PTP``, ``BAS``,
    ``PDAT_ACT``, ``$VEL_AXIS``), or ``assignment`` / ``call`` for the rest."""
    word = _WORD.match(line.strip())
    first = word.group(0).upper() if word else line[:12]
    rest = line.strip()[len(first) :].lstrip()
    if first in _KEYWORDS or _STRUCTURE.match(first) or first.startswith("$") or "_ACT" in first:
        return first
    return "call" if rest.startswith("(") else "assignment"


def comment_texts(text: str) -> list[tuple[int, str]]:
    """The comments of a KRL text with their lines (what follows the first ``;`` outside a
    string on each line that is no ``&`` header), stripped, the characters outside ASCII as
    ``?`` (the KUKA post writes ASCII)."""
    from olp.frontends.krl.comments import comment_column

    found = []
    for number, raw in enumerate(text.splitlines(), start=1):
        column = comment_column(raw)
        if column is not None:
            comment = raw[column + 1 :].strip().encode("ascii", "replace").decode()
            found.append((number, comment))
    return found


def decoded(data: bytes) -> str:
    """A file's text as olp reads it: UTF-8, else Windows-1252, else Latin-1."""
    from olp.frontends.krl import _decode

    return _decode(data)


def _unwritten_routines(text: str, src: str, result: object) -> list[tuple[int, int]]:
    """The line ranges of the routines olp left out with a warning at their head (no IR node
    of theirs in the program): their comments go with their statements."""
    from olp.ir_flow import leaves_and_blocks

    program = result.compiled.program  # type: ignore[attr-defined]
    nodes = [*program.instructions, *(n for r in program.routines for n in r.body)]
    kept = {n.span.line for n in leaves_and_blocks(nodes) if n.span.file == src}
    warned = {
        d.span.line
        for d in result.diagnostics  # type: ignore[attr-defined]
        if d.span is not None and d.span.file == src and d.severity in ("warning", "error")
    }
    starts = [n for n, raw in enumerate(text.splitlines(), start=1) if _ROUTINE.match(raw.strip())]
    ends = [*starts[1:], len(text.splitlines()) + 1]
    return [
        (start, end)
        for start, end in zip(starts, ends, strict=True)
        if start in warned and not any(start < line < end for line in kept)
    ]


def count_comments(text: str, written: str, src: str, result: object, tally: Tally) -> None:
    """Comments and fold lines of the source that the written .src lacks (each text counted as
    often as it occurs; the post's own comments, the header, tool and base names, do not
    make up for a lost one of the source's), but for those of a routine olp left out with a
    warning (``comments_warned``)."""
    source = comment_texts(text)
    left = collections.Counter(comment for _, comment in comment_texts(written))
    unwritten = _unwritten_routines(text, src, result)
    tally.comments_in += len(source)
    for line, comment in source:
        if any(start <= line < end for start, end in unwritten):
            tally.comments_warned += 1
        elif left[comment] > 0:
            left[comment] -= 1
        else:
            tally.comments_lost.append(f"{src}:{line}: ;{comment[:60]}")


def find_config(folder: Path) -> Path | None:
    found = sorted(p for p in folder.rglob("*") if p.name.lower() == "$config.dat")
    return found[0] if found else None


def _public_lists(folder: Path) -> tuple[object, ...]:
    """The PUBLIC data lists under ``folder``, read once: the controller finds their GLOBAL
    names for every module (a bad one is skipped with a line on stderr)."""
    from olp.errors import OlpError
    from olp.frontends.krl import find_data_lists, parse_dat

    lists = []
    for path in find_data_lists(folder):
        try:
            data = parse_dat(path.read_bytes().decode("utf-8", "replace"), str(path))
        except OlpError as exc:
            print(f"data list unreadable, skipped: {exc.message}", file=sys.stderr)
            continue
        lists.extend([data] if data.public else [])
    return tuple(lists)


def run(folder: Path, station_path: Path, config: Path | None, post: str, verbose: bool) -> Tally:
    """Build every ``.src`` under ``folder`` with ``config`` and the folder's public lists."""
    import olp

    tally = Tally()
    run_backup(folder, olp.load_station(station_path), config, post, verbose, tally)
    return tally


def run_backup(  # type: ignore[no-untyped-def]
    folder: Path, station, config: Path | None, post: str, verbose: bool, tally: Tally
) -> None:
    """Add the ``.src`` files of one controller backup to ``tally``."""
    import olp
    from olp.errors import OlpError
    from olp.frontends.bundled import KrlOptions
    from olp.frontends.krl import load_config_dat

    config_data = None
    if config is not None:
        try:
            config_data = load_config_dat(config)
        except OlpError as exc:
            print(f"config-dat unreadable, built without it: {exc.message}", file=sys.stderr)
            print(f"  {exc.span}: {(exc.source_line or '').strip()[:80]}", file=sys.stderr)
    options = KrlOptions(config_dat=config_data, data_lists=_public_lists(folder))
    for path in sorted(p for p in folder.rglob("*") if p.suffix.lower() == ".src"):
        verdict = _one(olp, path, station, options, post, tally, OlpError)
        tally.classes[verdict.split(":")[0]] += 1
        if verbose:
            print(f"{path.relative_to(folder)}: {verdict}")


def run_backups(folder: Path, station_path: Path, post: str, verbose: bool) -> Tally:
    """Each folder directly under ``folder`` is one backup: its own ``$config.dat`` and data
    lists; a line per backup (files, build, program-level stops) and the sum."""
    import olp

    station = olp.load_station(station_path)
    tally = Tally()
    for backup in sorted(p for p in folder.iterdir() if p.is_dir()):
        before = collections.Counter(tally.classes)
        run_backup(backup, station, find_config(backup), post, verbose, tally)
        mine = tally.classes - before
        total = sum(mine.values())
        if total:
            known = mine["build"] + mine["program"] + mine["invalid"]
            print(
                f"  backup {backup.name}: {total} files, {mine['build']} build, "
                f"{mine['program']} program, {mine['invalid']} invalid KRL, "
                f"{total - known} other"
            )
    return tally


def _fault(message: str) -> str:
    """What an invalid-KRL error says is wrong, without the file's own names and lines: its
    words up to the first ':' or ';', numbers as ``N`` (``a bare name is not a KRL statement``,
    ``the '(' at column N is not closed``)."""
    return re.sub(r"\d+", "N", re.split(r"[:;] ", message, maxsplit=1)[0].strip())


def _one(olp, path, station, options, post, tally, olp_error) -> str:  # type: ignore[no-untyped-def]
    from olp.errors import INVALID_KRL

    try:
        result = olp.build(station, path, post=post, program_options=options, collisions=None)
    except olp_error as exc:
        if exc.code == INVALID_KRL:  # not olp's gap: the controller refuses the file too
            tally.constructs[f"invalid KRL: {_fault(exc.message)}"] += 1
            return f"invalid: {exc.message} ({exc.span})"
        construct = construct_of(exc.message, exc.source_line)
        tally.constructs[construct] += 1
        return f"syntax: {construct} ({exc.span})"
    except Exception as exc:  # a crash is what this benchmark exists to find
        tally.crashes.append(f"{path.name}: {type(exc).__name__}: {exc}")
        return f"crash: {type(exc).__name__}"
    src = str(path)  # data lists' lines (types, declarations) are not statements of the program
    drops = [d for d in result.diagnostics if d.kind == "ignored" and d.span and d.span.file == src]
    tally.silent_drops += sum(d.severity == "info" for d in drops)
    tally.warned_drops += sum(d.severity != "info" for d in drops)
    if not result.ok:
        errors = [d for d in result.diagnostics if d.severity == "error"]
        unwritable = [d for d in errors if d.kind in POST_KINDS]
        if unwritable:
            tally.constructs[f"post: {unwritable[0].kind}"] += 1
            return f"post: {unwritable[0].kind}"
        return f"program: {errors[0].kind}"
    text = path.read_text(encoding="latin-1")
    account(text, src, result, tally)
    if post == "kuka":
        count_text(text, src, result, tally.text)
        (written,) = [t for n, t in result.files.items() if n.lower().endswith(".src")]
        count_comments(decoded(path.read_bytes()), written, src, result, tally)
        try:
            same = round_trips(result, options)
        except olp_error as exc:  # the written KRL does not read again: a fault of olp's
            tally.round_trip_differs.append(f"{path.name}: read again: {exc.message[:160]}")
            return "build: KRL -> KRL does not read again"
        if not same:
            tally.round_trip_differs.append(path.name)
            return "build: KRL -> KRL differs"
    return "build"


def shape(program: object) -> list[str]:
    """The statements and blocks of a program in order, declarations apart (KRL wants them
    first): motions and other statements by kind, kept lines by their text."""
    from olp.ir_flow import leaves_and_blocks

    out = []
    from olp.frontends.krl.native import is_ini_line

    for node in leaves_and_blocks(program.instructions):  # type: ignore[attr-defined]
        if node.kind == "comment" or is_ini_line(node):  # (comments: comments_lost)
            continue
        if node.kind == "verbatim":
            out.append(node.text.upper().replace(" ", ""))
        elif node.kind != "declare":
            out.append(node.kind)
    return out


def round_trips(result: object, options: object) -> bool:
    """KRL -> KRL keeps every statement: the written .src, read again (with the same
    ``$config.dat`` and the other modules' data lists), lowers to the same statements in the
    same order as the source did. A written file olp cannot read again counts as differing."""
    import tempfile

    from olp.frontends.krl import load_krl

    files = result.files  # type: ignore[attr-defined]
    with tempfile.TemporaryDirectory() as scratch:
        for name, text in files.items():
            (Path(scratch) / name).write_text(text, encoding="latin-1")
        (written,) = [n for n in files if n.lower().endswith(".src")]
        config = options.config_dat  # type: ignore[attr-defined]
        # the other modules' data lists as the build had them; the module's own is written
        stem = Path(written).stem.lower()
        lists = [d for d in options.data_lists if Path(d.filename).stem.lower() != stem]  # type: ignore[attr-defined]
        again = load_krl(Path(scratch) / written, config, data_lists=lists).program
    # the compiled program is the analysis view (each call holds its routine's body): so is this
    return shape(again.expanded()) == shape(result.compiled.program)  # type: ignore[attr-defined]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folder", nargs="?", type=Path, default=CORPUS)
    parser.add_argument("--station", type=Path, default=STATION)
    parser.add_argument("--config-dat", type=Path, default=None)
    parser.add_argument("--post", default="kuka")
    parser.add_argument("--backups", action="store_true", help="each subfolder is one backup")
    parser.add_argument("-v", "--verbose", action="store_true")
    parser.add_argument(
        "--lost", action="store_true", help="list each statement lost in the KRL text"
    )
    args = parser.parse_args()
    start = time.perf_counter()
    if args.backups:
        tally = run_backups(args.folder, args.station, args.post, args.verbose)
    else:
        config = args.config_dat or find_config(args.folder)
        tally = run(args.folder, args.station, config, args.post, args.verbose)
    seconds = time.perf_counter() - start
    total = sum(tally.classes.values())
    for construct, count in tally.constructs.most_common():
        print(f"  stops on {construct}: {count}")
    for crash in tally.crashes:
        print(f"  crash {crash}")
    ok = tally.classes["build"] + tally.classes["program"]
    print(f"files: {total} files")
    print(f"build: {tally.classes['build']} files")
    print(f"program: {tally.classes['program']} files")
    print(f"invalid: {tally.classes['invalid']} files")
    print(f"syntax: {tally.classes['syntax']} files")
    print(f"post: {tally.classes['post']} files")
    print(f"crash: {tally.classes['crash']} files")
    print(f"build_or_program: {100.0 * ok / max(total, 1):.1f} %")
    ok_or_invalid = ok + tally.classes["invalid"]
    print(f"build_program_or_invalid: {100.0 * ok_or_invalid / max(total, 1):.1f} %")
    print(f"silent_drops: {tally.silent_drops} statements")
    print(f"warned_drops: {tally.warned_drops} statements")
    for line in tally.unaccounted:
        print(f"  unaccounted {line}")
    print(f"statements_in: {tally.statements_in} statements")
    print(f"statements_kept: {tally.kept} statements")
    print(f"statements_absorbed: {tally.absorbed} statements")
    print(f"statements_inlined_calls: {tally.inlined} statements")
    print(f"statements_warned: {tally.warned} statements")
    print(f"statements_unaccounted: {len(tally.unaccounted)} statements")
    for name in tally.round_trip_differs:
        print(f"  KRL -> KRL differs {name}")
    print(f"krl_round_trip_differs: {len(tally.round_trip_differs)} files")
    print_text_count(tally.text, args.verbose)
    if args.lost:
        for where in tally.text.where_lost:
            print(f"  lost at {where}")
    for line in tally.comments_lost[:20]:
        print(f"  comment lost {line}")
    print(f"comments_in: {tally.comments_in} lines")
    print(f"comments_warned: {tally.comments_warned} lines")
    print(f"comments_lost: {len(tally.comments_lost)} lines")
    print(f"seconds: {seconds:.2f} s")


def print_text_count(count: TextCount, verbose: bool) -> None:
    """The figures of :func:`count_text` (with ``verbose``: the texts lost most often and
    what was rewritten, by kind)."""
    if verbose:
        for kind, number in count.rewritten.most_common():
            print(f"  rewritten {number} x {kind}")
        for text, number in count.lost.most_common(40):
            print(f"  lost {number} x {text[:100]}")
        for text, number in count.routine_lines_lost.most_common(10):
            print(f"  routine line lost {number} x {text[:100]}")
    print(f"statements_text_in: {count.statements} statements")
    print(f"statements_text_found_krl: {count.found} statements")
    print(f"statements_rewritten_krl: {sum(count.rewritten.values())} statements")
    print(f"statements_lost_krl: {sum(count.lost.values())} statements")
    print(f"routine_lines_in: {count.routine_lines} lines")
    print(f"routine_lines_lost_krl: {sum(count.routine_lines_lost.values())} lines")


if __name__ == "__main__":
    main()
