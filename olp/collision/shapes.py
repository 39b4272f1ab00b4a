"""Station shapes as coal collision geometry, and how far their points reach from a point.

Primitives map one to one (box, cylinder, capsule, sphere); a mesh becomes the convex hull of
its vertices (trimesh), so every collision geometry is convex. That keeps coal's signed distance
well defined (negative = penetration depth) and 1-Lipschitz in the motion of the bodies, which
the conservative advancement in :mod:`olp.collision.advance` relies on.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from olp.station.model import Shape

FloatArray = NDArray[np.float64]


def coal_geometry(shape: Shape) -> Any:
    """The coal geometry of ``shape`` in the shape's own frame (metres)."""
    import coal

    if shape.kind == "box":
        return coal.Box(*shape.size)
    if shape.kind == "sphere":
        return coal.Sphere(shape.size[0])
    if shape.kind == "cylinder":
        return coal.Cylinder(*shape.size)
    if shape.kind == "capsule":
        return coal.Capsule(*shape.size)
    vertices, faces = mesh_hull(shape)
    points = coal.StdVec_Vec3s()
    for v in vertices:
        points.append(v)
    triangles = coal.StdVec_Triangle()
    for a, b, c in faces.tolist():
        triangles.append(coal.Triangle(a, b, c))
    return coal.Convex(points, triangles)


def mesh_hull(shape: Shape) -> tuple[FloatArray, NDArray[np.int64]]:
    """Vertices (V, 3) m and triangles (F, 3) of the convex hull of a mesh shape, shape frame:
    the hull the station loader read and checked, or, for a shape made in code, the same
    reading and checks (:func:`olp.station.meshes.mesh_hull`: a bad mesh is a MeshError)."""
    if shape.hull is not None:
        return shape.hull.vertices, shape.hull.faces
    if shape.mesh is None:
        raise ValueError(f"a {shape.kind} has no mesh file")
    return _hull(shape.mesh, shape.scale)


@lru_cache(maxsize=64)
def _hull(path: str, scale: float) -> tuple[FloatArray, NDArray[np.int64]]:
    from pathlib import Path

    from olp.station.meshes import mesh_hull as read_hull

    hull = read_hull(Path(path), scale)
    vertices = np.ascontiguousarray(hull.vertices, dtype=np.float64)
    faces = np.ascontiguousarray(hull.faces, dtype=np.int64)
    vertices.setflags(write=False)
    faces.setflags(write=False)
    return vertices, faces


def reach(shape: Shape, placement: FloatArray) -> float:
    """Largest distance (m) from the origin of a frame to any point of ``shape`` placed in that
    frame by ``placement`` (4, 4) (the shape's pose is applied on top). Exact for every kind
    (a mesh counts as its convex hull)."""
    pose = placement @ shape.pose
    centre, rotation = pose[:3, 3], pose[:3, :3]
    if shape.kind == "sphere":
        return float(np.linalg.norm(centre) + shape.size[0])
    if shape.kind == "capsule":
        radius, length = shape.size
        ends = centre + np.outer([-0.5, 0.5], rotation[:, 2] * length)
        return float(np.max(np.linalg.norm(ends, axis=1)) + radius)
    if shape.kind == "box":
        corners = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
        points = centre + (corners * np.asarray(shape.size) / 2) @ rotation.T
        return float(np.max(np.linalg.norm(points, axis=1)))
    if shape.kind == "cylinder":
        radius, length = shape.size
        return max(
            _rim_reach(centre + s * rotation[:, 2] * length / 2, rotation[:, 2], radius)
            for s in (-1.0, 1.0)
        )
    vertices, _ = mesh_hull(shape)
    return float(np.max(np.linalg.norm(vertices @ rotation.T + centre, axis=1)))


def _rim_reach(centre: FloatArray, normal: FloatArray, radius: float) -> float:
    """Largest |p| over the circle of ``radius`` about ``centre`` (3,) in the plane of unit
    ``normal`` (3,): ``|c + r u|² = |c|² + r² + 2 r c·u``, largest for u along c's in-plane part."""
    in_plane = centre - np.dot(centre, normal) * normal
    return float(
        np.sqrt(np.dot(centre, centre) + radius**2 + 2 * radius * np.linalg.norm(in_plane))
    )
