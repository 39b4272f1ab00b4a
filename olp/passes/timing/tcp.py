"""The TCP along joint paths, vectorised: poses and positions by forward kinematics in batches,
and the TCP's linear and angular rates |J q'(s)| that the path-speed limits divide by."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from olp.geometry import rotation_log
from olp.station.model import Robot

FloatArray = NDArray[np.float64]


def tcp_poses(robot: Robot, joints: FloatArray, tools: FloatArray) -> FloatArray:
    """TCP poses (N, 4, 4) in the world for joints (N, dof) rad and tools (N, 4, 4) or one
    (4, 4); forward kinematics in batches of ``FK_ROWS`` rows (bounds memory)."""
    parts = [
        robot.flange_poses(joints[lo : lo + FK_ROWS])
        @ (tools[lo : lo + FK_ROWS] if tools.ndim == 3 else tools)
        for lo in range(0, len(joints), FK_ROWS)
    ]
    return np.concatenate(parts) if parts else np.zeros((0, 4, 4))


def tcp_positions(robot: Robot, joints: FloatArray, tools: FloatArray) -> FloatArray:
    """TCP positions (N, 3) m in the world, as :func:`tcp_poses` (without its rotations)."""
    parts = []
    for lo in range(0, len(joints), FK_ROWS):
        flange = robot.flange_poses(joints[lo : lo + FK_ROWS])
        if tools.ndim == 3:
            offset = np.einsum("nij,nj->ni", flange[:, :3, :3], tools[lo : lo + FK_ROWS, :3, 3])
        else:
            offset = flange[:, :3, :3] @ tools[:3, 3]
        parts.append(flange[:, :3, 3] + offset)
    return np.concatenate(parts) if parts else np.zeros((0, 3))


FK_ROWS = 1 << 18
"""Joint samples per forward-kinematics batch in :func:`olp.passes.timing.table.travel`
(bounds memory)."""


def tcp_rates(
    robot: Robot, tool: FloatArray, q: FloatArray, dq: FloatArray, angular: bool = True
) -> tuple[FloatArray, FloatArray]:
    """TCP linear and angular rates along joint directions: ``|J_v(q) dq|`` (N,) m and
    ``|J_w(q) dq|`` (N,) rad per unit of the path parameter, for joints ``q`` and directions
    ``dq`` (N, dof) and the tool ``tool`` (4, 4) or (N, 4, 4); the angular ones 0 unless
    ``angular``.

    Computed as a central difference of the vectorised forward kinematics along ``dq`` with a
    joint step of 1e-6 rad (relative error ~1e-9), which is ``J dq`` without building J; in
    batches (bounds memory).
    """
    scale = np.max(np.abs(dq), axis=-1)
    h = 1e-6 / np.where(scale > 0, scale, 1.0)
    step = h[:, None] * dq
    if not angular:
        plus, minus = tcp_positions(robot, q + step, tool), tcp_positions(robot, q - step, tool)
        return np.linalg.norm(plus - minus, axis=-1) / (2 * h), np.zeros_like(h)
    ahead, behind = tcp_poses(robot, q + step, tool), tcp_poses(robot, q - step, tool)
    linear = np.linalg.norm(ahead[:, :3, 3] - behind[:, :3, 3], axis=-1) / (2 * h)
    turn = np.swapaxes(behind[:, :3, :3], -1, -2) @ ahead[:, :3, :3]
    return linear, np.linalg.norm(rotation_log(turn), axis=-1) / (2 * h)


def rate_bound(rate: FloatArray, limit: FloatArray) -> FloatArray:
    """``x <= (limit / rate)²`` (K,) for ``rate * ds/dt <= limit``; no bound where rate is 0."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        out: FloatArray = np.where(rate > 0, (limit / rate) ** 2, np.inf)
    return out
