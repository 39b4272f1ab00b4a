"""A collision scene: the robot's links, its tool and carried parts, and the station's objects as
one pinocchio ``GeometryModel`` (coal shapes), grouped into named bodies and checked pairs.

Everything is expressed in the robot's kinematic base frame (the frame of its pinocchio chain):
world objects are placed by ``inv(robot.base) @ pose``, so the chain's own joint frames carry the
moving bodies and distances are those of the world.

Each checked :class:`BodyPair` carries ``weights`` (nq,): a bound on how far any point of one body
can move relative to the other per unit of each chain joint (m/rad for revolute joints, m/m for
prismatic ones). For a joint-space step ``dq`` no point moves further than ``|dq| · weights`` —
see :class:`DisplacementBound` for the derivation.

Which pairs are checked
-----------------------
Every body that can move relative to another is checked against it, except (and nothing here
depends on the clearance a user asks for, so a larger clearance only adds margin):

* bodies on the same or on neighbouring joints (one rigid body, or two links sharing a joint);
* link pairs the robot library declares (``allowed_pairs`` in ``stations/robots/...``): the
  simplified shapes of some links overlap in every position by construction, and the library
  entry states each such pair with its reason, instead of olp guessing them from one pose;
* pairs of body names in :attr:`PairRules.allowed` (the station's ``allowed_pairs``,
  ``--allow-contact``): the user's decision;
* link and tool shapes *proven* to overlap in every configuration (:class:`_FixedPoints`): when
  every joint that moves one body relative to the other turns about an axis through one point
  ``p`` (a spherical wrist's centre), ``p`` is fixed relative to both bodies, so each shape's
  signed distance from ``p`` never changes. If ``depth_a(p) + depth_b(p) > 0`` (depth: how far
  ``p`` lies inside a shape, negative outside), then at every configuration the shapes overlap by
  at least that sum: the one ``p`` lies deeper in contains a ball about ``p`` that holds the
  other's nearest point to ``p``. This is decided per pair of shapes, so a tool whose bracket
  always overlaps the wrist is still checked with its other shapes;
* by choice of the caller (:attr:`PairRules.home_contacts`, off by default): link and tool pairs
  that overlap at the robot's home position. One pose proves nothing about others, so this is
  never automatic.

Pairs at a constant distance
----------------------------
Some shape pairs keep one distance in every configuration (the UR5e's link_4 and link_6 capsules:
14.7 mm; its link_1 and the bench it stands on: 0 mm). No program changes it, so checking such a
pair along every motion against a larger clearance would fail every program. These shape pairs
are listed in :attr:`Scene.constant` with their distance instead of being checked per motion
(the pass says once when one lies within the clearance asked for). Which they are is proven, not
sampled (:class:`_Proofs`). Take the joints that move one shape relative to the other, in chain
order from the shape ``n`` on the ancestor's side to the shape ``f`` beyond them:

1. A revolute joint at either end whose axis is a symmetry axis of the shape next to it does not
   change the distance. The last joint turns ``f`` about its axis; a sphere centred on that axis,
   or a capsule or cylinder along it, is mapped onto itself. The first joint turns everything
   beyond it, which as far as distances go is turning ``n`` the other way, mapped onto itself
   the same way. Such joints are dropped from either end, repeatedly: each drop holds whatever
   the other joints do, so the next test may use any configuration (the neutral one).
2. If no joint is left, the distance is that of any configuration. If the joints left all turn
   about one line ``L`` and the two shapes lie in disjoint slabs across it (coordinates along
   ``L``: ``n`` within ``[lo_n, hi_n]``, ``f`` within ``[lo_f, hi_f]``, ``hi_n <= lo_f``) and
   each contains the point of ``L`` on its facing side (at ``hi_n`` in ``n``, at ``lo_f`` in
   ``f``), the distance is ``lo_f - hi_n`` in every configuration: no two points are closer
   than their separation along ``L``, and those two points, which turning about ``L`` does not
   move, are exactly that far apart.

Everything else is checked per motion, as is a shape pair proven to overlap by more than
:data:`ALWAYS_IN_CONTACT_M` this way (a permanent overlap stays a collision, reported at every
motion, unless a rule above allows it).

Bodies farther than :data:`MAX_REACH_M` from the origin of their frame are left out of the scene
and listed in :attr:`Scene.unchecked`: beyond that, coal's distances lose the accuracy the check
needs (a box of 50 km side 10 mm below a link is reported touching), so the pass reports them
instead.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from olp.collision.shapes import coal_geometry, reach
from olp.geometry import inv
from olp.station.model import Robot, Shape

FloatArray = NDArray[np.float64]

Role = Literal["link", "tool", "carried", "part", "fixture"]
PairKind = Literal["collision", "self_collision"]

_ROBOT_SIDE: frozenset[str] = frozenset({"link", "tool", "carried"})
_FIXED_SHAPES: frozenset[str] = frozenset({"link", "tool"})

MAX_REACH_M = 1e3
"""Largest distance (m) of a body's points from the origin of the frame it moves with (the robot's
base for a part or fixture) that is checked. Measured with coal 3.0, a capsule 10 mm above a box
of side 30 km is 10 mm away to 1e-12 m; at a side of 50 km coal reports it touching. 1 km covers
any cell and leaves a factor 30."""

ALWAYS_IN_CONTACT_M = 1e-6
"""Overlap (m) two shapes must be proven to keep in every configuration to go unchecked: a
micrometre above zero, so that rounding in coal's point depths cannot turn a gap into a proof."""

