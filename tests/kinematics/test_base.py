"""The shared kinematics helpers: joint couplings, angle wrapping and turn variants for any
number of joints."""

from __future__ import annotations

import math

import numpy as np
import pytest

from olp.geometry import wrap_half_open
from olp.kinematics.base import FANUC_J2_J3, JointCoupling, turn_variants, wrap_joints


def test_fanuc_coupling_adds_j2_to_j3_and_back() -> None:
    coupling = JointCoupling.from_terms(6, FANUC_J2_J3)
    q = np.array([0.1, 0.5, -0.2, 0.3, -0.4, 0.6])
    chain = coupling.to_chain(q)
    assert chain[2] == pytest.approx(-0.2 + 0.5)
    assert np.allclose(np.delete(chain, 2), np.delete(q, 2))
    assert np.allclose(coupling.to_controller(chain), q)
    assert np.allclose(coupling.to_chain(np.tile(q, (4, 1))), np.tile(chain, (4, 1)))


def test_a_turn_stays_a_turn() -> None:
    """2 pi on any controller joint is a whole number of turns on every chain joint."""
    coupling = JointCoupling.from_terms(6, FANUC_J2_J3)
    for j in range(6):
        shift = coupling.to_chain(np.eye(6)[j] * 2 * math.pi)
        assert np.allclose(shift / (2 * math.pi), np.round(shift / (2 * math.pi)))


def test_identity_and_invalid_couplings() -> None:
    identity = JointCoupling.identity(3)
    q = np.array([1.0, 2.0, 3.0])
    assert identity.is_identity and identity.to_chain(q) is not None
    assert np.array_equal(identity.to_controller(q), q)
    with pytest.raises(ValueError, match="itself"):
        JointCoupling.from_terms(6, [(2, 2, 1)])
    with pytest.raises(ValueError, match="integer inverse"):
        JointCoupling.from_terms(2, [(0, 1, 1), (1, 0, 1)])  # det 0


def test_wrap_joints_is_half_open() -> None:
    x = np.array([-math.pi, math.pi, 3 * math.pi, -3 * math.pi + 1e-3, 0.0, np.nan, 7.0])
    wrapped = wrap_joints(x)
    assert np.allclose(wrapped[:5], wrap_half_open(x[:5]))
    assert wrapped[0] == math.pi and wrapped[1] == math.pi
    assert np.isnan(wrapped[5])
    assert np.all(wrapped[~np.isnan(wrapped)] > -math.pi)


def test_turn_variants_for_any_number_of_joints() -> None:
    lower = np.radians([-360.0, -90.0, -10.0, -200.0, -170.0, -360.0, -720.0])
    upper = np.radians([360.0, 90.0, 10.0, 200.0, 170.0, 360.0, 720.0])
    q = np.radians([[100.0, 10.0, 5.0, 170.0, 0.0, -30.0, 45.0]])
    variants = turn_variants(q, lower, upper)
    rows = variants[0][~np.isnan(variants[0]).any(axis=1)]
    # joint 1: 100, -260; joint 4: 170, -190; joint 6: -30, 330; joint 7: 45, -315, 405, -675
    assert len(rows) == 2 * 2 * 2 * 4
    assert np.allclose(rows[0], q[0])
    assert np.all((rows >= lower - 1e-9) & (rows <= upper + 1e-9))
    with pytest.raises(ValueError):
        turn_variants(q, lower[:6], upper[:6])
