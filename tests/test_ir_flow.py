"""Control flow and data in the IR (olp.ir_flow, re-exported from olp.ir): plain frozen data that
users walk and edit, and programs that keep iterating as a sequence of instructions."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from olp import ir


def move(z: float) -> ir.LinearMove:
    pose = np.eye(4)
    pose[2, 3] = z
    return ir.LinearMove(target=ir.CartesianTarget(pose=pose), speed=ir.Speed(linear=0.5))


def nested() -> ir.Program:
    inner = ir.While(condition=ir.DigitalInput(index=2), body=[move(0.3), ir.Wait(seconds=1)])
    branch = ir.Branch(condition=ir.DigitalInput(index=1), body=[move(0.1), inner])
    block = ir.If(branches=[branch], orelse=[ir.Exit()])
    count = ir.Assign(target=ir.Name(name="n"), value=ir.Constant(value=1))
    return ir.Program(name="p", instructions=(move(0.0), block, count, move(0.4)))


def test_iterating_walks_into_blocks_in_source_order() -> None:
    program = nested()
    assert [i.kind for i in program] == [
        "linear",
        "linear",
        "linear",
        "wait",
        "exit",
        "assign",
        "linear",
    ]
    assert len(program) == 7 and program.has_flow
    assert [m.target.pose[2, 3] for m in program.motions()] == [0.0, 0.1, 0.3, 0.4]


def test_editing_motions_keeps_the_blocks() -> None:
    slow = nested().map_motions(lambda m: m.with_speed(linear=0.1))
    block = slow.instructions[1]
    assert isinstance(block, ir.If) and isinstance(block.branches[0].body[1], ir.While)
    assert [m.speed.linear for m in slow.motions()] == [0.1] * 4
    fewer = nested().filter(lambda i: i.kind != "wait")
    inner = fewer.instructions[1].branches[0].body[1]  # type: ignore[union-attr]
    assert [i.kind for i in inner.body] == ["linear"]


def test_nodes_are_frozen_and_validated() -> None:
    block = nested().instructions[1]
    with pytest.raises(dataclasses.FrozenInstanceError):
        block.orelse = ()  # type: ignore[misc, union-attr]
    assert isinstance(block, ir.If) and isinstance(block.branches, tuple)
    with pytest.raises(ir.FlowError):
        ir.If(branches=())
    with pytest.raises(ir.FlowError):
        ir.BinaryOp(op="**", left=ir.Constant(value=1), right=ir.Constant(value=2))
    assert not ir.Program(name="p", instructions=(move(0.0),)).has_flow
