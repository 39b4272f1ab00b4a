"""The LS post (Fanuc R-30iB): TP programs as LS text, ``NAME.ls``.

Conventions shared with frontends (W, P, R; CONFIG and turn numbers; the J2/J3 coupling; what
CONFIG can select) live in :mod:`olp.vendors.fanuc`; this module is how the post spells them.
Pinned by ``tests/posts/test_fanuc.py``, the cross-post table and the golden files
``tests/golden/fanuc/``.

Layout as in LS files exported by R-30iB controllers and ROBOGUIDE (public backups; the
project vendor notes): ``/PROG  NAME``, ``/ATTR``, ``/MN``, ``/POS``, ``/END``; CRLF line
endings (the files are DOS text; medium confidence that LF would also do).

* ``/ATTR``: olp writes the fields exported files carry except the dates, sizes and file name
  the controller fills in (``CREATE``/``MODIFIED`` are left out so that the bytes do not depend
  on the clock; whether MakeTP requires them is unverified), ``LINE_COUNT`` = numbered /MN
  lines, ``DEFAULT_GROUP = 1,*,*,*,*`` (one robot, group 1).
* ``/MN``: ``%4d:`` line numbers from 1 (:func:`number_lines`); motion lines ``J P[1] 100%
  FINE    ;``, other lines ``  DO[1]=ON ;``; a circular move is ``C P[via]`` and, on a
  continuation line ``    :  P[end] 100mm/sec FINE    ;``, one program line.
* Speeds: ``J`` in percent of each axis' maximum, ``Speed.joint`` rounded half up to an integer
  1..100 (:func:`joint_percent`); ``L``/``C`` in integer mm/sec, ``Speed.linear`` rounded half
  up, at least 1 (:func:`linear_mm_per_s`; the pendant takes integers there, medium
  confidence; 21.17 mm/s becomes 21mm/sec).
* Termination (:func:`termination`): a zone of radius 0 is ``FINE``; any other is ``CNTn`` with
  ``n = round(radius in mm)`` capped at 100, the rule of RoboDK's public Fanuc post
  (``setZoneData``: ``'CNT%i' % round(min(zone_mm, 100))``; olp rounds halves up). It is not
  exact: ``CNT`` is a percentage of corner rounding whose path depends on speed and
  acceleration, not a distance.
* ``UFRAME_NUM``/``UTOOL_NUM`` before each file's first motion and wherever they change; every
  position records the ``UF``/``UT`` it was taught in (the controller refuses a mismatch).

  - Frames (:func:`uframe_number`): a frame numbered 1..9 (R-30iB user frames, medium
    confidence) is ``UF n``; positions are then relative to it, and the controller's
    ``UFRAME[n]`` must hold the station's frame in World (an info diagnostic gives the values).
    Every other frame (number 0, the station's world, or none, e.g. a KRL inline ``$BASE``) is
    written as ``UF 0`` with the positions in Fanuc's World frame (the post's ``frames_in:
    robot_base``: the robot's ``base · controller_base``, at J2 height for Fanuc arms): exact,
    nothing to set up.
  - Tools (:func:`utool_number`): a tool numbered 0..10 is ``UT n`` (``UT 0``: the faceplate,
    seen in controller exports as ``UTOOL_NUM=0``; 1..10 R-30iB tool frames, medium
    confidence). An unnumbered tool whose TCP is the faceplate is ``UT 0``; any other unnumbered
    tool is the post option ``default_utool`` (1), with a warning that gives the TCP the
    controller's ``UTOOL[n]`` must hold; two such tools, or one whose default number another
    tool of the program has, are an error.

* Arcs: ``C P[via]`` / ``P[end]`` only, with the orientation rule
  :attr:`~olp.ir.ArcOrientation.INTERPOLATE` (start to end; low confidence: Fanuc's handling
  of the via point's orientation on ``C`` is not verified from a stored source) and no
  circular angle. Fanuc's ``A`` (circular arc through consecutive points) is not written: its
  rules could not be verified.
* Positions (:func:`ls_moves`): ``P[n]`` numbered in order of use in each file (a circle's via
  point before its end). A Cartesian target of an OPW arm is written as ``X, Y, Z`` (mm),
  ``W, P, R`` (deg) and the ``CONFIG`` of the planned joints (:func:`config_from_joints`), but
  only where that CONFIG selects the planned joints and no other IK solution within the limits
  (:func:`selecting_configs`, the post hook :func:`step_values`; not e.g. when J3 and J3 ± 360°
  both fit, or at a wrist singularity); otherwise, for joint targets and for arms without
  CONFIG (UR, numeric), as ``J1..J6`` (deg, the controller's joint convention), with an info
  diagnostic for a Cartesian target. Values: ``X = %9.3f  mm``, ``J1=%10.3f deg`` (the widths
  of exported files; they write ``-.000`` where olp writes ``0.000``).
* ``DO[n]=ON/OFF``, ``WAIT DI[n]=ON/OFF``, ``WAIT 1.00(sec)`` (2 decimals), ``CALL NAME`` or
  ``CALL NAME(1,2.5)`` (numeric arguments only), ``!comment ;`` lines of at most
  :data:`COMMENT_LENGTH` characters (longer comments are wrapped over several lines, a line
  break of the text starts another comment line, ``;`` becomes ``,``; the TP+ compiler writes
  comments in pieces of about 31 characters). I/O numbers 1..4096 (:data:`IO_RANGE`: the start
  at 1 is certain, the end is unverified; a template folder may set the option ``io_range``).
* Numbers: positions and frames are 32-bit REALs on the controller (medium confidence), held to
  0.01 mm; J speeds 1..100 %, CNT 0..100, integer mm/sec >= 1.
* Control flow and data (``WRITES_FLOW``): blocks lowered to ``LBL[n]``/``JMP LBL[n]``,
  ``IF ...,JMP``, ``SELECT``, ``FOR``/``ENDFOR``, ``WAIT (...)``, variables in ``R[]``/``PR[]``
  (post options ``registers``, ``position_registers``, ``mixed_logic``), by
  :mod:`olp.posts.fanuc_flow` (conventions and sources there); the first motion after a block
  boundary or label sets ``UFRAME_NUM``/``UTOOL_NUM`` again. What LS cannot express is a
  ``flow`` error on its line.
* Long programs are split (:mod:`olp.transforms.split`, the manifest's ``limits``) into parts
  ``NAME_P1`` ... and a main program of ``CALL`` lines. The bound is RoboDK's public Fanuc post
  default of 9999 lines per program (``MAX_LINES_X_PROG``; not a documented Fanuc figure),
  applied as 3000 instructions per file: an instruction takes at most three /MN lines
  (``UFRAME_NUM``, ``UTOOL_NUM``, the motion) unless it is a long comment.
* A dense toolpath (:class:`~olp.ir.LinearPath`) is written from columns (:attr:`COLUMNS
  <olp.posts.base.Post.COLUMNS>`, :mod:`olp.posts.fanuc_rows`): its rows' ``L`` lines and
  ``/POS`` entries are formatted as arrays, the same text as the template writes move by move
  (``tests/posts/test_fanuc_columns.py``); runs of ordinary linear moves go to the row writer
  (:func:`ls_rows_mn`, :func:`ls_rows_pos`), everything else to the template.
"""

