"""The generic post-processor: load ``posts/<name>/``, build the template context, write files.

A post folder holds ``post.yaml`` (the manifest) and Jinja2 templates. The manifest says::

    name: kuka
    vendor: kuka                      # olp.vendors.<vendor>: filters, name rules, hooks
    description: ...                  # one line for `olp posts`
    line_ending: "\\r\\n"
    encoding: ascii                   # text that cannot be encoded is an error, never mangled
    files:                            # one entry per output file of a program (or of a part)
      - {template: program.src.j2, name: "{name}.src"}
    main_files:                       # a split program's main program (calls the parts)
      - {template: main.src.j2, name: "{name}.src"}
    limits:                           # per file; omitted or null: no limit
      max_motions_per_file: 2000      # positions
      max_instructions_per_file: null # instructions of any kind
      max_lines_per_file: null        # text lines, checked on the rendered files
    frames_in: world                  # or robot_base: the controller's reference for frames
    options: {...}                    # free-form: templates see them as `options`, vendor
                                      # hooks get them too

Splitting (:mod:`olp.transforms.split`): when ``limits`` are exceeded, the program becomes parts
``<name>_P1`` ... rendered with ``files`` each, and a main program rendered with ``main_files``
that calls them in order. Posts with ``limits`` must have ``main_files``.

Template context (every file)
-----------------------------
``program``
    ``name`` (legal name of this file's program: the whole program, a part, or the main),
    ``source`` (where the program came from), ``main`` (the main program's name).
``split``
    True when the program was split (in parts and in the main).
``unit``
    ``name``, ``routine`` (the name of the routine to define: for the whole program or the main
    the option ``entry``, default the program's name; for a part the option ``part_routine``,
    a pattern like ``"{name}_run"``, default the part's name), ``index`` (0 for the whole
    program or the main, k for part k), ``count`` (number of parts, 0 when not split),
    ``is_part``, ``is_main`` (the whole program or the main).
``parts``
    In ``main_files``: the parts in call order, each ``{name, index, routine}``; else empty.
``steps``
    This file's instructions (:class:`PostStep`); empty in ``main_files``.
``tools`` / ``frames``
    The tools and frames this file's motions use (the main: all of the program's), each a
    :class:`PostTool` / :class:`PostFrame` with a legal unique name.
``vendor``
    What the vendor module's ``context_values`` hook returns for this file (e.g. ABB's custom
    speed and zone data); empty without the hook.
``modal``
    A :class:`Modal` change tracker for modal controller state: ``modal.changed("cdis", v)``.
    Fresh for every file.
``station``, ``robot`` (``station.robot``), ``options``, ``post`` (``name``, ``vendor``).

Filters: ``num`` (:func:`num`), ``deg`` (radians to degrees), ``basename`` (:func:`basename`) and
the vendor's ``TEMPLATE_FILTERS``.

Vendor hooks (all optional, in ``olp.vendors.<vendor>``)
--------------------------------------------------------
* ``legal_name(str) -> str`` and ``MAX_NAME_LENGTH``: names of programs, parts, data.
* ``PREDEFINED_NAMES``: names the controller already defines (never given to generated data).
* ``NULL_TOOL_NAME`` / ``NULL_FRAME_NAME``: the controller's own name for no tool / the world
  frame (ABB ``tool0`` / ``wobj0``), used for :data:`olp.ir.FLANGE` / :data:`olp.ir.WORLD`.
* ``step_values(robot, joints, options) -> list[dict]``: per motion, from its planned joints
  ``(N, dof)`` rad, vendor values such as KUKA Status/Turn or ABB confdata
  (:attr:`PostStep.vendor`). Raising TypeError or ValueError becomes a :class:`PostError`.
* ``context_values(steps, options) -> dict``: per file (the ``vendor`` context entry).
* ``post_diagnostics(compiled, options) -> list[Diagnostic]``: what the post cannot say
  exactly (see :func:`post_diagnostics`).

Output never depends on the locale (Python's ``format`` is locale-independent), nor on hash
seeds (no set iteration reaches the text), and every file is written atomically (temporary
file, then rename) only after all of them rendered.
"""

