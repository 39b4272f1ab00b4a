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


# --------------------------------------------------------------------------------------------
# Editing as data (USERS.md job 12)


def _edit_program() -> ir.Program:
    span = ir.SourceSpan("p.src", 3)
    lin = ir.LinearMove(
        target=ir.CartesianTarget(pose=np.eye(4)), speed=ir.Speed(linear=0.5), span=span
    )
    return ir.Program(
        name="p",
        instructions=(
            lin,
            ir.Wait(seconds=1.0),
            ir.Call(name="Grip"),
            lin.with_speed(linear=0.05),
            ir.Comment(text="end"),
        ),
    )


def test_with_speed_changes_only_the_parts_given() -> None:
    move = _edit_program().instructions[0]
    assert isinstance(move, ir.LinearMove)
    slower = move.with_speed(linear=0.1, joint=0.5)
    assert (slower.speed.linear, slower.speed.joint) == (0.1, 0.5)
    assert slower.speed.angular == move.speed.angular and slower.span == move.span
    assert move.speed.linear == 0.5  # the original is unchanged
    with pytest.raises(ir.IRError):
        move.with_speed(linear=-1.0)
    zoned = move.with_zone(0.01).with_tool(ir.Tool(name="t")).with_frame(ir.Frame(name="f"))
    assert (zoned.zone.radius, zoned.tool.name, zoned.frame.name) == (0.01, "t", "f")


def test_map_motions_filter_and_insert_after() -> None:
    program = _edit_program()
    capped = program.map_motions(lambda m: m.with_speed(linear=min(m.speed.linear, 0.1)))
    assert [m.speed.linear for m in capped.motions()] == [0.1, 0.05]
    assert [i.kind for i in capped] == [i.kind for i in program]
    no_waits = capped.filter(lambda i: i.kind != "wait")
    assert [i.kind for i in no_waits] == ["linear", "call", "linear", "comment"]
    logged = no_waits.insert_after(
        lambda i: isinstance(i, ir.Call), lambda i: ir.Call(name="LogStep", args=(f'"{i.name}"',))
    )
    assert [getattr(i, "name", i.kind) for i in logged] == [
        "linear",
        "Grip",
        "LogStep",
        "linear",
        "comment",
    ]
    before = logged.insert_before(lambda i: i.kind == "comment", lambda i: [ir.Wait(seconds=0.1)])
    assert [i.kind for i in before][-2:] == ["wait", "comment"]
    assert program.instructions[0].span == logged.instructions[0].span


def test_map_deletes_and_expands() -> None:
    program = _edit_program()
    edited = program.map(
        lambda i: None if i.kind == "comment" else [i, i] if i.kind == "wait" else i
    )
    assert [i.kind for i in edited] == ["linear", "wait", "wait", "call", "linear"]


def test_a_runtime_move_holds_an_expression_and_checks_its_shape() -> None:
    """A motion to a run-time target: the target an expression, a via point for an arc only,
    an angle for an arc only; not one of the motions with targets (``is_motion``)."""
    path = ir.Index(base=ir.Name(name="xPath"), indices=(ir.Name(name="i"),))
    move = ir.RuntimeMove(motion="linear", target=path, reason="i is set at run time")
    assert move.kind == "runtime_move" and move.zone.is_fine and not ir.is_motion(move)
    arc = ir.RuntimeMove(motion="circular", target=path, via=ir.Name(name="pVia"), angle=1.0)
    assert arc.via == ir.Name(name="pVia")
    with pytest.raises(ir.IRError, match="via"):
        ir.RuntimeMove(motion="linear", target=path, via=ir.Name(name="pVia"))
    with pytest.raises(ir.IRError, match="via"):
        ir.RuntimeMove(motion="circular", target=path)
    with pytest.raises(ir.IRError, match="angle"):
        ir.RuntimeMove(motion="joint", target=path, angle=1.0)
    with pytest.raises(ir.IRError, match="motion"):
        ir.RuntimeMove(motion="spline", target=path)  # type: ignore[arg-type]
    assert ir.RuntimeMove(motion="joint", target=path, relative="axes").relative == "axes"
    with pytest.raises(ir.IRError, match="relative must be None or one of"):
        ir.RuntimeMove(motion="linear", target=path, relative="world")  # type: ignore[arg-type]
    with pytest.raises(ir.IRError, match="'axes' is a joint move's"):
        ir.RuntimeMove(motion="linear", target=path, relative="axes")
