"""Batch OPW and UR inverse kinematics against numeric and compiled references.

Run from the repository root: ``python -m benchmarks.ik [--poses N] [--dls-poses M]``.

* olp's numpy OPW IK: all 8 branches for N reachable poses (tool0 poses of random joints within
  the KR 6 R900 sixx limits), timed cold (first call in the process, fresh output memory),
  warm (output allocated per call) and into a preallocated ``out``.
* Reference 1, pinocchio damped least squares: the CLIK loop of pinocchio's documentation
  (full steps, damping 1e-12, stop at |log6 error| < 1e-10) from the HOME seed, for M poses.
  It finds at most *one* branch per pose.
* Reference 2, rs-opw-kinematics through ``py-opw-kinematics`` (``Robot.reach``: 8 branches,
  Rust, one thread), when installed, on the first 200,000 of the poses (its rate does not depend
  on the batch size). Its ``reach`` also computes a Jacobian singular value per branch unless the
  branch is outside given limits, so it is timed twice: as is, and with limits no branch meets
  (IK, limit margins and reach extension only). Its solutions are compared with olp's.

* olp's numpy UR IK (all 8 branches) for N tool0 poses of random UR5e joints within the
  limits, against ur-analytic-ik (C++, one pose per Python call, all branches; when installed)
  on the first 20,000 poses and the same pinocchio DLS loop on the UR5e DH chain; the solutions
  are compared with ur-analytic-ik's.

Everything runs on one core (numpy elementwise code does not use threads). The last lines give
each reference's rate as a ratio to olp's rate for the same arm, measured in the same run.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import pinocchio as pin

from olp.geometry import pose_distance, wrap_half_open
from olp.kinematics import opw, ur
from olp.kinematics.pinocchio_model import TOOL0, build_dh_model, build_model

DEG = math.pi / 180.0
KR6_R900 = opw.OPWParameters(
    0.025, -0.035, 0.0, 0.400, 0.455, 0.420, 0.080,
    offsets=(0.0, -90 * DEG, 0.0, 0.0, 0.0, 0.0), signs=(-1, 1, 1, -1, 1, -1),
)  # fmt: skip
LOWER = np.array([-170, -190, -120, -185, -120, -350]) * DEG
UPPER = np.array([170, 45, 156, 185, 120, 350]) * DEG
HOME = np.array([0, -90, 90, 0, 0, 0]) * DEG
UR5E = ur.URParameters(0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996)
UR_LOWER = np.array([-360, -360, -180, -360, -360, -360]) * DEG
UR_HOME = np.array([0, -90, 90, -90, -90, 0]) * DEG


def _timed(fn: Callable[[], Any], repeats: int) -> list[float]:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return times


def _rate(count: int, seconds: float) -> str:
    return f"{count / seconds:.3g} poses/s"


def bench_opw(poses: np.ndarray, q: np.ndarray) -> dict[str, float]:
    n = len(poses)
    start = time.perf_counter()
    solutions = opw.inverse(KR6_R900, poses)
    cold = time.perf_counter() - start
    warm = _timed(lambda: opw.inverse(KR6_R900, poses), 5)
    out = np.empty((n, 8, 6))
    prealloc = _timed(lambda: opw.inverse(KR6_R900, poses, out=out), 5)
    print(f"olp OPW IK, numpy, {n:,} poses x 8 branches")
    print(f"  cold first call          {cold:.3f} s  {_rate(n, cold)}")
    print(
        f"  warm, allocating output  median {statistics.median(warm):.3f} s (min {min(warm):.3f})"
    )
    print(f"  warm, preallocated out=  median {statistics.median(prealloc):.3f} s")
    err = np.max(np.abs(wrap_half_open(solutions - q[:, None, :])), axis=-1)
    found = np.min(np.where(np.isnan(err), np.inf, err), axis=1)
    sample = solutions[:20000]
    valid = ~np.isnan(sample).any(axis=-1)
    dist, angle = pose_distance(opw.forward(KR6_R900, sample[valid]), poses[np.nonzero(valid)[0]])
    print(f"  input joints recovered: {np.mean(found < 1e-7):.4%} (worst {found.max():.1e} rad)")
    print(f"  branches per pose: {np.mean(np.sum(~np.isnan(solutions[..., 0]), axis=1)):.2f}")
    print(f"  FK of every branch, first 20,000 poses: {dist.max():.1e} m, {angle.max():.1e} rad")
    fk = _timed(lambda: opw.forward(KR6_R900, q), 3)
    return {
        "opw_ik_batch": n / statistics.median(warm),
        "opw_ik_batch_cold": n / cold,
        "opw_ik_batch_out": n / statistics.median(prealloc),
        "opw_fk_batch": n / statistics.median(fk),
    }


def _dls(
    model: pin.Model, data: pin.Data, frame: int, target: pin.SE3, seed: np.ndarray
) -> tuple[np.ndarray, bool]:
    q = seed.copy()
    for _ in range(200):
        pin.framesForwardKinematics(model, data, q)
        error_pose = data.oMf[frame].actInv(target)
        error = pin.log6(error_pose).vector
        if np.linalg.norm(error) < 1e-10:
            return q, True
        jac = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL)
        jac = -pin.Jlog6(error_pose.inverse()) @ jac
        step = -jac.T @ np.linalg.solve(jac @ jac.T + 1e-12 * np.eye(6), error)
        q = pin.integrate(model, q, step)
    return q, False


def bench_dls(poses: np.ndarray, model: pin.Model | None = None, seed: np.ndarray = HOME) -> float:
    model = build_model(KR6_R900) if model is None else model
    data = model.createData()
    frame = model.getFrameId(TOOL0)
    targets = [pin.SE3(p) for p in poses]
    start = time.perf_counter()
    results = [_dls(model, data, frame, t, seed) for t in targets]
    seconds = time.perf_counter() - start
    converged = sum(ok for _, ok in results)
    print(f"pinocchio DLS IK (1 branch per pose), {len(poses)} poses from {model.name} home")
    print(f"  {seconds:.3f} s  {_rate(len(poses), seconds)}, converged {converged}/{len(poses)}")
    return len(poses) / seconds


def bench_rs_opw(poses: np.ndarray) -> dict[str, float]:
    try:
        import py_opw_kinematics as popw
        from scipy.spatial.transform import RigidTransform
    except ImportError as exc:
        print(f"py-opw-kinematics not available ({exc}); `pip install py-opw-kinematics` adds it")
        return {}
    p = KR6_R900
    robot = popw.Robot(
        popw.KinematicModel(
            a1=p.a1, a2=p.a2, b=p.b, c1=p.c1, c2=p.c2, c3=p.c3, c4=p.c4,
            offsets=p.offsets, flip_axes=tuple(s < 0 for s in p.signs),
        ),
        degrees=False,
    )  # fmt: skip
    transforms = RigidTransform.from_matrix(poses)
    start = time.perf_counter()
    result = robot.reach(transforms)
    full = time.perf_counter() - start
    unreachable_limits = [(100.0, 101.0)] * 6
    start = time.perf_counter()
    robot.reach(transforms, joint_limits=unreachable_limits)
    ik_only = time.perf_counter() - start
    # Its slot is 4·flip + 2·shoulder + elbow; olp's row is 4·shoulder + 2·elbow + flip.
    slots = [4 * w + 2 * s + e for s in (0, 1) for e in (0, 1) for w in (0, 1)]
    theirs = result.joints[:, slots]
    ours = opw.inverse(p, poses)
    same_nan = np.array_equal(np.isnan(ours), np.isnan(theirs))
    diff = np.abs(wrap_half_open(ours - theirs))
    print(f"rs-opw-kinematics {popw.__name__} reach(), Rust, 1 thread, {len(poses):,} poses x 8")
    print(f"  with sigma_min per branch  {full:.3f} s  {_rate(len(poses), full)}")
    print(f"  IK + margins only          {ik_only:.3f} s  {_rate(len(poses), ik_only)}")
    print(f"  agrees with olp: same NaN rows {same_nan}, max diff {np.nanmax(diff):.1e} rad")
    return {"rs_opw_reach": len(poses) / full, "rs_opw_reach_ik_only": len(poses) / ik_only}


def bench_ur(poses: np.ndarray, q: np.ndarray, dls_poses: int) -> dict[str, float]:
    n = len(poses)
    solutions = ur.inverse(UR5E, poses)
    warm = _timed(lambda: ur.inverse(UR5E, poses), 5)
    err = np.max(np.abs(wrap_half_open(solutions - q[:, None, :])), axis=-1)
    found = np.min(np.where(np.isnan(err), np.inf, err), axis=1)
    print(f"olp UR IK, numpy, {n:,} UR5e poses x 8 branches")
    print(f"  warm, allocating output  median {statistics.median(warm):.3f} s")
    print(f"  input joints recovered: {np.mean(found < 1e-7):.4%} (worst {found.max():.1e} rad)")
    figures = {"ur_ik_batch": n / statistics.median(warm)}
    dh = build_dh_model(UR5E.a, ur.ALPHA, UR5E.d)
    dh.name = "UR5e"
    figures["ur_pinocchio_dls_ik"] = bench_dls(poses[:dls_poses], dh, UR_HOME)
    try:
        from ur_analytic_ik import ur5e
    except ImportError as exc:
        print(f"ur-analytic-ik not available ({exc}); `pip install ur-analytic-ik` adds it")
        return figures
    sample = [np.ascontiguousarray(p) for p in poses[:20_000]]
    start = time.perf_counter()
    theirs = [ur5e.inverse_kinematics(p) for p in sample]
    seconds = time.perf_counter() - start
    counts = np.array([len(t) for t in theirs])
    ours = np.sum(~np.isnan(solutions[: len(sample), :, 0]), axis=1)
    print(f"ur-analytic-ik inverse_kinematics, C++, 1 pose per call, {len(sample):,} poses")
    print(
        f"  {seconds:.3f} s  {_rate(len(sample), seconds)}; same solution count as olp: "
        f"{np.mean(counts == ours):.2%}"
    )
    figures["ur_analytic_ik"] = len(sample) / seconds
    return figures


def _ratios(figures: dict[str, float]) -> None:
    print()
    print("ratios (reference rate / olp rate, same run; below 1 means olp is faster):")
    pairs = [
        ("pinocchio_dls_ik", "opw_ik_batch"),
        ("rs_opw_reach_ik_only", "opw_ik_batch"),
        ("ur_pinocchio_dls_ik", "ur_ik_batch"),
        ("ur_analytic_ik", "ur_ik_batch"),
    ]
    for ref, ours in pairs:
        if ref in figures and ours in figures:
            print(f"  {ref} / {ours}: {figures[ref] / figures[ours]:.3g}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=1_000_000)
    parser.add_argument("--dls-poses", type=int, default=200)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    q = rng.uniform(LOWER, UPPER, (args.poses, 6))
    poses = opw.forward(KR6_R900, q)
    print(f"numpy {np.__version__}, pinocchio {pin.__version__}, KUKA KR 6 R900 sixx")
    figures = bench_opw(poses, q)
    figures["pinocchio_dls_ik"] = bench_dls(poses[: args.dls_poses])
    figures.update(bench_rs_opw(poses[:200_000]))
    q_ur = rng.uniform(UR_LOWER, -UR_LOWER, (args.poses, 6))
    figures.update(bench_ur(ur.forward(UR5E, q_ur), q_ur, args.dls_poses))
    print()
    for name, value in figures.items():
        print(f"{name}: {value:.3g} poses/s")
    _ratios(figures)


if __name__ == "__main__":
    main()
