"""End to end: the README's demo, exit codes, the JSON report, round trip, nothing half-written."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import olp
from olp.cli import main
from olp.frontends.krl import load_krl, parse_krl
from olp.ir import CartesianTarget, JointTarget

REPO = Path(__file__).resolve().parents[1]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
MILLING = REPO / "examples" / "milling.src"


def _build(tmp_path: Path, *extra: str, program: Path = MILLING) -> tuple[int, Path]:
    out = tmp_path / "out"
    code = main(["build", str(CELL), str(program), "--post", "kuka", "-o", str(out), *extra])
    return code, out


def test_demo_builds_and_writes_src_and_dat(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out = _build(tmp_path, "--report", str(tmp_path / "r.json"))
    assert code == 0
    src = (out / "Milling.src").read_bytes()
    dat = (out / "Milling.dat").read_bytes()
    assert src.startswith(b"&ACCESS RVP\r\n") and b"DEF Milling( )\r\n" in src
    assert src.rstrip().endswith(b"END")
    assert b"DEFDAT Milling PUBLIC" in dat and dat.rstrip().endswith(b"ENDDAT")
    summary = capsys.readouterr().out
    assert "all 7 motions feasible" in summary and "cycle time" in summary


def test_report_has_the_stable_keys(tmp_path: Path) -> None:
    report_path = tmp_path / "r.json"
    code, _out = _build(tmp_path, "--report", str(report_path), "--quiet")
    assert code == 0
    report = json.loads(report_path.read_text())
    for key in ("program", "post", "files", "cycle_time_s", "instructions", "diagnostics"):
        assert key in report
    assert report["program"] == "Milling" and report["post"] == "kuka"
    assert sorted(Path(f).name for f in report["files"]) == ["Milling.dat", "Milling.src"]
    motions = report["instructions"]
    assert [m["kind"] for m in motions] == ["joint"] + ["linear"] * 6
    assert motions[0]["source"].endswith("milling.src:5") and motions[1]["source"].endswith(":6")
    assert motions[0]["joints_deg"] == pytest.approx(
        [107.78457, -44.9526, 141.64681, 107.66839, -87.93467, 6.3771]
    )
    assert all(m["time_s"] > 0 for m in motions)
    assert report["cycle_time_s"] == pytest.approx(sum(m["time_s"] for m in motions), rel=1e-6)


def test_emitted_krl_reparses_to_the_same_targets(tmp_path: Path) -> None:
    code, out = _build(tmp_path, "--quiet")
    assert code == 0
    original = load_krl(MILLING).program
    again = load_krl(out / "Milling.src").program
    first, second = list(original.motions()), list(again.motions())
    assert len(first) == len(second)
    for a, b in zip(first, second, strict=True):
        assert a.kind == b.kind
        # the speed that governs the motion: $VEL.CP for LIN, $VEL_AXIS for PTP
        if a.kind == "linear":
            assert a.speed.linear == pytest.approx(b.speed.linear, abs=1e-12)
        else:
            assert a.speed.joint == pytest.approx(b.speed.joint, abs=1e-12)
        assert a.tool.pose is not None and b.tool.pose is not None
        assert np.allclose(a.tool.pose, b.tool.pose, atol=1e-9)
        assert a.frame.pose is not None and b.frame.pose is not None
        assert np.allclose(a.frame.pose, b.frame.pose, atol=1e-9)
        if isinstance(a.target, CartesianTarget):
            assert isinstance(b.target, CartesianTarget)
            # 1e-6 mm on positions; orientations to the same precision at a 1 m lever arm
            assert np.allclose(a.target.pose[:3, 3], b.target.pose[:3, 3], atol=1e-9)
            assert np.allclose(a.target.pose[:3, :3], b.target.pose[:3, :3], atol=1e-9)
        else:
            assert isinstance(a.target, JointTarget) and isinstance(b.target, JointTarget)
            assert np.allclose(a.target.joints, b.target.joints, atol=1e-9)


def test_output_is_deterministic(tmp_path: Path) -> None:
    _build(tmp_path / "a", "--quiet")
    _build(tmp_path / "b", "--quiet")
    for name in ("Milling.src", "Milling.dat"):
        assert (tmp_path / "a/out" / name).read_bytes() == (tmp_path / "b/out" / name).read_bytes()


def test_bad_src_line_exits_2_with_a_located_message(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.src"
    bad.write_text("DEF bad( )\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 0,A6 0}\nLIN {X 1,Y 2,Z}\nEND\n")
    code, out = _build(tmp_path, program=bad)
    assert code == 2
    err = capsys.readouterr().err
    assert f"{bad}:3:" in err and "LIN {X 1,Y 2,Z}" in err and "^" in err
    assert not out.exists()


def test_unreachable_target_exits_1_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    far = tmp_path / "far.src"
    far.write_text(
        "DEF far( )\n$VEL.CP = 0.5\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 0,A6 0}\n"
        "LIN {X 5000,Y 0,Z 500,A 0,B 90,C 0}\nEND\n"
    )
    code, out = _build(tmp_path, program=far)
    assert code == 1
    err = capsys.readouterr().err
    assert f"{far}:4:1: error[unreachable" in err
    assert not out.exists()


def test_library_build_matches_the_cli(tmp_path: Path) -> None:
    result = olp.build(olp.load_station(CELL), MILLING, post="kuka", out_dir=tmp_path / "lib")
    _build(tmp_path, "--quiet")
    assert result.ok
    assert (tmp_path / "lib/Milling.src").read_bytes() == (
        tmp_path / "out/Milling.src"
    ).read_bytes()


def test_unknown_post_is_a_usage_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _ = _build(tmp_path, "--post", "nosuchpost")
    assert code == 2 and "unknown post 'nosuchpost'" in capsys.readouterr().err


def test_help_does_not_import_heavy_modules() -> None:
    code = (
        "import sys; from olp.cli import main\n"
        "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
        "names = ('pinocchio', 'toppra', 'trimesh', 'ruckig', 'lark')\n"
        "heavy = [m for m in names if m in sys.modules]\n"
        "print(heavy)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]"


def test_parse_krl_is_usable_on_text() -> None:
    result = parse_krl(MILLING.read_text(), "milling.src")
    assert result.program.name.lower() == "milling"