from __future__ import annotations

import importlib
import inspect
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from olp.diagnostics import Diagnostic
from olp.errors import PostError, UsageError
from olp.geometry import inv
from olp.ir import (
    FLANGE,
    MOTION_TYPES,
    CartesianTarget,
    CircularMove,
    Frame,
    JointMove,
    Tool,
)
from olp.passes.resolve import CompiledProgram, Step
from olp.posts.sandbox import make_environment
from olp.posts.view import Modal, changed
from olp.resources import data_path
from olp.transforms.split import LIMIT_KEYS, SplitLimits, part_names, split_steps

FloatArray = NDArray[np.float64]

FRAMES_IN = ("world", "robot_base")
"""What frame poses are written relative to: the station's world (the controller's world frame
must then be the station's) or the robot's controller base (``robot.base @
robot.controller_base``; a controller whose world is its robot base, as delivered)."""


@dataclass(frozen=True, slots=True)
class PostManifest:
    """A parsed ``post.yaml``."""

    name: str
    vendor: str
    folder: Path
    files: tuple[tuple[str, str], ...]
    description: str = ""
    line_ending: str = "\n"
    encoding: str = "ascii"
    options: Mapping[str, Any] = field(default_factory=dict)
    main_files: tuple[tuple[str, str], ...] = ()
    limits: SplitLimits = field(default_factory=SplitLimits)
    frames_in: str = "world"


def available_posts() -> dict[str, Path]:
    """Bundled posts (``posts/<name>/post.yaml``) and those added by packages through the
    ``olp.posts`` entry-point group (an entry point names a folder path)."""
    found = {p.parent.name: p.parent for p in sorted(data_path("posts").glob("*/post.yaml"))}
    from importlib.metadata import entry_points

    for ep in entry_points(group="olp.posts"):
        folder = Path(str(ep.load()))
        if (folder / "post.yaml").is_file():
            found.setdefault(ep.name, folder)
    return dict(sorted(found.items()))


def find_post(name_or_path: str) -> PostManifest:
    """A post by name (bundled or entry point) or by folder path (``./my_posts/kuka_line3``).

    A bare name (no path separator, not starting with ``.`` or ``~``) is only ever a bundled or
    installed post: a folder of that name in the working directory never replaces it, so a
    cloned project cannot slip its own templates in for ``--post kuka``. A folder post is used
    only when the user names it as a path.
    """
    if not is_post_path(name_or_path):
        posts = available_posts()
        if name_or_path not in posts:
            hint = None
            if (Path(name_or_path) / "post.yaml").is_file():
                hint = f"to use the folder {name_or_path!r}, name it as a path: ./{name_or_path}"
            raise UsageError(
                f"unknown post {name_or_path!r}: the posts are {', '.join(posts) or 'none'}",
                hint=hint,
            )
        return load_manifest(posts[name_or_path])
    folder = Path(name_or_path).expanduser()
    if not (folder / "post.yaml").is_file():
        raise UsageError(f"post folder {name_or_path!r} has no post.yaml")
    return load_manifest(folder)


def is_post_path(name_or_path: str) -> bool:
    """Whether ``--post`` names a folder (a path) rather than a registered post."""
    text = str(name_or_path)
    return "/" in text or "\\" in text or text.startswith((".", "~")) or Path(text).is_absolute()


def load_manifest(folder: Path) -> PostManifest:
    """Read and check ``folder/post.yaml``."""
    import yaml

    path = folder / "post.yaml"
    try:
        raw = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as exc:
        raise PostError(f"cannot read post manifest {path}: {exc}") from exc
    if not isinstance(raw, dict) or not isinstance(raw.get("files"), list):
        raise PostError(f"{path}: expected a mapping with a 'files' list")
    limits = _limits(raw.get("limits"), path)
    main_files = _file_entries(raw.get("main_files") or [], folder, path)
    if limits.active and not main_files:
        raise PostError(f"{path}: 'limits' need 'main_files' (the main program of the parts)")
    frames_in = str(raw.get("frames_in", "world"))
    if frames_in not in FRAMES_IN:
        raise PostError(f"{path}: frames_in must be one of {', '.join(FRAMES_IN)}")
    return PostManifest(
        name=str(raw.get("name", folder.name)),
        vendor=str(raw.get("vendor", "")),
        folder=folder,
        files=_file_entries(raw["files"], folder, path),
        description=str(raw.get("description", "")),
        line_ending=str(raw.get("line_ending", "\n")),
        encoding=str(raw.get("encoding", "ascii")),
        options=dict(raw.get("options") or {}),
        main_files=main_files,
        limits=limits,
        frames_in=frames_in,
    )


