"""Control flow for posts that write it (``Post.WRITES_FLOW``): the blocks of the program woven
into a file's flat list of :class:`~olp.posts.view.PostStep`\\ s as marker steps.

A template keeps walking one list, ``steps``; besides the instructions it meets markers whose
``kind`` opens, divides or closes a block, with the block as ``instruction``:

==========  ===========================================================
``if``      ``instruction.branches[0].condition`` (olp's KRL lowering makes one branch;
            further branches come as ``elif`` markers with ``instruction`` the branch)
``else``    the If (only when it has an else body)
``end_if``  the If
``switch``  ``instruction.subject``; ``case`` markers carry the Case (``values``);
            ``default`` (only when the default body is not empty); ``end_switch``
``while``   ``instruction.condition``; ``end_while``
``repeat``  ``until`` (``instruction.until``)
``loop``    ``end_loop``
``for``     ``instruction.variable``, ``start``, ``stop``, ``step``; ``end_for``
==========  ===========================================================

A call of one of the program's routines is the marker ``routine_call`` (``instruction``: the
:class:`olp.ir.RoutineCall`); the routine's own steps come from :func:`weave_routines`.

Declarations (kind ``declare``) are moved to the front, once per name (a routine inlined twice
declares its variables twice), because languages such as KRL want them before any statement.

Modal settings: a template writes ``$TOOL``, speeds and zones only when they change from the
previous motion *in the text*; after a block boundary the previous motion in the text need not
be the one that ran, so the first motion of each kind after any marker or label gets every
``new_*`` flag set, and templates should forget their own trackers there
(``modal.forget(...)``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator, Sequence
from typing import Any

from olp import ir
from olp.ir_flow import bodies, leaves
from olp.posts.view import PostStep

_CLOSERS = {
    ir.While: "end_while",
    ir.Loop: "end_loop",
    ir.For: "end_for",
}


def weave(
    program: ir.Program, steps: Sequence[PostStep], empty_arms: bool = False
) -> list[PostStep]:
    """``steps`` (one per instruction, in the order iterating ``program`` gives) with the
    program's block markers woven in and the declarations first; see the module docstring.
    A routine's body expanded at a call (:class:`olp.ir.Expanded`) is the one marker
    ``routine_call`` (``instruction``: the :class:`olp.ir.RoutineCall`); its steps are the
    routine's (:func:`weave_routines`). ``empty_arms``: write the else and default arms the
    source wrote empty (:attr:`olp.ir.If.has_else`; a post of the program's own language)."""
    by_index = {s.index: s for s in steps}
    return _ordered(list(_Weaver(by_index, empty_arms=empty_arms).nodes(program.instructions)))


def _ordered(body: list[PostStep], fresh: bool = False) -> list[PostStep]:
    declared: dict[str, PostStep] = {}
    for step in body:
        if step.kind == "declare":
            declared.setdefault(step.instruction.name.upper(), step)
    rest = [s for s in body if s.kind != "declare"]
    return [*declared.values(), *_fresh_after_boundaries(rest, fresh)]


@dataclasses.dataclass(frozen=True, slots=True)
class RoutineSteps:
    """A routine as a template writes it: ``routine`` (the :class:`olp.ir.Routine`: name,
    parameters, declarations, result type) and ``steps``, its body woven like the program's
    (the steps of its first call site; every setting written at its first motion, since the
    routine cannot rely on its caller's)."""

    routine: ir.Routine
    steps: Sequence[Any]


def routine_statements(routines: Sequence[RoutineSteps]) -> list[PostStep]:
    """The steps of ``routines``, each routine's parameters (of a known type) and local
    declarations first as ``declare`` steps (index -1): what a post's ``context_values``
    needs to know of the names and types its routines use."""
    out: list[PostStep] = []
    for item in routines:
        routine = item.routine
        params = [
            ir.Declare(name=p.name, type_name=p.type_name, dims=p.dims, span=p.span)
            for p in routine.params
            if p.type_name
        ]
        for decl in [*params, *routine.declarations]:
            out.append(PostStep(-1, "declare", decl.span.location, decl))
        out += [s for s in item.steps if isinstance(s, PostStep)]
    return out


def expansions(program: ir.Program) -> dict[str, list[tuple[ir.Expanded, int]]]:
    """Upper-case routine name -> every :class:`olp.ir.Expanded` of it in ``program`` (the
    analysis view) with the index of its first instruction, in program order."""
    found: dict[str, list[tuple[ir.Expanded, int]]] = {}
    cursor = 0

    def walk(nodes: Sequence[Any]) -> None:
        nonlocal cursor
        for node in nodes:
            if isinstance(node, ir.Expanded):
                found.setdefault(node.call.name.upper(), []).append((node, cursor))
            if isinstance(node, ir.BLOCK_TYPES):
                for body in bodies(node):
                    walk(body)
            else:
                cursor += len(node) if isinstance(node, ir.LinearPath) else 1

    walk(program.instructions)
    return found


def weave_routines(
    program: ir.Program, steps: Sequence[PostStep], lines: Any, empty_arms: bool = False
) -> list[RoutineSteps]:
    """The program's routines with their steps (:class:`RoutineSteps`), in the program's
    order. A routine no call expands (a function, an interrupt handler) holds no motion: its
    statements get steps of their own (index -1; ``lines`` makes a comment's lines)."""
    by_index = {s.index: s for s in steps}
    sites = expansions(program)
    out = []
    for routine in program.routines:
        found = sites.get(routine.name.upper())
        weaver = _Weaver(by_index, lines, empty_arms)
        if found:
            node, weaver.cursor = found[0]
            body = list(weaver.nodes(node.body))
        else:
            weaver.alone = True
            body = list(weaver.nodes(routine.body))
        out.append(RoutineSteps(routine, _ordered(body, fresh=True)))
    return out


class _Weaver:
    def __init__(
        self, by_index: dict[int, PostStep], lines: Any = None, empty_arms: bool = False
    ) -> None:
        self.by_index = by_index
        self.empty_arms = empty_arms  # write an else/default arm the source left empty
        self.cursor = 0
        self.lines = lines
        self.alone = False  # a routine without steps: its statements become steps here

    def nodes(self, nodes: Sequence[Any]) -> Iterator[PostStep]:
        for node in nodes:
            if isinstance(node, ir.Expanded):
                if not node.entry:  # an entry is no call: its routine is written on its own
                    yield _marker("routine_call", node.call, node.span)
                self.cursor += sum(
                    len(n) if isinstance(n, ir.LinearPath) else 1 for n in leaves(node.body)
                )
            elif isinstance(node, ir.BLOCK_TYPES):
                yield from self.block(node)
            elif self.alone:
                yield self.own(node)
            elif isinstance(node, ir.LinearPath):
                for _ in range(len(node)):
                    yield from self.leaf()
            else:
                yield from self.leaf()

    def leaf(self) -> Iterator[PostStep]:
        step = self.by_index.get(self.cursor)
        self.cursor += 1
        if step is not None:
            yield step

    def own(self, node: Any) -> PostStep:
        """A step for a statement of a routine no call expands (never a motion)."""
        if isinstance(node, ir.RoutineCall):
            return _marker("routine_call", node, node.span)
        comment = tuple(self.lines(node)) if node.kind == "comment" and self.lines else ()
        return PostStep(-1, node.kind, node.span.location, node, comment=comment)

    def block(self, node: Any) -> Iterator[PostStep]:
        if isinstance(node, ir.If):
            for k, branch in enumerate(node.branches):
                yield _marker("if" if k == 0 else "elif", node if k == 0 else branch, branch.span)
                yield from self.nodes(branch.body)
            if node.orelse or (node.has_else and self.empty_arms):
                yield _marker("else", node, node.span)
                yield from self.nodes(node.orelse)
            yield _marker("end_if", node, node.span)
        elif isinstance(node, ir.Switch):
            yield _marker("switch", node, node.span)
            for case in node.cases:
                yield _marker("case", case, case.span)
                yield from self.nodes(case.body)
            if node.default or (node.has_default and self.empty_arms):
                yield _marker("default", node, node.span)
                yield from self.nodes(node.default)
            yield _marker("end_switch", node, node.span)
        elif isinstance(node, ir.Repeat):
            yield _marker("repeat", node, node.span)
            yield from self.nodes(node.body)
            yield _marker("until", node, node.span)
        else:
            yield _marker(node.kind, node, node.span)
            yield from self.nodes(node.body)
            yield _marker(_CLOSERS[type(node)], node, node.span)


def _marker(kind: str, node: Any, span: ir.SourceSpan) -> PostStep:
    return PostStep(-1, kind, span.location, node)


_MARKERS = frozenset(
    {"if", "elif", "else", "end_if", "switch", "case", "default", "end_switch", "while"}
    | {"end_while", "repeat", "until", "loop", "end_loop", "for", "end_for", "label"}
    | {"routine_call"}
)
_SETTINGS = frozenset({"tool", "frame", "zone", "joint", "linear"})


def _fresh_after_boundaries(steps: Sequence[PostStep], fresh: bool = False) -> Iterator[PostStep]:
    stale: set[str] = set(_SETTINGS) if fresh else set()
    for step in steps:
        if step.kind in _MARKERS:
            stale = set(_SETTINGS)
            yield step
            continue
        ins = step.instruction
        if not isinstance(ins, (*ir.MOTION_TYPES, ir.RuntimeMove)) or not stale:
            yield step
            continue
        kind = ins.motion if isinstance(ins, ir.RuntimeMove) else step.kind
        speed = "joint" if kind == "joint" else "linear"
        fresh = speed in stale
        tool, frame, zone = ("tool" in stale), ("frame" in stale), ("zone" in stale)
        stale -= {"tool", "frame", "zone", speed}
        yield dataclasses.replace(
            step,
            new_tool=step.new_tool or tool,
            new_frame=step.new_frame or frame,
            new_zone=step.new_zone or zone,
            new_joint_speed=step.new_joint_speed or (fresh and speed == "joint"),
            new_linear_speed=step.new_linear_speed or (fresh and speed == "linear"),
        )
