"""A post's ``TRANSFORMS`` applied to a program streamed window by window (:mod:`olp.stream`),
with what they read across a window boundary carried over, so that every window comes out as
the same rows of the whole program would (``tests/test_stream.py`` compares both builds).

A post lists them as :attr:`olp.posts.base.Post.WINDOW_TRANSFORMS`: one class per transform,
made once per build, whose :meth:`WindowTransform.apply` takes each timed window in order
with the windows around it. A streamed program is a CSV toolpath: no control flow, and no
instruction after its first row.

:class:`BlendCapWindows` is :func:`olp.transforms.blend.cap_blends` (UR's ``cap_blend_radii``):
a target's capped radius reads the distance to its neighbours and whether they blend, so a
window is capped with the previous window's last motion before it and the next window's first
two motions after it (the second says whether the first is the program's last motion, where
the robot stops). The previous motion's radius is the one it was given (capping reads the
requested radii only), so it is kept from before its window was capped.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from olp.compiled import BlockRows, CompiledProgram, Item, PathBlock, items_of
from olp.diagnostics import Diagnostic
from olp.errors import PostError
from olp.ir import is_motion
from olp.transforms.blend import _diagnostic, blend_columns, with_radii

if TYPE_CHECKING:
    from olp.posts.base import Post


class WindowTransform(Protocol):
    """A post transform applied window by window (see the module text)."""

    def __init__(self, post: Post) -> None: ...

    def apply(
        self, window: CompiledProgram, following: CompiledProgram | None, last: bool
    ) -> tuple[CompiledProgram, list[Diagnostic]]:
        """``window`` transformed, and its diagnostics (instruction indices the window's own);
        ``following``: the next window (checked, not yet timed nor transformed; None: this is
        the last), ``last``: ``following`` is the program's last window."""
        ...


class BlendCapWindows:
    """:func:`olp.transforms.blend.cap_blends` window by window (see the module text)."""

    def __init__(self, post: Post) -> None:
        self.before: list[Any] = []

    def apply(
        self, window: CompiledProgram, following: CompiledProgram | None, last: bool
    ) -> tuple[CompiledProgram, list[Diagnostic]]:
        items = items_of(window.steps)
        after = [] if following is None else _first_motions(items_of(following.steps), 2)
        if following is not None and _motion_count(after) < 2 and not last:
            raise PostError(
                "a streamed window of one motion inside the program: build it whole "
                "(olp build --chunk-rows 0)"
            )
        before, self.before = self.before, _last_motion(items)
        robot = window.station.robot
        found = blend_columns([*before, *items, *after], robot, window.start_joints)
        lo = _motion_count(before)
        hi = lo + _motion_count(items)
        reduced = found.reduced[(found.reduced >= lo) & (found.reduced < hi)]
        if not reduced.size:
            return window, []
        index, radius = found.index[reduced], found.radius[reduced]
        capped = with_radii(window, index, radius)
        requested, reasons = found.requested, found.reasons
        diagnostics = [
            _diagnostic(i, float(requested[k]), float(radius[j]), reasons[k], window.steps)
            for j, (k, i) in enumerate(zip(reduced.tolist(), index.tolist(), strict=True))
        ]
        return capped, diagnostics


def _motion_count(items: Sequence[Any]) -> int:
    """The emitted motions of ``items`` (steps and toolpath rows)."""
    count = 0
    for item in items:
        if isinstance(item, BlockRows):
            count += len(item) if item.block.joints is not None else 0
        elif isinstance(item, PathBlock):
            count += len(item) if item.joints is not None else 0
        elif is_motion(item.instruction) and item.joints is not None:
            count += 1
    return count


def _first_motions(items: Sequence[Item], wanted: int) -> list[Any]:
    """The items of a window up to its ``wanted``-th emitted motion (a toolpath's rows as
    copied rows of their own: the window itself is not kept)."""
    out: list[Any] = []
    for item in items:
        need = wanted - _motion_count(out)
        if need <= 0:
            break
        if isinstance(item, PathBlock):
            out.append(_own_rows(item, 0, min(need, len(item))))
        else:
            out.append(item)
    return out


def _last_motion(items: Sequence[Item]) -> list[Any]:
    """A window's last emitted motion and the items after it (a stop among them makes it a
    stop), toolpath rows copied."""
    out: list[Any] = []
    for item in reversed(items):
        if isinstance(item, PathBlock):
            if item.joints is not None and len(item):
                return [_own_rows(item, len(item) - 1, len(item)), *out]
            continue
        out.insert(0, item)
        if is_motion(item.instruction) and item.joints is not None:
            return out
    return out


def _own_rows(block: PathBlock, lo: int, hi: int) -> BlockRows:
    """Rows ``lo`` to ``hi`` of ``block`` as a block of their own with copied arrays (what
    capping reads: joints, zones, tool, index)."""
    node = block.node.rows(lo, hi)
    node = dataclasses.replace(
        node,
        poses=np.array(node.poses),
        speeds=np.array(node.speeds),
        zones=np.array(node.zones),
        lines=np.array(node.lines),
        widths=None if node.widths is None else np.array(node.widths),
        labels=None if node.labels is None else np.array(node.labels),
    )
    joints = None if block.joints is None else np.array(block.joints[lo:hi])
    small = PathBlock(block.start + lo, node, block.tool, block.frame, joints)
    return BlockRows(small, 0, hi - lo)