def _file_entries(entries: Any, folder: Path, path: Path) -> tuple[tuple[str, str], ...]:
    if not isinstance(entries, list):
        raise PostError(f"{path}: expected a list of files, got {entries!r}")
    files = []
    for entry in entries:
        if not isinstance(entry, dict) or "template" not in entry or "name" not in entry:
            raise PostError(f"{path}: each file needs 'template' and 'name', got {entry!r}")
        if not (folder / entry["template"]).is_file():
            raise PostError(f"{path}: template {entry['template']!r} not found in {folder}")
        files.append((str(entry["template"]), str(entry["name"])))
    return tuple(files)


def _limits(raw: Any, path: Path) -> SplitLimits:
    if raw is None:
        return SplitLimits()
    if not isinstance(raw, dict) or set(raw) - set(LIMIT_KEYS):
        raise PostError(f"{path}: 'limits' takes only {', '.join(LIMIT_KEYS)}, got {raw!r}")
    try:
        return SplitLimits(
            raw.get("max_motions_per_file"),
            raw.get("max_instructions_per_file"),
            raw.get("max_lines_per_file"),
        )
    except ValueError as exc:
        raise PostError(f"{path}: limits: {exc}") from exc


# --------------------------------------------------------------------------------------------
# Template context


@dataclass(frozen=True, slots=True, eq=False)
class PostTool:
    """A tool as the output names it: ``name`` (legal, unique in the program), ``tool`` (the
    resolved tool; its ``pose`` is the TCP in the vendor's flange frame, (4, 4) m), ``number``
    (the station's number or None), ``mass`` (kg from the station, None when unknown), ``null``
    (it is the bare flange)."""

    name: str
    tool: Tool
    number: int | None
    mass: float | None
    null: bool = False

    @property
    def pose(self) -> FloatArray:
        assert self.tool.pose is not None
        return self.tool.pose


@dataclass(frozen=True, slots=True, eq=False)
class PostFrame:
    """A frame as the output names it: ``name`` (legal, unique in the program), ``frame`` (the
    resolved frame, pose in the station's world), ``number`` (the station's number or None),
    ``pose`` ((4, 4) m, relative to the manifest's ``frames_in`` reference: what the controller
    is told), ``null`` (it is the reference itself: the world, or the robot base)."""

    name: str
    frame: Frame
    number: int | None
    pose: FloatArray
    null: bool = False


