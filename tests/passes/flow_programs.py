"""Small programs for the path-timing tests: linear moves in front of the KR 6 cell, the tool
along the base's x axis (KUKA A 0, B 90, C 0: reachable all over the test area)."""

from __future__ import annotations

import numpy as np

from olp import ir

TOOL_FORWARD = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])


def span(line: int) -> ir.SourceSpan:
    return ir.SourceSpan("t.src", line, 3)


def pose(y_mm: float, z_mm: float = 300.0) -> np.ndarray:
    """The TCP at x 500 mm, ``y_mm``, ``z_mm`` (4, 4) m."""
    out = np.eye(4)
    out[:3, :3] = TOOL_FORWARD
    out[:3, 3] = [0.5, y_mm / 1000, z_mm / 1000]
    return out


def start() -> ir.JointMove:
    return ir.JointMove(target=ir.CartesianTarget(pose=pose(-400)), span=span(1))


def lin(line: int, y_mm: float, z_mm: float = 300.0, zone_mm: float = 0.0) -> ir.LinearMove:
    target = ir.CartesianTarget(pose=pose(y_mm, z_mm))
    return ir.LinearMove(target=target, zone=ir.Zone(zone_mm / 1000), span=span(line))


def program(*nodes: ir.Node) -> ir.Program:
    return ir.Program(name="t", instructions=nodes, source="t.src")
