"""``robodk.robomath`` for programs olp runs: RoboDK's matrix and pose toolbox, same names,
argument orders, units and return shapes.

Sources: the RoboDK API for Python (``robodk/robomath.py``, Apache-2.0), whose docstrings state
each convention; the ones that move a robot are pinned by ``tests/compat/test_robomath.py``:

* ``rotx/roty/rotz`` take **radians**; ``transl`` takes mm; poses are 4 x 4 :class:`Mat`.
* ``Pose(x, y, z, rx, ry, rz)``: mm and **degrees**, ``transl · rotx · roty · rotz``.
* ``TxyzRxyz_2_Pose([x, y, z, rx, ry, rz])`` / ``Pose_2_TxyzRxyz``: mm and **radians**, the
  same ``transl · rotx · roty · rotz``.
* ``xyzrpw_2_pose([x, y, z, r, p, w])`` / ``pose_2_xyzrpw``: mm and degrees,
  ``transl · rotz(w) · roty(p) · rotx(r)``.
* ``Pose_2_KUKA`` / ``KUKA_2_Pose``: ``[x, y, z, A, B, C]`` mm and degrees, ``Rz(A)·Ry(B)·Rx(C)``;
  ``Pose_2_Fanuc`` / ``Fanuc_2_Pose``: ``[x, y, z, W, P, R]`` mm and degrees,
  ``Rz(R)·Ry(P)·Rx(W)``; ``Pose_2_ABB``: ``[x, y, z, q1, q2, q3, q4]`` mm and a unit quaternion
  w first; ``Pose_2_UR`` / ``UR_2_Pose``: ``[x, y, z, rx, ry, rz]`` **mm** and a rotation vector
  in radians (RoboDK keeps mm here; URScript's metres are the post's business).

The vendor angle sets are computed by :mod:`olp.vendors` (one place for every convention).
``pause`` and ``tic``/``toc`` do not wait or measure a robot: ``pause`` is a no-op with a note
in the build output (olp does not run the robot in time).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from olp.vendors import abb, fanuc, kuka, ur

FloatArray = NDArray[np.float64]
Numbers = list[float]
RowList = list[list[float]]

pi = math.pi
sin, cos, tan, sqrt = math.sin, math.cos, math.tan, math.sqrt
asin, acos, atan, atan2 = math.asin, math.acos, math.atan, math.atan2


class MatrixError(Exception):
    """A matrix operation with wrong sizes (RoboDK's ``robomath.MatrixError``)."""


class Mat:
    """A matrix of any size, RoboDK's ``robomath.Mat``: poses are 4 x 4 (mm), joints a column.

    As in RoboDK: ``Mat()`` is 4 x 4 zeros, ``Mat(n, m)`` n x m zeros, ``Mat([[...], ...])``
    rows, ``Mat([a, b, c])`` a column (how joints come back from ``Joints``/``SolveIK``).
    """

    __slots__ = ("_m",)

    def __init__(self, rows: Any = None, ncols: int | None = None) -> None:
        if isinstance(rows, int) and ncols is not None:
            self._m = np.zeros((rows, ncols))
            return
        if rows is None:
            self._m = np.zeros((4, 4))
            return
        source = rows._m if isinstance(rows, Mat) else _plain(rows)
        m = np.array(source, dtype=np.float64)
        if m.ndim == 1:
            m = m.reshape(-1, 1)
        if m.ndim != 2:
            raise MatrixError(f"Mat needs rows of numbers, got an array of shape {m.shape}")
        self._m = m

    # ---- RoboDK's attributes and sizes
    @property
    def rows(self) -> RowList:
        """The rows as lists (RoboDK's ``Mat.rows``)."""
        rows: list[list[float]] = self._m.tolist()
        return rows

    def size(self, dim: int | None = None) -> Any:
        """``(rows, cols)``, or one of them for ``dim`` 0 or 1."""
        shape = self._m.shape
        return shape if dim is None else shape[dim]

    def __len__(self) -> int:
        """The number of **columns** (RoboDK's ``Mat.__len__``)."""
        return int(self._m.shape[1])

    def __iter__(self) -> Iterator[Numbers]:
        """The **columns**, each a list (RoboDK's ``Mat.__iter__``): a joint column gives one
        list; the dof x M answer of ``SolveIK_All`` gives one list per solution."""
        return iter(self._m.T.tolist())

    def __getitem__(self, index: Any) -> Any:
        """``m[i, j]`` a number; ``m[i]`` row i as a column Mat; slices a Mat (as RoboDK)."""
        if isinstance(index, int | np.integer):
            return Mat(self._m[int(index)].tolist())
        value = self._m[index]
        return float(value) if np.ndim(value) == 0 else Mat(np.atleast_2d(value))

    def __setitem__(self, index: Any, value: Any) -> None:
        self._m[index] = value._m if isinstance(value, Mat) else value

    def Rows(self) -> RowList:
        """The rows as lists."""
        return self.rows

    def Cols(self) -> RowList:
        """The columns as lists."""
        rows: RowList = self._m.T.tolist()
        return rows

    def Row(self, n: int) -> Numbers:
        row: Numbers = self._m[n].tolist()
        return row

    def Col(self, n: int) -> Numbers:
        col: Numbers = self._m[:, n].tolist()
        return col

    def RowsCount(self) -> int:
        return int(self._m.shape[0])

    def ColsCount(self) -> int:
        return int(self._m.shape[1])

    def __array__(self, dtype: Any = None, copy: Any = None) -> FloatArray:
        return np.array(self._m, dtype=dtype)

    def __eq__(self, other: object) -> bool:
        """Equal sizes and values within 1e-6 (RoboDK compares with ``pose_is_similar``)."""
        if not isinstance(other, Mat):
            return NotImplemented
        same = self._m.shape == other._m.shape
        return same and bool(np.allclose(self._m, other._m, rtol=0.0, atol=1e-6))

    __hash__ = None  # type: ignore[assignment]

    def __str__(self) -> str:
        """RoboDK's layout: ``Pose(x, y, z,  rx, ry, rz):`` (mm, deg) for a pose, then rows."""
        head = ""
        if self.isHomogeneous():
            x, y, z, rx, ry, rz = Pose_2_TxyzRxyz(self)
            r = 180 / pi
            head = f"Pose({x:.3f}, {y:.3f}, {z:.3f},  {rx * r:.3f}, {ry * r:.3f}, {rz * r:.3f}):\n"
        rows = "\n [ ".join(", ".join(f"{v:.3f}" for v in row) + " ]," for row in self._m)
        return f"{head}[[ {rows[:-1]}]\n"

    def __repr__(self) -> str:
        return f"Matrix: {self.size()}\n{self}"

    # ---- arithmetic
    def __mul__(self, other: Any) -> Any:
        if isinstance(other, Mat):
            if self._m.shape[1] != other._m.shape[0]:
                raise MatrixError(f"cannot multiply {self._m.shape} by {other._m.shape}")
            return Mat(self._m @ other._m)
        if isinstance(other, int | float) and not isinstance(other, bool):
            return Mat(self._m * other)
        vector = np.asarray(other, dtype=np.float64)
        if self._m.shape == (4, 4) and vector.shape == (3,):
            return (self._m[:3, :3] @ vector + self._m[:3, 3]).tolist()
        if self._m.shape == (4, 4) and vector.ndim == 2 and vector.shape[1] == 3:
            return (vector @ self._m[:3, :3].T + self._m[:3, 3]).tolist()
        if vector.shape == (self._m.shape[1],):
            return (self._m @ vector).tolist()
        raise MatrixError(f"cannot multiply a {self._m.shape} Mat by shape {vector.shape}")

    def __rmul__(self, other: Any) -> Mat:
        if isinstance(other, int | float) and not isinstance(other, bool):
            return Mat(self._m * other)
        return NotImplemented

    def __add__(self, other: Any) -> Mat:
        return Mat(self._m + (other._m if isinstance(other, Mat) else other))

    def __sub__(self, other: Any) -> Mat:
        return Mat(self._m - (other._m if isinstance(other, Mat) else other))

    def __neg__(self) -> Mat:
        return Mat(-self._m)

    # ---- lists
    def list(self) -> Numbers:
        """The first column as a list (the joints of a joint Mat); [] for an empty Mat."""
        column: Numbers = self._m[:, 0].tolist() if self._m.size else []
        return column

    tolist = list

    def list2(self) -> RowList:
        """The columns as lists (RoboDK: "one list per column")."""
        return self.Cols()

    def tr(self) -> Mat:
        """The transpose."""
        return Mat(self._m.T.copy())

    def copy(self) -> Mat:
        return Mat(self._m.copy())

    def catV(self, other: Mat) -> Mat:
        """Vertical concatenation."""
        return Mat(np.vstack([self._m, Mat(other)._m]))

    def catH(self, other: Mat) -> Mat:
        """Horizontal concatenation."""
        return Mat(np.hstack([self._m, Mat(other)._m]))

    # ---- poses
    def _pose(self, what: str) -> FloatArray:
        if self._m.shape != (4, 4):
            raise MatrixError(f"{what} needs a 4 x 4 pose, this Mat is {self._m.shape}")
        return self._m

    def Pos(self) -> Numbers:
        """The translation ``[x, y, z]`` in mm."""
        return self._pose("Pos")[:3, 3].tolist()

    def setPos(self, xyz: Sequence[float]) -> Mat:
        """Set the translation (mm) in place; returns the pose itself."""
        self._pose("setPos")[:3, 3] = np.asarray(xyz, dtype=np.float64).reshape(-1)[:3]
        return self

    def VX(self) -> Numbers:
        """The X axis of the rotation."""
        return self._pose("VX")[:3, 0].tolist()

    def VY(self) -> Numbers:
        """The Y axis of the rotation."""
        return self._pose("VY")[:3, 1].tolist()

    def VZ(self) -> Numbers:
        """The Z axis of the rotation (the tool axis of a target)."""
        return self._pose("VZ")[:3, 2].tolist()

    def setVX(self, v: Sequence[float]) -> Mat:
        self._pose("setVX")[:3, 0] = np.asarray(v, dtype=np.float64)[:3]
        return self

    def setVY(self, v: Sequence[float]) -> Mat:
        self._pose("setVY")[:3, 1] = np.asarray(v, dtype=np.float64)[:3]
        return self

    def setVZ(self, v: Sequence[float]) -> Mat:
        self._pose("setVZ")[:3, 2] = np.asarray(v, dtype=np.float64)[:3]
        return self

    def inv(self) -> Mat:
        """The inverse of a rigid transform (RoboDK: the same as :meth:`invH`)."""
        return self.invH()

    def invH(self) -> Mat:
        """The inverse of a rigid transform; a MatrixError for any other matrix."""
        m = self._pose("invH")
        if not self.isHomogeneous():
            raise MatrixError("invH: the pose is not homogeneous (a rigid transform)")
        out = np.eye(4)
        out[:3, :3] = m[:3, :3].T
        out[:3, 3] = -m[:3, :3].T @ m[:3, 3]
        return Mat(out)

    def isHomogeneous(self) -> bool:
        """True for a 4 x 4 rigid transform: RoboDK's test (the entries of ``R·Rᵀ - I`` sum to
        at most 1e-4 in absolute value), plus a last row 0 0 0 1 and no mirror (olp's IR
        checks rigidity again, with its own tolerance)."""
        m = self._m
        if m.shape != (4, 4) or not np.all(np.isfinite(m)):
            return False
        if not np.allclose(m[3], [0.0, 0.0, 0.0, 1.0], atol=1e-9):
            return False
        rot = m[:3, :3]
        deviation = float(np.sum(np.abs(rot @ rot.T - np.eye(3))))
        return deviation <= 1e-4 and float(np.linalg.det(rot)) > 0

    def translationPose(self) -> Mat:
        """The translation part as a pose."""
        return transl(self.Pos())

    def rotationPose(self) -> Mat:
        """The rotation part as a pose."""
        out = Mat(self._pose("rotationPose").copy())
        out._m[:3, 3] = 0.0
        return out

    def Offset(
        self, x: float, y: float, z: float, rx: float = 0, ry: float = 0, rz: float = 0
    ) -> Mat:
        """``Pose(x, y, z, rx, ry, rz) · self`` (mm, deg): along the reference's axes."""
        return Offset(self, x, y, z, rx, ry, rz)

    def RelTool(
        self, x: float, y: float, z: float, rx: float = 0, ry: float = 0, rz: float = 0
    ) -> Mat:
        """``self · Pose(x, y, z, rx, ry, rz)`` (mm, deg): along the pose's own axes."""
        return RelTool(self, x, y, z, rx, ry, rz)

    def SaveMat(self, strfile: str, separator: str = ",") -> None:
        """Write the rows to a CSV file (RoboDK's ``Mat.SaveMat``)."""
        with open(strfile, "w", encoding="utf-8") as file:
            for row in self._m:
                file.write(separator.join(f"{v:.6f}" for v in row) + "\n")


def _plain(rows: Any) -> Any:
    """Nested lists of numbers from rows that may hold :class:`Mat` columns."""
    if isinstance(rows, list | tuple):
        return [r._m.reshape(-1).tolist() if isinstance(r, Mat) else r for r in rows]
    return rows


def _array(pose: Any) -> FloatArray:
    m = pose._m if isinstance(pose, Mat) else np.asarray(pose, dtype=np.float64)
    if m.shape != (4, 4):
        raise MatrixError(f"expected a 4 x 4 pose, got shape {m.shape}")
    return m


def _si(pose: Any) -> FloatArray:
    """A copy of a pose in metres, for :mod:`olp.vendors`."""
    m = np.array(_array(pose), dtype=np.float64)
    m[:3, 3] /= 1000.0
    return m


def _mm(pose_si: FloatArray) -> Mat:
    m = np.array(pose_si, dtype=np.float64)
    m[:3, 3] *= 1000.0
    return Mat(m)


def _values(values: Any, count: int, what: str) -> list[float]:
    flat = np.asarray(values._m if isinstance(values, Mat) else values, dtype=np.float64)
    flat = flat.reshape(-1)
    if flat.size < count:
        raise MatrixError(f"{what} needs {count} values, got {flat.size}")
    return [float(v) for v in flat[:count]]


# ------------------------------------------------------------------------------------------------
# Building poses


def eye(size: int = 4) -> Mat:
    """The identity matrix (4 x 4 by default)."""
    return Mat(np.eye(size))


def transl(tx: Any = 0.0, ty: float | None = None, tz: float | None = None) -> Mat:
    """A translation in mm: ``transl(x, y, z)`` or ``transl([x, y, z])``."""
    if ty is None and tz is None and not isinstance(tx, int | float):
        x, y, z = _values(tx, 3, "transl")
    else:
        x, y, z = float(tx), float(ty or 0.0), float(tz or 0.0)
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return Mat(m)


def _rotation(axis: int, angle: float) -> Mat:
    c, s = math.cos(angle), math.sin(angle)
    m = np.eye(4)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m[i, i] = m[j, j] = c
    m[i, j], m[j, i] = -s, s
    return Mat(m)


def rotx(rx: float) -> Mat:
    """Rotation about X by ``rx`` **radians**."""
    return _rotation(0, float(rx))


def roty(ry: float) -> Mat:
    """Rotation about Y by ``ry`` **radians**."""
    return _rotation(1, float(ry))


def rotz(rz: float) -> Mat:
    """Rotation about Z by ``rz`` **radians**."""
    return _rotation(2, float(rz))


def Pose(x: float, y: float, z: float, rx: float, ry: float, rz: float) -> Mat:
    """``transl(x, y, z) · rotx(rx) · roty(ry) · rotz(rz)``, mm and **degrees**."""
    d = pi / 180
    return transl(x, y, z) * rotx(rx * d) * roty(ry * d) * rotz(rz * d)


def TxyzRxyz_2_Pose(xyzrxyz: Any) -> Mat:
    """``[x, y, z, rx, ry, rz]`` (mm, **radians**) to ``transl · rotx · roty · rotz``."""
    x, y, z, rx, ry, rz = _values(xyzrxyz, 6, "TxyzRxyz_2_Pose")
    return transl(x, y, z) * rotx(rx) * roty(ry) * rotz(rz)


def Pose_2_TxyzRxyz(pose: Any) -> list[float]:
    """``[x, y, z, rx, ry, rz]`` (mm, **radians**) with ``pose = transl · rotx · roty · rotz``.

    At ``ry = ±90°`` ``rz`` is 0 and ``rx`` carries the rotation about the common axis.
    """
    m = _array(pose)
    r02 = max(-1.0, min(1.0, float(m[0, 2])))
    ry = math.asin(r02)
    if abs(r02) > 1 - 1e-12:
        rx, rz = math.atan2(m[2, 1], m[1, 1]), 0.0
    else:
        rx, rz = math.atan2(-m[1, 2], m[2, 2]), math.atan2(-m[0, 1], m[0, 0])
    return [float(m[0, 3]), float(m[1, 3]), float(m[2, 3]), rx, ry, rz]


def xyzrpw_2_pose(xyzrpw: Any) -> Mat:
    """``[x, y, z, r, p, w]`` (mm, degrees) to ``transl · rotz(w) · roty(p) · rotx(r)``."""
    x, y, z, r, p, w = _values(xyzrpw, 6, "xyzrpw_2_pose")
    return _mm(fanuc.xyzwpr_to_pose([x, y, z, r, p, w]))


def pose_2_xyzrpw(pose: Any) -> list[float]:
    """``[x, y, z, r, p, w]`` (mm, degrees) with ``pose = transl · rotz(w) · roty(p) · rotx(r)``."""
    return [float(v) for v in fanuc.pose_to_xyzwpr(_si(pose))]


def KUKA_2_Pose(xyzabc: Any) -> Mat:
    """KUKA ``[x, y, z, A, B, C]`` (mm, degrees) to a pose: ``transl · Rz(A) · Ry(B) · Rx(C)``."""
    return _mm(kuka.frame_to_pose(_values(xyzabc, 6, "KUKA_2_Pose")))


def Pose_2_KUKA(pose: Any) -> list[float]:
    """A pose to KUKA ``[x, y, z, A, B, C]`` (mm, degrees)."""
    return [float(v) for v in kuka.pose_to_frame(_si(pose))]


def Fanuc_2_Pose(xyzwpr: Any) -> Mat:
    """Fanuc ``[x, y, z, W, P, R]`` (mm, degrees) to a pose: ``transl · Rz(R) · Ry(P) · Rx(W)``."""
    return _mm(fanuc.xyzwpr_to_pose(_values(xyzwpr, 6, "Fanuc_2_Pose")))


def Pose_2_Fanuc(pose: Any) -> list[float]:
    """A pose to Fanuc ``[x, y, z, W, P, R]`` (mm, degrees)."""
    return [float(v) for v in fanuc.pose_to_xyzwpr(_si(pose))]


Motoman_2_Pose = Fanuc_2_Pose
Pose_2_Motoman = Pose_2_Fanuc


def pose_2_quaternion(pose: Any) -> list[float]:
    """The unit quaternion ``[q1, q2, q3, q4]`` (w first) of a pose's rotation."""
    return [float(v) for v in abb.quaternion_from_rotation(_array(pose)[:3, :3])]


def quaternion_2_pose(quaternion: Any) -> Mat:
    """A pose (no translation) from a quaternion ``[q1, q2, q3, q4]`` (w first)."""
    q = _values(quaternion, 4, "quaternion_2_pose")
    return _mm(abb.robtarget_to_pose([0.0, 0.0, 0.0], q))


def Pose_2_ABB(pose: Any) -> list[float]:
    """A pose to ABB ``[x, y, z, q1, q2, q3, q4]``: mm and a unit quaternion, w first."""
    trans, rot = abb.pose_to_robtarget(_si(pose))
    return [float(v) for v in (*trans, *rot)]


def ABB_2_Pose(xyzq: Any) -> Mat:
    """ABB ``[x, y, z, q1, q2, q3, q4]`` (mm, quaternion w first) to a pose."""
    v = _values(xyzq, 7, "ABB_2_Pose")
    return _mm(abb.robtarget_to_pose(v[:3], v[3:]))


def Pose_2_UR(pose: Any) -> list[float]:
    """A pose to UR ``[x, y, z, rx, ry, rz]``: **mm** and a rotation vector in radians."""
    values = ur.pose_to_ur(_si(pose))
    return [float(v) for v in (*(values[:3] * 1000.0), *values[3:])]


def UR_2_Pose(xyzrxyz: Any) -> Mat:
    """UR ``[x, y, z, rx, ry, rz]`` (mm, rotation vector in radians) to a pose."""
    v = _values(xyzrxyz, 6, "UR_2_Pose")
    return _mm(ur.ur_to_pose([v[0] / 1000.0, v[1] / 1000.0, v[2] / 1000.0, *v[3:]]))


def RelTool(
    target_pose: Any, x: float, y: float, z: float, rx: float = 0, ry: float = 0, rz: float = 0
) -> Mat:
    """``target_pose · Pose(x, y, z, rx, ry, rz)``: mm and degrees along the target's axes."""
    return Mat(_array(target_pose)) * Pose(x, y, z, rx, ry, rz)


def Offset(
    target_pose: Any, x: float, y: float, z: float, rx: float = 0, ry: float = 0, rz: float = 0
) -> Mat:
    """``Pose(x, y, z, rx, ry, rz) · target_pose``: mm and degrees along the reference's axes."""
    return Pose(x, y, z, rx, ry, rz) * Mat(_array(target_pose))


def invH(matrix: Any) -> Mat:
    """The inverse of a rigid transform."""
    return Mat(matrix).invH()


def tr(matrix: Any) -> Mat:
    """The transpose."""
    return Mat(matrix).tr()


def size(matrix: Any, dim: int | None = None) -> Any:
    """``(rows, cols)`` of a Mat (or one of them)."""
    return Mat(matrix).size(dim)


def catV(mat1: Any, mat2: Any) -> Mat:
    return Mat(mat1).catV(mat2)


def catH(mat1: Any, mat2: Any) -> Mat:
    return Mat(mat1).catH(mat2)


def point_Zaxis_2_pose(
    point: Sequence[float],
    zaxis: Sequence[float],
    yaxis_hint1: Sequence[float] = (0, 0, 1),
    yaxis_hint2: Sequence[float] = (0, 1, 1),
) -> Mat:
    """A pose at ``point`` (mm) whose Z axis is ``zaxis``; Y as close as possible to a hint."""
    z = np.asarray(normalize3(zaxis))
    hint = np.asarray(yaxis_hint1, dtype=np.float64)
    if abs(float(np.dot(z, hint / np.linalg.norm(hint)))) > 0.99:
        hint = np.asarray(yaxis_hint2, dtype=np.float64)
    x = np.cross(hint, z)
    x /= np.linalg.norm(x)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x, np.cross(z, x), z, point[:3]
    return Mat(m)


# ------------------------------------------------------------------------------------------------
# 3-vectors (lists of 3 numbers, mm)


def norm(p: Sequence[float]) -> float:
    return float(np.linalg.norm(np.asarray(p, dtype=np.float64)))


def normalize3(a: Sequence[float]) -> list[float]:
    v = np.asarray(a, dtype=np.float64)
    return (v / np.linalg.norm(v)).tolist()


def cross(a: Sequence[float], b: Sequence[float]) -> list[float]:
    return np.cross(np.asarray(a, float), np.asarray(b, float)).tolist()


def dot(a: Sequence[float], b: Sequence[float]) -> float:
    return float(np.dot(np.asarray(a, float), np.asarray(b, float)))


def angle3(a: Sequence[float], b: Sequence[float]) -> float:
    """The angle between two vectors, radians."""
    c = dot(a, b) / (norm(a) * norm(b))
    return math.acos(max(-1.0, min(1.0, c)))


def mult3(v: Sequence[float], d: float) -> list[float]:
    return [float(x) * d for x in v[:3]]


def add3(a: Sequence[float], b: Sequence[float]) -> list[float]:
    return [float(x) + float(y) for x, y in zip(a[:3], b[:3], strict=True)]


def subs3(a: Sequence[float], b: Sequence[float]) -> list[float]:
    return [float(x) - float(y) for x, y in zip(a[:3], b[:3], strict=True)]


def distance(a: Sequence[float], b: Sequence[float]) -> float:
    """The distance between two points (mm)."""
    return norm(subs3(a, b))


def pose_angle(pose: Any) -> float:
    """The rotation angle of a pose, radians."""
    r = _array(pose)[:3, :3]
    return math.acos(max(-1.0, min(1.0, (float(np.trace(r)) - 1) / 2)))


def pose_angle_between(pose1: Any, pose2: Any) -> float:
    """The rotation angle between two poses, radians."""
    return pose_angle(invH(pose1) * Mat(_array(pose2)))


# ------------------------------------------------------------------------------------------------
# Time: olp does not run the robot in time


_TIC = [0.0]


def tic() -> None:
    """Start RoboDK's stopwatch (wall time of the script, not robot time)."""
    import time

    _TIC[0] = time.perf_counter()


def toc() -> float:
    """Seconds since :func:`tic` (wall time of the script)."""
    import time

    return time.perf_counter() - _TIC[0]


def pause(seconds: float) -> None:
    """RoboDK waits ``seconds``; olp does not run in time: a no-op, noted in the build."""
    from olp.compat import note

    note("pause", "olp does not wait (the script runs offline); use robot.Pause(ms) in a program")


_OWN = frozenset(
    {"annotations", "math", "np", "NDArray", "Any", "Iterator", "Sequence", "FloatArray"}
    | {"Numbers", "RowList"}
    | {"abb", "fanuc", "kuka", "ur"}
)
__all__ = sorted(n for n in globals() if not n.startswith("_") and n not in _OWN)
"""What ``from robodk.robomath import *`` gives: RoboDK's names, ``pi`` and the math
functions its scripts use unqualified."""
