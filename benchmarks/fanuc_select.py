"""Fanuc CONFIG selection on a long toolpath: the fast path against the reference, same run.

The planned joints of a tool-down helix of N points on the bundled M-20iA weld cell (one IK
branch, turns kept continuous) go through :func:`olp.vendors.fanuc.selecting_configs` and
:func:`olp.vendors.fanuc.selecting_configs_reference` (every IK solution with every turn
variant); both must agree. Prints seconds, points/s and the peak of numpy/Python allocations
(tracemalloc, a second pass) of each, with the ratios. Run with one BLAS thread for numbers
comparable to the full builds (``OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1``).

    python benchmarks/fanuc_select.py [N]

Last lines: ``name: value unit``.
"""

from __future__ import annotations

import sys
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


def main() -> None:
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
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


if __name__ == "__main__":
    main()
