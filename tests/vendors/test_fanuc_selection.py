"""Fanuc CONFIG selection: the fast path (:func:`olp.vendors.fanuc.selecting_configs`) gives the
reference's result (:func:`olp.vendors.fanuc.selecting_configs_reference`, every IK solution
with every turn variant) for every point: random joints with boundary cases mixed in, on arms
with and without Fanuc's J2/J3 coupling and with 1 to 3 turn variants per joint, and a helix."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from olp.kinematics import opw
from olp.kinematics.base import JointCoupling
from olp.kinematics.configuration import elbow_angle, wrist_x
from olp.station.loader import load_station
from olp.vendors import fanuc

STATIONS = Path(__file__).resolve().parents[2] / "stations"
CELLS = ("fanuc_m20ia_weld_cell.yaml", "kr6_milling_cell.yaml", "abb_irb120_pick_cell.yaml")


def _robot(cell: str) -> Any:
    return load_station(STATIONS / cell).robot


def _edge_joints(robot: Any, count: int, seed: int) -> np.ndarray:
    """Random joints (count, 6) rad around the limits, a third of the entries moved onto a
    boundary the selection reads: J5 at or next to 0 (wrist flag, wrist singularity), J1/J4/J6
    at or next to odd multiples of 180° (turn numbers), limits +- a hair, the arm stretched."""
    rng = np.random.default_rng(seed)
    lower, upper = robot.limits.lower, robot.limits.upper
    q = rng.uniform(lower - 0.05, upper + 0.05, size=(count, 6))
    hair = np.array([0.0, 1e-13, -1e-13, 1e-10, -1e-10, 1e-9, -1e-9, 2e-9, -2e-9, 1e-6])
    pick = rng.random((count, 6)) < 1 / 3
    odd = np.array([-3, -1, 1, 3]) * math.pi
    for j in range(6):
        rows = np.flatnonzero(pick[:, j])
        near = hair[rng.integers(0, hair.size, rows.size)]
        if j == 4:
            q[rows, j] = near
        elif j in fanuc.TURN_AXES:
            q[rows, j] = odd[rng.integers(0, odd.size, rows.size)] + near
        else:
            ends = np.where(rng.random(rows.size) < 0.5, lower[j], upper[j])
            q[rows, j] = ends + near
    stretched = rng.random(count) < 0.05
    q[stretched] = _stretched(robot, q[stretched])
    shoulder = np.flatnonzero(rng.random(count) < 0.1)
    q[shoulder] = _wrist_on_axis_1(robot, q[shoulder], hair[rng.integers(0, 9, shoulder.size)])
    return q


def _wrist_on_axis_1(robot: Any, q: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``q`` (n, 6) with J2 moved so that the wrist centre lies ``x`` (n,) m in front of axis 1
    (the shoulder flag's boundary; ``x`` of a few 1e-10 m puts the other shoulder solution,
    half a turn of J1 away, within the flag's tolerance)."""
    kinematics = robot.kinematics
    p = kinematics.params
    theta = opw.to_model_joints(p, kinematics.chain_joints(q))
    t3 = theta[:, 2]
    a = p.c2 - p.a2 * np.sin(t3) + p.c3 * np.cos(t3)
    b = p.a2 * np.cos(t3) + p.c3 * np.sin(t3)
    theta[:, 1] = np.arcsin(np.clip((x - p.a1) / np.hypot(a, b), -1, 1)) - np.arctan2(b, a)
    for _ in range(3):  # Newton on x(t2): the closed form leaves ~1e-16 m of rounding
        err = opw._arm_x_z(p, theta)[0] - x
        slope = a * np.cos(theta[:, 1]) - b * np.sin(theta[:, 1])
        theta[:, 1] -= err / np.where(slope == 0.0, np.inf, slope)
    return kinematics.coupling.to_controller(opw.to_controller_joints(p, theta))


def _stretched(robot: Any, q: np.ndarray) -> np.ndarray:
    """``q`` (n, 6) with J3 moved so that the elbow flag sits on its boundary (elbow angle 0:
    the wrist centre on the line of the lower arm)."""
    kinematics = robot.kinematics
    params = kinematics.params
    theta = opw.to_model_joints(params, kinematics.chain_joints(q))
    theta[:, 2] = -math.atan2(params.a2, params.c3)
    return kinematics.coupling.to_controller(opw.to_controller_joints(params, theta))


