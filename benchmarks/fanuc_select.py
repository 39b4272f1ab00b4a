"""Fanuc CONFIG selection on a long toolpath: the fast path against the reference, same run.

The planned joints of a tool-down helix of N points on the bundled M-20iA weld cell (one IK
branch, turns kept continuous) go through :func:`olp.vendors.fanuc.selecting_configs` and
:func:`olp.vendors.fanuc.selecting_configs_reference` (every IK solution with every turn
variant); both must agree. Prints seconds, points/s and the peak of numpy/Python allocations
(tracemalloc, a second pass) of each, with the ratios. Run with one BLAS thread for numbers
comparable to the full builds (``OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1``).

With ``--reference DIR`` (a checkout of other olp code, e.g. ``git archive main | tar -x -C
DIR``) it also builds the helix as a CSV on the weld cell, ``olp build ... --post fanuc`` with
all checks, collisions and timing, in fresh interpreters (:mod:`benchmarks.full_builds`),
alternating that code and this code ``--repeat`` times, and prints the best wall time and
peak memory of each with the ratios.

    python benchmarks/fanuc_select.py [N] [--reference DIR] [--repeat K]

Last lines: ``name: value unit``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
import tracemalloc
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from olp.station.loader import load_station
from olp.vendors import fanuc

REPO = Path(__file__).resolve().parents[1]
CELL = REPO / "stations" / "fanuc_m20ia_weld_cell.yaml"


def helix_joints(count: int) -> tuple[Any, np.ndarray]:
    """The robot and planned joints (count, 6) rad of a tool-down helix on the weld table."""
    station = load_station(CELL)
    frame, tool = station.frames["weld_table"], station.tools["torch"]
    assert frame.pose is not None and tool.pose is not None
    t = np.linspace(0.0, 40.0 * np.pi, count)
    poses = np.repeat(np.eye(4)[None], count, axis=0)
    poses[:, :3, :3] = np.diag([-1.0, 1.0, -1.0])
    poses[:, 0, 3] = -0.3 + 0.06 * np.cos(t)
    poses[:, 1, 3] = 0.06 * np.sin(t)
    poses[:, 2, 3] = 0.02 + np.linspace(0.0, 0.03, count)
    sols = station.robot.solve(frame.pose @ poses @ np.linalg.inv(tool.pose))
    return station.robot, np.unwrap(sols[:, 0], axis=0)


def measure(select: Callable[[Any, np.ndarray], list[str | None]], robot: Any, q: np.ndarray) -> (
    tuple[list[str | None], float, float]
):  # fmt: skip
    """Result, seconds and peak traced memory (MB) of ``select(robot, q)``."""
    start = time.perf_counter()
    result = select(robot, q)
    seconds = time.perf_counter() - start
    tracemalloc.start()
    select(robot, q)
    peak = tracemalloc.get_traced_memory()[1] / 1e6
    tracemalloc.stop()
    return result, seconds, peak


def helix_csv(count: int, path: Path) -> None:
    """The helix of :func:`helix_joints` as CSV rows x, y, z (mm, in the weld table frame)."""
    t = np.linspace(0.0, 40.0 * np.pi, count)
    xyz = np.c_[-300 + 60 * np.cos(t), 60 * np.sin(t), 20 + np.linspace(0.0, 30.0, count)]
    np.savetxt(path, xyz, fmt="%.4f", delimiter=",", header="x,y,z", comments="")


def builds(count: int, reference: Path, repeat: int) -> list[tuple[str, float, str]]:
    """Best wall time (s) and peak memory (MB) of the weld-cell build, reference and this."""
    sys.path.insert(0, str(REPO / "benchmarks"))
    from full_builds import run_olp

    best: dict[str, tuple[float, float]] = {}
    with tempfile.TemporaryDirectory() as scratch:
        csv = Path(scratch) / "helix.csv"
        helix_csv(count, csv)
        for _ in range(repeat):
            for label, code in (("reference_", reference.resolve()), ("", None)):
                wall, peak, exit_code = run_olp(
                    "build", str(CELL), str(csv), "--frame", "weld_table", "--orientation",
                    "180,0,180", "--post", "fanuc", "-o", str(Path(scratch) / "out"), "--quiet",
                    code=code,
                )  # fmt: skip
                if exit_code != 0:
                    raise SystemExit(f"{label}build exited {exit_code}")
                old = best.get(label, (np.inf, np.inf))
                best[label] = (min(old[0], wall), min(old[1], peak))
    out = []
    for label in ("reference_", ""):
        out.append((f"{label}fanuc_weld_{count}_build_seconds", best[label][0], "s"))
        out.append((f"{label}fanuc_weld_{count}_peak_memory", best[label][1], "MB"))
    out.append(("fanuc_weld_build_vs_reference", best[""][0] / best["reference_"][0], "x"))
    out.append(("fanuc_weld_memory_vs_reference", best[""][1] / best["reference_"][1], "x"))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("points", nargs="?", type=int, default=100_000)
    parser.add_argument("--reference", type=Path, default=None)
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    count = args.points
    robot, q = helix_joints(count)
    fast, fast_s, fast_mb = measure(fanuc.selecting_configs, robot, q)
    ref, ref_s, ref_mb = measure(fanuc.selecting_configs_reference, robot, q)
    if fast != ref:
        raise SystemExit("fast and reference selections differ")
    written = sum(c is not None for c in fast)
    distinct = len({c for c in fast if c is not None})
    print(f"points: {count} ({written} with a selecting CONFIG, {distinct} distinct)")
    print(f"fanuc_select_seconds: {fast_s:.3f} s")
    print(f"fanuc_select_reference_seconds: {ref_s:.3f} s")
    print(f"fanuc_select_rate: {count / fast_s:.4g} points/s")
    print(f"fanuc_select_reference_rate: {count / ref_s:.4g} points/s")
    print(f"fanuc_select_speedup: {ref_s / fast_s:.1f} x")
    print(f"fanuc_select_peak_traced: {fast_mb:.1f} MB")
    print(f"fanuc_select_reference_peak_traced: {ref_mb:.1f} MB")
    print(f"fanuc_select_memory_ratio: {fast_mb / ref_mb:.3f} x")
    if args.reference is not None:
        for name, value, unit in builds(count, args.reference, args.repeat):
            print(f"{name}: {value:.3f} {unit}")


if __name__ == "__main__":
    main()
