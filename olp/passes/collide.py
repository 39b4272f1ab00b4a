"""Collide: every motion of a compiled program checked for collisions, between samples too.

What is checked (coal through pinocchio's ``GeometryModel``; meshes as convex hulls):

* the robot's links, its current tool and any carried part against the station's parts and
  fixtures (kind ``collision``);
* the robot's links, tool and carried parts against each other (kind ``self_collision``), except
  bodies on the same or on adjacent joints (the tool and a carried part sit on the last joint, so
  they may touch the last two links), the link pairs the robot library declares (capsules that
  overlap by construction), link and tool shapes proven to overlap in every configuration (a
  tool's bracket inside the wrist's capsule) — see :mod:`olp.collision.scene`;
* never the pairs the station's ``allowed_pairs`` or :attr:`CollisionOptions.allowed_pairs` name;
* by default the tool may touch and enter *parts* (machining, welding, screwing); it is checked
  against fixtures.

Two clearances: ``clearance_m`` between the robot side (links, tool, carried parts) and the
station (parts, fixtures), ``self_clearance_m`` between the robot's own bodies (link-link,
link-tool, link-carried part). The set of checked pairs depends on neither: a larger clearance
only adds margin, so a program that fails at one pair of clearances fails at every larger one.

Shape pairs whose distance no joint motion changes (proven from the geometry, see
:mod:`olp.collision.scene`: the UR5e's link_4 and link_6 stay 14.7 mm apart) are not checked per
motion: no program can change them. When one lies within the clearance for its kind, one
warning per build (kind ``clearance_unmet``) names it, its distance and the clearance asked
for; every other pair is checked as usual.

Along every motion the piecewise-linear joint path between the resolve pass's samples is proven
free by conservative advancement (:mod:`olp.collision.advance`): if nothing is reported, every
checked pair keeps a signed distance above its clearance minus ``tolerance_m`` everywhere on that
path, a thin wall between two samples included. For a joint move that path is the motion itself
(straight in joint space). For a linear move the real TCP line is sampled every ``step_m`` /
``step_rad`` and joined by joint-space chords; between samples the chord deviates from the
exact path by a second-order amount: :func:`olp.collision.chord.chord_deviation` estimates it
(at the default 5 mm step, a few hundredths of a millimetre of link-point motion on the bundled
milling toolpath, below the default tolerance); ``clearance_m`` covers it where that matters.
Rounded corners (zones) are not modelled: the checked path is the programmed one.

Pick and place: an :class:`Attachment` makes the tool carry a station part from one instruction
to another; the part keeps the pose relative to the flange it had when gripped and stays where
it was let go.

What cannot be checked is an error diagnostic (kind ``collision_unchecked``), never a pass: a
body beyond :data:`olp.collision.scene.MAX_REACH_M`, a distance that is not a number, or a
path the advancement cannot prove free within its evaluation budget.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import NDArray

from olp import progress
from olp.compiled import PathBlock, Step, items_of
from olp.diagnostics import Diagnostic
from olp.errors import UsageError
from olp.geometry import inv
from olp.ir import FLANGE, Tool, is_motion
from olp.passes.wording import percent

if TYPE_CHECKING:
    from olp.collision.advance import Hit, Unresolved
    from olp.collision.scene import ConstantPair, Placed, Scene
    from olp.compiled import CompiledProgram
    from olp.passes.pipeline import BuildOptions
    from olp.station.model import Station

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True, slots=True)
class Attachment:
    """The tool carries station part (or fixture) ``part`` from instruction ``grasp`` up to, not
    including, instruction ``release`` (None: to the end). It keeps the pose relative to the
    flange it has when gripped (at the robot's position before instruction ``grasp``) and stays
    where the robot lets it go."""

    part: str
    grasp: int
    release: int | None = None


@dataclass(frozen=True, slots=True)
class CollisionOptions:
    """Settings of the collision check.

    ``clearance_m``: the robot's links, tool and carried parts closer than this (m) to a part or
    fixture collide (0: only overlap counts). ``self_clearance_m``: the same between the robot's
    own bodies (link-link, link-tool, link-carried part). Each adds margin to every pair of its
    kind and never changes which pairs are checked. ``tolerance_m``: the resolution (within
    :data:`TOLERANCE_RANGE_M`): a pair closer than its clearance minus ``tolerance_m`` anywhere
    on a motion is always reported; one that stays above its clearance minus ``tolerance_m / 2``
    never is (so parts resting on fixtures do not collide).

    ``allowed_pairs``: pairs of body names never checked, added to the station's (robot links by
    link name, e.g. ``"link_3"``; the tool by its station name; parts and fixtures by name).
    ``self_collision``: check the robot's bodies against each other. ``tool_touches_parts``: the
    tool may touch and enter parts. ``home_contacts``: also allow the link and tool pairs that
    overlap at the home position (off by default: one pose does not show that two bodies always
    touch; the robot library declares the pairs that do). ``attachments``: parts carried by the
    tool (pick and place). ``mode``: ``"advance"`` proves the path between samples free;
    ``"samples"`` checks the resolve samples only (a reference that misses thin obstacles).

    Raises :class:`~olp.errors.UsageError` for a clearance that is negative or not finite, a
    tolerance outside :data:`TOLERANCE_RANGE_M`, or an unknown mode.
    """

    clearance_m: float = 0.0
    self_clearance_m: float = 0.0
    tolerance_m: float = 1e-4
    allowed_pairs: tuple[tuple[str, str], ...] = ()
    self_collision: bool = True
    tool_touches_parts: bool = True
    home_contacts: bool = False
    attachments: tuple[Attachment, ...] = ()
    mode: Literal["advance", "samples"] = "advance"

    def __post_init__(self) -> None:
        for what, value in (("", self.clearance_m), ("self-", self.self_clearance_m)):
            if not (math.isfinite(value) and value >= 0):
                raise UsageError(
                    f"the collision {what}clearance must be a finite distance >= 0, "
                    f"got {value * 1000:g} mm"
                )
        low, high = TOLERANCE_RANGE_M
        if not low <= self.tolerance_m <= high:
            raise UsageError(
                f"the collision tolerance must lie in {low * 1000:g}..{high * 1000:g} mm, "
                f"got {self.tolerance_m * 1000:g} mm"
            )
        if self.mode not in ("advance", "samples"):
            raise UsageError(f"collision mode must be 'advance' or 'samples', got {self.mode!r}")


TOLERANCE_RANGE_M = (1e-6, 1e-2)
"""Allowed ``tolerance_m`` (m). Below a micrometre the tolerance is finer than coal's distances
and the advancement crawls (up to ``2 c / tolerance`` evaluations); above 10 mm an overlap that
deep could pass unreported, which is a disabled check rather than a resolution."""


@dataclass(frozen=True, slots=True)
class CollisionStats:
    """What a check did: distance evaluations and path rows (for benchmarks)."""

    evaluations: int = 0
    rows: int = 0
    pairs: int = 0


def check_collisions(
    compiled: CompiledProgram, options: CollisionOptions | None = None
) -> list[Diagnostic]:
    """Diagnostics for every collision along the motions of ``compiled`` (see the module text).

    Motions the resolve pass could not resolve (no path) are skipped. Never raises on a bad
    program; an unknown part in ``options.attachments`` is an error diagnostic.
    """
    return check_collisions_with_stats(compiled, options)[0]


def check_collisions_with_stats(
    compiled: CompiledProgram, options: CollisionOptions | None = None
) -> tuple[list[Diagnostic], CollisionStats]:
    """:func:`check_collisions` and what it cost."""
    from olp.collision.scene import UnsupportedChain

    opts = options or CollisionOptions()
    try:
        runs, setup = _runs(compiled, opts)
    except UnsupportedChain as exc:
        message = f"collisions not checked: {exc}"
        return [Diagnostic("warning", "collision_unchecked", message)], CollisionStats()
    found: list[_Found] = []
    unresolved: list[Diagnostic] = []
    stats = CollisionStats()
    for run in runs:
        hits, failed, run_stats = _check_run(run, opts)
        progress.advance(sum(len(p) if isinstance(p, PathBlock) else 1 for p in run.parts))
        found.extend(hits)
        unresolved.extend(failed)
        stats = CollisionStats(
            stats.evaluations + run_stats.evaluations,
            stats.rows + run_stats.rows,
            max(stats.pairs, run_stats.pairs),
        )
    checked = _diagnostics(found, opts)
    return _bodiless_tools(compiled) + setup + unresolved + checked, stats


# --------------------------------------------------------------------------------------------
# The program as runs of motions in one scene


@dataclass(slots=True, eq=False)
class _Run:
    """Consecutive resolved motions (joined end to start) in one scene: ordinary steps and whole
    toolpath blocks (``parts``); ``ordinals``: each part's first motion's ordinal among the
    program's motions."""

    scene: Scene
    parts: list[Step | PathBlock] = field(default_factory=list)
    ordinals: list[int] = field(default_factory=list)

    def counts(self) -> list[IntArray]:
        """Per part, the path segments of each of its motions."""
        return [_segments(part) for part in self.parts]

    def motion(self, m: int) -> tuple[Step, int]:
        """The step of the run's motion ``m`` and its ordinal (a block's row made only here)."""
        sizes = np.cumsum([len(part) if isinstance(part, PathBlock) else 1 for part in self.parts])
        k = int(np.searchsorted(sizes, m, side="right"))
        part, within = self.parts[k], m - (int(sizes[k - 1]) if k else 0)
        step = part.step(within) if isinstance(part, PathBlock) else part
        return step, self.ordinals[k] + within


