"""The station's ``targets:`` section (issue 16): named Cartesian targets in a frame and joint
targets, read in SI, and every mistake a located StationError."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import numpy as np
import pytest

from olp.errors import StationError
from olp.geometry import rotation_from_zyx
from olp.station.loader import load_station
from olp.station.schema import station_schema_json

BASE = (
    "robot:\n  model: kuka/kr6_r900_sixx\n"
    "frames:\n  - {name: table, pose: {xyz: [400, 0, -100]}}\n"
    "targets:\n"
)


def _load(tmp_path: Path, targets: str) -> object:
    path = tmp_path / "cell.yaml"
    path.write_text(BASE + targets, encoding="utf-8")
    return load_station(path)


def test_targets_are_read_in_si_in_their_frame(tmp_path: Path) -> None:
    station = _load(
        tmp_path,
        "  - {name: Home, joints_deg: [0, -90, 90, 0, 45, 0]}\n"
        "  - {name: Target 1, frame: table, pose: {xyz: [10, 20, 30], zyx: [90, 0, 180]}}\n",
    )
    home, target = station.targets["Home"], station.targets["Target 1"]  # type: ignore[attr-defined]
    assert home.pose is None and home.frame == "world"
    assert np.allclose(np.degrees(home.joints), [0, -90, 90, 0, 45, 0])
    assert target.joints is None and target.frame == "table"
    assert np.allclose(target.pose[:3, 3], [0.010, 0.020, 0.030])  # mm -> m, in the frame
    assert np.allclose(target.pose[:3, :3], rotation_from_zyx(*np.radians([90, 0, 180])))


BAD_TARGETS = [
    (
        "both",
        "  - {name: a, pose: {xyz: [0, 0, 0]}, joints_deg: [0, 0, 0, 0, 0, 0]}\n",
        6,
        "either a 'pose' or 'joints_deg', exactly one",
    ),
    ("neither", "  - {name: a}\n", 6, "either a 'pose' or 'joints_deg', exactly one"),
    ("joint count", "  - {name: a, joints_deg: [0, 0, 0]}\n", 6, "expected a list of 6 numbers"),
    (
        "outside limits",
        "  - {name: a, joints_deg: [0, -90, 200, 0, 0, 0]}\n",
        6,
        "joint 3 lies outside its limits (-120 to 156 deg)",
    ),
    (
        "unknown frame",
        "  - {name: a, frame: tabel, pose: {xyz: [0, 0, 0]}}\n",
        6,
        "unknown frame 'tabel' (frames: table)",
    ),
    (
        "duplicate",
        "  - {name: a, joints_deg: [0, -90, 90, 0, 0, 0]}\n"
        "  - {name: a, joints_deg: [0, -90, 90, 0, 0, 0]}\n",
        7,
        "duplicate target name 'a'",
    ),
    ("unknown key", "  - {name: a, joints: [0, 0, 0, 0, 0, 0]}\n", 6, "unknown key 'joints'"),
    ("bad pose", "  - {name: a, pose: {xyz: [0, 0]}}\n", 6, "expected a list of 3 numbers"),
]


@pytest.mark.parametrize(
    ("text", "line", "message"), [r[1:] for r in BAD_TARGETS], ids=[r[0] for r in BAD_TARGETS]
)
def test_bad_targets_are_located_errors(tmp_path: Path, text: str, line: int, message: str) -> None:
    with pytest.raises(StationError) as info:
        _load(tmp_path, text)
    assert info.value.span is not None and info.value.span.line == line
    assert message in info.value.message


def test_the_schema_knows_targets(tmp_path: Path) -> None:
    import yaml

    schema = json.loads(station_schema_json())
    good = yaml.safe_load(BASE + "  - {name: a, frame: table, pose: {xyz: [0, 0, 0]}}\n")
    jsonschema.validate(good, schema)
    bad = yaml.safe_load(BASE + "  - {name: a}\n")
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, schema)
