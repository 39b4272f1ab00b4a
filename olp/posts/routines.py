"""The program's routines in a post: written as routines, or written out at every call.

A post that writes routines (``Post.WRITES_ROUTINES`` and ``routines: true`` in its manifest)
writes each routine once, from the steps of its first call site
(:func:`olp.posts.flow.weave_routines`). A motion inside a routine is then one line of text for
every call, while the checks resolved it at each call site on its own: where two call sites
resolved it to configurations the text tells apart (KUKA Status/Turn, ABB confdata, Fanuc
CONFIG: the post's ``step_values``), the text cannot hold both, and :func:`routine_checks`
reports an error on that motion naming both calls (never a silent pick of one).

A post that does not write routines gets the program with each routine's body written out at
its calls (:func:`written_out`), as olp wrote every program before it kept routines: exact for a
routine without parameters and without an early return, an error otherwise (a parameter or a
``RETURN`` means something else once written out), and a warning for each routine no call
expands (a function, an interrupt handler), which is then not in the output.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from olp import ir
from olp.diagnostics import Diagnostic
from olp.ir_flow import inline_expansions, leaves, leaves_and_blocks
from olp.posts.flow import expansions

if TYPE_CHECKING:
    from olp.compiled import CompiledProgram
    from olp.posts.base import Post


def written_out(compiled: CompiledProgram, post: Post) -> tuple[CompiledProgram, list[Diagnostic]]:
    """``compiled`` with every routine's body in place of its calls and no routines (the
    steps stay the steps: an expansion's instructions are already one step each)."""
    program = compiled.program
    sites = expansions(program)
    found: list[Diagnostic] = []
    for routine in program.routines:
        called = any(not node.entry for node, _ in sites.get(routine.name.upper(), []))
        found += _written_out_problems(routine, called, post)
    found += _shared_names(program, sites, post)
    nodes = inline_expansions(program.instructions)
    flat = dataclasses.replace(program, instructions=nodes, routines=())
    return dataclasses.replace(compiled, program=flat), found


def _written_out_problems(routine: ir.Routine, called: bool, post: Post) -> list[Diagnostic]:
    what = f"{'function' if routine.is_function else 'routine'} {routine.name}"
    lead = f"the {post.LANGUAGE} post does not write routines yet"
    if not called:
        message = (
            f"{lead}: {what} is not written (no call of the program runs it: an interrupt "
            "handler or a function); the program refers to a routine the output does not hold"
        )
        return [Diagnostic("warning", "routine_not_written", message, routine.span)]
    if routine.params:
        message = (
            f"{lead}, and {what} takes parameters: its body written out at each call would "
            "lose them"
        )
        return [Diagnostic("error", "routine", message, routine.span)]
    early = next((n for n in leaves(routine.body) if isinstance(n, ir.Return)), None)
    if early is not None:
        message = (
            f"{lead}, and {what} returns at line {early.span.line}: written out at its calls, "
            "the RETURN would end the program"
        )
        return [Diagnostic("error", "routine", message, early.span)]
    return []


def _shared_names(program: ir.Program, sites: Mapping[str, Any], post: Post) -> list[Diagnostic]:
    """Errors for a local variable of a routine written out at its calls whose name another
    routine or the program declares too: written out, one variable would stand for both."""
    owners: dict[str, str] = {}
    main = [n for n in leaves(inline_expansions(program.instructions)) if isinstance(n, ir.Declare)]
    for decl in main:
        owners.setdefault(decl.name.casefold(), "the program")
    found = []
    for routine in program.routines:
        if routine.name.upper() not in sites:
            continue
        for decl in routine.declarations:
            other = owners.setdefault(decl.name.casefold(), routine.name)
            if other != routine.name:
                message = (
                    f"the {post.LANGUAGE} post does not write routines yet, and {routine.name}'s "
                    f"variable {decl.name} would be the same variable as {other}'s once written "
                    "out at its calls"
                )
                found.append(Diagnostic("error", "routine", message, decl.span))
    return found


def routine_checks(compiled: CompiledProgram, post: Post) -> list[Diagnostic]:
    """Errors for what one routine text cannot hold: a motion that call sites resolve to
    configurations the post writes differently, and a routine that moves the robot where no
    call of the program runs it (its motions were never checked)."""
    program = compiled.program
    sites = expansions(program)
    found: list[Diagnostic] = []
    for routine in program.routines:
        calls = sites.get(routine.name.upper(), [])
        if not calls:
            found += _unchecked_motion(routine)
        elif len(calls) > 1:
            found += _configurations(compiled, post, routine, calls)
    return found


