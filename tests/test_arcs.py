"""Arc geometry against closed forms: circles, circular angles, degenerate arcs, orientation
rules (olp/arcs.py)."""

from __future__ import annotations

import numpy as np
import pytest

from olp.arcs import ArcError, arc_poses, arc_rotations, circle_through, sample_count
from olp.geometry import pose_from, rotation_angle, rotx, rotz
from olp.ir import ArcOrientation, CartesianTarget, CircularMove, IRError

CENTRE = np.array([0.4, -0.1, 0.3])
R = 0.05


def _on_circle(deg: float) -> np.ndarray:
    """A point of the circle of radius R about CENTRE in a plane tilted about x by 30°."""
    t = np.radians(deg)
    local = np.array([np.cos(t), np.sin(t), 0.0]) * R
    return CENTRE + rotx(np.radians(30.0))[:3, :3] @ local


def test_circle_through_three_points_matches_the_circle() -> None:
    arc = circle_through(_on_circle(10), _on_circle(100), _on_circle(190))
    assert np.allclose(arc.centre, CENTRE, atol=1e-12)
    assert arc.radius == pytest.approx(R, abs=1e-12)
    assert np.degrees(arc.sweep) == pytest.approx(180.0, abs=1e-9)
    assert np.degrees(arc.via_angle) == pytest.approx(90.0, abs=1e-9)
    fractions = np.linspace(0, 1, 101)
    points = arc.points(fractions)
    radius = np.linalg.norm(points - CENTRE, axis=1)
    assert np.max(np.abs(radius - R)) < 1e-9
    expected = np.stack([_on_circle(10 + 180 * f) for f in fractions])
    assert np.max(np.linalg.norm(points - expected, axis=1)) < 1e-9
    assert arc.length == pytest.approx(np.pi * R, rel=1e-12)


def test_the_arc_runs_through_the_via_point_the_long_way_if_needed() -> None:
    # start 0°, via 300°, end 90°: the arc from 0° past 300° to 90° is 270° the other way.
    arc = circle_through(_on_circle(0), _on_circle(300), _on_circle(90))
    assert np.degrees(arc.sweep) == pytest.approx(270.0, abs=1e-9)
    assert np.allclose(arc.points([60 / 270])[0], _on_circle(-60), atol=1e-12)


@pytest.mark.parametrize(
    ("ca", "end_deg"), [(45.0, 55.0), (135.0, 145.0), (-90.0, -80.0), (360.0, 10.0), (-720.0, 10.0)]
)
def test_circular_angle(ca: float, end_deg: float) -> None:
    arc = circle_through(_on_circle(10), _on_circle(40), _on_circle(100), np.radians(ca))
    assert arc.sweep == pytest.approx(np.radians(ca))
    assert np.linalg.norm(arc.points([1.0])[0] - _on_circle(end_deg)) < 1e-9
    assert arc.length == pytest.approx(R * abs(np.radians(ca)), rel=1e-12)
    # a negative angle turns the other way: a little way in it lies before the start
    sign = np.sign(ca)
    quarter = arc.points([1e-3])[0]
    assert np.linalg.norm(quarter - _on_circle(10 + sign * abs(ca) * 1e-3)) < 1e-9


def test_full_circle_comes_back_to_the_start() -> None:
    arc = circle_through(_on_circle(0), _on_circle(120), _on_circle(240), np.radians(360.0))
    points = arc.points(np.linspace(0, 1, 9))
    assert np.linalg.norm(points[-1] - points[0]) < 1e-12
    assert np.linalg.norm(points[4] - _on_circle(180)) < 1e-9


@pytest.mark.parametrize(
    ("points", "angle", "kind"),
    [
        ((0, 0, 1e-7), None, "coincident"),
        ((0, 90, 90), None, "coincident"),
        ((0, 90, 1e-8), None, "coincident"),
        ((0, 40, 80), np.radians(30.0), "via_outside"),
    ],
)
def test_degenerate_arcs(points: tuple[float, ...], angle: float | None, kind: str) -> None:
    p0, p1, p2 = (_on_circle(d) for d in points)
    with pytest.raises(ArcError) as caught:
        circle_through(p0, p1, p2, angle)
    assert caught.value.kind == kind


def test_collinear_and_tiny_arcs_are_errors() -> None:
    line = [np.array([0.0, 0.0, 0.0]), np.array([0.1, 0.0, 0.0]), np.array([0.3, 0.0, 0.0])]
    with pytest.raises(ArcError) as caught:
        circle_through(*line)
    assert caught.value.kind == "collinear"
    tiny = [np.array([0.0, 0.0, 0.0]), np.array([2e-5, 2e-5, 0.0]), np.array([4e-5, 0.0, 0.0])]
    with pytest.raises(ArcError) as caught:
        circle_through(*tiny)
    assert caught.value.kind == "radius"
    # a negative angle never needs the via point on the arc
    arc = circle_through(_on_circle(0), _on_circle(40), _on_circle(80), np.radians(-30.0))
    assert arc.sweep < 0


