"""Transpiling: ``olp build cell.yaml prog.src --post kuka|abb`` turns a KUKA program into KRL
and RAPID with the same joint-space path.

The post never plans: both outputs come from one compiled program. The proof reads each output
back independently of olp's posts (the KRL frontend for KRL; a small reader of the RAPID olp
writes, below), solves every written target with olp's IK under the written configuration
(KUKA S/T, ABB confdata) and the written tool and frame, and checks that both give the joints
the compiler planned, motion by motion: job 5 (milling.src on the KR 6 cell) and a pick program
on the IRB 120 cell.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.cli import main
from olp.frontends.bundled import KrlOptions
from olp.frontends.krl import load_krl
from olp.geometry import inv
from olp.kinematics.base import turn_variants
from olp.kinematics.configuration import satisfies
from olp.station.model import Robot, Station
from olp.vendors import abb, kuka

with warnings.catch_warnings():  # rapidchecker uses pyparsing names deprecated since
    warnings.simplefilter("ignore", DeprecationWarning)
    from rapidchecker.cli import check_file as _check_file

REPO = Path(__file__).resolve().parents[2]
CASES = {
    "job5_milling": (
        REPO / "stations" / "kr6_milling_cell.yaml",
        REPO / "examples" / "milling.src",
    ),
    "irb120_pick": (
        REPO / "stations" / "abb_irb120_pick_cell.yaml",
        Path(__file__).resolve().parent / "pick_irb120.src",
    ),
}


def check_file(text: str) -> list[object]:
    """rapidchecker's errors for a module's text (its deprecation warnings silenced)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        return list(_check_file(text))


KEEPS = {"irb120_pick": ("Gripper_Check",)}
"""Routines of another module a case calls that leave the settings and the robot alone."""


def _build(case: str, post: str, out: Path) -> tuple[Station, olp.BuildResult]:
    cell, program = CASES[case]
    keeps = KEEPS.get(case, ())
    vouch = [arg for name in keeps for arg in ("--call-keeps-settings", name)]
    argv = ["build", str(cell), str(program), "--post", post, "-o", str(out), "-q", *vouch]
    assert main(argv) == 0
    station = olp.load_station(cell)
    options = KrlOptions(calls_keep_settings=keeps)
    return station, olp.build(station, program, post=post, program_options=options)


def _candidates(robot: Robot, flange: np.ndarray) -> np.ndarray:
    sols = robot.solve(flange[None])[0]
    variants = turn_variants(sols, robot.limits.lower, robot.limits.upper).reshape(-1, robot.dof)
    finite = np.all(np.isfinite(variants), axis=-1)
    ok = finite & ~np.any(robot.limits.violations(np.where(finite[:, None], variants, 0)), axis=-1)
    return variants[ok]


def _select(robot: Robot, flange: np.ndarray, config: ir.Configuration) -> np.ndarray:
    """The one joint solution ``config`` selects for ``flange`` (fails if none or several)."""
    candidates = _candidates(robot, flange)
    chosen = candidates[satisfies(config, candidates, robot)]
    assert chosen.shape[0] >= 1
    assert np.all(np.abs(chosen - chosen[0]) < 1e-3), "the configuration selects several"
    return chosen[0]


def _krl_joints(station: Station, src: Path) -> list[np.ndarray]:
    """Joints of every motion of a KRL file: axis values, or the pose with its S/T solved."""
    result = load_krl(src)
    status = {st.span.line: st for st in result.status_turn}
    out = []
    for motion in result.program.motions():
        if isinstance(motion.target, ir.JointTarget):
            out.append(np.array(motion.target.joints))
            continue
        st = status[motion.span.line]
        assert st.status is not None and st.turn is not None
        assert motion.frame.pose is not None and motion.tool.pose is not None
        flange = motion.frame.pose @ motion.target.pose @ inv(motion.tool.pose)
        config = kuka.configuration_from_status_turn(st.status, st.turn)
        out.append(_select(station.robot, flange, config))
    return out


NUM = r"-?\d+(?:\.\d+)?(?:E[+-]\d+)?"
POSE = rf"\[\[({NUM}),({NUM}),({NUM})\],\[({NUM}),({NUM}),({NUM}),({NUM})\]\]"


def _rapid_pose(values: tuple[str, ...]) -> np.ndarray:
    return abb.robtarget_to_pose([float(v) for v in values[:3]], [float(v) for v in values[3:7]])


