"""The RAPID post (ABB IRC5, RobotWare 6): one program module ``name.mod``.

Conventions shared with frontends (quaternions, confdata, the flange) live in
:mod:`olp.vendors.abb`; this module is how the post spells them. Pinned by
``tests/posts/test_abb.py`` (every module it produces passes the independent ``rapidchecker``),
the cross-post table and the golden files ``tests/golden/abb/``. RAPID reference manual
(instructions and data types) as summarised in the project's vendor notes and as recalled, with
the confidence given:

* Module: ``MODULE name`` ... ``ENDMODULE``, data before routines, ``PROC main()`` the entry
  (program modules); two-space indentation and upper-case keywords as RobotStudio writes them;
  CRLF (RobotStudio's files; RAPID reads any line ending). High confidence.
* Identifiers: at most 32 characters, a letter first, then letters, digits and ``_``; RAPID's
  reserved words are not allowed (RAPID overview manual; the reserved-word list is from memory
  of that manual: medium confidence).
* Data: ``PERS tooldata`` / ``PERS wobjdata`` (a move's tool and work object must be persistent,
  high confidence); targets, custom speed and zone data ``LOCAL CONST`` so that a part module's
  names never clash with another module's (medium confidence on local shadowing global names).
  ``tool0`` and ``wobj0`` are the predefined no-tool and world (high confidence).
* Predefined speeddata ``v5 .. v7000`` (:data:`PREDEFINED_SPEEDS`, each ``[v, 500, 5000,
  1000]``) and zonedata ``z0 .. z200`` (:data:`PREDEFINED_ZONES`): medium-high confidence.
* Moves: ``MoveAbsJ jointtarget\\NoEOffs, speed, zone, tool;`` for joint targets, ``MoveJ`` /
  ``MoveL`` / ``MoveC via, to`` with robtargets and ``\\WObj:=`` (left out for ``wobj0``).
  ``MoveC`` interpolates the tool orientation from the start to the ``ToPoint`` and does not
  reach the ``CirPoint``'s (RAPID reference, ``MoveC``, as remembered: medium confidence, not
  found in a stored source): only :attr:`~olp.ir.ArcOrientation.INTERPOLATE` is written, no
  circular angle (the base post's ``arc_orientation`` / ``arc_angle`` errors).
  ``ConfJ \\On`` / ``ConfL \\On`` make the controller take the written confdata. Joint moves are
  limited by the speeddata's TCP speed: RAPID has no joint speed fraction (warned).
* Motions to run-time targets (:class:`~olp.ir.RuntimeMove`): ``MoveL`` / ``MoveJ`` /
  ``MoveC via, to`` to a ``robtarget`` variable (or an element of an array of them, ``xPath{i}``)
  the program declares, ``MoveAbsJ ...\\NoEOffs`` to a ``jointtarget`` one, with the same
  speed, zone, tool and ``\\WObj`` arguments as any move (RAPID reference, MoveL: ``MoveL
  ToPoint, Speed, Zone, Tool [\\WObj]``, ToPoint a robtarget "defined as a named position";
  as recalled, medium confidence; that an array element may stand there is unverified against
  a stored manual: ``rapidchecker`` accepts ``MoveL xPath{i}, ...`` but no index with an
  operator, ``xPath{i + 1}``). Anything else is an error on the motion
  (:mod:`olp.posts.runtime`).
* ``Speed.linear_acceleration`` (m/s²) as ``PathAccLim TRUE \\AccMax:=a, TRUE \\DecelMax:=a;``
  before the path move where it changes, and ``PathAccLim FALSE, FALSE;`` where it is unset
  again or before a joint move (olp's estimate limits only path moves with it). PathAccLim
  limits the TCP's acceleration and deceleration *along the path* in m/s², at least 0.1 m/s²
  (RAPID reference, PathAccLim, as summarised in a public RAPID tutorial: medium confidence).
  ``AccSet Acc, Ramp`` (percent of an unpublished maximum) is not written: a value in m/s²
  cannot be mapped to it honestly. The orientation acceleration has no RAPID counterpart
  (the base post warns).
* ``SetDO signal, 0|1;``, ``WaitDI signal, 0|1;`` (I/O by configured signal name:
  :func:`rapid_signal`), ``WaitTime \\InPos, t;`` (the dwell starts once the robot stands
  still, like KRL's ``WAIT SEC``), ``Name args;`` procedure calls, ``!`` comments.
* Numbers: RAPID's ``num`` is an IEEE 754 single-precision float (ABB, "Basic characteristics
  RAPID": "the value must be in the range specified by the ANSI IEEE 754-1985 standard (single
  precision)"; medium-high confidence): every written value must be held by one to the
  resolution of :data:`NUMBERS`.
* Call arguments: numbers, names, and ``"strings"`` of at most 80 characters without ``"`` or
  ``\\`` (RAPID strings hold 80 characters, medium confidence; a backslash starts a character
  code).
* Control flow and data (:mod:`olp.ir_flow`): :mod:`olp.posts.rapid_flow`, with its sources.
  A template folder writes them only if its ``post.yaml`` says ``flow: true`` (the bundled one
  does): a folder copied before would write every block's body unconditionally, so a program
  with control flow stops on such a folder with an error (``control_flow``).
* Work objects are given in the controller's world frame, which on a delivered single-robot
  controller is the robot's base frame (post manifest ``frames_in: robot_base``).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp import ir
from olp.compiled import PathBlock, items_of
from olp.diagnostics import Diagnostic
from olp.errors import PostError
from olp.ir_flow import leaves_and_blocks
from olp.posts.base import Filter, Post
from olp.posts.flow_text import (
    FLOW_STEP_KINDS,
    FlowProblem,
    Symbols,
    flow_lines_filter,
    flow_pad_filter,
    flow_problems,
    jump_problems,
    uncalled_bodies,
    undeclared_names,
)
from olp.posts.numbers import NumberFormat, Storage
from olp.posts.rapid_flow import RapidWriter, counter_problems, reference_problems
from olp.posts.rows import number_column
from olp.posts.runtime import pose_kind, program_nodes, targets
from olp.posts.sandbox import SafeText
from olp.posts.text import IDENTIFIER, NUMBER, ArgumentRule, NameRule, one_of
from olp.posts.view import RowColumns
from olp.vendors.abb import confdata, normalised_rounded, pose_to_robtarget

if TYPE_CHECKING:
    from olp.compiled import CompiledProgram, Step
    from olp.ir import Tool
    from olp.posts.rows import PostRows
    from olp.posts.view import Modal, PostFrame, PostStep, PostTool
    from olp.span import SourceSpan

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]

QUATERNION_DECIMALS = 9
"""Quaternion components, as RobotStudio writes them; a 1e-9 component error is ~2e-9 rad."""
EXTERNAL_AXIS_UNUSED = "9E+09"
"""An unused external axis in robtarget and jointtarget."""

MAX_NAME_LENGTH = 32
"""RAPID identifiers: at most 32 characters."""

_RESERVED = """
ALIAS AND BACKWARD CASE CONNECT CONST DEFAULT DIV DO ELSE ELSEIF ENDFOR ENDFUNC ENDIF
ENDMODULE ENDPROC ENDRECORD ENDTEST ENDTRAP ENDWHILE ERROR EXIT FALSE FOR FROM FUNC GOTO
IF INOUT LOCAL MOD MODULE NOSTEPIN NOT NOVIEW OR PERS PROC RAISE READONLY RECORD RETRY
RETURN STEP SYSMODULE TEST THEN TO TRAP TRUE TRYNEXT UNDO VAR VIEWONLY WHILE WITH XOR
"""
RESERVED_WORDS = frozenset(_RESERVED.split())
"""RAPID reserved words (case-insensitive); from the RAPID overview manual, medium confidence."""

NAME_RULE = NameRule(max_length=MAX_NAME_LENGTH, reserved=RESERVED_WORDS)

NULL_TOOL_NAME = "tool0"
"""The predefined tool: TCP at the flange (tool0)."""
NULL_FRAME_NAME = "wobj0"
"""The predefined work object: the world frame (wobj0)."""

_SPEEDS_MM_S = """
5 10 20 30 40 50 60 80 100 150 200 300 400 500 600 800 1000 1500 2000 2500 3000 4000 5000 6000
7000
"""
PREDEFINED_SPEEDS = {float(v): f"v{v}" for v in _SPEEDS_MM_S.split()}
"""Predefined speeddata by TCP speed (mm/s). Each is ``[v_tcp, 500, 5000, 1000]``."""
SPEED_DEFAULTS = (500.0, 5000.0, 1000.0)
"""``v_ori`` (deg/s), ``v_leax`` (mm/s), ``v_reax`` (deg/s) of the predefined speeddata; olp's
custom speeddata use them where the program says nothing (no orientation speed limit)."""

PREDEFINED_ZONES = {
    0.3: "z0",
    **{float(r): f"z{r}" for r in (1, 5, 10, 15, 20, 30, 40, 50, 60, 80, 100, 150, 200)},
}
"""Predefined zonedata by TCP zone radius ``pzone_tcp`` (mm); ``fine`` is the exact stop."""

PREDEFINED_NAMES = frozenset(
    {"tool0", "wobj0", "load0", "fine", "vmax", *PREDEFINED_SPEEDS.values()}
    | set(PREDEFINED_ZONES.values())
)
"""Names the controller defines already: generated data never take them."""

TOOL_MASS_PLACEHOLDER = 0.001
"""kg, tool0's load mass: written when the station gives no mass (with a warning)."""

