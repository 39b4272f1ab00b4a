"""Mesh files named by a station: read once, checked, reduced to the convex hull collision uses.

A mesh that cannot serve as collision geometry is a :class:`MeshError` whose text says why
(the station loader adds the file, line and column of the ``file:`` key that names it):
a file that is not a regular file or is larger than :data:`MAX_MESH_BYTES`, a type trimesh
cannot read from bytes alone, an empty or malformed file, a mesh without triangles, with
non-finite points or far beyond any cell, and a flat (or line, or point) mesh, whose convex
hull has no volume. trimesh reads the bytes olp read itself, with no resolver, so a mesh file
cannot make olp open another file (an OBJ's material library, a glTF's external buffer).
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np

from olp.station.model import MeshHull
from olp.yamlsafe import UnreadableFile, read_regular_file

MAX_MESH_BYTES = 64 * 2**20
"""Largest mesh file read (64 MiB, about 1.3 million triangles of binary STL)."""
MAX_MESH_REACH = 1000.0
"""Farthest (m) a mesh point may lie from the mesh's origin once scaled: 1 km means wrong
units or a corrupt file, and would swamp the collision checks' tolerances."""
MESH_TYPES: dict[str, str] = {".stl": "STL", ".obj": "OBJ", ".ply": "PLY", ".glb": "GLB"}
"""Readable mesh types by file suffix (lower case)."""

_FLAT = 1e-9  # smallest/largest principal extent below which a point set has no volume


class MeshError(ValueError):
    """A mesh file that cannot be used; the message says why."""


def read_mesh(path: Path, suffix: str | None = None) -> Any:
    """The mesh in ``path`` as a ``trimesh.Trimesh`` in the file's units, checked to have
    triangles and finite points. ``suffix``: the type as the user named the file (default:
    ``path``'s; a symbolic link's target may be named otherwise). Raises :class:`MeshError`."""
    suffix = path.suffix if suffix is None else suffix
    kind = MESH_TYPES.get(suffix.lower())
    if kind is None:
        raise MeshError(f"unsupported mesh type '{suffix}' (olp reads {', '.join(MESH_TYPES)})")
    try:
        data = read_regular_file(path, MAX_MESH_BYTES)
    except UnreadableFile as exc:
        raise MeshError(str(exc)) from None
    if not data:
        raise MeshError("the file is empty")
    import trimesh

    try:
        mesh = trimesh.load(file_obj=io.BytesIO(data), file_type=kind.lower(), force="mesh")
    except Exception as exc:  # trimesh's parsers raise anything on malformed bytes
        raise MeshError(f"not a readable {kind} file ({type(exc).__name__}: {exc})") from None
    faces = getattr(mesh, "faces", None)
    if not isinstance(mesh, trimesh.Trimesh) or faces is None or len(faces) == 0:
        raise MeshError(f"no triangles in it (empty, or not a valid {kind} file)")
    if not np.all(np.isfinite(mesh.vertices)):
        raise MeshError("some of its points are not finite numbers")
    return mesh


def mesh_hull(path: Path, scale: float, suffix: str | None = None) -> MeshHull:
    """The convex hull of the mesh in ``path`` (type by ``suffix``, see :func:`read_mesh`),
    scaled by ``scale`` (file units to metres): vertices (V, 3) m and outward triangles (F, 3),
    as the collision checks use it. Raises :class:`MeshError`."""
    mesh = read_mesh(path, suffix)
    mesh.apply_scale(scale)
    points = np.asarray(mesh.vertices, dtype=np.float64)
    reach = float(np.max(np.abs(points)))
    if reach > MAX_MESH_REACH:
        raise MeshError(
            f"its points reach {reach:.4g} m from its origin (at most {MAX_MESH_REACH:g} m); "
            "wrong units?"
        )
    extents = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)
    if extents[0] == 0.0 or extents[-1] <= _FLAT * extents[0]:
        raise MeshError(
            "it is flat (all its points lie in one plane), so it has no convex hull with a "
            "volume for the collision checks"
        )
    try:
        hull = mesh.convex_hull
    except Exception as exc:  # qhull's errors on degenerate input
        raise MeshError(f"no convex hull ({type(exc).__name__}: {exc})") from None
    if len(hull.faces) < 4 or not hull.volume > 0:
        raise MeshError("its convex hull has no volume")
    return MeshHull(np.asarray(hull.vertices, np.float64), np.asarray(hull.faces, np.int64))
