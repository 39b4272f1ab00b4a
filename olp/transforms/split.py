"""Split a long program into parts that fit a controller's limits, called in order by a main
program.

Controllers limit what one program file may hold (positions, lines; see each post's
``post.yaml`` ``limits`` and where its numbers come from). The rule is greedy and keeps the
program's order: a part takes instructions until the next *motion* would exceed
``max_motions`` or the next instruction would exceed ``max_instructions``. Non-motion
instructions (an output set after a move, a wait) therefore stay in the part of the motion
before them. Instructions that are not written (skipped motions, see
:attr:`olp.compiled.Step.skipped`) count for nothing.

Names: the main program keeps the program's name; part ``k`` of ``n`` is
``<name>_P<k>`` (``k`` zero-padded to the width of ``n``), the name cut so that the suffix fits
the vendor's length limit, and every name unique ignoring case (KRL, RAPID and Fanuc TP names
are case-insensitive). :func:`part_names` applies the vendor's ``legal_name``.

Entry points: :func:`split_bounds` (the rule on instruction kinds), :func:`split_program`
(IR -> IR: a main program of :class:`~olp.ir.Call` instructions and the parts, for use before
compiling) and :func:`split_steps` (a compiled program's steps, what :func:`olp.posts.render.render`
uses: splitting after planning cannot change a planned joint).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

from olp.ir import Call, Instruction, Program, is_motion
from olp.transforms.limits import LIMIT_KEYS, SplitLimits

if TYPE_CHECKING:
    from olp.compiled import Step

__all__ = [
    "LIMIT_KEYS",
    "SplitLimits",
    "part_names",
    "split_bounds",
    "split_program",
    "split_steps",
]


def split_bounds(
    motions: Sequence[bool], written: Sequence[bool], limits: SplitLimits
) -> list[tuple[int, int]]:
    """Half-open index ranges ``[start, stop)`` of the parts, in order, covering every index.

    ``motions[i]``: instruction ``i`` is a motion. ``written[i]``: it is written at all (False
    for skipped motions, which count for nothing). One range when no limit is exceeded; never
    an empty range, except ``[(0, 0)]`` for an empty program.
    """
    bounds: list[tuple[int, int]] = []
    start = count_motions = count_all = 0
    for i, (motion, shown) in enumerate(zip(motions, written, strict=True)):
        if not shown:
            continue
        over_motions = (
            motion and limits.max_motions is not None and count_motions >= limits.max_motions
        )
        over_all = limits.max_instructions is not None and count_all >= limits.max_instructions
        if (over_motions or over_all) and count_all > 0:
            bounds.append((start, i))
            start, count_motions, count_all = i, 0, 0
        count_motions += int(motion)
        count_all += 1
    bounds.append((start, len(motions)))
    return bounds


def part_names(
    name: str,
    count: int,
    legal_name: Callable[[str], str] = str,
    max_length: int | None = None,
) -> list[str]:
    """Names of ``count`` parts of program ``name``: ``<name>_P1`` ... (zero-padded), legal
    (``legal_name``), at most ``max_length`` characters, unique ignoring case and different from
    ``legal_name(name)``."""
    main = legal_name(name)
    width = len(str(count))
    taken = {main.casefold()}
    names = []
    for k in range(1, count + 1):
        suffix = f"_P{k:0{width}d}"
        base = main if max_length is None else main[: max(max_length - len(suffix), 1)]
        candidate = legal_name(base + suffix)
        while candidate.casefold() in taken:
            base = base[:-1]
            if not base:
                raise ValueError(f"cannot make {count} unique part names from {name!r}")
            candidate = legal_name(base + suffix)
        taken.add(candidate.casefold())
        names.append(candidate)
    return names


def split_program(
    program: Program,
    limits: SplitLimits,
    legal_name: Callable[[str], str] = str,
    max_length: int | None = None,
) -> tuple[Program, list[Program]]:
    """IR -> IR: ``(main, parts)``. With no limit exceeded, ``main`` is the program itself and
    ``parts`` is empty; otherwise ``main`` holds one :class:`~olp.ir.Call` per part, in order.
    ``limits.max_lines`` is not applied here (it needs the rendered text)."""
    instructions = program.instructions
    motions = [is_motion(i) for i in instructions]
    bounds = split_bounds(motions, [True] * len(instructions), limits)
    if len(bounds) == 1:
        return program, []
    names = part_names(program.name, len(bounds), legal_name, max_length)
    parts = [
        Program(name=n, instructions=instructions[a:b], source=program.source)
        for n, (a, b) in zip(names, bounds, strict=True)
    ]
    calls: list[Instruction] = [Call(name=p.name) for p in parts]
    main = Program(name=legal_name(program.name), instructions=tuple(calls), source=program.source)
    return main, parts


def split_steps(steps: Sequence[Step], limits: SplitLimits) -> list[tuple[Step, ...]]:
    """A compiled program's steps in parts (:func:`split_bounds`; skipped motions count for
    nothing). One part when no limit is exceeded."""
    motions = [is_motion(s.instruction) for s in steps]
    written = [not s.skipped for s in steps]
    return [tuple(steps[a:b]) for a, b in split_bounds(motions, written, limits)]