from __future__ import annotations

import math
import re
import weakref
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp import ir
from olp.compiled import PathBlock, Step, items_of
from olp.diagnostics import Diagnostic
from olp.geometry import inv
from olp.posts.base import Filter, Post
from olp.posts.fanuc_flow import FLOW_KINDS, Unwritable, lower
from olp.posts.fanuc_rows import LsColumns, column_moves, configured, mn_lines
from olp.posts.flow_text import constant_int
from olp.posts.numbers import NumberError, NumberFormat, Storage
from olp.posts.rows import PostRows
from olp.posts.runtime import targets as runtime_targets
from olp.posts.sandbox import SafeText
from olp.posts.text import ArgumentRule, CommentRule, NameRule
from olp.posts.view import OPAQUE_KINDS, PostStep, RowColumns, is_opaque
from olp.vendors.fanuc import (
    candidates,
    config_from_joints,
    has_config,
    pose_to_xyzwpr,
    selecting_config_column,
)

if TYPE_CHECKING:
    from olp.compiled import CompiledProgram
    from olp.posts.view import PostStep

FloatArray = NDArray[np.float64]

MAX_NAME_LENGTH = 36
"""Program names: 1-36 characters (medium confidence; older controllers accept 8)."""

NAME_RULE = NameRule(max_length=MAX_NAME_LENGTH, upper=True)
"""A legal program name: upper case A-Z, 0-9 and ``_``, a letter first (``P`` is put in front
otherwise), at most 36 characters."""

UFRAME_RANGE = (1, 9)
"""User frames a program may select besides World (0) (R-30iB default; medium confidence)."""
UTOOL_RANGE = (0, 10)
"""Tool frames: 0 the faceplate, 1..10 taught tools (medium confidence)."""
DEFAULT_UTOOL = 1
"""``UT`` of a tool without a number (the post option ``default_utool`` overrides it)."""
COMMENT_LENGTH = 32
"""Characters per ``!`` comment line olp writes (a conservative bound; unverified)."""

_REAL: Storage = "real32"

NUMBERS: Mapping[str, NumberFormat] = {
    **Post.NUMBERS,
    "position": NumberFormat("position", "mm", 3, storage=_REAL, resolution=0.01),
    "angle": NumberFormat("angle", "deg", 3, storage=_REAL, resolution=0.001),
    "joint_percent": NumberFormat("J speed", "%", 0, 1, 100, storage="int"),
    "linear": NumberFormat("L/C speed", "mm/sec", 0, low=1, storage="int"),
    "cnt": NumberFormat("CNT", "", 0, 0, 100, storage="int"),
    "wait": NumberFormat("WAIT", "s", 2, low=0.0, storage=_REAL, resolution=0.01),
}
"""How the LS post writes each quantity (printed units)."""


# --------------------------------------------------------------------------------------------
# Spelling


def ls_xyzwpr(post: Post, pose: ArrayLike) -> list[str]:
    """X, Y, Z (mm) and W, P, R (deg) of a pose (4, 4) in metres as 6 strings (3 decimals)."""
    v = pose_to_xyzwpr(pose)
    return [post.number("position", x) for x in v[:3]] + [post.number("angle", x) for x in v[3:]]


def ls_joints(post: Post, joints: ArrayLike) -> list[str]:
    """J1..J6 in degrees (3 decimals) from controller joints (6,) in rad."""
    return [post.number("angle", v) for v in np.degrees(np.asarray(joints, dtype=np.float64))]


def _round_half_up(value: float) -> int:
    return math.floor(value + 0.5)


def joint_percent(post: Post, speed: Any) -> str:
    """``J`` speed in percent (1..100) of ``speed.joint`` (a fraction of each axis' maximum)."""
    return post.number("joint_percent", min(100, max(1, _round_half_up(speed.joint * 100.0))))


def linear_mm_per_s(post: Post, speed: Any) -> str:
    """``L``/``C`` speed in integer mm/sec (>= 1) of ``speed.linear`` (m/s)."""
    return post.number("linear", max(1, _round_half_up(speed.linear * 1000.0)))


def termination(post: Post, zone: Any) -> str:
    """``FINE`` for a zone of radius 0, else ``CNTn``, n = round(radius mm) capped at 100."""
    if zone.radius <= 0:
        return "FINE"
    return "CNT" + post.number("cnt", min(100, _round_half_up(zone.radius * 1000.0)))


def wait_seconds(post: Post, seconds: float) -> str:
    """A ``WAIT`` time: seconds with 2 decimals."""
    return post.number("wait", seconds)