_NUM: Storage = "real32"

NUMBERS: Mapping[str, NumberFormat] = {
    **Post.NUMBERS,
    "position": NumberFormat("position", "mm", 3, storage=_NUM, resolution=0.01),
    "quaternion": NumberFormat(
        "quaternion component", "", QUATERNION_DECIMALS, -1.0, 1.0, storage=_NUM, resolution=1e-6
    ),
    "axis": NumberFormat("axis value", "deg", 5, storage=_NUM, resolution=0.001),
    "speed": NumberFormat(
        "speed", "mm/s or deg/s", 3, low=0.0, low_open=True, storage=_NUM, compact=True
    ),
    "zone": NumberFormat("zone size", "mm or deg", 3, low=0.0, storage=_NUM, compact=True),
    "mass": NumberFormat("tool mass", "kg", 3, low=0.0, low_open=True, storage=_NUM, compact=True),
    "wait": NumberFormat("dwell WaitTime", "s", 3, low=0.0, storage=_NUM, resolution=0.01),
    "path_acc": NumberFormat("path acceleration PathAccLim", "m/s²", 3, low=0.1, storage=_NUM),
}
"""How the RAPID post writes each quantity (printed units)."""


# --------------------------------------------------------------------------------------------
# Spelling


def rapid_pose(post: Post, pose: ArrayLike) -> str:
    """``[[x,y,z],[q1,q2,q3,q4]]`` (mm, unit quaternion w first) from a pose (4, 4) in metres."""
    trans, rot = pose_to_robtarget(pose)
    quat = normalised_rounded(rot, QUATERNION_DECIMALS)
    xyz = ",".join(post.number("position", v) for v in trans)
    return f"[[{xyz}],[{','.join(post.number('quaternion', v) for v in quat)}]]"


