"""The core of KRL lowering: the controller state a program sets, and what one run shares.

:class:`Core` holds the state (:class:`State`: speeds, approximation, tool, base; :class:`Track`:
where the robot is, as far as the text tells), the variables, the reports (ignored lines, notes),
value helpers that raise located errors, and the assignments of system variables (``$VEL``,
``$APO``, ``$TOOL``, ``$BASE``, ``$OUT``, ...). :mod:`olp.frontends.krl.inline` (BAS and WITH),
:mod:`olp.frontends.krl.motion` (motions) and :mod:`olp.frontends.krl.lower` (the statement walk,
calls and loops) build on it, in that order.

Cartesian targets are collected as KRL values (mm, deg) and converted to poses in one vectorised
call at the end (:func:`olp.frontends.krl.rows.build_instructions`), as milling programs have
tens of thousands of them.
"""

from __future__ import annotations

import dataclasses
import fnmatch
import functools
import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

from olp import ir
from olp.errors import ParseError
from olp.frontends.krl.ast import (
    Aggregate,
    Assign,
    Binary,
    EnumValue,
    Expr,
    FuncCall,
    IgnoredLine,
    Index,
    Note,
    Routine,
    SourceSet,
    StatusTurn,
    Stmt,
    Unary,
    Var,
)
from olp.frontends.krl.data import DataOps, KrlData, text_value
from olp.frontends.krl.declared import KRL_FUNCTIONS, MODELLED_NAMES, external_functions, uses
from olp.frontends.krl.values import (
    AXES,
    CARTESIAN,
    EXTERNAL,
    POS_TYPES,
    ArrayValue,
    Bool,
    Counter,
    Evaluator,
    Signal,
    Unknown,
    Value,
    Variables,
    as_int,
    as_number,
    frame_values,
    variables_read,
)
from olp.vendors.kuka import ARC_ORIENTATIONS, frame_to_pose

DEFAULT_VEL_CP = 2.0
"""m/s: ``$VEL.CP`` assumed before the program sets it (what ``BAS(#INITMOV, 0)`` is reported to
set on KSS 8; unverified). A LIN/CIRC relying on it gets a note."""


@dataclass(frozen=True, slots=True, kw_only=True)
class KrlResult:
    """What the KRL frontend read: the program and everything it did not lower as-is.

    ``data_sources``: the data lists read besides the .src (its .dat, a ``$config.dat``).
    """

    program: ir.Program
    ignored: tuple[IgnoredLine, ...] = ()
    notes: tuple[Note, ...] = ()
    status_turn: tuple[StatusTurn, ...] = ()
    data_sources: tuple[str, ...] = ()


# ------------------------------------------------------------------------------------------------
# State


@dataclass(frozen=True, slots=True, kw_only=True)
class State:
    """The controller state that motions pick up, as the program has set it so far."""

    speed: ir.Speed = field(default_factory=lambda: ir.Speed(linear=DEFAULT_VEL_CP))
    vel_cp_set: bool = False
    vel_axis: dict[int, float] = field(default_factory=dict)  # percent per axis 1..6
    acc_axis: dict[int, float] = field(default_factory=dict)
    cdis_mm: float | None = None
    tool: ir.Tool = field(default_factory=lambda: ir.FLANGE)
    frame: ir.Frame = field(default_factory=lambda: ir.WORLD)
    ori_type: str = "VAR"  # $ORI_TYPE: VAR, CONSTANT or JOINT
    circ_type: str = "BASE"  # $CIRC_TYPE: BASE or PATH

    @property
    def arc_orientation(self) -> ir.ArcOrientation:
        """The rule of a CIRC under this state (:data:`olp.vendors.kuka.ARC_ORIENTATIONS`)."""
        return ARC_ORIENTATIONS[(self.ori_type, self.circ_type)]


ORI_TYPES = frozenset({"VAR", "CONSTANT", "JOINT"})
CIRC_TYPES = frozenset({"BASE", "PATH"})


class Held(str):
    """Why a motion setting is ambiguous, when it is because the controller holds a value only
    the run time knows: a BAS given run-time values, a motion setting (``$VEL.CP``,
    ``$BASE``, ...) assigned a run-time value (both kept as written), a call of a routine olp
    did not read (which may set any of them). A motion that runs with such a setting runs with
    the controller's settings, which the output leaves as the source does
    (:meth:`olp.frontends.krl.motion.Motions._controller_settings_motion`); one that differs
    between paths olp lowered is not held (olp absorbed the statements that set it, so it
    cannot leave it to the controller). A ``str`` so that the reasons read as any other.

    The speed's parts are held one by one (:data:`SPEED_PARTS`): ``$ACC.CP = 2`` after a
    run-time ``$VEL.CP`` leaves the path speed held."""

    __slots__ = ()


def axis_parts(field_name: str, axes: Sequence[int]) -> tuple[str, ...]:
    """The keys of ``axes`` (1-based) of ``field_name`` (``vel_axis``/``acc_axis``) in
    :data:`SPEED_PARTS`."""
    return tuple(f"{field_name}[{axis}]" for axis in axes)


ALL_AXES = tuple(range(1, len(AXES) + 1))
VEL_AXIS_PARTS = axis_parts("vel_axis", ALL_AXES)
ACC_AXIS_PARTS = axis_parts("acc_axis", ALL_AXES)
PATH_SPEED_PARTS = ("vel_cp", "acc_cp", "acc_ori")
SPEED_PARTS: dict[str, str] = {
    "vel_cp": "$VEL.CP",
    "acc_cp": "$ACC.CP",
    "acc_ori": "$ACC.ORI1",
    **{key: f"$VEL_AXIS[{n}]" for n, key in zip(ALL_AXES, VEL_AXIS_PARTS, strict=True)},
    **{key: f"$ACC_AXIS[{n}]" for n, key in zip(ALL_AXES, ACC_AXIS_PARTS, strict=True)},
}
"""The parts of the speed (:class:`olp.ir.Speed`, ``vel_axis``, ``acc_axis``) that are held
apart (keys of ``ambiguous`` besides the fields of :class:`State`) -> their system variable.
One set from a run-time value is :class:`Held` alone and settled only by setting that part
again: the state's ``speed`` is one object, so a change to it (``$ACC.CP = 2``) cannot tell
which part the program knows again. A PTP runs with the axis parts, a LIN or CIRC with the path
parts (:data:`PATH_SPEED_PARTS`)."""
RUNTIME_HOLDS: dict[str, tuple[str, ...]] = {
    "$VEL.CP": ("vel_cp",),
    "$ACC.CP": ("acc_cp",),
    "$ACC.ORI1": ("acc_ori",),
    "$APO.CDIS": ("cdis_mm",),
    "$ORI_TYPE": ("ori_type",),
    "$CIRC_TYPE": ("circ_type",),
}
"""What an assignment of a motion setting olp models holds when its value is known only at run
time (keys of ``ambiguous``); ``$VEL_AXIS[n]``/``$ACC_AXIS[n]``, ``$TOOL`` and ``$BASE`` are held
by their setters (:meth:`Core._set_axis_percent`, :meth:`Core._frame_at_run_time`)."""


