"""How far a linear (or circular) move's joint-space chords stray from its true Cartesian path.

The collision check proves the piecewise-linear joint path between the resolve pass's samples
free. A linear move's controller follows the Cartesian line instead, whose joint path between two
samples bends away from the chord by a second-order amount: ``e(t) ≈ t (1 - t) h² q''/2`` for a
sample spacing h, largest at the middle of a segment. :func:`chord_deviation` measures that
midpoint gap, converted to link-point motion with the scene's displacement weights: an estimate
(exact up to third-order terms) of how far any point of the robot, its tool or a carried part can
be from where the checked path puts it. A clearance of that size covers it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from olp.collision.scene import DisplacementBound, Scene
from olp.geometry import inv, pose_from, rotation_exp, rotation_log
from olp.station.model import Robot

FloatArray = NDArray[np.float64]


def chord_deviation(
    robot: Robot,
    scene: Scene,
    paths: Sequence[FloatArray],
    tool_pose: FloatArray,
    midpoints: FloatArray | None = None,
) -> FloatArray:
    """Midpoint deviation of every segment of linear-move joint paths, metres of point motion.

    Parameters
    ----------
    robot : the robot the paths belong to.
    scene : its collision scene (which bodies count: links, tool, carried parts).
    paths : joint paths (S_k, dof) rad of linear moves, samples of a straight TCP line.
    tool_pose : (4, 4) the TCP in the flange frame, metres.
    midpoints : (sum of S_k - 1, 4, 4) the exact TCP poses half way along each segment of
        another path than a line (a circular move's arc, :func:`olp.arcs.arc_poses` at the
        half fractions), or None for linear moves.

    Returns
    -------
    (sum of S_k - 1,) for each segment, the largest distance any point of a robot-side body
    moves between the joint-chord midpoint and the exact Cartesian midpoint (same IK branch:
    the solution nearest the chord midpoint).
    """
    starts = np.concatenate([p[:-1] for p in paths])
    ends = np.concatenate([p[1:] for p in paths])
    if midpoints is None:
        exact = _line_midpoints(robot, starts, ends, tool_pose)
    else:
        exact = _nearest_solutions(robot, midpoints @ inv(tool_pose), starts, ends)
    error = np.abs(
        robot.kinematics.chain_joints(exact) - robot.kinematics.chain_joints((starts + ends) / 2)
    )
    bound = DisplacementBound(scene.model, robot)
    weights = np.array([bound.body(b) for b in scene.bodies if b.joint > 0])
    out: FloatArray = np.max(error @ weights.T, axis=1)
    return out


def _line_midpoints(
    robot: Robot, starts: FloatArray, ends: FloatArray, tool_pose: FloatArray
) -> FloatArray:
    """Joints (N, dof) at the Cartesian midpoints of the TCP segments between joint rows."""
    a = robot.flange_poses(starts) @ tool_pose
    b = robot.flange_poses(ends) @ tool_pose
    turn = rotation_log(np.swapaxes(a[:, :3, :3], -1, -2) @ b[:, :3, :3])
    middle = pose_from(a[:, :3, :3] @ rotation_exp(turn / 2), (a[:, :3, 3] + b[:, :3, 3]) / 2)
    return _nearest_solutions(robot, middle @ inv(tool_pose), starts, ends)


def _nearest_solutions(
    robot: Robot, flanges: FloatArray, starts: FloatArray, ends: FloatArray
) -> FloatArray:
    """Joints (N, dof) reaching the flange poses (N, 4, 4): per row, the solution nearest the
    midpoint of the joint chord from ``starts`` to ``ends`` (N, dof)."""
    solutions = robot.solve(flanges)
    chord = (starts + ends) / 2
    # The branch's solution nearest the chord midpoint, every joint unwrapped next to it.
    diff = (solutions - chord[:, None, :] + np.pi) % (2 * np.pi) - np.pi
    cost = np.where(np.isfinite(diff).all(axis=-1), np.sum(diff**2, axis=-1), np.inf)
    best = np.argmin(cost, axis=1)
    nearest: FloatArray = chord + diff[np.arange(len(chord)), best]
    return nearest