@dataclass(frozen=True, slots=True, eq=False)
class PostStep:
    """What a template sees for one instruction.

    Every instruction: ``index`` (in the program), ``kind`` (``joint``, ``linear``,
    ``circular``, ``wait``, ``set_output``, ``wait_input``, ``call``, ``comment``), ``source``
    (``file:line``), ``instruction`` (the IR object).

    Motions:

    * ``joints``: planned joints at the end, (dof,) rad, controller convention.
    * ``pose``: the TCP in the motion's frame, (4, 4) m (the target itself for a Cartesian
      target; from the planned joints otherwise).
    * ``tool`` / ``frame``: the resolved :class:`olp.ir.Tool` / :class:`olp.ir.Frame`.
    * ``cartesian``: the source gave a Cartesian target.
    * ``new_tool``, ``new_frame``, ``new_linear_speed``, ``new_joint_speed``, ``new_zone``:
      the value differs from the previous motion's *in this file* (each file starts afresh, so
      a part never relies on state set by another).
    * ``motion`` (added): 1-based number of the motion in the whole program.
    * ``name`` (added): a legal identifier for the target, unique in the program (the manifest
      option ``point_names``, default ``"P{n}"``, with ``n`` = ``motion``).
    * ``via`` / ``via_name`` (added): a circular move's auxiliary point, (4, 4) m in the frame,
      and its identifier (option ``via_names``, default ``"V{n}"``).
    * ``tool_name`` / ``frame_name`` (added): the names of this motion's :class:`PostTool` /
      :class:`PostFrame` (see the ``tools`` / ``frames`` context entries).
    * ``frame_pose`` (added): the frame as the controller is told, (4, 4) m relative to the
      manifest's ``frames_in`` reference; ``base_pose`` (added): the TCP in that reference,
      ``frame_pose @ pose``.
    * ``duration`` (added): seconds, from the timing pass (0 when it did not run).
    * ``vendor`` (added): per-motion vendor values from the vendor module's ``step_values``
      (KUKA ``status``, ``turn``; ABB ``confdata``), empty without the hook.

    Properties ``speed`` and ``zone`` are the instruction's.
    """

    index: int
    kind: str
    source: str
    instruction: Any
    joints: FloatArray | None = None
    pose: FloatArray | None = None
    tool: Tool | None = None
    frame: Frame | None = None
    cartesian: bool = False
    new_tool: bool = False
    new_frame: bool = False
    new_linear_speed: bool = False
    new_joint_speed: bool = False
    new_zone: bool = False
    motion: int = 0
    name: str = ""
    via: FloatArray | None = None
    via_name: str = ""
    tool_name: str = ""
    frame_name: str = ""
    frame_pose: FloatArray | None = None
    base_pose: FloatArray | None = None
    duration: float = 0.0
    vendor: Mapping[str, Any] = field(default_factory=dict)

    @property
    def speed(self) -> Any:
        return self.instruction.speed

    @property
    def zone(self) -> Any:
        return self.instruction.zone


def build_steps(compiled: CompiledProgram) -> list[PostStep]:
    """The template view of every compiled instruction as one file (generic names, no vendor
    values), with modal-state change flags."""
    view = _ProgramView(compiled, None, PostManifest("", "", Path("."), ()))
    names = _Names(str, None, ())
    return view.unit_steps(compiled.steps, view.allocate(names))


@dataclass(frozen=True, slots=True, eq=False)
class _Motion:
    """Per-motion data computed once per render (not per file)."""

    pose: FloatArray
    frame_pose: FloatArray
    via: FloatArray | None
    vendor: Mapping[str, Any]
    number: int


@dataclass(frozen=True, slots=True)
class _Allocation:
    """Names given to one program's points, tools and frames."""

    points: Mapping[int, tuple[str, str]]
    tools: Mapping[int, PostTool]
    frames: Mapping[int, PostFrame]