def _unchecked_motion(routine: ir.Routine) -> list[Diagnostic]:
    motion = next(
        (n for n in leaves(routine.body) if ir.is_motion(n) or isinstance(n, ir.LinearPath)), None
    )
    if motion is None:
        return []
    message = (
        f"routine {routine.name} moves the robot (line {motion.span.line}), but no call of the "
        "program runs it, so olp has not checked where it moves"
    )
    return [Diagnostic("error", "routine", message, motion.span)]


def _configurations(
    compiled: CompiledProgram,
    post: Post,
    routine: ir.Routine,
    calls: Sequence[tuple[ir.Expanded, int]],
) -> list[Diagnostic]:
    """One error per motion of ``routine`` whose written values differ between its first call
    and a later one (the first later call that differs)."""
    size = sum(len(n) if isinstance(n, ir.LinearPath) else 1 for n in leaves(calls[0][0].body))
    steps = compiled.steps
    motions = [k for k in range(size) if ir.is_motion(steps[calls[0][1] + k].instruction)]
    first = _written_values(compiled, post, calls[0][1], motions)
    found: list[Diagnostic] = []
    reported: set[int] = set()
    for node, start in calls[1:]:
        values = _written_values(compiled, post, start, motions)
        for k, mine, theirs in zip(motions, first, values, strict=True):
            if k in reported or mine is None or theirs is None or _same(mine, theirs):
                continue
            reported.add(k)
            step = steps[start + k]
            found.append(_conflict(routine, step, calls[0][0], node, mine, theirs))
    return found


def _written_values(
    compiled: CompiledProgram, post: Post, start: int, motions: Sequence[int]
) -> list[Mapping[str, Any] | None]:
    """The post's per-motion values (``step_values``) of the motions at ``start + k``."""
    steps = [compiled.steps[start + k] for k in motions]
    known = [s for s in steps if s.joints is not None]
    if not known:
        return [None] * len(steps)
    joints = np.stack([np.asarray(s.joints, dtype=float) for s in known])
    written = post.step_values(compiled.station.robot, joints)
    if not written:  # a post without per-motion values
        return [None] * len(steps)
    values = iter(written)
    return [next(values) if s.joints is not None else None for s in steps]


def _same(a: Mapping[str, Any], b: Mapping[str, Any]) -> bool:
    return a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)


def _conflict(
    routine: ir.Routine,
    step: Any,
    first: ir.Expanded,
    other: ir.Expanded,
    mine: Mapping[str, Any],
    theirs: Mapping[str, Any],
) -> Diagnostic:
    ins = step.instruction
    message = (
        f"the motion at line {ins.span.line} in routine {routine.name} is one line of text for "
        f"every call, but it resolves to another configuration from the call at line "
        f"{other.span.line} ({_describe(theirs)}) than from the call at line {first.span.line} "
        f"({_describe(mine)}); the text can hold only one"
    )
    hint = (
        "give the target a configuration both calls reach, or move the robot to the same "
        "place before each call"
    )
    return Diagnostic("error", "routine_configuration", message, ins.span, step.index, hint=hint)


def _describe(values: Mapping[str, Any]) -> str:
    return ", ".join(f"{k} {_text(v)}" for k, v in values.items() if not isinstance(v, bool))


def _text(value: Any) -> str:
    if isinstance(value, np.ndarray | list | tuple):
        return "[" + " ".join(str(v) for v in np.asarray(value).tolist()) + "]"
    return str(value)


def once_per_statement(found: Sequence[Diagnostic]) -> list[Diagnostic]:
    """``found`` with one diagnostic per statement and message: a routine written once says
    what cannot be written once, not at each of its calls."""
    seen: set[tuple[str, str, str, Any]] = set()
    out = []
    for diag in found:
        key = (diag.severity, diag.kind, diag.message, diag.span)
        if key not in seen:
            seen.add(key)
            out.append(diag)
    return out


def flow_nodes_of_routines(program: ir.Program) -> list[Any]:
    """Every node of the program's routines (declarations, bodies, blocks included)."""
    out: list[Any] = []
    for routine in program.routines:
        out += [*routine.declarations, *leaves_and_blocks(routine.body)]
    return out