def _segments(part: Step | PathBlock) -> IntArray:
    if isinstance(part, PathBlock):
        assert part.ends is not None
        return np.diff(part.ends, prepend=0).astype(np.int64)
    assert part.path is not None
    return np.array([len(part.path) - 1], dtype=np.int64)


@dataclass(slots=True, eq=False)
class _World:
    """The state the scene depends on while walking the program."""

    objects: dict[str, FloatArray]
    carried: dict[str, FloatArray]
    joints: FloatArray
    pending: list[Attachment]
    version: int = 0


@dataclass(slots=True, eq=False)
class _Walk:
    """Walking the program's motions into runs."""

    compiled: CompiledProgram
    opts: CollisionOptions
    world: _World
    scenes: dict[tuple[object, ...], Scene] = field(default_factory=dict)
    runs: list[_Run] = field(default_factory=list)
    unchecked: dict[str, Diagnostic] = field(default_factory=dict)
    unmet: dict[tuple[str, str], tuple[float, Diagnostic]] = field(default_factory=dict)
    last: bytes = b""
    ordinal: int = 0

    def add(self, part: Step | PathBlock) -> None:
        """Add a motion, or a whole toolpath block, to the runs."""
        station, world = self.compiled.station, self.world
        first = part if isinstance(part, Step) else part.start
        index = first.index if isinstance(first, Step) else first
        changed = bool(world.pending) and _apply_attachments(index, world, station)
        ordinal = self.ordinal
        self.ordinal += len(part) if isinstance(part, PathBlock) else 1
        path = part.path
        if path is None or len(path) < 2:
            self.last = b""
            return
        step = part.step(0) if isinstance(part, PathBlock) else part
        key = _scene_key(step, world)
        scene = self.scenes.get(key)
        if scene is None:
            scene = self.scenes[key] = _scene(station, step, world, self.opts)
            for label, radius in scene.unchecked:
                self.unchecked.setdefault(label, _too_far(label, radius, step))
            _constant_within_clearance(scene, step, self.opts, self.unmet)
        runs = self.runs
        if changed or not runs or runs[-1].scene is not scene or path[0].tobytes() != self.last:
            runs.append(_Run(scene))
        runs[-1].parts.append(part)
        runs[-1].ordinals.append(ordinal)
        self.last = path[-1].tobytes()
        world.joints = path[-1]


