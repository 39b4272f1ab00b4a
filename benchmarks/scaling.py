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
reference build that fails (out of memory) is reported as such. With ``--whole`` each per-post
build also runs whole (``--chunk-rows 0``), right after, and the ratios streamed / whole are
printed. ``--series-post`` names the post the series builds (default kuka).

    python benchmarks/scaling.py [--points 100000,1000000,10000000] [--posts kuka]
                                 [--post-points 1000000] [--reference DIR] [--whole]
                                 [--series-post kuka]

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
    parser.add_argument("--whole", action="store_true")
    parser.add_argument("--series-post", default="kuka")
    args = parser.parse_args()
    series = args.series_post
    sizes = [int(p) for p in args.points.split(",") if p]
    results: list[tuple[str, float, str]] = []
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        walls: dict[int, float] = {}
        for points in sizes:
            csv = folder / f"helix_{points}.csv"
            helix(points, csv)
            done = build(csv, series, folder / "out", WINDOW_ROWS)
            csv.unlink()
            tag = f"{series}_{label(points)}"
            if done is None:
                results.append((f"{tag}_streamed_failed", 1.0, "x"))
                continue
            walls[points] = done[0]
            results.append((f"{tag}_streamed_seconds", done[0], "s"))
            results.append((f"{tag}_streamed_peak_memory", done[1], "MB"))
            results.append((f"{tag}_streamed_us_per_point", done[0] / points * 1e6, "us"))
        results += fit(walls)
        posts = [p for p in args.posts.split(",") if p]
        results += per_post(folder, posts, args.post_points, args.reference, args.whole)
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
    folder: Path, posts: list[str], points: int, reference: Path | None, whole: bool = False
) -> list[tuple[str, float, str]]:
    """Each post's build of ``points`` as a user runs it, with the reference code, and
    (``whole``) built whole."""
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
        if whole:
            out += whole_build(csv, post, folder / "whole", tag, done)
    return out


def whole_build(
    csv: Path, post: str, out: Path, tag: str, done: tuple[float, float]
) -> list[tuple[str, float, str]]:
    """The same build whole (``--chunk-rows 0``), and the build as run (``done``) against it."""
    whole = build(csv, post, out, 0)
    if whole is None:
        return [(f"{post}_{tag}_whole_build_failed", 1.0, "x")]
    return [
        (f"{post}_{tag}_whole_build_seconds", whole[0], "s"),
        (f"{post}_{tag}_whole_peak_memory", whole[1], "MB"),
        (f"{post}_{tag}_build_seconds_vs_whole", done[0] / whole[0], "x"),
        (f"{post}_{tag}_peak_memory_vs_whole", done[1] / whole[1], "x"),
    ]


if __name__ == "__main__":
    main()
