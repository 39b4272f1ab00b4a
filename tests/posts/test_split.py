"""Splitting long programs (olp.transforms.split): the greedy rule, part names, IR -> IR, steps."""

from __future__ import annotations

import numpy as np
import pytest

from olp import ir
from olp.compiled import Step
from olp.posts.abb import NAME_RULE as ABB_NAMES
from olp.posts.kuka import NAME_RULE as KUKA_NAMES
from olp.transforms.split import (
    SplitLimits,
    part_names,
    split_bounds,
    split_program,
    split_steps,
)

M, X = True, False  # a motion, another instruction


@pytest.mark.parametrize(
    ("kinds", "limits", "bounds"),
    [
        # no limit: one part
        ([M, M, M], SplitLimits(), [(0, 3)]),
        # two motions per part; the output after motion 2 stays with it
        ([M, M, X, M, M, M], SplitLimits(max_motions=2), [(0, 3), (3, 5), (5, 6)]),
        # leading non-motions stay with the first motion
        ([X, X, M, M, M], SplitLimits(max_motions=2), [(0, 4), (4, 5)]),
        # instructions of any kind
        ([M, X, M, X, M], SplitLimits(max_instructions=2), [(0, 2), (2, 4), (4, 5)]),
        # both limits: whichever comes first
        ([M, X, X, M, M], SplitLimits(max_motions=2, max_instructions=3), [(0, 3), (3, 5)]),
        # exactly at the limit: no empty part at the end
        ([M, M], SplitLimits(max_motions=2), [(0, 2)]),
        ([], SplitLimits(max_motions=1), [(0, 0)]),
    ],
)
def test_split_bounds(
    kinds: list[bool], limits: SplitLimits, bounds: list[tuple[int, int]]
) -> None:
    assert split_bounds(kinds, [True] * len(kinds), limits) == bounds


def test_unwritten_instructions_count_for_nothing() -> None:
    kinds = [M, M, M, M]
    written = [True, False, True, True]
    assert split_bounds(kinds, written, SplitLimits(max_motions=2)) == [(0, 3), (3, 4)]


@pytest.mark.parametrize("bad", [0, -1, 1.5, True])
def test_limits_must_be_positive_integers(bad: object) -> None:
    with pytest.raises(ValueError):
        SplitLimits(max_motions=bad)  # type: ignore[arg-type]


def test_part_names_are_numbered_padded_and_legal() -> None:
    assert part_names("Milling", 3, KUKA_NAMES.legal, KUKA_NAMES.max_length) == [
        "Milling_P1",
        "Milling_P2",
        "Milling_P3",
    ]
    names = part_names("Milling", 12, KUKA_NAMES.legal, KUKA_NAMES.max_length)
    assert names[0] == "Milling_P01" and names[-1] == "Milling_P12"


@pytest.mark.parametrize(("legal", "limit"), [(KUKA_NAMES.legal, 24), (ABB_NAMES.legal, 32)])
def test_long_names_are_cut_to_fit_the_suffix(legal: object, limit: int) -> None:
    name = "A_very_long_program_name_for_a_milling_job"
    names = part_names(name, 150, legal, limit)  # type: ignore[arg-type]
    assert all(len(n) <= limit for n in names)
    assert names[0].endswith("_P001") and names[-1].endswith("_P150")
    assert len({n.casefold() for n in names} | {legal(name).casefold()}) == 151  # type: ignore[operator]


def test_part_names_never_clash_with_the_main_ignoring_case() -> None:
    # The main name, cut to 24 characters, ends like part 1 would: the part must differ.
    main = "ABCDEFGHIJKLMNOPQRSTU_P1"
    names = part_names(main, 2, KUKA_NAMES.legal, 24)
    assert main.casefold() not in {n.casefold() for n in names}
    assert len({n.casefold() for n in names}) == 2 and all(len(n) <= 24 for n in names)


def _moves(n: int) -> list[ir.Instruction]:
    out: list[ir.Instruction] = []
    for i in range(n):
        out.append(ir.JointMove(target=ir.JointTarget(joints=np.full(6, 0.01 * i))))
        if i % 2:
            out.append(ir.SetOutput(index=i, value=True))
    return out


def test_split_program_is_ir_to_ir() -> None:
    program = ir.Program(name="Job", instructions=tuple(_moves(5)), source="job.src")
    main, parts = split_program(program, SplitLimits(max_motions=2), KUKA_NAMES.legal, 24)
    assert [p.name for p in parts] == ["Job_P1", "Job_P2", "Job_P3"]
    assert [i.name for i in main.instructions] == ["Job_P1", "Job_P2", "Job_P3"]  # type: ignore[union-attr]
    joined = tuple(i for p in parts for i in p.instructions)
    assert joined == program.instructions
    assert all(sum(ir.is_motion(i) for i in p.instructions) <= 2 for p in parts)
    assert all(p.source == "job.src" for p in parts)


def test_split_program_without_need_returns_the_program() -> None:
    program = ir.Program(name="Job", instructions=tuple(_moves(3)))
    assert split_program(program, SplitLimits(max_motions=10)) == (program, [])


def test_split_steps_keeps_every_step_in_order() -> None:
    instructions = _moves(7)
    steps = [Step(index=i, instruction=ins, skipped=(i == 1)) for i, ins in enumerate(instructions)]
    parts = split_steps(steps, SplitLimits(max_motions=3))
    assert [s.index for p in parts for s in p] == list(range(len(steps)))
    for part in parts:
        assert sum(ir.is_motion(s.instruction) and not s.skipped for s in part) <= 3
