"""Which motion settings the output has put on the controller, per path (for joins).

At a join where a motion setting differs between the paths (``$TOOL = TOOL_DATA[1]`` in one CASE,
``TOOL_DATA[2]`` in another), the controller holds whichever value the path that ran set: the
setting is :class:`~olp.frontends.krl.state.Held` after the join, as after a call of a routine
olp did not read, and a motion that runs with it runs with the controller's settings (the KRL
post writes none of olp's before it). That is only true of the *output* if every path's value
really reaches the controller there. olp absorbs the statements that set motion settings into
its motions, and the KRL post writes a setting only before a motion that uses it
(``$VEL_AXIS`` before a PTP, ``$VEL.CP`` before a LIN or CIRC, ``$APO.CDIS`` before an
approximated LIN or CIRC, ``$ORI_TYPE`` and ``$CIRC_TYPE`` before a CIRC, ``$TOOL`` and
``$BASE`` before any; ``posts/kuka/program.src.j2``). So a path may end with a value the
output never wrote: ``$VEL.CP = 0.5`` followed by a PTP only.

The lowering tracks that per path with *setting keys* (:data:`FIELD_KEYS`: the parts of
:class:`~olp.frontends.krl.state.State` the post writes separately). A key is *clean* when the
controller running the output holds what it holds running the source at that point (a value
the program never set is the controller's own in both). The statements absorbed since the last
motion are kept as written where a join needs them (``unwritten``); a key whose setting
statement a motion that did not write it has passed is *lost* (``lost``): no statement can be
kept for it any more, and a join where it differs stays an error.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from olp import ir
from olp.frontends.krl.ast import Assign, CallStmt, EnumValue, Stmt
from olp.frontends.krl.inline import _BAS_SETS
from olp.frontends.krl.state import (
    ACC_AXIS_PARTS,
    VEL_AXIS_PARTS,
    Held,
    Pending,
    PendingRows,
    State,
)

FIELD_KEYS: dict[str, frozenset[str]] = {
    "speed": frozenset({"speed.linear", "speed.joint"}),
    "vel_axis": frozenset({"vel_axis"}),
    "acc_axis": frozenset({"acc_axis"}),
    "cdis_mm": frozenset({"cdis_mm"}),
    "tool": frozenset({"tool"}),
    "frame": frozenset({"frame"}),
    "ori_type": frozenset({"ori_type"}),
    "circ_type": frozenset({"circ_type"}),
}
"""The setting keys of each :class:`~olp.frontends.krl.state.State` field olp joins: the speed
is one field, but the post writes its joint part before a PTP and its path part before a LIN
or CIRC."""
PART_KEYS: dict[str, frozenset[str]] = {
    "vel_cp": frozenset({"speed.linear"}),
    "acc_cp": frozenset({"speed.linear"}),
    "acc_ori": frozenset({"speed.linear"}),
    **{key: frozenset({"vel_axis", "speed.joint"}) for key in VEL_AXIS_PARTS},
    **{key: frozenset({"acc_axis", "speed.joint"}) for key in ACC_AXIS_PARTS},
}
"""The setting keys of each part of the speed held apart
(:data:`~olp.frontends.krl.state.SPEED_PARTS`): the post writes the path parts before a LIN or
CIRC and the axis parts before a PTP."""

_LINEAR_PARTS = ("linear", "angular", "linear_acceleration", "angular_acceleration")
_JOINT_PARTS = ("joint", "joint_acceleration")
_ANY_MOTION = frozenset({"tool", "frame"})
_JOINT = _ANY_MOTION | {"speed.joint", "vel_axis", "acc_axis"}
_PATH = _ANY_MOTION | {"speed.linear"}
_ARC = _PATH | {"ori_type", "circ_type"}
_ROWS_CDIS = frozenset({"cdis_mm"})


def set_keys(
    before: State,
    before_ambiguous: Mapping[str, str],
    after: State,
    after_ambiguous: Mapping[str, str],
) -> set[str]:
    """The setting keys a statement set: the fields it replaced (a field set anew is a new
    object, even with an equal value: what the source sets must reach the controller whatever
    olp assumed before) or whose ambiguity it changed; of the speed, the parts it replaced
    (both when it replaced none, or when it ended an ambiguity that was not the controller's:
    the part it left is then no value the controller holds)."""
    keys: set[str] = set()
    for name, field_keys in FIELD_KEYS.items():
        old, new = getattr(before, name), getattr(after, name)
        why = before_ambiguous.get(name)
        ambiguity = why is not after_ambiguous.get(name)
        if old is new and not ambiguity:
            continue
        if name == "speed" and (why is None or isinstance(why, Held)):
            keys |= _speed_parts(old, new)
        else:
            keys |= field_keys
    return keys


_ASSIGNED_KEYS: dict[str, frozenset[str]] = {
    "$BASE": frozenset({"frame"}),
    "$TOOL": frozenset({"tool"}),
    "$VEL.CP": frozenset({"speed.linear"}),
    "$VEL": frozenset({"speed.linear"}),
    "$ACC.CP": frozenset({"speed.linear"}),
    "$ACC.ORI1": frozenset({"speed.linear"}),
    "$ACC": frozenset({"speed.linear"}),
    "$APO.CDIS": frozenset({"cdis_mm"}),
    "$APO": frozenset({"cdis_mm"}),
    "$ORI_TYPE": frozenset({"ori_type"}),
    "$CIRC_TYPE": frozenset({"circ_type"}),
    "$VEL_AXIS[]": frozenset({"vel_axis", "speed.joint"}),
    "$ACC_AXIS[]": frozenset({"acc_axis", "speed.joint"}),
}
"""The setting keys an assignment of each system variable sets (keys as :attr:`Var.key`)."""


def named_keys(stmt: Stmt) -> set[str]:
    """The setting keys ``stmt`` sets by what it names (``$BASE = $NULLFRAME`` sets the base
    even where olp's state already holds the same object), for an assignment of a system
    variable or a BAS command (:data:`olp.frontends.krl.inline._BAS_SETS`)."""
    if isinstance(stmt, Assign):
        return set(_ASSIGNED_KEYS.get(stmt.target.key, ()))
    command = stmt.args[0] if isinstance(stmt, CallStmt) and stmt.args else None
    if not isinstance(stmt, CallStmt) or stmt.name.upper() != "BAS":
        return set()
    if not isinstance(command, EnumValue):
        return set()
    name = command.name.upper()
    keys: set[str] = set()
    for field_name in _BAS_SETS.get(name, ()):
        if field_name == "speed":
            keys.add("speed.joint" if "PTP" in name else "speed.linear")
        else:
            keys |= FIELD_KEYS.get(field_name) or PART_KEYS[field_name]
    return keys


def _speed_parts(old: ir.Speed, new: ir.Speed) -> set[str]:
    parts = set()
    if any(getattr(old, p) is not getattr(new, p) for p in _LINEAR_PARTS):
        parts.add("speed.linear")
    if any(getattr(old, p) is not getattr(new, p) for p in _JOINT_PARTS):
        parts.add("speed.joint")
    return parts or set(FIELD_KEYS["speed"])


def written_keys(nodes: Iterable[Any], state: State) -> set[str]:
    """The setting keys the KRL post writes (or finds already written) before the motions among
    ``nodes``, each with the values of ``state`` (the state the motions were lowered with). A
    motion with the controller's settings writes none; ``$APO.CDIS`` counts only for an
    approximated LIN or CIRC whose distance is the state's (a PTP's C_PTP writes ``$APO.CPTP``
    instead)."""
    keys: set[str] = set()
    for node in nodes:
        if isinstance(node, Pending):
            kind, zone = node.make, node.fields.get("zone")
        elif isinstance(node, PendingRows | ir.LinearPath):
            keys |= _PATH | (_ROWS_CDIS if _rows_approximated_with(node.zones, state) else set())
            continue
        elif isinstance(node, ir.RuntimeMove):
            if not node.controller_settings:
                keys |= {"joint": _JOINT, "linear": _PATH, "circular": _ARC}[node.motion]
            continue
        elif isinstance(node, ir.JointMove | ir.LinearMove | ir.CircularMove):
            kind, zone = type(node), node.zone
        else:
            continue
        if kind is ir.JointMove:
            keys |= _JOINT
            continue
        keys |= _ARC if kind is ir.CircularMove else _PATH
        if _approximated_with(zone, state):
            keys.add("cdis_mm")
    return keys


def _rows_approximated_with(zones: np.ndarray, state: State) -> bool:
    """Whether a run of plain LINs (``zones`` (N,) m, 0 a fine stop) leaves the state's
    ``$APO.CDIS`` on the controller: the post writes it before a row whose distance changes,
    so every approximated row must have the state's."""
    approximated = zones[zones > 0]
    if state.cdis_mm is None or approximated.size == 0:
        return False
    return bool(np.all(np.abs(approximated * 1000 - state.cdis_mm) < 1e-9))


def _approximated_with(zone: Any, state: State) -> bool:
    if not isinstance(zone, ir.Zone) or zone.is_fine or state.cdis_mm is None:
        return False
    return abs(zone.radius * 1000 - state.cdis_mm) < 1e-9