ON_AXIS_M = 1e-9
"""How close (m, and rad between directions) a point or a shape's axis must lie to a joint axis
to count as on it, in the constant-distance proofs; proven distances hold to about this."""


class UnsupportedChain(ValueError):
    """A chain joint whose point motion the advancement cannot bound (not revolute/prismatic)."""


@dataclass(frozen=True, slots=True)
class Body:
    """A named rigid body of the scene.

    ``joint``: the pinocchio joint it moves with (0: fixed in the world). ``geometries``: its
    geometry object ids. ``reach``: largest distance (m) of its points from its joint's origin.
    """

    name: str
    label: str
    role: Role
    joint: int
    geometries: tuple[int, ...]
    reach: float


@dataclass(frozen=True, slots=True, eq=False)
class BodyPair:
    """Two bodies whose distance is checked: ``first`` moves with the robot.

    ``geometry_pairs``: indices into the geometry model's collision pairs (every shape of one
    body against every shape of the other). ``weights`` (nq,): point displacement bound per
    unit of chain-joint motion, m/rad (revolute) or m/m (prismatic).
    """

    first: int
    second: int
    kind: PairKind
    geometry_pairs: tuple[int, ...]
    weights: FloatArray


@dataclass(frozen=True, slots=True)
class ConstantPair:
    """Shapes of two bodies proven to keep one distance in every configuration (see the module
    text), not checked per motion: ``first`` moves with the robot; ``distance`` (m) of the
    closest of those shape pairs; ``whole``: they are all the shape pairs of the two bodies
    (otherwise the others are checked per motion as a :class:`BodyPair`)."""

    first: int
    second: int
    kind: PairKind
    distance: float
    whole: bool


@dataclass(frozen=True, slots=True)
class Placed:
    """Shapes placed rigidly on a body: ``pose`` (4, 4) in the body's frame (the world for a
    station object, the flange for a tool or a carried part)."""

    name: str
    role: Role
    pose: FloatArray
    shapes: tuple[Shape, ...]


@dataclass(frozen=True, slots=True)
class PairRules:
    """Which pairs are not checked, besides those the module text lists as never checked.

    ``allowed``: pairs of body names (either order) never checked. ``tool_touches_parts``: the
    tool (not the links) may touch and enter parts. ``self_collision``: check the robot's bodies
    against each other. ``home_contacts``: also leave out the link and tool pairs that overlap
    (signed distance below zero) at the robot's home position — a caller's choice, off by
    default, and independent of any clearance.
    """

    allowed: frozenset[frozenset[str]] = frozenset()
    tool_touches_parts: bool = True
    self_collision: bool = True
    home_contacts: bool = False