@dataclass(slots=True)
class Track:
    """Where the robot is, as far as the program text tells: the start of the next motion,
    for targets that leave components out and for _REL motions (and why it is unknown)."""

    cartesian: tuple[float, ...] | None = None  # X, Y, Z (mm), A, B, C (deg) in the base
    no_cartesian: str = "there is no earlier Cartesian target in the program"
    joints: tuple[float, ...] | None = None  # A1..A6 (deg)
    no_joints: str = "there is no earlier motion to axis values in the program"

    def lose_cartesian(self, reason: str) -> None:
        self.cartesian, self.no_cartesian = None, reason

    def lose(self, reason: str) -> None:
        """The robot went where olp does not know: neither position nor axes are known."""
        self.cartesian, self.no_cartesian = None, reason
        self.joints, self.no_joints = None, reason

    def at_axes(self, degrees: tuple[float, ...], line: int) -> None:
        self.cartesian = None
        self.no_cartesian = f"the motion at line {line} went to axis values"
        self.joints = degrees

    def at_position(self, values: tuple[float, ...], line: int) -> None:
        self.cartesian = values
        self.joints = None
        self.no_joints = f"the motion at line {line} went to a Cartesian position"


@dataclass(frozen=True, slots=True)
class Cartesian:
    """A Cartesian target before its pose is computed: KRL values X..C (mm, deg)."""

    values: tuple[float, ...]
    name: str | None = None
    config: ir.Configuration | None = None


Target = ir.JointTarget | Cartesian


@dataclass(frozen=True, slots=True)
class Pending:
    """A motion whose Cartesian target(s) get their poses in
    :func:`olp.frontends.krl.rows.build_instructions`."""

    make: Callable[..., ir.Instruction]
    target: Target
    via: Cartesian | None
    fields: dict[str, Any]


@dataclass(frozen=True, slots=True)
class PendingRows:
    """A run of plain LIN motions read as arrays (see
    :meth:`olp.frontends.krl.motion.Motions._lin_rows`).

    ``values`` (N, 6): X, Y, Z (mm), A, B, C (deg) in ``fields["frame"]``; ``speeds`` (N,) m/s;
    ``zones`` (N,) m; ``lines`` (N,) 1-based source lines; ``ends`` (N,) each row's end column
    (exclusive, 1-based; every row starts in column 1). ``fields`` holds the speed (its linear
    part is the first row's), tool, frame and file all rows share.
    """

    values: np.ndarray
    speeds: np.ndarray
    zones: np.ndarray
    lines: np.ndarray
    ends: np.ndarray
    fields: dict[str, Any]

    def __len__(self) -> int:
        return int(self.values.shape[0])


_F = TypeVar("_F", ir.Frame, ir.Tool)
_DATA_TABLES = {"$BASE": "BASE_DATA", "$TOOL": "TOOL_DATA"}
_TABLE_NAMES = {"TOOL_DATA": "TOOL_NAME", "BASE_DATA": "BASE_NAME"}
SYSTEM_REASONS = {
    "$BWDSTART": "$BWDSTART only matters when stepping backwards on the pendant",
    "$APO.CPTP": "$APO.CPTP (%) is not lowered: olp approximates C_PTP with $APO.CDIS",
    "$APO.CORI": "$APO.CORI is not lowered: olp approximates C_ORI with $APO.CDIS",
    "$APO.CVEL": "$APO.CVEL is not lowered: olp approximates C_VEL with $APO.CDIS",
    # Reached only for forms no setter reads (a spline WITH's SACC_CP(...)): plain
    # assignments of $ACC.CP / $ACC.ORI1 / $ACC are lowered.
    "$ACC.CP": "a computed path acceleration ($ACC.CP from a function) is not lowered",
    "$ACC": "a computed path acceleration ($ACC from a function) is not lowered",
    "$ACC.ORI2": "$ACC.ORI2 (rotation about the tool axis) is not lowered: olp's orientation "
    "acceleration is $ACC.ORI1's",
    "$ADVANCE": "the advance run does not change the path",
    "$CIRC_MODE": "$CIRC_MODE is not lowered: olp ignores the auxiliary point's orientation",
    "$LOAD": "payload data are not part of olp's IR",
    "$GEAR_JERK[]": "gear jerk limits are not part of olp's IR",
    "$JERK": "jerk limits are not part of olp's IR",
    "$COLLMON_TOL_PRO[]": "collision-detection tolerances are not modelled",
}
"""Why a system variable olp knows but does not lower is ignored (keys as :attr:`Var.key`)."""
KEPT_SYSTEM_VARIABLES = frozenset(
    {
        "$ACC.CP",
        "$ACC",
        "$ACC.ORI1",
        "$ACC.ORI2",
        "$VEL.ORI1",
        "$VEL.ORI2",
        "$APO.CPTP",
        "$APO.CORI",
        "$APO.CVEL",
        "$ADVANCE",
        "$LOAD",
        "$GEAR_JERK[]",
        "$JERK",
        "$COLLMON_TOL_PRO[]",
    }
)
"""Motion parameters olp does not model yet but must not lose: kept as :class:`~olp.ir.Verbatim`
(timing does not use them; the KRL post writes them back)."""
KRL_ONLY_SYSTEM_VARIABLES = frozenset({"$LOAD", "$GEAR_JERK[]", "$COLLMON_TOL_PRO[]"})
"""System variables that only mean something on a KUKA controller (payload data, gear jerk
limits, collision-detection tolerances): kept for the KRL post (also from a spline WITH, where
the pendant's motion folds set them), left out by other posts with a warning
(:meth:`Core._keep_krl_only`)."""
TIMING_NOTES = {
    "$OV_PRO": "the program override ($OV_PRO) scales the speed of every motion after it: "
    "olp does not model it, so its cycle time is the program's at 100 %",
}
"""What a kept system variable does to olp's figures, said once per program (keys as
:attr:`Var.key`)."""
INPUT_ASSIGNMENT = "is an input ({io}) and cannot be set"
"""Why an assignment to an input means nothing olp models: the controller sets inputs. It is
kept as written for the KRL post (KRL to KRL keeps every statement, and the controller then
decides as it did for the source) with a warning; whether the KRL compiler refuses it is not
verified, so olp does not stop on it (:meth:`Core._input_assignment`)."""
SYSTEM_REASONS = {
    **SYSTEM_REASONS,
    "$ACC.ORI1": "orientation acceleration ($ACC.ORI1) is not part of olp's IR",
    "$ACC.ORI2": "orientation acceleration ($ACC.ORI2) is not part of olp's IR",
    "$VEL.ORI1": "orientation speed ($VEL.ORI1) is not lowered",
    "$VEL.ORI2": "orientation speed ($VEL.ORI2) is not lowered",
    "$IN[]": f"$IN {INPUT_ASSIGNMENT.format(io='$IN')}",
}