def _rapid_joints(station: Station, mod: str) -> list[np.ndarray]:
    """Joints of every Move of a RAPID module: jointtargets as written, robtargets solved with
    their confdata, in their work object (relative to the robot base) with their tool."""
    tools = {
        n: _rapid_pose(v) for n, *v in re.findall(rf"PERS tooldata (\w+) := \[TRUE,{POSE}", mod)
    }
    tools["tool0"] = np.eye(4)
    wobjs = {
        n: _rapid_pose(v)
        for n, *v in re.findall(rf'PERS wobjdata (\w+) := \[FALSE,TRUE,"",{POSE}', mod)
    }
    wobjs["wobj0"] = np.eye(4)
    robtargets = {
        name: (_rapid_pose(values[:7]), [int(v) for v in values[7:]])
        for name, *values in re.findall(
            rf"CONST robtarget (\w+) := \[{POSE[2:-2]},\[(-?\d+),(-?\d+),(-?\d+),(\d)\]",
            mod,
        )
    }
    jointtargets = {
        name: np.radians([float(v) for v in values])
        for name, *values in re.findall(
            rf"CONST jointtarget (\w+) := \[\[{','.join([f'({NUM})'] * 6)}\]", mod
        )
    }
    robot = station.robot
    reference = robot.base @ robot.controller_base  # the post's frames_in: robot_base
    out = []
    for kind, target, tool, wobj in re.findall(
        r"Move(AbsJ|J|L|C) (?:\w+, )?(\w+)(?:\\NoEOffs)?, \w+, \w+, (\w+)(?:\\WObj:=(\w+))?;", mod
    ):
        if kind == "AbsJ":
            out.append(jointtargets[target])
            continue
        pose, conf = robtargets[target]
        flange = reference @ wobjs[wobj or "wobj0"] @ pose @ inv(tools[tool])
        out.append(_select(robot, flange, abb.configuration_from_confdata(conf)))
    return out


@pytest.mark.parametrize("case", list(CASES))
def test_kuka_and_abb_outputs_run_the_planned_joint_path(case: str, tmp_path: Path) -> None:
    station, krl = _build(case, "kuka", tmp_path / "kuka")
    _, rapid = _build(case, "abb", tmp_path / "abb")
    # one plan: the post does not change planning
    planned = [s.joints for s in krl.compiled.motion_steps()]
    again = [s.joints for s in rapid.compiled.motion_steps()]
    assert len(planned) == len(again) > 3
    for a, b in zip(planned, again, strict=True):
        assert np.array_equal(a, b)  # type: ignore[arg-type]
    name = krl.compiled.program.name
    from_krl = _krl_joints(station, tmp_path / "kuka" / f"{name}.src")
    mod = (tmp_path / "abb" / f"{name}.mod").read_text()
    assert [str(e) for e in check_file(mod)] == []
    from_rapid = _rapid_joints(station, mod)
    assert len(from_krl) == len(from_rapid) == len(planned)
    for q, k, r in zip(planned, from_krl, from_rapid, strict=True):
        # written to 1 µm / 1e-4° (KRL) and 1e-9 per quaternion component (RAPID)
        assert np.max(np.abs(k - q)) < 1e-4 and np.max(np.abs(r - q)) < 1e-4


def test_the_other_instructions_carry_over(tmp_path: Path) -> None:
    _, krl = _build("irb120_pick", "kuka", tmp_path / "kuka")
    _, rapid = _build("irb120_pick", "abb", tmp_path / "abb")
    src = krl.files["PickIrb120.src"]
    mod = rapid.files["PickIrb120.mod"]
    pairs = [
        ("$OUT[1] = TRUE", "SetDO do1, 1;"),
        ("WAIT SEC 0.300", "WaitTime \\InPos, 0.300;"),
        ("WAIT FOR $IN[2]", "WaitDI di2, 1;"),
        ("$OUT[1] = FALSE", "SetDO do1, 0;"),
        ("Gripper_Check()", "Gripper_Check;"),
    ]
    krl_lines = [line.strip() for line in src.split("\r\n")]
    rapid_lines = [line.strip() for line in mod.split("\r\n")]
    assert [krl_lines.index(a) for a, _ in pairs] == sorted(krl_lines.index(a) for a, _ in pairs)
    assert [rapid_lines.index(b) for _, b in pairs] == sorted(
        rapid_lines.index(b) for _, b in pairs
    )
