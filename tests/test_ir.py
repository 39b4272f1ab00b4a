"""The IR: validated at construction, immutable, value equality, easy to edit as data."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from olp import ir
from olp.geometry import rotz, transl


def _lin(x: float, speed: float = 0.1) -> ir.LinearMove:
    return ir.LinearMove(
        target=ir.CartesianTarget(pose=transl(x, 0, 0)),
        speed=ir.Speed(linear=speed),
        span=ir.SourceSpan("p.src", 3, 1),
    )


def test_targets_are_read_only_copies() -> None:
    pose = transl(1, 2, 3)
    target = ir.CartesianTarget(pose=pose)
    pose[0, 3] = 99
    assert target.pose[0, 3] == 1
    with pytest.raises(ValueError):
        target.pose[0, 3] = 5


def test_instructions_are_frozen() -> None:
    with pytest.raises(dataclasses.FrozenInstanceError):
        _lin(0).speed = ir.Speed()  # type: ignore[misc]


def test_value_equality_compares_arrays() -> None:
    assert _lin(0.5) == _lin(0.5)
    assert _lin(0.5) != _lin(0.6)
    assert _lin(0.5, speed=0.1) != _lin(0.5, speed=0.2)


@pytest.mark.parametrize(
    "make",
    [
        lambda: ir.CartesianTarget(pose=np.eye(3)),
        lambda: ir.CartesianTarget(pose=np.full((4, 4), np.nan)),
        lambda: ir.CartesianTarget(pose=np.diag([1.0, 1.0, -1.0, 1.0])),
        lambda: ir.JointTarget(joints=[]),
        lambda: ir.Speed(linear=0),
        lambda: ir.Speed(joint=1.5),
        lambda: ir.Zone(-0.001),
        lambda: ir.Wait(seconds=-1),
    ],
)
def test_invalid_values_are_rejected(make: object) -> None:
    with pytest.raises(ir.IRError):
        make()  # type: ignore[operator]


def test_program_edit_as_data_lowers_speeds() -> None:
    program = ir.Program(name="p", instructions=[_lin(0.1, 0.5), _lin(0.2, 0.05)])
    slower = program.replace_instructions(
        dataclasses.replace(i, speed=dataclasses.replace(i.speed, linear=min(i.speed.linear, 0.1)))
        if isinstance(i, ir.LinearMove)
        else i
        for i in program
    )
    assert [m.speed.linear for m in slower.motions()] == [0.1, 0.05]
    assert [m.speed.linear for m in program.motions()] == [0.5, 0.05]


def test_motion_kinds_and_defaults() -> None:
    move = ir.JointMove(target=ir.JointTarget(joints=np.zeros(6)))
    assert move.kind == "joint" and move.zone.is_fine
    assert move.tool is ir.FLANGE and move.frame is ir.WORLD
    assert _lin(0).kind == "linear" and ir.is_motion(move)
    assert not ir.is_motion(ir.Wait(seconds=1.0))


def test_span_prints_compiler_style() -> None:
    span = ir.SourceSpan("prog.src", 12, 5)
    assert str(span) == "prog.src:12:5" and span.location == "prog.src:12"


def test_tool_reference_without_pose_is_allowed() -> None:
    tool = ir.Tool(name="TOOL_DATA[1]", number=1)
    assert tool.pose is None
    frame = ir.Frame(name="table", pose=rotz(0.1))
    assert frame.pose is not None