# ---- orientation rules, against hand-computed poses
# The circle lies in the world XY plane about the origin: start (R, 0), via (0, R), end (-R, 0):
# a half turn about +z. Tool down (rotx 180°) at the start; the target turned 90° about z.
START = pose_from(rotx(np.pi)[:3, :3], [R, 0.0, 0.0])
VIA = pose_from(rotz(1.0)[:3, :3], [0.0, R, 0.0])  # its rotation must not matter
END = pose_from((rotz(np.pi / 2) @ rotx(np.pi))[:3, :3], [-R, 0.0, 0.0])
HALF = np.array([0.5])


def _middle(mode: ArcOrientation) -> np.ndarray:
    return arc_poses(START, VIA, END, HALF, mode)[0]


def test_interpolate_is_start_to_end_ignoring_the_via() -> None:
    pose = _middle(ArcOrientation.INTERPOLATE)
    assert np.allclose(pose[:3, 3], [0.0, R, 0.0], atol=1e-12)
    assert np.allclose(pose[:3, :3], (rotz(np.pi / 4) @ rotx(np.pi))[:3, :3], atol=1e-12)
    other_via = pose_from(np.eye(3), [0.0, R, 0.0])
    same = arc_poses(START, other_via, END, HALF, ArcOrientation.INTERPOLATE)[0]
    assert np.allclose(same, pose, atol=1e-12)


def test_constant_keeps_the_start_orientation() -> None:
    poses = arc_poses(START, VIA, END, np.linspace(0, 1, 5), ArcOrientation.CONSTANT)
    assert np.allclose(poses[:, :3, :3], START[:3, :3], atol=1e-12)
    assert np.allclose(poses[-1, :3, 3], END[:3, 3], atol=1e-12)


def test_path_constant_turns_with_the_tangent() -> None:
    # half way round a half turn about +z: the tool turned 90° about z with the path
    pose = _middle(ArcOrientation.PATH_CONSTANT)
    assert np.allclose(pose[:3, :3], (rotz(np.pi / 2) @ rotx(np.pi))[:3, :3], atol=1e-12)
    end = arc_poses(START, VIA, END, np.ones(1), ArcOrientation.PATH_CONSTANT)[0]
    assert np.allclose(end[:3, :3], (rotz(np.pi) @ rotx(np.pi))[:3, :3], atol=1e-12)


def test_path_turns_with_the_tangent_and_reaches_the_target() -> None:
    # the turn with the path is 180° about z, the target only 90°: the remaining -90° about
    # the (turned) tool's own axis is spread over the arc, so half way: 90° - 45° = 45° about z.
    pose = _middle(ArcOrientation.PATH)
    assert np.allclose(pose[:3, :3], (rotz(np.pi / 4) @ rotx(np.pi))[:3, :3], atol=1e-12)
    end = arc_poses(START, VIA, END, np.ones(1), ArcOrientation.PATH)[0]
    assert np.allclose(end[:3, :3], END[:3, :3], atol=1e-12)


def test_wrist_mode_is_not_a_cartesian_rule() -> None:
    arc = circle_through(START[:3, 3], VIA[:3, 3], END[:3, 3])
    with pytest.raises(ValueError, match="not a Cartesian rule"):
        arc_rotations(START[:3, :3], END[:3, :3], arc, HALF, ArcOrientation.WRIST)


def test_sample_count_bounds_the_chord_sag() -> None:
    arc = circle_through(START[:3, 3], VIA[:3, 3], END[:3, 3])
    count = sample_count(arc, 0.0, 0.005, np.radians(2.0), np.radians(2.0))
    assert count == 90.0  # 180° at 2°, more than 157 mm / 5 mm = 32
    poses = arc_poses(START, VIA, END, np.linspace(0, 1, int(count) + 1))
    chords = np.linalg.norm(np.diff(poses[:, :3, 3], axis=0), axis=1)
    assert np.sum(chords) == pytest.approx(np.pi * R, rel=1e-4)
    assert np.max(rotation_angle(poses[:, :3, :3])) <= np.pi


def test_circular_move_validates_its_angle_and_mode() -> None:
    target = CartesianTarget(pose=END)
    via = CartesianTarget(pose=VIA)
    with pytest.raises(IRError):
        CircularMove(target=target, via=via, angle=0.0)
    with pytest.raises(IRError):
        CircularMove(target=target, via=via, angle=float("nan"))
    with pytest.raises(IRError):
        CircularMove(target=target, via=via, orientation="path")  # type: ignore[arg-type]
    move = CircularMove(target=target, via=via, angle=-np.pi, orientation=ArcOrientation.PATH)
    assert move.angle == -np.pi and move.orientation is ArcOrientation.PATH
