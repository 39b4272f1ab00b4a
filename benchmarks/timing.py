"""Cycle-time estimation: olp's timing pass against a naive trapezoid model, in one process.

Run from the repository root: ``python -m benchmarks.timing [--samples N] [--moves M]``.

* A LIN of N joint samples (default 10,000; 0.54 m resolved every 0.054 mm) on the KR 6 milling
  cell at 0.5 m/s: olp's TOPPRA parameterisation (joint velocity and acceleration limits, TCP
  speed) against a trapezoid in TCP speed with a guessed TCP acceleration (``--tcp-accel``,
  default 2 m/s²), the model a commercial suite typically uses.
* M joint moves (default 1,000) between random joint targets within the limits at 80% speed:
  olp's synchronised jerk-limited Ruckig profiles against per-axis trapezoids (the station's
  velocity and acceleration, no jerk), vectorised over all moves.
* The discretisation error of the path timing: the LIN and a chain of blended LINs timed again on
  a grid 8x finer.
* The path solver: olp's vectorised reachability analysis against the toppra package on the LIN
  (same grid, same constraints).

Each model is timed as the best of ``--repeats`` runs. The last lines are the headline figures,
one per line as ``name: value unit``.
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from olp import ir
from olp.compiled import CompiledProgram
from olp.passes.resolve import ResolveOptions, resolve
from olp.passes.timing import TimingOptions, time_program
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[1]
Q0 = np.radians([10, -80, 95, 0, 30, 0])
FINE = TimingOptions(
    grid_per_sample=16,
    max_grid_step_rad=math.radians(0.0625),
    max_grid_turn_rad=math.radians(0.125),
    refine_points=96,
)


def _best(fn: Callable[[], Any], repeats: int) -> tuple[float, Any]:
    best, result = math.inf, None
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - start)
    return best, result


def _lin_program(station: Station, samples: int, speed: float) -> CompiledProgram:
    tool = station.tools["spindle"]
    target = station.robot.flange_poses(Q0) @ tool.pose
    target[:3, 3] += [0.0, 0.5, -0.2]
    length = float(np.linalg.norm([0.0, 0.5, -0.2]))
    moves = [
        ir.JointMove(target=ir.JointTarget(joints=Q0), tool=tool),
        ir.LinearMove(
            target=ir.CartesianTarget(pose=target), speed=ir.Speed(linear=speed), tool=tool
        ),
    ]
    options = ResolveOptions(step_m=length / (samples - 1))
    compiled = resolve(ir.Program(name="lin", instructions=moves), station, options)
    assert compiled.ok and compiled.steps[1].path is not None
    return compiled


def _ptp_program(station: Station, moves: int, speed: float) -> CompiledProgram:
    lim = station.robot.limits
    rng = np.random.default_rng(0)
    targets = rng.uniform(lim.lower * 0.9, lim.upper * 0.9, size=(moves, 6))
    instructions = [
        ir.JointMove(target=ir.JointTarget(joints=q), speed=ir.Speed(joint=speed)) for q in targets
    ]
    compiled = resolve(ir.Program(name="ptp", instructions=instructions), station)
    assert compiled.ok
    return compiled


def trapezoid_lin(length: float, speed: float, accel: float) -> float:
    """Rest-to-rest time (s) of a trapezoid (triangle when short) in TCP speed."""
    if length * accel >= speed**2:
        return length / speed + speed / accel
    return 2.0 * math.sqrt(length / accel)


def trapezoid_ptp(q: np.ndarray, velocity: np.ndarray, accel: np.ndarray) -> np.ndarray:
    """Per-move time (M,) s of joint moves between rows of ``q`` (M + 1, dof): each axis a
    trapezoid (or triangle) with its own limits, the move as long as its slowest axis."""
    d = np.abs(np.diff(q, axis=0))
    cruise = d * accel >= velocity**2
    with np.errstate(invalid="ignore"):
        per_axis = np.where(cruise, d / velocity + velocity / accel, 2.0 * np.sqrt(d / accel))
    result: np.ndarray = np.max(per_axis, axis=1)
    return result


def _chain(station: Station) -> CompiledProgram:
    tool = station.tools["spindle"]
    start = station.robot.flange_poses(Q0) @ tool.pose
    moves: list[ir.Instruction] = [ir.JointMove(target=ir.JointTarget(joints=Q0), tool=tool)]
    for k, offset in enumerate([[0, 0.3, 0], [0.2, 0.3, 0], [0.2, 0.0, -0.1], [0, 0, 0]]):
        pose = start.copy()
        pose[:3, 3] += offset
        zone = ir.Zone(0.05) if k < 3 else ir.FINE
        moves.append(
            ir.LinearMove(
                target=ir.CartesianTarget(pose=pose),
                speed=ir.Speed(linear=1.0),
                zone=zone,
                tool=tool,
            )
        )
    return resolve(ir.Program(name="chain", instructions=moves), station)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, default=10_000)
    parser.add_argument("--moves", type=int, default=1_000)
    parser.add_argument("--tcp-accel", type=float, default=2.0, help="trapezoid guess, m/s^2")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    station = load_station(REPO / "stations" / "kr6_milling_cell.yaml")
    robot = station.robot

    lin = _lin_program(station, args.samples, 0.5)
    samples = lin.steps[1].path.shape[0]  # type: ignore[union-attr]
    lin_s, lin_timed = _best(lambda: time_program(lin), args.repeats)
    length = lin_timed.steps[1].path_length
    trap_lin_s, trap_lin = _best(lambda: trapezoid_lin(length, 0.5, args.tcp_accel), args.repeats)
    olp_lin = lin_timed.steps[1].duration
    reference = TimingOptions(solver="toppra")
    ref_lin_s, ref_timed = _best(lambda: time_program(lin, options=reference), args.repeats)
    ref_lin = ref_timed.steps[1].duration

    ptp = _ptp_program(station, args.moves, 0.8)
    ptp_s, ptp_timed = _best(lambda: time_program(ptp), args.repeats)
    joints = np.vstack([ptp.start_joints, [s.joints for s in ptp.steps]])
    trap_ptp_s, trap_ptp = _best(
        lambda: trapezoid_ptp(joints, robot.limits.velocity * 0.8, robot.limits.acceleration),
        args.repeats,
    )
    olp_ptp = np.array([s.duration for s in ptp_timed.steps])

    fine_lin = time_program(lin, options=FINE).steps[1].duration
    chain = _chain(station)
    chain_t = time_program(chain).cycle_time
    chain_fine = time_program(chain, options=FINE).cycle_time

    print(f"LIN {length * 1000:.1f} mm at 500 mm/s, {samples} joint samples:")
    print(f"  olp reachability  {lin_s * 1000:10.2f} ms   estimate {olp_lin:.4f} s")
    print(f"  toppra package    {ref_lin_s * 1000:10.2f} ms   estimate {ref_lin:.4f} s")
    print(f"  trapezoid         {trap_lin_s * 1000:10.4f} ms   estimate {trap_lin:.4f} s")
    print(f"{args.moves} joint moves at 80% speed:")
    print(f"  olp Ruckig        {ptp_s * 1000:10.2f} ms   total {olp_ptp.sum():.3f} s")
    print(f"  trapezoid (numpy) {trap_ptp_s * 1000:10.4f} ms   total {trap_ptp.sum():.3f} s")
    ratio = olp_ptp / trap_ptp
    print(f"  per move olp / trapezoid: min {ratio.min():.3f}, max {ratio.max():.3f}")
    print("TOPPRA grid error (default vs 8x finer grid):")
    print(f"  LIN   {olp_lin:.5f} s vs {fine_lin:.5f} s")
    print(f"  chain {chain_t:.5f} s vs {chain_fine:.5f} s (3 blended corners, 1 m/s)")
    print()
    print(f"lin_{samples}_samples_olp_time: {lin_s * 1000:.1f} ms")
    print(f"lin_{samples}_samples_trapezoid_time: {trap_lin_s * 1e6:.2f} us")
    print(f"lin_compute_ratio_olp_over_trapezoid: {lin_s / trap_lin_s:.3g} x")
    print(f"lin_{samples}_samples_toppra_package_time: {ref_lin_s * 1000:.1f} ms")
    print(f"lin_compute_ratio_toppra_package_over_olp: {ref_lin_s / lin_s:.3g} x")
    print(f"lin_estimate_difference_olp_vs_toppra_package: {(olp_lin / ref_lin - 1) * 100:+.5f} %")
    print(f"lin_estimate_ratio_olp_over_trapezoid: {olp_lin / trap_lin:.4f} x")
    print(f"ptp_{args.moves}_moves_olp_time: {ptp_s * 1000:.1f} ms")
    print(f"ptp_{args.moves}_moves_trapezoid_time: {trap_ptp_s * 1000:.3f} ms")
    print(f"ptp_compute_ratio_olp_over_trapezoid: {ptp_s / trap_ptp_s:.3g} x")
    print(f"ptp_estimate_ratio_olp_over_trapezoid: {olp_ptp.sum() / trap_ptp.sum():.4f} x")
    print(f"ptp_olp_time_per_move: {ptp_s / args.moves * 1e6:.1f} us")
    print(f"toppra_grid_error_lin: {abs(olp_lin / fine_lin - 1) * 100:.3f} %")
    print(f"toppra_grid_error_chain: {abs(chain_t / chain_fine - 1) * 100:.3f} %")


if __name__ == "__main__":
    main()
