"""The comments of a KRL module, put in place among its statements.

The grammar reads a comment as part of a line break (``_NL``), so the parse tree has none. This
module finds them in the text (:func:`scan`: a ``;`` outside a string, on a line that is no
``&`` header) and :func:`attach` inserts each into the AST as a
:class:`~olp.frontends.krl.ast.CommentStmt` where it stands, at every level: a routine's body,
the bodies of IF/ELSE, SWITCH's CASEs and DEFAULT, WHILE, LOOP, REPEAT, FOR and SPLINE. Both
reading paths (the full grammar and the fast path of :mod:`olp.frontends.krl.fast`) give the
same statements with the same lines, so the comments land in the same places.

Where a comment goes:

* a comment on a line of its own goes between the statements around it, into the innermost
  body whose lines hold it (a body runs from its header line, ``IF``/``ELSE``/``CASE``/``FOR``
  ..., to the next header or the block's closing line); one between ``SWITCH`` and its first
  ``CASE`` goes at the start of the first case;
* a comment at the end of a statement's line comes right after that statement; at the end of
  a block's header line it starts that body, at the end of its closing line (``ENDIF ; x``) it
  comes after the block; at the end of ``DEF``/``END`` it starts/ends the routine;
* comments before the first routine start that routine, comments between two routines start
  the next one, comments after the last one end it; comments inside a ``DEFDAT`` are data, not
  program, and stay out.

A fold line is a comment whose text starts with ``FOLD`` or ``ENDFOLD`` right after the ``;``
(how the pendant writes them; ``; FOLD`` with a blank is an ordinary comment): its text is
kept as written so that the KRL post writes the fold back unchanged.

Cost: nothing for a file without ``;``; otherwise one pass over the text with ``str.find``
(C speed) plus a short Python look at each line holding a ``;``, so a million-line toolpath
with a few comments reads as fast as one without.
"""

from __future__ import annotations

import dataclasses
import re
import unicodedata
from collections.abc import Sequence

from olp import ir
from olp.frontends.krl.ast import (
    Block,
    CommentStmt,
    DatBlock,
    ForLoop,
    LinRows,
    Module,
    Routine,
    Source,
    Stmt,
)

_FOLD = re.compile(r"(END)?FOLD\b", re.IGNORECASE)
_END = re.compile(r"[ \t]*END(FCT|DAT)?\b", re.IGNORECASE)


def scan(source: Source) -> list[CommentStmt]:
    """Every comment of ``source`` in line order (at most one per line: the rest of the line
    after the first ``;`` outside a string)."""
    text = source.text
    found: list[CommentStmt] = []
    position, line = 0, 1
    while True:
        hit = text.find(";", position)
        if hit < 0:
            return found
        line += text.count("\n", position, hit)
        start = text.rfind("\n", 0, hit) + 1
        end = text.find("\n", hit)
        end = len(text) if end < 0 else end
        column = comment_column(text[start:end])
        if column is not None:
            found.append(_comment(text[start + column + 1 : end], line, column + 1, source))
        position = end


def comment_column(line: str) -> int | None:
    """The 0-based index of the ``;`` that starts ``line``'s comment, or None (no comment, or
    an ``&`` header line, which holds any text)."""
    if line.lstrip().startswith("&"):
        return None
    quoted = False
    for index, char in enumerate(line):
        if char == '"':
            quoted = not quoted
        elif char == ";" and not quoted:
            return index
    return None


def _comment(raw: str, line: int, column: int, source: Source) -> CommentStmt:
    span = ir.SourceSpan(source.filename, line, column, line, column + 1 + len(raw))
    text = _printable(raw.rstrip())
    fold = _FOLD.match(text)
    if fold is None:
        return CommentStmt(text.strip(), None, span)
    return CommentStmt(text, "close" if fold.group(1) else "open", span)  # as written


def _printable(text: str) -> str:
    """``text`` with each control character but the tab as ``?``: a comment is one line."""
    if text.isprintable():
        return text
    return "".join(
        "?" if unicodedata.category(c) in ("Cc", "Zl", "Zp") and c != "\t" else c for c in text
    )


# ------------------------------------------------------------------------------------------------
# Placing comments in the AST


def attach(module: Module, source: Source) -> Module:
    """``module`` with the comments of ``source`` (:func:`scan`) among its routines'
    statements (see the module's docstring for where each goes)."""
    if ";" not in source.text:
        return module
    comments = scan(source)
    if not comments:
        return module
    code = _CodeLines(source.lines)
    datas = [(d.span.line, code.routine_end(d.span.end_line or d.span.line)) for d in _dats(module)]
    comments = [c for c in comments if not any(lo <= c.span.line <= hi for lo, hi in datas)]
    routines = [item for item in module.items if isinstance(item, Routine)]
    if not routines or not comments:
        return module
    placed: dict[int, Routine] = {}
    remaining = comments
    for number, routine in enumerate(routines):
        end = code.routine_end(routine.span.end_line or routine.span.line)
        mine = [c for c in remaining if c.span.line <= end or number == len(routines) - 1]
        remaining = remaining[len(mine) :]
        placed[id(routine)] = _place_routine(routine, mine, end, code)
    items = tuple(placed.get(id(item), item) for item in module.items)
    return dataclasses.replace(module, items=items)


