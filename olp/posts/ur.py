"""The URScript post (Universal Robots CB3 / e-Series): one ``name.script``.

Conventions shared with frontends (rotation vectors, the flange, no configuration bits) live in
:mod:`olp.vendors.ur`; this module is how the post spells them. Pinned by
``tests/posts/test_ur.py``, the cross-post table and the golden files ``tests/golden/ur/``.

* A program is one ``def name():`` ... ``end`` block, body indented by two spaces, ``#``
  comments, LF line endings, file ``name.script`` (project vendor notes: sent as plain text to
  port 30002, which runs the ``def``; medium confidence that nothing else is needed).
* ``movej([q1..q6], a, v, r)``: the planned joints (rad), never a pose (see Configuration).
  ``v`` (rad/s) is the speed of the leading axis (URScript manual, ``movej``); olp writes
  ``Speed.joint`` (a fraction of each axis' maximum) times the *smallest* axis velocity limit of
  the station's robot (:func:`movej_speed`): at 100 % the leading axis may then run at the
  slowest axis' maximum, so no axis exceeds its own. ``a`` (rad/s²) is URScript's documented
  default 1.4 rad/s² times ``Speed.joint_acceleration`` (:func:`movej_acceleration`): UR
  publishes no joint acceleration limits. Both come from
  :func:`olp.vendors.ur.movej_parameters`, which olp's timing of a UR program uses too
  (:mod:`olp.passes.timing.ur`): the estimate is the trapezoid of the values written.
* ``movel(p[...], a, v, r)`` / ``movec(p_via, p_to, a, v, r, mode=0)``: the TCP pose in the
  robot's Base frame: the post's manifest says ``frames_in: robot_base``, so the template's
  ``base_pose`` is the target in ``station base · controller_base`` (for UR arms the kinematic
  base *is* the controller's Base, DH frame 0, see :mod:`olp.kinematics.ur`; the target equals
  forward kinematics of the planned joints, which resolve solved for it), and olp's user frames
  need no counterpart on the controller. ``v`` = ``Speed.linear`` (m/s), ``a`` =
  ``Speed.linear_acceleration`` (m/s², "tool acceleration") where set, else URScript's default
  1.2 m/s². The orientation acceleration has no URScript counterpart (the base post warns).
  ``mode=0`` ("Unconstrained mode. Interpolate
  orientation from current pose to target pose") for :attr:`~olp.ir.ArcOrientation.INTERPOLATE`
  and ``mode=1`` ("Fixed mode. Keep orientation constant relative to the tangent of the circular
  arc") for :attr:`~olp.ir.ArcOrientation.PATH_CONSTANT`; the via pose's rotation is not used
  (URScript manual, ``movec``, SW 10.10; high confidence). Other rules and circular angles are
  errors (:attr:`UrPost.ARC_ORIENTATIONS`).
* Blends at arcs (:meth:`UrPost.check_program`, kind ``arc_blend``): a ``movec`` with ``r > 0``
  followed by another ``movec`` is refused: an arc-to-arc blend is the case a ROS-Industrial
  UR driver changed its blend radii for ("to avoid CIRC_ARC_BLENDING_RADIUS", a controller
  message); which radii the controller accepts there is not documented in any source found, so
  olp writes none (low confidence on the exact rule, high that the case is refused at least for
  some radii). Also refused: a blend sphere at either end of an arc that holds the via point
  (the blend would cut the arc before its defining point; olp's rule, like the overlapping
  blends the controller skips).
* ``r`` (m): the zone radius capped by :mod:`olp.transforms.blend` (neighbouring blends must not
  overlap, ``r = 0`` where the robot stops; project vendor notes); in a program with control
  flow, ``r = 0`` where the next motion lies beyond a block boundary
  (:func:`stop_at_block_boundaries`).
* ``set_tcp(p[...])``: the tool's TCP in the flange frame, before the first motion with it.
* ``set_digital_out(n, b)``, ``get_digital_in(n)`` polled with ``sync()`` for an input wait,
  ``sleep(s)``; output and input numbers 0..9 (e-Series script manual: ``set_digital_out``
  "Deprecated ... integer: [0:9]", ports 8-9 are the tool's; ``set_standard_digital_out`` takes
  0..7; high confidence). The IR's I/O number is written unchanged.
* Calls: ``name(args)``; the function must exist on the controller (e.g. in the installation's
  script). Arguments must be numbers or double-quoted strings.
* Very long scripts fail on the controller (field reports between ~1,000 and 2,500 targets):
  above :data:`MAX_MOTIONS` motions a warning asks for splitting or streaming.
* Numbers: URScript's float width is unverified (believed 64-bit); positions are written to
  1 µm and checked to 10 µm, speeds and accelerations must stay positive once printed, and a
  ``sleep`` above :data:`MAX_SLEEP` s is refused (olp's bound; URScript states none).
* Control flow and data (:mod:`olp.ir_flow`): :mod:`olp.posts.ur_flow`, with its sources. A
  template folder writes them only if its ``post.yaml`` says ``flow: true`` (the bundled one
  does): a folder copied before would write every block's body unconditionally, so a program
  with control flow stops on such a folder with an error (``control_flow``).
* Comments: ``#`` to the end of the line, whitespace collapsed; a comment of several lines
  becomes several ``#`` lines.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from olp import ir
from olp.compiled import PathBlock, StepBlocks, items_of, span_of
from olp.diagnostics import Diagnostic
from olp.ir import ArcOrientation
from olp.ir_flow import bodies
from olp.posts.base import Filter, Post
from olp.posts.flow_text import (
    FLOW_STEP_KINDS,
    Symbols,
    assigned_module_data,
    flow_lines_filter,
    flow_pad_filter,
    flow_problems,
    uncalled_bodies,
    undeclared_names,
)
from olp.posts.numbers import NumberFormat
from olp.posts.rows import PostRows, number_column
from olp.posts.sandbox import SafeText
from olp.posts.stream_transforms import BlendCapWindows
from olp.posts.text import NUMBER, ArgumentRule, CommentRule, NameRule
from olp.posts.ur_flow import UrWriter
from olp.posts.view import RowColumns
from olp.transforms.blend import with_radii
from olp.vendors.ur import (
    MOTION_DECIMALS,
    movej_parameters,
    movel_parameters,
    pose_to_ur,
)

if TYPE_CHECKING:
    from olp.compiled import CompiledProgram, Step
    from olp.posts.view import PostStep
    from olp.span import SourceSpan

_KEYWORDS = """
def end if elif else while for return thread run kill halt break continue pass global local
and or not xor True False
"""
KEYWORDS = frozenset(_KEYWORDS.split())
"""URScript words a program name must not be (Python-like; unverified list)."""

POST_BUILTINS = frozenset(
    ["movej", "movel", "movec", "set_tcp", "set_digital_out", "get_digital_in", "sleep", "sync"]
)
"""URScript functions the post calls: a program of the same name would shadow them."""

NAME_RULE = NameRule(reserved=KEYWORDS | POST_BUILTINS, case_sensitive=True, prefix="p")
"""A legal ``def`` name: ASCII letters, digits and ``_``, a letter first (``p`` is put in front
otherwise); a keyword, or a function the post calls, gets a trailing ``_``."""

MAX_MOTIONS = 1000
"""Motions in one script above which a warning asks for splitting or streaming (field reports of
trouble between ~1,000 and 2,500 targets; low confidence on the exact limit)."""
MAX_SLEEP = 1e6
"""s: the longest ``sleep`` olp writes (olp's bound, about 11.6 days)."""

NUMBERS: Mapping[str, NumberFormat] = {
    **Post.NUMBERS,
    "position": NumberFormat("position", "m", 6, resolution=1e-5),
    "angle": NumberFormat("angle", "rad", 6, resolution=1e-5),
    "speed": NumberFormat("speed", "m/s or rad/s", MOTION_DECIMALS, low=0.0, low_open=True),
    "acceleration": NumberFormat(
        "acceleration", "m/s² or rad/s²", MOTION_DECIMALS, low=0.0, low_open=True
    ),
    "radius": NumberFormat("blend radius", "m", 6, low=0.0),
    "sleep": NumberFormat("sleep", "s", 3, 0.0, MAX_SLEEP),
}
"""How the URScript post writes each quantity."""

_LITERAL = re.compile(NUMBER + r'|"[^"\\\x00-\x1f\x7f-\x9f]*"')


# --------------------------------------------------------------------------------------------
# Spelling


def ur_pose(post: Post, pose: ArrayLike) -> str:
    """``p[x, y, z, rx, ry, rz]`` from a pose (4, 4) in metres."""
    v = pose_to_ur(pose)
    values = [post.number("position", x) for x in v[:3]]
    values += [post.number("angle", x) for x in v[3:]]
    return "p[" + ", ".join(values) + "]"


def ur_joints(post: Post, joints: ArrayLike) -> str:
    """``[q1, ..., q6]`` in rad (the ``movej`` joint target) from controller joints (6,) in rad."""
    return "[" + ", ".join(post.number("angle", x) for x in np.asarray(joints, float)) + "]"


def movej_speed(post: Post, speed: Any, robot: Any) -> str:
    """``v`` of ``movej`` in rad/s (:func:`olp.vendors.ur.movej_parameters`)."""
    v = movej_parameters(speed.joint, speed.joint_acceleration, robot.limits.velocity, False)[1]
    return post.number("speed", v)


def movej_acceleration(post: Post, speed: Any) -> str:
    """``a`` of ``movej`` in rad/s² (:func:`olp.vendors.ur.movej_parameters`; it does not
    depend on the axes' limits)."""
    a = movej_parameters(speed.joint, speed.joint_acceleration, [1.0], False)[0]
    return post.number("acceleration", a)


def movel_acceleration(post: Post, speed: Any) -> str:
    """``a`` of ``movel``/``movec`` in m/s² (:func:`olp.vendors.ur.movel_parameters`)."""
    a = movel_parameters(speed.linear, speed.linear_acceleration, False)[0]
    return post.number("acceleration", a)


def linear_speed(post: Post, speed: Any) -> str:
    """``v`` of ``movel``/``movec`` in m/s (:func:`olp.vendors.ur.movel_parameters`)."""
    v = movel_parameters(speed.linear, speed.linear_acceleration, False)[1]
    return post.number("speed", v)


def radius(post: Post, value: float) -> str:
    """A blend radius in metres (6 decimals)."""
    return post.number("radius", value)


def seconds(post: Post, value: float) -> str:
    """A ``sleep`` time in seconds (3 decimals)."""
    return post.number("sleep", value)


def ur_rows(post: Post, rows: PostRows | RowColumns) -> SafeText:
    """The lines of a run of ``movel`` (:mod:`olp.posts.rows`), exactly as
    ``program.script.j2`` writes each: ``set_tcp`` where the tool changes, then
    ``movel(p[..], a=.., v=.., r=..)`` with the target in the robot's Base frame. Poses, speeds
    and radii are formatted as columns (a toolpath's rows as :class:`RowColumns`: no object per
    row, :func:`_column_lines`); every piece is a checked number, so the lines are
    :class:`~olp.posts.sandbox.SafeText`."""
    if isinstance(rows, RowColumns):
        return SafeText(_column_lines(post, rows))
    steps = rows.steps
    v = pose_to_ur(np.stack([s.base_pose for s in steps]))  # type: ignore[misc]
    xyz = post.number_column("position", v[:, :3], steps)
    rot = post.number_column("angle", v[:, 3:], steps)
    speeds = post.number_column("speed", [s.speed.linear for s in steps], steps)
    radii = post.number_column("radius", [s.zone.radius for s in steps], steps)
    accelerations: dict[Any, str] = {}
    lines: list[str] = []
    for k, step in enumerate(steps):
        post.current_step = step
        if step.new_tool:
            assert step.tool is not None
            lines.append(f"  set_tcp({ur_pose(post, step.tool.pose)})")  # type: ignore[arg-type]
        a = accelerations.get(step.speed)
        if a is None:
            a = accelerations[step.speed] = movel_acceleration(post, step.speed)
        p = 3 * k
        pose = f"p[{xyz[p]}, {xyz[p + 1]}, {xyz[p + 2]}, {rot[p]}, {rot[p + 1]}, {rot[p + 2]}]"
        lines.append(f"  movel({pose}, a={a}, v={speeds[k]}, r={radii[k]})")
    post.current_step = rows
    return SafeText("\n".join(lines))


def _column_lines(post: Post, rows: RowColumns) -> str:
    """:func:`ur_rows` of a toolpath's rows as columns: the targets in the robot's Base frame
    (``frame_pose @ pose``, as the view computes each step's ``base_pose``), ``a`` (one value:
    the block's path acceleration), ``v`` and ``r`` spelled as whole columns; ``set_tcp``
    before the first row where the tool changes. A number that cannot be written is an error
    on its own row, reported in the order the template would report it (row by row)."""
    at = rows.at
    since = len(post.problems)
    head = []
    if rows.new_tool:
        post.current_step = at(0)
        head.append(f"  set_tcp({ur_pose(post, rows.tool_item.pose)})")
    v = pose_to_ur(rows.motions.frame_pose @ rows.poses)
    xyz = post.number_texts("position", v[:, :3], at)
    rot = post.number_texts("angle", v[:, 3:], at)
    accel = movel_parameters(1.0, rows.node.acceleration, False)[0]
    a = _constant_texts(post, "acceleration", accel, len(rows), at)
    speeds = post.number_texts("speed", rows.speeds, at)
    radii = post.number_texts("radius", rows.zones, at)
    post.current_step = rows
    _in_row_order(post, since)
    columns = (xyz[:, 0], xyz[:, 1], xyz[:, 2], rot[:, 0], rot[:, 1], rot[:, 2], speeds, radii)
    lines = [
        f"  movel(p[{x}, {y}, {z}, {rx}, {ry}, {rz}], a={a}, v={s}, r={r})"
        for x, y, z, rx, ry, rz, s, r in zip(*(c.tolist() for c in columns), strict=True)
    ]
    return "\n".join([*head, *lines])


def _constant_texts(
    post: Post, quantity: str, value: float, n: int, at: Callable[[int], PostStep]
) -> str:
    """``value`` spelled once for ``n`` rows; where it cannot be written, the error on every
    row (as the template reports it on each)."""
    texts, ok = number_column(np.array([value]), post.NUMBERS[quantity])
    if ok:
        return str(texts[0])
    return str(post.number_texts(quantity, np.full(n, value), at)[0])


def _in_row_order(post: Post, since: int) -> None:
    """The problems found since ``since`` ordered by instruction (stable: within a row, in the
    order of its line's numbers), as a template writing row by row finds them."""
    found = post.problems[since:]
    found.sort(key=lambda d: -1 if d.index is None else d.index)
    post.problems[since:] = found


def _via_filter(post: Post, step: PostStep) -> str:
    """Template filter: ``s | ur_via``, the ``p[...]`` of a circle's via point in the robot's
    Base frame (the post's ``frames_in: robot_base`` makes ``frame_pose`` relative to it)."""
    return ur_pose(post, np.asarray(step.frame_pose) @ np.asarray(step.via))


def movec_mode(post: Post, step: PostStep) -> str:
    """``mode`` of ``movec``: 0 interpolates start to end, 1 keeps the orientation constant
    relative to the arc's tangent (URScript manual, ``movec``)."""
    ins: Any = step.instruction
    return "1" if ins.orientation is ArcOrientation.PATH_CONSTANT else "0"


def _blends_filter(post: Post, steps: Any, station: Any) -> dict[int, float]:
    """Template filter: ``steps | ur_blend_radii(station)``, instruction index -> capped blend
    radius in m (:func:`olp.transforms.blend.blend_radii`, from the robot's home joints). The
    bundled template writes the zone radius, which :class:`UrPost`'s transform already capped;
    folders made before keep working."""
    from olp.transforms.blend import blend_columns

    items: list[Any] = []
    for s in steps:
        if isinstance(s, RowColumns):
            items.append(s.piece)  # a toolpath's rows, as arrays
        elif isinstance(s, PostRows):
            items.extend(s.steps)
        else:
            items.append(s)
    robot = station.robot
    found = blend_columns(items, robot, robot.home)
    return dict(zip(found.index.tolist(), found.radius.tolist(), strict=True))


FILTERS: Mapping[str, Filter] = {
    **Post.FILTERS,
    "ur_flow": flow_lines_filter,
    "ur_routine_head": lambda post, routine: post.flow.routine_head(routine),
    "ur_local": lambda post, decl: post.flow.local_declaration(decl),
    "ur_pad": flow_pad_filter,
    "ur_pose": ur_pose,
    "ur_joints": ur_joints,
    "ur_via": _via_filter,
    "ur_blend_radii": _blends_filter,
    "ur_movej_v": movej_speed,
    "ur_movej_a": movej_acceleration,
    "ur_movel_v": linear_speed,
    "ur_movel_a": movel_acceleration,
    "ur_radius": radius,
    "ur_seconds": seconds,
    "ur_movec_mode": movec_mode,
    "ur_rows": ur_rows,
}


def cap_blend_radii(
    compiled: CompiledProgram, post: Post
) -> tuple[CompiledProgram, list[Diagnostic]]:
    """The transform :func:`olp.transforms.blend.cap_blends`: neighbouring blends never overlap
    and the robot stops where it must (the controller skips moves whose blends overlap)."""
    from olp.transforms.blend import cap_blends

    capped, found = cap_blends(compiled)
    return capped, list(found)


def stop_at_block_boundaries(
    compiled: CompiledProgram, post: Post
) -> tuple[CompiledProgram, list[Diagnostic]]:
    """The transform for programs with control flow: a motion whose next motion in the text lies
    beyond a block boundary (an ``if``, ``else``, ``end``, a loop's turn, a label, a jump, an
    exit or a return) is written with ``r = 0``, with a warning (``blend_stopped``). Which motion
    follows it is known only at run time, so olp cannot cap its blend against its neighbour's,
    and the controller skips a move whose blend overlaps its neighbour's (project vendor notes,
    as for :func:`cap_blend_radii`); stopping is olp's conservative choice. Idempotent."""
    if not compiled.program.has_flow:
        return compiled, []
    steps = compiled.steps
    ends = [
        (i, radius)
        for i in _motions_before_boundaries(compiled.program.instructions)
        if 0 <= i < len(steps) and (radius := zone_radius(steps, i)) > 0.0
    ]
    if not ends:
        return compiled, []
    index = np.array([i for i, _ in ends], dtype=np.int64)
    stopped = with_radii(compiled, index, np.zeros(index.size))
    return stopped, [_stop_warning(i, radius, span_of(steps, i)) for i, radius in ends]


def zone_radius(steps: Sequence[Step], index: int) -> float:
    """The zone radius (m) of instruction ``index``, without making a toolpath row's step."""
    item = steps.item_at(index) if isinstance(steps, StepBlocks) else steps[index]
    if isinstance(item, PathBlock):
        return float(item.node.zones[index - item.start])
    motion: Any = item.instruction
    return float(motion.zone.radius)


def _stop_warning(index: int, radius: float, span: SourceSpan) -> Diagnostic:
    return Diagnostic(
        "warning",
        "blend_stopped",
        f"blend radius {radius * 1000:.1f} mm written as 0 (the robot stops here): the "
        "next motion is beyond a block boundary, known only at run time, so olp cannot keep "
        "the blends from overlapping (the controller would skip a move); the cycle time per "
        "path times it as a stop too",
        span,
        index,
    )


def _motions_before_boundaries(nodes: Sequence[Any]) -> list[int]:
    """Step indices of the motions whose next motion in the text comes after a block boundary
    (or that are followed by one and no motion)."""
    out: list[int] = []
    previous: int | None = None
    crossed = False
    for token in _flow_tokens(nodes, itertools.count()):
        if token is None:
            crossed = True
            continue
        if previous is not None and crossed:
            out.append(previous)
        previous, crossed = token, False
    if previous is not None and crossed:
        out.append(previous)
    return out


def _flow_tokens(nodes: Sequence[Any], counter: Iterator[int]) -> Iterator[int | None]:
    """The program's motions as their step indices, and None at each block boundary, in the
    order of the text (step indices count the leaves, a toolpath's rows one each)."""
    for node in nodes:
        if isinstance(node, ir.BLOCK_TYPES):
            yield None
            for body in bodies(node):
                yield from _flow_tokens(body, counter)
                yield None
        elif isinstance(node, ir.LinearPath):
            for _ in range(len(node)):
                yield next(counter)
        else:
            index = next(counter)
            if isinstance(node, ir.MOTION_TYPES):
                yield index
            elif isinstance(node, ir.Label | ir.Goto | ir.Exit | ir.Return):
                yield None


class UrPost(Post):
    """Universal Robots URScript; see the module docstring."""

    RUNTIME_REFUSAL = (
        "URScript would name it by a pose variable (movel(p)), and olp's URScript post "
        "declares none: KRL gives a position in mm and degrees with Euler angles, URScript in "
        "metres with a rotation vector, and olp does not convert a variable's value "
        "(olp.posts.ur_flow)"
    )

    NAME = "ur"
    VENDOR = "ur"
    LANGUAGE = "URScript"
    NAME_RULE = NAME_RULE
    COMMENTS = CommentRule(collapse=True)
    ROWS = True
    IO_RANGE = (0, 9)
    CALL_ARGUMENTS = ArgumentRule(_LITERAL, 'numbers and "strings" without " or \\')
    ACCELERATIONS: ClassVar[frozenset[str]] = frozenset({"linear_acceleration"})
    NUMBERS: ClassVar[Mapping[str, NumberFormat]] = NUMBERS
    FILTERS: ClassVar[Mapping[str, Filter]] = FILTERS
    TRANSFORMS = (stop_at_block_boundaries, cap_blend_radii)
    ARC_ORIENTATIONS = frozenset({ArcOrientation.INTERPOLATE, ArcOrientation.PATH_CONSTANT})
    WINDOW_TRANSFORMS = (BlendCapWindows,)
    """Streamed programs have no control flow: ``stop_at_block_boundaries`` leaves them."""
    WRITES_FLOW = True
    COLUMNS = True
    WRITES_ROUTINES = True
    PROGRAM_PARAMS = (
        "olp writes a program as one def that the controller runs when it receives the "
        "script, with no arguments to give; a def with parameters would need a caller the "
        "script does not hold (and URScript passes arguments by value only, so an :OUT "
        "parameter has no equivalent)"
    )
    PROGRAM_RETURNS = (
        "olp writes a program as one def that the controller runs when it receives the "
        "script; its result would go to no caller (a URScript def may return a value, but "
        "only to a caller in the same script, and a module called from other programs has "
        "no equivalent there)"
    )
    STREAMS = True
    STREAM_NEUTRAL_FILTERS = frozenset({"ur_pad"})
    TOTAL_KINDS = frozenset({"program_too_long"})

    def __init__(self, manifest: Any) -> None:
        super().__init__(manifest)
        self.flow: UrWriter | None = None
        """The flow writer of the file being rendered (made by :meth:`context_values`)."""

    def writer(self, nodes: Sequence[Any]) -> UrWriter:
        """A :class:`~olp.posts.ur_flow.UrWriter` for a program's statements."""
        return UrWriter(Symbols(nodes), NAME_RULE, POST_BUILTINS)

    def reserved_names(self, compiled: CompiledProgram) -> Sequence[str]:
        """The program's variable names (:class:`~olp.posts.flow_text.Symbols`)."""
        return list(Symbols(compiled.program.instructions).spelling.values())

    def step_columns(self, robot: Any, joints: Any) -> Mapping[str, Any]:
        """None: URScript has no configuration bits (the pose and the planned joints say all)."""
        return {}

    def check_rows(self, block: PathBlock, compiled: CompiledProgram) -> list[Diagnostic]:
        """Nothing: :meth:`check_instruction` (the base's) finds nothing in a linear move."""
        return []

    def context_values(self, steps: Sequence[PostStep]) -> Mapping[str, Any]:
        """The flow writer of this file (``vendor.flow_kinds``: the steps it writes)."""
        self.flow = self.writer([s.instruction for s in steps if s.kind in FLOW_STEP_KINDS])
        self.flow.prepare(steps)
        return {"flow_kinds": FLOW_STEP_KINDS}

    def check_program(self, compiled: CompiledProgram) -> list[Diagnostic]:
        """``program_too_long`` (warning): more than :data:`MAX_MOTIONS` motions;
        ``arc_blend`` (error): blends at arcs the controller refuses (module docstring);
        ``flow`` (error): a control-flow statement or declaration URScript cannot hold
        exactly (:mod:`olp.posts.ur_flow`); ``module_data`` (warning): module data the program
        assigns, whose value a URScript run does not keep for the next."""
        nodes = compiled.program.instructions
        routines = compiled.program.routines
        own = [n for r in routines for n in (*_param_declarations(r), *r.declarations)]
        writer = self.writer([*own, *nodes])
        extra = [found for r in routines for found in writer.routine_problems(r)]
        undeclared = undeclared_names(nodes, routines, routines_see_main=True)
        statements = [*nodes, *uncalled_bodies(nodes, routines)]
        found = flow_problems(statements, writer, extra, undeclared) + arc_blends(compiled)
        found += [
            Diagnostic(
                "warning",
                "module_data",
                f"{decl.name} is module data, which the source controller keeps from one run "
                "to the next; URScript starts it from its declared value on every run",
                node.span,
            )
            for decl, node in assigned_module_data(nodes)
        ]
        motions = sum(_emitted(item) for item in items_of(compiled.steps))
        return found + self.check_totals(motions)

    def check_totals(self, motions: int) -> list[Diagnostic]:
        """``program_too_long`` (warning) for more than :data:`MAX_MOTIONS` motions."""
        if motions <= MAX_MOTIONS:
            return []
        return [
            Diagnostic(
                "warning",
                "program_too_long",
                f"{motions} motions in one script: UR controllers are reported to fail on "
                f"scripts beyond about {MAX_MOTIONS} targets",
                hint="split the program or stream it to the controller",
            ),
        ]


def _param_declarations(routine: Any) -> list[ir.Declare]:
    """A routine's typed parameters as declarations (their types, for the writer)."""
    return [
        ir.Declare(name=p.name, type_name=p.type_name, dims=p.dims, span=p.span)
        for p in routine.params
        if p.type_name
    ]


def arc_blends(compiled: CompiledProgram) -> list[Diagnostic]:
    """Errors for ``movec`` blends the controller refuses (see the module docstring): an arc
    blended into another arc, and a blend sphere around either end of an arc that holds its via
    point (radii after :func:`cap_blend_radii`). A toolpath's rows are linear: only its last
    row can be an arc's start, and only that row is made into a step."""
    motions = [
        item
        for item in items_of(compiled.steps)
        if _emitted(item) and (isinstance(item, PathBlock) or not item.skipped)
    ]
    out: list[Diagnostic] = []
    for k, step in enumerate(motions):
        if isinstance(step, PathBlock):
            continue
        ins: Any = step.instruction
        if ins.kind != "circular":
            continue
        before = _last_step(motions[k - 1]) if k > 0 else None
        previous: Any = None if before is None else before.instruction
        if previous is not None and previous.kind == "circular" and not previous.zone.is_fine:
            msg = (
                "URScript cannot blend a movec into another movec (the controller refuses such "
                "blends, CIRC_ARC_BLENDING_RADIUS): program a fine stop or a short linear move "
                "between the arcs"
            )
            out.append(Diagnostic("error", "arc_blend", msg, ins.span, step.index))
            continue
        out += _via_in_blend(before, step, compiled.station.robot)
    return out


def _emitted(item: Step | PathBlock) -> int:
    """How many motions ``item`` writes (a toolpath's rows, once resolved: all of them)."""
    if isinstance(item, PathBlock):
        return 0 if item.joints is None else len(item)
    return int(item.joints is not None)


def _last_step(item: Step | PathBlock) -> Step:
    return item.step(len(item) - 1) if isinstance(item, PathBlock) else item


def _via_in_blend(before: Step | None, step: Step, robot: Any) -> list[Diagnostic]:
    """The error of a blend sphere at the start (``before``: the motion before the arc) or end
    of arc ``step`` that holds its via point."""
    ins: Any = step.instruction
    if step.frame is None or step.frame.pose is None:
        return []
    via = (step.frame.pose @ ins.via.pose)[:3, 3]
    ends = [(before, "start")] if before is not None else []
    ends.append((step, "end"))
    for end_step, where in ends:
        radius = end_step.instruction.zone.radius  # type: ignore[union-attr]
        if radius <= 0.0 or end_step.tool is None or end_step.tool.pose is None:
            continue
        tcp = (robot.flange_poses(end_step.joints) @ end_step.tool.pose)[:3, 3]
        if np.linalg.norm(tcp - via) < radius:
            msg = (
                f"the blend radius of {radius * 1000:g} mm at the arc's {where} holds its via "
                "point: the controller would cut the arc before the point that defines it"
            )
            return [Diagnostic("error", "arc_blend", msg, ins.span, step.index)]
    return []
