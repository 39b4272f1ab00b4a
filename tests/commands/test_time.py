"""``olp time``: the per-instruction table, the speed sweep, trajectory and plot files, errors.

The command is run through its own module (``add_arguments`` + ``run``, as :mod:`olp.cli` does),
so these tests do not depend on its registration in :data:`olp.commands.COMMANDS`.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import olp
from olp.commands import time as time_command
from olp.errors import OlpError

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
MILLING = REPO / "examples" / "milling.src"


def _olp_time(*argv: str | Path) -> int:
    parser = argparse.ArgumentParser(prog="olp time")
    time_command.add_arguments(parser)
    args = parser.parse_args([str(a) for a in argv])
    try:
        return time_command.run(args)
    except OlpError as exc:
        print(exc.format(), file=sys.stderr)
        return 2


def _numbers(line: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?", line)]


def test_prints_total_and_a_row_per_instruction(capsys: pytest.CaptureFixture[str]) -> None:
    assert _olp_time(CELL, MILLING) == 0
    out = capsys.readouterr().out
    parsed = olp.parse(MILLING).program
    compiled = olp.compile(parsed, olp.load_station(CELL))
    assert f"cycle time   {compiled.cycle_time:.3f} s" in out
    rows = [line for line in out.splitlines() if "milling.src:" in line]
    assert len(rows) == len(parsed.instructions) == 7
    for row, step in zip(rows, compiled.steps, strict=True):
        index, line, path_mm, seconds = _numbers(row)
        assert int(index) == step.index and int(line) == step.instruction.span.line
        assert path_mm == pytest.approx(step.path_length * 1000, abs=0.006)
        assert seconds == pytest.approx(step.duration, abs=6e-4)
    total = next(line for line in out.splitlines() if line.split()[:1] == ["total"])
    assert _numbers(total)[-1] == pytest.approx(compiled.cycle_time, abs=6e-4)


def test_sweep_table_is_monotonic_in_both_speeds(capsys: pytest.CaptureFixture[str]) -> None:
    code = _olp_time(
        CELL, MILLING, "--sweep-linear", "20,50,200", "--sweep-joint", "25,100", "--quiet"
    )
    assert code == 0
    out = capsys.readouterr()
    lines = out.out.splitlines()
    head = next(i for i, line in enumerate(lines) if line.lstrip().startswith("mm/s"))
    assert _numbers(lines[head]) == [25, 100]
    table = np.array([_numbers(line) for line in lines[head + 1 : head + 4]])
    assert table[:, 0].tolist() == [20, 50, 200]
    times = table[:, 1:]
    assert np.all(np.diff(times, axis=0) < 0) and np.all(np.diff(times, axis=1) < 0)
    compiled = olp.compile(olp.parse(MILLING).program, olp.load_station(CELL))
    lin_travel = sum(s.path_length for s in compiled.steps if s.instruction.kind == "linear")
    assert times[0, 1] > lin_travel / 0.02  # the LINs alone at 20 mm/s
    assert "timing speeds" not in out.err  # not a terminal: no progress


def test_writes_trajectory_and_plot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    csv, png = tmp_path / "t.csv", tmp_path / "t.png"
    assert _olp_time(CELL, MILLING, "--trajectory", csv, "--plot", png, "--dt", "0.05") == 0
    lines = csv.read_text().splitlines()
    cycle = float(_numbers(capsys.readouterr().out.splitlines()[2])[0])
    assert len(lines) - 1 == int(np.ceil(cycle / 0.05 - 1e-9)) + 1
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_time_overrides_change_the_cycle(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    program = tmp_path / "calls.src"
    program.write_text("DEF calls( )\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 0,A6 0}\nSprayOn()\nEND\n")
    assert _olp_time(CELL, program, "--time", "call:sprayon=1.5") == 0
    assert "cycle time   1.500 s" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--sweep-linear", "fast"], "--sweep-linear: expected numbers in mm/s"),
        (["--sweep-linear", "0,100"], "speeds must be > 0"),
        (["--sweep-joint", "50,150"], "at most 100 %"),
        (["--time", "teleport=1"], "KIND one of"),
        (["--time", "call=-1"], "must be >= 0"),
        (["--dt", "0"], "--dt must be a positive"),
    ],
)
def test_bad_options_exit_2(
    options: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert _olp_time(CELL, MILLING, *options) == 2
    assert message in capsys.readouterr().err


def test_a_program_with_errors_exits_1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    far = tmp_path / "far.src"
    far.write_text(
        "DEF far( )\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 0,A6 0}\n"
        "LIN {X 5000,Y 0,Z 500,A 0,B 90,C 0}\nEND\n"
    )
    assert _olp_time(CELL, far, "--trajectory", tmp_path / "t.csv") == 1
    captured = capsys.readouterr()
    assert "error[unreachable" in captured.err and "cycle time" not in captured.out
    assert not (tmp_path / "t.csv").exists()


def test_the_command_module_imports_nothing_heavy() -> None:
    code = (
        "import sys, olp.commands.time\n"
        "heavy = ('pinocchio', 'toppra', 'ruckig', 'matplotlib', 'trimesh', 'lark')\n"
        "print([m for m in heavy if m in sys.modules])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize("quiet", [False, True])
def test_sweep_progress_only_on_a_terminal_and_not_quiet(
    quiet: bool, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    options = ["--sweep-linear", "50,100", "--sweep-joint", "50"] + (["--quiet"] if quiet else [])
    assert _olp_time(CELL, MILLING, *options) == 0
    err = capsys.readouterr().err
    if quiet:
        assert "timing speeds" not in err
    else:
        assert "timing speeds 1/3" in err and "timing speeds 3/3" in err


def test_a_huge_dwell_is_printed_short(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    program = tmp_path / "w.src"
    program.write_text("DEF w( )\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 45,A6 0}\nWAIT SEC 1E300\nEND\n")
    assert _olp_time(CELL, program) == 0
    out = capsys.readouterr().out
    assert "1e+300" in out and max(len(line) for line in out.splitlines()) < 120
