"""``olp check``: every check, nothing written; SARIF for CI systems."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from olp.cli import main

REPO = Path(__file__).resolve().parents[2]
CELL = str(REPO / "stations" / "kr6_milling_cell.yaml")

BAD = """DEF bad( )
$TOOL = $NULLFRAME
$BASE = $NULLFRAME
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
    assert region["startLine"] == 6
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


COLLISION_CELL = str(REPO / "stations" / "kr6_milling_collision_cell.yaml")
MILLING = str(REPO / "examples" / "milling.src")


def test_collisions_are_checked_by_default_and_can_be_switched_off(
    capsys: pytest.CaptureFixture[str],
) -> None:
    # The job-5 program on the collision cell: turning the tool to A -160 on line 9 swings the
    # spindle into a clamp (the job-5 inline $TOOL is matched to the station spindle by TCP).
    assert main(["check", COLLISION_CELL, MILLING, "-q"]) == 1
    err = capsys.readouterr().err
    assert "milling.src:9:1: error[collision]: tool 'spindle' hits fixture 'clamp_x_plus'" in err
    # allowed contact, or no collision check at all, lets it pass
    allowed = ["--allow-contact", "spindle,clamp_x_plus"]
    assert main(["check", COLLISION_CELL, MILLING, "-q", *allowed]) == 0
    assert main(["check", COLLISION_CELL, MILLING, "-q", "--no-collisions"]) == 0
    # a clearance makes the check stricter: a link near another clamp is reported too
    args = ["check", COLLISION_CELL, MILLING, "-q", *allowed, "--clearance", "200"]
    assert main(args) == 1
    assert "closer than 200.0 mm" in capsys.readouterr().err


def test_allow_contact_needs_two_names(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", COLLISION_CELL, MILLING, "--allow-contact", "link_3"]) == 2
    assert "two names" in capsys.readouterr().err
