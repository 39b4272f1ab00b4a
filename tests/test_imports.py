"""``import olp``, ``olp --help`` and ``olp posts`` stay light (issue 11; issue 14's fixed cost):
no pinocchio, toppra, trimesh, matplotlib or scipy, and ``olp --help``/``olp posts`` not even
numpy. Checked in a fresh interpreter, since the test process has imported everything."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

HEAVY = ("pinocchio", "toppra", "trimesh", "matplotlib", "scipy", "coal", "numpy")

CODE = """
import json, sys, contextlib, io
{setup}
print(json.dumps(sorted(m for m in {heavy!r} if m in sys.modules)))
"""

CASES = {
    "import olp": ("import olp", []),
    "olp --help": (
        "from olp.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    try:\n        main(['--help'])\n    except SystemExit:\n        pass",
        [],
    ),
    "olp posts": (
        "from olp.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n    main(['posts'])",
        [],
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_light_imports(case: str) -> None:
    setup, allowed = CASES[case]
    code = CODE.format(setup=setup, heavy=HEAVY)
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = json.loads(run.stdout.strip().splitlines()[-1])
    assert set(loaded) <= set(allowed), f"{case} imports {loaded}"
