"""KRL lowering of the pendant's inline forms: KUKA's BAS routine and the spline WITH lists.

KSS 8 inline forms (KUKATPBASIS) write ``PDAT_ACT=PPDAT1``, ``FDAT_ACT=FP1`` and
``BAS(#PTP_PARAMS, 100)`` before each motion; the spline forms write ``SPTP XP1 WITH
$VEL_AXIS[1] = SVEL_JOINT(100.0), $TOOL = STOOL2(FP1), ...``. Both are read here as the
assignments they stand for (KUKA's documented meaning; unverified against ``BAS.SRC`` or a
controller). See :mod:`olp.frontends.krl` for the rules.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from olp.frontends.krl.ast import (
    Aggregate,
    Assign,
    CallStmt,
    EnumValue,
    Expr,
    FuncCall,
)
from olp.frontends.krl.native import INITMOV
from olp.frontends.krl.state import (
    ACC_AXIS_PARTS,
    KRL_ONLY_SYSTEM_VARIABLES,
    SYSTEM_REASONS,
    VEL_AXIS_PARTS,
    WRITTEN,
    Core,
    Held,
)
from olp.frontends.krl.values import (
    Unknown,
)

_BAS_READS: dict[str, tuple[str, ...]] = {
    "VEL_CP": ("value",),
    "VEL_PTP": ("value",),
    "ACC_PTP": ("value",),
    "TOOL": ("value",),
    "BASE": ("value",),
    "FRAMES": ("FDAT_ACT",),
    "PTP_DAT": ("PDAT_ACT",),
    "CP_DAT": ("LDAT_ACT",),
    "PTP_PARAMS": ("value", "FDAT_ACT", "PDAT_ACT"),
    "CP_PARAMS": ("value", "FDAT_ACT", "LDAT_ACT"),
}
"""What each BAS command reads: its value argument and the inline forms' data records."""

_PTP_SPEEDS = ("vel_axis", "acc_axis", "speed", *VEL_AXIS_PARTS, *ACC_AXIS_PARTS)
_BAS_SETS: dict[str, tuple[str, ...]] = {
    "VEL_CP": ("speed", "vel_cp"),
    "VEL_PTP": ("vel_axis", "speed", *VEL_AXIS_PARTS),
    "ACC_PTP": ("acc_axis", "speed", *ACC_AXIS_PARTS),
    "TOOL": ("tool",),
    "BASE": ("frame",),
    "FRAMES": ("tool", "frame"),
    "PTP_DAT": (*_PTP_SPEEDS, "cdis_mm"),
    "CP_DAT": ("speed", "vel_cp", "cdis_mm"),
    "PTP_PARAMS": (*_PTP_SPEEDS, "cdis_mm", "tool", "frame"),
    "CP_PARAMS": ("speed", "vel_cp", "cdis_mm", "tool", "frame"),
}
"""The motion settings (fields of :class:`~olp.frontends.krl.state.State` and the parts of the
speed held apart, :data:`~olp.frontends.krl.state.SPEED_PARTS`) each BAS command sets, as
:meth:`InlineForms._bas_handlers` lowers them."""