def rapid_confdata(conf: ArrayLike) -> str:
    """``[cf1,cf4,cf6,cfx]`` from four integers."""
    return "[" + ",".join(str(int(v)) for v in np.asarray(conf)) + "]"


def rapid_robtarget(post: Post, pose: ArrayLike, conf: ArrayLike) -> str:
    """A robtarget value: pose (4, 4) in metres, confdata ``[cf1, cf4, cf6, cfx]``, no external
    axes."""
    extax = ",".join([EXTERNAL_AXIS_UNUSED] * 6)
    return f"[{rapid_pose(post, pose)[1:-1]},{rapid_confdata(conf)},[{extax}]]"


def rapid_jointtarget(post: Post, joints: ArrayLike) -> str:
    """A jointtarget value ``[[j1,...,j6],[9E+09,...]]`` from controller joints (6,) in rad."""
    deg = np.degrees(np.asarray(joints, dtype=np.float64))
    extax = ",".join([EXTERNAL_AXIS_UNUSED] * 6)
    return f"[[{','.join(post.number('axis', v) for v in deg)}],[{extax}]]"


def speed_name(post: Post, speed: Any) -> str:
    """The speeddata name of an :class:`olp.ir.Speed`: a predefined ``v100`` when the TCP speed
    is one of :data:`PREDEFINED_SPEEDS` and no orientation limit is set, else a custom name
    ``v21_17`` (mm/s, ``_`` for the point) or ``v100_o30`` (with ``v_ori`` 30 deg/s)."""
    text = post.number("speed", float(speed.linear) * 1000.0)
    if speed.angular is None:
        return speed_label(text, None)
    return speed_label(text, post.number("speed", math.degrees(speed.angular)))


def speed_label(text: str, ori: str | None) -> str:
    """:func:`speed_name` from the TCP speed as written (mm/s) and the orientation speed as
    written (deg/s, None: no limit)."""
    if ori is None:
        predefined = PREDEFINED_SPEEDS.get(float(text)) if text != "?" else None
        return predefined or "v" + text.replace(".", "_")
    return f"v{text.replace('.', '_')}_o{ori.replace('.', '_')}"


def speeddata(post: Post, speed: Any) -> str:
    """``[v_tcp, v_ori, v_leax, v_reax]`` of an :class:`olp.ir.Speed` (mm/s, deg/s)."""
    values = speeddata_values(float(speed.linear), speed.angular)[0].tolist()
    return "[" + ",".join(post.number("speed", v) for v in values) + "]"


def speeddata_values(linear: ArrayLike, angular: float | None) -> FloatArray:
    """``[v_tcp, v_ori, v_leax, v_reax]`` (n, 4) (mm/s, deg/s) of path speeds (n,) m/s with
    the orientation speed limit ``angular`` rad/s (None: :data:`SPEED_DEFAULTS`)."""
    v = np.asarray(linear, dtype=np.float64).reshape(-1)
    v_ori = SPEED_DEFAULTS[0] if angular is None else math.degrees(angular)
    out = np.empty((v.size, 4))
    out[:, 0] = v * 1000.0
    out[:, 1:] = [v_ori, *SPEED_DEFAULTS[1:]]
    return out


def zone_name(post: Post, zone: Any) -> str:
    """The zonedata name of an :class:`olp.ir.Zone`: ``fine``, a predefined ``z10``, or a custom
    ``z12_5`` (radius in mm)."""
    if zone.is_fine:
        return "fine"
    return zone_label(post.number("zone", float(zone.radius) * 1000.0))


def zone_label(text: str) -> str:
    """:func:`zone_name` of a zone that is not fine, from its radius as written (mm)."""
    predefined = PREDEFINED_ZONES.get(float(text)) if text != "?" else None
    return predefined or "z" + text.replace(".", "_")


def zonedata(post: Post, zone: Any) -> str:
    """A custom zonedata ``[FALSE, r, 1.5r, 1.5r, 0.15r, 1.5r, 0.15r]`` for a radius r (mm):
    pzone_tcp, pzone_ori, pzone_eax (mm), zone_ori (deg), zone_leax (mm), zone_reax (deg).
    The ratios are those of the predefined z10 .. z200 (olp's choice for other radii)."""
    values = zonedata_values(float(zone.radius))[0].tolist()
    return "[FALSE," + ",".join(post.number("zone", v) for v in values) + "]"


