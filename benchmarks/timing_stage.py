"""The timing stage and KUKA's column writer inside a helix build, this code against a
reference in the same run: where "a million points in a minute" spends its time after resolve.

Each build is ``olp build stations/kr6_milling_cell.yaml helix.csv --frame table --orientation
180,0,180 --post kuka`` as a user runs it (streamed in windows from 1M rows), in a fresh
interpreter with one BLAS/OpenMP thread, on the helix of ``full_builds.helix``. Inside it the
CPU time (``time.process_time``: the other processes on a busy machine count less than in
wall time) spent in ``time_program`` (the timing stage: every call, all windows) and in KUKA's
``_column_lines`` (the row writer) is summed. With ``--reference DIR`` (e.g. ``git archive main
| tar -x -C DIR``) every build also runs with that code, right before this code's, and the
ratios this / reference are printed. The best of ``--repeats`` builds is kept per stage.
The written files of the two builds are compared byte for byte.

    python benchmarks/timing_stage.py [--points 100000,1000000] [--reference DIR]
                                      [--repeats 1]

Last lines: ``name: value unit``.
"""

from __future__ import annotations

import argparse
import filecmp
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from full_builds import CELL, ORIENTATION, child_line
from scaling import helix, label

CHILD = r"""
import sys, time
import olp.passes.timing.program as program
import olp.posts.kuka as kuka
spent = {"timing": 0.0, "writer": 0.0}

def summed(name, fn):
    def wrapper(*args, **kwargs):
        start = time.process_time()
        try:
            return fn(*args, **kwargs)
        finally:
            spent[name] += time.process_time() - start
    return wrapper

timer = summed("timing", program.time_program)
for module in list(sys.modules.values()):  # every module that imported time_program by name
    if getattr(module, "__name__", "").startswith("olp.") and (
        getattr(module, "time_program", None) is program.time_program
    ):
        module.time_program = timer
kuka._column_lines = summed("writer", kuka._column_lines)
import olp.passes.timing.window  # noqa: F401 (the streamed build's timer, patched below)
sys.modules["olp.passes.timing.window"].time_program = timer
from olp.cli import main
code = 0
try:
    main(sys.argv[1:])
except SystemExit as exc:
    code = exc.code or 0
print(f"@@ {spent['timing']:.4f} {spent['writer']:.4f} {code}", file=sys.stderr)
"""


def stages(csv: Path, out: Path, code: Path | None) -> tuple[float, float]:
    """CPU seconds in the timing stage and in the writer of one build."""
    args = [
        "build", str(CELL), str(csv), "--frame", "table", "--orientation", ORIENTATION,
        "--post", "kuka", "-o", str(out), "--quiet",
    ]  # fmt: skip
    line, tail = child_line(CHILD, args, code)
    if line is None or line.split()[3] != "0":
        raise SystemExit(f"olp {' '.join(args)} failed:\n{tail}")
    timing, writer = line.split()[1:3]
    return float(timing), float(writer)


def same_files(left: Path, right: Path) -> bool:
    """Whether two output folders hold the same files with the same bytes."""
    names = sorted(p.name for p in left.iterdir())
    if names != sorted(p.name for p in right.iterdir()):
        return False
    _, mismatch, errors = filecmp.cmpfiles(left, right, names, shallow=False)
    return not mismatch and not errors


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", default="100000,1000000")
    parser.add_argument("--reference", type=Path, default=None)
    parser.add_argument("--repeats", type=int, default=1)
    args = parser.parse_args()
    results: list[tuple[str, float, str]] = []
    with tempfile.TemporaryDirectory() as scratch:
        root = Path(scratch)
        for points in [int(p) for p in args.points.split(",") if p]:
            csv = root / f"helix{points}.csv"
            helix(points, csv)
            name = label(points)
            codes: dict[str, Path | None] = {}
            if args.reference is not None:
                codes["ref"] = args.reference  # first: the machine's load drifts
            codes["this"] = None
            best: dict[str, tuple[float, float]] = {}
            for repeat in range(args.repeats):
                for key, code in codes.items():
                    out = root / f"{key}{points}"
                    timing, writer = stages(csv, out, code)
                    old = best.get(key, (float("inf"), float("inf")))
                    best[key] = (min(old[0], timing), min(old[1], writer))
                    print(f"# {name} {key} run {repeat}: timing {timing:.3f} s, writer "
                          f"{writer:.3f} s", file=sys.stderr)  # fmt: skip
            results += [
                (f"timing_{name}", best["this"][0], "s"),
                (f"writer_{name}", best["this"][1], "s"),
            ]
            if "ref" in best:
                ref = best["ref"]
                results += [
                    (f"timing_{name}_reference", ref[0], "s"),
                    (f"writer_{name}_reference", ref[1], "s"),
                    (f"timing_{name}_ratio", best["this"][0] / ref[0], "x"),
                    (f"writer_{name}_ratio", best["this"][1] / ref[1], "x"),
                    (f"same_bytes_{name}", float(same_files(root / f"ref{points}",
                                                            root / f"this{points}")), "bool"),
                ]  # fmt: skip
    for name, value, unit in results:
        print(f"{name}: {value:.4g} {unit}")


if __name__ == "__main__":
    main()
