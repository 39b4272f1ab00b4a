"""CSV toolpath parsing: a generated XYZ+speed file of N rows (default 1,000,000), same process.

Prints ``name: value unit`` lines:

* ``csv_stream``: olp's streaming reader (:func:`olp.frontends.csv.open_csv`) turning every block
  into SI poses (N, 4, 4) and speeds, nothing kept per row; its peak traced memory shows that
  memory is bounded by the block size, not the file.
* ``csv_reference``: Python's ``csv`` module with ``float()`` per cell into lists, the usual
  hand-written loader (and what RoboDK's ``LoadList`` does), on the same file.
* ``csv_ir``: :func:`olp.frontends.csv.load_csv`, the full frontend building one IR move per row
  (on the first ``--ir-rows`` rows, default 100,000; scaled per row). This is where per-row
  Python objects are unavoidable with today's IR.

    python -m benchmarks.csv_parse [--rows N] [--ir-rows M]
"""

from __future__ import annotations

import argparse
import csv
import tempfile
import time
import tracemalloc
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

import numpy as np

from olp.frontends.csv import CsvOptions, load_csv, open_csv
from olp.geometry import pose_from

OPTIONS = CsvOptions(orientation=(180.0, 0.0, 180.0))
T = TypeVar("T")


def write_file(path: Path, rows: int) -> None:
    """x, y, z in mm on a spiral and a speed column that changes every 1000 rows."""
    t = np.linspace(0.0, 1.0, rows)
    data = np.column_stack(
        [
            100 + 150 * np.cos(200 * np.pi * t),
            150 + 150 * np.sin(200 * np.pi * t),
            20 + 50 * t,
            20 + (np.arange(rows) // 1000) % 5,
        ]
    )
    with path.open("w", encoding="ascii") as file:
        file.write("x [mm],y [mm],z [mm],speed [mm/s]\n")
        np.savetxt(file, data, fmt=["%.3f", "%.3f", "%.3f", "%.1f"], delimiter=",")


def stream_poses(path: Path) -> int:
    """Stream the file into SI poses block by block; return the row count."""
    count = 0
    with open_csv(path, OPTIONS) as stream:
        rotation = np.diag([-1.0, 1.0, -1.0])
        for chunk in stream:
            rows = chunk.values.shape[0]
            poses = pose_from(np.broadcast_to(rotation, (rows, 3, 3)), chunk.values[:, :3] / 1e3)
            speeds = chunk.values[:, 3] / 1e3
            assert speeds.shape == (rows,) and poses.shape == (rows, 4, 4)
            count += rows
    return count


def reference_lists(path: Path) -> int:
    with path.open(newline="", encoding="ascii") as file:
        reader = csv.reader(file)
        next(reader)
        rows = [[float(cell) for cell in row] for row in reader]
    return len(rows)


def timed(fn: Callable[..., T], *args: object) -> tuple[float, T]:
    start = time.perf_counter()
    result = fn(*args)
    return time.perf_counter() - start, result


def traced_peak_mb(fn: Callable[[Path], object], path: Path) -> float:
    tracemalloc.start()
    fn(path)
    peak = tracemalloc.get_traced_memory()[1] / 1e6
    tracemalloc.stop()
    return peak


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rows", type=int, default=1_000_000)
    parser.add_argument("--ir-rows", type=int, default=100_000)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "path.csv"
        write_file(path, args.rows)
        size_mb = path.stat().st_size / 1e6
        stream_s, count = timed(stream_poses, path)
        assert count == args.rows, count
        # Memory in a second pass (tracing slows allocations down), for this file and one a
        # tenth its size: the same peak means memory follows the block size, not the file.
        peak_mb = traced_peak_mb(stream_poses, path)
        tenth = Path(folder) / "tenth.csv"
        write_file(tenth, max(args.rows // 10, 1))
        tenth_peak_mb = traced_peak_mb(stream_poses, tenth)
        reference_s, ref_count = timed(reference_lists, path)
        assert ref_count == args.rows
        small = Path(folder) / "small.csv"
        write_file(small, min(args.ir_rows, args.rows))
        ir_s, result = timed(load_csv, small, OPTIONS)
        ir_rows = len(result.program)
    print(f"csv_file: {args.rows} rows, {size_mb:.1f} MB")
    print(f"csv_stream_seconds: {stream_s:.3f} s")
    print(f"csv_stream: {args.rows / stream_s:.4g} rows/s")
    print(f"csv_stream_peak_memory: {peak_mb:.1f} MB (traced; file {size_mb:.1f} MB)")
    print(f"csv_stream_peak_memory_tenth_file: {tenth_peak_mb:.1f} MB")
    print(f"csv_reference_seconds: {reference_s:.3f} s (csv module + float per cell)")
    print(f"csv_reference: {args.rows / reference_s:.4g} rows/s")
    print(f"csv_stream_speedup: {reference_s / stream_s:.1f} x")
    print(f"csv_ir: {ir_rows / ir_s:.4g} rows/s ({ir_rows} rows into IR moves)")
    print(f"csv_ir_per_row: {ir_s / ir_rows * 1e6:.2f} us")
    print(f"csv_ir_extrapolated: {ir_s / ir_rows * args.rows:.1f} s for {args.rows} rows")


if __name__ == "__main__":
    main()
