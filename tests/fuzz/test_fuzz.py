"""A short run of the build fuzzer in CI (the long run: ``python benchmarks/fuzz_builds.py``):
no mutated example or station may end in anything but a build, program diagnostics or a located
input error (issue 10, item 7)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest


def _fuzzer() -> ModuleType:
    path = Path(__file__).with_name("fuzz_builds.py")
    spec = importlib.util.spec_from_file_location("olp_fuzz_builds", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("seed", [20261123, 7])
def test_mutated_builds_end_honestly(seed: int, tmp_path: Path) -> None:
    report = _fuzzer().run(30, seed, tmp_path)
    crashes = [f"{c.seed}/{c.post} {c.mutations}\n{c.detail}" for c in report.crashes]
    assert crashes == []
    assert sum(report.counts.values()) == 30
