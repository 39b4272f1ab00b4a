"""Path and orientation accelerations (``Speed.linear_acceleration`` / ``angular_acceleration``)
written back by every post, or warned where the language cannot say them."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.geometry import transl
from olp.station.model import Station
from tests.posts.test_all_posts import CELLS, READY, _lines
from tests.posts.test_rows import _both, _moves


@pytest.fixture(scope="module")
def stations() -> dict[str, Station]:
    return {post: olp.load_station(path) for post, path in CELLS.items()}


def _program(station: Station, post: str, speed: ir.Speed) -> ir.Program:
    """READY, 20 mm out along the flange's Z with ``speed``, a joint move back to READY."""
    ready = ir.JointMove(target=ir.JointTarget(joints=np.radians(READY[post])))
    flange = station.robot.flange_poses(np.radians(READY[post]))
    away = ir.CartesianTarget(pose=flange @ transl(0.0, 0.0, 0.02))
    out = ir.LinearMove(target=away, speed=speed)
    return ir.Program(name="Acc", instructions=(ready, out, ready))


SET = ir.Speed(linear=0.1, linear_acceleration=0.5, angular_acceleration=math.radians(90))

WRITTEN = {
    "kuka": ["$VEL.CP = 0.10000", "$ACC.CP = 0.5000", "$ACC.ORI1 = 90.000"],
    "abb": ["PathAccLim TRUE \\AccMax:=0.500, TRUE \\DecelMax:=0.500;"],
    "ur": ["movel("],
    "fanuc": ["L P[2] 100mm/sec FINE    ;"],
}
"""Lines each post writes for the move out (UR: ``a=0.50000`` checked below)."""

WARNED = {
    "kuka": [],
    "abb": ["orientation"],
    "ur": ["orientation"],
    "fanuc": ["TCP path", "orientation"],
}
"""What each post warns that it cannot write (kind ``acceleration``)."""


@pytest.mark.parametrize("post", sorted(CELLS))
def test_accelerations_written_or_warned(stations: dict[str, Station], post: str) -> None:
    result = olp.build(stations[post], _program(stations[post], post, SET), post=post)
    lines = _lines(result.files)
    for expected in WRITTEN[post]:
        assert any(line.startswith(expected) for line in lines), "\n".join(lines)
    warned = [d for d in result.diagnostics if d.kind == "acceleration"]
    assert [d.severity for d in warned] == ["warning"] * len(WARNED[post])
    for diagnostic, what in zip(warned, WARNED[post], strict=True):
        assert what in diagnostic.message and diagnostic.index == 1
    if post == "ur":
        (movel,) = [line for line in lines if line.startswith("movel(")]
        assert "a=0.50000, v=0.10000" in movel


def test_rapid_resets_the_path_acceleration_before_a_joint_move(
    stations: dict[str, Station],
) -> None:
    result = olp.build(stations["abb"], _program(stations["abb"], "abb", SET), post="abb")
    lines = _lines(result.files)
    at = lines.index("PathAccLim TRUE \\AccMax:=0.500, TRUE \\DecelMax:=0.500;")
    assert lines[at + 1].startswith("MoveL ")
    assert lines[at + 2] == "PathAccLim FALSE, FALSE;" and lines[at + 3].startswith("MoveAbsJ")


@pytest.mark.parametrize("post", sorted(CELLS))
def test_no_acceleration_no_change(stations: dict[str, Station], post: str) -> None:
    plain = ir.Speed(linear=0.1)
    result = olp.build(stations[post], _program(stations[post], post, plain), post=post)
    text = "\n".join(result.files.values())
    assert "$ACC.CP" not in text and "PathAccLim" not in text and "$ACC.ORI" not in text
    assert not [d for d in result.diagnostics if d.kind == "acceleration"]


@pytest.mark.parametrize(
    ("field", "value"), [("linear_acceleration", 0.0), ("angular_acceleration", math.inf)]
)
def test_speed_rejects_bad_accelerations(field: str, value: float) -> None:
    with pytest.raises(ir.IRError, match=field):
        ir.Speed(**{field: value})  # type: ignore[arg-type]


def test_linear_path_rows_carry_the_accelerations() -> None:
    path = ir.LinearPath(
        poses=np.stack([np.eye(4)] * 2),
        speeds=[0.1, 0.1],
        zones=[0.0, 0.0],
        lines=[1, 2],
        acceleration=0.5,
        angular_acceleration=1.0,
    )
    assert path.move(1).speed.linear_acceleration == 0.5
    assert path.move(1).speed.angular_acceleration == 1.0


@pytest.mark.parametrize("post", ["kuka", "ur", "abb", "fanuc"])
def test_row_writers_write_the_accelerations_as_the_templates(post: str, tmp_path: Path) -> None:
    """A run of LINs whose path acceleration is set, changed and unset again: the row writer's
    text is the templates' (tests/posts/test_rows.py), with the accelerations in it."""
    program = _moves(24, tmp_path)
    out = []
    for k, node in enumerate(program.instructions):
        if isinstance(node, ir.LinearMove) and 5 <= k < 15:
            node = node.with_speed(linear_acceleration=0.5 if k < 10 else 1.5)
        out.append(node)
    rows, template = _both(post, program.replace_instructions(out))
    assert rows.files == template.files
    text = "".join(rows.files.values())
    expected = {
        "kuka": ["$ACC.CP = 0.5000", "$ACC.CP = 1.5000"],
        "ur": ["a=0.50000", "a=1.50000", "a=1.20000"],
        "abb": ["\\AccMax:=0.500", "\\AccMax:=1.500", "PathAccLim FALSE, FALSE;"],
        "fanuc": [],
    }[post]
    for piece in expected:
        assert piece in text


@pytest.mark.parametrize("post", ["kuka", "ur", "abb"])
def test_a_folder_copied_before_accelerations_warns(
    stations: dict[str, Station], post: str, tmp_path: Path
) -> None:
    """A customer's copy of a post folder made before olp wrote accelerations has templates
    without them and no ``accelerations: true``: it warns, and names the fix."""
    import shutil

    from olp.posts import find_post

    folder = tmp_path / f"my_{post}"
    shutil.copytree(find_post(post).manifest.folder, folder)
    manifest = folder / "post.yaml"
    manifest.write_text(manifest.read_text().replace("accelerations: true\n", ""))
    copied = find_post(str(folder))
    program = _program(stations[post], post, SET)
    compiled = olp.compile(program, stations[post])
    linear = [d for d in copied.check(compiled) if "TCP path" in d.message]
    assert len(linear) == 1 and "does not declare accelerations: true" in linear[0].message
    assert not [d for d in find_post(post).check(compiled) if "TCP path" in d.message]
