"""``python -m olp`` never imports modules from the working directory (issue 10, item 5)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def test_python_dash_m_olp_ignores_modules_in_the_working_directory(tmp_path: Path) -> None:
    (tmp_path / "yaml.py").write_text('raise SystemExit("yaml.py from the working directory")\n')
    (tmp_path / "numpy.py").write_text('raise SystemExit("numpy.py from the working directory")\n')
    run = subprocess.run(
        [sys.executable, "-m", "olp", "posts"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr
    assert "working directory" not in run.stdout + run.stderr
    assert "kuka" in run.stdout