class Scene:
    """The pinocchio model with its geometry, the bodies and the checked pairs."""

    def __init__(
        self,
        model: Any,
        geometry: Any,
        bodies: Sequence[Body],
        chain_joints: Callable[[FloatArray], FloatArray],
        unchecked: Sequence[tuple[str, float]] = (),
    ) -> None:
        import pinocchio as pin

        self.chain_joints = chain_joints
        """Controller joints (..., dof) -> the model's configuration (..., nq)."""
        self.model = model
        self.geometry = geometry
        self.bodies = tuple(bodies)
        self.unchecked = tuple(unchecked)
        """(label, reach in m) of the bodies left out for lying beyond :data:`MAX_REACH_M`."""
        self.pairs: tuple[BodyPair, ...] = ()
        self.constant: tuple[ConstantPair, ...] = ()
        """Shape pairs at a proven constant distance, not in :attr:`pairs`."""
        self._pin = pin
        self._data = model.createData()
        self._gdata: Any = None

    def finalize(self, pairs: Sequence[BodyPair]) -> None:
        """Set the checked pairs (their geometry pairs must be registered already)."""
        self.pairs = tuple(pairs)
        self._gdata = self._pin.GeometryData(self.geometry)

    def place(self, q_chain: FloatArray) -> None:
        """Move every geometry to chain configuration ``q_chain`` (nq,)."""
        self._pin.forwardKinematics(self.model, self._data, q_chain)
        self._pin.updateGeometryPlacements(self.model, self._data, self.geometry, self._gdata)

    def distance(self, pair: BodyPair) -> float:
        """Signed distance (m, negative = penetration depth) of a pair at the last
        :meth:`place`: the least over its shape pairs."""
        compute, geometry, gdata = self._pin.computeDistance, self.geometry, self._gdata
        return min(compute(geometry, gdata, k).min_distance for k in pair.geometry_pairs)

    def name_of(self, pair: BodyPair | ConstantPair) -> tuple[str, str]:
        return self.bodies[pair.first].label, self.bodies[pair.second].label


def build_scene(
    robot: Robot,
    tool: Placed | None,
    carried: Sequence[Placed],
    objects: Sequence[Placed],
    rules: PairRules,
) -> Scene:
    """The scene of ``robot`` with its ``tool`` and ``carried`` parts (poses in the flange frame)
    among world ``objects`` (poses in the world frame), with the pairs ``rules`` check.

    Raises :class:`UnsupportedChain` for chain joints other than revolute or prismatic.
    """
    import pinocchio as pin

    model = robot.kinematics.chain_model()
    builder = _Builder(pin.GeometryModel())
    for link, (joint, frame) in _link_frames(model, robot).items():
        shapes = tuple(s for s in robot.collision if s.link == link)
        builder.add(Placed(link, "link", frame, shapes), f"robot {link}", joint)
    flange_joint, flange = _flange(model, robot)
    if tool is not None:
        builder.add(
            dataclasses.replace(tool, pose=flange @ tool.pose), f"tool {tool.name!r}", flange_joint
        )
    for part in carried:
        label = f"carried part {part.name!r}"
        builder.add(dataclasses.replace(part, pose=flange @ part.pose), label, flange_joint)
    world = inv(robot.base)
    for obj in objects:
        builder.add(dataclasses.replace(obj, pose=world @ obj.pose), f"{obj.role} {obj.name!r}", 0)
    chain = robot.kinematics.chain_joints
    scene = Scene(model, builder.geometry, builder.bodies, chain, builder.unchecked)
    bound = DisplacementBound(model, robot)
    links = frozenset(frozenset(p) for p in robot.allowed_pairs)
    proofs = _Proofs(scene)
    pairs, constant = [], []
    for i, j in _candidate_pairs(model, builder.bodies, rules, links):
        a, b = scene.bodies[i], scene.bodies[j]
        varying, distances = proofs.split_constant(a, b, proofs.unproven(a, b))
        if varying:
            pairs.append(_register(scene, i, j, varying, bound))
        if distances:
            first, second, kind = _oriented(scene, i, j)
            whole = len(distances) == len(a.geometries) * len(b.geometries)
            constant.append(ConstantPair(first, second, kind, min(distances), whole))
    scene.finalize(pairs)
    scene.constant = tuple(constant)
    if rules.home_contacts and rules.self_collision:
        scene.pairs = _without_home_contacts(scene, robot)
    return scene