def uframe_number(frame: Any) -> int:
    """``UF`` of a frame: its number when in 1..9, else 0 (World)."""
    number = getattr(frame, "number", None)
    if number is not None and UFRAME_RANGE[0] <= number <= UFRAME_RANGE[1]:
        return int(number)
    return 0


def is_flange(tool: Any) -> bool:
    """The tool's TCP is the faceplate itself."""
    return tool.pose is not None and bool(np.allclose(tool.pose, np.eye(4), rtol=0, atol=1e-12))


def utool_number(tool: Any, options: Mapping[str, Any] | None = None) -> int:
    """``UT`` of a tool: its number; 0 for an unnumbered tool whose TCP is the faceplate; the
    option ``default_utool`` (:data:`DEFAULT_UTOOL`) for any other unnumbered tool."""
    if tool.number is not None:
        return int(tool.number)
    if is_flange(tool):
        return 0
    return int((options or {}).get("default_utool", DEFAULT_UTOOL))


def _config_filter(post: Post, joints: ArrayLike, robot: Any) -> str:
    """Template filter: ``joints | fanuc_config(robot)`` gives ``N U T, 0, 0, 0``."""
    return str(config_from_joints(robot, joints))


# --------------------------------------------------------------------------------------------
# Positions and program lines


@dataclass(frozen=True, slots=True)
class LsPosition:
    """One ``P[n]`` of ``/POS``: ``uf``, ``ut``, ``config`` (None: joint representation) and six
    numbers already spelled (X..R in mm/deg, or J1..J6 in deg)."""

    number: int
    uf: int
    ut: int
    config: str | None
    values: tuple[str, ...]

    @property
    def cartesian(self) -> bool:
        return self.config is not None


@dataclass(frozen=True, slots=True)
class LsMove:
    """A motion of ``/MN``: its positions, and whether ``UFRAME_NUM``/``UTOOL_NUM`` must be set
    before it."""

    target: LsPosition
    via: LsPosition | None = None
    set_uf: bool = False
    set_ut: bool = False
    rows: ClassVar[bool] = False


@dataclass(frozen=True, slots=True)
class LsRuntime:
    """A motion to a run-time target in ``/MN``: its frame and tool numbers and whether they
    must be set before it (its motion line is :func:`ls_flow`'s, which knows the registers)."""

    uf: int
    ut: int
    set_uf: bool
    set_ut: bool
    rows: ClassVar[bool] = False
    target: ClassVar[None] = None  # no /POS entry: the register holds the position


@dataclass(frozen=True, slots=True)
class LsRows:
    """The LS motions of a run of linear moves (:mod:`olp.posts.rows`): one :class:`LsMove` per
    row, written by :func:`ls_rows_mn` and :func:`ls_rows_pos`."""

    rows_steps: PostRows
    moves: tuple[LsMove, ...]
    rows: ClassVar[bool] = True


def ls_moves(
    post: Post,
    steps: Sequence[PostStep | PostRows | RowColumns],
    robot: Any,
    options: Mapping[str, Any] | None = None,
) -> dict[int, LsMove | LsRows | LsColumns | LsRuntime]:
    """Template filter ``steps | ls_moves(robot, options)``: the LS motion of every motion of
    one file (template view steps, in order), by instruction index. Positions are numbered from
    1 in each file; ``UFRAME_NUM``/``UTOOL_NUM`` are set before the file's first motion, where
    they change, and at the first motion after a block boundary or label (the motion before it
    in the text need not be the one that ran: :data:`JUMP_TARGETS`) or a call (which may set
    others: :data:`~olp.posts.view.OPAQUE_KINDS`). A toolpath's rows
    (:class:`~olp.posts.view.RowColumns`) are one :class:`~olp.posts.fanuc_rows.LsColumns`."""
    out: dict[int, LsMove | LsRows | LsColumns | LsRuntime] = {}
    last: tuple[int, int] | None = None
    number = 0
    for step in steps:
        if step.kind in JUMP_TARGETS or (step.kind in OPAQUE_KINDS and is_opaque(step.instruction)):
            last = None  # arrived from elsewhere, or a called routine may have set others
            continue
        if isinstance(step, RowColumns):
            block = step.piece.block
            uf, ut = uframe_number(block.frame), utool_number(block.tool, options)
            post.current_step = step
            columns = column_moves(post, step, number, last, uf, ut)
            out[step.index] = columns
            number, last = columns.last, (uf, ut)
            continue
        if isinstance(step, PostRows):
            moves = _row_moves(post, step, number, last, options)
            out[step.index] = LsRows(step, moves)
            number = moves[-1].target.number
            last = (moves[-1].target.uf, moves[-1].target.ut)
            continue
        if step.kind == "runtime_move":
            uf, ut = uframe_number(step.frame), utool_number(step.tool, options)
            set_uf, set_ut = last is None or last[0] != uf, last is None or last[1] != ut
            out[step.index] = LsRuntime(uf, ut, set_uf, set_ut)
            last = (uf, ut)
            continue
        if step.joints is None:
            continue
        post.current_step = step
        uf, ut = uframe_number(step.frame), utool_number(step.tool, options)
        via = None
        if step.via is not None:
            number += 1
            via = _via_position(post, number, uf, ut, step, robot)
        number += 1
        target = _target_position(post, number, uf, ut, step)
        out[step.index] = LsMove(
            target, via, last is None or last[0] != uf, last is None or last[1] != ut
        )
        last = (uf, ut)
    post.current_step = None
    return out


JUMP_TARGETS = FLOW_KINDS - {"declare", "assign", "wait_until", "goto", "exit", "return"}
"""Step kinds after which the program may arrive from elsewhere (block markers, labels)."""


