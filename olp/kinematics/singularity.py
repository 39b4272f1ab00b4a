"""How far joint vectors are from the singular poses of an arm, from its analytic model.

An analytic IK has its branches (shoulder, elbow, wrist; see :mod:`olp.kinematics.opw` and
:mod:`olp.kinematics.ur`) meet exactly where the arm is singular: there the pose no longer
determines the joints, and near there small TCP motions need large joint motions. Each
singularity is where one branch-defining quantity crosses zero, so its distance is that
quantity:

* **wrist** — axes 4 and 6 aligned: ``sin(theta5)`` (OPW model joint 5, after the joint
  convention; UR joint 5). KUKA calls it the alpha-5 (wrist axis) singularity, at A5 = 0.
* **shoulder** — OPW: the wrist centre over axis 1, measured as its x (m) in the frame turning
  with axis 1 (its distance from axis 1's line when ``b = 0``, every bundled OPW arm). KUKA:
  the alpha-1 (overhead) singularity. UR: the wrist point (frame 5's origin) in the plane of
  axes 1 and 2, measured as its distance (m) from that plane.
* **elbow** — the arm fully stretched or folded (the wrist centre at the farthest or nearest
  distance from axis 2): ``sin`` of the forearm's angle to the lower arm (OPW
  ``theta3 + atan2(a2, c3)``, UR ``theta3``). KUKA: the alpha-2 (extended position)
  singularity.

Arms with numeric kinematics (:class:`olp.kinematics.models.ChainKinematics`) have no named
branches: :func:`singularity_distances` returns None for them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.kinematics import opw
from olp.kinematics.models import OPWKinematics, URKinematics

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class Singularities:
    """Signed distances (N,) of N joint vectors from each singularity (see the module
    docstring): ``wrist`` and ``elbow`` dimensionless (the sine of an angle), ``shoulder`` in
    metres; ``shoulder_place``: what the shoulder distance measures, for messages."""

    wrist: FloatArray
    shoulder: FloatArray
    elbow: FloatArray
    shoulder_place: str


def _opw(kinematics: OPWKinematics, q: FloatArray) -> Singularities:
    params, chain = kinematics.params, kinematics.chain_joints(q)
    theta = opw.to_model_joints(params, chain)
    return Singularities(
        wrist=np.sin(theta[..., 4]),
        shoulder=opw.wrist_x_in_a1(params, chain),
        elbow=np.sin(theta[..., 2] + math.atan2(params.a2, params.c3)),
        shoulder_place="wrist centre to axis 1",
    )


def _ur(kinematics: URKinematics, q: FloatArray) -> Singularities:
    p = kinematics.params
    t2, t23 = q[..., 1], q[..., 1] + q[..., 2]
    # Frame 5's origin along x1 (the normal of the plane of axes 1 and 2), from the DH chain:
    # a2 cos(t2) + a3 cos(t2 + t3) + d5 sin(t2 + t3 + t4).
    across = p.a2 * np.cos(t2) + p.a3 * np.cos(t23) + p.d5 * np.sin(t23 + q[..., 3])
    return Singularities(
        wrist=np.sin(q[..., 4]),
        shoulder=across,
        elbow=np.sin(q[..., 2]),
        shoulder_place="wrist point to the plane of axes 1 and 2",
    )


_MEASURES: dict[type, Callable[[object, FloatArray], Singularities]] = {
    OPWKinematics: _opw,  # type: ignore[dict-item]
    URKinematics: _ur,  # type: ignore[dict-item]
}
"""Singularity distances by kinematics type."""


def singularity_distances(kinematics: object, joints: ArrayLike) -> Singularities | None:
    """Distances of controller joints (N, 6) rad from the singularities of ``kinematics``, or
    None for kinematics without analytic branches."""
    measure = _MEASURES.get(type(kinematics))
    if measure is None:
        return None
    return measure(kinematics, np.asarray(joints, dtype=np.float64))


BRANCH_BITS: dict[str, int] = {"wrist": 1, "elbow": 2, "shoulder": 4}
"""The bit of each singularity in an IK branch index (``4·shoulder + 2·elbow + wrist``, the
layout of :mod:`olp.kinematics.opw` and :mod:`olp.kinematics.ur`): on a singularity the two
branches that differ in its bit meet."""

ON_SINGULARITY = 1e-9
"""A distance (sine, or metres) this small is on the singularity: there the IK's split of the
free joints comes from rounding noise (a pose known to 1e-16 fixes axis 4 next to the wrist
singularity only to 1e-16 / sin(theta5))."""


def meeting_branches(kinematics: object, joints: ArrayLike, branch: int) -> list[int]:
    """``branch`` and every branch that meets it at controller joints (6,) rad: those with the
    bit of each singularity the joints are on (within :data:`ON_SINGULARITY`) flipped."""
    found = singularity_distances(kinematics, np.asarray(joints, dtype=np.float64)[None])
    if found is None:
        return [branch]
    out = [branch]
    for name, bit in BRANCH_BITS.items():
        if abs(float(getattr(found, name)[0])) <= ON_SINGULARITY:
            out += [b ^ bit for b in out]
    return out
