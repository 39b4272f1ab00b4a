"""Scaling of a full build with the toolpath's length: 100k, 1M and 10M helix points, streamed
in windows (olp.stream), with the fitted slope and whether time is linear in N; and the 1M
build per post against another olp (``--reference``), in the same run.

Each build is ``olp build stations/kr6_milling_cell.yaml helix.csv --frame table --orientation
180,0,180 --post P`` (default checks, collisions and timing) in a fresh interpreter with one
BLAS/OpenMP thread; wall time and peak resident memory (VmHWM) are the child's own
(:func:`full_builds.run_olp`). The series builds every size with ``--chunk-rows 50000`` (the
window size a 1M build gets by itself), so that all sizes take the same path; the per-post
builds run as a user runs them (streamed from 1M rows where the post can stream). With
``--reference DIR`` (e.g. ``git archive main | tar -x -C DIR``) each per-post build also runs
with that code, right before this code's, and the ratios this / reference are printed. A
reference build that fails (out of memory) is reported as such.

    python benchmarks/scaling.py [--points 100000,1000000,10000000] [--posts kuka]
                                 [--post-points 1000000] [--reference DIR]

Last lines: ``name: value unit``.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from full_builds import CELL, ORIENTATION, run_olp

WINDOW_ROWS = 50_000
WRITE_ROWS = 1_000_000


def helix(points: int, path: Path) -> None:
    """The helix of ``full_builds.helix`` (same rows), written a million rows at a time."""
    with open(path, "w", encoding="ascii") as out:
        out.write("x,y,z\n")
        for lo in range(0, points, WRITE_ROWS):
            k = np.arange(lo, min(lo + WRITE_ROWS, points))
            t = 40.0 * np.pi * k / max(points - 1, 1)
            z = 30.0 * k / max(points - 1, 1)
            xyz = np.c_[100 + 60 * np.cos(t), 60 * np.sin(t), 20 + z]
            np.savetxt(out, xyz, fmt="%.4f", delimiter=",")


def build(
    csv: Path, post: str, out: Path, chunk_rows: int | None, code: Path | None = None
) -> tuple[float, float] | None:
    """Wall time (s) and peak memory (MB) of one build; None if it failed."""
    args = [
        "build", str(CELL), str(csv), "--frame", "table", "--orientation", ORIENTATION,
        "--post", post, "-o", str(out), "--quiet",
    ]  # fmt: skip
    if chunk_rows is not None:
        args += ["--chunk-rows", str(chunk_rows)]
    try:
        wall, peak, code_ = run_olp(*args, code=code)
    except (SystemExit, subprocess.SubprocessError) as exc:
        print(f"# {post} {csv.name}: {exc}"[:400], file=sys.stderr)
        return None
    return (wall, peak) if code_ == 0 else None


def label(points: int) -> str:
    return f"{points // 1_000_000}M" if points >= 1_000_000 else f"{points // 1000}k"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", default="100000,1000000,10000000")
    parser.add_argument("--posts", default="kuka")
    parser.add_argument("--post-points", type=int, default=1_000_000)
    parser.add_argument("--reference", type=Path, default=None)
    args = parser.parse_args()
    sizes = [int(p) for p in args.points.split(",") if p]
    results: list[tuple[str, float, str]] = []
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        walls: dict[int, float] = {}
        for points in sizes:
            csv = folder / f"helix_{points}.csv"
            helix(points, csv)
            done = build(csv, "kuka", folder / "out", WINDOW_ROWS)
            csv.unlink()
            if done is None:
                results.append((f"kuka_{label(points)}_streamed_failed", 1.0, "x"))
                continue
            walls[points] = done[0]
            results.append((f"kuka_{label(points)}_streamed_seconds", done[0], "s"))
            results.append((f"kuka_{label(points)}_streamed_peak_memory", done[1], "MB"))
            results.append(
                (f"kuka_{label(points)}_streamed_us_per_point", done[0] / points * 1e6, "us")
            )
        results += fit(walls)
        results += per_post(folder, args.posts.split(","), args.post_points, args.reference)
    for name, value, unit in results:
        print(f"{name}: {value:.4g} {unit}")


def fit(walls: dict[int, float]) -> list[tuple[str, float, str]]:
    """Least-squares line through (millions of points, seconds), and the per-point time of the
    largest build against the 1M one."""
    if len(walls) < 2:
        return []
    n = np.array(sorted(walls), dtype=float)
    t = np.array([walls[int(k)] for k in n])
    slope, intercept = np.polyfit(n / 1e6, t, 1)
    out = [
        ("fitted_slope", float(slope), "s/Mpoints"),
        ("fitted_intercept", float(intercept), "s"),
    ]
    if 1_000_000 in walls and max(walls) > 1_000_000:
        big = max(walls)
        ratio = (walls[big] / big) / (walls[1_000_000] / 1_000_000)
        out.append((f"per_point_time_{label(big)}_vs_1M", ratio, "x"))
    return out


def per_post(
    folder: Path, posts: list[str], points: int, reference: Path | None
) -> list[tuple[str, float, str]]:
    """Each post's build of ``points`` as a user runs it, and with the reference code."""
    if points <= 0:
        return []
    csv = folder / "helix_post.csv"
    helix(points, csv)
    out: list[tuple[str, float, str]] = []
    tag = label(points)
    for post in posts:
        ref = None
        if reference is not None:
            ref = build(csv, post, folder / "ref", None, reference.resolve())
            if ref is None:
                out.append((f"reference_{post}_{tag}_build_failed", 1.0, "x"))
            else:
                out.append((f"reference_{post}_{tag}_build_seconds", ref[0], "s"))
                out.append((f"reference_{post}_{tag}_peak_memory", ref[1], "MB"))
        done = build(csv, post, folder / "out", None)
        if done is None:
            out.append((f"{post}_{tag}_build_failed", 1.0, "x"))
            continue
        out.append((f"{post}_{tag}_build_seconds", done[0], "s"))
        out.append((f"{post}_{tag}_peak_memory", done[1], "MB"))
        if ref is not None:
            out.append((f"{post}_{tag}_build_seconds_vs_reference", done[0] / ref[0], "x"))
            out.append((f"{post}_{tag}_peak_memory_vs_reference", done[1] / ref[1], "x"))
    return out


if __name__ == "__main__":
    main()