class _ProgramView:
    """Everything the templates see that does not depend on how the program is split."""

    def __init__(self, compiled: CompiledProgram, vendor: Any, manifest: PostManifest) -> None:
        self.compiled = compiled
        self.vendor = vendor
        self.manifest = manifest
        robot = compiled.station.robot
        self.reference = (
            robot.base @ robot.controller_base if manifest.frames_in == "robot_base" else np.eye(4)
        )
        self.motions = self._motions()

    def _motions(self) -> dict[int, _Motion]:
        written = [s for s in self.compiled.steps if _written_motion(s)]
        if not written:
            return {}
        robot = self.compiled.station.robot
        joints = np.stack([np.asarray(s.joints, dtype=np.float64) for s in written])
        flanges = robot.flange_poses(joints)
        values = self._vendor_values(joints)
        ref_inv = inv(self.reference)
        out = {}
        for n, (step, flange, vendor) in enumerate(zip(written, flanges, values, strict=True)):
            assert step.frame is not None and step.frame.pose is not None
            out[step.index] = _Motion(
                pose=_pose_in_frame(step, flange),
                frame_pose=ref_inv @ step.frame.pose,
                via=_via(step),
                vendor=vendor,
                number=n + 1,
            )
        return out

    def _vendor_values(self, joints: FloatArray) -> list[Mapping[str, Any]]:
        hook = getattr(self.vendor, "step_values", None)
        if hook is None:
            return [{} for _ in range(joints.shape[0])]
        try:
            values: list[Mapping[str, Any]] = hook(
                self.compiled.station.robot, joints, self.manifest.options
            )
        except (TypeError, ValueError) as exc:
            raise PostError(
                f"post {self.manifest.name!r} cannot describe robot "
                f"{self.compiled.station.robot.name!r}: {exc}"
            ) from exc
        return values

    def allocate(self, names: _Names) -> _Allocation:
        """Give every point, tool and frame of the program a name."""
        options = self.manifest.options
        point_pattern = str(options.get("point_names", "P{n}"))
        via_pattern = str(options.get("via_names", "V{n}"))
        points: dict[int, tuple[str, str]] = {}
        tools: dict[int, PostTool] = {}
        frames: dict[int, PostFrame] = {}
        tool_keys: dict[tuple[str, bytes], PostTool] = {}
        frame_keys: dict[tuple[str, bytes], PostFrame] = {}
        for step in self.compiled.steps:
            motion = self.motions.get(step.index)
            if motion is None:
                continue
            via = names.take(via_pattern.format(n=motion.number)) if motion.via is not None else ""
            points[step.index] = (names.take(point_pattern.format(n=motion.number)), via)
            assert step.tool is not None and step.frame is not None
            tools[step.index] = self._tool(step.tool, tool_keys, names)
            frames[step.index] = self._frame(step.frame, motion.frame_pose, frame_keys, names)
        return _Allocation(points, tools, frames)

    def _tool(self, tool: Tool, seen: dict[tuple[str, bytes], PostTool], names: _Names) -> PostTool:
        assert tool.pose is not None
        key = (tool.name, np.asarray(tool.pose).tobytes())
        if key not in seen:
            null = _is_null(tool, FLANGE)
            special = getattr(self.vendor, "NULL_TOOL_NAME", None) if null else None
            body = self.compiled.station.tool_bodies.get(tool.name)
            seen[key] = PostTool(
                special or names.take(tool.name),
                tool,
                tool.number,
                None if body is None else body.mass,
                null,
            )
        return seen[key]

    def _frame(
        self,
        frame: Frame,
        pose: FloatArray,
        seen: dict[tuple[str, bytes], PostFrame],
        names: _Names,
    ) -> PostFrame:
        assert frame.pose is not None
        key = (frame.name, np.asarray(frame.pose).tobytes())
        if key not in seen:
            null = bool(np.allclose(pose, np.eye(4), rtol=0.0, atol=1e-12))
            special = getattr(self.vendor, "NULL_FRAME_NAME", None) if null else None
            seen[key] = PostFrame(
                special or names.take(frame.name), frame, frame.number, pose, null
            )
        return seen[key]

    def unit_steps(self, steps: Sequence[Step], names: _Allocation) -> list[PostStep]:
        """The template view of ``steps`` as one file: change flags start afresh."""
        out: list[PostStep] = []
        last: dict[str, Any] = {}
        for step in steps:
            ins = step.instruction
            if not isinstance(ins, MOTION_TYPES):
                out.append(PostStep(step.index, ins.kind, ins.span.location, ins))
            elif step.index in self.motions:
                out.append(self._motion_step(step, names, last))
        return out

    def _motion_step(self, step: Step, names: _Allocation, last: dict[str, Any]) -> PostStep:
        ins: Any = step.instruction
        motion = self.motions[step.index]
        flags = {
            "new_tool": changed(last, "tool", step.tool),
            "new_frame": changed(last, "frame", step.frame),
            "new_zone": changed(last, "zone", ins.zone),
        }
        if isinstance(ins, JointMove):
            speed = (ins.speed.joint, ins.speed.joint_acceleration)
            flags["new_joint_speed"] = changed(last, "joint_speed", speed)
        else:
            speed = (ins.speed.linear, ins.speed.angular)
            flags["new_linear_speed"] = changed(last, "linear_speed", speed)
        point, via = names.points[step.index]
        return PostStep(
            step.index,
            ins.kind,
            ins.span.location,
            ins,
            joints=step.joints,
            pose=motion.pose,
            tool=step.tool,
            frame=step.frame,
            cartesian=isinstance(ins.target, CartesianTarget),
            motion=motion.number,
            name=point,
            via=motion.via,
            via_name=via,
            tool_name=names.tools[step.index].name,
            frame_name=names.frames[step.index].name,
            frame_pose=motion.frame_pose,
            base_pose=motion.frame_pose @ motion.pose,
            duration=step.duration,
            vendor=motion.vendor,
            **flags,
        )