def _runs(compiled: CompiledProgram, opts: CollisionOptions) -> tuple[list[_Run], list[Diagnostic]]:
    """The resolved motions in runs: a new run where a motion does not start where the previous
    one ended, or where the tool or the carried parts change. A toolpath block joins a run whole
    unless a part is gripped or let go inside it (then row by row)."""
    station = compiled.station
    known = {o.name for o in station.objects}
    world = _World(
        objects={o.name: o.pose for o in station.objects},
        carried={},
        joints=compiled.start_joints,
        pending=[a for a in opts.attachments if a.part in known],
    )
    walk = _Walk(compiled, opts, world)
    for item in items_of(compiled.steps):
        if isinstance(item, PathBlock):
            if _whole(item, world):
                walk.add(item)
            else:
                for k in range(len(item)):
                    walk.add(item.step(k))
        elif is_motion(item.instruction):
            walk.add(item)
    warnings = [d for _, d in walk.unmet.values()]
    return walk.runs, _unknown_parts(compiled, opts) + list(walk.unchecked.values()) + warnings


def _whole(block: PathBlock, world: _World) -> bool:
    """Whether a block can join a run whole: resolved, every row with a segment, and no part
    gripped or let go after its first row."""
    if block.path is None or block.ends is None or np.any(np.diff(block.ends, prepend=0) < 1):
        return block.path is None  # unresolved: skipped whole; odd rows: row by row
    inside = range(block.start + 1, block.stop)
    return not any(a.grasp in inside or a.release in inside for a in world.pending)


