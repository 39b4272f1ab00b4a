"""The lowered program as IR nodes: Cartesian poses in one vectorised call, and long runs of
plain LIN motions as one :class:`olp.ir.LinearPath` (the dense toolpath node).

A run is a sequence of consecutive LIN motions, with nothing else between them in the IR, that a
``LinearPath`` holds exactly: each row read back (:meth:`olp.ir.LinearPath.move`) equals the
:class:`olp.ir.LinearMove` the motion would be on its own. So a row has no via point, a target
without a name or a configuration, the speed's joint parts at their defaults (a LinearPath has
none) and a one-line span that starts in column 1 (a LinearPath keeps line and end column);
the rows share tool, frame, file and the speed parts a LinearPath holds once (orientation speed,
path and orientation accelerations). Per-row path speeds and zones are arrays.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from olp import ir
from olp.frontends.krl.state import Cartesian, Pending, PendingRows
from olp.vendors.kuka import frame_to_pose

DENSE_MIN_ROWS = 64
"""A run of fewer LIN motions stays ordinary moves. Programs people write (pendant programs,
the examples and golden jobs) have short runs between their I/O, waits and PTPs and keep the
one-object-per-motion IR they are written as; CAM toolpaths run to thousands of rows, where a
node of arrays saves the per-move objects and checks. At 64 rows a node's fixed cost (a few
array allocations and one vectorised validation, ~50 us) is below 1 us per row."""


Item = ir.Node | Pending | PendingRows


def build_instructions(out: Sequence[Item], dense: bool = True) -> tuple[ir.Node, ...]:
    """The instructions, all Cartesian poses computed in one vectorised call; with ``dense``,
    runs of at least :data:`DENSE_MIN_ROWS` LIN motions as :class:`~olp.ir.LinearPath` nodes."""
    poses = _all_poses(out)
    built: list[ir.Node] = []
    start = 0  # index into poses of the next Cartesian target
    group: list[Pending | PendingRows] = []
    key: tuple[Any, ...] | None = None
    for item in out:
        item_key = _row_key(item) if dense else None
        if group and (item_key is None or item_key != key):
            start = _flush(group, poses, start, built)
            group = []
        if item_key is not None:
            assert isinstance(item, Pending | PendingRows)
            group.append(item)
            key = item_key
        elif isinstance(item, Pending):
            built.append(_single(item, poses, start))
            start += 1 if item.via is None else 2
        elif isinstance(item, PendingRows):
            built.extend(_row_moves(item, poses[start : start + len(item)]))
            start += len(item)
        else:
            built.append(item)
    if group:
        _flush(group, poses, start, built)
    return tuple(built)


def _all_poses(out: Sequence[Item]) -> ir.FloatArray:
    blocks: list[np.ndarray] = []
    values: list[tuple[float, ...]] = []
    for item in out:
        if isinstance(item, Pending):
            assert isinstance(item.target, Cartesian)
            values.append(item.target.values)
            if item.via is not None:
                values.append(item.via.values)
        elif isinstance(item, PendingRows):
            if values:
                blocks.append(np.array(values, dtype=np.float64).reshape(-1, 6))
                values = []
            blocks.append(item.values)
    blocks.append(np.array(values, dtype=np.float64).reshape(-1, 6))
    return frame_to_pose(np.concatenate(blocks) if len(blocks) > 1 else blocks[0])


def _row_key(item: Item) -> tuple[Any, ...] | None:
    """What rows of one LinearPath share, or None if ``item`` cannot be a row (module doc)."""
    if isinstance(item, PendingRows):
        return _shared(item.fields)
    if not isinstance(item, Pending) or item.make is not ir.LinearMove or item.via is not None:
        return None
    target, fields = item.target, item.fields
    assert isinstance(target, Cartesian)
    if target.name is not None or target.config is not None or fields.keys() != _FIELDS:
        return None
    span: ir.SourceSpan = fields["span"]
    if span.column != 1 or span.end_line != span.line or span.end_column is None:
        return None
    return _shared({**fields, "file": span.file})


_FIELDS = frozenset({"speed", "zone", "tool", "frame", "span"})


def _shared(fields: dict[str, Any]) -> tuple[Any, ...] | None:
    speed: ir.Speed = fields["speed"]
    if speed.joint != 1.0 or speed.joint_acceleration != 1.0:
        return None
    return (
        fields["file"],
        fields["tool"],
        fields["frame"],
        speed.angular,
        speed.linear_acceleration,
        speed.angular_acceleration,
    )


def _flush(
    group: list[Pending | PendingRows], poses: ir.FloatArray, start: int, built: list[ir.Node]
) -> int:
    """Append ``group`` to ``built`` (one LinearPath if long enough); the next pose index."""
    count = sum(len(item) if isinstance(item, PendingRows) else 1 for item in group)
    stop = start + count
    if count >= DENSE_MIN_ROWS:
        built.append(_linear_path(group, poses[start:stop]))
        return stop
    for item in group:
        if isinstance(item, PendingRows):
            built.extend(_row_moves(item, poses[start : start + len(item)]))
            start += len(item)
        else:
            built.append(_single(item, poses, start))
            start += 1
    return stop


def _linear_path(group: list[Pending | PendingRows], poses: ir.FloatArray) -> ir.LinearPath:
    columns: dict[str, list[Any]] = {"speeds": [], "zones": [], "lines": [], "widths": []}
    for item in group:
        parts: tuple[Any, ...]
        if isinstance(item, PendingRows):
            parts = (item.speeds, item.zones, item.lines, item.ends - 1)
        else:
            span: ir.SourceSpan = item.fields["span"]
            assert span.end_column is not None
            parts = (
                [item.fields["speed"].linear],
                [item.fields["zone"].radius],
                [span.line],
                [span.end_column - 1],
            )
        for column, part in zip(columns.values(), parts, strict=True):
            column.append(part)
    first = group[0].fields
    speed: ir.Speed = first["speed"]
    return ir.LinearPath(
        poses=poses,
        speeds=np.concatenate(columns["speeds"]),
        zones=np.concatenate(columns["zones"]),
        lines=np.concatenate(columns["lines"]),
        widths=np.concatenate(columns["widths"]),
        tool=first["tool"],
        frame=first["frame"],
        angular=speed.angular,
        acceleration=speed.linear_acceleration,
        angular_acceleration=speed.angular_acceleration,
        source=first["file"] if isinstance(group[0], PendingRows) else first["span"].file,
    )


def _row_moves(rows: PendingRows, poses: ir.FloatArray) -> list[ir.LinearMove]:
    """A short run as ordinary moves, each as the per-line lowering makes it."""
    fields = rows.fields
    moves = []
    for k in range(len(rows)):
        line, end = int(rows.lines[k]), int(rows.ends[k])
        speed = ir.Speed(**{**_speed_parts(fields["speed"]), "linear": float(rows.speeds[k])})
        moves.append(
            ir.LinearMove(
                target=ir.CartesianTarget(pose=poses[k]),
                speed=speed,
                zone=ir.Zone(float(rows.zones[k])),
                tool=fields["tool"],
                frame=fields["frame"],
                span=ir.SourceSpan(fields["file"], line, 1, line, end),
            )
        )
    return moves


def _speed_parts(speed: ir.Speed) -> dict[str, Any]:
    return {name: getattr(speed, name) for name in speed.__dataclass_fields__}


def _single(item: Pending, poses: ir.FloatArray, start: int) -> ir.Node:
    target = item.target
    assert isinstance(target, Cartesian)
    fields = dict(item.fields)
    fields["target"] = ir.CartesianTarget(pose=poses[start], config=target.config, name=target.name)
    if item.via is not None:
        via = item.via
        fields["via"] = ir.CartesianTarget(pose=poses[start + 1], config=via.config, name=via.name)
    return item.make(**fields)