def ls_flow(
    post: Post, steps: Sequence[PostStep | PostRows | RowColumns], options: Mapping[str, Any]
) -> tuple[SafeText, ...]:
    """Template filter ``steps | ls_flow(options)``: per step of a file (by position), the /MN
    lines of a control-flow or data step (:func:`olp.posts.fanuc_flow.lower`), empty for any
    other step. They are built from checked pieces (register and label numbers, comments of
    letters, digits and ``_``, checked numbers). What LS cannot express becomes an error on its
    line (:meth:`FanucPost.check_program` reports the same before rendering)."""
    lowered = lower(((s.kind, s.instruction) for s in steps), options, post.io_range)
    for node, message in lowered.problems:
        text = f"{_what(node)} cannot be written in LS: {message}"
        post.problems.append(Diagnostic("error", "flow", text, getattr(node, "span", None)))
    out = [SafeText("\n".join(lines)) for lines in lowered.lines]
    for k, step in enumerate(steps):
        if step.kind == "runtime_move" and isinstance(step, PostStep):
            out[k] = SafeText("\n".join(_runtime_lines(post, step, lowered.variables)))
    return tuple(out)


def _runtime_lines(post: Post, step: PostStep, registers: Mapping[str, Any]) -> list[str]:
    """The ``/MN`` lines of a motion to a run-time target: ``J PR[n:name] v% term``, ``L PR[n]
    v mm/sec term``, ``C PR[a]`` / ``:  PR[b] ...`` (position registers as motion targets:
    FANUC's motion instruction syntax "Motion Type, Position Type (P or PR), Speed,
    Termination", e.g. ``L PR[2] 110mm/s CNT50``, from a public FANUC teach-pendant
    programming course; an unverified point: olp assumes a Cartesian PR is read in the
    UFRAME_NUM/UTOOL_NUM in effect, which it sets before the line as for any motion). A
    target LS cannot name is an error on the motion (reported before rendering by
    :meth:`FanucPost.check_program`)."""
    ins: Any = step.instruction
    post.current_step = step
    try:
        refs = [position_register(expr, registers, ins) for expr in runtime_targets(ins)]
    except Unwritable as exc:
        post.problems.append(Diagnostic("error", "runtime_target", str(exc), ins.span, step.index))
        return []
    term = termination(post, ins.zone)
    if ins.motion == "joint":
        return [f"J {refs[0]} {joint_percent(post, ins.speed)}% {term}    ;"]
    speed = f"{linear_mm_per_s(post, ins.speed)}mm/sec {term}    ;"
    if ins.motion == "linear":
        return [f"L {refs[0]} {speed}"]
    return [f"C {refs[0]}", f":  {refs[1]} {speed}"]


def position_register(expr: Any, registers: Mapping[str, Any], ins: Any) -> str:
    """``PR[n:name]`` of the position variable ``expr`` names (a name, or an element of an
    array of them with a constant index: arrays take consecutive registers,
    :class:`olp.posts.fanuc_flow.Registers`). :class:`~olp.posts.fanuc_flow.Unwritable` for
    anything else: an element chosen at run time would need indirect addressing
    (``PR[R[i]]``), which olp has not verified; a linear or circular move to a joint position
    register is refused rather than left to the controller's conversion."""
    base = expr.base if isinstance(expr, ir.Index) else expr
    if not isinstance(base, ir.Name):
        raise Unwritable(
            "LS names a run-time target by a position register (a position variable of the "
            "program); olp does not write this expression as one",
            ins,
        )
    var = registers.get(base.name.upper())
    if var is None or not var.position:
        what = "not declared in the program" if var is None else "not a position"
        raise Unwritable(f"{base.name} is {what}: no position register holds it", ins)
    element = 1
    if isinstance(expr, ir.Index):
        index = constant_int(expr.indices[0]) if len(expr.indices) == 1 else None
        if index is None or not 1 <= index <= var.size:
            raise Unwritable(
                f"the element of {base.name} is chosen at run time (or out of its range): LS "
                "would need indirect addressing (PR[R[i]]), which olp has not verified",
                ins,
            )
        element = index
    if ins.motion != "joint" and var.kind != "cartesian":
        raise Unwritable(
            f"a {ins.motion} move needs a Cartesian position; {base.name} holds joints", ins
        )
    return str(var.ref(element))


def _row_moves(
    post: Post,
    rows: PostRows,
    number: int,
    last: tuple[int, int] | None,
    options: Mapping[str, Any] | None,
) -> tuple[LsMove, ...]:
    """:func:`ls_moves` of a run of linear moves, positions numbered from ``number + 1``: the
    numbers of all Cartesian positions formatted as columns, the others (no CONFIG selects the
    joints alone) as joints."""
    steps = rows.steps
    uf = [uframe_number(s.frame) for s in steps]
    ut = [utool_number(s.tool, options) for s in steps]
    configs = [s.vendor.get("config") if s.cartesian else None for s in steps]
    cartesian = [k for k, c in enumerate(configs) if c is not None]
    values: list[tuple[str, ...]] = [()] * len(steps)
    if cartesian:
        chosen = [steps[k] for k in cartesian]
        poses = np.stack([s.pose for s in chosen])  # type: ignore[misc]
        world = np.stack([s.frame_pose for s in chosen]) @ poses  # type: ignore[misc]
        in_uf = np.where(np.array([uf[k] > 0 for k in cartesian])[:, None, None], poses, world)
        v = pose_to_xyzwpr(in_uf)
        xyz = post.number_column("position", v[:, :3], chosen)
        wpr = post.number_column("angle", v[:, 3:], chosen)
        for j, k in enumerate(cartesian):
            values[k] = (*xyz[3 * j : 3 * j + 3], *wpr[3 * j : 3 * j + 3])
    for k, step in enumerate(steps):
        if configs[k] is None:
            post.current_step = step
            values[k] = tuple(ls_joints(post, step.joints))  # type: ignore[arg-type]
    post.current_step = rows
    out = []
    for k in range(len(steps)):
        number += 1
        target = LsPosition(number, uf[k], ut[k], configs[k], values[k])
        out.append(
            LsMove(target, None, last is None or last[0] != uf[k], last is None or last[1] != ut[k])
        )
        last = (uf[k], ut[k])
    return tuple(out)


