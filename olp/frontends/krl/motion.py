"""KRL lowering of motions: PTP/LIN/CIRC, their spline and _REL forms, and the fast path.

Targets are inline aggregates or named points; Cartesian ones stay KRL values (mm, deg) until
:func:`olp.frontends.krl.rows.build_instructions`. See :mod:`olp.frontends.krl` for the rules.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Callable
from typing import Any, Literal

import numpy as np

from olp import ir
from olp.frontends.krl.ast import (
    Aggregate,
    Expr,
    FastMotion,
    LinRows,
    MotionStmt,
    StatusTurn,
    Var,
)
from olp.frontends.krl.fast import materialise, row_motions
from olp.frontends.krl.flow import to_expr
from olp.frontends.krl.inline import InlineForms
from olp.frontends.krl.state import (
    ACC_AXIS_PARTS,
    DEFAULT_VEL_CP,
    PATH_SPEED_PARTS,
    VEL_AXIS_PARTS,
    Cartesian,
    Held,
    Pending,
    PendingRows,
    Target,
)
from olp.frontends.krl.values import (
    AXES,
    AXIS_TYPES,
    CARTESIAN,
    EXTERNAL,
    Unknown,
    is_axis_aggregate,
)
from olp.vendors.kuka import (
    approximation_problem,
    configuration_from_status_turn,
    frame_to_pose,
    pose_to_frame,
)

_BASE_MOTION = {
    "PTP": "PTP",
    "SPTP": "PTP",
    "PTP_REL": "PTP",
    "LIN": "LIN",
    "SLIN": "LIN",
    "LIN_REL": "LIN",
    "CIRC": "CIRC",
    "SCIRC": "CIRC",
    "CIRC_REL": "CIRC",
    "SPTP_REL": "PTP",
    "SLIN_REL": "LIN",
    "SCIRC_REL": "CIRC",
}
_SPLINE_MOTIONS = frozenset({"SPTP", "SLIN", "SCIRC", "SPTP_REL", "SLIN_REL", "SCIRC_REL"})
# The approximations the fast path lowers without a note (a subset of what KRL takes,
# olp.vendors.kuka.approximation_problem; any other goes through _motion and its check).
_PTP_APPROX = frozenset({("C_PTP",), ("C_PTP", "C_DIS"), ("C_DIS",)})
_LIN_APPROX = frozenset({("C_DIS",), ("C_DIS", "C_DIS")})
_FAST_KEYWORDS = {"PTP": "PTP", "SPTP": "PTP", "LIN": "LIN", "SLIN": "LIN"}
_AXIS_SET = frozenset(AXES)
_CARTESIAN_SET = frozenset(CARTESIAN)
_AXIS_PARTS = frozenset({*VEL_AXIS_PARTS, *ACC_AXIS_PARTS})
_USED_SETTINGS: dict[str, frozenset[str]] = {
    "PTP": frozenset({"vel_axis", "acc_axis", "speed", "tool", "frame"}) | _AXIS_PARTS,
    "LIN": frozenset({"speed", "tool", "frame", "ori_type", *PATH_SPEED_PARTS}),
    "CIRC": frozenset({"speed", "tool", "frame", "ori_type", "circ_type", *PATH_SPEED_PARTS}),
}
"""The motion settings (fields of :class:`~olp.frontends.krl.state.State`) a motion of each
kind runs with, besides ``cdis_mm`` when it is approximated (see :meth:`Motions._unsettled`),
and the parts of the speed held apart (:data:`~olp.frontends.krl.state.SPEED_PARTS`)."""
_WITH_SETS: dict[tuple[str, bool], frozenset[str]] = {
    ("$VEL_AXIS[]", True): frozenset({"vel_axis", "speed", *VEL_AXIS_PARTS}),
    ("$ACC_AXIS[]", True): frozenset({"acc_axis", *ACC_AXIS_PARTS}),
    ("$VEL", False): frozenset({"speed", "vel_cp"}),
    ("$VEL.CP", False): frozenset({"speed", "vel_cp"}),
    ("$TOOL", True): frozenset({"tool"}),
    ("$TOOL", False): frozenset({"tool"}),
    ("$BASE", True): frozenset({"frame"}),
    ("$BASE", False): frozenset({"frame"}),
    ("$APO", True): frozenset({"cdis_mm"}),
    ("$APO", False): frozenset({"cdis_mm"}),
    ("$ORI_TYPE", False): frozenset({"ori_type"}),
    ("$CIRC_TYPE", False): frozenset({"circ_type"}),
}
"""(a WITH item's target, whether the motion is a PTP) -> the settings of
:data:`_USED_SETTINGS` it sets for that motion: the axis speeds are a PTP's speed, the path
speed a LIN's or CIRC's (:meth:`Motions._unsettled`)."""


class Motions(InlineForms):
    """Motion statements -> IR motions, tracking where the robot goes."""

    # ---- the fast path
    def _lin_rows(self, rows: LinRows) -> None:
        """Rows of the CAM shape as one :class:`PendingRows` where each would take
        :meth:`_lower_fast` with nothing to note; else line by line, as :class:`FastMotion`."""
        if not self._takes_rows(rows):
            for motion in row_motions(rows):
                self.lower_statement(motion)  # type: ignore[attr-defined]
            return
        self.ctx.remaining -= len(rows)  # what lower_statement spends per line
        self.motion_count += len(rows)
        self._after_kept_settings(rows.span)
        state = self.state
        zone = 0.0 if state.cdis_mm is None else state.cdis_mm / 1000.0
        fields = {"speed": state.speed, "tool": state.tool, "frame": state.frame}
        self.out.append(
            PendingRows(
                values=rows.values,
                speeds=np.full(len(rows), state.speed.linear),
                zones=np.where(rows.approx, zone, 0.0),
                lines=rows.lines,
                ends=rows.ends,
                fields={**fields, "file": rows.span.file},
            )
        )
        self.track.at_position(tuple(map(float, rows.values[-1])), int(rows.lines[-1]))

    def _takes_rows(self, rows: LinRows) -> bool:
        """Whether every row would be lowered by :meth:`_lower_fast` without a note, an
        ignored line or an error (then the rows need no statement of their own)."""
        state = self.state
        return (
            self.returned is None
            and self.exiting is None
            and getattr(self, "jumped", None) is None
            and not getattr(self, "ambiguous", None)
            and not getattr(self, "unset", None)
            and self.ctx.remaining >= len(rows)
            and self._after_with is None
            and state.ori_type == "VAR"
            and state.vel_cp_set
            and (state.cdis_mm is not None or not rows.approx.any())
            and bool(np.isfinite(rows.values).all())
        )

    def _fast_motion(self, stmt: FastMotion) -> None:
        """The common simple motion, lowered without building its full AST; anything less
        common goes through :meth:`_motion` with the materialised statement (which counts
        itself). A motion is counted (``motion_count``) like any: a variable given $POS_ACT
        before it no longer holds where the robot is."""
        if self._lower_fast(stmt):
            self.motion_count += 1
        else:
            self._motion(materialise(stmt))

    def _lower_fast(self, stmt: FastMotion) -> bool:
        base = _FAST_KEYWORDS[stmt.keyword]
        state, track = self.state, self.track
        if (
            self._after_with is not None
            or getattr(self, "unset", None)  # the slow path notes it once
            or (base == "LIN" and state.ori_type != "VAR")
            or stmt.type_name is not None
            or not all(map(math.isfinite, stmt.values))
        ):
            return False
        zone = self._fast_zone(stmt.approx, base, stmt.keyword)
        members = dict(zip(stmt.names, stmt.values, strict=True))
        if zone is None or len(members) != len(stmt.names):
            return False
        target: Target
        if base == "PTP" and members.keys() == _AXIS_SET:
            degrees = tuple(members[a] for a in AXES)
            track.at_axes(degrees, stmt.span.line)
            target = ir.JointTarget(joints=np.radians(degrees))
        elif members.keys() <= _CARTESIAN_SET and (base == "PTP" or state.vel_cp_set):
            previous = track.cartesian
            if len(members) == len(CARTESIAN):
                values = tuple(members[c] for c in CARTESIAN)
            elif previous is not None:
                values = tuple(members.get(c, previous[i]) for i, c in enumerate(CARTESIAN))
            else:
                return False
            track.at_position(values, stmt.span.line)
            target = Cartesian(values)
        else:
            return False
        make = ir.JointMove if base == "PTP" else ir.LinearMove
        fields = {
            "speed": state.speed,
            "zone": zone,
            "tool": state.tool,
            "frame": state.frame,
            "span": stmt.span,
            **_spline(stmt.keyword),
        }
        self._emit(make, target, None, fields)
        return True

    def _fast_zone(self, approx: tuple[str, ...], base: str, keyword: str) -> ir.Zone | None:
        if not approx:
            return ir.FINE
        cdis = self.state.cdis_mm
        valid = _PTP_APPROX if base == "PTP" else _LIN_APPROX
        if cdis is None or approx not in valid or keyword not in ("PTP", "LIN"):
            return None
        return ir.Zone(cdis / 1000.0)

    # ---- motions
    def _motion(self, stmt: MotionStmt) -> None:
        self.motion_count += 1
        base = _BASE_MOTION.get(stmt.keyword)
        if base is None:
            raise self._error(
                f"{stmt.keyword} is a spline segment: it belongs inside SPLINE ... ENDSPLINE",
                stmt.span,
            )
        expected = 2 if base == "CIRC" else 1
        if len(stmt.targets) != expected:
            message = f"{stmt.keyword} takes {expected} target{'s' if expected > 1 else ''}"
            raise self._error(f"{message}, found {len(stmt.targets)}", stmt.span)
        if stmt.angle is not None and base != "CIRC":
            raise self._error(f"{stmt.keyword} takes no CA (only CIRC does)", stmt.angle.span)
        relative = stmt.keyword.endswith("_REL")
        if stmt.frame_option is not None and not relative:
            raise self._error(
                f"{stmt.keyword} takes no #BASE/#TOOL (only the _REL motions do)",
                stmt.frame_option.span,
            )
        runtime = None if self.ctx.probing_for else self._runtime_target(stmt)
        if runtime is None and not self.ctx.probing_for:
            runtime = self._runtime_start(stmt, base)
        elif runtime is not None and relative and self._start_relative(stmt, base) is None:
            self._keep_runtime_motion(stmt, base, runtime)
            return
        if stmt.with_clause:
            self._with_motion(stmt, base, relative, runtime)
        elif runtime is not None:
            self._note_after_with(stmt)
            self._runtime_motion(stmt, base, runtime)
        else:
            self._note_after_with(stmt)
            self._plain_motion(stmt, base, relative)

    # ---- motions to targets known only at run time
    def _runtime_target(self, stmt: MotionStmt) -> str | None:
        """Why a target of ``stmt`` is known only when the program runs, else None.

        A run-time target (or a component of an inline aggregate) is one olp cannot evaluate
        although every name it depends on is declared: a position computed from a function's
        result, an input, a parameter, a path-dependent value, a controller variable
        (``joint = $AXIS_ACT_MEAS``). So is one that depends on a name no file olp read
        declares while a file where the controller would find it was not given (the module's
        .dat, the controller's $config.dat: ``XHOME`` without it): its value is the cell's,
        which olp never guesses (:meth:`olp.frontends.krl.state.Context.unknown_name`). A name
        declared nowhere while every such file was given is left to the usual error, which
        tells the user which data list is missing."""
        for expr in stmt.targets:
            parts = [m.value for m in expr.members] if isinstance(expr, Aggregate) else [expr]
            for part in parts:
                value = self._value(part)
                if self._runtime(value):
                    assert isinstance(value, Unknown)
                    return value.reason
        return None

    def _runtime_motion(self, stmt: MotionStmt, base: str, reason: str) -> None:
        """A motion to a run-time target as :class:`~olp.ir.RuntimeMove`: the target stays an
        expression, the settings are those in effect (a post writes them before it as before
        any motion); the passes say what they cannot check, and the next motion starts where
        olp does not know."""
        zone = self._zone(stmt, base)
        fields = self._fields(stmt, zone)
        if base != "PTP":
            self._note_default_speed(stmt)
        if base == "CIRC":
            fields.update(self._arc_fields(stmt))
        elif base == "LIN":
            self._note_line_orientation(stmt)
        self._after_kept_settings(stmt.span)
        self.out.append(
            ir.RuntimeMove(
                motion=_RUNTIME_KINDS[base],
                target=self._target_expr(stmt.targets[-1]),
                via=self._target_expr(stmt.targets[0]) if base == "CIRC" else None,
                reason=reason,
                relative=self._start_relative(stmt, base),
                **fields,
            )
        )
        self.track.lose(
            RuntimeStart(f"the {stmt.keyword} at line {stmt.span.line} goes to a run-time target")
        )

    def _runtime_start(self, stmt: MotionStmt, base: str) -> str | None:
        """Why ``stmt``'s target is known only when the program runs because it refers to the
        start position (a _REL motion; an inline target that leaves components out, which
        KRL takes from the start) and the motion before went to a run-time target, else None.
        Such a motion is a :class:`~olp.ir.RuntimeMove` with ``relative`` saying how its target
        refers to the start: the controller computes it, as from any start (before: an error
        that olp cannot know the start). A start unknown for another reason (no Cartesian
        target before, a motion to axis values, a WITH's $TOOL) stays the error it was."""
        kind = self._start_relative(stmt, base)
        if kind is None:
            return None
        joints = kind == "axes"
        known = self.track.joints if joints else self.track.cartesian
        lost = self.track.no_joints if joints else self.track.no_cartesian
        if known is not None or not isinstance(lost, RuntimeStart):
            return None
        if kind == "start":
            what = "takes the components its target leaves out from the start position"
        else:
            what = "moves relative to the start position"
        return f"{stmt.keyword} {what}, and {lost}"

    def _start_relative(self, stmt: MotionStmt, base: str) -> RelativeKind | None:
        """How ``stmt``'s target refers to its start position (:attr:`olp.ir.RuntimeMove.relative`):
        a _REL motion's offsets (``"axes"`` for a PTP_REL by axis values, else ``"tool"`` with
        ``#TOOL``, ``"base"`` with ``#BASE`` or none: KRL's default), an inline target that
        leaves Cartesian components out (``"start"``), else None. None too for a _REL motion
        whose offsets or option olp would refuse anyway (the usual error then stands)."""
        if not stmt.keyword.endswith("_REL"):
            return self._partial_kind(stmt, base)
        option = stmt.frame_option.name.upper() if stmt.frame_option is not None else "BASE"
        if option not in ("BASE", "TOOL"):
            return None
        target = stmt.targets[-1]
        if isinstance(target, Aggregate) and is_axis_aggregate(target):
            return "axes" if base == "PTP" else None
        if not isinstance(target, Aggregate) and base == "PTP":
            value = self._value(target)
            if isinstance(value, Aggregate) and is_axis_aggregate(value):
                return "axes"
            if isinstance(value, Unknown):  # offsets of the axes or of the position: its type
                declared = self._declared_type(target)
                if declared is None:
                    return None
                if declared in AXIS_TYPES:
                    return "axes"
        return "tool" if option == "TOOL" else "base"

    def _declared_type(self, target: Expr) -> str | None:
        """The type (upper case) a routine's DECL gives the plain variable ``target``, where it
        is one olp knows to be a position (``AXIS``, ``E6AXIS``, ``POS``, ``E6POS``,
        ``FRAME``), else None."""
        if not isinstance(target, Var) or target.selectors:
            return None
        declared = self.ctx.declared_types.get(target.name.upper())
        return declared if declared in _POSITION_TYPES else None

    @staticmethod
    def _partial_kind(stmt: MotionStmt, base: str) -> RelativeKind | None:
        """``"start"`` when an inline Cartesian target (or a CIRC's via point) of ``stmt``
        leaves out some of X..C (KRL takes them from the start position), else None."""
        for expr in stmt.targets:
            if not isinstance(expr, Aggregate) or is_axis_aggregate(expr):
                continue
            names = {m.name.upper() for m in expr.members}
            if not names >= _CARTESIAN_SET:
                return "start"
        return None

    def _target_expr(self, expr: Expr) -> ir.Expr:
        converted = to_expr(expr, self._input_of)
        assert converted is not None
        return converted

    def _unsettled(self, stmt: MotionStmt) -> dict[str, str]:
        """The motion settings ``stmt`` runs with that are ambiguous here (``ambiguous``: set
        from run-time values, or different between the paths that reach it), and why.

        A motion runs with (and the posts write before it) its tool and base; a PTP with the
        axis speeds and accelerations (``$VEL_AXIS``/``$ACC_AXIS``: the joint part of the speed,
        which the KRL post writes only before a PTP and the timing applies only to joint moves,
        :mod:`olp.passes.timing`); a LIN or CIRC with the path speed (``$VEL.CP``), ``$ORI_TYPE``
        and a CIRC with ``$CIRC_TYPE``; an approximated motion with ``$APO.CDIS``. So a LIN
        after ``BAS(#PTP_PARAMS)`` with run-time values, whose own inline form set the tool,
        base, path speed and distance again (``BAS(#CP_PARAMS, 2)`` with known data), is
        lowered as any: the axis speeds that BAS left unknown are not its settings. The speed
        is one setting in olp (:class:`olp.ir.Speed`): what sets either part of it counts for
        both (conservative: a LIN right after a run-time ``BAS(#VEL_PTP)`` still stops); its
        parts held from run-time values (:data:`~olp.frontends.krl.state.SPEED_PARTS`) are
        held one by one: a PTP is not held by a run-time ``$VEL.CP``, a LIN is. What
        the motion's own WITH sets (a spline inline form's ``$TOOL = STOOL2(FP1)``, ...) is not
        ambiguous for it."""
        ambiguous: dict[str, str] = getattr(self, "ambiguous", {})
        used = self._used_settings(stmt)
        return {name: why for name, why in ambiguous.items() if name in used}

    @staticmethod
    def _used_settings(stmt: MotionStmt) -> frozenset[str]:
        """The motion settings ``stmt`` runs with that its own WITH does not set
        (:meth:`_unsettled`)."""
        base = _BASE_MOTION.get(stmt.keyword, "PTP")
        used = _USED_SETTINGS[base] | ({"cdis_mm"} if stmt.approx else set())
        for assignment in stmt.with_clause or ():
            used = used - _WITH_SETS.get((assignment.target.key, base == "PTP"), frozenset())
        return used

    def _controller_settings_motion(self, stmt: MotionStmt, unsettled: dict[str, str]) -> bool:
        """A motion whose ambiguous settings (``unsettled``, :meth:`_unsettled`) are all held
        by the controller (:class:`~olp.frontends.krl.state.Held`: a BAS given run-time values,
        the pendant's ``FDAT_ACT=FHOME``, ``BAS(#PTP_PARAMS,100)``, ``PTP XHOME`` without the
        ``$config.dat``; ``$BASE`` set from a run-time value; a call of a routine olp did not
        read, ``MoveSettings(nBase, nTool)``): a :class:`~olp.ir.RuntimeMove` that runs with
        the controller's settings (``controller_settings``: the KRL post writes no setting
        before it, so those the source's statements set hold), its target an expression, a
        _REL motion's offsets or a partial target's components taken from the start at run
        time (``relative``: the tool and base they refer to are the controller's too). So does
        every motion after it until the program sets those settings again.

        The statements olp absorbed into the motion settings since the last motion (a
        ``$VEL.CP``, ``BAS(#VEL_PTP,100)``) are kept as written where they stand
        (:meth:`_keep_unwritten`): the output writes settings only before the motions that use
        them, and this one writes none, so without them it would run without what they set.
        One with a WITH or a CA is kept as written (:meth:`_keep_controller_motion`). Returns
        whether it lowered ``stmt`` (else the caller's error stands)."""
        base = _BASE_MOTION.get(stmt.keyword)
        if base is None or not all(isinstance(why, Held) for why in unsettled.values()):
            return False
        expected = 2 if base == "CIRC" else 1
        if len(stmt.targets) != expected:
            return False
        if stmt.with_clause or stmt.angle is not None:
            return self._keep_controller_motion(stmt, unsettled)
        relative = self._start_relative(stmt, base)
        if stmt.keyword.endswith("_REL") and relative is None:
            return False  # an offset olp refuses anyway: the usual error
        self.motion_count += 1
        runtime = self._runtime_target(stmt)
        self._keep_unwritten(
            "sets motion settings before a motion that runs with the controller's settings "
            "(olp writes none before it)"
        )
        why = "; ".join(sorted(set(unsettled.values())))
        if stmt.approx:
            self._check_approx(stmt, base)  # (a modelled motion's is checked by _zone)
        approximated = tuple(word.upper() for word in stmt.approx)
        unkeepable: Callable[[], set[str]] | None = getattr(self, "unkeepable", None)
        if approximated and "cdis_mm" not in unsettled and unkeepable and "cdis_mm" in unkeepable():
            self._note(
                stmt.span,
                f"{' '.join(stmt.approx)} with the controller's settings: the $APO.CDIS the "
                "program set is not on the controller here (olp writes it only before a motion "
                "that approximates with it), so the controller would approximate with another "
                "distance; written as an exact stop",
            )
            approximated = ()
        self.out.append(
            ir.RuntimeMove(
                motion=_RUNTIME_KINDS[base],
                target=self._target_expr(stmt.targets[-1]),
                via=self._target_expr(stmt.targets[0]) if base == "CIRC" else None,
                reason=why if runtime is None else f"{runtime}; {why}",
                controller_settings=True,
                spline=stmt.keyword.upper() in _SPLINE_MOTIONS,
                relative=relative,
                approximated=approximated,
                span=stmt.span,
            )
        )
        self.track.lose(
            RuntimeStart(f"the {stmt.keyword} at line {stmt.span.line} runs with unknown settings")
        )
        return True

    def _keep_controller_motion(self, stmt: MotionStmt, unsettled: dict[str, str]) -> bool:
        """A motion with a WITH (or a CA) that runs with settings the controller holds
        (:meth:`_controller_settings_motion`): kept as written, WITH and all
        (:class:`~olp.ir.RuntimeMove` has no WITH), for the KRL post; olp checks nothing of it
        and the next motion starts where olp does not know."""
        self.motion_count += 1
        self._keep_unwritten(
            "sets motion settings before a motion that runs with the controller's settings "
            "(olp writes none before it)"
        )
        why = "; ".join(sorted(set(unsettled.values())))
        self._keep(stmt, f"it runs with settings the controller holds ({why})")
        self._note(
            stmt.span,
            f"{stmt.keyword} with settings the controller holds ({why}): kept as written and "
            "not checked (reach, limits, collisions, time)",
        )
        self.track.lose(
            RuntimeStart(f"the {stmt.keyword} at line {stmt.span.line} runs with unknown settings")
        )
        return True

    def _keep_unwritten(
        self,
        reason: str,
        strict: bool = True,
        only: list[Any] | None = None,
        deferred: bool | None = None,
    ) -> None:
        """Keep as written, where they stand and for the KRL post only
        (:attr:`olp.ir.Verbatim.native_only`), the statements olp absorbed into the motion
        settings since the last motion (``unwritten``): something that runs with the
        controller's settings comes next (a call of a routine olp did not read, a motion with
        the controller's settings, the end of the module), before which the output writes none
        of olp's. Only those in an output list still being built (``live_outs``: this
        lowering's and those it is nested in). One inside a block already lowered cannot be
        kept where it stands: with ``strict`` (a call or motion with the controller's settings
        comes next, which would run without it on that path) that is an error at it, else it
        is reported at the end (:meth:`report_unwritten_settings`). One a kept BAS already wrote
        (a data record it reads) is not written twice. ``only``: keep just those in that output
        list (a block's path at its join: :meth:`olp.frontends.krl.lower._Lowering._join`).

        ``deferred`` (by default with ``strict``): the statements a motion passed that wrote
        none of what they set (``$VEL.CP`` before a PTP, :mod:`olp.frontends.krl.written`) are
        kept too, where they stand (after the others: they stand before them); one in an
        output already lowered is lost (``lost``)."""
        unwritten: list[Any] = getattr(self, "unwritten", [])
        positions: list[tuple[list[Any], int, frozenset[str]]] = getattr(self, "unwritten_at", [])
        live = [*getattr(self, "live_outs", []), self.out]
        for k in range(len(unwritten) - 1, -1, -1):  # from the back: earlier positions hold
            out, at, _ = positions[k]
            if only is not None and out is not only:
                continue
            if not any(out is candidate for candidate in live):
                if strict:
                    raise self._error(
                        "this statement sets motion settings inside a block no motion of which "
                        "runs with them, and what follows the block runs with the controller's "
                        "settings (a call of a routine olp did not read, or a motion after one): "
                        "olp writes settings only before its motions, so on this path the "
                        "controller would run without it",
                        unwritten[k].span,
                        hint="set it after the block, or give the block a motion that uses it",
                    )
                continue
            stmt = unwritten.pop(k)
            del positions[k]
            if any(getattr(node, "span", None) == stmt.span for node in out[at:]):
                continue
            self._keep_krl_only(stmt, reason)
            out.insert(at, self.out.pop())
        if strict if deferred is None else deferred:
            self._keep_deferred(reason, live)

    def _keep_deferred(self, reason: str, live: list[list[Any]]) -> None:
        waiting: list[Any] = getattr(self, "deferred", [])
        lost: set[str] = getattr(self, "lost", set())
        for stmt, (out, at, keys) in reversed(waiting):
            if not any(out is candidate for candidate in live):
                lost |= keys
            elif not any(getattr(node, "span", None) == stmt.span for node in out[at:]):
                self._keep_krl_only(stmt, reason)
                out.insert(at, self.out.pop())
        waiting.clear()

    def _keep_runtime_motion(self, stmt: MotionStmt, base: str, reason: str) -> None:
        """Keep a _REL motion by run-time offsets as written (:class:`~olp.ir.Verbatim`, with a
        warning: :class:`~olp.ir.RuntimeMove` holds an absolute target): the KRL post writes it
        back, the controller computes the target; olp checks nothing of it, and the next motion
        starts where olp does not know."""
        self._settings_written_before(stmt, base, reason)
        self._keep(stmt, f"its target is known only when the program runs ({reason})")
        self._note(
            stmt.span,
            f"{stmt.keyword} to a target olp cannot know offline ({reason}): kept as written "
            "and not checked (reach, limits, collisions, time)",
        )
        self.track.lose(
            RuntimeStart(f"the {stmt.keyword} at line {stmt.span.line} goes to a run-time target")
        )
        self._after_with = None

    def _after_kept_settings(self, span: ir.SourceSpan) -> None:
        """A motion olp models after a BAS kept as written (one given run-time values) in the
        same straight stretch: the BAS changed the controller's settings behind the output's
        back, and the posts write a setting only where it differs from the previous motion's,
        so this motion could run with the BAS's values. An error naming the BAS.

        The look back ends at the previous motion too: that one was checked the same way, so
        nothing before it can be such a BAS (one scan per motion, not one over the whole
        straight stretch: a pendant program of thousands of motions was quadratic)."""
        for node in reversed(self.out):
            if isinstance(node, (ir.Label, *ir.BLOCK_TYPES)):
                return
            if isinstance(node, (Pending, PendingRows, ir.RuntimeMove, *ir.MOTION_TYPES)):
                return  # (after a run-time motion with the controller's settings, the output
                # writes every setting of the next motion again)
            if isinstance(node, ir.Verbatim) and node.reason.startswith("BAS #"):
                raise self._error(
                    f"this motion follows {node.text} (line {node.span.line}), kept as written "
                    "because it sets motion settings from run-time values: olp cannot make the "
                    "output write the settings this motion runs with after it",
                    span,
                    hint="olp keeps such a BAS where no motion follows it before the end of its "
                    "block or a label (a routine that only sets the speeds)",
                )

    def _settings_written_before(self, stmt: MotionStmt, base: str, reason: str) -> None:
        """A motion kept as written runs with the tool, base, speed and approximation the
        controller holds; the posts write those only before the motions olp models, and only
        where they change. So it is kept only right after a modelled motion of its kind (PTP,
        or LIN/CIRC) with the same settings, in the same straight stretch of the program: the
        output has written them there and nothing in between changes them."""
        zone = self._zone(stmt, base)
        fields = self._fields(stmt, zone)
        joint = base == "PTP"
        why = self._previous_settings(fields, joint)
        if why is not None:
            raise self._error(
                f"{stmt.keyword} to a target olp cannot know offline ({reason}): olp would keep "
                f"it as written, but cannot write the motion settings it runs with ({why})",
                stmt.span,
                hint=f"olp keeps such a motion only right after a {'PTP' if joint else 'LIN'} "
                "with the same tool, base, speed and approximation, in the same block; or give "
                "it a target olp can compute (a taught point, a constant offset)",
            )

    def _previous_settings(self, fields: dict[str, Any], joint: bool) -> str | None:
        """Why the settings in ``fields`` may not be on the controller here, else None."""
        for node in reversed(self.out):
            if isinstance(node, ir.Verbatim) and (node.native_only or _is_motion_text(node.text)):
                continue  # a motion kept before, already checked, or $BWDSTART: no setting
            if isinstance(node, Pending):
                made, got = node.make, node.fields
            elif isinstance(node, PendingRows):  # plain LINs: the last row is the one before
                made, got = ir.LinearMove, dict(node.fields)
                got["speed"] = dataclasses.replace(got["speed"], linear=float(node.speeds[-1]))
                got["zone"] = ir.Zone(radius=float(node.zones[-1]))
            elif isinstance(node, ir.JointMove | ir.LinearMove | ir.CircularMove):
                made = type(node)
                got = {k: getattr(node, k) for k in ("speed", "zone", "tool", "frame")}
            elif isinstance(node, ir.Comment | ir.Wait | ir.SetOutput | ir.WaitInput):
                continue
            elif isinstance(node, ir.Assign | ir.Declare | ir.WaitUntil):
                target = getattr(node, "target", None)
                if isinstance(target, ir.Name | ir.Index | ir.Member) and _names_system(target):
                    return f"line {node.span.line} sets a system variable olp writes as written"
                continue
            else:
                kind = getattr(node, "kind", type(node).__name__)
                line = getattr(getattr(node, "span", None), "line", "?")
                return f"no motion of its kind before it since the {kind} at line {line}"
            if (made is ir.JointMove) != joint:
                return "the motion before it is of another kind"
            for key in ("tool", "frame", "speed", "zone"):
                if not _same(got[key], fields[key]):
                    return f"its {key} differs from the motion's before it"
            return None
        return "no motion before it in its block"

    def _plain_motion(self, stmt: MotionStmt, base: str, relative: bool) -> None:
        zone = self._zone(stmt, base)
        if base == "PTP":
            target = self._relative(stmt, stmt.targets[0]) if relative else self._ptp_target(stmt)
            self._emit(ir.JointMove, target, None, self._fields(stmt, zone))
            return
        via: Cartesian | None = None
        if base == "CIRC":
            start = self.track.cartesian, self.track.no_cartesian
            via = self._point(stmt, stmt.targets[0], relative)
            # The end point's missing components (and CIRC_REL's offsets) refer to the start.
            self.track.cartesian, self.track.no_cartesian = start
        target = self._point(stmt, stmt.targets[-1], relative)
        self._note_default_speed(stmt)
        fields = self._fields(stmt, zone)
        if base == "CIRC":
            fields.update(self._arc_fields(stmt))
        else:
            self._note_line_orientation(stmt)
        make = ir.CircularMove if base == "CIRC" else ir.LinearMove
        self._emit(make, target, via, fields)
        if stmt.angle is not None:
            line = stmt.span.line
            self.track.lose_cartesian(f"the CIRC with CA at line {line} ends off its end point")

    def _arc_fields(self, stmt: MotionStmt) -> dict[str, Any]:
        """A CIRC's circular angle (``CA``, degrees, signed, not 0) and orientation rule (the
        state's ``$ORI_TYPE`` and ``$CIRC_TYPE``, :data:`olp.vendors.kuka.ARC_ORIENTATIONS`).
        SCIRC follows the same rules in olp (its ``$CIRC_MODE`` is not modelled: noted)."""
        fields: dict[str, Any] = {"orientation": self.state.arc_orientation}
        if stmt.keyword == "SCIRC":
            message = (
                "SCIRC is planned like CIRC: orientation by $ORI_TYPE/$CIRC_TYPE, the auxiliary "
                "point's orientation not reached ($CIRC_MODE is not modelled; unverified default)"
            )
            self._note(stmt.span, message, once="scirc-mode")
        if stmt.angle is not None:
            degrees = self._number(stmt.angle, "CA (circular angle, deg)")
            if degrees == 0:
                raise self._error("CA (circular angle) must not be 0", stmt.angle.span)
            fields["angle"] = math.radians(degrees)
        return fields

    def _note_line_orientation(self, stmt: MotionStmt) -> None:
        if self.state.ori_type != "VAR":
            message = (
                f"$ORI_TYPE #{self.state.ori_type} is not modelled for {stmt.keyword}: olp "
                "interpolates the orientation from the start to the target"
            )
            self._note(stmt.span, message)

    def _point(self, stmt: MotionStmt, expr: Expr, relative: bool) -> Cartesian:
        target = self._relative(stmt, expr) if relative else self._cartesian(expr, stmt)
        if not isinstance(target, Cartesian):
            raise self._error(f"{stmt.keyword} needs a Cartesian target {{X ..,Y ..}}", expr.span)
        return target

    def _emit(
        self,
        make: Callable[..., ir.Instruction],
        target: Target,
        via: Cartesian | None,
        fields: dict[str, Any],
    ) -> None:
        self._after_kept_settings(fields["span"])
        if isinstance(target, ir.JointTarget):
            self.out.append(make(target=target, **fields))
        else:
            self.out.append(Pending(make, target, via, fields))

    def _fields(self, stmt: MotionStmt, zone: ir.Zone) -> dict[str, Any]:
        self._note_unset_frames(stmt)
        state = self.state
        return {
            "speed": state.speed,
            "zone": zone,
            "tool": state.tool,
            "frame": state.frame,
            "span": stmt.span,
            **_spline(stmt.keyword),
        }

    def _note_unset_frames(self, stmt: MotionStmt) -> None:
        """A motion before the program sets its tool (base): olp checks it with the flange
        (the world) and the output writes that before it, where the source ran with the one
        the controller held when the module started (its caller's, the last program's). A
        warning, once each (then the fast path may take the motions again)."""
        unset: set[str] = getattr(self, "unset", set())
        for name in sorted(unset):
            setting, what, default = _UNSET_WORDS[name]
            message = (
                f"{stmt.keyword} before any {setting}: olp checks it with the {default} "
                f"($NULLFRAME) as its {what}, and the output sets that {what} before it, while "
                f"the source runs with the {what} the controller holds when the module starts "
                f"(a caller's, the last program's): set {setting} (or use an inline form) "
                "before the first motion if the module relies on another"
            )
            self._note(stmt.span, message, once=f"unset-{name}")
        unset.clear()

    def _note_default_speed(self, stmt: MotionStmt) -> None:
        if not self.state.vel_cp_set:
            message = (
                f"{stmt.keyword} before any $VEL.CP: olp assumes {DEFAULT_VEL_CP} m/s, the value "
                "BAS(#INITMOV) is reported to set; set $VEL.CP to be sure"
            )
            self._note(stmt.span, message, once="default-vel-cp")

    # ---- approximation
    def _zone(self, stmt: MotionStmt, base: str) -> ir.Zone:
        if not stmt.approx:
            return ir.FINE
        self._check_approx(stmt, base)
        if self.state.cdis_mm is None:
            message = (
                f"{' '.join(stmt.approx)} before any $APO.CDIS: olp does not know the "
                "controller's approximation distance and programs an exact stop"
            )
            self._note(stmt.span, message)
            return ir.FINE
        if base != "PTP" and stmt.approx[0] in ("C_VEL", "C_ORI"):
            self._note(stmt.span, f"{stmt.approx[0]} is approximated with the $APO.CDIS distance")
        return ir.Zone(self.state.cdis_mm / 1000.0)

    def _check_approx(self, stmt: MotionStmt, base: str) -> None:
        """A spline motion approximates with C_SPL; an SPTP also takes C_DIS, which real KR C4
        programs write (``SPTP basePos[i] C_DIS``, ``SPTP X WITH ..., $APO.CDIS = 500 C_DIS``,
        in three of the public cells measured with benchmarks/krl_corpus.py) and olp reads as
        C_SPL: the $APO.CDIS distance. (The KSS manual was not at hand to confirm it.)"""
        approx = stmt.approx
        spline = stmt.keyword in _SPLINE_MOTIONS
        problem = approximation_problem(approx, base == "PTP", spline)
        if problem is not None:
            rule = problem.replace("a LIN or CIRC", stmt.keyword, 1)
            raise self._error(f"invalid approximation {' '.join(approx)!r}: {rule}", stmt.span)

    # ---- targets
    def _position(self, expr: Expr, stmt: MotionStmt) -> tuple[Aggregate, str | None]:
        """The position ``expr`` names (an inline aggregate or a declared point) and its name."""
        if isinstance(expr, Aggregate):
            return expr, None
        named = isinstance(expr, Var) and not expr.selectors and not expr.name.startswith("$")
        name = expr.name if isinstance(expr, Var) and named else None
        return self._aggregate(expr, f"{stmt.keyword} to"), name

    def _ptp_target(self, stmt: MotionStmt) -> Target:
        agg, name = self._position(stmt.targets[0], stmt)
        if is_axis_aggregate(agg):
            return self._joint_target(agg, stmt, name)
        return self._cartesian_from(agg, stmt, name, ptp=True)

    def _cartesian(self, expr: Expr, stmt: MotionStmt) -> Cartesian:
        agg, name = self._position(expr, stmt)
        if is_axis_aggregate(agg):
            raise self._error(f"{stmt.keyword} needs a Cartesian target {{X ..,Y ..}}", agg.span)
        return self._cartesian_from(agg, stmt, name, ptp=False)

    def _joint_target(self, agg: Aggregate, stmt: MotionStmt, name: str | None) -> ir.JointTarget:
        members = self._members(agg, frozenset(AXES + EXTERNAL), "axis")
        missing = [a for a in AXES if a not in members]
        if missing:
            raise self._error(
                f"{stmt.keyword} to axis values needs all of A1..A6; missing {', '.join(missing)}",
                agg.span,
                hint="the other axes would keep the robot's current values, which olp cannot know",
            )
        degrees = tuple(self._number(members[a], a) for a in AXES)
        self._check_external(members, stmt)
        return self._went_to_axes(degrees, stmt, name)

    def _went_to_axes(
        self, degrees: tuple[float, ...], stmt: MotionStmt, name: str | None
    ) -> ir.JointTarget:
        self.track.at_axes(degrees, stmt.span.line)
        return ir.JointTarget(joints=np.radians(degrees), name=name)

    def _went_to(self, values: tuple[float, ...], stmt: MotionStmt) -> None:
        self.track.at_position(values, stmt.span.line)

    def _cartesian_from(
        self, agg: Aggregate, stmt: MotionStmt, name: str | None, ptp: bool
    ) -> Cartesian:
        typed = agg.type_name is not None and agg.type_name.upper() != "FRAME"
        allowed = CARTESIAN + EXTERNAL + (("S", "T") if typed or agg.type_name is None else ())
        members = self._members(agg, frozenset(allowed), "position component")
        values = self._complete(agg, members, stmt)
        self._check_external(members, stmt)
        config = self._record_status_turn(members, stmt, ptp)
        self._went_to(values, stmt)
        return Cartesian(values, name, config)

    def _complete(
        self, agg: Aggregate, members: dict[str, Expr], stmt: MotionStmt
    ) -> tuple[float, ...]:
        """X..C from the aggregate, missing ones from the previous Cartesian target."""
        missing = [c for c in CARTESIAN if c not in members]
        previous = self.track.cartesian
        if previous is None:
            if missing:
                raise self._error(
                    f"{stmt.keyword} target leaves out {', '.join(missing)}, which KRL takes from "
                    f"the start position; olp cannot know it because {self.track.no_cartesian}",
                    agg.span,
                    hint="give all of X, Y, Z, A, B, C",
                )
            previous = (0.0,) * len(CARTESIAN)
        return tuple(
            self._number(members[c], c) if c in members else previous[i]
            for i, c in enumerate(CARTESIAN)
        )

    # ---- relative (_REL) targets
    def _relative(self, stmt: MotionStmt, expr: Expr) -> Target:
        """A _REL target: offsets from the start position, made absolute (the start must be
        known from the program text)."""
        agg, _ = self._position(expr, stmt)
        if is_axis_aggregate(agg):
            if _BASE_MOTION[stmt.keyword] != "PTP":
                raise self._error(f"{stmt.keyword} needs Cartesian offsets {{X ..}}", agg.span)
            return self._relative_axes(agg, stmt)
        option = stmt.frame_option.name.upper() if stmt.frame_option is not None else "BASE"
        if option not in ("BASE", "TOOL"):
            assert stmt.frame_option is not None
            raise self._error("a _REL motion is relative to #BASE or #TOOL", stmt.frame_option.span)
        members = self._members(agg, frozenset(CARTESIAN + EXTERNAL), "offset component")
        start = self.track.cartesian
        if start is None:
            raise self._error(
                f"{stmt.keyword} moves relative to the start position; olp cannot know it "
                f"because {self.track.no_cartesian}",
                stmt.span,
            )
        delta = tuple(self._number(members[c], c) if c in members else 0.0 for c in CARTESIAN)
        self._check_external(members, stmt)
        values = _offset(start, delta, option)
        self._went_to(values, stmt)
        return Cartesian(values)

    def _relative_axes(self, agg: Aggregate, stmt: MotionStmt) -> ir.JointTarget:
        members = self._members(agg, frozenset(AXES + EXTERNAL), "axis")
        start = self.track.joints
        if start is None:
            raise self._error(
                f"{stmt.keyword} moves the axes relative to where they are; olp cannot know "
                f"that because {self.track.no_joints}",
                stmt.span,
            )
        degrees = tuple(
            start[i] + (self._number(members[a], a) if a in members else 0.0)
            for i, a in enumerate(AXES)
        )
        self._check_external(members, stmt)
        return self._went_to_axes(degrees, stmt, None)

    def _check_external(self, members: dict[str, Expr], stmt: MotionStmt) -> None:
        used = [e for e in EXTERNAL if e in members and self._number(members[e], e) != 0]
        if used:
            message = f"external axis values ({', '.join(used)}) are not supported yet; dropped"
            self._note(stmt.span, message)

    def _record_status_turn(
        self, members: dict[str, Expr], stmt: MotionStmt, ptp: bool
    ) -> ir.Configuration | None:
        """S and T are kept (:attr:`KrlResult.status_turn`); a PTP target with both gets the
        :class:`~olp.ir.Configuration` they ask for. LIN/CIRC get none: the controller ignores
        S/T there (the branch follows from the start), so olp must not enforce one."""
        status = self._integer(members["S"], "S (Status)") if "S" in members else None
        turn = self._integer(members["T"], "T (Turn)") if "T" in members else None
        if status is None and turn is None:
            return None
        record = StatusTurn(stmt.span, status, turn)
        if ("st", record) not in self._reported:
            self._reported.add(("st", record))
            self.status_turn.append(record)
        if not ptp or status is None or turn is None:
            return None
        try:
            return configuration_from_status_turn(status, turn)
        except ValueError as exc:
            culprit = members["S"] if not 0 <= status < 32 else members["T"]
            raise self._error(str(exc), culprit.span) from None

    # ---- WITH
    def _with_motion(
        self, stmt: MotionStmt, base: str, relative: bool, runtime: str | None = None
    ) -> None:
        """WITH assignments hold for this motion only (olp's reading of the KSS manual,
        unverified); the next motion without WITH gets a note saying so. ``runtime``: why the
        target is known only at run time (then a :class:`~olp.ir.RuntimeMove`), or None."""
        saved = self.state
        ambiguous = dict(getattr(self, "ambiguous", {}))  # the WITH's values are this motion's
        unset = set(getattr(self, "unset", set()))  # a WITH's tool is not the program's
        self.in_with = True  # a $BASE or $TOOL set from a run-time value cannot be kept here
        try:
            for assignment in stmt.with_clause:
                self._with_assignment(assignment)
        finally:
            self.in_with = False
        during = self.state
        if runtime is None:
            self._plain_motion(stmt, base, relative)
        else:
            self._runtime_motion(stmt, base, runtime)
        self.state = saved
        if hasattr(self, "ambiguous"):
            self.ambiguous = ambiguous
        if hasattr(self, "unset"):
            self.unset = unset
        if (during.tool, during.frame) != (saved.tool, saved.frame):
            line = stmt.span.line
            self.track.lose_cartesian(f"the WITH at line {line} set $TOOL/$BASE for that motion")
        self._after_with = stmt.span.line if during != saved else None

    def _note_after_with(self, stmt: MotionStmt) -> None:
        if self._after_with is not None:
            self._note(
                stmt.span,
                f"olp takes the WITH values of line {self._after_with} as valid for that motion "
                "only (unverified); this motion uses the values set before it",
            )
            self._after_with = None


def _offset(start: tuple[float, ...], delta: tuple[float, ...], option: str) -> tuple[float, ...]:
    """``start`` moved by ``delta`` (X..C, mm/deg): in the tool frame (#TOOL: start · delta), or
    along and about the base axes (#BASE: positions add, the rotation is applied in the base)."""
    start_pose, delta_pose = frame_to_pose(start), frame_to_pose(delta)
    if option == "TOOL":
        pose = start_pose @ delta_pose
    else:
        pose = start_pose.copy()
        pose[:3, :3] = delta_pose[:3, :3] @ start_pose[:3, :3]
        pose[:3, 3] = start_pose[:3, 3] + delta_pose[:3, 3]
    return tuple(float(v) for v in pose_to_frame(pose))


_POSITION_TYPES = frozenset({"AXIS", "E6AXIS", "POS", "E6POS", "FRAME"})
_RUNTIME_KINDS: dict[str, Any] = {"PTP": "joint", "LIN": "linear", "CIRC": "circular"}

RelativeKind = Literal["base", "tool", "axes", "start"]


class RuntimeStart(str):
    """Why the robot's position is unknown, when it is because a motion went where only the
    run time knows (a :class:`~olp.ir.RuntimeMove`, a motion kept as written): a motion that
    refers to its start position is then a run-time motion too (:meth:`Motions._runtime_start`).
    A ``str`` so that :class:`~olp.frontends.krl.state.Track` holds it as any reason."""

    __slots__ = ()


_MOTION_TEXT = re.compile(r"\s*(S?PTP|S?LIN|S?CIRC)(_REL)?\b", re.IGNORECASE)


_UNSET_WORDS = {"tool": ("$TOOL", "tool", "flange"), "frame": ("$BASE", "base", "world")}
"""A state field -> its KRL variable, its name and what olp takes before the program sets it."""


def _spline(keyword: str) -> dict[str, bool]:
    """``spline=True`` for a spline motion (``SLIN``, ``SPTP_REL``, ...), so that KRL writes
    its keyword back; nothing for a plain one (a plain LIN keeps the fields a row of a
    :class:`~olp.ir.LinearPath` holds, :mod:`olp.frontends.krl.rows`)."""
    return {"spline": True} if keyword.upper() in _SPLINE_MOTIONS else {}


def _is_motion_text(text: str) -> bool:
    return _MOTION_TEXT.match(text) is not None


def _names_system(expr: Any) -> bool:
    """Whether an assignment target is (part of) a system variable (``$APO.CPTP``)."""
    while isinstance(expr, ir.Index | ir.Member):
        expr = expr.base
    return isinstance(expr, ir.Name) and expr.name.startswith("$")


def _same(a: Any, b: Any) -> bool:
    """Equal motion settings (tools and frames compared by name, number and pose)."""
    if isinstance(a, ir.Tool | ir.Frame) and isinstance(b, ir.Tool | ir.Frame):
        return (
            type(a) is type(b)
            and a.name == b.name
            and a.number == b.number
            and np.array_equal(np.asarray(a.pose), np.asarray(b.pose))
        )
    return bool(a == b)
