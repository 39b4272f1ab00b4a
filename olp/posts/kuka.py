"""The KRL post (KUKA KR C4, KSS 8): a ``.src`` module with its ``.dat`` data list.

Conventions shared with the KRL frontend (ABC angles, Status and Turn, the flange frame) live in
:mod:`olp.vendors.kuka`; this module is how the post spells them. Pinned by
``tests/posts/test_kuka.py``, the cross-post table ``tests/posts/test_all_posts.py`` and the golden
files ``tests/golden/kuka/``.

* Module: ``&ACCESS RVP`` / ``&REL 1`` header, ``DEF name( )`` ... ``END`` in ``name.src`` and
  ``DEFDAT name PUBLIC`` ... ``ENDDAT`` in ``name.dat``; the module name is the file name
  (:data:`NAME_RULE`: letters, digits, ``_``, 24 characters, not a keyword; the length is widely
  cited, unverified). CRLF line endings, ASCII (WorkVisual and the pendant write CRLF).
* The INI fold ``;FOLD INI;%{PE}`` with ``BASISTECH INI`` (``GLOBAL INTERRUPT DECL 3 WHEN
  $STOPMESS==TRUE DO IR_STOPM ( )``, ``INTERRUPT ON 3``, ``BAS (#INITMOV,0 )``) and ``USER INI``:
  the KSS 8 new-module template, as found verbatim in several public KR C4 programs (high
  confidence).
* Targets: ``E6POS`` ``{X,Y,Z,A,B,C,S,T}`` (mm, deg, S and T decimal as the pendant writes them
  in .dat files) for Cartesian targets, ``E6AXIS`` ``{A1..A6}`` (deg) for joint targets; inline
  aggregates or named points ``DECL E6POS XP1={..}`` in the .dat (the pendant's naming);
  ``CIRC aux, end`` (``, CA angle`` in degrees when the move has a circular angle), with
  ``$ORI_TYPE``/``$CIRC_TYPE`` written before an arc whose rule differs from the last written
  (:data:`olp.vendors.kuka.ARC_TYPES`; the first arc always writes both) and ``$ORI_TYPE =
  #VAR`` again before the next LIN (olp's LIN interpolates the orientation). KRL writes every
  rule but the wrist one (:attr:`KukaPost.ARC_ORIENTATIONS`). External axes E1..E6 are not
  written: on a robot without them they mean nothing, and a written 0 would move an axis that
  exists.
* ``$TOOL``/``$BASE``: ``{FRAME: ..}`` or ``TOOL_DATA[1..16]``/``BASE_DATA[1..32]`` (the arrays
  of ``$config.dat``); ``$NULLFRAME`` for no tool / the world. ``$BASE`` is relative to
  ``$WORLD``.
* Speeds: ``$VEL.CP`` in m/s, ``$VEL.ORI1``/``$VEL.ORI2`` in deg/s, ``$VEL_AXIS[i]``/
  ``$ACC_AXIS[i]`` in whole percent 1..100 (:data:`VEL_AXIS_MIN_PERCENT`, medium confidence);
  approximation ``C_DIS`` with ``$APO.CDIS`` (mm), ``C_PTP`` with ``$APO.CPTP`` (INT, 1..100 %:
  KUKA's mxAutomation manual describes the APO structure so, medium confidence).
  ``Speed.linear_acceleration`` as ``$ACC.CP`` (m/s², the LIN/CIRC path acceleration; KSS
  system variables as quoted by forum threads and simulation vendors' KUKA interface pages,
  medium confidence) and ``Speed.angular_acceleration`` as ``$ACC.ORI1`` (deg/s², swivel;
  ``$ACC.ORI2`` is left as the controller has it), with the path speed, only where the
  program sets them (the controller's values apply otherwise).
* ``$OUT[n] = TRUE``, ``WAIT SEC t``, ``WAIT FOR $IN[n]``, ``name(args)`` (the forms KUKA's inline
  forms produce). I/O numbers 1..4096 (:data:`IO_RANGE`; KR C4's digital inputs and outputs as
  recalled, unverified: a template folder may set the option ``io_range``).
* Numbers: KRL's REAL is a 32-bit float (range ±3.4E+38, about 7 digits: medium confidence), so
  every written value must be held by one to the resolution of :data:`NUMBERS`: positions to
  0.01 mm, angles to 0.001°.
* Comments: ``;`` to the end of the line; a comment of several lines becomes several ``;`` lines.
  A pendant fold read from KRL (``;FOLD ...``/``;ENDFOLD``) is written back as it was read
  (:meth:`KukaPost.comment_node_lines`); a program read from KRL with its own ``;FOLD INI``
  gets that INI (its lines kept as written) instead of the template's.
* Call arguments: numbers, ``"strings"``, names, ``#ENUM`` values and ``$`` system variables.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.diagnostics import Diagnostic
from olp.errors import PostError
from olp.ir import RUNTIME_RELATIVE, ArcOrientation, CartesianTarget
from olp.ir_flow import FLOW_TYPES, Declare, Routine, leaves_and_blocks
from olp.posts.base import Filter, Post
from olp.posts.kuka_flow import (
    EVENT_KINDS,
    flow_expr_problem,
    flow_problem,
    krl_approximation,
    krl_call,
    krl_decl,
    krl_declaration,
    krl_declarations,
    krl_event,
    krl_expr,
    krl_io,
    krl_param_decl,
    krl_program_head,
    krl_return,
    krl_routine_end,
    krl_routine_head,
    krl_type_definition,
    routine_problem,
)
from olp.posts.numbers import NumberFormat, Storage
from olp.posts.routines import flow_nodes_of_routines
from olp.posts.sandbox import SafeText
from olp.posts.text import IDENTIFIER, NUMBER, ArgumentRule, NameRule, double_quoted, one_of
from olp.posts.view import RowColumns
from olp.vendors.kuka import ARC_TYPES, pose_to_frame, status_turn, turn_ambiguous

if TYPE_CHECKING:
    from olp.compiled import CompiledProgram, PathBlock, Step
    from olp.posts.rows import PostRows
    from olp.posts.view import Modal, PostStep

_KEYWORDS = """
AND ANIN ANOUT B_AND B_EXOR B_NOT B_OR BOOL BRAKE C_DIS C_ORI C_PTP C_VEL CASE CHAR CIRC
CIRC_REL CONST CONTINUE DECL DEF DEFAULT DEFDAT DEFFCT DELAY DO ELSE END ENDDAT ENDFCT ENDFOR
ENDIF ENDLOOP ENDSWITCH ENDWHILE ENUM EXIT EXOR EXT EXTFCT FALSE FOR GLOBAL GOTO HALT IF IMPORT
INT INTERRUPT IS LIN LIN_REL LOOP MAXIMUM MINIMUM NOT OR PRIO PTP PTP_REL PUBLIC REAL REPEAT
RESUME RETURN SEC SIGNAL STEP STRUC SWITCH THEN TO TRIGGER TRUE UNTIL WAIT WHEN WHILE
"""
KEYWORDS = frozenset(_KEYWORDS.split())
"""KRL keywords (case-insensitive) a name must not be; from the KSS 8 expert programming manual's
syntax chapters as remembered (medium confidence: the list may be incomplete)."""

MAX_NAME_LENGTH = 24
"""KRL identifiers and module names: 24 characters (widely cited; unverified against KUKA docs)."""

NAME_RULE = NameRule(max_length=MAX_NAME_LENGTH, reserved=KEYWORDS)

_AGGREGATE_PART = r"[A-Za-z0-9_$#.+\-,: \[\]]|" + double_quoted()
AGGREGATE = rf"\{{(?:{_AGGREGATE_PART}|\{{(?:{_AGGREGATE_PART})*\}})*\}}"
"""A KRL aggregate as a call argument: ``{rX 810, rY 67}``, ``{POS: X 1, Y 2}``, members that
are aggregates one level deep, strings without ``"``. No ``;`` outside a string (KRL's comment
would hide the call's closing parenthesis) and no parenthesis (an aggregate holds constants, no
call). The alternatives start with different characters, so matching is linear in the length."""
"""A legal KRL name: letters, digits and ``_``, a letter first, 24 characters, not a keyword (a
keyword gets a trailing ``_``). The .src/.dat file names use it too: DEF name == file name."""

VEL_AXIS_MIN_PERCENT = 1
"""The smallest ``$VEL_AXIS`` / ``$ACC_AXIS`` value, %: INT, range 1 .. 100 (medium confidence;
KUKA's own inline forms and public third-party KRL posts write whole percents). olp writes whole
percents, rounded down (:func:`krl_percent`)."""

TOOL_DATA_SIZE = 16
"""``TOOL_DATA[1..16]`` in ``$config.dat`` (KSS 8; project vendor notes)."""
BASE_DATA_SIZE = 32
"""``BASE_DATA[1..32]`` in ``$config.dat`` (KSS 8; project vendor notes)."""

NULL_FRAME = "$NULLFRAME"
"""KRL's zero frame: ``$TOOL = $NULLFRAME`` is the bare flange, ``$BASE = $NULLFRAME`` the world
(KSS 8 system variables)."""

_REAL: Storage = "real32"

NUMBERS: Mapping[str, NumberFormat] = {
    **Post.NUMBERS,
    "position": NumberFormat("position", "mm", 3, storage=_REAL, resolution=0.01),
    "angle": NumberFormat("angle", "deg", 4, storage=_REAL, resolution=0.001),
    "axis": NumberFormat("axis value", "deg", 5, storage=_REAL, resolution=0.001),
    "vel_cp": NumberFormat(
        "path speed $VEL.CP", "m/s", 5, low=0.0, low_open=True, storage=_REAL, resolution=1e-5
    ),
    "vel_ori": NumberFormat(
        "orientation speed $VEL.ORI", "deg/s", 3, low=0.0, low_open=True, storage=_REAL
    ),
    "acc_cp": NumberFormat(
        "path acceleration $ACC.CP", "m/s²", 4, low=0.0, low_open=True, storage=_REAL
    ),
    "acc_ori": NumberFormat(
        "orientation acceleration $ACC.ORI1", "deg/s²", 3, low=0.0, low_open=True, storage=_REAL
    ),
    "percent": NumberFormat("axis speed or acceleration", "%", 0, 1, 100, storage="int"),
    "cdis": NumberFormat(
        "approximation distance $APO.CDIS", "mm", 3, low=0.0, low_open=True, storage=_REAL
    ),
    "cptp": NumberFormat("approximation $APO.CPTP", "%", 0, 1, 100, storage="int"),
    "wait": NumberFormat("dwell WAIT SEC", "s", 3, low=0.0, storage=_REAL, resolution=0.01),
}
"""How the KRL post writes each quantity (printed units)."""


# --------------------------------------------------------------------------------------------
# Spelling


def krl_frame(post: Post, pose: ArrayLike) -> str:
    """``X 1.000,Y 2.000,Z 3.000,A 0.0000,B 90.0000,C 0.0000`` from a pose (4, 4) in metres."""
    x, y, z, a, b, c = pose_to_frame(pose)
    values = [post.number("position", v) for v in (x, y, z)]
    values += [post.number("angle", v) for v in (a, b, c)]
    return ",".join(f"{k} {v}" for k, v in zip("XYZABC", values, strict=True))


def krl_axis(post: Post, joints: ArrayLike) -> str:
    """``A1 0.00000,A2 -90.00000,...`` from controller joint values (6,) in radians."""
    deg = np.degrees(np.asarray(joints, dtype=np.float64))
    return ",".join(f"A{i + 1} {post.number('axis', v)}" for i, v in enumerate(deg))


def krl_e6pos(post: Post, pose: ArrayLike, status: int, turn: int) -> str:
    """An E6POS value without braces, ``X ..,Y ..,Z ..,A ..,B ..,C ..,S 2,T 10``: a pose (4, 4)
    in metres with Status and Turn (decimal, as the pendant writes them in .dat files)."""
    return f"{krl_frame(post, pose)},S {int(status)},T {int(turn)}"


def krl_point_type(post: Post, step: PostStep) -> str:
    """``E6AXIS`` for a PTP to a joint target, and for a PTP whose Turn cannot select the
    planned joints (``step.vendor["turn_ambiguous"]``, :func:`olp.vendors.kuka.turn_ambiguous`);
    ``E6POS`` for every other motion."""
    if step.kind == "joint" and (not step.cartesian or step.vendor.get("turn_ambiguous")):
        return "E6AXIS"
    return "E6POS"


def krl_point(post: Post, step: PostStep) -> str:
    """A step's target without braces: axis values where :func:`krl_point_type` says
    ``E6AXIS``, else the TCP pose in the motion's base with the planned joints' Status and Turn
    (LIN and CIRC ignore S and T, PTP honours them)."""
    assert step.joints is not None
    if krl_point_type(post, step) == "E6AXIS":
        return krl_axis(post, step.joints)
    assert step.pose is not None
    return krl_e6pos(post, step.pose, step.vendor["status"], step.vendor["turn"])


def krl_tool(post: Post, step: PostStep, mode: str = "inline") -> str:
    """``$TOOL``: ``$NULLFRAME`` for the bare flange; ``{FRAME: ..}`` (the TCP in KUKA's flange
    frame) in ``inline`` mode, ``TOOL_DATA[n]`` (the station's number, 1 .. 16) in ``indexed``."""
    tool = step.tool
    assert tool is not None and tool.pose is not None
    if _is_identity(tool.pose):
        return NULL_FRAME
    if mode == "indexed":
        return f"TOOL_DATA[{_index(step, tool, TOOL_DATA_SIZE, 'tool')}]"
    return "{FRAME: " + krl_frame(post, tool.pose) + "}"


def krl_base(post: Post, step: PostStep, mode: str = "inline") -> str:
    """``$BASE``: ``$NULLFRAME`` when the frame is the reference itself; ``{FRAME: ..}``
    (``step.frame_pose``) in ``inline`` mode, ``BASE_DATA[n]`` (1 .. 32) in ``indexed``."""
    assert step.frame_pose is not None
    if _is_identity(step.frame_pose):
        return NULL_FRAME
    if mode == "indexed":
        return f"BASE_DATA[{_index(step, step.frame, BASE_DATA_SIZE, 'base')}]"
    return "{FRAME: " + krl_frame(post, step.frame_pose) + "}"


def krl_percent(post: Post, fraction: float) -> str:
    """A fraction (0, 1] as a whole ``$VEL_AXIS``/``$ACC_AXIS`` percent, rounded down (never
    faster than planned; a fraction within 1e-9 of a whole percent counts as it), at least 1."""
    return post.number("percent", max(VEL_AXIS_MIN_PERCENT, whole_percent(fraction)))


def whole_percent(fraction: float) -> int:
    """``floor(100 · fraction)``, with fractions within 1e-9 % of a whole percent on it."""
    return math.floor(float(fraction) * 100.0 + 1e-9)


def krl_arc_types(post: Post, step: PostStep) -> tuple[str, str]:
    """``($ORI_TYPE, $CIRC_TYPE)`` without ``#`` of a circular move's orientation rule."""
    ins: Any = step.instruction
    return ARC_TYPES[ins.orientation]


def krl_ca(post: Post, step: PostStep) -> str:
    """``, CA 90.0000`` for a circular move with a circular angle (degrees), else ''."""
    angle = getattr(step.instruction, "angle", None)
    return "" if angle is None else f", CA {post.number('angle', math.degrees(angle))}"


def krl_rows(
    post: Post, rows: PostRows | RowColumns, modal: Modal, arcs_written: bool = False
) -> SafeText:
    """The lines of a run of LINs (:mod:`olp.posts.rows`), exactly as ``program.src.j2`` writes
    each (inline points): ``$BASE``/``$TOOL`` where they change, ``$VEL.CP`` (and ``$VEL.ORI``,
    ``$ACC.CP``, ``$ACC.ORI1`` where set) where the speed changes, ``$APO.CDIS`` where the
    approximation distance changes (``modal``),
    ``$ORI_TYPE = #VAR`` after an arc (``arcs_written``), then ``LIN {E6POS} [C_DIS]``. The
    targets' numbers are formatted as columns. Every piece is a checked number, a legal name or
    a keyword, so the lines are :class:`~olp.posts.sandbox.SafeText`."""
    if isinstance(rows, RowColumns):
        return SafeText(_column_lines(post, rows, modal, arcs_written))
    steps = rows.steps
    named = post.options.get("points", "inline") == "dat"
    targets = [s.name for s in steps] if named else [f"{{{t}}}" for t in _e6pos_texts(post, rows)]
    mode = str(post.options.get("frames", "inline"))
    lines: list[str] = []
    for k, step in enumerate(steps):
        post.current_step = step
        if step.new_frame:
            lines.append(f"$BASE = {krl_base(post, step, mode)} ; {step.frame_name}")
        if step.new_tool:
            lines.append(f"$TOOL = {krl_tool(post, step, mode)} ; {step.tool_name}")
        speed, zone = step.speed, step.zone
        if step.new_linear_speed:
            lines.append(f"$VEL.CP = {post.number('vel_cp', speed.linear)}")
            if speed.angular is not None:
                ori = post.number("vel_ori", math.degrees(speed.angular))
                lines += [f"$VEL.ORI1 = {ori}", f"$VEL.ORI2 = {ori}"]
            if speed.linear_acceleration is not None:
                lines.append(f"$ACC.CP = {post.number('acc_cp', speed.linear_acceleration)}")
            if speed.angular_acceleration is not None:
                acc_ori = post.number("acc_ori", math.degrees(speed.angular_acceleration))
                lines.append(f"$ACC.ORI1 = {acc_ori}")
        fine = zone.is_fine
        if not fine and modal.changed("cdis", zone.radius):
            lines.append(f"$APO.CDIS = {post.number('cdis', zone.radius * 1000)}")
        if arcs_written and modal.changed("ori_type", "VAR"):
            lines.append("$ORI_TYPE = #VAR")
        lines.append(f"LIN {targets[k]}" + ("" if fine else " C_DIS"))
    post.current_step = rows
    return SafeText("\n".join(lines))


def krl_rows_dat(post: Post, rows: PostRows | RowColumns) -> SafeText:
    """The .dat declarations of a run of LINs with named points (``points: dat``), exactly as
    ``program.dat.j2`` writes each: ``DECL E6POS XP12={X ..,S ..,T ..}``."""
    if isinstance(rows, RowColumns):
        fields = _e6pos_fields(post, rows)
        heads = [f"DECL E6POS {name}={{" for name in rows.names]
        return SafeText("\n".join(_e6pos_lines(fields, heads, ["}"] * len(heads))))
    texts = _e6pos_texts(post, rows)
    lines = [f"DECL E6POS {s.name}={{{t}}}" for s, t in zip(rows.steps, texts, strict=True)]
    return SafeText("\n".join(lines))


def _e6pos_texts(post: Post, rows: PostRows) -> list[str]:
    """Each row's E6POS without braces (:func:`krl_e6pos`), its numbers formatted as columns."""
    steps = rows.steps
    frames = pose_to_frame(rows.poses())
    xyz = post.number_column("position", frames[:, :3], steps)
    abc = post.number_column("angle", frames[:, 3:], steps)
    out = []
    for k, step in enumerate(steps):
        p = 3 * k
        out.append(
            f"X {xyz[p]},Y {xyz[p + 1]},Z {xyz[p + 2]},A {abc[p]},B {abc[p + 1]},C {abc[p + 2]}"
            f",S {int(step.vendor['status'])},T {int(step.vendor['turn'])}"
        )
    return out


def _e6pos_fields(post: Post, rows: RowColumns) -> list[list[Any]]:
    """The numbers of each row's E6POS (:func:`krl_e6pos`) formatted as columns: lists (n,)
    of the texts of X, Y, Z, A, B, C and of the integers S, T."""
    frames = pose_to_frame(rows.poses)
    xyz = post.number_texts("position", frames[:, :3], rows.at)
    abc = post.number_texts("angle", frames[:, 3:], rows.at)
    texts = [column.tolist() for column in (*xyz.T, *abc.T)]
    # Python ints print as numpy's int64 texts did (decimal, '-' only)
    integers = [np.asarray(rows.column(k), dtype=np.int64).tolist() for k in ("status", "turn")]
    return [*texts, *integers]


def _e6pos_lines(fields: list[list[Any]], heads: list[str], tails: list[str]) -> list[str]:
    """Each row's E6POS without braces from its :func:`_e6pos_fields`, between the row's
    ``heads`` and ``tails`` (n,) texts: one f-string per row (about twice as fast as
    concatenating the columns with ``np.strings.add``, measured by
    benchmarks/timing_stage.py)."""
    return [
        f"{head}X {x},Y {y},Z {z},A {a},B {b},C {c},S {s},T {t}{tail}"
        for head, x, y, z, a, b, c, s, t, tail in zip(heads, *fields, tails, strict=True)
    ]


def _column_lines(post: Post, rows: RowColumns, modal: Modal, arcs_written: bool) -> str:
    """:func:`krl_rows` of a toolpath's rows as columns: the ``LIN`` lines as arrays, and
    before each row the lines it changes (modal state tracked over the arrays)."""
    n = len(rows)
    at = rows.at
    dat = post.options.get("points", "inline") == "dat"
    fields = None if dat else _e6pos_fields(post, rows)
    zones = rows.zones
    fine = zones == 0.0
    before = np.full(n, "", dtype=np.str_)

    def add(where: NDArray[np.intp], texts: NDArray[np.str_]) -> None:
        nonlocal before
        if where.size:
            longer = np.strings.add(np.strings.add(before[where], texts), "\n")
            before = before.astype(np.result_type(before.dtype, longer.dtype))
            before[where] = longer

    node = rows.node
    changed = np.flatnonzero(rows.new_linear_speed)
    if changed.size:
        at_changed = lambda j: at(int(changed[j]))  # noqa: E731
        same = np.ones(changed.size)
        vel = post.number_texts("vel_cp", rows.speeds[changed], at_changed)
        add(changed, np.strings.add("$VEL.CP = ", vel))
        if node.angular is not None:
            ori = post.number_texts("vel_ori", same * math.degrees(node.angular), at_changed)
            ori1 = np.strings.add(np.strings.add("$VEL.ORI1 = ", ori), "\n$VEL.ORI2 = ")
            add(changed, np.strings.add(ori1, ori))
        if node.acceleration is not None:
            acc = post.number_texts("acc_cp", same * node.acceleration, at_changed)
            add(changed, np.strings.add("$ACC.CP = ", acc))
        if node.angular_acceleration is not None:
            value = math.degrees(node.angular_acceleration)
            acc_ori = post.number_texts("acc_ori", same * value, at_changed)
            add(changed, np.strings.add("$ACC.ORI1 = ", acc_ori))
    blended = np.flatnonzero(~fine)
    if blended.size:
        radii = zones[blended]
        new = np.empty(blended.size, dtype=bool)
        new[0] = modal.changed("cdis", float(radii[0]))
        new[1:] = radii[1:] != radii[:-1]
        modal.changed("cdis", float(radii[-1]))
        where = blended[new]
        cdis = post.number_texts("cdis", zones[where] * 1000, lambda j: at(int(where[j])))
        add(where, np.strings.add("$APO.CDIS = ", cdis))
    if arcs_written and modal.changed("ori_type", "VAR"):
        add(np.zeros(1, dtype=np.intp), np.array(["$ORI_TYPE = #VAR"]))
    head = _head_lines(post, rows)
    post.current_step = rows
    heads = np.strings.add(before, "LIN ")
    if fields is None:
        ends = np.where(fine, "", " C_DIS").tolist()
        names = zip(heads.tolist(), rows.names, ends, strict=True)
        lines = [f"{start}{name}{end}" for start, name, end in names]
    else:
        ends = np.where(fine, "}", "} C_DIS").tolist()
        lines = _e6pos_lines(fields, np.strings.add(heads, "{").tolist(), ends)
    return "\n".join([*head, *lines])


def _head_lines(post: Post, rows: RowColumns) -> list[str]:
    """``$BASE`` / ``$TOOL`` before the first row, where they change."""
    if not (rows.new_frame or rows.new_tool):
        return []
    mode = str(post.options.get("frames", "inline"))
    step = rows.at(0)
    post.current_step = step
    out = []
    if step.new_frame:
        out.append(f"$BASE = {krl_base(post, step, mode)} ; {step.frame_name}")
    if step.new_tool:
        out.append(f"$TOOL = {krl_tool(post, step, mode)} ; {step.tool_name}")
    return out


def _is_identity(pose: ArrayLike) -> bool:
    return bool(np.allclose(pose, np.eye(4), rtol=0.0, atol=1e-12))


def _index(step: PostStep, item: Any, size: int, what: str) -> int:
    number = item.number
    if number is None or not 1 <= number <= size:
        raise PostError(
            f"{what} {item.name!r} needs a number 1..{size} for {what.upper()}_DATA "
            f"(it has {number})",
            step.instruction.span,
            hint="give it a number in the station, or use the post option frames: inline",
        )
    return int(number)


FILTERS: Mapping[str, Filter] = {
    **Post.FILTERS,
    "krl_frame": krl_frame,
    "krl_axis": krl_axis,
    "krl_e6pos": krl_e6pos,
    "krl_point": krl_point,
    "krl_point_type": krl_point_type,
    "krl_tool": krl_tool,
    "krl_base": krl_base,
    "krl_percent": krl_percent,
    "krl_arc_types": krl_arc_types,
    "krl_ca": krl_ca,
    "krl_rows": krl_rows,
    "krl_rows_dat": krl_rows_dat,
    "krl_expr": lambda post, expr: krl_expr(expr),
    "krl_decl": lambda post, step: krl_decl(step),
    "krl_declaration": lambda post, step: krl_declaration(step),
    "krl_declarations": lambda post, steps: krl_declarations(steps),
    "krl_type_definition": lambda post, step: krl_type_definition(step),
    "krl_event": lambda post, node: krl_event(node),
    "krl_routine_head": lambda post, routine: krl_routine_head(routine),
    "krl_io": lambda post, node, io: krl_io(node, io),
    "krl_program_head": lambda post, program: krl_program_head(
        program["name"],
        program["params"],
        program["returns"],
        program["returns_dims"],
        program["exported"] and program["language"] == "krl",
    ),
    "krl_routine_end": lambda post, routine: krl_routine_end(routine),
    "krl_param_decl": lambda post, param: krl_param_decl(param),
    "krl_call": lambda post, call: krl_call(call),
    "krl_return": lambda post, node: krl_return(node),
    "krl_approximation": lambda post, move: krl_approximation(move),
}


class KukaPost(Post):
    """KUKA KR C4 (KSS 8) KRL; see the module docstring."""

    NAME = "kuka"
    VENDOR = "kuka"
    LANGUAGE = "KRL"
    VERBATIM = "krl"
    WRITES_FLOW = True
    WRITES_ROUTINES = True
    KINDS: ClassVar[frozenset[str]] = Post.KINDS | EVENT_KINDS | {"runtime_move"}
    RUNTIME_RELATIVE = frozenset(RUNTIME_RELATIVE)  # KRL's own forms (_REL, #TOOL, partial)
    NAME_RULE = NAME_RULE
    IO_RANGE = (1, 4096)
    CALL_ARGUMENTS = ArgumentRule(
        one_of(
            NUMBER,
            double_quoted(),
            IDENTIFIER,
            "#" + IDENTIFIER,
            r"\$" + IDENTIFIER,
            # a whole array or an element (P00(#CHK_HOME, #PGNO_GET, DMY[], 0) in every cell.src;
            # PULSE($OUT[PGNO_REQ], TRUE, 0.2)): names, numbers and commas only inside
            r"\$?" + IDENTIFIER + r"\[[A-Za-z0-9_$,.+\- ]*\]",
            # a component (SWRITE(..., $DATE.HOUR), lfPos.X, aPts[2].Z): names, dots and an
            # element's index only
            r"\$?" + IDENTIFIER + r"(?:\[[A-Za-z0-9_$,.+\- ]*\])?(?:\." + IDENTIFIER + r")+",
            # an aggregate for a STRUC parameter (DrillHole({rX 810, rY 67, rZ 0})), one
            # nested level: KRL takes it as it stands. No ';' (a comment) outside its strings
            AGGREGATE,
        ),
        'numbers, "strings", names, #ENUM values, $ variables, array names and elements '
        "(NAME[], NAME[1,k]), components (NAME.X, $DATE.HOUR), aggregates ({X 1, Y 2})",
    )
    ACCELERATIONS: ClassVar[frozenset[str]] = frozenset(
        {"linear_acceleration", "angular_acceleration"}
    )
    NUMBERS: ClassVar[Mapping[str, NumberFormat]] = NUMBERS
    FILTERS: ClassVar[Mapping[str, Filter]] = FILTERS
    ARC_ORIENTATIONS = frozenset(ARC_TYPES) - {ArcOrientation.WRIST}
    ARC_ANGLE = True
    ROWS = True
    COLUMNS = True
    STREAMS = True

    def comment_node_lines(self, comment: Any) -> tuple[str, ...]:
        """A pendant fold line (``fold``) as it was read: its whole text, written after a ``;``
        with no blank (``;FOLD PTP P1 ...;%{PE}...``, ``;ENDFOLD``), so that the pendant shows
        the fold again; any other comment as every post writes it."""
        if comment.fold is None:
            return super().comment_node_lines(comment)
        lines = self.comment_lines(comment.text)
        return self._source_lines(lines) if comment.from_source else lines

    def step_columns(self, robot: Any, joints: Any) -> Mapping[str, Any]:
        """:meth:`step_values` as arrays (N,)."""
        q = np.asarray(joints, dtype=np.float64)
        try:
            status, turn = status_turn(robot, q)
        except (TypeError, ValueError) as exc:
            raise PostError(f"the KRL post cannot describe robot {robot.name!r}: {exc}") from exc
        limits = robot.limits
        ambiguous = turn_ambiguous(q, limits.lower, limits.upper)
        return {"status": status, "turn": turn, "turn_ambiguous": ambiguous}

    def check_rows(self, block: PathBlock, compiled: CompiledProgram) -> list[Diagnostic]:
        """Nothing: :meth:`check_instruction` checks joint moves only."""
        return []

    def step_values(self, robot: Any, joints: Any) -> list[Mapping[str, Any]]:
        """Status and Turn of each motion's planned joints (N, 6) rad, and whether Turn cannot
        select them within ``robot``'s joint limits (:func:`olp.vendors.kuka.turn_ambiguous`)."""
        columns = self.step_columns(robot, joints)
        status, turn, ambiguous = (columns[k] for k in ("status", "turn", "turn_ambiguous"))
        rows = zip(status.tolist(), turn.tolist(), ambiguous.tolist(), strict=True)
        return [{"status": int(s), "turn": int(t), "turn_ambiguous": bool(a)} for s, t, a in rows]

    def check_instruction(self, step: Step, compiled: CompiledProgram) -> list[Diagnostic]:
        """* ``zone_dropped`` (warning): without the option ``ptp_approximation`` (a
          ``$APO.CPTP`` percentage), joint moves with a zone are written as exact stops: KRL
          approximates PTP with ``C_PTP`` and ``$APO.CPTP`` in percent of an axis-specific
          distance, which a TCP distance zone does not translate to (olp's estimate blends
          the corner, :mod:`olp.passes.timing.ptp_blend`: the program written is slower).
        * ``joint_speed`` (error): a joint speed or acceleration below 1 %; (warning) one that
          is not a whole percent, written rounded down (:func:`krl_percent`).
        * ``ptp_axis_values`` (warning): a PTP to a Cartesian target written as axis values,
          because Turn cannot tell two turns of an axis apart on this robot."""
        ins: Any = step.instruction
        if ins.kind == "runtime_move":
            return _runtime_checks(step.index, ins, self.options)
        if ins.kind != "joint" or step.skipped:
            return []
        return _joint_checks(step.index, ins, self.options) + _ambiguity(
            compiled.station.robot, step
        )

    def check_program(self, compiled: CompiledProgram) -> list[Diagnostic]:
        """* ``flow`` (error): a name or text of a control-flow statement or condition that
        KRL cannot hold (:func:`olp.posts.kuka_flow.flow_problem`).
        * ``module_data`` (error): module data or another module's names in a program, and a
          template folder that does not declare ``module_data: true`` (a copy made before
          olp placed declarations by scope would declare them all in the ``.src``)."""
        found = []
        program = compiled.program
        nodes = [*leaves_and_blocks(program.instructions), *flow_nodes_of_routines(program)]
        seen = set()
        for node in nodes:  # a routine's nodes are also in each of its expansions: once each
            if isinstance(node, FLOW_TYPES) and (problem := flow_problem(node)) is not None:
                message = f"{node.kind.replace('_', ' ')} cannot be written in KRL: {problem}"
                if (message, node.span) not in seen:
                    seen.add((message, node.span))
                    found.append(Diagnostic("error", "flow", message, node.span))
        head = Routine(
            name=program.name,
            params=program.params,
            returns=program.returns,
            returns_dims=program.returns_dims,
        )
        if (program.params or head.is_function) and (problem := routine_problem(head)):
            message = f"program {program.name} cannot be written in KRL: {problem}"
            span = program.params[0].span if program.params else None
            found.append(Diagnostic("error", "flow", message, span))
        for routine in program.routines:
            if (problem := routine_problem(routine)) is not None:
                message = f"routine {routine.name} cannot be written in KRL: {problem}"
                found.append(Diagnostic("error", "flow", message, routine.span))
        scoped = [
            n
            for n in leaves_and_blocks(compiled.program.instructions)
            if isinstance(n, Declare) and n.scope != "routine"
        ]
        if scoped and not self.manifest.module_data:
            message = (
                f"{scoped[0].name} is {scoped[0].scope} data, and the template folder "
                f"{self.manifest.folder.name} does not declare module_data: true (a copy made "
                "before olp wrote module data into the .dat): copy the bundled templates' "
                "declaration lines and declare it"
            )
            found.append(Diagnostic("error", "module_data", message, scoped[0].span))
        return found


def _runtime_checks(index: int, ins: Any, options: Mapping[str, Any]) -> list[Diagnostic]:
    """A motion to a run-time target is written back as ``PTP|LIN|CIRC <expression>``
    (:func:`~olp.posts.kuka_flow.krl_expr`; ``PTP_REL|LIN_REL|CIRC_REL <expression>``, with
    ``#TOOL`` where the offsets are the tool's, where :attr:`olp.ir.RuntimeMove.relative` says
    so): every name in it must be a KRL name (``runtime_target``, error); a PTP is checked like
    any (:func:`_joint_checks`)."""
    out = []
    for expr in (ins.target, ins.via):
        problem = None if expr is None else flow_expr_problem(expr)
        if problem is not None:
            message = f"the run-time target cannot be written in KRL: {problem}"
            out.append(Diagnostic("error", "runtime_target", message, ins.span, index))
    return out + (_joint_checks(index, ins, options) if ins.motion == "joint" else [])


def _ambiguity(robot: Any, step: Step) -> list[Diagnostic]:
    ins: Any = step.instruction
    if step.joints is None or not isinstance(ins.target, CartesianTarget):
        return []
    if not turn_ambiguous(step.joints, robot.limits.lower, robot.limits.upper):
        return []
    message = (
        "PTP written with axis values: Status/Turn cannot select the planned joints on this "
        "robot (an axis has two turns of the same sign within its limits)"
    )
    return [Diagnostic("warning", "ptp_axis_values", message, ins.span, step.index)]


def _joint_checks(index: int, ins: Any, options: Mapping[str, Any]) -> list[Diagnostic]:
    out = []
    if not ins.zone.is_fine and not options.get("ptp_approximation"):
        out.append(
            Diagnostic(
                "warning",
                "zone_dropped",
                f"PTP with a {ins.zone.radius * 1000:.1f} mm zone is written as an exact stop "
                "(the cycle time estimate blends it)",
                ins.span,
                index,
            )
        )
    for what, fraction in (
        ("speed", ins.speed.joint),
        ("acceleration", ins.speed.joint_acceleration),
    ):
        percent = fraction * 100.0
        if whole_percent(fraction) < VEL_AXIS_MIN_PERCENT:
            message = (
                f"joint {what} {percent:.6g} % is below KRL's smallest $VEL_AXIS/$ACC_AXIS "
                f"value, {VEL_AXIS_MIN_PERCENT} %"
            )
            out.append(Diagnostic("error", "joint_speed", message, ins.span, index))
        elif abs(percent - whole_percent(fraction)) > 1e-6:
            written = whole_percent(fraction)
            message = f"joint {what} {percent:.2f} % written as {written} % (KRL: whole percents)"
            out.append(Diagnostic("warning", "joint_speed", message, ins.span, index))
    return out