def ls_rows_mn(post: Post, moves: LsRows | LsColumns) -> SafeText:
    """The ``/MN`` lines of a run of linear moves, exactly as ``program.ls.j2`` writes each:
    ``UFRAME_NUM``/``UTOOL_NUM`` where they change, then ``L P[n] v mm/sec term`` (a
    toolpath's rows as columns: :func:`olp.posts.fanuc_rows.mn_lines`)."""
    if isinstance(moves, LsColumns):
        return SafeText(mn_lines(post, moves))
    speeds: dict[Any, str] = {}
    terms: dict[Any, str] = {}
    lines = []
    for step, move in zip(moves.rows_steps.steps, moves.moves, strict=True):
        post.current_step = step
        if move.set_uf:
            lines.append(f"  UFRAME_NUM={move.target.uf} ;")
        if move.set_ut:
            lines.append(f"  UTOOL_NUM={move.target.ut} ;")
        speed = speeds.get(step.speed)
        if speed is None:
            speed = speeds[step.speed] = linear_mm_per_s(post, step.speed)
        term = terms.get(step.zone)
        if term is None:
            term = terms[step.zone] = termination(post, step.zone)
        lines.append(f"L P[{move.target.number}] {speed}mm/sec {term}    ;")
    post.current_step = moves.rows_steps
    return SafeText("\n".join(lines))


def ls_rows_pos(post: Post, moves: LsRows | LsColumns) -> SafeText:
    """The ``/POS`` entries of a run of linear moves, exactly as the template's ``position``
    macro writes each (each entry ends with its line break)."""
    if isinstance(moves, LsColumns):
        return SafeText(moves.positions)
    return SafeText("".join(_position_text(move.target) for move in moves.moves))


def _position_text(p: LsPosition) -> str:
    v = p.values
    if p.cartesian:
        x, y, z, w, pp, r = (f"{value:>9}" for value in v)
        body = (
            f"\tUF : {p.uf}, UT : {p.ut},\t\tCONFIG : '{p.config}',\n"
            f"\tX = {x}  mm,\tY = {y}  mm,\tZ = {z}  mm,\n"
            f"\tW = {w} deg,\tP = {pp} deg,\tR = {r} deg\n"
        )
    else:
        j = [f"{value:>10}" for value in v]
        body = (
            f"\tUF : {p.uf}, UT : {p.ut},\n"
            f"\tJ1={j[0]} deg,\tJ2={j[1]} deg,\tJ3={j[2]} deg,\n"
            f"\tJ4={j[3]} deg,\tJ5={j[4]} deg,\tJ6={j[5]} deg\n"
        )
    return f"P[{p.number}]{{\n   GP1:\n{body}}};\n"


def _in_user_frame(step: PostStep, pose_in_frame: ArrayLike, uf: int) -> FloatArray:
    """A pose given in the step's frame, in the frame ``UF`` positions refer to: the frame
    itself for UF 1..9, World (the post's ``frames_in: robot_base`` reference) for UF 0."""
    pose = np.asarray(pose_in_frame, dtype=np.float64)
    if uf > 0:
        return pose
    world: FloatArray = np.asarray(step.frame_pose) @ pose
    return world


def _target_position(post: Post, number: int, uf: int, ut: int, step: PostStep) -> LsPosition:
    assert step.joints is not None and step.pose is not None
    config = step.vendor.get("config") if step.cartesian else None
    if config is None:
        return LsPosition(number, uf, ut, None, tuple(ls_joints(post, step.joints)))
    pose = _in_user_frame(step, step.pose, uf)
    return LsPosition(number, uf, ut, config, tuple(ls_xyzwpr(post, pose)))


def _via_position(
    post: Post, number: int, uf: int, ut: int, step: PostStep, robot: Any
) -> LsPosition:
    """A circle's via point with the CONFIG of its IK solution nearest to the end joints (the
    arc stays in one branch), or the end joints' CONFIG when it has none."""
    assert step.frame is not None and step.tool is not None and step.via is not None
    assert step.frame.pose is not None and step.tool.pose is not None
    joints = np.asarray(step.joints, dtype=np.float64)
    config = "N U T, 0, 0, 0"
    if has_config(robot):
        via_world = np.asarray(step.frame.pose) @ np.asarray(step.via) @ inv(step.tool.pose)
        found = candidates(robot, via_world)
        if found.shape[0]:
            joints = found[np.argmin(np.sum((found - joints) ** 2, axis=-1))]
        config = str(config_from_joints(robot, joints))
    pose = _in_user_frame(step, step.via, uf)
    return LsPosition(number, uf, ut, config, tuple(ls_xyzwpr(post, pose)))


def number_lines(post: Post, body: str) -> SafeText:
    """Number the /MN lines: ``%4d:`` before each line, ``    :`` before a continuation line
    (one starting with ``:``); empty lines are dropped. The body was rendered from checked
    pieces, so its lines are safe."""
    out: list[str] = []
    count = 0
    for line in body.splitlines():
        if not line.strip():
            continue
        if line.startswith(":"):
            out.append("    " + line)
            continue
        count += 1
        out.append(f"{count:4d}:{line}")
    return SafeText("\n".join(out))


def line_count(post: Post, body: str) -> int:
    """The number of program lines of an un-numbered /MN body (continuations excluded)."""
    return sum(1 for line in body.splitlines() if line.strip() and not line.startswith(":"))


def _xyz_filter(post: Post, value: str) -> str:
    return f"{value:>9}"


def _joint_filter(post: Post, value: str) -> str:
    return f"{value:>10}"


