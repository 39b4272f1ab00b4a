"""Routines in the IR (issue 15): definitions with typed in/out parameters, calls, functions with
results; plain frozen data, and an analysis view with every call expanded."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from olp import ir


def move(z: float, line: int = 0) -> ir.LinearMove:
    pose = np.eye(4)
    pose[2, 3] = z
    span = ir.SourceSpan("p.src", line) if line else ir.GENERATED
    return ir.LinearMove(
        target=ir.CartesianTarget(pose=pose), speed=ir.Speed(linear=0.5), span=span
    )


def program() -> ir.Program:
    count = ir.Parameter(name="nCount", type_name="INT", direction="out")
    place = ir.Routine(
        name="Place",
        params=[ir.Parameter(name="nSlot", type_name="INT"), count],
        declarations=[ir.Declare(name="rDepth", type_name="REAL")],
        body=[move(0.2, 20), ir.RoutineCall(name="Grip"), move(0.3, 22)],
    )
    grip = ir.Routine(name="Grip", body=[ir.SetOutput(index=7, value=True), ir.Return()])
    full = ir.Routine(
        name="Full",
        params=[ir.Parameter(name="n", type_name="INT")],
        returns="BOOL",
        body=[
            ir.Return(value=ir.BinaryOp(op=">", left=ir.Name(name="n"), right=ir.Constant(value=3)))
        ],
    )
    calls = [
        ir.RoutineCall(name="Place", args=(ir.Constant(value=i), ir.Name(name="k"))) for i in (1, 2)
    ]
    body = [
        move(0.1, 1),
        calls[0],
        ir.If(branches=[ir.Branch(condition=ir.Name(name="b"), body=[calls[1]])]),
    ]
    return ir.Program(name="p", instructions=body, routines=[place, grip, full])


def test_routines_are_frozen_plain_data() -> None:
    prog = program()
    place = prog.routine("PLACE")
    assert place is not None and prog.routine("nothing") is None
    assert [p.by_reference for p in place.params] == [False, True]
    assert isinstance(place.body, tuple) and not place.is_function
    full = prog.routine("full")
    assert full is not None and full.is_function
    with pytest.raises(dataclasses.FrozenInstanceError):
        place.name = "other"  # type: ignore[misc]
    renamed = dataclasses.replace(place, name="Put")
    assert renamed.name == "Put" and renamed.params == place.params


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: ir.Parameter(name="n", direction="inout"), "direction"),
        (lambda: ir.Parameter(name=""), "name"),
        (lambda: ir.Routine(name=""), "name"),
        (
            lambda: ir.Routine(
                name="R",
                params=[ir.Parameter(name="n")],
                declarations=[ir.Declare(name="N", type_name="INT")],
            ),
            "declared twice",
        ),
        (lambda: ir.RoutineCall(name=""), "name"),
    ],
)
def test_routine_nodes_refuse_values_they_cannot_hold(make: object, message: str) -> None:
    with pytest.raises(ir.FlowError, match=message):
        make()  # type: ignore[operator]


def test_a_program_holds_each_routine_once() -> None:
    with pytest.raises(ir.IRError, match="defined twice"):
        ir.Program(name="p", instructions=(), routines=[ir.Routine(name="a"), ir.Routine(name="A")])


def test_iterating_a_program_walks_its_own_body_and_expanded_walks_into_calls() -> None:
    prog = program()
    assert [i.kind for i in prog] == ["linear", "routine_call", "routine_call"]
    expanded = prog.expanded()
    kinds = [i.kind for i in expanded]
    run = ["linear", "set_output", "return", "linear"]
    assert kinds == ["linear", *run, *run]
    assert [m.span.line for m in expanded.motions()] == [1, 20, 22, 20, 22]
    assert expanded.routines == prog.routines  # a post writes them from the view
    first = expanded.instructions[1]
    assert isinstance(first, ir.Expanded) and first.call == prog.instructions[1]
    inner = first.body[1]
    assert isinstance(inner, ir.Expanded) and inner.call.name == "Grip"
    flat = ir.inline_expansions(expanded.instructions)
    assert [n.kind for n in ir.leaves(flat)] == kinds  # same order: the steps stay the steps


def test_recursion_cannot_be_expanded() -> None:
    a = ir.Routine(name="A", body=[ir.RoutineCall(name="B", span=ir.SourceSpan("p.src", 7))])
    b = ir.Routine(name="B", body=[ir.RoutineCall(name="a")])
    prog = ir.Program(name="p", instructions=[ir.RoutineCall(name="A")], routines=[a, b])
    with pytest.raises(ir.FlowError, match="A calls itself"):
        prog.expanded()


def test_a_call_of_another_modules_routine_is_not_expanded() -> None:
    prog = ir.Program(name="p", instructions=[ir.RoutineCall(name="Elsewhere")], routines=[])
    assert prog.expanded() is prog
    other = dataclasses.replace(program(), instructions=(ir.RoutineCall(name="Elsewhere"),))
    expanded = other.expanded().instructions
    assert [n.kind for n in expanded] == ["routine_call", "expanded"]
    # Place moves the robot and no call runs it: an entry after the program's end (checked
    # from an unknown caller), Grip runs inside it, Full does not move
    entry = expanded[1]
    assert isinstance(entry, ir.Expanded) and entry.entry and entry.call.name == "Place"
    assert ir.inline_expansions(expanded) == expanded[:1]  # no part of the program's run


def test_editing_motions_reaches_the_routines() -> None:
    slow = program().map_motions(lambda m: m.with_speed(linear=0.1))
    assert [m.speed.linear for m in slow.expanded().motions()] == [0.1] * 5
    fewer = program().filter(lambda i: i.kind != "set_output")
    grip = fewer.routine("Grip")
    assert grip is not None and [n.kind for n in grip.body] == ["return"]


def test_a_program_takes_typed_parameters_once_each() -> None:
    """A program other programs call has parameters as a routine's (issue 15); they make it
    a program with data (never split into parts, which would not see them)."""
    slot = ir.Parameter(name="nSlot", type_name="INT")
    called = ir.Program(name="SetGrip", instructions=[ir.Wait(seconds=0.1)], params=[slot])
    assert called.params == (slot,) and called.has_flow
    with pytest.raises(ir.IRError, match="parameter NSLOT is given twice"):
        ir.Program(name="p", instructions=(), params=(slot, ir.Parameter(name="NSLOT")))
    with pytest.raises(ir.IRError, match="must hold Parameter objects"):
        ir.Program(name="p", instructions=(), params=("nSlot",))  # type: ignore[arg-type]
