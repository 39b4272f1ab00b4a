"""The three kinds of robot kinematics behind :class:`olp.kinematics.base.Kinematics`.

* :class:`OPWKinematics`: closed-form OPW (:mod:`olp.kinematics.opw`), 8 branches.
* :class:`URKinematics`: closed-form Universal Robots (:mod:`olp.kinematics.ur`), 8 branches.
* :class:`ChainKinematics`: any serial chain held as a pinocchio model (from a URDF file or a DH
  table); damped-least-squares IK (:mod:`olp.kinematics.numeric`), one branch per seed.

All take and return the controller's joint values; a :class:`~olp.kinematics.base.JointCoupling`
(Fanuc's J2/J3) is applied inside. pinocchio is imported only when a chain model is needed.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.kinematics import opw, ur
from olp.kinematics.base import JointCoupling, wrap_joints

FloatArray = NDArray[np.float64]


def _coupled_inverse(coupling: JointCoupling, chain_solutions: FloatArray) -> FloatArray:
    """Controller joints, wrapped to (-pi, pi], from chain-joint IK rows."""
    if coupling.is_identity:
        return chain_solutions
    return wrap_joints(coupling.to_controller(chain_solutions))


@dataclass(frozen=True, slots=True, eq=False)
class OPWKinematics:
    """An OPW arm; ``coupling`` maps controller joints to the joints ``params`` expects."""

    params: opw.OPWParameters
    coupling: JointCoupling = field(default_factory=lambda: JointCoupling.identity(6))
    _cache: dict[str, Any] = field(default_factory=dict, init=False, repr=False)

    dof = 6
    branch_names = opw.BRANCH_NAMES

    def forward(self, joints: ArrayLike) -> FloatArray:
        """tool0 poses (..., 4, 4) m for controller joints (..., 6) rad."""
        return opw.forward(self.params, self.coupling.to_chain(joints))

    def inverse(self, poses: ArrayLike, seed: ArrayLike | None = None) -> FloatArray:
        """All 8 branches (N, 8, 6) rad, rows as :data:`olp.kinematics.opw.BRANCH_NAMES`."""
        del seed
        return _coupled_inverse(self.coupling, opw.inverse(self.params, poses))

    def chain_joints(self, joints: ArrayLike) -> FloatArray:
        return self.coupling.to_chain(joints)

    def chain_model(self) -> Any:
        if "model" not in self._cache:
            from olp.kinematics.pinocchio_model import build_model

            self._cache["model"] = build_model(self.params)
        return self._cache["model"]


@dataclass(frozen=True, slots=True, eq=False)
class URKinematics:
    """A Universal Robots arm (controller joints are the DH angles)."""

    params: ur.URParameters
    _cache: dict[str, Any] = field(default_factory=dict, init=False, repr=False)

    dof = 6
    branch_names = ur.BRANCH_NAMES

    def forward(self, joints: ArrayLike) -> FloatArray:
        """tool0 poses (..., 4, 4) m in UR's Base frame for joints (..., 6) rad."""
        return ur.forward(self.params, joints)

    def inverse(self, poses: ArrayLike, seed: ArrayLike | None = None) -> FloatArray:
        """All 8 branches (N, 8, 6) rad, rows as :data:`olp.kinematics.ur.BRANCH_NAMES`."""
        del seed
        return ur.inverse(self.params, poses)

    def chain_joints(self, joints: ArrayLike) -> FloatArray:
        return np.asarray(joints, dtype=np.float64)

    def chain_model(self) -> Any:
        if "model" not in self._cache:
            from olp.kinematics.pinocchio_model import build_dh_model

            p = self.params
            self._cache["model"] = build_dh_model(p.a, ur.ALPHA, p.d)
        return self._cache["model"]


@dataclass(frozen=True, slots=True, eq=False)
class ChainKinematics:
    """A serial chain held as a pinocchio model (frame ``tool0`` at the tip), numeric IK.

    ``model``: a ``pinocchio.Model`` whose configuration is the chain joints (revolute joints
    only, nq = dof). ``seeds`` (S, dof): controller joints the IK branches start from;
    :meth:`inverse` returns ``1 + S`` rows: row 0 continues from ``seed`` (or ``seeds[0]``),
    row ``1 + s`` from ``seeds[s]``.
    """

    model: Any
    seeds: FloatArray
    coupling: JointCoupling
    description: str = "chain"

    def __post_init__(self) -> None:
        if self.model.nq != self.model.nv:
            raise ValueError("ChainKinematics: only revolute and prismatic joints are supported")
        seeds = np.array(self.seeds, dtype=np.float64).reshape(-1, self.model.nq)
        seeds.setflags(write=False)
        object.__setattr__(self, "seeds", seeds)

    @property
    def dof(self) -> int:
        return int(self.model.nq)

    @property
    def branch_names(self) -> tuple[str, ...]:
        return ("from seed", *(f"seed {i}" for i in range(len(self.seeds))))

    def forward(self, joints: ArrayLike) -> FloatArray:
        """tool0 poses (..., 4, 4) m for controller joints (..., dof) rad (pinocchio per pose)."""
        from olp.kinematics.pinocchio_model import frame_poses

        q = self.chain_joints(joints)
        if q.shape[-1:] != (self.dof,):
            raise ValueError(f"forward: expected joints of shape (..., {self.dof}), got {q.shape}")
        return frame_poses(self.model, q).reshape(*q.shape[:-1], 4, 4)

    def inverse(self, poses: ArrayLike, seed: ArrayLike | None = None) -> FloatArray:
        """Numeric IK (N, 1 + S, dof) rad, NaN rows where a branch did not converge."""
        from olp.kinematics.numeric import solve_dls
        from olp.kinematics.pinocchio_model import TOOL0

        first = self.seeds[:1] if seed is None else np.asarray(seed, np.float64)[None]
        starts = self.coupling.to_chain(np.vstack([first, self.seeds]))
        t = np.asarray(poses, dtype=np.float64)
        chain = solve_dls(self.model, TOOL0, t.reshape(-1, 4, 4), starts)
        out = wrap_joints(self.coupling.to_controller(chain))
        return out.reshape(*t.shape[:-2], len(starts), self.dof)

    def chain_joints(self, joints: ArrayLike) -> FloatArray:
        return self.coupling.to_chain(joints)

    def chain_model(self) -> Any:
        return self.model


def default_seeds(home: ArrayLike, lower: ArrayLike, upper: ArrayLike) -> FloatArray:
    """Seeds (8, dof) for numeric IK: ``home``, then the 7 other corners of a box half-way
    from the middle of the limits towards them on axes 1-3 (other axes at mid-range)."""
    lo, hi = np.asarray(lower, np.float64), np.asarray(upper, np.float64)
    mid, half = (lo + hi) / 2, (hi - lo) / 4
    seeds = [np.asarray(home, np.float64)]
    for k in range(1, 8):
        q = mid.copy()
        for j in range(min(3, len(q))):
            q[j] += half[j] if (k >> j) & 1 else -half[j]
        seeds.append(q)
    return np.array(seeds)
