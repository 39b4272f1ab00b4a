"""Singularity distances against the Jacobian: for every bundled arm, ``|det J|`` is a constant
times the product of the wrist, shoulder and elbow distances, so each distance is one factor of
the determinant and together they vanish exactly where the arm is singular."""

from __future__ import annotations

import numpy as np
import pytest

from olp.geometry import rotation_log
from olp.kinematics.singularity import singularity_distances
from olp.station.loader import load_library_robot, robot_library


def _jacobian(forward, q: np.ndarray, h: float = 1e-6) -> np.ndarray:  # type: ignore[no-untyped-def]
    """The geometric Jacobian (6, 6) of tool0 by central differences of the forward kinematics
    (independent of the distances under test)."""
    out = np.zeros((6, 6))
    for j in range(6):
        step = np.zeros(6)
        step[j] = h
        ahead, behind = forward(q + step), forward(q - step)
        out[:3, j] = (ahead[:3, 3] - behind[:3, 3]) / (2 * h)
        out[3:, j] = rotation_log(ahead[:3, :3] @ behind[:3, :3].T) / (2 * h)
    return out


@pytest.mark.parametrize("name", robot_library())
def test_distances_are_the_factors_of_the_jacobian_determinant(name: str) -> None:
    kinematics = load_library_robot(name).kinematics
    q = np.random.default_rng(7).uniform(-2.5, 2.5, (25, 6))
    found = singularity_distances(kinematics, q)
    assert found is not None
    product = np.abs(found.wrist * found.shoulder * found.elbow)
    determinant = np.abs([np.linalg.det(_jacobian(kinematics.forward, row)) for row in q])
    ratio = determinant / product
    assert np.ptp(ratio) <= 1e-5 * np.mean(ratio)


def test_kinematics_without_named_branches_have_no_distances() -> None:
    assert singularity_distances(object(), np.zeros((1, 6))) is None
