"""Load a station from YAML (mm and degrees, as on vendor datasheets) into SI values.

Every mistake is a :class:`~olp.errors.StationError` naming the file, line, column and key. The
format is described by the JSON Schema in :mod:`olp.station.schema` (``olp schema station``),
from which this loader also takes the allowed keys of every mapping.

Station file::

    name: kr6_milling
    robot:
      model: kuka/kr6_r900_sixx        # stations/robots/<vendor>/<model>.yaml, or a .yaml file
      base: {xyz: [0, 0, 0], zyx: [0, 0, 0]}
      home_deg: [0, -90, 90, 0, 0, 0]  # optional, else the model's
    tools:
      - {name: spindle, number: 1, tcp: {xyz: [466.6, -4.2, 109.6], zyx: [0, 90, 0]},
         mass_kg: 3.5, geometry: [{cylinder: {radius: 40, length: 200}, pose: {xyz: [0, 0, 100]}}]}
    frames:
      - {name: table, number: 1, pose: {xyz: [0, -1000, 0]}}
      - {name: fixture_1, parent: table, pose: {xyz: [100, 50, 20]}}
    parts:
      - {name: plate, frame: fixture_1, geometry: [{box: {size: [300, 200, 10]}}]}
    fixtures:
      - {name: vice, frame: table, geometry: [{mesh: {file: vice.stl}}]}
    targets:                           # named targets (RoboDK's target items)
      - {name: Home, joints_deg: [0, -90, 90, 0, 0, 0]}
      - {name: Approach, frame: table, pose: {xyz: [100, 50, 120], zyx: [0, 180, 0]}}

Instead of ``model:`` a station may define the robot inline with the keys of a library file
(``name``, ``vendor``, ``kinematics``, ``limits``, ``home_deg``, ``collision``,
``controller_base``). Kinematics types: ``opw`` (a1 a2 b c1 c2 c3 c4 in mm, ``offsets_deg``,
``signs``), ``ur`` (d1 a2 a3 d4 d5 d6 in mm), ``dh`` (standard DH ``rows`` of ``a``, ``alpha_deg``,
``d``, ``theta_deg``) and ``urdf`` (``file``, ``tip`` link, optional ``base`` link); any of them
may declare a joint ``coupling`` (Fanuc: ``[{joint: 3, from: 2, factor: 1}]``).

A pose is ``{xyz: [x, y, z]}`` in mm with an optional rotation, either ``zyx: [a, b, c]`` in
degrees meaning ``Rz(a)·Ry(b)·Rx(c)`` (the order of KUKA's A, B, C) or ``quat: [w, x, y, z]``.

The YAML is read by :func:`olp.yamlsafe.read_yaml` (no tags beyond the core ones, unique keys,
bounded aliases; see there), and every value through :mod:`olp.station.fields`, which checks
its type and the range of its quantity (a length within ±1 km, joint speeds from 0.1 deg/s
...) and quotes what the user wrote. Files a station names (meshes, a robot ``.yaml``, a URDF)
are relative to its folder and must lie inside it, symbolic links followed, unless the station
says ``allow_outside_paths: true``; /proc, /sys, /dev, devices and FIFOs are never read. Meshes
are read and checked at load (:mod:`olp.station.meshes`): an empty, malformed, flat or huge
mesh is an error at the ``file:`` that names it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from olp import vendors
from olp.errors import StationError
from olp.geometry import pose_from, rotation_from_quaternion, rotation_from_zyx
from olp.ir import Frame, Tool
from olp.kinematics.base import JointCoupling, Kinematics, turn_shifts
from olp.kinematics.models import ChainKinematics, OPWKinematics, URKinematics, default_seeds
from olp.kinematics.opw import OPWParameters
from olp.kinematics.ur import URParameters
from olp.resources import data_path
from olp.station.fields import (
    ACCELERATION,
    ANGLE,
    JERK,
    LENGTH,
    MASS,
    MAX_CONTROLLER_INTEGER,
    PATH_ACCELERATION,
    QUATERNION,
    SIZE,
    SPEED,
    Source,
    check_keys,
    flag,
    get,
    got,
    integer,
    items,
    name,
    number,
    numbers,
    referenced_file,
    text,
)
from olp.station.meshes import MeshError, mesh_hull
from olp.station.model import (
    JointLimits,
    NamedTarget,
    Robot,
    Shape,
    Station,
    StationObject,
    ToolBody,
)
from olp.station.schema import KEYS, OPW_KEYS, PRIMITIVE_KINDS, UR_KEYS
from olp.yamlsafe import KeyPath, UnreadableFile, read_regular_file, read_yaml, shorten

MAX_URDF_BYTES = 16 * 2**20
"""Largest URDF file read (16 MiB)."""
MAX_COUPLING_FACTOR = 100


def _read(path: Path, allow_outside: bool = False) -> Source:
    return Source(read_yaml(path, StationError), allow_outside)


def _pose(src: Source, value: Any, path: KeyPath) -> np.ndarray:
    """A pose from ``{xyz: mm, zyx: deg | quat: [w, x, y, z]}``; metres inside."""
    if value is None:
        return np.eye(4)
    check_keys(src, value, path, KEYS["pose"])
    xyz = value.get("xyz")
    position = (
        numbers(src, xyz, (*path, "xyz"), 3, LENGTH) / 1000.0 if xyz is not None else np.zeros(3)
    )
    if "zyx" in value and "quat" in value:
        raise src.error(path, "give the rotation either as 'zyx' or as 'quat', not both")
    rotation = np.eye(3)
    if "zyx" in value:
        angles = np.radians(numbers(src, value["zyx"], (*path, "zyx"), 3, ANGLE))
        rotation = rotation_from_zyx(*angles)
    elif "quat" in value:
        quat = numbers(src, value["quat"], (*path, "quat"), 4, QUATERNION)
        rotation = _quat_to_rotation(src, quat, path)
    return pose_from(rotation, position)


def _quat_to_rotation(src: Source, q: np.ndarray, path: KeyPath) -> np.ndarray:
    norm = float(np.linalg.norm(q))
    if not 0.99 < norm < 1.01:
        raise src.error((*path, "quat"), f"quaternion must be unit length, its norm is {norm:.6g}")
    return rotation_from_quaternion(q)


def _shapes(
    src: Source, value: Any, path: KeyPath, links: set[str] | None = None
) -> tuple[Shape, ...]:
    """Shapes of a list; ``links`` (robot collision models): the allowed ``link`` names."""
    return tuple(
        _shape(src, item, (*path, i), links) for i, item in enumerate(items(src, value, path))
    )


def _shape(src: Source, value: Any, path: KeyPath, links: set[str] | None) -> Shape:
    check_keys(src, value, path, KEYS["shape"])
    kinds = [k for k in PRIMITIVE_KINDS if k in value]
    if len(kinds) != 1:
        given = ", ".join(kinds) or "none"
        raise src.error(path, f"give exactly one of {', '.join(PRIMITIVE_KINDS)}; got {given}")
    shape_kind = kinds[0]
    where: KeyPath = (*path, shape_kind)
    spec = value[shape_kind]
    check_keys(src, spec, where, KEYS[shape_kind])
    pose = _pose(src, value.get("pose"), (*path, "pose"))
    link = _shape_link(src, value, path, links)
    if shape_kind == "mesh":
        return _mesh(src, spec, where, pose, link)
    if shape_kind == "capsule":
        return _capsule(src, spec, where, pose, link)
    sizes: dict[str, Callable[[], tuple[float, ...]]] = {
        "box": lambda: tuple(
            numbers(src, get(src, spec, where, "size"), (*where, "size"), 3, SIZE)
        ),
        "cylinder": lambda: (_size(src, spec, where, "radius"), _size(src, spec, where, "length")),
        "sphere": lambda: (_size(src, spec, where, "radius"),),
    }
    size = tuple(float(s) / 1000.0 for s in sizes[shape_kind]())
    return Shape(shape_kind, pose, size=size, link=link)  # type: ignore[arg-type]


def _size(src: Source, spec: Any, path: KeyPath, key: str) -> float:
    return number(src, get(src, spec, path, key), (*path, key), SIZE)


def _mesh(src: Source, spec: Any, path: KeyPath, pose: np.ndarray, link: str) -> Shape:
    """A mesh shape, its file read and checked now (:mod:`olp.station.meshes`), so that a bad
    mesh is an error at the ``file:`` that names it, not a traceback in the collision checks."""
    units = spec.get("units", "mm")
    if units not in ("mm", "m"):
        raise src.error(
            (*path, "units"), f"expected 'mm' or 'm', got {src.shown((*path, 'units'))}"
        )
    file_path: KeyPath = (*path, "file")
    written = Path(text(src, get(src, spec, path, "file"), file_path))
    file = referenced_file(src, str(written), file_path)
    scale = 0.001 if units == "mm" else 1.0
    try:
        hull = mesh_hull(file, scale, written.suffix)
    except MeshError as exc:
        raise src.error(file_path, f"mesh {shorten(written.name)}: {exc}") from None
    return Shape("mesh", pose, mesh=str(file), scale=scale, link=link, hull=hull)


def _shape_link(src: Source, value: Any, path: KeyPath, links: set[str] | None) -> str:
    if links is None:
        if "link" in value:
            raise src.error((*path, "link"), "'link' is only for a robot's collision shapes")
        return ""
    link = text(src, get(src, value, path, "link"), (*path, "link"))
    if link not in links:
        raise src.error(
            (*path, "link"),
            f"unknown link '{shorten(link)}' (links: {', '.join(sorted(links))})",
        )
    return link


def _capsule(src: Source, spec: Any, path: KeyPath, pose: np.ndarray, link: str) -> Shape:
    """A capsule around the segment from-to: its own pose has Z along the segment, centred."""
    start = numbers(src, get(src, spec, path, "from"), (*path, "from"), 3, LENGTH) / 1000.0
    end = numbers(src, get(src, spec, path, "to"), (*path, "to"), 3, LENGTH) / 1000.0
    radius = _size(src, spec, path, "radius") / 1000.0
    axis = end - start
    length = float(np.linalg.norm(axis))
    z = axis / length if length > 0 else np.array([0.0, 0.0, 1.0])
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    local = pose_from(np.column_stack([x, np.cross(z, x), z]), (start + end) / 2)
    # A zero-length capsule is a sphere; Shape needs a positive length, so give it a hair.
    return Shape("capsule", pose @ local, size=(radius, max(length, 1e-9)), link=link)


# --------------------------------------------------------------------------------------------
# Robot models


_RATE_LIMITS = {
    "velocity": ("velocity_deg_s", SPEED),
    "acceleration": ("acceleration_deg_s2", ACCELERATION),
    "jerk": ("jerk_deg_s3", JERK),
}


def _limits(
    src: Source, value: Any, path: KeyPath, base: JointLimits | None, dof: int, vendor: str
) -> JointLimits:
    check_keys(src, value, path, KEYS["limits"])
    path_acceleration = _path_acceleration(src, value, path, vendor)
    fields: dict[str, np.ndarray] = {}
    if value.get("position_deg") is not None:
        fields["lower"], fields["upper"] = _position_limits(
            src, value["position_deg"], (*path, "position_deg"), dof
        )
    for field, (key, quantity) in _RATE_LIMITS.items():
        if key in value:
            fields[field] = np.radians(numbers(src, value[key], (*path, key), dof, quantity))
    names = ("lower", "upper", "velocity", "acceleration", "jerk")
    if base is None:
        missing = [n for n in names if n not in fields]
        if missing:
            raise src.error(path, f"missing limits: {', '.join(missing)}")
        return JointLimits(**fields, path_acceleration=path_acceleration)
    if path_acceleration is None:
        path_acceleration = base.path_acceleration
    merged = {n: fields.get(n, getattr(base, n)) for n in names}
    return JointLimits(**merged, path_acceleration=path_acceleration)


def _path_acceleration(src: Source, value: Any, path: KeyPath, vendor: str) -> float | None:
    """``path_acceleration_m_s2``: the controller's default TCP path acceleration (m/s²)."""
    key = "path_acceleration_m_s2"
    if value.get(key) is None:
        return None
    if vendor == "ur":
        raise src.error(
            (*path, key),
            "a UR program states the tool acceleration (a=) on every movel, so the arm has no "
            "default path acceleration: set it in the program (KRL $ACC.CP, DSL "
            "setAcceleration)",
        )
    return number(src, value[key], (*path, key), PATH_ACCELERATION)


