"""Numeric IK: damped least squares on a pinocchio model, the fallback for arms without a
closed form (URDF robots that are neither OPW nor UR, DH tables).

Each of ``S`` seeds starts its own solution "branch". Along a batch of poses (a sampled path),
branch ``b`` of pose ``i`` starts from branch ``b``'s solution of pose ``i - 1`` when that one
converged, else from seed ``b`` again: a continuation, so a smooth path gives smooth joints in
every branch. Results are deterministic (fixed seeds, fixed iteration rules).

Iteration (pinocchio's documented CLIK step, damped): with the pose error
``E = T(q)^-1 · T_target``, ``e = log6(E)`` in the local frame and
``J = Jlog6(E^-1) · J_local``,
``dq = J^T (J J^T + lambda I)^-1 e``, each joint step clipped to ``max_step`` rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class DLSOptions:
    """``tolerance``: stop at ``|log6 error|`` below it (m and rad mixed, as pinocchio's CLIK);
    ``damping``: lambda; ``iterations``: per pose and branch; ``max_step``: rad per iteration."""

    tolerance: float = 1e-10
    damping: float = 1e-8
    iterations: int = 200
    max_step: float = 0.5


def solve_dls(
    model: pin.Model,
    frame: str,
    targets: ArrayLike,
    seeds: ArrayLike,
    options: DLSOptions | None = None,
) -> FloatArray:
    """IK of frame poses (N, 4, 4) from seeds (S, nq): configurations (N, S, nq), NaN rows
    where a branch did not converge. Poses are in the model's root frame, metres."""
    opts = options or DLSOptions()
    poses = np.asarray(targets, dtype=np.float64).reshape(-1, 4, 4)
    starts = np.asarray(seeds, dtype=np.float64).reshape(-1, model.nq)
    data = model.createData()
    frame_id = model.getFrameId(frame)
    out = np.full((len(poses), len(starts), model.nq), np.nan)
    current = starts.copy()
    for i, pose in enumerate(poses):
        target = pin.SE3(pose[:3, :3], pose[:3, 3])
        for b in range(len(starts)):
            q, ok = _dls(model, data, frame_id, target, current[b], opts)
            if ok:
                out[i, b] = q
            current[b] = q if ok else starts[b]
    return out


def _dls(
    model: pin.Model,
    data: pin.Data,
    frame_id: int,
    target: pin.SE3,
    seed: FloatArray,
    opts: DLSOptions,
) -> tuple[FloatArray, bool]:
    q = seed.copy()
    eye = np.eye(6)
    for _ in range(opts.iterations):
        pin.framesForwardKinematics(model, data, q)
        error_pose = data.oMf[frame_id].actInv(target)
        error = pin.log6(error_pose).vector
        if np.linalg.norm(error) < opts.tolerance:
            return q, True
        # (6, nv): pinocchio hands a one-joint chain's Jacobian back as a vector
        jac = np.asarray(pin.computeFrameJacobian(model, data, q, frame_id, pin.LOCAL))
        jac = jac.reshape(6, model.nv)
        # pinocchio's example writes J = -Jlog6(E^-1)·J and dq = -J^T(...)e: the signs cancel.
        jac = pin.Jlog6(error_pose.inverse()) @ jac
        step = jac.T @ np.linalg.solve(jac @ jac.T + opts.damping * eye, error)
        largest = np.max(np.abs(step))
        if largest > opts.max_step:
            step *= opts.max_step / largest
        q = pin.integrate(model, q, step)
    return q, False
