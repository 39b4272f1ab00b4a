"""``olp check``: every check, nothing written; SARIF for CI systems."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from olp.cli import main

REPO = Path(__file__).resolve().parents[2]
CELL = str(REPO / "stations" / "kr6_milling_cell.yaml")

BAD = """DEF bad( )
$VEL.CP = 0.5
PTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}
LIN {X 5000,Y 0,Z 500,A 0,B 90,C 0}
LIN {X 500,Y 0,Z 600,A 0,B 90,C 0}
END
"""


def _program(tmp_path: Path, text: str = BAD) -> str:
    path = tmp_path / "bad.src"
    path.write_text(text)
    return str(path)


def test_check_reports_and_writes_no_code(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    code = main(["check", CELL, _program(tmp_path)])
    assert code == 1
    assert not (tmp_path / "out").exists()
    assert main(["check", CELL, str(REPO / "examples" / "milling.src"), "-q"]) == 0


def test_sarif_points_at_the_source_line(tmp_path: Path) -> None:
    sarif = tmp_path / "r.sarif"
    assert main(["check", CELL, _program(tmp_path), "--sarif", str(sarif), "-q"]) == 1
    log = json.loads(sarif.read_text())
    assert log["version"] == "2.1.0"
    run = log["runs"][0]
    assert run["tool"]["driver"]["name"] == "olp"
    (result,) = run["results"]
    assert result["ruleId"] == "unreachable" and result["level"] == "error"
    region = result["locations"][0]["physicalLocation"]["region"]
    assert region["startLine"] == 4
    assert run["tool"]["driver"]["rules"][result["ruleIndex"]]["id"] == "unreachable"


def test_skip_unreachable_makes_the_check_pass_with_a_warning(tmp_path: Path) -> None:
    sarif = tmp_path / "r.sarif"
    args = ["check", CELL, _program(tmp_path), "--skip-unreachable", "--sarif", str(sarif), "-q"]
    assert main(args) == 0
    levels = [r["level"] for r in json.loads(sarif.read_text())["runs"][0]["results"]]
    assert "warning" in levels and "error" not in levels


def test_sarif_output_is_deterministic(tmp_path: Path) -> None:
    prog = _program(tmp_path)
    main(["check", CELL, prog, "--sarif", str(tmp_path / "a.sarif"), "-q"])
    main(["check", CELL, prog, "--sarif", str(tmp_path / "b.sarif"), "-q"])
    assert (tmp_path / "a.sarif").read_bytes() == (tmp_path / "b.sarif").read_bytes()
