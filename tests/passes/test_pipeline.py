"""One pass pipeline (issue 11): every pass is ``(CompiledProgram, BuildOptions) ->
CompiledProgram``, ``olp.compile`` runs a tuple of them, and a pass of one's own is one
function."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.compiled import CompiledProgram
from olp.diagnostics import Diagnostic
from olp.geometry import transl
from olp.passes.pipeline import CHECKS, PIPELINE, BuildOptions
from olp.passes.resolve import ResolveOptions
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
MILLING = REPO / "examples" / "milling.src"


@pytest.fixture(scope="module")
def station() -> Station:
    return olp.load_station(CELL)


@pytest.fixture(scope="module")
def milling(station: Station) -> ir.Program:
    return olp.parse(MILLING, station=station).program


def test_the_default_pipeline_is_resolve_collide_time(
    milling: ir.Program, station: Station
) -> None:
    compiled = olp.compile(milling, station)
    assert compiled.ok and compiled.cycle_time > 0
    assert [p.__name__ for p in PIPELINE] == [
        "resolve_pass",
        "flow_pass",  # a no-op without control flow (olp.passes.flow)
        "collision_pass",
        "timing_pass",
        "path_timing_pass",  # per path, with control flow (olp.passes.timing.branches)
    ]
    checked = olp.compile(milling, station, passes=CHECKS)
    assert checked.ok and checked.cycle_time == 0.0  # no timing pass
    assert [s.joints.tolist() for s in checked.motion_steps() if s.joints is not None] == [
        s.joints.tolist() for s in compiled.motion_steps() if s.joints is not None
    ]


def thin_points(compiled: CompiledProgram, options: BuildOptions) -> CompiledProgram:
    """A pass of one's own: drop linear moves shorter than 1 mm after resolve (a stand-in for
    point thinning), and say how many."""
    kept, dropped = [], 0
    for step in compiled.steps:
        short = (
            isinstance(step.instruction, ir.LinearMove)
            and step.path is not None
            and float(np.max(np.abs(step.path[-1] - step.path[0]))) < 1e-6
        )
        dropped += short
        if not short:
            kept.append(step.instruction)
    program = compiled.program.replace_instructions(kept)
    thinned = CompiledProgram.start(program, compiled.station)
    note = Diagnostic("info", "thinned", f"{dropped} moves dropped")
    return dataclasses.replace(thinned, diagnostics=(*compiled.diagnostics, note))


def test_a_pass_of_ones_own_is_one_function(milling: ir.Program, station: Station) -> None:
    home = ir.JointMove(target=ir.JointTarget(joints=np.radians([0, -90, 90, 0, 45, 0])))
    still = ir.LinearMove(
        target=ir.CartesianTarget(pose=station.robot.flange_poses(home.target.joints))
    )  # type: ignore[union-attr]
    program = ir.Program(name="p", instructions=(home, still, still))
    resolve, flow, collide, time, _ = PIPELINE
    passes = (resolve, thin_points, resolve, flow, collide, time)
    compiled = olp.compile(program, station, passes=passes)
    assert [d.message for d in compiled.diagnostics if d.kind == "thinned"] == ["2 moves dropped"]
    assert [s.instruction.kind for s in compiled.steps] == ["joint"]
    assert compiled.ok and compiled.cycle_time > 0


def test_options_reach_their_pass(station: Station) -> None:
    far = ir.LinearMove(target=ir.CartesianTarget(pose=transl(5.0, 0.0, 0.0)))
    program = ir.Program(name="p", instructions=(far,))
    strict = olp.compile(program, station)
    assert [d.kind for d in strict.diagnostics if d.severity == "error"] == ["unreachable"]
    skipping = BuildOptions(resolve=ResolveOptions(skip_unreachable=True))
    assert olp.compile(program, station, skipping).steps[0].skipped
    assert olp.compile(program, station, ResolveOptions(skip_unreachable=True)).steps[0].skipped


def test_no_collision_options_means_no_collision_pass(station: Station) -> None:
    bump = ir.Program(
        name="bump",
        instructions=tuple(
            ir.JointMove(target=ir.JointTarget(joints=np.radians(q)))
            for q in ([0, -90, 90, 0, 30, 0], [0, 45, -120, 0, -120, 0])
        ),
    )
    assert not olp.compile(bump, station).ok  # link 2 hits the base
    unchecked = olp.compile(bump, station, BuildOptions(collisions=None))
    assert unchecked.ok and unchecked.cycle_time > 0