@dataclass(slots=True)
class _Builder:
    """Collects geometry objects and the bodies they make up."""

    geometry: Any
    bodies: list[Body] = field(default_factory=list)
    unchecked: list[tuple[str, float]] = field(default_factory=list)

    def add(self, placed: Placed, label: str, joint: int) -> None:
        """Add a body made of ``placed.shapes`` at ``placed.pose`` in ``joint``'s frame, unless
        it reaches beyond :data:`MAX_REACH_M` (then it is listed in ``unchecked``)."""
        import pinocchio as pin

        if not placed.shapes:
            return
        with np.errstate(over="ignore", invalid="ignore"):  # 1e300 m squared: inf, then refused
            radius = max(reach(s, placed.pose) for s in placed.shapes)
        if not radius <= MAX_REACH_M:
            self.unchecked.append((label, radius))
            return
        ids = []
        for k, shape in enumerate(placed.shapes):
            placement = pin.SE3(placed.pose @ shape.pose)
            obj = pin.GeometryObject(f"{placed.name}#{k}", joint, placement, coal_geometry(shape))
            ids.append(self.geometry.addGeometryObject(obj))
        self.bodies.append(Body(placed.name, label, placed.role, joint, tuple(ids), radius))


def _flange(model: Any, robot: Robot) -> tuple[int, FloatArray]:
    """The joint the flange moves with and the flange pose (4, 4) in that joint's frame."""
    frame = model.frames[model.getFrameId("tool0")]
    return int(frame.parentJoint), np.asarray(frame.placement.homogeneous) @ robot.flange_in_tool0


def _link_frames(model: Any, robot: Robot) -> dict[str, tuple[int, FloatArray]]:
    """Each collision link name -> (joint, link frame (4, 4) in that joint's frame)."""
    out: dict[str, tuple[int, FloatArray]] = {"base": (0, np.eye(4))}
    for link in {s.link for s in robot.collision} - {"base"}:
        frame = model.frames[model.getFrameId(link)]
        out[link] = (int(frame.parentJoint), np.asarray(frame.placement.homogeneous))
    return dict(sorted(out.items(), key=lambda item: (item[1][0], item[0])))


def _register(
    scene: Scene, i: int, j: int, shapes: Sequence[tuple[int, int]], bound: DisplacementBound
) -> BodyPair:
    """Register the geometry pairs ``shapes`` of bodies i and j as one checked pair."""
    import pinocchio as pin

    i, j, kind = _oriented(scene, i, j)
    start = len(scene.geometry.collisionPairs)
    for ga, gb in shapes:
        scene.geometry.addCollisionPair(pin.CollisionPair(ga, gb))
    a, b = scene.bodies[i], scene.bodies[j]
    return BodyPair(i, j, kind, tuple(range(start, start + len(shapes))), bound.pair(a, b))


def _oriented(scene: Scene, i: int, j: int) -> tuple[int, int, PairKind]:
    """Bodies i and j with the one that moves with the robot first, and the pair's kind."""
    if scene.bodies[i].joint == 0:
        i, j = j, i
    kind: PairKind = "self_collision" if scene.bodies[j].role in _ROBOT_SIDE else "collision"
    return i, j, kind


def _candidate_pairs(
    model: Any, bodies: Sequence[Body], rules: PairRules, links: frozenset[frozenset[str]]
) -> list[tuple[int, int]]:
    """Body index pairs to check: something moving against anything it could meet.
    ``links``: the robot's allowed link pairs (they name links only, never a station body)."""
    out = []
    for i, a in enumerate(bodies):
        for j in range(i + 1, len(bodies)):
            b = bodies[j]
            if _checked(model, a, b, rules, links):
                out.append((i, j))
    return out


