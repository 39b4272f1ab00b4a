"""Jerk-limited rest-to-rest profiles in one coordinate (the "double S"), vectorised: the
closed form the straight-line timer and the UR model use, and the reference the path-move tests
compare with.

A move over ``D`` from rest to rest with ``|v| <= V``, ``|a| <= A``, ``|j| <= J`` takes, time
optimally (Biagiotti & Melchiorri, *Trajectory Planning for Automatic Machines and Robots*,
Springer 2008, section 3.4; the cases below are theirs, written for a symmetric profile):

* it reaches ``V`` and cruises when ``D >= V Ta`` with the ramp ``Ta = V / A + A / J`` if
  ``V J >= A²`` (``A`` is reached), else ``Ta = 2 sqrt(V / J)``; then ``T = D / V + Ta``;
* otherwise it peaks below ``V``: with ``A`` reached when the peak ``vp`` solving
  ``D = vp (vp / A + A / J)`` has ``vp J >= A²`` (``T = 2 (vp / A + A / J)``), else
  ``T = 4 (D / (2 J))^(1/3)``.

Each ramp is: jerk ``+J`` for ``Tj``, constant acceleration ``ap`` for ``Ta - 2 Tj``, jerk
``-J`` for ``Tj`` (``ap = J Tj``); ``J = inf`` gives the trapezoid (``Tj = 0``). The state along
such a profile is :class:`olp.trajectory.LineTimeLaw`'s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class SCurves:
    """Rest-to-rest double-S profiles (M,) each: ``jerk_time`` ``Tj`` s, ``ramp`` ``Ta`` s (each
    of the acceleration and braking phases), ``duration`` s, ``peak`` speed and ``accel`` (the
    acceleration ``ap`` held between the jerk phases), in the units of the distance given."""

    jerk_time: FloatArray
    ramp: FloatArray
    duration: FloatArray
    peak: FloatArray
    accel: FloatArray


def double_s(length: FloatArray, speed: FloatArray, accel: FloatArray, jerk: FloatArray) -> SCurves:
    """Time-optimal rest-to-rest profiles over ``length`` (M,) with at most ``speed``,
    ``accel`` and ``jerk`` (M,) each (``jerk = inf``: a trapezoid); see the module docstring."""
    d, v, a, j = np.broadcast_arrays(
        *(np.asarray(x, dtype=np.float64) for x in (length, speed, accel, jerk))
    )
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        reach, tj_cruise, ta_cruise = _cruise_ramp(v, a, j)
        cruise = d >= v * ta_cruise
        tj_a = a / j
        peak_a = 0.5 * a * (np.sqrt(tj_a**2 + 4.0 * d / a) - tj_a)
        with_a = peak_a * j >= a**2
        tj_b = np.cbrt(d / (2.0 * j))
        peak = np.where(cruise, v, np.where(with_a, peak_a, j * tj_b**2))
        tj = np.where(cruise, tj_cruise, np.where(with_a, tj_a, tj_b))
        held = np.where(cruise, reach, with_a)
        ap = np.where(held, a, j * tj)
        ramp = peak / ap + tj
        duration = np.where(cruise, d / v + ramp, 2.0 * ramp)
    return SCurves(tj, ramp, duration, peak, ap)


def _cruise_ramp(
    v: FloatArray, a: FloatArray, j: FloatArray
) -> tuple[NDArray[np.bool_], FloatArray, FloatArray]:
    """Whether a ramp to ``v`` reaches ``a``, its jerk phase and its duration ``Ta`` (s)."""
    reach = v * j >= a**2
    tj_cruise = np.where(reach, a / j, np.sqrt(v / j))
    ta_cruise = np.where(reach, v / a + tj_cruise, 2.0 * tj_cruise)
    return reach, tj_cruise, ta_cruise


def short_of_cruise(
    length: FloatArray, speed: FloatArray, accel: FloatArray, jerk: FloatArray
) -> NDArray[np.bool_]:
    """Where the double S over ``length`` with ``speed``, ``accel``, ``jerk`` (M,) each peaks
    below ``speed`` with a margin: so does the one with any higher speed cap, and all of them
    are the same law to the bit (:func:`double_s` reads ``speed`` only where it cruises).

    :func:`double_s` cruises where ``length >= V Ta(V)``, as rounded. ``V Ta(V)`` rounds
    monotonically in ``V`` on each side of ``V J = A²``, and across it ``Ta`` is continuous
    (``2 A / J`` from both sides), so rounding can lower it by a few ulps there at most;
    :data:`CRUISE_CLEARANCE` is far above that."""
    v, a, j = (np.asarray(x, dtype=np.float64) for x in (speed, accel, jerk))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        ta = _cruise_ramp(v, a, j)[2]
        short: NDArray[np.bool_] = length < v * ta * (1.0 - CRUISE_CLEARANCE)
    return short


CRUISE_CLEARANCE = 1e-9
"""Relative margin of :func:`short_of_cruise` below the distance a ramp to the cap covers."""