FILTERS: Mapping[str, Filter] = {
    **Post.FILTERS,
    "fanuc_config": _config_filter,
    "ls_xyzwpr": ls_xyzwpr,
    "ls_joints": ls_joints,
    "ls_moves": ls_moves,
    "ls_joint_speed": joint_percent,
    "ls_linear_speed": linear_mm_per_s,
    "ls_termination": termination,
    "ls_seconds": wait_seconds,
    "ls_number_lines": number_lines,
    "ls_line_count": line_count,
    "ls_xyz_field": _xyz_filter,
    "ls_joint_field": _joint_filter,
    "ls_rows_mn": ls_rows_mn,
    "ls_rows_pos": ls_rows_pos,
    "ls_flow": ls_flow,
}


class FanucPost(Post):
    """Fanuc R-30iB LS; see the module docstring."""

    NAME = "fanuc"
    VENDOR = "fanuc"
    LANGUAGE = "LS"
    ROWS = True
    COLUMNS = True
    WRITES_FLOW = True
    STREAMS = True
    STREAM_PARTS = True
    PROGRAM_PARAMS = (
        "a TP program called with arguments reads them as AR[1], AR[2], ... (numbers and "
        "strings, by value), and olp has no Fanuc document at hand to cite for how an LS "
        "program declares and reads them, so it does not write them"
    )
    PROGRAM_RETURNS = (
        "a TP program has no result: a CALL runs it for its effects only (values come back "
        "through registers the program sets, which a caller must be written to read)"
    )
    ONCE_PER_PROGRAM = frozenset({"controller_frame", "controller_tool"})
    NAME_RULE = NAME_RULE
    COMMENTS = CommentRule(max_length=COMMENT_LENGTH, replace=((";", ","),), collapse=True)
    IO_RANGE = (1, 4096)
    CALL_ARGUMENTS = ArgumentRule(re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)"), "numbers")
    NUMBERS: ClassVar[Mapping[str, NumberFormat]] = NUMBERS
    FILTERS: ClassVar[Mapping[str, Filter]] = FILTERS
    KINDS: ClassVar[frozenset[str]] = Post.KINDS | {"runtime_move"}

    def __init__(self, manifest: Any) -> None:
        super().__init__(manifest)
        self._configs: dict[int, tuple[Any, _SelectionMemo]] = {}
        self._columns: dict[int, tuple[weakref.ref[Any], Any, NDArray[np.object_]]] = {}

    def check_instruction(self, step: Step, compiled: CompiledProgram) -> list[Diagnostic]:
        """``speed_raised`` (warning): a speed LS cannot write so slow, written at its least
        (``L``/``C`` 1mm/sec, ``J`` 1%): the robot moves faster there than programmed and
        timed."""
        ins: Any = step.instruction
        kind = ins.motion if ins.kind == "runtime_move" else ins.kind
        if step.skipped or kind not in ("joint", "linear", "circular"):
            return []
        if kind == "joint":
            given, least, unit = ins.speed.joint * 100.0, 1, "%"
        else:
            given, least, unit = ins.speed.linear * 1000.0, 1, "mm/sec"
        if _round_half_up(given) >= least:
            return []
        message = (
            f"speed {given:.3g} {unit} is below the least LS can write; written as "
            f"{least}{unit}, faster than programmed"
        )
        return [Diagnostic("warning", "speed_raised", message, ins.span, step.index)]

    def check_rows(self, block: PathBlock, compiled: CompiledProgram) -> list[Diagnostic]:
        """:meth:`check_instruction` of a toolpath's rows (linear moves), from its speeds:
        ``speed_raised`` on each row whose speed rounds below 1mm/sec, in row order."""
        given = block.node.speeds * 1000.0
        raised = np.flatnonzero(np.floor(given + 0.5) < 1)
        out = []
        for k in raised.tolist():
            message = (
                f"speed {float(given[k]):.3g} mm/sec is below the least LS can write; written "
                "as 1mm/sec, faster than programmed"
            )
            span = block.node.row_span(k)
            out.append(Diagnostic("warning", "speed_raised", message, span, block.start + k))
        return out

    def step_values(self, robot: Any, joints: Any) -> list[Mapping[str, Any]]:
        """Per planned motion (joints (N, 6) rad) ``{"config": str | None}``, the CONFIG a
        Cartesian position gets (:func:`olp.vendors.fanuc.selecting_configs`)."""
        return [{"config": c} for c in self.selecting_configs(robot, joints)]

    def step_columns(self, robot: Any, joints: Any) -> Mapping[str, Any]:
        """:meth:`step_values` of a toolpath's rows (joints (N, 6) rad) as columns:
        ``{"config": array (N,)}`` of CONFIG texts (each distinct text one object) and None
        (:func:`olp.vendors.fanuc.selecting_config_column`).

        Remembered per joints array while it lives (the checks and the render ask for the same
        block's array), rather than per row as :meth:`selecting_configs` remembers: a
        million rows in a few hundred blocks would re-sort the row memo once per block."""
        key = id(joints)
        known = self._columns.get(key)
        if known is None or known[0]() is not joints or known[1] is not robot:
            column = selecting_config_column(robot, joints)
            columns = self._columns
            known = (weakref.ref(joints, lambda _: columns.pop(key, None)), robot, column)
            columns[key] = known
        return {"config": known[2]}

    def selecting_configs(self, robot: Any, joints: Any) -> list[str | None]:
        """:func:`olp.vendors.fanuc.selecting_configs`, remembered per joint vector for this
        post and robot: the checks and the render ask for the same motions (an IK per row)."""
        configs: list[str | None] = self.config_column(robot, joints).tolist()
        return configs

    def config_column(self, robot: Any, joints: Any) -> NDArray[np.object_]:
        """:meth:`selecting_configs` as an array (N,) of objects (a CONFIG text or None;
        :func:`olp.vendors.fanuc.selecting_config_column`)."""
        q = np.ascontiguousarray(joints, dtype=np.float64).reshape(-1, 6)
        memo = self._configs.get(id(robot))
        if memo is None or memo[0] is not robot:
            memo = self._configs[id(robot)] = (robot, _SelectionMemo())
        out, missing = memo[1].lookup(q)
        if missing.size:
            found = selecting_config_column(robot, q[missing])
            memo[1].add(q[missing], found)
            out[missing] = found
        return out

    def check_program(self, compiled: CompiledProgram) -> list[Diagnostic]:
        """Frame and tool numbers LS cannot write (errors), a tool number olp chose (warning,
        with the TCP the controller must hold), the controller frames and tools the program
        relies on (info), Cartesian targets written as joints because no CONFIG selects them
        alone (info)."""
        robot = compiled.station.robot
        motions = _motions(compiled)
        firsts = [m.step(0) if isinstance(m, PathBlock) else m for m in motions]
        out = _frame_checks(self, firsts, robot)
        out += _tool_checks(self, firsts, self.options)
        out += _joint_position_notes(self, motions, robot) + _flow_checks(self, compiled)
        return out + _runtime_checks(self, compiled)