CONFIG_DAT_DATA = frozenset({"FHOME", "PDEFAULT", "LDEFAULT"})
"""Inline-form data every KR C4 ``$config.dat`` declares (``DECL FDAT FHOME``: all seven
controller backups of benchmarks/krl_corpus.py that hold one; ``PDEFAULT``/``LDEFAULT``: the
defaults the pendant's inline forms name)."""
CONFIG_DAT_POINTS = frozenset({"XHOME", *(f"XHOME{n}" for n in range(1, 7))})
"""Points every KR C4 ``$config.dat`` declares (``E6AXIS XHOME``, ``XHOME1`` .. ``XHOME6``:
found in all seven controller backups of benchmarks/krl_corpus.py that hold one; ``XHOME6``
in one of them)."""
CONFIG_DAT_NAMES = CONFIG_DAT_DATA | CONFIG_DAT_POINTS
"""Without a ``$config.dat`` these are values olp does not know, never guesses, and names
the file of (:meth:`Context.unknown_name`): a motion to ``XHOME`` is a motion to a run-time
target, a BAS reading ``FDAT_ACT = FHOME`` is kept as written."""
WRITTEN = "written"
"""An inline-form record whose value the output has set (``absorbed_data``)."""

INLINE_FORM_DATA = frozenset({"PDAT_ACT", "LDAT_ACT", "FDAT_ACT"})
"""What the pendant's inline forms assign for BAS to read: absorbed into the motions' speeds,
zones, tools and bases (:mod:`olp.frontends.krl.inline`), not kept as assignments."""


def code_of(line: str) -> str:
    """``line`` without its comment (a ``;`` outside a string or character constant) and
    surrounding blanks."""
    quote = None
    for index, char in enumerate(line):
        if quote is not None:
            quote = None if char == quote else quote
        elif char in "\"'":
            quote = char
        elif char == ";":
            return line[:index].strip()
    return line.strip()


def calls_function(expr: Expr) -> bool:
    """Whether ``expr`` calls a function anywhere (a call may have effects: RSI_ON(...))."""
    if isinstance(expr, FuncCall):
        return True
    if isinstance(expr, Binary):
        return calls_function(expr.left) or calls_function(expr.right)
    if isinstance(expr, Unary):
        return calls_function(expr.operand)
    return False


# ------------------------------------------------------------------------------------------------
# What one run shares


class Context:
    """The files, routines, limits and naming rules of one run (shared by probes)."""

    def __init__(
        self,
        sources: SourceSet,
        routines: dict[str, Routine],
        src: str,
        dat: KrlData | None,
        config: KrlData | None,
        budget: int,
        shared: Sequence[KrlData] = (),
    ) -> None:
        self.sources = sources
        self.routines = routines
        self.called: set[str] = set()
        self.handlers: dict[str, str] = {}  # routine -> "the interrupt at line 12" (never inlined)
        self.reads_params: dict[str, bool] = {}  # routine -> a statement names a parameter
        self.main = next(iter(routines), "")
        self.budget = self.remaining = budget
        self.config = config
        self.module_dat = dat
        self.src = src
        self.shared = tuple(shared)
        self.src_name = os.path.basename(src)
        self.files = [src, *(d.filename for d in (dat, config, *self.shared) if d is not None)]
        self._where = self._describe_files(src)
        # routines olp did not read that the user vouches leave settings and position alone
        self.calls_keep_settings: tuple[str, ...] = ()
        # > 0 while a FOR body is tried with its counter unknown: a motion to a run-time
        # target then fails the try, so that the loop is unrolled and its targets known
        self.probing_for = 0
        # name (upper case) -> the type a routine's DECL gives it (AXIS, E6POS, ...): what a
        # PTP_REL by a run-time value offsets, the axes or the position
        self.declared_types: dict[str, str] = {}

    def keeps_settings(self, name: str) -> bool:
        """Whether the user vouched that the unread routine ``name`` leaves the motion settings
        and the robot's position as they were (``calls_keep_settings``: names or ``fnmatch``
        patterns, compared without case as KRL names are)."""
        key = name.upper()
        return any(fnmatch.fnmatchcase(key, p.upper()) for p in self.calls_keep_settings)

    def _describe_files(self, src: str) -> str:
        dat = (
            "no .dat file beside it" if self.module_dat is None else data_file_name(self.module_dat)
        )
        config = "no $config.dat given" if self.config is None else data_file_name(self.config)
        shared = "".join(f"; {data_file_name(d)}" for d in self.shared)
        return f"{os.path.basename(src)} ({dat}; {config}{shared})"

    def missing_files(self) -> list[tuple[str, str]]:
        """The files where the controller finds a name olp did not (the module's ``.dat``, the
        controller's ``$config.dat``) that olp was not given: (what, how to give it)."""
        missing = []
        if self.module_dat is None:
            dat = f"{os.path.splitext(self.src_name)[0]}.dat"
            missing.append((f"the module's {dat}", f"put {dat} beside the module"))
        if self.config is None:
            missing.append(("the controller's $config.dat", "pass --config-dat"))
        return missing

    def unknown_name(self, name: str) -> Unknown:
        """Why ``name`` has no value: a controller variable; a name no file olp read declares
        while a file where the controller would find it was not given (:meth:`missing_files`):
        a value known only when the program runs, which olp does not guess; else declared
        nowhere olp looked (``missing``: the controller's compiler refuses it too)."""
        if name == "$H_POS":
            return Unknown(
                "$H_POS is not set by the program (the controller keeps it in $machine.dat, "
                "which olp does not read)",
                "set it in the program ($H_POS=XHOME) or move to XHOME directly",
                missing=True,  # a value of the controller's files, not of the run
            )
        if name.startswith("$"):
            return Unknown(f"{name} is a controller variable olp does not track")
        if self.config is None and name in CONFIG_DAT_NAMES:
            return Unknown(
                f"{name} is declared in the controller's $config.dat, which was not given with "
                "--config-dat; olp does not guess its value"
            )
        missing = self.missing_files()
        if missing:
            return Unknown(
                f"{name} is not declared in {self._where}: olp takes it as a value known only "
                "when the program runs",
                f"{' / '.join(how for _, how in missing)} to check what depends on it",
            )
        hint = None
        if not self.shared:
            hint = (
                "a point declared GLOBAL in another module's PUBLIC data list is found with "
                "--data-list FILE.dat or --data-lists-from FOLDER (KrlOptions(data_lists=...))"
            )
        return Unknown(f"{name} is not declared in {self._where}", hint, missing=True)

    def undeclared_message(self, name: str, function: bool) -> str:
        """The warning for the first use of ``name`` (a variable, or a ``function``) that no
        file olp read declares."""
        if function:
            return (
                f"{name}(...) is a function no module olp read declares (no DEFFCT in "
                f"{self.src_name}, no EXTFCT, not a KRL system function): the controller may "
                "hold it in another module; olp writes the call as it stands and cannot check it"
            )
        missing = self.missing_files()
        if not missing:
            return (
                f"{name} is not declared in {self._where}: the controller's compiler refuses a "
                "name nothing declares, unless another module's PUBLIC data list declares it "
                "GLOBAL (give it with --data-list FILE.dat or --data-lists-from FOLDER)"
            )
        files = " or ".join(what for what, _ in missing)
        remedy = " / ".join(how for _, how in missing)
        # the KRL post writes the module's .dat: it replaces the controller's, which olp lacks
        written = (
            ""
            if self.module_dat is not None
            else ("; the .dat olp writes with a KRL output does not declare it either")
        )
        return (
            f"{name} is not declared in {self._where}: olp takes it as a value known only when "
            f"the program runs (the controller may find it in {files}) and cannot check what "
            f"depends on it; a misspelt name looks the same: {remedy} to check these{written}"
        )

    @functools.cached_property
    def functions(self) -> frozenset[str]:
        """The functions (upper case) a call may name without a warning: the module's
        routines, those an ``EXTFCT`` declares, KRL's system functions."""
        sources = [s for s in map(self.sources.source, self.files) if s is not None]
        return frozenset(self.routines) | external_functions(sources) | KRL_FUNCTIONS

    def spend(self, stmt: Stmt) -> None:
        self.remaining -= 1
        if self.remaining < 0:
            raise self.sources.error(
                f"the program expands to more than {self.budget:,} statements through "
                "loops and calls; olp stops here",
                stmt.span,
                hint="olp unrolls FOR loops and inlines calls; a program this large is better "
                "generated as straight-line code",
            )


