"""The progress display: stage lines with counts, rate and ETA on a terminal; nothing elsewhere."""

from __future__ import annotations

import io
import subprocess
import sys
from pathlib import Path

import pytest

from olp import progress

REPO = Path(__file__).resolve().parents[1]


class _Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_a_stage_shows_count_rate_and_eta_then_a_summary() -> None:
    out, clock = io.StringIO(), _Clock()
    with progress.showing(progress.Reporter(out, clock)), progress.stage("resolve", 1000):
        clock.now = 0.5
        progress.advance(250)  # 500 rows/s: 750 left, 1.5 s
        clock.now = 0.55
        progress.advance(10)  # within REFRESH_S of the last draw: not drawn
        clock.now = 2.0
    frames = out.getvalue().split("\r\033[K")
    assert frames[1] == "resolve   0/1,000 rows"
    assert frames[2] == "resolve   250/1,000 rows   500 rows/s   ETA 1.5 s"
    assert frames[3] == "resolve   1,000 rows in 2.0 s (500 rows/s)\n"
    assert len(frames) == 4


def test_without_a_reporter_nothing_is_shown(capsys: pytest.CaptureFixture[str]) -> None:
    with progress.stage("resolve", 10):
        progress.advance(10)
    assert capsys.readouterr() == ("", "")


@pytest.mark.parametrize(
    ("quiet", "ci", "tty", "shown"),
    [
        (False, None, True, True),
        (True, None, True, False),  # --quiet
        (False, "true", True, False),  # under CI
        (False, None, False, False),  # output to a file or a pipe
    ],
)
def test_progress_only_for_a_person_at_a_terminal(
    monkeypatch: pytest.MonkeyPatch, quiet: bool, ci: str | None, tty: bool, shown: bool
) -> None:
    if ci is None:
        monkeypatch.delenv("CI", raising=False)
    else:
        monkeypatch.setenv("CI", ci)
    stream = _Tty() if tty else io.StringIO()
    assert (progress.terminal_reporter(quiet, stream) is not None) is shown


def test_a_build_in_a_pipe_writes_no_progress(tmp_path: Path) -> None:
    csv = tmp_path / "p.csv"
    csv.write_text("x,y,z\n100,0,20\n110,0,20\n120,0,20\n", encoding="utf-8")
    done = subprocess.run(
        [sys.executable, "-m", "olp", "build", str(REPO / "stations" / "kr6_milling_cell.yaml"),
         str(csv), "--frame", "table", "--orientation", "180,0,180", "-o", str(tmp_path / "o")],
        capture_output=True, text=True, check=False, cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "\r" not in done.stderr and "rows/s" not in done.stderr + done.stdout