def _too_far(label: str, radius: float, step: Step) -> Diagnostic:
    """The error for a body the scene left out (beyond ``MAX_REACH_M``), at its first motion."""
    from olp.collision.scene import MAX_REACH_M

    message = (
        f"collisions with {label} cannot be checked: it lies up to {radius:.3g} m from the "
        f"robot, beyond the {MAX_REACH_M:g} m within which distances are exact"
    )
    hint = "check the station's units and poses for this body"
    span = step.instruction.span
    return Diagnostic("error", "collision_unchecked", message, span, step.index, hint=hint)


def _clearance(kind: str, opts: CollisionOptions) -> float:
    """The clearance (m) for a pair of ``kind``: robot-internal or against the station."""
    return opts.self_clearance_m if kind == "self_collision" else opts.clearance_m


def _constant_within_clearance(
    scene: Scene,
    step: Step,
    opts: CollisionOptions,
    unmet: dict[tuple[str, str], tuple[float, Diagnostic]],
) -> None:
    """Add to ``unmet`` a warning for each of the scene's constant-distance pairs closer than
    its clearance (where a motion check would report it), the closest one per pair of names."""
    for pair in scene.constant:
        clearance = _clearance(pair.kind, opts)
        names = scene.name_of(pair)
        known = unmet.get(names)
        if pair.distance < clearance - opts.tolerance_m / 2 and (
            known is None or pair.distance < known[0]
        ):
            unmet[names] = pair.distance, _unmet(names, pair, clearance, step)


def _unmet(names: tuple[str, str], pair: ConstantPair, clearance: float, step: Step) -> Diagnostic:
    """The warning for a constant-distance pair within its clearance, at its first motion."""
    what = "self-clearance" if pair.kind == "self_collision" else "clearance"
    bodies = f"{names[0]} and {names[1]}" if pair.whole else f"shapes of {names[0]} and {names[1]}"
    message = (
        f"the {what} of {clearance * 1000:.1f} mm cannot be met: {bodies} are "
        f"{pair.distance * 1000:.1f} mm apart in every position of the robot, whatever the "
        f"program does; every other pair is checked with this {what}"
    )
    option = "--self-clearance" if pair.kind == "self_collision" else "--clearance"
    hint = (
        f"this pair allows a {what} up to {pair.distance * 1000:.1f} mm ({option}); for more, "
        "change the station or the robot's collision model"
    )
    span = step.instruction.span
    return Diagnostic("warning", "clearance_unmet", message, span, step.index, hint=hint)


def _unknown_parts(compiled: CompiledProgram, opts: CollisionOptions) -> list[Diagnostic]:
    known = {o.name for o in compiled.station.objects}
    out = []
    for a in opts.attachments:
        if a.part not in known:
            step = next((s for s in compiled.steps if s.index == a.grasp), None)
            span = step.instruction.span if step is not None else None
            names = ", ".join(sorted(known)) or "none"
            message = f"the tool cannot carry {a.part!r}: no such part in the station ({names})"
            out.append(Diagnostic("error", "unknown_part", message, span, a.grasp))
    return out