def _written_motion(step: Step) -> bool:
    motion = isinstance(step.instruction, MOTION_TYPES)
    return motion and not step.skipped and step.joints is not None


def _is_null(obj: Tool | Frame, null: Tool | Frame) -> bool:
    assert obj.pose is not None
    return obj.name == null.name and bool(np.array_equal(obj.pose, np.eye(4)))


def _via(step: Step) -> FloatArray | None:
    ins = step.instruction
    return np.array(ins.via.pose) if isinstance(ins, CircularMove) else None


def _pose_in_frame(step: Step, flange: FloatArray) -> FloatArray:
    ins = step.instruction
    if isinstance(ins, MOTION_TYPES) and isinstance(ins.target, CartesianTarget):
        return np.array(ins.target.pose)
    assert step.tool is not None and step.frame is not None
    assert step.tool.pose is not None and step.frame.pose is not None
    result: FloatArray = inv(step.frame.pose) @ flange @ step.tool.pose
    return result


class _Names:
    """Identifiers that are legal for the vendor and unique ignoring case."""

    def __init__(
        self, legal: Callable[[str], str], max_length: int | None, reserved: Sequence[str]
    ) -> None:
        self.legal = legal
        self.max_length = max_length
        self.taken = {r.casefold() for r in reserved}

    def take(self, wanted: str) -> str:
        base = self.legal(wanted)
        name, k = base, 2
        while name.casefold() in self.taken:
            suffix = f"_{k}"
            cut = base if self.max_length is None else base[: self.max_length - len(suffix)]
            name, k = self.legal(cut + suffix), k + 1
        self.taken.add(name.casefold())
        return name


# --------------------------------------------------------------------------------------------
# Rendering and writing


def num(value: float, decimals: int = 3) -> str:
    """A fixed-point number, locale-independent, never ``-0.000``."""
    text = f"{float(value):.{decimals}f}"
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]
    return text


def basename(path: str) -> str:
    """The last component of a path written with ``/`` or ``\\`` (for header comments: where a
    program came from, without the machine's folders)."""
    return str(path).replace("\\", "/").rstrip("/").rsplit("/", 1)[-1]


_MAX_SPLIT_ROUNDS = 12
"""How often :func:`render` splits finer to meet ``max_lines_per_file`` before it gives up."""


def render(
    compiled: CompiledProgram, manifest: PostManifest, name: str | None = None
) -> dict[str, str]:
    """Render every file of the post: ``{file name: text}``. Raises PostError, writes nothing.

    Splits the program into parts when the manifest's ``limits`` ask for it (splitting finer
    until every file has at most ``max_lines_per_file`` lines).
    """
    renderer = _Renderer(compiled, manifest, name)
    limits = manifest.limits
    for _ in range(_MAX_SPLIT_ROUNDS):
        parts = split_steps(compiled.steps, limits)
        files = renderer.render(parts)
        longest, lines = _longest(files, manifest.line_ending)
        if manifest.limits.max_lines is None or lines <= manifest.limits.max_lines:
            return files
        limits = _finer(limits, parts, lines, manifest.limits.max_lines, longest, renderer)
    raise PostError(f"post {manifest.name!r}: could not meet max_lines_per_file by splitting")


def _longest(files: Mapping[str, str], ending: str) -> tuple[str, int]:
    counts = {f: text.count(ending) + (not text.endswith(ending)) for f, text in files.items()}
    fname = max(counts, key=lambda f: (counts[f], f))
    return fname, counts[fname]