def _runtime_checks(post: Post, compiled: CompiledProgram) -> list[Diagnostic]:
    """``runtime_target`` (error): a motion to a run-time target whose target LS cannot name
    as a position register (:func:`position_register`)."""
    items = items_of(compiled.steps)  # a toolpath's rows stay a block: none is a run-time motion
    runtime = [
        s for s in items if isinstance(s, Step) and isinstance(s.instruction, ir.RuntimeMove)
    ]
    if not runtime:
        return []
    from olp.posts.flow import weave
    from olp.posts.view import PostStep

    steps = [PostStep(s.index, s.instruction.kind, "", s.instruction) for s in compiled.steps]
    events = [(s.kind, s.instruction) for s in weave(compiled.program, steps)]
    registers = lower(events, post.options, post.io_range).variables
    out = []
    for step in runtime:
        ins: Any = step.instruction
        try:
            for expr in runtime_targets(ins):
                position_register(expr, registers, ins)
        except Unwritable as exc:
            msg = f"the run-time target cannot be written in LS: {exc}"
            out.append(Diagnostic("error", "runtime_target", msg, ins.span, step.index))
    return out


def _motions(compiled: CompiledProgram) -> list[Step | PathBlock]:
    """The planned motions of ``compiled`` in order: steps with joints, and toolpath blocks
    (their rows, all with joints, as one item)."""
    return [item for item in items_of(compiled.steps) if item.joints is not None]


def _flow_checks(post: Post, compiled: CompiledProgram) -> list[Diagnostic]:
    """* ``flow`` (error): a control-flow or data statement LS cannot express
    (:mod:`olp.posts.fanuc_flow`), on its line;
    * ``declaration_dropped`` (warning): a declaration of a type LS has no register for (text,
      structures); using the variable is an error."""
    if not compiled.program.has_flow:
        return []
    from olp.posts.flow import weave
    from olp.posts.view import PostStep

    steps = [PostStep(s.index, s.instruction.kind, "", s.instruction) for s in compiled.steps]
    events = [(s.kind, s.instruction) for s in weave(compiled.program, steps)]
    lowered = lower(events, post.options, post.io_range)
    out = [
        Diagnostic("error", "flow", f"{_what(node)} cannot be written in LS: {msg}", node.span)
        for node, msg in lowered.problems
    ]
    for decl in lowered.unwritten:
        msg = (
            f"declaration of {decl.name} ({decl.type_name}) is not written: LS has no register "
            "for that type"
        )
        out.append(Diagnostic("warning", "declaration_dropped", msg, decl.span))
    return out + module_data_notes(compiled.program.instructions, lowered)


def module_data_notes(nodes: Sequence[Any], lowered: Any) -> list[Diagnostic]:
    """``module_data`` (warning): one per module-data variable written to a register, whose
    value LS does not set: the register must hold the data list's value before the first run."""
    from olp import ir_flow
    from olp.posts.kuka_flow import krl_expr

    out = []
    for node in ir_flow.leaves_and_blocks(nodes):
        if not (isinstance(node, ir_flow.Declare) and node.scope == "module"):
            continue
        var = lowered.variables.get(node.name.upper())
        if var is None:
            continue
        value = "" if node.value is None else f" = {krl_expr(node.value)}"
        elements = " and its elements' values" if node.elements else ""
        msg = (
            f"{node.name}{value} is module data, kept from one run to the next; LS does not set "
            f"{var.ref()} when the program loads: set it to the data list's value{elements} "
            "on the controller before the first run"
        )
        out.append(Diagnostic("warning", "module_data", msg, node.span))
    return out


def _what(node: Any) -> str:
    kind = getattr(node, "kind", None) or type(node).__name__.lower()
    return str(kind).replace("_", " ")


def _first_use(motions: Sequence[Any], attr: str) -> dict[str, Any]:
    seen: dict[str, Any] = {}
    for step in motions:
        seen.setdefault(getattr(step, attr).name, step)
    return seen


def _frame_checks(post: Post, motions: Sequence[Any], robot: Any) -> list[Diagnostic]:
    out: list[Diagnostic] = []
    world = np.asarray(robot.base) @ np.asarray(robot.controller_base)
    for name, step in _first_use(motions, "frame").items():
        number = step.frame.number
        if number is not None and number > UFRAME_RANGE[1]:
            msg = f"frame {name!r} has number {number}: LS user frames are 1..{UFRAME_RANGE[1]}"
            out.append(_diag("error", "frame_number", msg, step))
        elif uframe_number(step.frame) > 0:
            values = _written(post, inv(world) @ np.asarray(step.frame.pose))
            msg = f"positions use UFRAME[{number}] ({name!r}); the controller must hold it as "
            out.append(_diag("info", "controller_frame", msg + values, step))
    return out