def zonedata_values(radius: ArrayLike) -> FloatArray:
    """The numbers of :func:`zonedata` (n, 6) (mm, deg) of zone radii (n,) m."""
    r = np.asarray(radius, dtype=np.float64).reshape(-1, 1) * 1000.0
    return np.hstack([r, 1.5 * r, 1.5 * r, 0.15 * r, 1.5 * r, 0.15 * r])


def rapid_tooldata(post: Post, tool: PostTool) -> str:
    """A tooldata value ``[TRUE,[[x,y,z],[q]],[mass,[cog],[1,0,0,0],0,0,0]]``: held by the
    robot, TCP in tool0 (mm, quaternion); the load is the station's mass (or
    :data:`TOOL_MASS_PLACEHOLDER`) with the centre of gravity 1 mm along the flange axis, as
    tool0 has it (the station gives none)."""
    mass = post.number("mass", tool.mass if tool.mass else TOOL_MASS_PLACEHOLDER)
    return f"[TRUE,{rapid_pose(post, tool.pose)},[{mass},[0,0,0.001],[1,0,0,0],0,0,0]]"


def rapid_wobjdata(post: Post, frame: PostFrame) -> str:
    """A wobjdata value ``[FALSE,TRUE,"",[[uf],[q]],[[0,0,0],[1,0,0,0]]]``: not held by the
    robot, fixed user frame = the frame's pose in the controller's reference, object frame = the
    user frame."""
    return f'[FALSE,TRUE,"",{rapid_pose(post, frame.pose)},[[0,0,0],[1,0,0,0]]]'


def rapid_signal(post: Post, index: int, pattern: str) -> str:
    """The name of digital signal ``index`` from a pattern such as ``"do{index}"`` (RAPID I/O is
    by signal name, configured on the controller; a post option sets the pattern)."""
    name = str(pattern).format(index=int(index))
    if not NAME_RULE.is_legal(name):
        raise PostError(f"signal name {name!r} (from {pattern!r}) is not a legal RAPID name")
    return name


def rapid_rows_data(post: Post, rows: PostRows | RowColumns) -> SafeText:
    """The robtarget declarations of a run of MoveL (:mod:`olp.posts.rows`), exactly as
    ``module.mod.j2`` writes each (``LOCAL CONST robtarget p12 := [..];``): positions and
    quaternions formatted as columns. Names are legal identifiers and numbers are checked, so
    the lines are :class:`~olp.posts.sandbox.SafeText`."""
    if isinstance(rows, RowColumns):
        return SafeText("\n".join(_robtarget_lines(post, rows)))
    steps = rows.steps
    trans, rot = pose_to_robtarget(rows.poses())
    xyz = post.number_column("position", trans, steps)
    quat = post.number_column("quaternion", normalised_rounded(rot, QUATERNION_DECIMALS), steps)
    extax = ",".join([EXTERNAL_AXIS_UNUSED] * 6)
    lines = []
    for k, step in enumerate(steps):
        p, q = 3 * k, 4 * k
        pose = f"[{xyz[p]},{xyz[p + 1]},{xyz[p + 2]}],[{','.join(quat[q : q + 4])}]"
        conf = rapid_confdata(step.vendor["confdata"])
        lines.append(f"  LOCAL CONST robtarget {step.name} := [{pose},{conf},[{extax}]];")
    return SafeText("\n".join(lines))


def rapid_rows(post: Post, rows: PostRows | RowColumns, modal: Modal | None = None) -> SafeText:
    """The moves of a run of MoveL (:mod:`olp.posts.rows`), exactly as ``module.mod.j2``
    writes each: ``PathAccLim`` where the path acceleration changes (``modal``, the template's
    state; without it, where a set one changes within the run), then
    ``MoveL p12, v100, z10, tool\\WObj:=wobj;`` (speed and zone data names computed once per
    distinct value). A toolpath's rows (:class:`~olp.posts.view.RowColumns`) are written as
    columns, or row by row where one of their speed or zone numbers cannot be written (to
    report it on each row as the templates do)."""
    if isinstance(rows, RowColumns):
        data = RowData.of(post, rows)
        if data is not None:
            return SafeText(_move_lines(post, rows, data, modal))
        return _step_moves(post, [rows.at(k) for k in range(len(rows))], modal, rows)
    return _step_moves(post, rows.steps, modal, rows)


def _step_moves(
    post: Post, steps: Sequence[PostStep], modal: Modal | None, rows: PostRows | RowColumns
) -> SafeText:
    """:func:`rapid_rows` of moves one by one."""
    names: dict[Any, str] = {}
    lines = []
    previous = None
    for step in steps:
        post.current_step = step
        accel = step.speed.linear_acceleration
        if modal.changed("path_acc", accel) if modal is not None else accel not in (None, previous):
            lines.append(path_acc_line(post, accel))
        previous = accel
        speed = names.get(step.speed)
        if speed is None:
            speed = names[step.speed] = speed_name(post, step.speed)
        zone = names.get(step.zone)
        if zone is None:
            zone = names[step.zone] = zone_name(post, step.zone)
        wobj = "" if step.frame_name == "wobj0" else "\\WObj:=" + step.frame_name
        lines.append(f"    MoveL {step.name}, {speed}, {zone}, {step.tool_name}{wobj};")
    post.current_step = rows
    return SafeText("\n".join(lines))


