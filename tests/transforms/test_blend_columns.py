"""Blend capping reads a toolpath's rows as arrays (:func:`olp.transforms.blend.blend_columns`)
and gives the same numbers, bit for bit, as the per-step code it replaced (kept here as the
reference, :func:`_reference`), on random programs and edge cases; :func:`cap_blends` keeps a
toolpath's blocks as blocks and a program's control-flow blocks as blocks."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import olp
from olp import ir
from olp.compiled import CompiledProgram, Item, PathBlock, Step, StepBlocks, items_of, make_steps
from olp.ir_flow import Branch, DigitalInput, If, leaves
from olp.span import SourceSpan
from olp.transforms import blend
from olp.transforms.blend import STOP_TYPES, blend_columns, blend_radii, cap_blends, with_radii

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"


# --------------------------------------------------------------------------------------------
# The reference: the per-step code (one Step per motion, reasons for every motion)


def _reference(
    steps: Sequence[Step], robot: Any, start_joints: np.ndarray
) -> list[tuple[int, float, float, str]]:
    motions = [s for s in steps if ir.is_motion(s.instruction) and s.joints is not None]
    if not motions:
        return []
    indices = {s.index for s in motions}
    flags: list[bool] = []
    for step in steps:
        if step.index in indices:
            flags.append(False)
        elif flags and isinstance(step.instruction, STOP_TYPES):
            flags[-1] = True
    flags[-1] = True
    stops = np.array(flags, dtype=bool)
    joints = np.stack([np.asarray(s.joints, dtype=np.float64) for s in motions])
    tools = np.stack([np.asarray(s.tool.pose, dtype=np.float64) for s in motions])  # type: ignore[union-attr]
    tcp = robot.flange_poses(joints) @ tools
    start = (robot.flange_poses(start_joints) @ tools[0])[:3, 3]
    radii = np.array([float(s.instruction.zone.radius) for s in motions])  # type: ignore[union-attr]
    points = np.vstack([start[None], tcp[:, :3, 3]])
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=-1)
    wanted = np.where(stops, 0.0, radii)
    blends = wanted > 0
    prev_k = np.where(np.concatenate([[False], blends[:-1]]), 2.0, 1.0)
    next_len = np.concatenate([lengths[1:], [np.inf]])
    next_k = np.where(np.concatenate([blends[1:], [False]]), 2.0, 1.0)
    by_prev, by_next = lengths / prev_k, next_len / next_k
    out = np.minimum(wanted, np.minimum(by_prev, by_next))
    reasons = [
        blend._reason(radii[i], out[i], stops[i], by_prev[i], by_next[i], prev_k[i], next_k[i])
        for i in range(len(motions))
    ]
    return [
        (s.index, float(r), float(c), why)
        for s, r, c, why in zip(motions, radii, out, reasons, strict=True)
    ]


# --------------------------------------------------------------------------------------------
# Random compiled programs: toolpath blocks and ordinary steps, built by hand


def _station() -> Any:
    return olp.load_station(CELL)


def _span(k: int) -> SourceSpan:
    return SourceSpan("t.csv", k + 1)


def _zones(rng: np.random.Generator, n: int) -> np.ndarray:
    """Fine stops, small zones and zones far larger than the distances (capped)."""
    return rng.choice([0.0, 0.0005, 0.002, 0.05, 0.3], size=n) * rng.uniform(0.5, 1.0, n)


def _joints(rng: np.random.Generator, home: np.ndarray, n: int) -> np.ndarray:
    q = home + np.cumsum(rng.normal(0.0, 0.02, (n, home.size)), axis=0)
    repeat = rng.random(n) < 0.1  # a repeated target: a segment of length 0
    q[1:][repeat[1:]] = q[:-1][repeat[1:]]
    return q


def _program(seed: int) -> CompiledProgram:
    """A random program: toolpath blocks (resolved, or not), linear moves with and without
    joints, waits, calls, outputs and comments, with two tools."""
    rng = np.random.default_rng(seed)
    station = _station()
    tools = [station.tools["spindle"], dataclasses.replace(station.tools["spindle"], name="b")]
    tools[1] = dataclasses.replace(tools[1], pose=tools[0].pose @ np.diag([1, -1, -1, 1.0]))
    frame = station.frames["table"]
    home = station.robot.home
    items: list[Item] = []
    nodes: list[Any] = []
    index = 0
    for _ in range(int(rng.integers(1, 9))):
        choice = rng.random()
        tool = tools[int(rng.integers(2))]
        if choice < 0.4:
            n = int(rng.integers(1, 40))
            node = ir.LinearPath(
                poses=np.broadcast_to(np.eye(4), (n, 4, 4)),
                speeds=np.full(n, 0.1),
                zones=_zones(rng, n),
                lines=np.arange(index + 1, index + n + 1),
                tool=tool,
                frame=frame,
                source="t.csv",
            )
            joints = None if rng.random() < 0.1 else _joints(rng, home, n)
            items.append(PathBlock(index, node, tool, frame, joints))
            nodes.append(node)
            index += n
            continue
        if choice < 0.75:
            ins: Any = ir.LinearMove(
                target=ir.CartesianTarget(pose=np.eye(4)),
                zone=ir.Zone(float(_zones(rng, 1)[0])),
                tool=tool,
                frame=frame,
                span=_span(index),
            )
            q = None if rng.random() < 0.1 else _joints(rng, home, 1)[0]
            items.append(Step(index, ins, joints=q, tool=tool, frame=frame))
        else:
            kind = int(rng.integers(4))
            ins = [
                ir.Wait(seconds=0.5, span=_span(index)),
                ir.Call(name="Glue", span=_span(index)),
                ir.SetOutput(index=1, value=True, span=_span(index)),
                ir.Comment(text="c", span=_span(index)),
            ][kind]
            items.append(Step(index, ins))
        nodes.append(ins)
        index += 1
    program = ir.Program(name="Rand", instructions=tuple(nodes), source="t.csv")
    start = home + rng.normal(0.0, 0.05, home.size)
    return CompiledProgram(program, station, start, make_steps(items))


@pytest.mark.parametrize("chunk", [blend._FK_CHUNK, 3])
@pytest.mark.parametrize("seed", range(40))
def test_radii_as_columns_are_the_per_step_numbers(
    seed: int, chunk: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(blend, "_FK_CHUNK", chunk)
    compiled = _program(seed)
    robot = compiled.station.robot
    expected = _reference(list(compiled.steps), robot, compiled.start_joints)
    found = blend_columns(items_of(compiled.steps), robot, compiled.start_joints)
    assert found.index.tolist() == [i for i, *_ in expected]
    assert found.requested.tobytes() == np.array([r for _, r, _, _ in expected]).tobytes()
    assert found.radius.tobytes() == np.array([c for _, _, c, _ in expected]).tobytes()
    assert found.reasons == [why for *_, why in expected]
    per_step = blend_radii(list(compiled.steps), robot, compiled.start_joints)
    assert [(c.index, c.requested, c.radius, c.reason) for c in per_step] == expected


@pytest.mark.parametrize("seed", range(40))
def test_capping_a_program_rewrites_the_arrays_as_the_steps(seed: int) -> None:
    compiled = _program(seed)
    robot = compiled.station.robot
    expected = _reference(list(compiled.steps), robot, compiled.start_joints)
    capped, found = cap_blends(compiled)
    reduced = [(i, r, c, why) for i, r, c, why in expected if why]
    assert [(d.kind, d.index) for d in found] == [("blend_capped", i) for i, *_ in reduced]
    for diag, (_, r, c, why) in zip(found, reduced, strict=True):
        assert diag.message == f"blend radius {r * 1000:.1f} mm reduced to {c * 1000:.1f} mm: {why}"
        assert diag.span == _span(diag.index or 0)
    radius = {i: c for i, _, c, why in expected if why}
    before = {s.index: s for s in compiled.steps}
    for step in capped.steps:  # every instruction: the capped radius where reduced, else as was
        ins: Any = step.instruction
        if ir.is_motion(ins):
            old: Any = before[step.index].instruction
            assert ins.zone.radius == radius.get(step.index, old.zone.radius)
    motions = [s.instruction for s in capped.steps]
    assert [getattr(m, "zone", None) for m in capped.program] == [
        getattr(m, "zone", None) for m in motions
    ]
    # toolpaths stay arrays: the same blocks, in the steps and in the program
    assert _shape(capped.steps) == _shape(compiled.steps)
    assert [type(n) for n in capped.program.instructions] == [
        type(n) for n in compiled.program.instructions
    ]
    assert cap_blends(capped)[1] == []  # idempotent


def _shape(steps: Sequence[Step]) -> list[tuple[str, int]]:
    return [
        ("block", len(item)) if isinstance(item, PathBlock) else ("step", item.index)
        for item in items_of(steps)
    ]


def test_a_wait_after_a_toolpath_stops_its_last_row() -> None:
    station = _station()
    tool, frame = station.tools["spindle"], station.frames["table"]
    node = ir.LinearPath(
        poses=np.broadcast_to(np.eye(4), (3, 4, 4)),
        speeds=np.full(3, 0.1),
        zones=np.full(3, 0.001),
        lines=np.arange(1, 4),
        tool=tool,
        frame=frame,
    )
    q = station.robot.home + np.linspace(0.1, 0.3, 3)[:, None]
    block = PathBlock(0, node, tool, frame, q)
    wait = ir.Wait(seconds=1.0)
    program = ir.Program(name="W", instructions=(node, wait))
    compiled = CompiledProgram(
        program, station, station.robot.home, make_steps([block, Step(3, wait)])
    )
    found = blend_columns(items_of(compiled.steps), station.robot, compiled.start_joints)
    assert found.radius.tolist() == [0.001, 0.001, 0.0]
    assert "the robot stops at this target" in found.reasons[2]


def test_a_program_without_motions_has_no_blends() -> None:
    station = _station()
    wait = ir.Wait(seconds=1.0)
    compiled = CompiledProgram(
        ir.Program(name="W", instructions=(wait,)), station, station.robot.home, (Step(0, wait),)
    )
    assert blend_columns(compiled.steps, station.robot, compiled.start_joints).index.size == 0
    assert cap_blends(compiled) == (compiled, [])


def test_radii_set_inside_a_block_of_control_flow_keep_the_block() -> None:
    """A toolpath and a move inside an IF: their new radii land in the IF's body, which stays
    an IF (a flat program would write the body unconditionally), and the toolpath stays one
    node and one block."""
    station = _station()
    tool, frame = station.tools["spindle"], station.frames["table"]
    node = ir.LinearPath(
        poses=np.broadcast_to(np.eye(4), (4, 4, 4)),
        speeds=np.full(4, 0.1),
        zones=np.full(4, 0.002),
        lines=np.arange(2, 6),
        tool=tool,
        frame=frame,
    )
    move = ir.LinearMove(target=ir.CartesianTarget(pose=np.eye(4)), zone=ir.Zone(0.003))
    first = ir.LinearMove(target=ir.CartesianTarget(pose=np.eye(4)), zone=ir.Zone(0.004))
    branch = Branch(condition=DigitalInput(index=1), body=(node, move))
    program = ir.Program(name="F", instructions=(first, If(branches=(branch,))))
    assert program.has_flow
    q = station.robot.home
    items: list[Item] = [
        Step(0, first, joints=q, tool=tool, frame=frame),
        PathBlock(1, node, tool, frame, np.stack([q] * 4)),
        Step(5, move, joints=q, tool=tool, frame=frame),
    ]
    compiled = CompiledProgram(program, station, q, make_steps(items))
    changed = with_radii(compiled, np.array([0, 2, 4, 5]), np.array([0.0, 0.001, 0.0, 0.0]))
    (head, block) = changed.program.instructions
    assert isinstance(block, If) and head.zone.radius == 0.0  # type: ignore[union-attr]
    inner = block.branches[0].body
    assert isinstance(inner[0], ir.LinearPath) and inner[0].zones.tolist() == [
        0.002,
        0.001,
        0.002,
        0.0,
    ]
    assert inner[1].zone.radius == 0.0  # type: ignore[union-attr]
    assert isinstance(changed.steps, StepBlocks)
    assert [type(i) for i in changed.steps.blocks] == [Step, PathBlock, Step]
    assert changed.steps[4].instruction.zone.radius == 0.0  # type: ignore[union-attr]
    assert [type(n) for n in leaves(changed.program.instructions)] == [
        ir.LinearMove,
        ir.LinearPath,
        ir.LinearMove,
    ]