def _finer(
    limits: SplitLimits,
    parts: list[tuple[Step, ...]],
    lines: int,
    max_lines: int,
    longest: str,
    renderer: _Renderer,
) -> SplitLimits:
    """Tighter instruction limits after a file came out with ``lines`` > ``max_lines``."""
    biggest = max(sum(1 for s in p if not s.skipped) for p in parts)
    if longest in renderer.main_file_names or biggest <= 1:
        raise PostError(
            f"post {renderer.manifest.name!r}: {longest} has {lines} lines, more than "
            f"max_lines_per_file {max_lines}, and splitting cannot make it shorter"
        )
    fewer = max(1, min(biggest - 1, math.floor(biggest * max_lines / lines)))
    return SplitLimits(limits.max_motions, fewer, limits.max_lines)


class _Renderer:
    """Renders one compiled program through one post, for a given split."""

    def __init__(self, compiled: CompiledProgram, manifest: PostManifest, name: str | None):
        self.compiled = compiled
        self.manifest = manifest
        self.vendor = _vendor_module(manifest)
        self.legal: Callable[[str], str] = getattr(self.vendor, "legal_name", lambda s: s)
        self.max_length: int | None = getattr(self.vendor, "MAX_NAME_LENGTH", None)
        self.name = self.legal(name or compiled.program.name)
        self.view = _ProgramView(compiled, self.vendor, manifest)
        filters: Mapping[str, Callable[..., Any]] = getattr(self.vendor, "TEMPLATE_FILTERS", {})
        self.env = make_environment(
            manifest.folder, {"num": num, "deg": math.degrees, "basename": basename, **filters}
        )
        self.main_file_names: set[str] = set()

    def render(self, parts: list[tuple[Step, ...]]) -> dict[str, str]:
        split = len(parts) > 1
        unit_names = part_names(self.name, len(parts), self.legal, self.max_length) if split else []
        names = _Names(
            self.legal,
            self.max_length,
            [self.name, *unit_names, *getattr(self.vendor, "PREDEFINED_NAMES", ())],
        )
        options = self.manifest.options
        entry = names.take(str(options["entry"])) if "entry" in options else self.name
        routines = [
            names.take(str(options.get("part_routine", "{name}")).format(name=n))
            if "part_routine" in options
            else n
            for n in unit_names
        ]
        allocation = self.view.allocate(names)
        if not split:
            return self._files(self.manifest.files, self._unit(parts[0], allocation, 0, 0, entry))
        main = self._unit((), allocation, 0, len(parts), entry)
        main["parts"] = [
            {"name": n, "index": k + 1, "routine": r}
            for k, (n, r) in enumerate(zip(unit_names, routines, strict=True))
        ]
        main["tools"], main["frames"] = _used(allocation, [s.index for s in self.compiled.steps])
        main_files = self._files(self.manifest.main_files, main)
        self.main_file_names = set(main_files)
        files: dict[str, str] = {}
        for k, (steps, unit_name) in enumerate(zip(parts, unit_names, strict=True)):
            unit = self._unit(steps, allocation, k + 1, len(parts), routines[k], unit_name)
            files.update(self._files(self.manifest.files, unit, clash=files.keys() | main_files))
        return {**main_files, **files}

    def _unit(
        self,
        steps: Sequence[Step],
        allocation: _Allocation,
        index: int,
        count: int,
        routine: str,
        unit_name: str | None = None,
    ) -> dict[str, Any]:
        view = self.view.unit_steps(steps, allocation)
        tools, frames = _used(allocation, [s.index for s in view])
        name = unit_name or self.name
        return {
            "program": {"name": name, "source": self.compiled.program.source, "main": self.name},
            "split": count > 0,
            "unit": {
                "name": name,
                "routine": routine,
                "index": index,
                "count": count,
                "is_part": index > 0,
                "is_main": index == 0,
            },
            "parts": [],
            "steps": view,
            "tools": tools,
            "frames": frames,
            "vendor": self._context_values(view),
            "station": self.compiled.station,
            "robot": self.compiled.station.robot,
            "options": self.manifest.options,
            "post": {"name": self.manifest.name, "vendor": self.manifest.vendor},
        }

    def _context_values(self, steps: list[PostStep]) -> Mapping[str, Any]:
        hook = getattr(self.vendor, "context_values", None)
        if hook is None:
            return {}
        values: Mapping[str, Any] = hook(steps, self.manifest.options)
        return values

    def _files(
        self,
        entries: Sequence[tuple[str, str]],
        context: dict[str, Any],
        clash: Any = frozenset(),
    ) -> dict[str, str]:
        import jinja2

        files: dict[str, str] = {}
        for template, pattern in entries:
            context["modal"] = Modal()
            try:
                text = self.env.get_template(template).render(**context)
            except jinja2.TemplateError as exc:
                path = self.manifest.folder / template
                raise PostError(
                    f"{path}:{_template_line(exc, path)}: template error: {exc}"
                ) from exc
            fname = pattern.format(name=context["program"]["name"])
            if fname in files or fname in clash:
                raise PostError(f"post {self.manifest.name!r} writes {fname} twice")
            files[fname] = _line_endings(text, self.manifest.line_ending)
        return files


