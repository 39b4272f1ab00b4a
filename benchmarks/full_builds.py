"""Full builds of a helix toolpath (CSV) on every post, as a new user runs them, with a reference
from the same run: the targets of "a million points in a minute".

Each build is ``olp build stations/kr6_milling_cell.yaml helix.csv --frame table --orientation
180,0,180 --post P`` with the default checks, collisions and timing, in a fresh interpreter with
one BLAS/OpenMP thread; its wall time and peak resident memory (Linux's VmHWM) are the child's
own. Also timed: ``olp --help`` and ``olp posts`` (the fixed cost of starting), and a 1k-point
build. The reference is the naive approach the issue names: olp's own single-pose inverse
kinematics called once per point in a Python loop, on the same points, in the same run.
With ``--reference DIR`` (a checkout of other olp code, e.g. ``git archive main | tar -x -C
DIR``), every build also runs with that code first on the import path, right before this
code's (the machine's load drifts less between the two), and the ratios this / reference are
printed.

    python benchmarks/full_builds.py [POINTS] [--posts kuka,abb,ur,fanuc] [--reference DIR]

Last lines: ``name: value unit``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
ORIENTATION = "180,0,180"

CHILD = r"""
import runpy, sys, time
start = time.perf_counter()
sys.argv = ["olp", *sys.argv[1:]]
code = 0
try:
    runpy.run_module("olp", run_name="__main__")
except SystemExit as exc:
    code = exc.code or 0
wall = time.perf_counter() - start
peak = 0.0
for line in open("/proc/self/status"):
    if line.startswith("VmHWM:"):
        peak = int(line.split()[1]) / 1024
print(f"@@ {wall:.3f} {peak:.1f} {code}", file=sys.stderr)
"""


def helix(points: int, path: Path) -> None:
    """A helix of ``points`` rows (mm, in the table frame) that the KR 6 cell reaches."""
    t = np.linspace(0.0, 40.0 * np.pi, points)
    xyz = np.c_[100 + 60 * np.cos(t), 60 * np.sin(t), 20 + np.linspace(0.0, 30.0, points)]
    np.savetxt(path, xyz, fmt="%.4f", delimiter=",", header="x,y,z", comments="")


def child_line(child: str, args: Sequence[str], code: Path | None) -> tuple[str | None, str]:
    """Run the script ``child`` with ``args`` in a fresh interpreter with one BLAS/OpenMP
    thread (``code``: a folder holding another ``olp`` package, imported instead of this one):
    the ``@@ ...`` line it prints on stderr (None if it printed none) and the stderr's end."""
    env = {**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "CI": "1"}
    if code is not None:
        env["PYTHONPATH"] = str(code)
    # From the repository's parent: the working folder comes first on the import path, so a
    # run from the repository would import this code even where ``code`` names another.
    done = subprocess.run(
        [sys.executable, "-c", child, *args],
        capture_output=True,
        text=True,
        env=env,
        check=False,
        cwd=REPO.parent,
    )
    line = next((x for x in done.stderr.splitlines() if x.startswith("@@ ")), None)
    return line, done.stderr[-2000:]


def run_olp(*args: str, code: Path | None = None) -> tuple[float, float, int]:
    """Wall time (s), peak memory (MB) and exit code of ``olp ARGS`` in a fresh interpreter
    (``code``: a folder holding another ``olp`` package, imported instead of this one)."""
    line, tail = child_line(CHILD, args, code)
    if line is None:
        raise SystemExit(f"olp {' '.join(args)} failed:\n{tail}")
    wall, peak, code = line.split()[1:]
    return float(wall), float(peak), int(code)


def naive_ik_seconds(points: int) -> float:
    """Seconds for olp's single-pose IK called once per helix point (the naive loop)."""
    import olp

    station = olp.load_station(CELL)
    robot = station.robot
    table, tool = station.frames["table"], station.tools["spindle"]
    assert table.pose is not None and tool.pose is not None
    t = np.linspace(0.0, 40.0 * np.pi, points)
    rotation = np.diag([-1.0, 1.0, -1.0])  # 180, 0, 180: the tool points down
    flange_in_tcp = np.linalg.inv(tool.pose)
    start = time.perf_counter()
    for k in range(points):
        pose = np.eye(4)
        pose[:3, :3] = rotation
        pose[:3, 3] = [0.1 + 0.06 * np.cos(t[k]), 0.06 * np.sin(t[k]), 0.02 + 0.03 * k / points]
        robot.solve(table.pose @ pose @ flange_in_tcp)
    return time.perf_counter() - start


def _build(folder: Path, post: str, label: str, code: Path | None) -> tuple[float, float]:
    """Wall time (s) and peak memory (MB) of building ``label``.csv in ``folder``."""
    wall, peak, exit_code = run_olp(
        "build", str(CELL), str(folder / f"{label}.csv"), "--frame", "table",
        "--orientation", ORIENTATION, "--post", post, "-o",
        str(folder / f"out_{post}_{label}"), "--quiet", code=code,
    )  # fmt: skip
    if exit_code != 0:
        raise SystemExit(f"olp build --post {post} on {label} exited {exit_code}")
    return wall, peak


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("points", nargs="?", type=int, default=100_000)
    parser.add_argument("--posts", default="kuka,abb,ur,fanuc")
    parser.add_argument("--reference", type=Path, default=None)
    args = parser.parse_args()
    posts = args.posts.split(",")
    results: list[tuple[str, float, str]] = []
    codes: list[tuple[str, Path | None]] = [("", None)]
    if args.reference is not None:
        codes.insert(0, ("reference_", args.reference.resolve()))
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        for label, count in (("1k", 1000), ("n", args.points)):
            helix(count, folder / f"{label}.csv")
        for command in (("--help",), ("posts",)):
            for prefix, code in codes:
                wall, _, _ = run_olp(*command, code=code)
                results.append((f"{prefix}olp_{command[0].strip('-')}_seconds", wall, "s"))
        for post in posts:
            for label in ("1k", "n"):
                for prefix, code in codes:
                    wall, peak = _build(folder, post, label, code)
                    tag = "1k" if label == "1k" else f"{args.points}"
                    results.append((f"{prefix}{post}_{tag}_build_seconds", wall, "s"))
                    results.append((f"{prefix}{post}_{tag}_peak_memory", peak, "MB"))
    reference = naive_ik_seconds(args.points)
    results.append((f"naive_ik_loop_{args.points}_seconds", reference, "s"))
    for post in posts:
        wall = next(v for n, v, _ in results if n == f"{post}_{args.points}_build_seconds")
        results.append((f"{post}_build_vs_naive_ik_loop", wall / reference, "x"))
    if args.reference is not None:
        values = {n: v for n, v, _ in results}
        for name, value, _unit in list(results):
            if not name.startswith("reference_") and f"reference_{name}" in values:
                ratio = value / values[f"reference_{name}"]
                results.append((f"{name}_vs_reference", ratio, "x"))
    print(f"points: {args.points}")
    for name, value, unit in results:
        print(f"{name}: {value:.3f} {unit}")


if __name__ == "__main__":
    main()