class InlineForms(Core):
    """BAS commands and WITH assignments of the inline forms."""

    # ---- KUKA's BAS routine (the KUKATPBASIS inline forms)
    def _bas(self, stmt: CallStmt) -> None:
        """BAS commands that stand for plain assignments, and those of the inline forms."""
        command = stmt.args[0] if stmt.args else None
        name = command.name.upper() if isinstance(command, EnumValue) else ""
        handler = self._bas_handlers().get(name)
        if handler is None:
            raise self._error(
                f"BAS command {self.sources.snippet(stmt.span)!r} is not supported yet",
                stmt.span,
                hint="olp lowers BAS #INITMOV, #VEL_CP, #VEL_PTP, #ACC_PTP, #ACC_CP, #TOOL, "
                "#BASE, #FRAMES, #PTP_DAT, #CP_DAT, #PTP_PARAMS and #CP_PARAMS",
            )
        reason = self._bas_runtime(stmt, name)
        if reason is None:
            handler(stmt)
        else:
            self._bas_at_run_time(stmt, name, reason)

    def _bas_runtime(self, stmt: CallStmt, command: str) -> str | None:
        """Why BAS ``command`` reads a value known only when the program runs (its argument,
        or ``PDAT_ACT``/``LDAT_ACT``/``FDAT_ACT`` given a parameter or a path-dependent value,
        as in a routine ``SetVel(eVelocity)`` that picks the PDAT by a SWITCH), else None."""
        reads = _BAS_READS.get(command, ())
        for read in reads:
            if read == "value":
                arg = stmt.args[1] if len(stmt.args) == 2 else None
                value = None if arg is None else self._value(arg)
            else:
                value = self.variables.lookup(read)
            if value is not None and self._runtime(value):
                assert isinstance(value, Unknown)
                return value.reason
            stationary = self._stationary_tool(value) if read == "FDAT_ACT" else None
            if stationary is not None:
                return stationary
        return None

    def _stationary_tool(self, fdat: Any) -> str | None:
        """Why an FDAT's ``IPO_FRAME #TCP`` leaves the motions it sets to the run, else None.

        ``#TCP`` is KUKA's external-TCP mode: the tool stands in the cell (a nut welder, a
        pedestal gun) and the robot carries the part past it, so the programmed point is the
        part's, in the fixed tool's frame. olp models robot-held tools only: the BAS is kept as
        written and the motion right after it runs with the settings it gives (a run-time
        motion: written back as written by the KUKA post, not checked, refused by the others).
        """
        mode = fdat.member("IPO_FRAME") if isinstance(fdat, Aggregate) else None
        found = None if mode is None else self._value(mode.value)
        if not (isinstance(found, EnumValue) and found.name.upper() == "TCP"):
            return None
        assert mode is not None
        return (
            f"FDAT_ACT's IPO_FRAME #TCP ({mode.value.span.location}) moves the part past a "
            "stationary tool (external TCP), which olp does not model: the motion is the "
            "controller's to plan, not checked"
        )

    def _bas_at_run_time(self, stmt: CallStmt, command: str, reason: str) -> None:
        """Keep a BAS command with run-time values as written: the KRL post writes it back;
        the motion settings it sets are unknown from here on, so a motion that relies on them
        is an error, and a module without one (a settings routine) builds.

        The records it reads that olp knows (``PDAT_ACT = PDEFAULT`` beside a run-time
        ``FDAT_ACT = FHOME``) had their assignments absorbed into the motions: they are written
        before it, or the BAS would read whatever the controller held."""
        self._write_absorbed_records(stmt, command)
        self._keep(stmt, f"BAS #{command} with a value known only at run time ({reason})")
        ambiguous: dict[str, str] | None = getattr(self, "ambiguous", None)
        why = Held(f"BAS(#{command}) at line {stmt.span.line} sets them from run-time values")
        for field_name in _BAS_SETS[command]:
            if ambiguous is not None:
                ambiguous[field_name] = why
        if {"tool", "frame"} & set(_BAS_SETS[command]):
            self.track.lose_cartesian(f"$TOOL/$BASE were set at run time at line {stmt.span.line}")

    def _write_absorbed_records(self, stmt: CallStmt, command: str) -> None:
        for read in _BAS_READS.get(command, ()):
            if read == "value" or self._runtime(self.variables.lookup(read)):
                continue
            absorbed = self.absorbed_data.get(read, WRITTEN)
            if absorbed == WRITTEN:  # (or never assigned: the output left it as olp assumes)
                continue
            if not isinstance(absorbed, Assign):
                raise self._error(
                    f"this BAS reads {read}, whose value olp knows but cannot write back here "
                    "(assigned member by member, or in another block): the BAS is kept as written "
                    f"(it also reads a value known only at run time), so it would read a {read} "
                    "the output never set",
                    stmt.span,
                    hint=f"assign {read} a whole record right before the BAS",
                )
            self.out.append(self._assignment(absorbed))
            self.absorbed_data[read] = WRITTEN

    def _bas_handlers(self) -> dict[str, Callable[[CallStmt], None]]:
        return {
            "INITMOV": lambda s: self._ignore(s, INITMOV),
            "ACC_CP": lambda s: self._ignore(
                s, "BAS #ACC_CP is a percentage of the machine's path acceleration, unknown to olp"
            ),
            "VEL_CP": lambda s: self._vel_cp(self._bas_number(s, "$VEL.CP (m/s)"), s.span),
            "VEL_PTP": lambda s: self._all_axes("$VEL_AXIS", self._bas_percent(s, "#VEL_PTP")),
            "ACC_PTP": lambda s: self._all_axes("$ACC_AXIS", self._bas_percent(s, "#ACC_PTP")),
            "TOOL": lambda s: self._tool_number(self._bas_int(s, "TOOL_DATA"), s, s.span),
            "BASE": lambda s: self._base_number(self._bas_int(s, "BASE_DATA"), s, s.span),
            "FRAMES": self._bas_frames,
            "PTP_DAT": lambda s: self._bas_ptp(s, None),
            "CP_DAT": lambda s: self._bas_cp(s, None),
            "PTP_PARAMS": lambda s: self._bas_ptp(s, self._bas_percent(s, "#PTP_PARAMS"), True),
            "CP_PARAMS": lambda s: self._bas_cp(s, self._bas_number(s, "#CP_PARAMS (m/s)"), True),
        }

    def _bas_value(self, stmt: CallStmt, what: str) -> Expr:
        value = stmt.args[1] if len(stmt.args) == 2 else None
        if value is None:
            raise self._error(f"BAS needs a value for {what}", stmt.span)
        return value

    def _bas_number(self, stmt: CallStmt, what: str) -> float:
        return self._number(self._bas_value(stmt, what), what)

    def _bas_percent(self, stmt: CallStmt, what: str) -> float:
        return self._percent(self._bas_value(stmt, what), what)

    def _bas_int(self, stmt: CallStmt, table: str) -> int:
        return self._integer(self._bas_value(stmt, table), f"the {table} number")

    def _bas_record(self, stmt: CallStmt, variable: str) -> Aggregate:
        """The PDAT/LDAT/FDAT a BAS command reads from ``PDAT_ACT``/``LDAT_ACT``/``FDAT_ACT``."""
        value = self.variables.lookup(variable)
        if isinstance(value, Aggregate):
            return value
        command = self.sources.snippet(stmt.span)
        why = value.reason if isinstance(value, Unknown) else "it is not an aggregate {...}"
        hint = value.hint if isinstance(value, Unknown) else None
        raise self._error(
            f"{command} reads {variable}, which has no value olp knows: {why}",
            stmt.span,
            hint or f"the inline forms set {variable} just before BAS (e.g. PDAT_ACT=PPDAT1)",
        )

    def _bas_frames(self, stmt: CallStmt) -> None:
        """FDAT_ACT's tool, base and interpolation mode become $TOOL, $BASE and $IPO_MODE."""
        fdat = self._bas_record(stmt, "FDAT_ACT")
        for member, apply in (
            ("TOOL_NO", lambda n, span: self._tool_number(n, stmt, span)),
            ("BASE_NO", lambda n, span: self._base_number(n, stmt, span)),
        ):
            found = fdat.member(member)
            if found is not None:
                apply(self._integer(found.value, f"FDAT {member}"), found.value.span)
        mode = fdat.member("IPO_FRAME")
        if mode is not None:
            self._ipo_mode(self._value(mode.value), mode.value.span)

    def _bas_ptp(self, stmt: CallStmt, percent: float | None, frames: bool = False) -> None:
        """PDAT_ACT (VEL %, ACC %, APO_DIST mm) for the following PTP motions."""
        if frames:
            self._bas_frames(stmt)
        pdat = self._bas_record(stmt, "PDAT_ACT")
        vel = pdat.member("VEL")
        if percent is None and vel is not None:
            percent = self._percent(vel.value, "PDAT VEL")
        if percent is not None:
            self._all_axes("$VEL_AXIS", percent)
        acc = pdat.member("ACC")
        if acc is not None:
            self._all_axes("$ACC_AXIS", self._percent(acc.value, "PDAT ACC"))
        self._record_apo(pdat, "PDAT")

    def _bas_cp(self, stmt: CallStmt, speed: float | None, frames: bool = False) -> None:
        """LDAT_ACT (VEL m/s, APO_DIST mm) for the following LIN/CIRC motions."""
        if frames:
            self._bas_frames(stmt)
        ldat = self._bas_record(stmt, "LDAT_ACT")
        vel = ldat.member("VEL")
        if speed is None and vel is not None:
            speed = self._number(vel.value, "LDAT VEL (m/s)")
        if speed is not None:
            self._vel_cp(speed, stmt.span)
        acc = ldat.member("ACC")
        if acc is not None and self._number(acc.value, "LDAT ACC") != 100:
            self._note(stmt.span, "the path acceleration (LDAT ACC) is not modelled", "ldat-acc")
        self._record_apo(ldat, "LDAT")

    def _record_apo(self, record: Aggregate, what: str) -> None:
        apo = record.member("APO_DIST")
        if apo is not None:
            self._cdis(self._number(apo.value, f"{what} APO_DIST (mm)"), apo.value.span, what)

    # ---- WITH (the spline inline forms)
    def _with_assignment(self, assign: Assign) -> None:
        key = assign.target.key
        value = assign.value
        if not isinstance(value, FuncCall):
            self._assign(assign)
            return
        handler = self._with_functions().get((key, value.name.upper()))
        if handler is not None:
            handler(value, assign)
        elif key in KRL_ONLY_SYSTEM_VARIABLES:  # the pendant's folds: $LOAD = SLOAD(...), ...
            self._keep_system(assign, key, ": a WITH item of this motion, written before it")
        elif key in SYSTEM_REASONS:
            self._ignore(assign, SYSTEM_REASONS[key])
        else:
            raise self._error(
                f"WITH {self.sources.snippet(assign.span)!r}: olp does not know {value.name}(...)",
                assign.span,
                hint="olp reads the spline inline forms' SVEL_JOINT, SVEL_CP, SACC_JOINT, STOOL2, "
                "SBASE, SIPO_MODE, SAPO, SAPO_PTP, SORI_TYP and SCIRC_TYP",
            )

    def _with_functions(self) -> dict[tuple[str, str], Callable[[FuncCall, Assign], None]]:
        return {
            ("$VEL_AXIS[]", "SVEL_JOINT"): lambda f, a: self._all_axes(
                "$VEL_AXIS", self._percent(self._arg(f, 0), "SVEL_JOINT")
            ),
            ("$ACC_AXIS[]", "SACC_JOINT"): lambda f, a: self._all_axes(
                "$ACC_AXIS", self._record_number(f, "ACC", percent=True)
            ),
            ("$VEL", "SVEL_CP"): lambda f, a: self._vel_cp(
                self._number(self._arg(f, 0), "SVEL_CP (m/s)"), a.span
            ),
            ("$TOOL", "STOOL2"): lambda f, a: self._tool_number(
                int(self._record_number(f, "TOOL_NO", integer=True)), a, a.span
            ),
            ("$BASE", "SBASE"): lambda f, a: self._base_number(
                self._integer(self._arg(f, 0), "SBASE (BASE_DATA number)"), a, a.span
            ),
            ("$IPO_MODE", "SIPO_MODE"): lambda f, a: self._ipo_mode(
                self._value(self._arg(f, 0)), a.span
            ),
            ("$APO", "SAPO"): lambda f, a: self._cdis(
                self._record_number(f, "APO_DIST"), a.span, "APO_DIST (mm)"
            ),
            ("$APO", "SAPO_PTP"): lambda f, a: self._cdis(
                self._record_number(f, "APO_DIST"), a.span, "APO_DIST (mm)"
            ),
            ("$ORI_TYPE", "SORI_TYP"): lambda f, a: self._record_type(f, "ORI_TYP", "$ORI_TYPE"),
            ("$CIRC_TYPE", "SCIRC_TYP"): lambda f, a: self._record_type(
                f, "CIRC_TYP", "$CIRC_TYPE"
            ),
        }

    def _record_type(self, call: FuncCall, member: str, name: str) -> None:
        """``$ORI_TYPE = SORI_TYP(LCPDAT1)``: the LDAT's ``ORI_TYP`` (``CIRC_TYP``); an LDAT
        without the member leaves the type as it was."""
        last = call.args[-1] if call.args else None
        if last is None:
            raise self._error(f"{call.name}(...) needs a data set as its last argument", call.span)
        found = self._aggregate(last, f"{call.name} reads").member(member)
        if found is not None:
            self._orientation_type(name, self._value(found.value), found.value.span)

    def _arg(self, call: FuncCall, index: int) -> Expr:
        arg = call.args[index] if index < len(call.args) else None
        if arg is None:
            raise self._error(f"{call.name} needs argument {index + 1}", call.span)
        return arg

    def _record_number(
        self, call: FuncCall, member: str, percent: bool = False, integer: bool = False
    ) -> float:
        """A member of the PDAT/LDAT/FDAT a spline function takes as its last argument."""
        last = call.args[-1] if call.args else None
        if last is None:
            raise self._error(f"{call.name}(...) needs a data set as its last argument", call.span)
        found = self._aggregate(last, f"{call.name} reads").member(member)
        if found is None:
            raise self._error(f"{call.name}(...) needs a data set with {member}", call.span)
        what = f"{member} of {self.sources.snippet(call.span)}"
        if integer:
            return float(self._integer(found.value, what))
        return self._percent(found.value, what) if percent else self._number(found.value, what)
