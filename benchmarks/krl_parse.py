"""Reading a long KRL milling program: olp's KRL frontend against references in the same run.

Run from the repository root: ``python -m benchmarks.krl_parse [--lines N] [--repeats R]``.

The program is generated (seeded): ``$BASE``/``$TOOL``/``$VEL.CP``/``$APO.CDIS``, one PTP, then N
``LIN {X ..,Y ..,Z ..,A ..,B ..,C ..} C_DIS`` lines with a feed change (``$VEL.CP``) every 500
lines, as CAM posts write them. It is written to a temporary file and timed as:

* reference, read + split: reading the file and splitting it into lines (the floor);
* reference, lark without positions: lark's LALR parse of the text with the same grammar and
  ``propagate_positions=False`` (no AST, no lowering; garbage collector paused as in olp):
  what the grammar alone costs;
* ``load_krl``: olp end to end (read, parse with the fast path, lower, build the IR);
* ``load_krl`` without the fast path (every line through lark with positions), the former speed.

Everything runs on one core. Times are the best of R runs (the grammar is built before timing).
The last lines give each time as a ratio to ``load_krl``'s.

With ``--reference DIR`` (a checkout of other olp code, e.g. ``git archive main | tar -x -C
DIR``), ``load_krl`` of this code and of that code are also timed in fresh interpreters, one
after the other on the same file (the machine's load drifts less between the two), and the
ratio this / reference is printed. ``--only-load`` leaves out the lark references (at 1M lines
they take minutes).
"""

from __future__ import annotations

import argparse
import gc
import os
import random
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from lark import Lark

from olp.frontends.krl import load_krl, parse_krl
from olp.frontends.krl.parse import gc_paused
from olp.resources import data_path

REPO = Path(__file__).resolve().parents[1]
CHILD = r"""
import gc, sys, time
import olp
from olp.frontends.krl import load_krl
best = float("inf")
for _ in range(int(sys.argv[2])):
    gc.collect()
    start = time.perf_counter()
    load_krl(sys.argv[1])
    best = min(best, time.perf_counter() - start)
print(f"@@ {best:.4f} {olp.__file__}")
"""


def child_load_krl(path: Path, repeats: int, code: Path | None) -> float:
    """Best ``load_krl(path)`` time (s) in a fresh interpreter importing olp from ``code`` (this
    checkout if None); the grammar is built in the first run, so ``repeats`` should be >= 2 for
    small files."""
    env = {**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    env["PYTHONPATH"] = str(code if code is not None else REPO)
    done = subprocess.run(
        [sys.executable, "-c", CHILD, str(path), str(repeats)],
        capture_output=True,
        text=True,
        env=env,
        check=False,
        cwd=REPO.parent,
    )
    line = next((x for x in done.stdout.splitlines() if x.startswith("@@ ")), None)
    if line is None:
        raise SystemExit(f"load_krl failed in {code or REPO}:\n{done.stderr[-2000:]}")
    seconds, imported = line.split()[1:]
    expected = (code if code is not None else REPO).resolve()
    if not Path(imported).resolve().is_relative_to(expected):
        raise SystemExit(f"the child imported olp from {imported}, not from {expected}")
    return float(seconds)


def milling_program(lines: int, seed: int = 1) -> str:
    """A facing toolpath as a CAM post writes it: mm, degrees, one LIN per line."""
    rng = random.Random(seed)
    out = [
        "&ACCESS RVP",
        "DEF Milling ( )",
        "$BASE = {FRAME: X 0.000,Y -1000.000,Z 0.000,A 0.000,B 0.000,C 0.000}",
        "$TOOL = {FRAME: X 466.604,Y -4.165,Z 109.636,A -0.000,B 90.000,C 0.000}",
        "$VEL.CP = 1.00000",
        "$APO.CDIS = 0.5",
        "PTP {A1 107.78457,A2 -44.95260,A3 141.64681,A4 107.66839,A5 -87.93467,A6 6.37710}",
    ]
    for i in range(lines):
        if i % 500 == 0:
            out.append(f"$VEL.CP = {rng.uniform(0.01, 0.05):.5f}")
        x, y, z = rng.uniform(-300, 300), rng.uniform(-300, 300), rng.uniform(0, 20)
        out.append(f"LIN {{X {x:.3f},Y {y:.3f},Z {z:.3f},A -180.000,B 0.000,C -180.000}} C_DIS")
    out.append("END")
    return "\n".join(out) + "\n"


def best_of(fn: Callable[[], Any], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        gc.collect()
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def _without_gc(fn: Callable[[str], Any], text: str) -> Any:
    """As olp's frontend runs: the cyclic collector paused (it slows lark down non-linearly)."""
    with gc_paused():
        return fn(text)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lines", type=int, default=20_000, help="LIN lines (default 20000)")
    parser.add_argument("--repeats", type=int, default=3, help="runs per measurement")
    parser.add_argument("--reference", type=Path, default=None, help="other olp code to compare")
    parser.add_argument("--only-load", action="store_true", help="leave out the lark references")
    args = parser.parse_args()

    text = milling_program(args.lines)
    parse_krl(milling_program(10), "warm.src")  # builds the grammars outside the timings
    times: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "milling.src"
        path.write_text(text, encoding="utf-8")
        result = load_krl(path)
        assert len(result.program) == args.lines + 1, "every LIN and the PTP are lowered"
        times["read_split"] = best_of(lambda: path.read_text(encoding="utf-8").split("\n"), 3)
        if not args.only_load:
            times.update(_lark_references(path))
        times["load_krl"] = best_of(lambda: load_krl(path), args.repeats)
        if args.reference is not None:
            times["reference_load_krl_child"] = child_load_krl(path, args.repeats, args.reference)
            times["load_krl_child"] = child_load_krl(path, args.repeats, None)

    n = args.lines
    print(f"lin_lines: {n} lines")
    for name, seconds in times.items():
        print(f"{name}: {seconds:.4f} s")
        print(f"{name}_per_line: {seconds / n * 1e6:.2f} us")
    for name, seconds in times.items():
        if name != "load_krl":
            print(f"ratio_{name}_to_load_krl: {seconds / times['load_krl']:.3f} x")
    if args.reference is not None:
        ratio = times["load_krl_child"] / times["reference_load_krl_child"]
        print(f"load_krl_{n}_lines: {times['load_krl_child']:.2f} s")
        print(f"load_krl_vs_reference: {ratio:.3f} x")


def _lark_references(path: Path) -> dict[str, float]:
    grammar = data_path("grammars", "krl.lark").read_text(encoding="utf-8")
    bare = Lark(grammar, parser="lalr", propagate_positions=False, maybe_placeholders=True)
    parse_krl(milling_program(10), "warm.src", fast_path=False)
    return {
        "lark_no_positions": best_of(lambda: _without_gc(bare.parse, path.read_text()), 1),
        "load_krl_without_fast_path": best_of(
            lambda: parse_krl(path.read_text(), str(path), fast_path=False), 1
        ),
    }


if __name__ == "__main__":
    main()