def _checked(
    model: Any, a: Body, b: Body, rules: PairRules, links: frozenset[frozenset[str]]
) -> bool:
    names = frozenset((a.name, b.name))
    if a.joint == b.joint or names in rules.allowed:
        return False  # one rigid body (or two fixed ones), or declared allowed
    if a.role == b.role == "link" and names in links:
        return False  # the robot library: overlapping by construction
    robot_side = a.role in _ROBOT_SIDE and b.role in _ROBOT_SIDE
    if robot_side:
        adjacent = model.parents[a.joint] == b.joint or model.parents[b.joint] == a.joint
        return rules.self_collision and not adjacent
    roles = {a.role, b.role}
    return not (rules.tool_touches_parts and roles == {"tool", "part"})


def _without_home_contacts(scene: Scene, robot: Robot) -> tuple[BodyPair, ...]:
    """The scene's pairs without the link/tool pairs that overlap at the robot's home."""
    scene.place(np.asarray(robot.kinematics.chain_joints(robot.home), dtype=np.float64))

    def touching(pair: BodyPair) -> bool:
        roles = {scene.bodies[pair.first].role, scene.bodies[pair.second].role}
        return pair.kind == "self_collision" and roles <= _FIXED_SHAPES and scene.distance(pair) < 0

    return tuple(p for p in scene.pairs if not touching(p))