def _helix_joints(count: int) -> np.ndarray:
    """Planned joints (count, 6) rad of a tool-down helix on the M-20iA weld cell, one IK
    branch followed continuously (turns of J1, J4, J6 as a resolve would keep them)."""
    station = load_station(STATIONS / "fanuc_m20ia_weld_cell.yaml")
    frame, tool = station.frames["weld_table"], station.tools["torch"]
    assert frame.pose is not None and tool.pose is not None
    t = np.linspace(0.0, 40.0 * np.pi, count)
    poses = np.repeat(np.eye(4)[None], count, axis=0)
    poses[:, :3, :3] = np.diag([-1.0, 1.0, -1.0])
    poses[:, 0, 3] = -0.3 + 0.06 * np.cos(t)
    poses[:, 1, 3] = 0.06 * np.sin(t)
    poses[:, 2, 3] = 0.02 + np.linspace(0.0, 0.03, count)
    sols = station.robot.solve(frame.pose @ poses @ np.linalg.inv(tool.pose))
    return np.unwrap(sols[:, 0], axis=0)


@pytest.mark.parametrize("cell", CELLS)
def test_fast_selection_equals_the_reference_on_random_and_boundary_joints(cell: str) -> None:
    robot = _robot(cell)
    q = _edge_joints(robot, 6000, seed=len(cell))
    q[:2, 3] = [2e4 * np.pi, -2e4 * np.pi]  # turn numbers of +-10000: still one packed code
    fast = fanuc.selecting_configs(robot, q)
    reference = fanuc.selecting_configs_reference(robot, q)
    differ = [k for k, (a, b) in enumerate(zip(fast, reference, strict=True)) if a != b]
    assert differ == [], [(k, q[k].tolist(), fast[k], reference[k]) for k in differ[:5]]
    # Both outcomes occur, so the comparison covers selections and joint-form fallbacks.
    assert 100 < sum(c is None for c in fast) < len(fast) - 100
    assert np.sum(np.abs(elbow_angle(robot, q)) < 1e-12) > 100  # the elbow boundary is in
    assert np.sum(np.abs(wrist_x(robot, q)) < 3e-9) > 100  # and the shoulder's


def test_fast_selection_equals_the_reference_with_turn_variants_on_every_joint() -> None:
    # Limits beyond +-180 deg on every joint: J2, J3 and J5 get 2-3 turn variants too, so the
    # (J2, J3) shift pairs and the J5 sign test on shifted values are exercised.
    robot = _robot("fanuc_m20ia_weld_cell.yaml")
    wide = np.radians([250.0, 200.0, 300.0, 400.0, 190.0, 420.0])
    limits = dataclasses.replace(robot.limits, lower=-wide, upper=wide)
    robot = dataclasses.replace(robot, limits=limits)
    q = _edge_joints(robot, 4000, seed=21)
    assert fanuc.selecting_configs(robot, q) == fanuc.selecting_configs_reference(robot, q)


def test_fast_selection_equals_the_reference_on_a_helix() -> None:
    robot = _robot("fanuc_m20ia_weld_cell.yaml")
    q = _helix_joints(5000)
    fast = fanuc.selecting_configs(robot, q)
    assert fast == fanuc.selecting_configs_reference(robot, q)
    assert len(set(fast)) > 1  # the helix changes CONFIG, not one text repeated


def test_the_bundled_fanuc_takes_the_fast_path(monkeypatch: pytest.MonkeyPatch) -> None:
    robot = _robot("fanuc_m20ia_weld_cell.yaml")
    assert fanuc._flags_follow_j2_j3(robot)

    def refuse(*_: Any) -> list[str | None]:
        raise AssertionError("reference path taken")

    monkeypatch.setattr(fanuc, "_selecting_configs_reference", refuse)
    assert len(fanuc.selecting_configs(robot, _helix_joints(50))) == 50


def test_a_coupling_into_the_arm_joints_from_elsewhere_takes_the_reference(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    robot = _robot("fanuc_m20ia_weld_cell.yaml")
    # Model J3 = J3 + J2 + J1: the proof's premise (flags read J2, J3 only) fails.
    coupling = JointCoupling.from_terms(6, ((2, 1, 1), (2, 0, 1)))
    mixed = dataclasses.replace(robot, kinematics=dataclasses.replace(
        robot.kinematics, coupling=coupling))  # fmt: skip
    assert not fanuc._flags_follow_j2_j3(mixed)
    called: list[int] = []
    original = fanuc._selecting_configs_reference

    def spy(r: Any, q: np.ndarray) -> list[str | None]:
        called.append(len(q))
        return original(r, q)

    monkeypatch.setattr(fanuc, "_selecting_configs", None)
    monkeypatch.setattr(fanuc, "_selecting_configs_reference", spy)
    fanuc.selecting_configs(mixed, _edge_joints(robot, 20, seed=3))
    assert called == [20]


def test_fast_selection_in_batches_is_the_selection_at_once(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    robot = _robot("fanuc_m20ia_weld_cell.yaml")
    q = _edge_joints(robot, 300, seed=11)
    whole = fanuc.selecting_configs(robot, q)
    monkeypatch.setattr(fanuc, "SELECT_ROWS", 7)
    assert fanuc.selecting_configs(robot, q) == whole
