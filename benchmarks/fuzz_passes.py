"""Fuzz the passes with absurd but valid IR: resolve, timing and trajectory sampling never raise.

Random short programs on the bundled KR 6 milling cell and UR5e screw cell: joint and linear
moves to joint targets (at the limits, ±1e-12 beyond, 1e308) and Cartesian targets (reachable,
moved by 1e-9 m, or 1e40 m away), speeds from 5e-324 to 1e308 (m/s, rad/s) and fractions down to
5e-324, zones up to 1e308 m, waits up to 1e308 s, tools up to 1e308 m long, comments between.
Each program is compiled (collisions off: the collision pass is not under test here) and, when
it has no error, sampled at 10 ms. Anything but a diagnostic (or the sampler's UsageError for a
program too long to sample) is a crash; numpy's RuntimeWarnings count as crashes too (they
reach the user's terminal).

    python -m benchmarks.fuzz_passes [--programs N] [--seed S]

Prints each crash, then ``name: value unit`` lines. tests/passes/test_robustness.py runs a
short seeded part of it.
"""

from __future__ import annotations

import argparse
import contextlib
import time
import traceback
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np

from olp import ir
from olp.api import compile
from olp.errors import UsageError
from olp.geometry import transl
from olp.station.loader import load_station
from olp.station.model import Station
from olp.trajectory import sample_program

REPO = Path(__file__).resolve().parents[1]
CELLS = ("kr6_milling_cell", "ur5e_screw_cell")
ABSURD = (0.0, 5e-324, 1e-300, 1e-150, 1e-12, 1e-9, 1e-6, 1e-3, 0.05, 0.5, 1.0, 3.0, 1e3, 1e6,
          1e40, 1e300, 1e308)  # fmt: skip
"""Magnitudes the values are drawn from (each with a random sign where a sign is allowed)."""


class _Draw:
    """Random values for one program, from ``rng``, for ``station``."""

    def __init__(self, rng: np.random.Generator, station: Station) -> None:
        self.rng, self.station = rng, station

    def number(self) -> float:
        if self.rng.random() < 0.4:
            return float(self.rng.normal() * 0.5)
        return float(ABSURD[self.rng.integers(len(ABSURD))] * self.rng.choice([-1.0, 1.0]))

    def positive(self, most: float = np.inf) -> float:
        return float(min(max(abs(self.number()), 5e-324), most))

    def joints(self) -> np.ndarray:
        lower, upper = self.station.robot.limits.lower, self.station.robot.limits.upper
        kind = self.rng.random()
        if kind < 0.2:
            edge = np.where(self.rng.random(6) < 0.5, lower, upper)
            return np.asarray(edge + self.rng.choice([0.0, 1e-12, -1e-12, 1e-8], 6))
        if kind < 0.3:
            return np.array([self.number() for _ in range(6)])
        return self.rng.uniform(lower, upper)

    def pose(self) -> np.ndarray:
        pose = self.station.robot.flange_poses(self.joints().clip(-1e3, 1e3))
        kind = self.rng.random()
        if kind < 0.3:
            return np.asarray(transl(self.number(), self.number(), self.number()) @ pose)
        if kind < 0.5:
            return np.asarray(transl(1e-9 * self.rng.normal(), 0.0, 0.0) @ pose)
        return np.asarray(pose)

    def speed(self) -> ir.Speed:
        options: dict[str, float] = {}
        for name, chance, most in (
            ("linear", 0.5, np.inf),
            ("joint", 0.3, 1.0),
            ("joint_acceleration", 0.2, 1.0),
            ("angular", 0.2, np.inf),
        ):
            if self.rng.random() < chance:
                options[name] = self.positive(most)
        return ir.Speed(**options)

    def zone(self) -> ir.Zone:
        return ir.Zone(self.positive()) if self.rng.random() < 0.5 else ir.FINE

    def tool(self) -> ir.Tool:
        if self.rng.random() < 0.7:
            return ir.FLANGE
        return ir.Tool(name="t", pose=transl(self.number(), self.number(), self.number()))

    def instruction(self, tool: ir.Tool) -> ir.Instruction:
        kind = self.rng.random()
        motion = {"speed": self.speed(), "zone": self.zone(), "tool": tool}
        if kind < 0.3:
            return ir.JointMove(target=ir.JointTarget(joints=self.joints()), **motion)  # type: ignore[arg-type]
        if kind < 0.45:
            return ir.JointMove(target=ir.CartesianTarget(pose=self.pose()), **motion)  # type: ignore[arg-type]
        if kind < 0.75:
            return ir.LinearMove(target=ir.CartesianTarget(pose=self.pose()), **motion)  # type: ignore[arg-type]
        if kind < 0.8:
            return ir.LinearMove(target=ir.JointTarget(joints=self.joints()), **motion)  # type: ignore[arg-type]
        if kind < 0.9:
            return ir.Wait(seconds=self.positive())
        return ir.Comment(text="c")


def absurd_program(rng: np.random.Generator, station: Station) -> ir.Program:
    """One to seven random instructions with one tool (see the module docstring)."""
    draw = _Draw(rng, station)
    tool = draw.tool()
    count = int(rng.integers(1, 8))
    return ir.Program(name="fuzz", instructions=[draw.instruction(tool) for _ in range(count)])


def crash_of(program: ir.Program, station: Station) -> str | None:
    """None if the passes handle ``program``, else the crash (type, message, olp frames)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            compiled = compile(program, station, collisions=None)
            if compiled.ok:
                with contextlib.suppress(UsageError):  # too long to sample: a located error
                    sample_program(compiled, 0.01)
    except Exception as exc:  # any exception is what this looks for
        frames = traceback.extract_tb(exc.__traceback__)
        where = [f"{Path(f.filename).name}:{f.lineno}" for f in frames if "/olp/" in f.filename]
        return f"{type(exc).__name__}: {str(exc)[:160]} at {where[-4:]}"
    return None


def run(programs: int, seed: int, report: Callable[[int, str], None]) -> int:
    """Fuzz ``programs`` programs from ``seed``; returns the number of crashes."""
    stations = [load_station(REPO / "stations" / f"{name}.yaml") for name in CELLS]
    rng = np.random.default_rng(seed)
    crashes = 0
    for k in range(programs):
        station = stations[int(rng.integers(len(stations)))]
        crash = crash_of(absurd_program(rng, station), station)
        if crash is not None:
            crashes += 1
            report(k, crash)
    return crashes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--programs", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    start = time.perf_counter()
    crashes = run(args.programs, args.seed, lambda k, text: print(f"crash in program {k}: {text}"))
    elapsed = time.perf_counter() - start
    print(f"fuzz_passes_programs: {args.programs} programs (seed {args.seed})")
    print(f"fuzz_passes_crashes: {crashes} programs")
    print(f"fuzz_passes_rate: {args.programs / elapsed:.1f} programs/s")


if __name__ == "__main__":
    main()