class _Proofs:
    """What holds in every configuration: link and tool shape pairs proven to overlap (the
    fixed-point argument) and shape pairs of any bodies proven to keep one distance (the
    symmetry and slab argument), both from the module text.

    The geometry is taken at the chain's neutral configuration: the joint axes, which point the
    joints between two bodies leave fixed, each shape's depth at that point and its symmetry
    about an axis are the same in every configuration, so any one configuration serves (it is
    not a sample of many).
    """

    def __init__(self, scene: Scene) -> None:
        import pinocchio as pin

        self._scene = scene
        model = scene.model
        data = model.createData()
        # World-frame joint twists (v at the world origin, then ω) as columns (6, nv).
        self._twists = np.array(pin.computeJointJacobians(model, data, pin.neutral(model)))
        gdata = pin.GeometryData(scene.geometry)
        pin.updateGeometryPlacements(model, data, scene.geometry, gdata)
        self._placements = [gdata.oMg[k] for k in range(scene.geometry.ngeoms)]
        self._axes = [None, *(self._axis(j) for j in range(1, model.njoints))]
        self._symmetric: dict[tuple[int, int], bool] = {}

    def unproven(self, a: Body, b: Body) -> list[tuple[int, int]]:
        """The shape pairs (geometry ids) of bodies ``a`` and ``b`` not proven in contact."""
        shapes = [(ga, gb) for ga in a.geometries for gb in b.geometries]
        if a.role not in _FIXED_SHAPES or b.role not in _FIXED_SHAPES:
            return shapes
        point = self._fixed_point(set(self._chain(a.joint)) ^ set(self._chain(b.joint)))
        if point is None:
            return shapes
        depth = {g: self._depth(g, point) for g in (*a.geometries, *b.geometries)}
        return [(ga, gb) for ga, gb in shapes if depth[ga] + depth[gb] <= ALWAYS_IN_CONTACT_M]

    def split_constant(
        self, a: Body, b: Body, shapes: Sequence[tuple[int, int]]
    ) -> tuple[list[tuple[int, int]], list[float]]:
        """``shapes`` (geometry id pairs of bodies ``a`` and ``b``) split into those whose
        distance varies or is not proven constant, and the constant distances (m) of the others.
        A pair proven to overlap by more than :data:`ALWAYS_IN_CONTACT_M` counts as varying: it
        stays checked."""
        path = self._path(a.joint, b.joint)
        varying, distances = [], []
        for ga, gb in shapes:
            near, far = (ga, gb) if path is not None and path[1] else (gb, ga)
            d = None if path is None else self._constant_distance(near, far, path[0])
            if d is None or d < -ALWAYS_IN_CONTACT_M:
                varying.append((ga, gb))
            else:
                distances.append(d)
        return varying, distances

    def _chain(self, joint: int) -> list[int]:
        out = []
        while joint > 0:
            out.append(joint)
            joint = self._scene.model.parents[joint]
        return out

    def _path(self, first: int, second: int) -> tuple[list[int], bool] | None:
        """The joints between two bodies' joints in chain order from the ancestor's side, and
        whether ``first`` is the ancestor; None if neither is an ancestor of the other."""
        up, down = self._chain(first), self._chain(second)
        if set(up) <= set(down):
            return sorted(set(down) - set(up)), True
        if set(down) <= set(up):
            return sorted(set(up) - set(down)), False
        return None

    def _constant_distance(self, near: int, far: int, joints: list[int]) -> float | None:
        """The distance (m) of shapes ``near`` and ``far`` if ``joints`` (chain order, from
        ``near``'s side) cannot change it, else None (steps 1 and 2 of the module text)."""
        left = list(joints)
        while left:
            if self._turns_in_place(far, left[-1]):
                left.pop()
            elif self._turns_in_place(near, left[0]):
                left.pop(0)
            else:
                break
        if not left:
            return self._distance(near, far)
        axes = [self._axes[j] for j in left]
        line = axes[0]
        if line is None or any(axis is None or not _same_line(axis, line) for axis in axes):
            return None
        return self._slab_gap(near, far, line)

    def _turns_in_place(self, geometry: int, joint: int) -> bool:
        """Whether ``joint`` turning maps the shape onto itself (remembered per pair)."""
        key = geometry, joint
        if key not in self._symmetric:
            axis = self._axes[joint]
            self._symmetric[key] = axis is not None and _symmetric_about(
                self._shape(geometry), axis
            )
        return self._symmetric[key]

    def _axis(self, joint: int) -> tuple[FloatArray, FloatArray] | None:
        """A revolute joint's axis as (a point on it, unit direction), world frame, neutral
        configuration; None for a joint that does not turn (prismatic)."""
        column = self._twists[:, self._scene.model.joints[joint].idx_v]
        v, w = column[:3], column[3:]
        norm = float(np.linalg.norm(w))
        if norm < 0.5:  # a unit twist: |ω| is 1 for a revolute joint, 0 for a prismatic one
            return None
        return _cross(w, v) / norm**2, w / norm

    def _shape(self, geometry: int) -> tuple[Any, FloatArray, FloatArray]:
        """(coal geometry, rotation (3, 3), translation (3,)) of a shape, world frame, neutral."""
        placement = self._placements[geometry]
        obj = self._scene.geometry.geometryObjects[geometry].geometry
        return obj, np.asarray(placement.rotation), np.asarray(placement.translation)

    def _slab_gap(self, near: int, far: int, line: tuple[FloatArray, FloatArray]) -> float | None:
        """The distance of two shapes turning about ``line`` relative to each other, if they
        lie in disjoint slabs across it and touch it on their facing sides (step 2), else None."""
        origin, direction = line
        near_extent = _extent(self._shape(near), direction)
        far_extent = _extent(self._shape(far), direction)
        if near_extent is None or far_extent is None:
            return None
        (low_n, high_n), (low_f, high_f) = near_extent, far_extent
        if high_n <= low_f:
            ends = ((near, high_n), (far, low_f))
        elif high_f <= low_n:
            ends = ((near, low_n), (far, high_f))
        else:
            return None
        for geometry, level in ends:
            point = origin + (level - float(origin @ direction)) * direction
            if self._depth(geometry, point) < -ON_AXIS_M:
                return None
        return float(abs(ends[1][1] - ends[0][1]))

    def _fixed_point(self, joints: set[int]) -> FloatArray | None:
        """The point (3,) that no joint in ``joints`` moves: ``v + ω × p = 0`` for every twist
        column, solved in least squares; None if it does not hold (to 1e-9 m/rad), e.g. for
        parallel axes or a prismatic joint."""
        if not joints:
            return None
        model = self._scene.model
        columns = [
            self._twists[:, model.joints[j].idx_v : model.joints[j].idx_v + model.joints[j].nv]
            for j in sorted(joints)
        ]
        twists = np.concatenate(columns, axis=1).T
        lhs = np.concatenate([_skew(w) for w in twists[:, 3:]])
        rhs = -twists[:, :3].reshape(-1)
        point = np.linalg.lstsq(lhs, rhs, rcond=None)[0]
        return point if np.max(np.abs(lhs @ point - rhs)) <= 1e-9 else None

    def _depth(self, geometry: int, point: FloatArray) -> float:
        """How far ``point`` (3,) lies inside a shape (m; negative: its distance outside)."""
        import coal

        return -self._signed_distance(geometry, coal.Sphere(0.0), np.eye(3), point)

    def _distance(self, first: int, second: int) -> float:
        """Signed distance (m) of two shapes at the neutral configuration."""
        other = self._placements[second]
        obj = self._scene.geometry.geometryObjects[second].geometry
        return self._signed_distance(first, obj, other.rotation, other.translation)

    def _signed_distance(
        self, geometry: int, other: Any, rotation: FloatArray, translation: FloatArray
    ) -> float:
        """Signed distance (m) of a shape (neutral placement) and coal geometry ``other`` placed
        by ``rotation`` (3, 3) and ``translation`` (3,)."""
        import coal

        placement = self._placements[geometry]
        shape = coal.Transform3s(placement.rotation, placement.translation)
        obj = self._scene.geometry.geometryObjects[geometry].geometry
        there = coal.Transform3s(rotation, translation)
        result = coal.DistanceResult()
        return float(coal.distance(obj, shape, other, there, coal.DistanceRequest(), result))


