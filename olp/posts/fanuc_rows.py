"""The LS post's column writer: a toolpath's rows (:class:`~olp.posts.view.RowColumns`, a dense
block's arrays with no object per row) as ``/MN`` motion lines and ``/POS`` entries, exactly as
``posts/fanuc/program.ls.j2`` writes each row as a linear move (:mod:`olp.posts.fanuc`), byte for
byte (``tests/posts/test_fanuc_columns.py``).

The rows of one block share its tool and frame, so ``UF``/``UT`` are one number each and
``UFRAME_NUM``/``UTOOL_NUM`` can only be written before the first row. Every number is spelled
and checked as a column (:meth:`olp.posts.base.Post.number_texts`, which spells as
:class:`~olp.posts.numbers.NumberFormat` does); a value that cannot be written is an error on
its own row's line. The rows' CONFIG texts come from the post's
:meth:`~olp.posts.fanuc.FanucPost.step_columns` (a row without one is written as joints).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

import numpy as np
from numpy.typing import NDArray

from olp.vendors.fanuc import pose_to_xyzwpr

if TYPE_CHECKING:
    from olp.posts.base import Post
    from olp.posts.view import PostStep, RowColumns

FloatArray = NDArray[np.float64]
Texts = NDArray[np.bytes_]
"""Texts as ASCII bytes: numpy's str arrays (UTF-32) move four times the memory when columns
are joined; what an LS file holds is ASCII (the manifest's encoding)."""


@dataclass(frozen=True, slots=True, eq=False)
class LsColumns:
    """The LS motions of a toolpath's rows: positions ``P[first]`` .. ``P[first + n - 1]`` in
    ``UF uf``/``UT ut``, whether ``UFRAME_NUM``/``UTOOL_NUM`` are set before the first row, and
    the rows' ``/POS`` entries already written (``positions``: each entry ends with its line
    break)."""

    columns: RowColumns
    first: int
    uf: int
    ut: int
    set_uf: bool
    set_ut: bool
    positions: str
    rows: ClassVar[bool] = True

    @property
    def last(self) -> int:
        """The number of the last row's position."""
        return self.first + len(self.columns) - 1


def column_moves(
    post: Post, rows: RowColumns, number: int, last: tuple[int, int] | None, uf: int, ut: int
) -> LsColumns:
    """The LS motions of ``rows`` (in ``UF uf``/``UT ut``), positions numbered from
    ``number + 1``; ``last``: the ``(UF, UT)`` of the motion before them in the file (None:
    none, or a jump target between)."""
    first = number + 1
    positions = position_texts(post, rows, first, uf, ut)
    new_uf = last is None or last[0] != uf
    new_ut = last is None or last[1] != ut
    return LsColumns(rows, first, uf, ut, new_uf, new_ut, positions)


def position_texts(post: Post, rows: RowColumns, first: int, uf: int, ut: int) -> str:
    """The ``/POS`` entries of ``rows`` as the template's ``position`` macro writes each:
    Cartesian (``CONFIG``, X..R in mm and deg, in the user frame for ``UF`` 1..9, else in
    World) where the row has a CONFIG, else joints (J1..J6 in deg). Numbers are checked in
    this order: the Cartesian rows' X, Y, Z, then their W, P, R, then the joint rows."""
    configs = rows.column("config")
    cartesian = configured(configs)
    numbers = np.arange(first, first + len(rows)).astype(np.bytes_)
    head = _join(b"P[", numbers, f"]{{\n   GP1:\n\tUF : {uf}, UT : {ut},".encode())
    out = np.empty(len(rows), dtype=object)
    where = np.flatnonzero(cartesian)
    if where.size:
        text = _cartesian(post, rows, where, uf, head[where], configs[where].astype(np.bytes_))
        out[where] = text
    joints = np.flatnonzero(~cartesian)
    if joints.size:
        out[joints] = _joints(post, rows, joints, head[joints])
    return b"".join(out.tolist()).decode("ascii")


def _cartesian(
    post: Post, rows: RowColumns, where: NDArray[np.intp], uf: int, head: Texts, configs: Texts
) -> Texts:
    """The Cartesian entries of rows ``where``; ``head``: each entry's first lines up to the
    ``UT``."""
    poses = rows.poses[where]
    if uf == 0:
        poses = rows.motions.frame_pose @ poses
    values = pose_to_xyzwpr(poses)
    at = _rows_at(rows, where)
    xyz = post.number_texts("position", values[:, :3], at).astype(np.bytes_)
    wpr = post.number_texts("angle", values[:, 3:], at).astype(np.bytes_)
    out = _join(head, b"\t\tCONFIG : '", configs, b"',\n\tX = ")
    fields = (
        (xyz[:, 0], b"  mm,\tY = "),
        (xyz[:, 1], b"  mm,\tZ = "),
        (xyz[:, 2], b"  mm,\n\tW = "),
        (wpr[:, 0], b" deg,\tP = "),
        (wpr[:, 1], b" deg,\tR = "),
        (wpr[:, 2], b" deg\n};\n"),
    )
    for column, after in fields:
        out = _join(out, np.strings.rjust(column, 9), after)
    return out


def _joints(post: Post, rows: RowColumns, where: NDArray[np.intp], head: Texts) -> Texts:
    """The joint entries (J1..J6, deg) of rows ``where``."""
    block = rows.piece.block
    assert block.joints is not None
    degrees = np.degrees(block.joints[rows.piece.lo + where])
    values = post.number_texts("angle", degrees, _rows_at(rows, where)).astype(np.bytes_)
    out = np.strings.add(head, b"\n\tJ1=")
    after = [b" deg,\tJ2=", b" deg,\tJ3=", b" deg,\n\tJ4=", b" deg,\tJ5=", b" deg,\tJ6="]
    for j, text in enumerate([*after, b" deg\n};\n"]):
        out = _join(out, np.strings.rjust(values[:, j], 10), text)
    return out


def mn_lines(post: Post, moves: LsColumns) -> str:
    """The ``/MN`` lines of the rows, as the template writes each linear move:
    ``UFRAME_NUM``/``UTOOL_NUM`` before the first where they change, then ``L P[n] v mm/sec
    FINE`` or ``CNTn`` (speeds rounded half up to whole mm/sec, at least 1; CNT the zone radius
    in mm rounded half up, at most 100)."""
    rows = moves.columns
    every = np.arange(len(rows))
    at = _rows_at(rows, every)
    mm = np.maximum(1.0, np.floor(rows.speeds * 1000.0 + 0.5))
    speeds = post.number_texts("linear", mm, at).astype(np.bytes_)
    zones = rows.zones
    terms = np.full(len(rows), b"FINE", dtype="S7")
    blended = np.flatnonzero(zones > 0)
    if blended.size:
        cnt = np.minimum(100.0, np.floor(zones[blended] * 1000.0 + 0.5))
        cnt_texts = post.number_texts("cnt", cnt, _rows_at(rows, blended)).astype(np.bytes_)
        terms[blended] = np.strings.add(b"CNT", cnt_texts)
    numbers = np.arange(moves.first, moves.first + len(rows)).astype(np.bytes_)
    lines = _join(b"L P[", numbers, b"] ", speeds, b"mm/sec ", terms, b"    ;")
    head = []
    if moves.set_uf:
        head.append(f"  UFRAME_NUM={moves.uf} ;")
    if moves.set_ut:
        head.append(f"  UTOOL_NUM={moves.ut} ;")
    post.current_step = rows
    return "\n".join([*head, b"\n".join(lines.tolist()).decode("ascii")])


def configured(configs: NDArray[np.object_]) -> NDArray[np.bool_]:
    """Which rows of a CONFIG column (N,) (objects: a CONFIG text, or None for a position
    written as joints) have a CONFIG."""
    found: NDArray[np.bool_] = np.not_equal(configs, _NONE)
    return found


_NONE = np.array(None, dtype=object)


def _rows_at(rows: RowColumns, where: NDArray[np.intp]) -> Callable[[int], PostStep]:
    """Row ``where[j]`` of ``rows`` as a step (the line an error on value row ``j`` names)."""
    return lambda j: rows.at(int(where[j]))


def _join(*parts: Texts | bytes) -> Texts:
    """The texts (n,) of ``parts`` (arrays (n,) or one text for all) joined row by row."""
    out = np.strings.add(parts[0], parts[1])
    for part in parts[2:]:
        out = np.strings.add(out, part)
    result: Texts = out
    return result
