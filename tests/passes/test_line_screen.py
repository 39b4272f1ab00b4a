"""The screen of :func:`olp.passes.timing.lines.line_profiles`: a short line that never reaches
its speed cap is timed from the TCP positions at its ends, without the five forward kinematics
per move, and its law is the same to the bit as with them.

* Random lines on the KR 6 cell, 1e-8 to 0.1 rad long, at TCP speeds from 1 mm/s to none, with
  and without the jerk limit: every field of the profiles equals the one computed with the five
  forward kinematics on every move (NaN ends: the screen proves nothing), and the screen
  decides most of those under 1e-3 rad (measured: 75% without the jerk limit), not all (so
  the comparison covers both paths).
* The screen's rate bound is above the five-point bound on every move, and within 20% of it
  on moves of 1e-6 to 1e-4 rad (measured: 11%; else it would prove little).
* :func:`~olp.passes.timing.scurve.short_of_cruise`: where it holds, the double S with any
  higher speed cap is the same law to the bit; where the double S cruises, it does not hold.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from olp.passes.timing import lines
from olp.passes.timing.scurve import double_s, short_of_cruise
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
Q0 = np.radians([10, -80, 95, 0, 30, 0])
FIELDS = ("accel", "ramp", "duration", "excess", "jerk_time", "lead")


@pytest.fixture(scope="module")
def station() -> Station:
    return load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def _lines(count: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ends (M, 6) rad of random lines around Q0, 1e-8 to 0.1 rad long, and TCP speeds (M,)."""
    rng = np.random.default_rng(seed)
    q0 = Q0 + rng.normal(0.0, 0.2, (count, 6))
    direction = rng.normal(size=(count, 6))
    direction /= np.linalg.norm(direction, axis=-1, keepdims=True)
    length = 10.0 ** rng.uniform(-8.0, -1.0, count)
    speed = rng.choice([0.001, 0.01, 0.25, 2.0, np.inf], count)
    return q0, q0 + length[:, None] * direction, speed


@pytest.mark.parametrize("jerk", [True, False])
def test_screened_lines_are_timed_as_with_five_forward_kinematics(
    station: Station, jerk: bool
) -> None:
    q0, q1, speed = _lines(3000, seed=1 if jerk else 2)
    tools = np.broadcast_to(station.tools["spindle"].pose, (len(q0), 4, 4))
    args = (q0, q1, station.robot, tools, speed, np.full(len(q0), np.inf))
    unknown = np.full((len(q0), 3), np.nan)
    screened = lines.line_profiles(*args, jerk=jerk, bow=np.zeros_like(q0))
    measured = lines.line_profiles(*args, jerk=jerk, bow=np.zeros_like(q0), ends=(unknown,) * 2)
    for name in FIELDS:
        assert np.array_equal(getattr(screened, name), getattr(measured, name)), name
    # how many the screen decided (the rest took the five forward kinematics after all)
    inf = np.full(len(q0), np.inf)
    span = np.linalg.norm(q1 - q0, axis=-1)
    moves = lines._Moves(q0, q1, tools, speed, inf, inf, inf, np.zeros_like(q0), span)
    rates = lines._screened_rates(moves, station.robot, None)
    clear = lines._laws(moves, station.robot.limits, jerk, rates, relax=True)[1]
    assert np.mean(clear[span < 1e-3]) > 0.5 and not np.all(clear)


def test_the_screen_bound_is_above_the_five_point_bound(station: Station) -> None:
    q0, q1, speed = _lines(3000, seed=3)
    tools = np.broadcast_to(station.tools["spindle"].pose, (len(q0), 4, 4))
    inf = np.full(len(q0), np.inf)
    moves = lines._Moves(
        q0, q1, tools, speed, inf, inf, inf, np.zeros_like(q0), np.linalg.norm(q1 - q0, axis=-1)
    )
    screen = lines._screened_rates(moves, station.robot, None)[1]
    five = lines._line_rates(moves, station.robot)[1]
    assert np.all(screen >= five)
    toolpath = (moves.span > 1e-6) & (moves.span < 1e-4)  # about 1 .. 100 um of TCP travel
    assert np.max(screen[toolpath] / five[toolpath]) < 1.2  # measured: 1.11


def test_short_of_cruise_means_the_speed_cap_is_not_read() -> None:
    rng = np.random.default_rng(4)
    n = 20000
    accel = 10.0 ** rng.uniform(-2.0, 2.0, n)
    jerk = np.where(rng.random(n) < 0.2, np.inf, 10.0 ** rng.uniform(-1.0, 3.0, n))
    speed = 10.0 ** rng.uniform(-3.0, 1.0, n)
    # around the speed where a ramp just reaches the acceleration, and around the cruise
    edge = (rng.random(n) < 0.3) & np.isfinite(jerk)
    speed[edge] = (accel**2 / jerk)[edge] * (1.0 + rng.choice([-1e-15, 0.0, 1e-15], edge.sum()))
    reach = double_s(np.full(n, np.inf), speed, accel, jerk)  # the ramp to the cap
    cruise = speed * reach.ramp
    factor = rng.choice([0.5, 1.0 - 1e-6, 1.0 - 1e-12, 1.0, 1.0 + 1e-12, 2.0], n)
    short = short_of_cruise(cruise * factor, speed, accel, jerk)
    assert np.array_equal(short, factor < 1.0 - 1e-9)
    length = cruise * factor
    base = double_s(length, speed, accel, jerk)
    for up in (1.0 + 1e-15, 1.001, 10.0, 1e6, np.inf):
        higher = double_s(length, speed * up, accel, jerk)
        for name in ("jerk_time", "ramp", "duration", "peak", "accel"):
            assert np.array_equal(getattr(higher, name)[short], getattr(base, name)[short]), name
