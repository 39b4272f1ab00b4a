"""Runs of linear moves written by a post's row writer instead of one template pass per move.

A toolpath is a long run of linear moves; a template evaluated once per move spends most of a
big build in Jinja's sandbox (each attribute lookup is checked). A post with a row writer
(:attr:`olp.posts.base.Post.ROWS`) whose templates declare ``rows: true`` in ``post.yaml`` gets
each maximal run of consecutive linear moves as one :class:`PostRows` step (``kind`` ``"rows"``)
and writes its lines in Python, formatting the numbers of the run column by column
(:meth:`olp.posts.base.Post.number_column`). The text is the same, byte for byte, as the
template's for the same moves (``tests/posts/test_rows.py`` renders both ways); headers, data
sections and every other instruction stay templates.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from olp.posts.view import PostStep

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class PostRows:
    """Consecutive linear moves (``steps``, each a :class:`~olp.posts.view.PostStep`) written
    by the post's row writer. ``motion`` is 0 so that a template's motion branch skips it; its
    ``index``, ``source`` and ``instruction`` are the first move's (where an error without a
    row of its own is reported)."""

    steps: tuple[PostStep, ...]
    kind: str = "rows"
    motion: int = 0

    @property
    def index(self) -> int:
        return self.steps[0].index

    @property
    def source(self) -> str:
        return self.steps[0].source

    @property
    def instruction(self) -> Any:
        return self.steps[0].instruction

    def __len__(self) -> int:
        return len(self.steps)

    def poses(self) -> FloatArray:
        """The targets (n, 4, 4) m in each move's frame."""
        return np.stack([s.pose for s in self.steps])  # type: ignore[misc]


def group_rows(steps: Sequence[PostStep]) -> list[PostStep | PostRows]:
    """``steps`` with every maximal run of consecutive linear moves as one :class:`PostRows`."""
    out: list[PostStep | PostRows] = []
    run: list[PostStep] = []
    for step in steps:
        if step.kind == "linear" and step.motion:
            run.append(step)
            continue
        if run:
            out.append(PostRows(tuple(run)))
            run = []
        out.append(step)
    if run:
        out.append(PostRows(tuple(run)))
    return out