def path_acc_line(post: Post, accel: float | None) -> str:
    """``PathAccLim`` for a path acceleration ``accel`` m/s² (None: the controller's own)."""
    if accel is None:
        return "    PathAccLim FALSE, FALSE;"
    value = post.number("path_acc", accel)
    return f"    PathAccLim TRUE \\AccMax:={value}, TRUE \\DecelMax:={value};"


# --------------------------------------------------------------------------------------------
# A toolpath's rows as columns (:class:`~olp.posts.view.RowColumns`): no step per row


@dataclass(frozen=True, slots=True, eq=False)
class RowData:
    """The speed and zone data of a toolpath's rows, spelled once per distinct value: for each
    distinct speed in order of first use its speeddata name (:func:`speed_name`) and value
    (:func:`speeddata`), ``speed_of`` (n,) the index of each row's; the same for zones
    (:func:`zone_name`, :func:`zonedata`: ``""`` for ``fine``)."""

    speed_names: list[str]
    speed_values: list[str]
    speed_of: IntArray
    zone_names: list[str]
    zone_values: list[str]
    zone_of: IntArray

    @classmethod
    def of(cls, post: Post, rows: RowColumns) -> RowData | None:
        """The data of ``rows``, or None where one of their numbers cannot be written (the
        caller then goes row by row, to report it on each row as the templates do)."""
        angular = rows.node.angular
        speeds, speed_of = first_uses(rows.speeds)
        speed_texts = _checked_texts(post, "speed", speeddata_values(speeds, angular))
        radii, zone_of = first_uses(rows.zones)
        zone_texts = _checked_texts(post, "zone", zonedata_values(radii))
        if speed_texts is None or zone_texts is None:
            return None
        speed_names = [
            speed_label(t[0], None if angular is None else t[1]) for t in speed_texts.tolist()
        ]
        zone_names = [
            "fine" if r == 0.0 else zone_label(t[0])
            for r, t in zip(radii.tolist(), zone_texts.tolist(), strict=True)
        ]
        return cls(
            speed_names,
            ["[" + ",".join(t) + "]" for t in speed_texts.tolist()],
            speed_of,
            zone_names,
            [
                "" if r == 0.0 else "[FALSE," + ",".join(t) + "]"
                for r, t in zip(radii.tolist(), zone_texts.tolist(), strict=True)
            ],
            zone_of,
        )