def _apply_attachments(index: int, world: _World, station: Station) -> bool:
    """Grip and let go of parts up to instruction ``index``; True if anything changed."""
    changed = False
    due = [a for a in world.pending if index >= a.grasp]
    if not due:
        return False
    flange = station.robot.flange_poses(world.joints)
    for a in due:
        if a.part not in world.carried and a.part in world.objects:
            world.carried[a.part] = inv(flange) @ world.objects.pop(a.part)
            changed = True
        if a.part in world.carried and a.release is not None and index >= a.release:
            world.objects[a.part] = flange @ world.carried.pop(a.part)
            world.pending.remove(a)
            changed = True
    world.version += changed
    return changed


def _scene_key(step: Step, world: _World) -> tuple[object, ...]:
    tool = step.tool
    return (None if tool is None else (tool.name, tool.number)), world.version


def _tool_body(station: Station, tool: Tool | None) -> Placed | None:
    """The station's body of a step's tool: by name, else the station tool of the same number
    (an inline KRL tool), else none."""
    from olp.collision.scene import Placed

    if tool is None:
        return None
    name = _station_tool_name(station, tool)
    body = station.tool_bodies.get(name)
    return Placed(name, "tool", np.eye(4), body.shapes) if body is not None else None


def _station_tool_name(station: Station, tool: Tool) -> str:
    """The station tool a step's tool is: by name, by number, else the one with the same TCP
    (an inline KRL ``$TOOL = {FRAME: ...}`` copied from the cell), else its own name."""
    if tool.name in station.tool_bodies:
        return tool.name
    known = station.tool(Tool(name=tool.name, number=tool.number))
    if known is not None:
        return known.name
    if tool.pose is not None:
        for candidate in station.tools.values():
            if candidate.pose is not None and np.allclose(candidate.pose, tool.pose, atol=1e-9):
                return candidate.name
    return tool.name


def _bodiless_tools(compiled: CompiledProgram) -> list[Diagnostic]:
    """A warning for each tool the program uses that has no collision geometry while the
    station gives geometry to its tools: only the robot's links are checked for it."""
    station = compiled.station
    if not any(body.shapes for body in station.tool_bodies.values()):
        return []
    out, seen = [], {FLANGE.name}
    for item in items_of(compiled.steps):
        tool = item.tool
        if tool is None or item.joints is None or tool.name in seen:
            continue
        seen.add(tool.name)
        if _station_tool_name(station, tool) not in station.tool_bodies:
            msg = (
                f"tool {tool.name!r} has no collision geometry in the station (no tool of that "
                "name, number or TCP): only the robot's links are checked while it is used"
            )
            step = item.step(0) if isinstance(item, PathBlock) else item
            span = step.instruction.span
            out.append(Diagnostic("warning", "collision_unchecked", msg, span, step.index))
    return out


def _scene(station: Station, step: Step, world: _World, opts: CollisionOptions) -> Scene:
    from olp.collision.scene import PairRules, Placed, build_scene

    shapes = {o.name: o for o in station.objects}
    tool = _tool_body(station, step.tool)
    carried = [Placed(n, "carried", p, shapes[n].shapes) for n, p in sorted(world.carried.items())]
    objects = [
        Placed(n, shapes[n].kind, p, shapes[n].shapes) for n, p in sorted(world.objects.items())
    ]
    rules = PairRules(
        allowed=frozenset(frozenset(p) for p in (*station.allowed_pairs, *opts.allowed_pairs)),
        tool_touches_parts=opts.tool_touches_parts,
        self_collision=opts.self_collision,
        home_contacts=opts.home_contacts,
    )
    return build_scene(station.robot, tool, carried, objects, rules)


# --------------------------------------------------------------------------------------------
# Checking a run


@dataclass(frozen=True, slots=True)
class _Found:
    """A hit located in the program."""

    first: str
    second: str
    kind: str
    ordinal: int
    step: Step
    hit: Hit