def _dats(module: Module) -> list[DatBlock]:
    return [item for item in module.items if isinstance(item, DatBlock)]


def _place_routine(
    routine: Routine, comments: Sequence[CommentStmt], end: int, code: _CodeLines
) -> Routine:
    """The routine with ``comments``: those before its ``DEF`` line first, those after its
    ``END`` line last, the others in place."""
    if not comments:
        return routine
    first = routine.span.line
    before = [c for c in comments if c.span.line < first]
    after = [c for c in comments if c.span.line > end]
    inside = [c for c in comments if first <= c.span.line <= end]
    body = _place(routine.body, inside, code)
    return dataclasses.replace(routine, body=(*before, *body, *after))


def _place(
    body: Sequence[Stmt], comments: Sequence[CommentStmt], code: _CodeLines
) -> tuple[Stmt, ...]:
    """``body`` with ``comments`` (all within the body's lines, in line order) in place."""
    if not comments:
        return tuple(body)
    out: list[Stmt] = []
    index, count = 0, len(comments)
    for stmt in body:
        first, last = _lines_of(stmt)
        while index < count and comments[index].span.line < first:
            out.append(comments[index])
            index += 1
        inner: list[CommentStmt] = []
        while index < count and comments[index].span.line <= last:
            inner.append(comments[index])
            index += 1
        if inner and isinstance(stmt, Block | ForLoop):
            closing = [c for c in inner if c.span.line == last]  # after ENDIF, ENDFOR, UNTIL ...
            opened = [c for c in inner if c.span.line < last]
            out.append(_place_block(stmt, opened, code))
            out.extend(closing)
        else:
            out.append(stmt)
            out.extend(inner)  # at the end of the statement's line
    out.extend(comments[index:])
    return tuple(out)


def _place_block(
    stmt: Block | ForLoop, comments: Sequence[CommentStmt], code: _CodeLines
) -> Block | ForLoop:
    """The block with ``comments`` (on its lines before the closing one) in its bodies."""
    if not comments:
        return stmt
    if isinstance(stmt, ForLoop):
        return dataclasses.replace(stmt, body=_place(stmt.body, comments, code))
    heads = _heads(stmt, code)
    bodies = []
    for number, body in enumerate(stmt.bodies):
        head = heads[number]
        later = [h for h in heads[number + 1 :] if h is not None]
        if head is None:  # an IF without ELSE, a SWITCH without DEFAULT: nothing of the source
            bodies.append(body)
            continue
        stop = later[0] if later else None
        start = head if number else (heads[0] or head)  # SWITCH: comments before the CASEs
        mine = [
            c for c in comments if c.span.line >= start and (stop is None or c.span.line < stop)
        ]
        bodies.append(_place(body, mine, code))
    return dataclasses.replace(stmt, bodies=tuple(bodies))


def _heads(stmt: Block, code: _CodeLines) -> list[int | None]:
    """The header line of each of the block's bodies (None: a body the source does not write,
    the empty ELSE of an IF without one). For a SWITCH the first is the SWITCH line itself, so
    that comments before the first CASE go into the first case."""
    heads: list[int | None] = [stmt.span.line]
    previous_end = _body_end(stmt.bodies[0], stmt.span.line)
    if stmt.keyword == "SWITCH":
        previous_end = stmt.span.line
        heads = []
        for number, body in enumerate(stmt.bodies):
            written = number < len(stmt.bodies) - 1 or stmt.has_else
            head = code.first_after(previous_end) if written else None
            heads.append(head)
            if head is not None:
                previous_end = _body_end(body, head)
        if heads and heads[0] is not None:
            heads[0] = stmt.span.line
        return heads
    for body in stmt.bodies[1:]:  # IF's ELSE
        head = code.first_after(previous_end) if stmt.has_else else None
        heads.append(head)
        if head is not None:
            previous_end = _body_end(body, head)
    return heads


def _body_end(body: Sequence[Stmt], head: int) -> int:
    """The last line of ``body``'s statements (its header line if it has none)."""
    return max((_lines_of(s)[1] for s in body), default=head)


def _lines_of(stmt: Stmt) -> tuple[int, int]:
    """The first and last line of a statement (a block's closing line; a toolpath's last row)."""
    if isinstance(stmt, LinRows):
        return stmt.span.line, int(stmt.lines[-1])
    span = stmt.span
    return span.line, max(span.line, span.end_line or span.line)


class _CodeLines:
    """The source's lines that hold code (not blank, not only a comment)."""

    def __init__(self, lines: Sequence[str]) -> None:
        self._lines = lines

    def _is_code(self, number: int) -> bool:
        text = self._lines[number - 1].strip()
        return bool(text) and not text.startswith(";")

    def first_after(self, line: int) -> int:
        """The first code line after ``line`` (past the end: the line after the last)."""
        number = line + 1
        while number <= len(self._lines) and not self._is_code(number):
            number += 1
        return number

    def routine_end(self, line: int) -> int:
        """The ``END``/``ENDFCT``/``ENDDAT`` line at or before ``line`` (a routine's span runs
        on over the comment lines after its END, up to the next code line)."""
        number = min(line, len(self._lines))
        while number > 1 and not _END.match(self._lines[number - 1]):
            number -= 1
        return number
