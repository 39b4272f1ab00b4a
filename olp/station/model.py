"""The station: one robot with its limits, its tools and frames, parts and fixtures, placed in a
world frame.

All values are SI (metres, radians, seconds, kilograms). Loading from YAML (mm, degrees) happens
in :mod:`olp.station.loader`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.geometry import inv
from olp.ir import FLANGE, WORLD, Frame, Tool
from olp.kinematics.base import Kinematics

FloatArray = NDArray[np.float64]

ShapeKind = Literal["box", "cylinder", "capsule", "sphere", "mesh"]


def _frozen(value: ArrayLike, shape: tuple[int, ...]) -> FloatArray:
    arr = np.array(value, dtype=np.float64)
    if arr.shape != shape:
        raise ValueError(f"expected an array of shape {shape}, got {arr.shape}")
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, slots=True, eq=False)
class JointLimits:
    """Per-joint limits, shape (dof,) each: position (rad), velocity (rad/s), acceleration
    (rad/s²), jerk (rad/s³). Controller joint convention.

    ``path_acceleration`` (m/s², optional): the controller's own TCP path acceleration, which
    bounds path moves whose program sets none (KUKA's ``$ACC.CP`` default from the BAS
    initialisation; fitted by ``olp time --calibrate``). None: only the joints bound it.
    """

    lower: FloatArray
    upper: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    jerk: FloatArray
    path_acceleration: float | None = None

    def __post_init__(self) -> None:
        dof = np.shape(self.lower)[0] if np.ndim(self.lower) == 1 else -1
        for name in ("lower", "upper", "velocity", "acceleration", "jerk"):
            arr = np.array(getattr(self, name), dtype=np.float64)
            if arr.shape != (dof,):
                raise ValueError(f"joint limits: {name} must have shape ({dof},)")
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        if np.any(self.lower >= self.upper):
            raise ValueError("joint limits: every lower limit must be below its upper limit")
        for name in ("velocity", "acceleration", "jerk"):
            if np.any(getattr(self, name) <= 0):
                raise ValueError(f"joint limits: {name} limits must be positive")
        a = self.path_acceleration
        if a is not None and not (math.isfinite(a) and a > 0):
            raise ValueError("joint limits: the path acceleration must be a positive number")

    def violations(self, joints: ArrayLike, tol: float = 1e-9) -> NDArray[np.bool_]:
        """Boolean mask (..., dof): which joints lie outside [lower, upper] (with tolerance)."""
        q = np.asarray(joints, dtype=np.float64)
        return (q < self.lower - tol) | (q > self.upper + tol)


@dataclass(frozen=True, slots=True, eq=False)
class MeshHull:
    """The convex hull of a mesh in its shape's frame: ``vertices`` (V, 3) m and outward
    triangles ``faces`` (F, 3), indices into ``vertices``. Read-only arrays."""

    vertices: FloatArray
    faces: NDArray[np.int64]

    def __post_init__(self) -> None:
        vertices = np.array(self.vertices, dtype=np.float64)
        faces = np.array(self.faces, dtype=np.int64)
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise ValueError(f"MeshHull: vertices must be (V, 3), got {vertices.shape}")
        if faces.ndim != 2 or faces.shape[1] != 3:
            raise ValueError(f"MeshHull: faces must be (F, 3), got {faces.shape}")
        if faces.size and (faces.min() < 0 or faces.max() >= len(vertices)):
            raise ValueError("MeshHull: faces must index into vertices")
        vertices.setflags(write=False)
        faces.setflags(write=False)
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "faces", faces)


@dataclass(frozen=True, slots=True, eq=False)
class Shape:
    """A body's geometry: a primitive or a mesh, placed by ``pose`` (4, 4) in its parent frame.

    ``kind`` and ``size`` (metres): ``box`` (x, y, z edge lengths, centred on the pose);
    ``cylinder`` (radius, length) and ``capsule`` (radius, length of its core segment), both
    along the pose's Z axis and centred on it; ``sphere`` (radius,); ``mesh``: the file ``mesh``
    scaled by ``scale`` (file units to metres). ``link``: for a robot's collision model, the
    link frame the shape moves with (``"base"`` or a link of the kinematic chain). ``hull``:
    a mesh's convex hull as the station loader read and checked it (None when the shape was
    made in code; then the file is read when needed).
    """

    kind: ShapeKind
    pose: FloatArray = field(default_factory=lambda: np.eye(4))
    size: tuple[float, ...] = ()
    mesh: str | None = None
    scale: float = 1.0
    link: str = ""
    hull: MeshHull | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "pose", _frozen(self.pose, (4, 4)))
        expected = {"box": 3, "cylinder": 2, "capsule": 2, "sphere": 1, "mesh": 0}[self.kind]
        if len(self.size) != expected or any(not s > 0 for s in self.size):
            raise ValueError(f"{self.kind}: expected {expected} positive sizes, got {self.size}")
        if (self.kind == "mesh") != (self.mesh is not None):
            raise ValueError("a mesh shape (and only a mesh shape) names a mesh file")
        if self.hull is not None and self.kind != "mesh":
            raise ValueError(f"a {self.kind} has no mesh hull")

    def contains(self, points: ArrayLike, frame: ArrayLike | None = None) -> NDArray[np.bool_]:
        """Which points (..., 3), metres in ``frame``'s coordinates (default: the parent frame,
        else ``frame`` (4, 4) is the parent's pose), lie inside this primitive.

        Meshes are not handled here (use :meth:`load_mesh`): a ValueError.
        """
        parent = np.eye(4) if frame is None else np.asarray(frame, dtype=np.float64)
        local = inv(parent @ self.pose)
        p = np.asarray(points, dtype=np.float64) @ local[:3, :3].T + local[:3, 3]
        if self.kind == "box":
            return np.all(np.abs(p) <= np.asarray(self.size) / 2, axis=-1)
        if self.kind == "sphere":
            return np.linalg.norm(p, axis=-1) <= self.size[0]
        radius, length = self.size
        radial = np.hypot(p[..., 0], p[..., 1])
        if self.kind == "cylinder":
            return (radial <= radius) & (np.abs(p[..., 2]) <= length / 2)
        if self.kind == "capsule":
            z = np.clip(p[..., 2], -length / 2, length / 2)
            return np.hypot(radial, p[..., 2] - z) <= radius
        raise ValueError("Shape.contains: meshes are not primitives; load the mesh")

    def load_mesh(self) -> Any:
        """The mesh as a ``trimesh.Trimesh`` in metres (in the shape's own frame), read under
        the rules of :func:`olp.station.meshes.read_mesh` (a ``MeshError`` if it breaks one)."""
        if self.mesh is None:
            raise ValueError(f"a {self.kind} has no mesh file")
        from olp.station.meshes import read_mesh

        mesh = read_mesh(Path(self.mesh))
        mesh.apply_scale(self.scale)
        return mesh


@dataclass(frozen=True, slots=True, eq=False)
class Robot:
    """A serial robot arm placed in a station.

    ``kinematics``: forward/inverse kinematics in the controller's joint convention
    (:class:`olp.kinematics.base.Kinematics`: OPW, UR or a numeric chain).
    ``base``: pose (4, 4) of the robot's kinematic base (its mounting face) in the station's
    world frame. ``flange_in_tool0``: the vendor's flange frame in the kinematic model's tool0
    frame (identity except for vendors whose flange is not Z-out, see :mod:`olp.vendors`).
    ``controller_base``: the controller's own robot base frame (KUKA ROBROOT, ABB base, Fanuc
    World at axis-2 height, UR Base) in the kinematic base frame. ``collision``: shapes in link
    frames (``Shape.link``), simple approximations of the links. ``allowed_pairs``: pairs of link
    names whose shapes overlap in every position by construction of that approximation (the
    robot library states each with its reason); they are never checked against each other.
    """

    name: str
    vendor: str
    kinematics: Kinematics
    limits: JointLimits
    home: FloatArray
    base: FloatArray = field(default_factory=lambda: np.eye(4))
    flange_in_tool0: FloatArray = field(default_factory=lambda: np.eye(4))
    controller_base: FloatArray = field(default_factory=lambda: np.eye(4))
    collision: tuple[Shape, ...] = ()
    allowed_pairs: tuple[tuple[str, str], ...] = ()

    @property
    def dof(self) -> int:
        return int(self.kinematics.dof)

    def flange_poses(self, joints: ArrayLike) -> FloatArray:
        """Flange poses in the world frame for joints (..., dof) rad; shape (..., 4, 4)."""
        tool0 = self.kinematics.forward(np.asarray(joints, dtype=np.float64))
        out: FloatArray = self.base @ tool0 @ self.flange_in_tool0
        return out

    def solve(self, flange_world: ArrayLike, seed: ArrayLike | None = None) -> FloatArray:
        """All IK solutions for flange poses (N, 4, 4) in the world frame: (N, B, dof), NaN rows
        where a branch has no solution (B = ``len(kinematics.branch_names)``). Joint limits are
        not applied here. ``seed`` (dof,) only matters for numeric kinematics (row 0)."""
        poses = np.asarray(flange_world, dtype=np.float64)
        tool0 = inv(self.base) @ poses @ inv(self.flange_in_tool0)
        return self.kinematics.inverse(tool0, seed=seed)

    def branch_of(self, joints: ArrayLike) -> int:
        """Index of the IK branch (a row of :meth:`solve`) that ``joints`` (dof,) lie in."""
        q = np.asarray(joints, dtype=np.float64)
        sols = self.solve(self.flange_poses(q)[None], seed=q)[0]
        diff = (sols - q + np.pi) % (2 * np.pi) - np.pi
        dist = np.where(np.all(np.isfinite(sols), axis=-1), np.sum(diff**2, axis=-1), np.inf)
        return int(np.argmin(dist))

    def link_poses(self, joints: ArrayLike) -> dict[str, FloatArray]:
        """World poses (4, 4) of ``"base"`` and every body frame of the kinematic chain for
        controller joints (dof,) rad (pinocchio; what :attr:`collision` shapes attach to)."""
        import pinocchio as pin

        model = self.kinematics.chain_model()
        data = model.createData()
        pin.framesForwardKinematics(model, data, self.kinematics.chain_joints(joints))
        out = {"base": self.base.copy()}
        for i, frame in enumerate(model.frames):
            if frame.type == pin.FrameType.BODY:
                out[frame.name] = self.base @ np.asarray(data.oMf[i].homogeneous)
        return out


@dataclass(frozen=True, slots=True, eq=False)
class ToolBody:
    """What a tool is physically: its mass (kg, None when unknown) and shapes in the flange
    frame."""

    mass: float | None = None
    shapes: tuple[Shape, ...] = ()


@dataclass(frozen=True, slots=True, eq=False)
class StationObject:
    """A part (what the robot works on) or a fixture (what holds it): ``pose`` (4, 4) in the
    world frame, ``shapes`` in the object's frame; ``frame``: the station frame it was placed in
    (``"world"`` when none)."""

    name: str
    kind: Literal["part", "fixture"]
    pose: FloatArray
    shapes: tuple[Shape, ...]
    frame: str = "world"

    def __post_init__(self) -> None:
        object.__setattr__(self, "pose", _frozen(self.pose, (4, 4)))


@dataclass(frozen=True, slots=True, eq=False)
class NamedTarget:
    """A target the station names (RoboDK's target items): either a Cartesian ``pose`` (4, 4)
    of the TCP in ``frame``, metres, or controller ``joints`` (dof,) rad. ``frame`` is a station
    frame or ``"world"``; a joint target keeps it as its place in the item tree."""

    name: str
    frame: str = "world"
    pose: FloatArray | None = None
    joints: FloatArray | None = None

    def __post_init__(self) -> None:
        if (self.pose is None) == (self.joints is None):
            raise ValueError(f"target {self.name!r}: give a pose or joints, exactly one")
        if self.pose is not None:
            object.__setattr__(self, "pose", _frozen(self.pose, (4, 4)))
        if self.joints is not None:
            joints = np.array(self.joints, dtype=np.float64)
            object.__setattr__(self, "joints", _frozen(joints, joints.shape))


@dataclass(frozen=True, slots=True, eq=False)
class Station:
    """A robot cell: the robot, named tools (TCP in flange) and frames (pose in world), the
    tools' bodies, each frame's parent frame, and the parts and fixtures. ``allowed_pairs``: pairs
    of body names (robot links, tools, parts, fixtures) the station allows to touch: never checked
    for collisions. ``targets``: the station's named targets (:class:`NamedTarget`) by name."""

    name: str
    robot: Robot
    tools: Mapping[str, Tool] = field(default_factory=dict)
    frames: Mapping[str, Frame] = field(default_factory=dict)
    source: str = "<memory>"
    tool_bodies: Mapping[str, ToolBody] = field(default_factory=dict)
    frame_parents: Mapping[str, str] = field(default_factory=dict)
    objects: tuple[StationObject, ...] = ()
    allowed_pairs: tuple[tuple[str, str], ...] = ()
    targets: Mapping[str, NamedTarget] = field(default_factory=dict)

    def tool(self, ref: Tool) -> Tool | None:
        """The station's definition for a tool reference (by name, then number), or None."""
        return _lookup(ref.name, ref.number, self.tools, FLANGE)

    def frame(self, ref: Frame) -> Frame | None:
        """The station's definition for a frame reference (by name, then number), or None."""
        return _lookup(ref.name, ref.number, self.frames, WORLD)


_T = TypeVar("_T", Tool, Frame)


def _lookup(name: str, number: int | None, table: Mapping[str, _T], null: _T) -> _T | None:
    if name in table:
        return table[name]
    if number is not None:
        for item in table.values():
            if item.number == number:
                return item
        if number == 0:
            return null
    return None