def _template_line(exc: Exception, path: Path) -> int | str:
    """The template line an error came from: syntax errors carry it; for runtime errors Jinja
    rewrites the traceback so that a frame points into the template file."""
    line = getattr(exc, "lineno", None)
    tb = exc.__traceback__
    while tb is not None:
        if Path(tb.tb_frame.f_code.co_filename) == path:
            line = tb.tb_lineno
        tb = tb.tb_next
    return line if line is not None else "?"


def _used(
    allocation: _Allocation, indices: Sequence[int]
) -> tuple[list[PostTool], list[PostFrame]]:
    """The distinct tools and frames of the motions at ``indices``, in order of first use."""
    tools: dict[str, PostTool] = {}
    frames: dict[str, PostFrame] = {}
    for i in indices:
        if i in allocation.tools:
            tools.setdefault(allocation.tools[i].name, allocation.tools[i])
            frames.setdefault(allocation.frames[i].name, allocation.frames[i])
    return list(tools.values()), list(frames.values())


def _vendor_module(manifest: PostManifest) -> Any:
    if not manifest.vendor:
        return None
    try:
        return importlib.import_module(f"olp.vendors.{manifest.vendor}")
    except ModuleNotFoundError as exc:
        raise PostError(f"post {manifest.name!r} names unknown vendor {manifest.vendor!r}") from exc


def _line_endings(text: str, ending: str) -> str:
    lines = text.replace("\r\n", "\n").split("\n")
    return ending.join(line.rstrip() for line in lines)


def post_diagnostics(compiled: CompiledProgram, manifest: PostManifest) -> list[Diagnostic]:
    """What this post cannot say exactly about ``compiled``: the vendor module's
    ``post_diagnostics(compiled, options)`` (older hooks take ``compiled`` only). Errors among
    them mean nothing may be written."""
    hook = getattr(_vendor_module(manifest), "post_diagnostics", None)
    if hook is None:
        return []
    if len(inspect.signature(hook).parameters) >= 2:
        found: list[Diagnostic] = hook(compiled, manifest.options)
    else:
        found = hook(compiled)
    return found


def write_files(files: Mapping[str, str], out_dir: Path, encoding: str = "ascii") -> list[Path]:
    """Encode every file (a character the encoding lacks is a PostError naming the file, line
    and column), then write them as one set into ``out_dir`` (:func:`olp.output.write_folder`:
    all or nothing, stale parts of an earlier build removed)."""
    from olp.output import write_folder

    encoded = {}
    for fname, text in files.items():
        try:
            encoded[fname] = text.encode(encoding)
        except UnicodeEncodeError as exc:
            bad = text[exc.start : exc.end]
            line = text.count("\n", 0, exc.start) + 1
            column = exc.start - (text.rfind("\n", 0, exc.start) + 1) + 1
            raise PostError(
                f"{fname}:{line}:{column}: character {bad!r} cannot be written in {encoding}"
            ) from exc
    return write_folder(encoded, out_dir)