def _symmetric_about(
    shape: tuple[Any, FloatArray, FloatArray], axis: tuple[FloatArray, FloatArray]
) -> bool:
    """Whether turning about ``axis`` (point, unit direction) maps ``shape`` onto itself: a
    sphere centred on the axis, a capsule or cylinder along it (to :data:`ON_AXIS_M`)."""
    import coal

    obj, rotation, centre = shape
    if not _on_line(centre, axis):
        return False
    if isinstance(obj, coal.Sphere):
        return True
    if isinstance(obj, (coal.Capsule, coal.Cylinder)):
        return _parallel(rotation[:, 2], axis[1])
    return False


def _on_line(point: FloatArray, line: tuple[FloatArray, FloatArray]) -> bool:
    origin, direction = line
    return _parallel(point - origin, direction)


def _same_line(a: tuple[FloatArray, FloatArray], b: tuple[FloatArray, FloatArray]) -> bool:
    return _on_line(a[0], b) and _parallel(a[1], b[1])


def _parallel(a: FloatArray, b: FloatArray) -> bool:
    """Whether ``|a × b| <= ON_AXIS_M`` (for a unit ``b``: ``a`` lies along it)."""
    c = _cross(a, b)
    return math.sqrt(float(c @ c)) <= ON_AXIS_M