def _position_limits(
    src: Source, value: Any, path: KeyPath, dof: int
) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper joint limits (dof,) rad from ``dof`` pairs ``[lower, upper]`` deg."""
    if not isinstance(value, list) or len(value) != dof:
        raise src.error(
            path, f"expected {dof} pairs [lower, upper] in degrees, got {src.shown(path)}"
        )
    pairs = np.radians([numbers(src, p, (*path, i), 2, ANGLE) for i, p in enumerate(value)])
    for i, (lower, upper) in enumerate(pairs):
        if lower >= upper:
            raise src.error((*path, i), "lower limit must be below upper limit")
    turns = [len(turn_shifts(lower, upper)) for lower, upper in pairs]
    if math.prod(turns) > MAX_TURN_COMBINATIONS:
        raise src.error(
            path,
            f"these ranges let the axes take {math.prod(turns):,} combinations of turns "
            f"(per axis: {', '.join(map(str, turns))}); olp considers every one for each target, "
            f"and allows at most {MAX_TURN_COMBINATIONS:,}",
        )
    return pairs[:, 0], pairs[:, 1]


MAX_TURN_COMBINATIONS = 4096
"""Most joint-turn combinations the position limits may allow (olp's bound): inverse kinematics
lists every ``q + 2 pi m`` inside the limits for each target, so a joint of ±1e8° meant half a
million variants (400 MB) per target. 4096 admits every real arm (the most among the bundled
robots: 729, six UR axes of ±360°) and, say, two axes of ±5000°."""


@dataclass(frozen=True, slots=True, eq=False)
class RobotModel:
    """A robot library entry (before placement in a station), SI units."""

    name: str
    vendor: str
    kinematics: Kinematics
    limits: JointLimits
    home: np.ndarray
    controller_base: np.ndarray
    collision: tuple[Shape, ...]
    sources: tuple[str, ...] = ()
    allowed_pairs: tuple[tuple[str, str], ...] = ()

    def place(self, base: np.ndarray | None = None, **changes: Any) -> Robot:
        """The model as a :class:`Robot` at ``base`` (4, 4) in the world (default: origin)."""
        return Robot(
            name=changes.get("name", self.name),
            vendor=self.vendor,
            kinematics=self.kinematics,
            limits=changes.get("limits", self.limits),
            home=changes.get("home", self.home),
            base=np.eye(4) if base is None else base,
            flange_in_tool0=vendors.flange_in_tool0(self.vendor),
            controller_base=self.controller_base,
            collision=self.collision,
            allowed_pairs=self.allowed_pairs,
        )


def load_robot_model(path: str | Path, allow_outside_paths: bool = False) -> RobotModel:
    """Read a robot library file (``stations/robots/<vendor>/<model>.yaml``).

    Files it names (a URDF, collision meshes) must lie inside its folder unless
    ``allow_outside_paths`` (a station that allows them hands this on).
    """
    src = _read(Path(path), allow_outside_paths)
    check_keys(src, src.value, (), KEYS["model"])
    return _model(src, src.value, ())


def _model(src: Source, value: dict[str, Any], path: KeyPath) -> RobotModel:
    """A robot model from the library keys of ``value`` (a library file or an inline robot)."""
    vendor = get(src, value, path, "vendor")
    if not isinstance(vendor, str) or vendor not in vendors.KNOWN:
        raise src.error(
            (*path, "vendor"),
            f"unknown vendor {src.shown((*path, 'vendor'))} (known: {', '.join(vendors.KNOWN)})",
        )
    limits_value = get(src, value, path, "limits")
    home_value = get(src, value, path, "home_deg")
    kin_path: KeyPath = (*path, "kinematics")
    kinematics, links = _kinematics(src, get(src, value, path, "kinematics"), kin_path)
    dof = kinematics.dof
    limits = _limits(src, limits_value, (*path, "limits"), None, dof, vendor)
    home = np.radians(numbers(src, home_value, (*path, "home_deg"), dof, ANGLE))
    if np.any(limits.violations(home)):
        raise src.error((*path, "home_deg"), "home position lies outside the joint limits")
    if isinstance(kinematics, ChainKinematics):
        seeds = default_seeds(home, limits.lower, limits.upper)
        kinematics = ChainKinematics(kinematics.model, seeds, kinematics.coupling)
    sources_path: KeyPath = (*path, "sources")
    sources = tuple(
        text(src, s, (*sources_path, i))
        for i, s in enumerate(items(src, value.get("sources"), sources_path))
    )
    robot_name = "robot" if value.get("name") is None else value["name"]
    return RobotModel(
        name=name(src, robot_name, (*path, "name")),
        vendor=vendor,
        kinematics=kinematics,
        limits=limits,
        home=home,
        controller_base=_pose(src, value.get("controller_base"), (*path, "controller_base")),
        collision=_shapes(src, value.get("collision"), (*path, "collision"), links),
        sources=sources,
        allowed_pairs=_pairs(src, value.get("allowed_pairs"), (*path, "allowed_pairs"), links),
    )


_KINEMATICS_KEYS = {
    "opw": {*OPW_KEYS, "offsets_deg", "signs"},
    "ur": set(UR_KEYS),
    "dh": {"rows"},
    "urdf": {"file", "tip", "base"},
}


def _kinematics(src: Source, value: Any, path: KeyPath) -> tuple[Kinematics, set[str]]:
    """The kinematics and the names of the links collision shapes may attach to."""
    check_keys(src, value, path, KEYS["kinematics"])
    kinematics_type = get(src, value, path, "type")
    readers: dict[str, Callable[[Source, Any, KeyPath], tuple[Kinematics, set[str]]]] = {
        "opw": _opw,
        "ur": _ur,
        "dh": _dh,
        "urdf": _urdf,
    }
    if not isinstance(kinematics_type, str) or kinematics_type not in readers:
        raise src.error(
            (*path, "type"),
            f"unsupported kinematics type {src.shown((*path, 'type'))} "
            "(expected one of: opw, ur, dh, urdf)",
        )
    expected = _KINEMATICS_KEYS[kinematics_type] | {"type", "coupling"}
    for key in value:
        if key not in expected:
            raise src.error(
                (*path, key), f"'{key}' does not belong to kinematics of type '{kinematics_type}'"
            )
    return readers[kinematics_type](src, value, path)


def _chain_links(dof: int) -> set[str]:
    return {"base", *(f"link_{i}" for i in range(1, dof + 1))}


def _coupling(src: Source, value: Any, path: KeyPath, dof: int) -> JointCoupling:
    terms = []
    for i, item in enumerate(items(src, value.get("coupling"), (*path, "coupling"))):
        where: KeyPath = (*path, "coupling", i)
        check_keys(src, item, where, KEYS["coupling"])
        joint = integer(src, get(src, item, where, "joint"), (*where, "joint"), 1, dof)
        source = integer(src, get(src, item, where, "from"), (*where, "from"), 1, dof)
        factor = integer(
            src,
            item.get("factor", 1),
            (*where, "factor"),
            -MAX_COUPLING_FACTOR,
            MAX_COUPLING_FACTOR,
        )
        if joint == source:
            raise src.error(where, f"joints must be two different numbers in 1..{dof}")
        terms.append((joint - 1, source - 1, factor))
    try:
        return JointCoupling.from_terms(dof, terms)
    except ValueError as exc:
        raise src.error((*path, "coupling"), str(exc)) from exc


def _lengths(src: Source, value: Any, path: KeyPath, keys: tuple[str, ...]) -> dict[str, float]:
    return {k: number(src, get(src, value, path, k), (*path, k), LENGTH) / 1000.0 for k in keys}


def _opw(src: Source, value: Any, path: KeyPath) -> tuple[Kinematics, set[str]]:
    lengths = _lengths(src, value, path, OPW_KEYS)
    offsets_path: KeyPath = (*path, "offsets_deg")
    offsets = np.radians(numbers(src, get(src, value, path, "offsets_deg"), offsets_path, 6, ANGLE))
    signs = _signs(src, get(src, value, path, "signs"), (*path, "signs"))
    try:
        params = OPWParameters(**lengths, offsets=tuple(offsets.tolist()), signs=signs)
    except ValueError as exc:
        raise src.error(path, str(exc)) from exc
    return OPWKinematics(params, _coupling(src, value, path, 6)), _chain_links(6)


def _signs(src: Source, value: Any, path: KeyPath) -> tuple[int, ...]:
    """Six joint directions, each 1 or -1."""
    signs = [
        integer(src, s, (*path, i), -1, 1) if isinstance(s, int) else s
        for i, s in enumerate(value if isinstance(value, list) else [])
    ]
    if not isinstance(value, list) or len(signs) != 6 or any(s not in (1, -1) for s in signs):
        raise src.error(path, f"expected six signs, each 1 or -1, got {src.shown(path)}")
    return tuple(int(s) for s in signs)


def _ur(src: Source, value: Any, path: KeyPath) -> tuple[Kinematics, set[str]]:
    if "coupling" in value:
        raise src.error((*path, "coupling"), "UR arms have no joint coupling")
    try:
        params = URParameters(**_lengths(src, value, path, UR_KEYS))
    except ValueError as exc:
        raise src.error(path, str(exc)) from exc
    return URKinematics(params), _chain_links(6)


MAX_JOINTS = 32
"""Most joints of a DH table or URDF chain olp takes (industrial arms have 4 to 7)."""


def _dh(src: Source, value: Any, path: KeyPath) -> tuple[Kinematics, set[str]]:
    rows_path: KeyPath = (*path, "rows")
    rows = items(src, get(src, value, path, "rows"), rows_path)
    if not rows:
        raise src.error(rows_path, "a DH table needs at least one row")
    if len(rows) > MAX_JOINTS:
        raise src.error(rows_path, f"a DH table has at most {MAX_JOINTS} rows, this {len(rows)}")
    table = []
    for i, row in enumerate(rows):
        where: KeyPath = (*rows_path, i)
        check_keys(src, row, where, KEYS["dh_row"])
        table.append(
            (
                number(src, get(src, row, where, "a"), (*where, "a"), LENGTH) / 1000.0,
                math.radians(
                    number(src, get(src, row, where, "alpha_deg"), (*where, "alpha_deg"), ANGLE)
                ),
                number(src, get(src, row, where, "d"), (*where, "d"), LENGTH) / 1000.0,
                math.radians(number(src, row.get("theta_deg", 0), (*where, "theta_deg"), ANGLE)),
            )
        )
    from olp.kinematics.pinocchio_model import build_dh_model

    a, alpha, d, theta = (np.array(c) for c in zip(*table, strict=True))
    model = build_dh_model(a, alpha, d, theta)
    coupling = _coupling(src, value, path, len(table))
    chain = ChainKinematics(model, np.zeros((1, len(table))), coupling, "dh")
    return chain, _chain_links(len(table))


def _urdf(src: Source, value: Any, path: KeyPath) -> tuple[Kinematics, set[str]]:
    file_path: KeyPath = (*path, "file")
    file = referenced_file(src, get(src, value, path, "file"), file_path)
    try:
        read_regular_file(file, MAX_URDF_BYTES)
    except UnreadableFile as exc:
        raise src.error(file_path, f"cannot read URDF {shorten(file.name)}: {exc}") from None
    tip = text(src, get(src, value, path, "tip"), (*path, "tip"))
    base = value.get("base")
    if base is not None:
        base = text(src, base, (*path, "base"))
    from olp.kinematics.pinocchio_model import ChainError, load_urdf_model

    try:
        model = load_urdf_model(str(file), tip, base)
    except ChainError as exc:
        key = "base" if base is not None and base in str(exc) else "tip"
        raise src.error((*path, key), shorten(str(exc), 300)) from exc
    except (ValueError, RuntimeError) as exc:  # pinocchio's errors for an unreadable file
        message = shorten(" ".join(str(exc).split()), 200)
        raise src.error(file_path, f"cannot read URDF {file.name}: {message}") from exc
    if model.nq != model.nv:
        raise src.error(
            file_path,
            f"the chain to '{shorten(tip)}' has a continuous, planar or floating joint; olp "
            "takes revolute and prismatic joints (give a continuous joint limits instead)",
        )
    if model.nq > MAX_JOINTS:
        raise src.error(file_path, f"the chain has {model.nq} joints, at most {MAX_JOINTS}")
    coupling = _coupling(src, value, path, model.nq)
    chain = ChainKinematics(model, np.zeros((1, model.nq)), coupling, f"urdf {file.name}")
    import pinocchio as pin

    links = {"base", *(f.name for f in model.frames if f.type == pin.FrameType.BODY)}
    return chain, links


def robot_library() -> list[str]:
    """Names of the bundled robot models, e.g. ``kuka/kr6_r900_sixx``."""
    root = data_path("stations", "robots")
    return sorted(str(p.relative_to(root).with_suffix("")) for p in root.glob("*/*.yaml"))


def _bundled(name: str) -> Path | None:
    """The file of a bundled model by library name; None unless the name is in the library
    (a name is never used as a path, so ``../..`` cannot leave the library)."""
    if name not in robot_library():
        return None
    return data_path("stations", "robots", *f"{name}.yaml".split("/"))


def load_library_robot(name: str) -> RobotModel:
    """A bundled robot model by name (see :func:`robot_library`); KeyError if unknown."""
    bundled = _bundled(name)
    if bundled is None:
        raise KeyError(f"unknown robot model {name!r} (bundled: {', '.join(robot_library())})")
    return load_robot_model(bundled)


# --------------------------------------------------------------------------------------------
# Stations


def load_station(path: str | Path) -> Station:
    """Load a station YAML file. Raises :class:`StationError` with file:line:col on mistakes.

    Files the station names (meshes, a robot file, a URDF) are relative to its folder and must
    lie inside it, symbolic links followed, unless the station says
    ``allow_outside_paths: true``; /proc, /sys, /dev, devices and FIFOs are never read.
    """
    path = Path(path)
    src = _read(path)
    top = src.value
    check_keys(src, top, (), KEYS["station"])
    if "allow_outside_paths" in top:
        allow = flag(src, top["allow_outside_paths"], ("allow_outside_paths",))
        src = Source(src.doc, allow)
    if "description" in top:
        text(src, top["description"], ("description",))
    robot = _station_robot(src, get(src, top, (), "robot"), ("robot",))
    tools, bodies = _tools(src, items(src, top.get("tools"), ("tools",)), ("tools",))
    frames, parents = _frames(src, items(src, top.get("frames"), ("frames",)), ("frames",))
    seen: set[str] = set()
    objects = (
        *_objects(src, top.get("parts"), ("parts",), "part", frames, seen),
        *_objects(src, top.get("fixtures"), ("fixtures",), "fixture", frames, seen),
    )
    targets = _targets(src, top.get("targets"), ("targets",), robot, frames)
    names = {"base", *(s.link for s in robot.collision), *tools, *seen}
    station_name = path.stem if top.get("name") is None else name(src, top["name"], ("name",))
    return Station(
        name=station_name,
        robot=robot,
        tools=tools,
        frames=frames,
        source=str(path),
        tool_bodies=bodies,
        frame_parents=parents,
        objects=objects,
        allowed_pairs=_pairs(src, top.get("allowed_pairs"), ("allowed_pairs",), names),
        targets=targets,
    )


def _targets(
    src: Source, value: Any, path: KeyPath, robot: Robot, frames: dict[str, Frame]
) -> dict[str, NamedTarget]:
    """Named targets: a ``pose`` (the TCP in ``frame``) or ``joints_deg`` inside the limits."""
    out: dict[str, NamedTarget] = {}
    for i, item in enumerate(items(src, value, path)):
        where: KeyPath = (*path, i)
        check_keys(src, item, where, KEYS["target"])
        target_name = name(src, get(src, item, where, "name"), (*where, "name"))
        if target_name in out:
            raise src.error((*where, "name"), f"duplicate target name '{target_name}'")
        if "description" in item:
            text(src, item["description"], (*where, "description"))
        frame = _frame_name(src, item, where, frames)
        if ("pose" in item) == ("joints_deg" in item):
            raise src.error(where, "give a target either a 'pose' or 'joints_deg', exactly one")
        if "pose" in item:
            pose = _pose(src, item["pose"], (*where, "pose"))
            out[target_name] = NamedTarget(target_name, frame, pose=pose)
            continue
        joints = np.radians(
            numbers(src, item["joints_deg"], (*where, "joints_deg"), robot.dof, ANGLE)
        )
        outside = np.flatnonzero(robot.limits.violations(joints))
        if outside.size:
            axis = int(outside[0])
            raise src.error(
                (*where, "joints_deg", axis),
                f"joint {axis + 1} lies outside its limits "
                f"({math.degrees(robot.limits.lower[axis]):g} to "
                f"{math.degrees(robot.limits.upper[axis]):g} deg)",
            )
        out[target_name] = NamedTarget(target_name, frame, joints=joints)
    return out


def _pairs(src: Source, value: Any, path: KeyPath, names: set[str]) -> tuple[tuple[str, str], ...]:
    """``allowed_pairs``: a list of [name, name], each one of ``names``."""
    out = []
    for i, pair in enumerate(items(src, value, path)):
        if not isinstance(pair, list) or len(pair) != 2 or pair[0] == pair[1]:
            where = (*path, i)
            raise src.error(where, f"expected two different names [A, B], {got(src, pair, where)}")
        for k, item in enumerate(pair):
            if not isinstance(item, str) or item not in names:
                known = ", ".join(sorted(names))
                raise src.error(
                    (*path, i, k), f"unknown body {src.shown((*path, i, k))} (known: {known})"
                )
        out.append((str(pair[0]), str(pair[1])))
    return tuple(out)


def _station_robot(src: Source, value: Any, path: KeyPath) -> Robot:
    check_keys(src, value, path, KEYS["robot"])
    if "model" not in value:
        model = _model(src, value, path)
        return model.place(_pose(src, value.get("base"), (*path, "base")))
    extra = set(value) - {"model", "base", "home_deg", "limits"}
    if extra:
        key = sorted(extra)[0]
        raise src.error(
            (*path, key),
            f"'{key}' belongs to an inline robot; with 'model' give only base, home_deg and limits",
        )
    model = _station_model(src, get(src, value, path, "model"), (*path, "model"))
    limits = model.limits
    if "limits" in value:
        limits = _limits(
            src,
            value["limits"],
            (*path, "limits"),
            model.limits,
            model.kinematics.dof,
            model.vendor,
        )
    home = model.home
    if "home_deg" in value:
        dof = model.kinematics.dof
        home = np.radians(numbers(src, value["home_deg"], (*path, "home_deg"), dof, ANGLE))
    if np.any(limits.violations(home)):
        raise src.error((*path, "home_deg"), "home position lies outside the joint limits")
    return model.place(_pose(src, value.get("base"), (*path, "base")), limits=limits, home=home)


def _station_model(src: Source, value: Any, path: KeyPath) -> RobotModel:
    """The robot model a station names: a library name, or a ``.yaml`` file beside it."""
    model_name = text(src, value, path)
    if model_name.endswith((".yaml", ".yml")):
        return load_robot_model(referenced_file(src, model_name, path), src.allow_outside)
    bundled = _bundled(model_name)
    if bundled is None:
        known = ", ".join(robot_library())
        raise src.error(path, f"unknown robot model {src.shown(path)} (bundled: {known})")
    return load_robot_model(bundled)


def _name_number(src: Source, item: Any, where: KeyPath) -> tuple[str, int | None]:
    item_name = name(src, get(src, item, where, "name"), (*where, "name"))
    number_value = item.get("number")
    if number_value is not None:
        number_value = integer(src, number_value, (*where, "number"), 0, MAX_CONTROLLER_INTEGER)
    if "description" in item:
        text(src, item["description"], (*where, "description"))
    return item_name, number_value


def _tools(
    src: Source, tool_items: list[Any], path: KeyPath
) -> tuple[dict[str, Tool], dict[str, ToolBody]]:
    tools: dict[str, Tool] = {}
    bodies: dict[str, ToolBody] = {}
    for i, item in enumerate(tool_items):
        where: KeyPath = (*path, i)
        check_keys(src, item, where, KEYS["tool"])
        tool_name, tool_number = _name_number(src, item, where)
        if tool_name in tools:
            raise src.error((*where, "name"), f"duplicate name '{tool_name}'")
        tools[tool_name] = Tool(
            name=tool_name, pose=_pose(src, item.get("tcp"), (*where, "tcp")), number=tool_number
        )
        mass = item.get("mass_kg")
        bodies[tool_name] = ToolBody(
            mass=None if mass is None else number(src, mass, (*where, "mass_kg"), MASS),
            shapes=_shapes(src, item.get("geometry"), (*where, "geometry")),
        )
    return tools, bodies


def _frames(
    src: Source, frame_items: list[Any], path: KeyPath
) -> tuple[dict[str, Frame], dict[str, str]]:
    """Frames with their world poses; a ``parent`` chains a frame to another (any order)."""
    local: dict[str, tuple[np.ndarray, int | None, KeyPath]] = {}
    parents: dict[str, str] = {}
    for i, item in enumerate(frame_items):
        where: KeyPath = (*path, i)
        check_keys(src, item, where, KEYS["frame"])
        frame_name, frame_number = _name_number(src, item, where)
        if frame_name in local:
            raise src.error((*where, "name"), f"duplicate name '{frame_name}'")
        local[frame_name] = (_pose(src, item.get("pose"), (*where, "pose")), frame_number, where)
        if "parent" in item:
            parents[frame_name] = text(src, item["parent"], (*where, "parent"))
    for frame_name, parent in parents.items():
        if parent != "world" and parent not in local:
            raise src.error(
                (*local[frame_name][2], "parent"),
                f"unknown parent frame '{shorten(parent)}' (frames: {shorten(', '.join(local))})",
            )
    world: dict[str, np.ndarray] = {}
    for frame_name in local:
        _world_pose(src, frame_name, local, parents, world)
    frames = {n: Frame(name=n, pose=world[n], number=local[n][1]) for n in local}
    return frames, {n: parents.get(n, "world") for n in local}


def _world_pose(
    src: Source,
    frame_name: str,
    local: dict[str, tuple[np.ndarray, int | None, KeyPath]],
    parents: dict[str, str],
    done: dict[str, np.ndarray],
) -> None:
    """Put the world pose of ``frame_name`` and of its ancestors in ``done``. A loop, not
    recursion: a chain of thousands of parents must not overflow the stack."""
    chain: list[str] = []
    current = frame_name
    while current != "world" and current not in done:
        if current in chain:
            cycle = " -> ".join((*chain[chain.index(current) :], current))
            raise src.error((*local[current][2], "parent"), f"frame parents form a cycle: {cycle}")
        chain.append(current)
        current = parents.get(current, "world")
    above = np.eye(4) if current == "world" else done[current]
    for link in reversed(chain):
        above = done[link] = above @ local[link][0]


def _objects(
    src: Source,
    value: Any,
    path: KeyPath,
    object_kind: str,
    frames: dict[str, Frame],
    seen: set[str],
) -> list[StationObject]:
    """Parts or fixtures placed in the world; names unique across both (``seen``)."""
    out = []
    for i, item in enumerate(items(src, value, path)):
        where: KeyPath = (*path, i)
        check_keys(src, item, where, KEYS["object"])
        object_name = name(src, get(src, item, where, "name"), (*where, "name"))
        if object_name in seen:
            raise src.error((*where, "name"), f"duplicate part or fixture name '{object_name}'")
        seen.add(object_name)
        if "description" in item:
            text(src, item["description"], (*where, "description"))
        frame = _frame_name(src, item, where, frames)
        above = np.eye(4) if frame == "world" else frames[frame].pose
        assert above is not None
        shapes = _shapes(src, get(src, item, where, "geometry"), (*where, "geometry"))
        if not shapes:
            raise src.error((*where, "geometry"), f"a {object_kind} needs at least one shape")
        pose = above @ _pose(src, item.get("pose"), (*where, "pose"))
        out.append(StationObject(object_name, object_kind, pose, shapes, frame))  # type: ignore[arg-type]
    return out


def _frame_name(
    src: Any, item: Mapping[str, Any], where: KeyPath, frames: Mapping[str, Any]
) -> str:
    """An item's ``frame`` (default ``world``): ``world`` or a frame of the station, else a
    located error listing the frames."""
    frame = text(src, item.get("frame", "world"), (*where, "frame"))
    if frame != "world" and frame not in frames:
        raise src.error(
            (*where, "frame"),
            f"unknown frame '{shorten(frame)}' (frames: {shorten(', '.join(frames) or 'none')})",
        )
    return frame
