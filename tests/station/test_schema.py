"""``olp schema station``: a valid JSON Schema that accepts every bundled station and robot file
and rejects the mistakes the loader rejects."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest
import yaml

from olp.commands import schema as schema_command
from olp.station.schema import STATION, station_schema_json

jsonschema = pytest.importorskip("jsonschema")

REPO = Path(__file__).resolve().parents[2]


def _validator(schema: dict) -> jsonschema.Draft202012Validator:
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> str:
    parser = argparse.ArgumentParser()
    schema_command.add_arguments(parser)
    assert schema_command.run(parser.parse_args(list(argv))) == 0
    return capsys.readouterr().out


def test_command_prints_the_schema_as_json(capsys: pytest.CaptureFixture[str]) -> None:
    printed = json.loads(_run(capsys, "station"))
    assert printed == json.loads(json.dumps(STATION))
    _validator(printed)


def test_command_writes_a_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "schemas" / "station.schema.json"
    assert _run(capsys, "station", "-o", str(out)) == ""
    assert out.read_text(encoding="utf-8") == station_schema_json()


@pytest.mark.parametrize("path", sorted((REPO / "stations").glob("*.yaml")), ids=lambda p: p.stem)
def test_bundled_stations_validate(path: Path) -> None:
    document = yaml.safe_load(path.read_text(encoding="utf-8"))
    errors = list(_validator(STATION).iter_errors(document))
    assert not errors, errors[0].message


@pytest.mark.parametrize(
    "path", sorted((REPO / "stations" / "robots").glob("*/*.yaml")), ids=lambda p: p.stem
)
def test_library_robots_validate(path: Path) -> None:
    robot_schema = {**STATION["$defs"]["robot_model"], "$defs": STATION["$defs"]}
    document = yaml.safe_load(path.read_text(encoding="utf-8"))
    errors = list(_validator(robot_schema).iter_errors(document))
    assert not errors, errors[0].message


@pytest.mark.parametrize(
    "text",
    [
        "name: x\n",
        "robot:\n  model: kuka/kr6_r900_sixx\n  bsae: {}\n",
        "robot:\n  model: kuka/kr6_r900_sixx\n  base: {xyz: [1, 2]}\n",
        "robot:\n  model: kuka/kr6_r900_sixx\n  base: {zyx: [0, 0, 0], quat: [1, 0, 0, 0]}\n",
        "robot: {model: kuka/kr6_r900_sixx}\ntools: [{name: t, mass_kg: -1}]\n",
        "robot: {model: kuka/kr6_r900_sixx}\ntools: [{name: t, geometry: [{sphere: {radius: 1},"
        " box: {size: [1, 1, 1]}}]}]\n",
        "robot: {model: kuka/kr6_r900_sixx}\nparts: [{name: p, geometry: []}]\n",
        "robot: {vendor: kuka, kinematics: {type: scara}, limits: {}, home_deg: []}\n",
        "robot: {model: kuka/kr6_r900_sixx, vendor: kuka}\n",
    ],
)
def test_schema_rejects_what_the_loader_rejects(text: str) -> None:
    assert list(_validator(STATION).iter_errors(yaml.safe_load(text)))
