"""KRL -> RAPID -> TCP samples: the arcs of examples/weld_rounded.src, written as RAPID MoveC
and read back from the RAPID text alone, give the same sampled TCP path within 0.01 mm."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

import olp
from olp import ir
from olp.passes.resolve import resolve
from olp.vendors import abb

REPO = Path(__file__).resolve().parents[2]
NUM = r"-?\d+(?:\.\d+)?(?:E[+-]\d+)?"
POSE = rf"\[\[({NUM}),({NUM}),({NUM})\],\[({NUM}),({NUM}),({NUM}),({NUM})\]\]"


def _pose(values: tuple[str, ...]) -> np.ndarray:
    return abb.robtarget_to_pose([float(v) for v in values[:3]], [float(v) for v in values[3:7]])


def _program_from_rapid(mod: str, reference: np.ndarray, start: ir.Instruction) -> ir.Program:
    """The path moves of a RAPID module as IR (world poses, the module's tool)."""
    (tool_name, *tool_values) = re.findall(rf"PERS tooldata (\w+) := \[TRUE,{POSE}", mod)[0]
    wobjs = {n: _pose(v) for n, *v in re.findall(rf'wobjdata (\w+) := \[FALSE,TRUE,"",{POSE}', mod)}
    targets = {n: _pose(v) for n, *v in re.findall(rf"robtarget (\w+) := \[{POSE[2:-2]}", mod)}
    tool = ir.Tool(name=tool_name, pose=_pose(tuple(tool_values)))
    out: list[ir.Instruction] = [start]
    for kind, via, target, wobj in re.findall(
        r"Move(L|C) (?:(\w+), )?(\w+), \w+, \w+, \w+\\WObj:=(\w+);", mod
    ):
        frame = reference @ wobjs[wobj]
        end = ir.CartesianTarget(pose=frame @ targets[target])
        if kind == "C":
            point = ir.CartesianTarget(pose=frame @ targets[via])
            out.append(ir.CircularMove(target=end, via=point, tool=tool))
        else:
            out.append(ir.LinearMove(target=end, tool=tool))
    return ir.Program(name="read_back", instructions=tuple(out))


def _arc_tcp(compiled: olp.CompiledProgram) -> list[np.ndarray]:
    robot = compiled.station.robot
    return [
        (robot.flange_poses(s.path) @ s.tool.pose)[:, :3, 3]  # type: ignore[union-attr]
        for s in compiled.steps
        if s.instruction.kind == "circular" and s.path is not None
    ]


def test_krl_arcs_through_rapid_reach_the_same_tcp_samples() -> None:
    station = olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")
    result = olp.build(station, REPO / "examples" / "weld_rounded.src", post="abb")
    assert result.files, [d.format() for d in result.diagnostics]
    (mod,) = result.files.values()
    original = result.compiled
    first = next(iter(original.motion_steps()))  # (the source's comments come first)
    start = ir.JointMove(target=ir.JointTarget(joints=first.joints))
    robot = station.robot
    back = resolve(_program_from_rapid(mod, robot.base @ robot.controller_base, start), station)
    assert back.ok, [d.format() for d in back.diagnostics]
    before, after = _arc_tcp(original), _arc_tcp(back)
    assert len(before) == len(after) == 4
    for a, b in zip(before, after, strict=True):
        assert a.shape == b.shape
        assert np.max(np.linalg.norm(a - b, axis=1)) < 1e-5  # 0.01 mm
