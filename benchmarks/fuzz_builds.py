"""The long run of the build fuzzer (tests/fuzz/fuzz_builds.py): N mutants of the bundled
examples and stations, each built through a random post; prints how they ended and saves every
crash (mutant and traceback) under the work folder.

    python benchmarks/fuzz_builds.py [COUNT] [SEED]

Last lines: ``name: value unit``.
"""

from __future__ import annotations

import importlib.util
import sys
import tempfile
import warnings
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def main() -> None:
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    spec = importlib.util.spec_from_file_location(
        "olp_fuzz_builds", REPO / "tests" / "fuzz" / "fuzz_builds.py"
    )
    assert spec is not None and spec.loader is not None
    fuzz = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = fuzz
    spec.loader.exec_module(fuzz)
    work = Path(tempfile.mkdtemp(prefix="olp-fuzz-"))
    tty = sys.stderr.isatty()

    def progress(done: int) -> None:
        if tty:
            print(f"\r{done}/{count}", end="", file=sys.stderr, flush=True)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        report = fuzz.run(count, seed, work, progress)
    if tty:
        print(file=sys.stderr)
    for crash in report.crashes:
        print(f"crash: {crash.seed}/{crash.post} {crash.mutations}")
        print("  " + crash.detail.strip().splitlines()[-1])
    print(f"work folder: {work}")
    for kind in ("built", "program", "input", "crash"):
        print(f"{kind}: {report.counts.get(kind, 0)} mutants")
    print(f"rate: {count / report.seconds:.1f} mutants/s")
    print(f"crashes: {len(report.crashes)} of {count}")


if __name__ == "__main__":
    main()