def _tool_checks(
    post: Post, motions: Sequence[Any], options: Mapping[str, Any] | None
) -> list[Diagnostic]:
    out: list[Diagnostic] = []
    first = _first_use(motions, "tool")
    numbered = {t.tool.number for t in first.values() if t.tool.number is not None}
    unnumbered = [n for n, s in first.items() if s.tool.number is None and not is_flange(s.tool)]
    for name, step in first.items():
        number, ut = step.tool.number, utool_number(step.tool, options)
        values = _written(post, step.tool.pose)
        if not UTOOL_RANGE[0] <= ut <= UTOOL_RANGE[1]:
            msg = f"tool {name!r} would be UTOOL {ut}: LS tool frames are 0..{UTOOL_RANGE[1]}"
            out.append(_diag("error", "tool_number", msg, step))
        elif number is None and ut > 0 and (len(unnumbered) > 1 or ut in numbered):
            msg = f"tool {name!r} has no number, and UTOOL {ut} cannot be its: " + (
                "another tool has that number"
                if ut in numbered
                else f"{len(unnumbered)} tools have no number"
            )
            out.append(_diag("error", "tool_number", msg, step))
        elif number is None and ut > 0:
            msg = f"tool {name!r} has no number: written as UTOOL {ut}, which must hold "
            out.append(_diag("warning", "tool_number", msg + values, step))
        elif ut > 0:
            msg = f"positions use UTOOL[{ut}] ({name!r}); the controller must hold it as "
            out.append(_diag("info", "controller_tool", msg + values, step))
    return out


def _joint_position_notes(
    post: FanucPost, motions: Sequence[Step | PathBlock], robot: Any
) -> list[Diagnostic]:
    """Info per Cartesian target written in joint form (no CONFIG selects it alone); a
    toolpath's rows (all Cartesian) from their column of CONFIGs."""
    from olp.ir import CartesianTarget

    steps = [
        m
        for m in motions
        if isinstance(m, Step) and isinstance(m.instruction.target, CartesianTarget)  # type: ignore[union-attr]
    ]
    configs: dict[int, str | None] = {}
    if steps:
        joints = np.stack([np.asarray(s.joints, dtype=np.float64) for s in steps])
        found = post.selecting_configs(robot, joints)
        configs = {s.index: c for s, c in zip(steps, found, strict=True)}
    out: list[Diagnostic] = []
    for item in motions:
        if isinstance(item, PathBlock):
            column = post.step_columns(robot, item.joints)["config"]
            for k in np.flatnonzero(~configured(column)).tolist():
                note = (_JOINT_POSITION, item.node.row_span(k), item.start + k)
                out.append(Diagnostic("info", "joint_position", *note))
        elif configs.get(item.index, "") is None:
            out.append(_diag("info", "joint_position", _JOINT_POSITION, item))
    return out


_JOINT_POSITION = (
    "Cartesian target written as joint values: no CONFIG selects the planned joints alone (an "
    "arm without CONFIG, a wrist singularity, or a J3 range holding two turns)"
)


def _written(post: Post, pose: ArrayLike) -> str:
    """A frame or tool pose as the controller must hold it, in words for a diagnostic."""
    try:
        return _spell(ls_xyzwpr(post, pose))
    except NumberError as exc:
        return f"(it cannot be written: {exc})"


def _spell(values: Sequence[str]) -> str:
    return " ".join(f"{k} {v}" for k, v in zip("XYZWPR", values, strict=True)) + " (mm, deg)"


def _diag(severity: Any, kind: str, message: str, step: Any) -> Diagnostic:
    return Diagnostic(severity, kind, message, step.instruction.span, step.index)


class _SelectionMemo:
    """CONFIG selections (:func:`olp.vendors.fanuc.selecting_configs`) remembered per joint
    vector, the rows found by a 64-bit hash of their bytes (sorted, ``np.searchsorted``) and
    confirmed by comparing all their bytes: a hit is the same row bit for bit (as a dict keyed
    by ``row.tobytes()`` would find it), a hash collision only a miss. About 64 bytes per row
    and no Python object per row (a dict of bytes keys took ~150 bytes and 3 us per row)."""

    def __init__(self) -> None:
        self.hashes = np.empty(0, dtype=np.uint64)
        self.bits = np.empty((0, 6), dtype=np.uint64)
        self.configs = np.empty(0, dtype=object)

    def lookup(self, q: NDArray[np.float64]) -> tuple[NDArray[np.object_], NDArray[np.intp]]:
        """Known selections (n,) of joints (n, 6) rad (None where unknown) and the indices
        of the unknown rows."""
        bits = q.view(np.uint64)
        out = np.full(q.shape[0], None, dtype=object)
        if self.hashes.size == 0:
            return out, np.arange(q.shape[0])
        h = _row_hashes(bits)
        at = np.minimum(np.searchsorted(self.hashes, h), self.hashes.size - 1)
        hit = (self.hashes[at] == h) & np.all(self.bits[at] == bits, axis=-1)
        out[hit] = self.configs[at[hit]]
        return out, np.flatnonzero(~hit)

    def add(self, q: NDArray[np.float64], configs: NDArray[np.object_]) -> None:
        """Remember the selections (m,) of joints (m, 6) rad."""
        bits = np.ascontiguousarray(q).view(np.uint64)
        hashes = np.concatenate([self.hashes, _row_hashes(bits)])
        order = np.argsort(hashes, kind="stable")
        self.hashes = hashes[order]
        self.bits = np.concatenate([self.bits, bits])[order]
        self.configs = np.concatenate([self.configs, configs])[order]


def _row_hashes(bits: NDArray[np.uint64]) -> NDArray[np.uint64]:
    """A 64-bit FNV-style hash (n,) of rows (n, 6) of float bits (wrapping arithmetic)."""
    h = np.full(bits.shape[0], 0xCBF29CE484222325, dtype=np.uint64)
    for j in range(bits.shape[1]):
        h ^= bits[:, j]
        h *= np.uint64(0x100000001B3)
        h ^= h >> np.uint64(29)
    return h