def first_uses(values: ArrayLike) -> tuple[FloatArray, IntArray]:
    """The distinct values (u,) of ``values`` (n,) in order of first use, and the index (n,) of
    each value among them (``-0.0`` is ``0.0``, as ``==`` has it)."""
    distinct, first, inverse = np.unique(
        np.asarray(values, dtype=np.float64), return_index=True, return_inverse=True
    )
    order = np.argsort(first, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    return distinct[order], rank[inverse.reshape(-1)]


def _checked_texts(post: Post, quantity: str, values: FloatArray) -> NDArray[np.str_] | None:
    """``values`` (u, k) spelled in ``quantity``, or None when one cannot be written."""
    texts, ok = number_column(values, post.NUMBERS[quantity])
    return texts.reshape(values.shape) if ok else None


def _robtarget_lines(post: Post, rows: RowColumns) -> list[str]:
    """:func:`rapid_rows_data` of a toolpath's rows: the numbers spelled and checked as
    columns (a value that cannot be written is an error on its own row)."""
    trans, rot = pose_to_robtarget(rows.poses)
    xyz = post.number_texts("position", trans, rows.at).tolist()
    quaternions = normalised_rounded(rot, QUATERNION_DECIMALS)
    quat = post.number_texts("quaternion", quaternions, rows.at).tolist()
    conf = rows.column("confdata").tolist()
    extax = ",".join([EXTERNAL_AXIS_UNUSED] * 6)
    return [
        f"  LOCAL CONST robtarget {name} := [[{','.join(p)}],[{','.join(q)}],"
        f"[{c[0]},{c[1]},{c[2]},{c[3]}],[{extax}]];"
        for name, p, q, c in zip(rows.names, xyz, quat, conf, strict=True)
    ]


def _move_lines(post: Post, rows: RowColumns, data: RowData, modal: Modal | None) -> str:
    """:func:`rapid_rows` of a toolpath's rows, their speed and zone names from ``data``. The
    rows share one path acceleration: ``PathAccLim`` goes before the first where it changes."""
    post.current_step = rows
    lines = []
    accel = rows.node.acceleration
    if modal.changed("path_acc", accel) if modal is not None else accel is not None:
        lines.append(path_acc_line(post, accel))
    frame = rows.frame_item.name
    wobj = "" if frame == "wobj0" else "\\WObj:=" + frame
    tail = f", {rows.tool_item.name}{wobj};"
    speeds, zones = data.speed_names, data.zone_names
    lines += [
        f"    MoveL {name}, {speeds[s]}, {zones[z]}{tail}"
        for name, s, z in zip(
            rows.names, data.speed_of.tolist(), data.zone_of.tolist(), strict=True
        )
    ]
    return "\n".join(lines)


def _robtarget_filter(post: Post, joints: ArrayLike, robot: Any, pose: ArrayLike) -> str:
    """Template filter: ``joints | rapid_robtarget(robot, pose)``."""
    return rapid_robtarget(post, pose, confdata(robot, joints))


def _confdata_filter(post: Post, joints: ArrayLike, robot: Any) -> str:
    """Template filter: ``joints | rapid_confdata(robot)``."""
    return rapid_confdata(confdata(robot, joints))


def rapid_runtime(post: Post, step: PostStep) -> dict[str, Any]:
    """Template filter ``s | rapid_runtime``: a motion to a run-time target as RAPID names it,
    ``{"target": ..., "via": ..., "joints": bool}``: each a pose variable the program declares
    (:func:`olp.posts.runtime.pose_kind`) spelled by the file's flow writer; ``joints``: the
    target is a ``jointtarget`` (written with ``MoveAbsJ``). What cannot be written is an error
    on the motion (:meth:`AbbPost.check_instruction` reports it before rendering)."""
    writer = getattr(post, "flow", None)
    assert isinstance(writer, RapidWriter)
    ins: Any = step.instruction
    post.current_step = step
    try:
        kind = pose_kind(ins.target, writer.symbols, "RAPID")
        via = "" if ins.via is None else writer.expr(ins.via)
        return {"target": writer.expr(ins.target), "via": via, "joints": kind == "joints"}
    except FlowProblem as exc:
        post.problems.append(Diagnostic("error", "runtime_target", str(exc), ins.span, step.index))
        return {"target": "?", "via": "?", "joints": False}


FILTERS: Mapping[str, Filter] = {
    **Post.FILTERS,
    "rapid_runtime": rapid_runtime,
    "rapid_flow": flow_lines_filter,
    "rapid_routine_head": lambda post, routine: post.flow.routine_head(routine),
    "rapid_routine_end": lambda post, routine: post.flow.routine_end(routine),
    "rapid_locals": lambda post, routine: post.flow.local_lines(routine),
    "rapid_pad": flow_pad_filter,
    "rapid_pose": rapid_pose,
    "rapid_robtarget": _robtarget_filter,
    "rapid_jointtarget": rapid_jointtarget,
    "rapid_confdata": _confdata_filter,
    "rapid_robtarget_value": rapid_robtarget,
    "rapid_tooldata": rapid_tooldata,
    "rapid_wobjdata": rapid_wobjdata,
    "rapid_speed": speed_name,
    "rapid_path_acc": path_acc_line,
    "rapid_zone": zone_name,
    "rapid_signal": rapid_signal,
    "rapid_rows_data": rapid_rows_data,
    "rapid_rows": rapid_rows,
}


class AbbPost(Post):
    """ABB IRC5 RAPID; see the module docstring."""

    NAME = "abb"
    VENDOR = "abb"
    LANGUAGE = "RAPID"
    ROWS = True
    COLUMNS = True
    NAME_RULE = NAME_RULE
    CALL_ARGUMENTS = ArgumentRule(
        one_of(NUMBER, r'"[^"\\\x00-\x1f\x7f-\x9f\u2028\u2029]{0,80}"', IDENTIFIER),
        'numbers, names, "strings" of at most 80 characters without " or \\',
    )
    ACCELERATIONS: ClassVar[frozenset[str]] = frozenset({"linear_acceleration"})
    NUMBERS: ClassVar[Mapping[str, NumberFormat]] = NUMBERS
    FILTERS: ClassVar[Mapping[str, Filter]] = FILTERS
    NULL_TOOL_NAME = NULL_TOOL_NAME
    NULL_FRAME_NAME = NULL_FRAME_NAME
    PREDEFINED_NAMES = PREDEFINED_NAMES
    WRITES_FLOW = True
    WRITES_ROUTINES = True
    PROGRAM_PARAMS = (
        "olp writes a program as the module's entry routine (PROC main, or the post option "
        "entry), which the controller starts without arguments; a module that other modules "
        "call with arguments would be a PROC with parameters (num p, INOUT num q) and no entry "
        "routine, which olp does not write yet"
    )
    PROGRAM_RETURNS = (
        "olp writes a program as the module's entry routine (PROC main, or the post option "
        "entry), which the controller starts and which gives no result; a module that other "
        "modules call for a result would be a FUNC (FUNC bool name(...) ... RETURN ...; "
        "ENDFUNC) and no entry routine, which olp does not write yet"
    )
    KINDS: ClassVar[frozenset[str]] = Post.KINDS | {"runtime_move"}
    STREAMS = True
    STREAM_NEUTRAL_FILTERS = frozenset({"rapid_pad"})
    ONCE_PER_PROGRAM = frozenset({"tool_load"})

    def __init__(self, manifest: Any) -> None:
        super().__init__(manifest)
        self.flow: RapidWriter | None = None
        """The flow writer of the file being rendered (made by :meth:`context_values`)."""

    def writer(self, nodes: Sequence[Any]) -> RapidWriter:
        """A :class:`~olp.posts.rapid_flow.RapidWriter` for a program's statements."""
        signal = str(self.options.get("input_signal", "di{index}"))
        return RapidWriter(Symbols(nodes), NAME_RULE, signal, PREDEFINED_NAMES)

    def reserved_names(self, compiled: CompiledProgram) -> Sequence[str]:
        """The program's variable names and labels (:class:`~olp.posts.flow_text.Symbols`)."""
        nodes = compiled.program.instructions
        labels = [n.name for n in leaves_and_blocks(nodes) if isinstance(n, ir.Label)]
        return [*Symbols(nodes).spelling.values(), *labels]

    def step_values(self, robot: Any, joints: Any) -> list[Mapping[str, Any]]:
        """The confdata ``(cf1, cf4, cf6, cfx)`` of each motion's planned joints (N, 6)."""
        conf = _confdata(robot, joints)
        return [{"confdata": tuple(int(v) for v in row)} for row in conf.tolist()]

    def step_columns(self, robot: Any, joints: Any) -> Mapping[str, Any]:
        """:meth:`step_values` as columns: ``{"confdata": array (N, 4)}`` of ``[cf1, cf4, cf6,
        cfx]`` per row."""
        return {"confdata": _confdata(robot, joints)}

    def context_values(self, steps: Sequence[PostStep | RowColumns]) -> Mapping[str, Any]:
        """The custom speeddata and zonedata one file's motions need, in order of first use:
        ``{"speeds": [{name, value}], "zones": [{name, value}]}`` (a toolpath's rows from
        their columns, :class:`RowData`)."""
        speeds: dict[str, str] = {}
        zones: dict[str, str] = {}
        for step in steps:
            if isinstance(step, RowColumns):
                self._row_data(step, speeds, zones)
            elif step.motion or step.kind == "runtime_move":
                self._motion_data(step, speeds, zones)
        self.current_step = None
        flow = self.flow = self.writer([s.instruction for s in steps if s.kind in FLOW_STEP_KINDS])
        flow.prepare(steps)
        # a routine's parameters and locals come as declare steps without an instruction index
        own = frozenset(id(s.instruction) for s in steps if s.kind == "declare" and s.index < 0)
        return {
            "speeds": [{"name": k, "value": v} for k, v in speeds.items()],
            "zones": [{"name": k, "value": v} for k, v in zones.items()],
            "flow_kinds": FLOW_STEP_KINDS,
            "routine_data": flow.declarations(exported=False, skip=own),
            "module_data": flow.declarations(exported=True),
        }

    def context_rows(self, rows: RowColumns) -> Sequence[int]:
        """The first row of each distinct speed and of each distinct zone of ``rows``: all
        :meth:`context_values` takes of rows is their data in order of first use."""
        first_speeds = np.unique(rows.speeds, return_index=True)[1]
        first_zones = np.unique(rows.zones, return_index=True)[1]
        keep: list[int] = np.union1d(first_speeds, first_zones).tolist()
        return keep

    def _motion_data(self, step: PostStep, speeds: dict[str, str], zones: dict[str, str]) -> None:
        """The custom speeddata and zonedata of one motion, added where new."""
        self.current_step = step
        name = speed_name(self, step.speed)
        if name not in PREDEFINED_NAMES:
            speeds.setdefault(name, speeddata(self, step.speed))
        zname = zone_name(self, step.zone)
        if zname not in PREDEFINED_NAMES:
            zones.setdefault(zname, zonedata(self, step.zone))

    def _row_data(self, rows: RowColumns, speeds: dict[str, str], zones: dict[str, str]) -> None:
        """:meth:`_motion_data` of a toolpath's rows, from their distinct values; row by row
        where a number cannot be written (reported on each row, as the steps would be)."""
        data = RowData.of(self, rows)
        if data is None:
            for k in range(len(rows)):
                self._motion_data(rows.at(k), speeds, zones)
            return
        for name, value in zip(data.speed_names, data.speed_values, strict=True):
            if name not in PREDEFINED_NAMES:
                speeds.setdefault(name, value)
        for name, value in zip(data.zone_names, data.zone_values, strict=True):
            if name not in PREDEFINED_NAMES:
                zones.setdefault(name, value)

    def check_rows(self, block: PathBlock, compiled: CompiledProgram) -> list[Diagnostic]:
        """Nothing: :meth:`check_instruction` checks joint moves and I/O only, and a toolpath's
        rows are linear moves."""
        return []

    def check_instruction(self, step: Step, compiled: CompiledProgram) -> list[Diagnostic]:
        """* ``joint_speed`` (warning): RAPID has no joint speed as a fraction of the axes'
          maximum; MoveJ/MoveAbsJ run limited by the speeddata's TCP and orientation speeds,
          which olp takes from the motion's linear speed (RAPID reference, MoveJ).
        * ``io_name`` (error): an I/O number whose signal name (the options ``output_signal``
          / ``input_signal``) is not a legal RAPID name."""
        ins: Any = step.instruction
        if ins.kind == "runtime_move":
            return self._runtime_target_checks(step, compiled)
        if ins.kind == "joint" and not step.skipped and ins.speed.joint < 1.0:
            return [_joint_speed_warning(self, step.index, ins)]
        if ins.kind in ("set_output", "wait_input"):
            option = "output_signal" if ins.kind == "set_output" else "input_signal"
            pattern = str(self.options.get(option, "{index}"))
            name = pattern.format(index=ins.index)
            if not NAME_RULE.is_legal(name):
                msg = f"signal name {name!r} (option {option} {pattern!r}): not a legal RAPID name"
                return [Diagnostic("error", "io_name", msg, ins.span, step.index)]
        return []

    def _runtime_target_checks(self, step: Step, compiled: CompiledProgram) -> list[Diagnostic]:
        """``runtime_target`` (error): a motion to a run-time target whose target (or via point)
        is not a ``robtarget`` or ``jointtarget`` variable the program declares, or a linear or
        circular move to a ``jointtarget`` (``MoveL``/``MoveC`` take robtargets; RAPID
        reference, MoveL: ``MoveL ToPoint, Speed, Zone, Tool [\\WObj]``, ToPoint of type
        robtarget). A joint move gets the ``joint_speed`` warning as any."""
        ins: Any = step.instruction
        nodes = program_nodes(compiled.program)
        writer = self.writer(nodes)
        found = []
        try:
            kinds = [pose_kind(expr, writer.symbols, "RAPID") for expr in targets(ins)]
            for expr in targets(ins):
                writer.expr(expr)
            if ins.motion != "joint" and "joints" in kinds:
                raise FlowProblem(
                    f"a {ins.motion} move takes a robtarget, and its target is a jointtarget"
                )
        except FlowProblem as exc:
            msg = f"the run-time target cannot be written in RAPID: {exc}"
            found.append(Diagnostic("error", "runtime_target", msg, ins.span, step.index))
        if ins.motion == "joint" and ins.speed.joint < 1.0:
            found.append(_joint_speed_warning(self, step.index, ins))
        return found

    def check_program(self, compiled: CompiledProgram) -> list[Diagnostic]:
        """``tool_load`` (warning, once per tool): the tooldata's load is a placeholder (no
        mass or centre of gravity in the station); ``flow`` (error): a control-flow statement
        or declaration RAPID cannot hold exactly (:mod:`olp.posts.rapid_flow`)."""
        nodes = compiled.program.instructions
        routines = compiled.program.routines
        table = {r.name.casefold(): r for r in routines}
        extra = [*jump_problems(nodes), *counter_problems(nodes), *reference_problems(nodes, table)]
        writer = self.writer(nodes)
        extra += [found for r in routines for found in writer.routine_problems(r, table)]
        undeclared = undeclared_names(nodes, routines, routines_see_main=False)
        statements = [*nodes, *uncalled_bodies(nodes, routines)]
        out: list[Diagnostic] = flow_problems(statements, writer, extra, undeclared)
        loads: set[str] = set()
        for index, span, tool in _motion_tools(compiled):
            if tool is None or tool.pose is None or tool.name in loads:
                continue
            if np.array_equal(tool.pose, np.eye(4)):
                continue
            loads.add(tool.name)
            body = compiled.station.tool_bodies.get(tool.name)
            out.append(_load_warning(index, span, tool.name, body))
        return out


def _confdata(robot: Any, joints: Any) -> IntArray:
    """:func:`olp.vendors.abb.confdata` of joints (N, 6) rad, (N, 4); a robot it cannot
    describe is a PostError."""
    try:
        return confdata(robot, np.asarray(joints, dtype=np.float64))
    except (TypeError, ValueError) as exc:
        raise PostError(f"the RAPID post cannot describe robot {robot.name!r}: {exc}") from exc


def _motion_tools(compiled: CompiledProgram) -> Iterator[tuple[int, SourceSpan, Tool | None]]:
    """Index, source span and tool of each written motion (a toolpath: its first row, as
    its rows share one tool)."""
    for item in items_of(compiled.steps):
        if isinstance(item, PathBlock):
            yield item.start, item.node.row_span(0), item.tool
            continue
        ins: Any = item.instruction
        if ins.kind in ("joint", "linear", "circular") and not item.skipped:
            yield item.index, ins.span, item.tool


def _joint_speed_warning(post: Post, index: int, ins: Any) -> Diagnostic:
    return Diagnostic(
        "warning",
        "joint_speed",
        f"RAPID cannot limit a joint move to {ins.speed.joint * 100:.0f} % of the axis speeds: "
        f"it runs limited by the TCP speed {ins.speed.linear * 1000:g} mm/s instead",
        ins.span,
        index,
        hint="set the linear speed of joint moves to what the robot may reach",
    )


def _load_warning(index: int, span: SourceSpan, name: str, body: Any) -> Diagnostic:
    mass = None if body is None else body.mass
    what = "no mass" if not mass else f"mass {mass:g} kg but no centre of gravity"
    return Diagnostic(
        "warning",
        "tool_load",
        f"tool {name!r}: the station gives {what}; its tooldata load is a placeholder",
        span,
        index,
        hint="identify the load on the controller (LoadIdentify) or enter it before running",
    )
