"""What KRL -> KRL must keep, for the round-trip tests: the statements in order, and the
source's comments and folds in order among the comments the KRL post writes (it adds its own:
the header, the names of tools and bases, its template's INI fold where the source has none)."""

from __future__ import annotations

from collections.abc import Iterable

from olp import ir
from olp.frontends.krl.native import is_ini_line
from olp.ir_flow import leaves_and_blocks


def statements(nodes: Iterable[ir.Node]) -> list[ir.Node]:
    """``nodes`` without comments and without the INI lines the KRL post writes from its
    template where the source has none (read back, they are the program's)."""
    return [n for n in nodes if n.kind != "comment" and not is_ini_line(n)]


def comment_lines(program: ir.Program) -> list[str]:
    """The comments of the program and its routines in order, as KRL lines (a fold as read)."""
    nodes = [*program.instructions, *(n for r in program.routines for n in r.body)]
    found = [n for n in leaves_and_blocks(nodes) if isinstance(n, ir.Comment)]
    return [(";" if n.fold else "; ") + n.text for n in found]


def keeps_in_order(written: list[str], source: list[str]) -> bool:
    """Whether every line of ``source`` is in ``written``, in the same order."""
    lines = iter(written)
    return all(any(line == want for line in lines) for want in source)
