"""What the timing pass works with: its options, its limits, and the fixed times of non-motion
instructions. (The plan of a program, which path moves blend into which, is
:func:`olp.passes.timing.table.plan`.)"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np
from numpy.typing import NDArray

from olp.ir import Call, Instruction, Wait, is_motion

FloatArray = NDArray[np.float64]


DEFAULT_TIMES: Mapping[str, float] = MappingProxyType(
    {
        # One interpolation cycle of a KUKA KR C4/C5 (12 ms), the controller olp posts for
        # today: an output set between moves delays the next motion by about one cycle.
        "set_output": 0.012,
        # The input is assumed already set; reading it takes one cycle.
        "wait_input": 0.012,
        # A called routine's content is unknown: nothing is charged unless told ("call:NAME").
        "call": 0.0,
        "comment": 0.0,
    }
)
"""Seconds charged for non-motion instructions, by kind; override through ``other_times``."""


MIN_BLEND_M = 1e-6
"""Blend distances (m) below this make the corner a stop."""


X_CAP = 1e12
"""Stand-in for 'no bound' on TOPPRA's squared path speed."""


@dataclass(frozen=True, slots=True)
class TimingOptions:
    """Discretisation and solvers of path moves.

    ``grid_per_sample``: TOPPRA gridpoints per interval of resolved samples (at least);
    ``max_grid_step_rad``: largest joint change between gridpoints; ``max_grid_turn_rad``:
    largest turn of the joint path's direction between gridpoints; ``refine_points``:
    gridpoints placed geometrically on each side of every stop and instruction boundary;
    ``blend_samples``: least number of samples on a blend curve (odd: its midpoint is one);
    more where the blend turns (one per 4° of joint-space turn).

    ``solver``: what finds a chain's path speeds on the grid, a key of :data:`PATH_SOLVERS`
    (``"reachability"``: TOPPRA's recursion vectorised in numpy; ``"toppra"``: the toppra
    package, kept as the reference). ``straight_lines``: time a stop-to-stop path move along a
    straight joint-space line in closed form (:func:`line_profiles`) where its error bound is
    below ``line_tolerance`` (relative excess over the time-optimal duration);
    ``line_deviation_rad``: how far a move's samples may lie off the chord of its joint path
    and still count as one straight line. ``curve_tolerance``: the same bound for a move
    resolved as three samples, timed along the parabola through them
    (:func:`~olp.passes.timing.lines.line_paths`); its bound is looser (the joints' rates
    change along it; where one joint binds, the law is that joint's own optimum).
    ``path_jerk``: path moves respect the joint jerk limits too (a double S on straight lines,
    a jerk-limited law along chains: see :mod:`olp.passes.timing.jerk`); False gives the
    acceleration-limited optimum.
    """

    grid_per_sample: int = 2
    max_grid_step_rad: float = float(np.radians(0.5))
    max_grid_turn_rad: float = float(np.radians(1.0))
    refine_points: int = 24
    blend_samples: int = 5
    solver: str = "reachability"
    straight_lines: bool = True
    # 0.1%: a tenth of what the solver's default grid may be off on such short moves.
    line_tolerance: float = 1e-3
    # 1e-7 rad moves a TCP 1 m from the axes by 0.1 um: far below the resolve pass's own
    # sampling error, so the chord and the samples are the same path.
    line_deviation_rad: float = 1e-7
    # 1%: what the tests hold short fine-stopped moves to; measured, the law is within
    # -1.6% .. +0.5% of the solver's (tests/passes/test_lines.py).
    curve_tolerance: float = 1e-2
    path_jerk: bool = True


class TimingError(Exception):
    """A motion could not be timed (reported as a diagnostic by :func:`time_program`)."""


def time_table(other_times: Mapping[str, float] | None) -> dict[str, float]:
    table = {**DEFAULT_TIMES, **(other_times or {})}
    return {key.casefold(): float(value) for key, value in table.items()}


def fixed_time(instruction: Instruction, times: Mapping[str, float]) -> float:
    """Seconds charged for a non-motion instruction (or an unresolved motion: 0)."""
    if isinstance(instruction, Wait):
        return instruction.seconds
    if isinstance(instruction, Call) and f"call:{instruction.name}".casefold() in times:
        return times[f"call:{instruction.name}".casefold()]
    return times.get(instruction.kind, 0.0) if not is_motion(instruction) else 0.0


MIN_PATH_SPEED = 1e-150
"""Slowest TCP speed (m/s, and rad/s for an orientation speed) a path move is timed at. The
solver works with the squared path speed ``(v / rate)²``, rate up to ~10 m/rad: below this it
would leave the normal float range (2.2e-308) and the time law would lose its digits, then
vanish (measured: 1e-160 m/s timed 5e-7 off, 1e-300 m/s found no time law)."""
