"""The station: one robot with its limits, its tools and frames, placed in a world frame.

All values are SI (metres, radians, seconds). Loading from YAML (mm, degrees) happens in
:mod:`olp.station.loader`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.geometry import inv
from olp.ir import FLANGE, WORLD, Frame, Tool
from olp.kinematics import opw

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class JointLimits:
    """Per-joint limits, shape (6,) each: position (rad), velocity (rad/s), acceleration (rad/s²),
    jerk (rad/s³). Controller joint convention."""

    lower: FloatArray
    upper: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    jerk: FloatArray

    def __post_init__(self) -> None:
        for name in ("lower", "upper", "velocity", "acceleration", "jerk"):
            arr = np.array(getattr(self, name), dtype=np.float64)
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        if np.any(self.lower >= self.upper):
            raise ValueError("joint limits: every lower limit must be below its upper limit")
        for name in ("velocity", "acceleration", "jerk"):
            if np.any(getattr(self, name) <= 0):
                raise ValueError(f"joint limits: {name} limits must be positive")

    def violations(self, joints: ArrayLike, tol: float = 1e-9) -> NDArray[np.bool_]:
        """Boolean mask (..., 6): which joints lie outside [lower, upper] (with tolerance)."""
        q = np.asarray(joints, dtype=np.float64)
        return (q < self.lower - tol) | (q > self.upper + tol)


@dataclass(frozen=True, slots=True, eq=False)
class Robot:
    """A 6-axis robot with OPW kinematics.

    ``base``: pose (4, 4) of the robot base in the station's world frame.
    ``flange_in_tool0``: the vendor's flange frame in the kinematic model's tool0 frame
    (identity except for vendors whose flange is not Z-out, see :mod:`olp.vendors`).
    """

    name: str
    vendor: str
    kinematics: opw.OPWParameters
    limits: JointLimits
    home: FloatArray
    base: FloatArray = field(default_factory=lambda: np.eye(4))
    flange_in_tool0: FloatArray = field(default_factory=lambda: np.eye(4))

    @property
    def dof(self) -> int:
        return 6

    def flange_poses(self, joints: ArrayLike) -> FloatArray:
        """Flange poses in the world frame for joints (..., 6) rad; shape (..., 4, 4)."""
        tool0 = opw.forward(self.kinematics, np.asarray(joints, dtype=np.float64))
        return self.base @ tool0 @ self.flange_in_tool0

    def solve(self, flange_world: ArrayLike) -> FloatArray:
        """All IK solutions for flange poses (N, 4, 4) in the world frame: (N, 8, 6), NaN rows
        where a branch has no solution. Joint limits are not applied here."""
        poses = np.asarray(flange_world, dtype=np.float64)
        tool0 = inv(self.base) @ poses @ inv(self.flange_in_tool0)
        return opw.inverse(self.kinematics, tool0)

    def branch_of(self, joints: ArrayLike) -> int:
        """Index of the IK branch (see :mod:`olp.kinematics.opw`) that ``joints`` (6,) lie in."""
        q = np.asarray(joints, dtype=np.float64)
        sols = self.solve(self.flange_poses(q)[None])[0]
        diff = (sols - q + np.pi) % (2 * np.pi) - np.pi
        dist = np.where(np.all(np.isfinite(sols), axis=-1), np.sum(diff**2, axis=-1), np.inf)
        return int(np.argmin(dist))


@dataclass(frozen=True, slots=True, eq=False)
class Station:
    """A robot cell: the robot, named tools (TCP in flange) and frames (pose in world)."""

    name: str
    robot: Robot
    tools: Mapping[str, Tool] = field(default_factory=dict)
    frames: Mapping[str, Frame] = field(default_factory=dict)
    source: str = "<memory>"

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