def _check_run(
    run: _Run, opts: CollisionOptions
) -> tuple[list[_Found], list[Diagnostic], CollisionStats]:
    """The hits of every pair along a run, and an error for each pair that could not be proven
    free (:class:`~olp.collision.advance.Unresolved`)."""
    from olp.collision.advance import (
        Unresolved,
        advance,
        cumulative_bounds,
        path_run,
        sample_hits,
    )

    scene = run.scene
    paths = [part.path for part in run.parts if part.path is not None]
    path = path_run(paths, scene.chain_joints, run.counts())
    found: list[_Found] = []
    failed: list[Diagnostic] = []
    evaluations = 0
    if not scene.pairs:
        return found, failed, CollisionStats(0, len(path.joints), 0)
    unique, inverse = np.unique([p.weights for p in scene.pairs], axis=0, return_inverse=True)
    which = inverse.reshape(-1)
    bounds = cumulative_bounds(path, unique) if opts.mode == "advance" else unique[:, :0]
    for k, pair in enumerate(scene.pairs):
        first, second = scene.name_of(pair)
        clearance = _clearance(pair.kind, opts)
        lower, upper = clearance - opts.tolerance_m, clearance - opts.tolerance_m / 2
        try:
            if opts.mode == "samples":
                hits, count = sample_hits(scene, pair, path, upper)
            else:
                hits, count = advance(scene, pair, path, lower, upper, bounds[int(which[k])])
        except Unresolved as exc:
            failed.append(_unresolved(run, first, second, exc))
            evaluations += exc.evaluations
            continue
        evaluations += count
        for hit in hits:
            step, ordinal = run.motion(hit.motion)
            found.append(_Found(first, second, pair.kind, ordinal, step, hit))
    return found, failed, CollisionStats(evaluations, len(path.joints), len(scene.pairs))


def _unresolved(run: _Run, first: str, second: str, exc: Unresolved) -> Diagnostic:
    step, _ = run.motion(exc.where.motion)
    message = (
        f"{first} against {second} cannot be checked from {percent(exc.where.fraction)} of "
        f"the move on: {exc.reason}"
    )
    return Diagnostic(
        "error",
        "collision_unchecked",
        message,
        step.instruction.span,
        step.index,
        joints=exc.where.joints,
    )


# --------------------------------------------------------------------------------------------
# Diagnostics


def _diagnostics(found: Sequence[_Found], opts: CollisionOptions) -> list[Diagnostic]:
    """One diagnostic per pair of bodies and run of consecutive colliding motions."""
    groups: dict[tuple[str, str, str], list[_Found]] = {}
    for f in sorted(found, key=lambda f: (f.first, f.second, f.ordinal)):
        groups.setdefault((f.first, f.second, f.kind), []).append(f)
    out = []
    for items in groups.values():
        start = 0
        for k in range(1, len(items) + 1):
            if k == len(items) or items[k].ordinal != items[k - 1].ordinal + 1:
                out.append(_diagnostic(items[start:k], _clearance(items[0].kind, opts)))
                start = k
    return sorted(out, key=lambda d: (d.index if d.index is not None else -1, d.message))


_HINTS = {
    "collision": "add a via point or change the approach so the path goes around the obstacle, "
    "or move the obstacle",
    "self_collision": "use another robot configuration (IK branch) or add a via point; if the "
    "two shapes touch by construction, declare the pair in allowed_pairs (station or robot file)",
}


def _diagnostic(items: Sequence[_Found], clearance: float) -> Diagnostic:
    first = items[0]
    hit = first.hit
    what = "self-collision: " if first.kind == "self_collision" else ""
    pair = f"{what}{first.first} hits {first.second}"
    near = f" (closer than {clearance * 1000:.1f} mm)" if hit.distance >= 0 else ""
    text = f"{pair} at {percent(hit.fraction)} of the move{near}"
    if len(items) > 1:
        text = (
            f"moves {first.step.index}-{items[-1].step.index}: {pair}{near} "
            f"(first at {percent(hit.fraction)} of move {first.step.index})"
        )
    return Diagnostic(
        "error",
        first.kind,
        text,
        first.step.instruction.span,
        first.step.index,
        joints=hit.joints,
        hint=_HINTS[first.kind],
    )


def collision_pass(compiled: CompiledProgram, options: BuildOptions) -> CompiledProgram:
    """The collision pass: :func:`check_collisions` with ``options.collisions`` (None: no
    check), its findings appended to the diagnostics."""
    if options.collisions is None:
        return compiled
    return compiled.with_diagnostics(check_collisions(compiled, options.collisions))
