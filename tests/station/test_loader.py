"""Station YAML: SI inside, and every mistake located by file, line, column and key."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from olp.errors import StationError
from olp.station.loader import load_station, robot_library

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"


def test_bundled_cell_loads_in_si_units() -> None:
    station = load_station(CELL)
    robot = station.robot
    assert robot.vendor == "kuka"
    assert robot.kinematics.c2 == pytest.approx(0.455)
    assert np.degrees(robot.limits.upper[5]) == pytest.approx(350)
    assert np.degrees(robot.limits.velocity[0]) == pytest.approx(360)
    spindle = station.tools["spindle"]
    assert spindle.pose is not None and spindle.pose[0, 3] == pytest.approx(0.466604)
    # zyx [0, 90, 0] turns the tool's Z axis onto the flange's X axis (out of the flange)
    assert np.allclose(spindle.pose[:3, :3] @ [0, 0, 1], [1, 0, 0], atol=1e-12)
    assert "kuka/kr6_r900_sixx" in robot_library()


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "cell.yaml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("text", "line", "needle"),
    [
        ("name: x\nrobot:\n  model: kuka/nope\n", 3, "unknown robot model 'kuka/nope'"),
        ("name: x\nrobot:\n  model: kuka/kr6_r900_sixx\n  bsae: {}\n", 4, "unknown key 'bsae'"),
        ("name: x\nrobot:\n  model: kuka/kr6_r900_sixx\n  base: {xyz: [1, 2]}\n", 4, "3 numbers"),
        (
            "name: x\nrobot:\n  model: kuka/kr6_r900_sixx\n"
            "tools:\n  - {name: t, tcp: {xyz: [1, 2, a]}}\n",
            5,
            "finite number",
        ),
        ("name: x\nrobot: [1, 2\n", 3, "invalid YAML"),
        ("name: x\n", 1, "missing required key 'robot'"),
        (
            "name: x\nrobot:\n  model: kuka/kr6_r900_sixx\n  home_deg: [0, -90, 90, 0, 0, 400]\n",
            4,
            "outside the joint limits",
        ),
        (
            "robot: {model: kuka/kr6_r900_sixx}\nframes:\n  - {name: a}\n  - {name: a}\n",
            4,
            "duplicate name 'a'",
        ),
    ],
)
def test_mistakes_are_located(tmp_path: Path, text: str, line: int, needle: str) -> None:
    path = _write(tmp_path, text)
    with pytest.raises(StationError) as info:
        load_station(path)
    err = info.value
    assert needle in err.message
    assert err.span is not None and err.span.file == str(path) and err.span.line == line
    assert f"{path}:{line}:" in err.format()


def test_limits_can_be_overridden_per_station(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "robot:\n  model: kuka/kr6_r900_sixx\n  limits:\n"
        "    velocity_deg_s: [10, 10, 10, 10, 10, 10]\n",
    )
    robot = load_station(path).robot
    assert np.allclose(np.degrees(robot.limits.velocity), 10)
    assert np.degrees(robot.limits.upper[0]) == pytest.approx(170)