def _cross(a: FloatArray, b: FloatArray) -> FloatArray:
    """``a × b`` of two 3-vectors (numpy's cross costs some 20 µs per call)."""
    return np.array(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


def _extent(
    shape: tuple[Any, FloatArray, FloatArray], direction: FloatArray
) -> tuple[float, float] | None:
    """The least and largest ``direction · x`` (m) over the points x of a shape (its support
    in ``-direction`` and ``direction``); a mesh counts as its convex hull. None for a kind of
    geometry this does not know."""
    import coal

    obj, rotation, centre = shape
    local = rotation.T @ direction  # the direction in the shape's frame
    middle = float(centre @ direction)
    if isinstance(obj, coal.Convex):
        levels = np.asarray(obj.points()) @ local
        return middle + float(levels.min()), middle + float(levels.max())
    if isinstance(obj, coal.Sphere):
        half = obj.radius
    elif isinstance(obj, coal.Capsule):
        half = obj.halfLength * abs(local[2]) + obj.radius
    elif isinstance(obj, coal.Cylinder):
        half = obj.halfLength * abs(local[2]) + obj.radius * np.sqrt(max(0.0, 1 - local[2] ** 2))
    elif isinstance(obj, coal.Box):
        half = float(np.abs(local) @ np.asarray(obj.halfSide))
    else:
        return None
    return middle - half, middle + half


def _skew(w: FloatArray) -> FloatArray:
    """The matrix (3, 3) of ``p -> w × p``."""
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


# --------------------------------------------------------------------------------------------
# Displacement bounds


_REVOLUTE = frozenset(
    {"JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned"}
)
_PRISMATIC = frozenset(
    {"JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned"}
)


def joint_kinds(model: Any) -> list[str]:
    """``"revolute"`` or ``"prismatic"`` for each joint 1..njoints-1 of a chain model; raises
    :class:`UnsupportedChain` for any other kind of joint."""
    kinds = []
    for j in range(1, model.njoints):
        name = model.joints[j].shortname()
        if name not in _REVOLUTE | _PRISMATIC:
            raise UnsupportedChain(
                f"joint {model.names[j]!r} ({name}) is neither revolute nor prismatic"
            )
        kinds.append("revolute" if name in _REVOLUTE else "prismatic")
    return kinds


class DisplacementBound:
    """Bounds on how far points of the scene's bodies move per unit of chain-joint motion.

    Along a straight joint-space step ``dq`` a point p of a body on joint ``b`` moves relative to
    the frame of joint ``c`` (an ancestor, 0 = the world) with speed at most
    ``sum_m |dq_m| · w_m`` over the joints m from c (exclusive) to b: a revolute joint turns p
    about its axis, which passes through its origin ``o_m``, so p's speed from it is
    ``|dq_m| · dist(p, axis) <= |dq_m| · |p - o_m|``, and ``|p - o_m| <= reach + sum
    |o_l - o_parent(l)|`` over the joints l after m up to b (constant joint offsets; a
    prismatic joint l adds its largest travel within the limits); a prismatic joint moves every
    point by exactly ``|dq_m|``. Two bodies are bounded relative to their deepest common joint:
    the sum of both bounds. The distance between two bodies changes no faster than their
    relative point motion.
    """

    def __init__(self, model: Any, robot: Robot) -> None:
        kinds = ["fixed", *joint_kinds(model)]
        self._model = model
        self._kinds = kinds
        self._offsets = [
            float(np.linalg.norm(model.jointPlacements[j].translation))
            for j in range(model.njoints)
        ]
        self._travel = _prismatic_travel(model, robot, kinds)

    def _chain_to(self, joint: int) -> list[int]:
        out = []
        while joint > 0:
            out.append(joint)
            joint = self._model.parents[joint]
        return out[::-1]

    def body(self, body: Body, below: int = 0) -> FloatArray:
        """Weights (nq,) of ``body``'s motion relative to joint ``below`` (0: the world)."""
        w = np.zeros(self._model.nq)
        path = self._chain_to(body.joint)
        path = path[path.index(below) + 1 :] if below in path else path
        for k, m in enumerate(path):
            q_index = self._model.joints[m].idx_q
            if self._kinds[m] == "prismatic":
                w[q_index] += 1.0
            else:
                lever = sum(self._offsets[n] + self._travel[n] for n in path[k + 1 :])
                w[q_index] += body.reach + lever
        return w

    def pair(self, a: Body, b: Body) -> FloatArray:
        """Weights (nq,) of the relative motion of two bodies."""
        common = set(self._chain_to(a.joint)) & set(self._chain_to(b.joint))
        c = max(common, default=0)
        return self.body(a, c) + self.body(b, c)


def _prismatic_travel(model: Any, robot: Robot, kinds: list[str]) -> list[float]:
    """Largest |q| (m) of each prismatic chain joint within the robot's joint limits (0 for
    revolute joints). Chain joints are ``C · q`` (a joint coupling), so ``|C| · max|q|``."""
    coupling = np.asarray(robot.kinematics.chain_joints(np.eye(robot.dof)), dtype=np.float64).T
    largest = np.maximum(np.abs(robot.limits.lower), np.abs(robot.limits.upper))
    chain = np.abs(coupling) @ largest
    out = [0.0] * model.njoints
    for j, kind in enumerate(kinds):
        if kind == "prismatic":
            out[j] = float(chain[model.joints[j].idx_q])
    return out