def data_file_name(data: KrlData) -> str:
    return os.path.basename(data.filename)


# ------------------------------------------------------------------------------------------------
# The core of a lowering


HERE = frozenset({"$POS_ACT", "$AXIS_ACT", "$POS_ACT_MES", "$AXIS_ACT_MEAS", "$AXIS_ACT_MES"})
"""Targets that are where the robot stands when the motion starts."""


def is_here(expr: object) -> bool:
    """Whether ``expr`` is one of :data:`HERE`."""
    return isinstance(expr, Var) and not expr.selectors and expr.name.upper() in HERE


class Core:
    """State, variables, reports, values and system-variable assignments of one lowering."""

    def __init__(self, ctx: Context, state: State, variables: Variables) -> None:
        self.ctx = ctx
        self.sources = ctx.sources
        self.state = state
        self.track = Track()
        self.variables = variables
        self.evaluator = Evaluator(variables, ctx.sources.snippet)
        self.data = DataOps(variables, self.evaluator, ctx.sources)
        self.out: list[ir.Node | Pending | PendingRows] = []
        self.ignored: list[IgnoredLine] = []
        self.notes: list[Note] = []
        self.status_turn: list[StatusTurn] = []
        self.call_stack: list[str] = []
        self.loop_depth = 0
        self.returned: tuple[str, int] | None = None  # (routine, line of its RETURN)
        self.exiting: int | None = None  # line of an EXIT leaving the current loop
        self._after_with: int | None = None  # line of the last motion whose WITH set anything
        self.in_with = False  # lowering the assignments of a motion's WITH
        self._reported: set[tuple[Any, ...]] = set()
        self.motion_count = 0  # motions lowered so far (by this lowering)
        self.here_vars: dict[str, tuple[str, int]] = {}  # name -> ($POS_ACT..., motion_count)
        # the last assignment of each inline-form record olp absorbed into the motions, for a
        # BAS kept as written: None where it cannot be written back alone (a member's),
        # WRITTEN once the output holds the record's value
        self.absorbed_data: dict[str, Assign | str | None] = {}
        self._setters: dict[str, Callable[[str, Expr, Stmt], None]] = {
            "$VEL.CP": self._set_vel_cp,
            "$ACC.CP": self._set_acc_cp,
            "$ACC.ORI1": self._set_acc_ori1,
            "$ACC": self._set_struct,
            "$APO.CDIS": self._set_apo_cdis,
            "$BASE": self._set_base,
            "$TOOL": self._set_tool,
            "$VEL": self._set_struct,
            "$APO": self._set_struct,
            "$VEL_AXIS[]": self._set_axis_percent,
            "$ACC_AXIS[]": self._set_axis_percent,
            "$OUT[]": self._set_output,
            "$H_POS": self._set_home,
            "$IPO_MODE": self._set_ipo_mode,
            "$ORI_TYPE": self._set_ori_type,
            "$CIRC_TYPE": self._set_circ_type,
        }

    # ---- reporting
    def _ignore(self, stmt: Stmt | Assign, reason: str) -> None:
        key = ("ignored", stmt.span, reason)  # loops and calls lower a line many times
        if key not in self._reported:
            self._reported.add(key)
            self.ignored.append(IgnoredLine(stmt.span, self.sources.snippet(stmt.span), reason))

    def _assignment(self, stmt: Assign) -> ir.Assign:
        """``stmt`` as IR: a statement of the program, kept whatever olp knows of its value."""
        from olp.frontends.krl.flow import to_expr

        target = to_expr(stmt.target, lambda _: None)
        value = to_expr(stmt.value, self._input_of)
        assert target is not None and value is not None
        return ir.Assign(target=target, value=value, span=stmt.span)

    def _input_of(self, var: Var) -> ir.DigitalInput | None:
        """``$IN[n]`` (a constant ``n``) or a one-bit SIGNAL of an input as the
        :class:`~olp.ir.DigitalInput` it reads, wherever an expression is (with the signal's
        name where :meth:`_signal_name` keeps it)."""
        if var.key == "$IN[]":
            index = var.selectors[0]
            assert isinstance(index, Index)
            arg = index.args[0] if len(index.args) == 1 else None
            number = None if arg is None else as_int(self._value(arg))
            return None if number is None else ir.DigitalInput(index=number, span=var.span)
        if not var.selectors:
            signal = self._value(var)
            if isinstance(signal, Signal) and signal.io == "$IN":
                name = self._signal_name(var, signal)
                return ir.DigitalInput(index=signal.index, signal=name, span=var.span)
        return None

    def _signal_name(self, var: Var, signal: Signal) -> str | None:
        """The name ``var`` reads ``signal`` by, where the written program can use it too: a
        SIGNAL declared outside the module (``$config.dat``, another module's data list),
        which the controller declares for the written program as for its source. One in the
        module's own ``.src`` or ``.dat`` is not written back, so the post writes the number
        there (None)."""
        dat = self.ctx.module_dat
        own = {self.ctx.src, *(() if dat is None else (dat.filename,))}
        return None if signal.span.file in own else var.name

    def _keep(self, stmt: Stmt | Assign, reason: str) -> None:
        """Keep a statement olp does not model as :class:`~olp.ir.Verbatim` (its text without
        the comment): the KRL post writes it back, other posts stop on it."""
        self._keep_text(code_of(self.sources.snippet(stmt.span)), stmt.span, reason)

    def _keep_krl_only(self, stmt: Stmt | Assign, reason: str) -> None:
        """Keep a statement that only means something on a KUKA controller (an ``EXT``
        declaration, payload data, code a GOTO jumps over): the KRL post writes it back; to
        another post it is harmless to leave out, with a warning giving ``reason``
        (:attr:`olp.ir.Verbatim.native_only`)."""
        self._keep_text(code_of(self.sources.snippet(stmt.span)), stmt.span, reason, True)

    def _keep_text(
        self, text: str, span: ir.SourceSpan, reason: str, krl_only: bool = False
    ) -> None:
        """Keep ``text`` (one statement of the source at ``span``) as written; ``krl_only``:
        it only means something on a KUKA controller (other posts leave it out with a warning:
        :attr:`olp.ir.Verbatim.native_only`)."""
        try:
            kept = ir.Verbatim(
                text=text, language="krl", reason=reason, span=span, native_only=krl_only
            )
        except ir.FlowError as exc:  # a control character (a lone carriage return) inside it
            raise self._error(
                f"olp keeps this statement as written, but it is not one clean line: {exc}",
                span,
                hint="remove the control character from the statement",
            ) from None
        self.out.append(kept)

    def _note(self, span: ir.SourceSpan, message: str, once: str | None = None) -> None:
        key = ("note", once) if once is not None else ("note", span, message)
        if key not in self._reported:
            self._reported.add(key)
            self.notes.append(Note(span, message))

    def _config_name(self, name: str) -> bool:
        return self.ctx.config is None and name in CONFIG_DAT_NAMES

    def _error(self, message: str, span: ir.SourceSpan, hint: str | None = None) -> ParseError:
        return self.sources.error(message, span, hint)

    def check_declared(self, stmt: Stmt) -> None:
        """A warning at the first use of each name ``stmt`` uses that no file olp read declares
        (:meth:`Context.undeclared_message`): a misspelling must not pass unseen, and what
        olp takes for a run-time value it says it cannot check. Names olp models without their
        declaration (:data:`~olp.frontends.krl.declared.MODELLED_NAMES`) and the controller's
        ``$`` variables are not reported, nor, without a ``$config.dat``, the names every one
        declares (:data:`CONFIG_DAT_NAMES`: not misspelt; what depends on them says so)."""
        for use in uses(stmt):
            name = use.name.upper()
            key = ("undeclared", name, isinstance(use, FuncCall))
            if key in self._reported:
                continue
            if isinstance(use, FuncCall):
                known = name in self.ctx.functions
            else:
                known = name.startswith("$") or name in MODELLED_NAMES
                known = known or self.variables.is_declared(name) or self._config_name(name)
            if not known:
                self._reported.add(key)
                message = self.ctx.undeclared_message(use.name, isinstance(use, FuncCall))
                self.notes.append(Note(use.span, message))

    # ---- values
    def _value(self, expr: Expr) -> Value:
        return self.evaluator.evaluate(expr)

    def _number(self, expr: Expr, what: str) -> float:
        value = self._value(expr)
        number = as_number(value)
        if number is None:
            found = self.sources.snippet(expr.span)
            why = f" ({value.reason})" if isinstance(value, Unknown) else ""
            hint = value.hint if isinstance(value, Unknown) else None
            message = f"{what} must be a constant number, found {found!r}{why}"
            raise self._error(message, expr.span, hint)
        if not math.isfinite(number):
            raise self._error(f"{what} is out of range", expr.span)
        return number

    def _integer(self, expr: Expr, what: str, minimum: int = 0) -> int:
        number = self._number(expr, what)
        value = as_int(self._value(expr))
        if value is None or value < minimum:
            found = self.sources.snippet(expr.span)
            raise self._error(f"{what} must be an integer >= {minimum}, found {found!r}", expr.span)
        return int(number)

    def _percent(self, expr: Expr, what: str) -> float:
        percent = self._number(expr, f"{what} (%)")
        if not 0 < percent <= 100:
            raise self._error(f"{what} must be in (0, 100] %, found {percent:g}", expr.span)
        return percent

    def _single_index(self, target: Var, what: str, minimum: int = 1) -> int:
        index = target.selectors[0]
        if not isinstance(index, Index) or len(index.args) != 1 or index.args[0] is None:
            raise self._error(f"{what} takes one index", target.span)
        return self._integer(index.args[0], f"the index of {what}", minimum)

    @staticmethod
    def _runtime(value: Value) -> bool:
        """Whether ``value`` is known only when the program runs (not for a missing name)."""
        return isinstance(value, Unknown) and not value.missing

    def _aggregate(self, expr: Expr, what: str, hint: str | None = None) -> Aggregate:
        """The aggregate ``expr`` stands for (inline, or a variable's value)."""
        value = self._value(expr)
        if isinstance(value, Aggregate):
            return value
        found = self.sources.snippet(expr.span)
        if isinstance(value, Unknown):
            raise self._error(f"{what} {found!r}: {value.reason}", expr.span, value.hint or hint)
        raise self._error(f"{what} {found!r}: not an aggregate {{...}}", expr.span, hint)

    # ---- assignments
    def _assign(self, stmt: Assign) -> None:
        key = stmt.target.key
        setter = self._setters.get(key)
        if setter is not None:
            setter(key, stmt.value, stmt)
        elif key in KEPT_SYSTEM_VARIABLES:
            self._keep_system(stmt, key)
        elif key == "$IN[]":
            self._input_assignment(stmt, "$IN")
        elif key in SYSTEM_REASONS:  # $BWDSTART, $CIRC_MODE
            self._ignore(stmt, SYSTEM_REASONS[key])
        elif key.startswith("$"):
            # a timer, a flag, a message text, torque monitoring: it changes what the program
            # does on the controller, so it is written back, never left out
            name = key.split("[")[0]
            self._keep(stmt, f"system variable {name} is not modelled: kept as written")
            if key in TIMING_NOTES:
                self._note(stmt.span, TIMING_NOTES[key], once=key)
        elif self._is_signal(stmt.target):
            self._signal_output(stmt)
        else:
            name = stmt.target.name.upper()
            if is_here(stmt.value) and not stmt.target.selectors:
                assert isinstance(stmt.value, Var)
                self.here_vars[name] = (stmt.value.name.upper(), self.motion_count)
            else:
                self.here_vars.pop(name, None)
            self.data.assign(stmt)  # what olp knows of the value afterwards
            if name not in INLINE_FORM_DATA or self._runtime(self.variables.lookup(name)):
                # PDAT_ACT = pdatNew with a run-time value: the BAS reading it is kept as
                # written, so the assignment must reach the output too
                self.out.append(self._assignment(stmt))
                self.absorbed_data[name] = WRITTEN
            else:
                self.absorbed_data[name] = None if stmt.target.selectors else stmt

    def _keep_system(self, stmt: Assign, key: str, why: str = "") -> None:
        """Keep an assignment of a system variable olp does not model
        (:data:`KEPT_SYSTEM_VARIABLES`); ``why`` is added to its reason."""
        reason = SYSTEM_REASONS[key] + why
        if key in KRL_ONLY_SYSTEM_VARIABLES:
            self._keep_krl_only(stmt, reason)
        else:
            self._keep(stmt, reason)

    # ---- motion settings set from run-time values
    def _at_run_time(self, value: Expr) -> Unknown | None:
        """The value of a motion setting's assignment where it is known only when the program
        runs (a parameter, a name no file olp read declares, an expression of such) and olp can
        keep the assignment as written, else None (then the setter's error stands: a name
        declared nowhere olp looked; a WITH item, which only that motion runs with)."""
        if self.in_with or getattr(self, "ambiguous", None) is None:
            return None
        known = self._value(value)
        if not (isinstance(known, Unknown) and self._runtime(known)):
            return None
        lookup = self.variables.lookup
        read = (lookup(v.name.upper()) for v in variables_read(value))
        if isinstance(known, Counter) or any(isinstance(v, Counter) for v in read):
            return None  # the loop is unrolled instead: each pass's value is known
        return known

    def _keep_at_run_time(
        self, stmt: Stmt, name: str, known: Unknown, holds: Sequence[str]
    ) -> None:
        """Keep ``stmt``, which sets the motion setting ``name`` from a run-time value, as
        written (not KRL-only: it changes how the robot moves, so another post refuses it) and
        hold ``holds`` (:class:`Held`): a motion that runs with them before the program sets
        them again runs with the controller's settings, as the source's does."""
        self._keep(stmt, f"{name} is set from a value known only at run time ({known.reason})")
        self._hold(holds, _held(name, stmt, known))

    def _hold(self, keys: Sequence[str], why: Held) -> None:
        ambiguous: dict[str, str] | None = getattr(self, "ambiguous", None)
        if ambiguous is not None:
            ambiguous.update(dict.fromkeys(keys, why))

    def call_holds(self) -> tuple[str, ...]:
        """The parts of the speed (:data:`SPEED_PARTS`) a call of a routine olp did not read
        holds: all but an acceleration olp leaves to the controller (None in
        :class:`olp.ir.Speed`), which the posts never write, so the controller's value holds
        in the output as in the source."""
        speed = self.state.speed
        optional = {"acc_cp": speed.linear_acceleration, "acc_ori": speed.angular_acceleration}
        return tuple(key for key in SPEED_PARTS if optional.get(key, 0.0) is not None)

    def _set_vel_cp(self, name: str, value: Expr, stmt: Stmt) -> None:
        if not self._runtime_setting(name, value, stmt):
            self._vel_cp(self._number(value, "$VEL.CP (m/s)"), value.span)

    def _runtime_setting(self, name: str, value: Expr, stmt: Stmt) -> bool:
        """Whether ``stmt`` sets ``name`` (:data:`RUNTIME_HOLDS`) from a run-time value, kept
        as written (:meth:`_keep_at_run_time`); a member of ``$VEL = {...}`` is the whole
        statement's (:meth:`_set_struct`)."""
        known = self._at_run_time(value)
        if known is None:
            return False
        if isinstance(stmt, Assign) and stmt.target.key == name:
            self._keep_at_run_time(stmt, name, known, RUNTIME_HOLDS[name])
        else:
            self._hold(RUNTIME_HOLDS[name], _held(name, stmt, known))
        return True

    def _vel_cp(self, speed: float, span: ir.SourceSpan) -> None:
        if speed <= 0:
            raise self._error(f"$VEL.CP (m/s) must be > 0, found {speed:g}", span)
        new_speed = dataclasses.replace(self.state.speed, linear=speed)
        self.state = dataclasses.replace(self.state, speed=new_speed, vel_cp_set=True)
        self._settled("vel_cp")

    def _set_acc_cp(self, name: str, value: Expr, stmt: Stmt) -> None:
        """``$ACC.CP`` (m/s²): the TCP path acceleration of LIN and CIRC motions (KUKA system
        variables: "path acceleration", in m/s²; medium confidence on the unit from the KSS
        documentation as cited in vendor notes and forum threads, e.g. a KSS default of 2.3)."""
        if self._runtime_setting(name, value, stmt):
            return
        accel = self._number(value, "$ACC.CP (m/s²)")
        if accel <= 0:
            raise self._error(f"$ACC.CP (m/s²) must be > 0, found {accel:g}", value.span)
        self._set_speed(linear_acceleration=accel)

    def _set_acc_ori1(self, name: str, value: Expr, stmt: Stmt) -> None:
        """``$ACC.ORI1`` (deg/s²): the TCP's swivel (orientation) acceleration; olp's
        orientation acceleration limit, in rad/s²."""
        if self._runtime_setting(name, value, stmt):
            return
        accel = self._number(value, "$ACC.ORI1 (deg/s²)")
        if accel <= 0:
            raise self._error(f"$ACC.ORI1 (deg/s²) must be > 0, found {accel:g}", value.span)
        self._set_speed(angular_acceleration=math.radians(accel))

    def _set_speed(self, **changes: float) -> None:
        speed = dataclasses.replace(self.state.speed, **changes)
        self.state = dataclasses.replace(self.state, speed=speed)
        for change in changes:
            self._settled(_SPEED_FIELD_PARTS[change])

    def _set_apo_cdis(self, name: str, value: Expr, stmt: Stmt) -> None:
        if self._runtime_setting(name, value, stmt):
            return
        self._cdis(self._number(value, "$APO.CDIS (mm)"), value.span, "$APO.CDIS (mm)")

    def _cdis(self, distance: float, span: ir.SourceSpan, what: str) -> None:
        if distance < 0:
            raise self._error(f"{what} must be >= 0", span)
        self.state = dataclasses.replace(self.state, cdis_mm=distance)
        self._settled("cdis_mm")  # the same number object again: identity cannot tell

    def _set_struct(self, name: str, value: Expr, stmt: Stmt) -> None:
        """``$VEL = {CP 0.5, ...}``: each component as its own assignment; a motion parameter
        olp keeps (:data:`KEPT_SYSTEM_VARIABLES`, e.g. ``$ACC = {CP 2, ORI1 200, ORI2 200}``)
        with components olp does not model is also kept as written, so none is lost."""
        if not isinstance(value, Aggregate):
            raise self._error(f"{name} must be set from an aggregate {{...}} here", value.span)
        runtime = [
            f"{name}.{m.name.upper()}"
            for m in value.members
            if f"{name}.{m.name.upper()}" in RUNTIME_HOLDS and self._at_run_time(m.value)
        ]
        if runtime:  # kept whole; each member set again below: the run-time ones held
            listed = ", ".join(runtime)
            self._keep(stmt, f"{listed} set from values known only at run time")
        unused = []
        for member in value.members:
            component = f"{name}.{member.name.upper()}"
            setter = self._setters.get(component)
            if setter is None:
                unused.append(member.name.upper())
            else:
                setter(component, member.value, stmt)
        if unused and not runtime:
            listed = ", ".join(unused)
            if name in KEPT_SYSTEM_VARIABLES:
                self._keep(stmt, f"{name} component(s) {listed} not modelled: kept as written")
            else:
                self._ignore(stmt, f"{name} component(s) {listed} not lowered yet")

    def _set_axis_percent(self, key: str, value: Expr, stmt: Stmt) -> None:
        assert isinstance(stmt, Assign)
        name = key.removesuffix("[]")
        known = self._at_run_time(value)
        axes = None if known is None else self._runtime_axes(stmt.target, name)
        if known is not None and axes is not None:
            parts = axis_parts(_AXIS_FIELDS[name], axes)
            if parts:
                self._keep_at_run_time(stmt, f"{name}[]" if len(axes) > 1 else name, known, parts)
            else:
                self._ignore(stmt, f"{name} of external axes is not lowered")
            return
        axis = self._single_index(stmt.target, name)
        percent = self._percent(value, f"{name}[{axis}]")
        if axis > len(AXES):
            self._ignore(stmt, f"{name} of external axes is not lowered")
            return
        self._set_axes_percent(name, {axis: percent})

    def _runtime_axes(self, target: Var, name: str) -> tuple[int, ...] | None:
        """The robot axes ``$VEL_AXIS[n]`` (``$ACC_AXIS[n]``) set from a run-time value sets:
        ``n``'s (none for an external axis), all where ``n`` is known only at run time; None
        where the index is not one number (the usual error)."""
        index = target.selectors[0]
        if not isinstance(index, Index) or len(index.args) != 1 or index.args[0] is None:
            return None
        number = self._value(index.args[0])
        if self._runtime(number):
            return ALL_AXES
        axis = as_int(number)
        if axis is None or axis < 1:
            return None
        return (axis,) if axis in ALL_AXES else ()

    def _set_axes_percent(self, name: str, percents: dict[int, float]) -> None:
        for part in axis_parts(_AXIS_FIELDS[name], sorted(percents)):
            self._settled(part)
        if name == "$VEL_AXIS":
            vel_axis = {**self.state.vel_axis, **percents}
            speed = dataclasses.replace(self.state.speed, joint=min(vel_axis.values()) / 100)
            self.state = dataclasses.replace(self.state, vel_axis=vel_axis, speed=speed)
        else:
            acc_axis = {**self.state.acc_axis, **percents}
            fraction = min(acc_axis.values()) / 100
            speed = dataclasses.replace(self.state.speed, joint_acceleration=fraction)
            self.state = dataclasses.replace(self.state, acc_axis=acc_axis, speed=speed)

    def _all_axes(self, name: str, percent: float) -> None:
        self._set_axes_percent(name, dict.fromkeys(range(1, len(AXES) + 1), percent))

    def _set_output(self, key: str, value: Expr, stmt: Stmt) -> None:
        """``$OUT[n] = value``: a :class:`~olp.ir.SetOutput` when ``n`` and the value are known
        (``$OUT[PGNO_REQ] = FALSE``, the index a variable of $config.dat); otherwise kept as
        written (``$OUT[nOut] = bState``): the KUKA post writes it back, others stop on it."""
        assert isinstance(stmt, Assign)
        selector = stmt.target.selectors[0]
        if isinstance(selector, Index) and len(selector.args) == 1 and selector.args[0] is not None:
            number = self._value(selector.args[0])
            if as_number(number) is None:  # a constant but wrong index stays an error below
                why = number.reason if isinstance(number, Unknown) else "not a number"
                self._keep(stmt, f"an output olp cannot number ({why})")
                return
        self._output(self._single_index(stmt.target, "$OUT"), value, stmt)

    def _output(self, index: int, value: Expr, stmt: Assign, signal: str | None = None) -> None:
        constant = self._value(value)
        if not isinstance(constant, Bool):
            self._keep(stmt, "an output set to a value olp does not know (not TRUE or FALSE)")
            return
        self.out.append(
            ir.SetOutput(index=index, value=constant.value, signal=signal, span=stmt.span)
        )

    def _input_assignment(self, stmt: Assign, io: str) -> None:
        """An assignment to an input (``bStart = FALSE`` of ``SIGNAL bStart $IN[3]``, or
        ``$IN[4] = TRUE``): the controller sets its inputs, so it changes nothing olp models.
        Kept as written for the KRL post, with a warning; another post leaves it out with one
        (:attr:`olp.ir.Verbatim.native_only`)."""
        what = f"{stmt.target.name} {INPUT_ASSIGNMENT.format(io=io)}"
        self._keep_krl_only(stmt, f"{what}: it means something only on a KUKA controller")
        self._note(
            stmt.span,
            f"{what} by the program: kept as written for the KRL output, as the source has it "
            "(olp has not verified whether the controller accepts a program that assigns an "
            "input; it models nothing of it)",
        )

    def _is_signal(self, target: Var) -> bool:
        return not target.selectors and isinstance(self._value(target), Signal)

    def _signal_output(self, stmt: Assign) -> None:
        signal = self._value(stmt.target)
        assert isinstance(signal, Signal)
        if signal.io != "$OUT":
            self._input_assignment(stmt, signal.io)
            return
        self._output(signal.index, stmt.value, stmt, self._signal_name(stmt.target, signal))

    def _set_home(self, name: str, value: Expr, stmt: Stmt) -> None:
        """``$H_POS = XHOME``: olp learns the home position (for ``PTP $H_POS``) and keeps the
        line as written: the controller compares the robot with ``$H_POS`` for its
        ``$IN_HOME`` output, which a PLC may read, so the line is not absorbed silently."""
        home = self._value(value)
        self.variables.globals["$H_POS"] = home
        if isinstance(stmt, Assign):
            self._keep(stmt, "$H_POS sets the controller's home position (its $IN_HOME output)")

    def _set_ipo_mode(self, name: str, value: Expr, stmt: Stmt) -> None:
        self._ipo_mode(self._value(value), value.span)

    def _set_ori_type(self, name: str, value: Expr, stmt: Stmt) -> None:
        if self._runtime_setting(name, value, stmt):
            return
        self._orientation_type("$ORI_TYPE", self._value(value), value.span)

    def _set_circ_type(self, name: str, value: Expr, stmt: Stmt) -> None:
        if self._runtime_setting(name, value, stmt):
            return
        self._orientation_type("$CIRC_TYPE", self._value(value), value.span)

    def _orientation_type(self, name: str, value: Value, span: ir.SourceSpan) -> None:
        """``$ORI_TYPE`` (#VAR, #CONSTANT, #JOINT) or ``$CIRC_TYPE`` (#BASE, #PATH)."""
        allowed = ORI_TYPES if name == "$ORI_TYPE" else CIRC_TYPES
        found = value.name.upper() if isinstance(value, EnumValue) else None
        if found not in allowed:
            names = ", ".join(f"#{a}" for a in sorted(allowed))
            raise self._error(
                f"{name} must be one of {names}, found {self.sources.snippet(span)!r}", span
            )
        if name == "$ORI_TYPE":
            self.state, field_name = dataclasses.replace(self.state, ori_type=found), "ori_type"
        else:
            self.state = dataclasses.replace(self.state, circ_type=found)
            field_name = "circ_type"
        self._settled(field_name)  # an interned name: identity cannot tell it was set

    def _ipo_mode(self, mode: Value, span: ir.SourceSpan) -> None:
        if isinstance(mode, EnumValue) and mode.name.upper() == "BASE":
            return
        found = self.sources.snippet(span)
        raise self._error(
            f"interpolation mode {found!r} is not supported: olp lowers motions of a robot-held "
            "tool (#BASE), not an external (stationary) TCP (#TCP)",
            span,
        )

    # ---- tools and bases
    def _set_base(self, name: str, value: Expr, stmt: Stmt) -> None:
        if not self._frame_at_run_time("$BASE", "frame", value, stmt):
            frame = self._frame_value(value, "$BASE", stmt.span, ir.Frame, ir.WORLD)
            self._change_frame(frame, stmt)

    def _set_tool(self, name: str, value: Expr, stmt: Stmt) -> None:
        if not self._frame_at_run_time("$TOOL", "tool", value, stmt):
            tool = self._frame_value(value, "$TOOL", stmt.span, ir.Tool, ir.FLANGE)
            self._change_tool(tool, stmt)

    def _frame_at_run_time(self, name: str, setting: str, value: Expr, stmt: Stmt) -> bool:
        """``$BASE = PalletBase[nActive].Base`` with a value known only when the program runs
        (a name no file olp read declares, a parameter, ...): kept as written (the KRL post
        writes it back; the first motion after a kept line gets all its settings written
        again), and the base (tool) is held (:class:`Held`) until the program sets it again:
        a motion before that runs with the controller's settings, unchecked, as after a BAS
        with run-time values. So is ``$BASE = BASE_DATA[nBase]`` with a run-time number. In a
        WITH the error stands (returns False)."""
        if isinstance(value, Var) and value.key == f"{_DATA_TABLES[name]}[]":
            selector = value.selectors[0]  # BASE_DATA[nBase]: the number's value decides
            args = selector.args if isinstance(selector, Index) else ()
            if len(args) != 1 or args[0] is None:
                return False  # the usual error (_frame_value)
            value = args[0]
        elif isinstance(value, Var) and value.key == "$NULLFRAME":
            return False
        known = self._at_run_time(value)
        if known is None:
            return False
        assert isinstance(stmt, Assign)
        self._keep_at_run_time(stmt, name, known, (setting,))
        self.track.lose_cartesian(f"{name} was set at run time at line {stmt.span.line}")
        return True

    def _change_frame(self, frame: ir.Frame, stmt: Stmt | Assign) -> None:
        if frame != self.state.frame:
            self._reset_start(dataclasses.replace(self.state, frame=frame), "$BASE", stmt.span)
        self._settled("frame")

    def _change_tool(self, tool: ir.Tool, stmt: Stmt | Assign) -> None:
        if tool != self.state.tool:
            self._reset_start(dataclasses.replace(self.state, tool=tool), "$TOOL", stmt.span)
        self._settled("tool")

    def _settled(self, name: str) -> None:
        """A setting the program has just set is known, whatever the paths before it set (the
        value may equal the one the state holds after a join: then nothing else changes)."""
        ambiguous: dict[str, str] | None = getattr(self, "ambiguous", None)
        if ambiguous:
            ambiguous.pop(name, None)
        unset: set[str] | None = getattr(self, "unset", None)
        if unset:
            unset.discard(name)

    def _reset_start(self, state: State, name: str, span: ir.SourceSpan) -> None:
        """A new tool or base: the start in its terms is unknown to olp. One the run already
        decides (:class:`~olp.frontends.krl.motion.RuntimeStart`) stays the run's."""
        from olp.frontends.krl.motion import RuntimeStart  # (motion.py builds on this module)

        self.state = state
        if not isinstance(self.track.no_cartesian, RuntimeStart) or self.track.cartesian:
            self.track.lose_cartesian(f"{name} changed at line {span.line}")

    def _frame_value(
        self, value: Expr, name: str, span: ir.SourceSpan, make: Callable[..., _F], null: _F
    ) -> _F:
        """A frame/tool from ``{FRAME: ...}`` (named after its line), a variable holding one (named
        after it), ``BASE_DATA[n]`` (or ``TOOL_DATA[n]``) or ``$NULLFRAME``."""
        table = _DATA_TABLES[name]
        if isinstance(value, Var) and value.key == f"{table}[]":
            return self._numbered(make, table, self._single_index(value, table), value.span)
        if isinstance(value, Var) and value.key == "$NULLFRAME":
            return null
        constant = self._value(value)
        if isinstance(constant, Aggregate):
            pose = frame_to_pose(self._frame_aggregate(constant, name))
            named = isinstance(value, Var) and not value.selectors
            label = value.name if isinstance(value, Var) and named else None
            return make(name=label or f"{name.strip('$').lower()}_l{span.line}", pose=pose)
        why = f": {constant.reason}" if isinstance(constant, Unknown) else ""
        raise self._error(
            f"cannot evaluate {name} = {self.sources.snippet(value.span)!r}{why}",
            value.span,
            hint=f"olp reads {name} = {{FRAME: X ..,Y ..,Z ..,A ..,B ..,C ..}}, {table}[n] "
            "or $NULLFRAME",
        )

    def _numbered(
        self, make: Callable[..., _F], table: str, number: int, span: ir.SourceSpan
    ) -> _F:
        """``TOOL_DATA[n]``/``BASE_DATA[n]``: its value if a data list gives one (named after
        ``TOOL_NAME[n,]``), else a reference the station resolves by number."""
        array = self.variables.lookup(table)
        element = array.elements.get((number,)) if isinstance(array, ArrayValue) else None
        if element is None:
            if self.ctx.config is not None:
                raise self._error(
                    f"{table}[{number}] has no value in {data_file_name(self.ctx.config)}",
                    span,
                    hint=f"{table} holds the tools/bases measured on the controller; is this the "
                    "robot's $config.dat?",
                )
            return make(name=f"{table}[{number}]", number=number)
        values = frame_values(element) if isinstance(element, Aggregate) else None
        if values is None or isinstance(values, Unknown):
            span = element_span(element, span)
            raise self._error(f"{table}[{number}] is not a FRAME with numbers", span)
        pose = frame_to_pose(values)
        label = self._table_name(table, number) or f"{table}[{number}]"
        return make(name=label, pose=pose, number=number)

    def _table_name(self, table: str, number: int) -> str | None:
        names = self.variables.lookup(_TABLE_NAMES[table])
        if not isinstance(names, ArrayValue):
            return None
        row = names.elements.get((number, None), names.elements.get((number,)))
        return None if row is None else text_value(row)

    def _tool_number(self, number: int, stmt: Stmt | Assign, span: ir.SourceSpan) -> None:
        tool = self._numbered(ir.Tool, "TOOL_DATA", number, span) if number else ir.FLANGE
        self._change_tool(tool, stmt)

    def _base_number(self, number: int, stmt: Stmt | Assign, span: ir.SourceSpan) -> None:
        base = self._numbered(ir.Frame, "BASE_DATA", number, span) if number else ir.WORLD
        self._change_frame(base, stmt)

    def _frame_aggregate(self, agg: Aggregate, name: str) -> list[float]:
        if agg.type_name is not None and agg.type_name.upper() not in POS_TYPES:
            raise self._error(f"{name} needs a FRAME aggregate, not {agg.type_name}", agg.span)
        typed = agg.type_name is not None and agg.type_name.upper() != "FRAME"
        allowed = CARTESIAN + (("S", "T", *EXTERNAL) if typed else ())
        members = self._members(agg, frozenset(allowed), f"{name} component")
        return [self._number(members[c], f"{name}.{c}") if c in members else 0.0 for c in CARTESIAN]

    def _members(self, agg: Aggregate, allowed: frozenset[str], what: str) -> dict[str, Expr]:
        """The aggregate's members by upper-case name; unknown or repeated names are errors."""
        members: dict[str, Expr] = {}
        for member in agg.members:
            key = member.name.upper()
            if key not in allowed:
                expected = ", ".join(sorted(allowed))
                message = f"unknown {what} {member.name!r} (expected one of {expected})"
                raise self._error(message, member.span)
            if key in members:
                raise self._error(f"{what} {member.name!r} is given twice", member.span)
            members[key] = member.value
        return members


_AXIS_FIELDS = {"$VEL_AXIS": "vel_axis", "$ACC_AXIS": "acc_axis"}
_SPEED_FIELD_PARTS = {"linear_acceleration": "acc_cp", "angular_acceleration": "acc_ori"}
"""The part (:data:`SPEED_PARTS`) each field of :class:`olp.ir.Speed` that
:meth:`Core._set_speed` sets is."""


def _held(name: str, stmt: Stmt, known: Unknown) -> Held:
    return Held(
        f"{name} is set at line {stmt.span.line} from a value olp does not know ({known.reason})"
    )


def element_span(element: Value, default: ir.SourceSpan) -> ir.SourceSpan:
    span = getattr(element, "span", None)
    return span if isinstance(span, ir.SourceSpan) else default
