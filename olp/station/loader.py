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

Instead of ``model:`` a station may define the robot inline with the keys of a library file
(``name``, ``vendor``, ``kinematics``, ``limits``, ``home_deg``, ``collision``,
``controller_base``). Kinematics types: ``opw`` (a1 a2 b c1 c2 c3 c4 in mm, ``offsets_deg``,
``signs``), ``ur`` (d1 a2 a3 d4 d5 d6 in mm), ``dh`` (standard DH ``rows`` of ``a``, ``alpha_deg``,
``d``, ``theta_deg``) and ``urdf`` (``file``, ``tip`` link, optional ``base`` link); any of them
may declare a joint ``coupling`` (Fanuc: ``[{joint: 3, from: 2, factor: 1}]``).

A pose is ``{xyz: [x, y, z]}`` in mm with an optional rotation, either ``zyx: [a, b, c]`` in
degrees meaning ``Rz(a)·Ry(b)·Rx(c)`` (the order of KUKA's A, B, C) or ``quat: [w, x, y, z]``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from olp import vendors
from olp.errors import StationError, line_of
from olp.geometry import pose_from, rotation_from_quaternion, rotation_from_zyx
from olp.ir import Frame, SourceSpan, Tool
from olp.kinematics.base import JointCoupling, Kinematics
from olp.kinematics.models import ChainKinematics, OPWKinematics, URKinematics, default_seeds
from olp.kinematics.opw import OPWParameters
from olp.kinematics.ur import URParameters
from olp.resources import data_path
from olp.station.model import JointLimits, Robot, Shape, Station, StationObject, ToolBody
from olp.station.schema import KEYS, OPW_KEYS, PRIMITIVE_KINDS, UR_KEYS

Path_ = tuple[str | int, ...]


@dataclass(frozen=True, slots=True)
class _Doc:
    """A parsed YAML document with the source position of every key path."""

    value: Any
    marks: dict[Path_, tuple[int, int]]
    file: str
    text: str

    @property
    def folder(self) -> Path:
        return Path(self.file).parent

    def error(self, path: Path_, message: str) -> StationError:
        line, col = self.marks.get(path, (1, 1))
        where = ".".join(str(p) for p in path) or "<top level>"
        return StationError(
            f"{where}: {message}", SourceSpan(self.file, line, col), line_of(self.text, line)
        )


def _read_yaml(path: Path) -> _Doc:
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise StationError(
            f"cannot read station file: {exc.strerror}", SourceSpan(str(path), 1)
        ) from exc
    try:
        node = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        raise StationError(
            f"invalid YAML: {exc.problem}", SourceSpan(str(path), line, col), line_of(text, line)
        ) from exc
    marks: dict[Path_, tuple[int, int]] = {}
    value = _to_python(node, (), marks) if node is not None else {}
    return _Doc(value, marks, str(path), text)


def _to_python(node: yaml.Node, path: Path_, marks: dict[Path_, tuple[int, int]]) -> Any:
    marks[path] = (node.start_mark.line + 1, node.start_mark.column + 1)
    if isinstance(node, yaml.MappingNode):
        out: dict[str, Any] = {}
        for key_node, value_node in node.value:
            key = str(key_node.value)
            out[key] = _to_python(value_node, (*path, key), marks)
            marks[(*path, key)] = (key_node.start_mark.line + 1, key_node.start_mark.column + 1)
        return out
    if isinstance(node, yaml.SequenceNode):
        return [_to_python(n, (*path, i), marks) for i, n in enumerate(node.value)]
    assert isinstance(node, yaml.ScalarNode)
    return _scalar(node)


def _scalar(node: yaml.ScalarNode) -> Any:
    loader = yaml.SafeLoader("")
    try:
        return loader.construct_object(node, deep=True)
    finally:
        loader.dispose()


# --------------------------------------------------------------------------------------------
# Typed field readers: each raises a located StationError.


def _get(doc: _Doc, obj: Any, path: Path_, key: str, required: bool = True) -> Any:
    if not isinstance(obj, dict):
        raise doc.error(path, f"expected a mapping, got {_kind(obj)}")
    if key not in obj:
        if required:
            raise doc.error(path, f"missing required key '{key}'")
        return None
    return obj[key]


def _kind(value: Any) -> str:
    return type(value).__name__ if value is not None else "nothing"


def _number(doc: _Doc, value: Any, path: Path_) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise doc.error(path, f"expected a finite number, got {value!r}")
    return float(value)


def _positive(doc: _Doc, value: Any, path: Path_) -> float:
    number = _number(doc, value, path)
    if number <= 0:
        raise doc.error(path, f"expected a positive number, got {value!r}")
    return number


def _numbers(doc: _Doc, value: Any, path: Path_, count: int) -> np.ndarray:
    if not isinstance(value, list) or len(value) != count:
        raise doc.error(path, f"expected a list of {count} numbers, got {value!r}")
    return np.array([_number(doc, v, (*path, i)) for i, v in enumerate(value)])


def _integer(doc: _Doc, value: Any, path: Path_, minimum: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise doc.error(path, f"expected a whole number, got {value!r}")
    if minimum is not None and value < minimum:
        raise doc.error(path, f"expected a whole number >= {minimum}, got {value!r}")
    return value


def _string(doc: _Doc, value: Any, path: Path_) -> str:
    if not isinstance(value, str) or not value:
        raise doc.error(path, f"expected a non-empty text, got {value!r}")
    return value


def _list(doc: _Doc, value: Any, path: Path_) -> list[Any]:
    if value is None:
        return []
    if not isinstance(value, list):
        raise doc.error(path, f"expected a list, got {_kind(value)}")
    return value


def _check_keys(doc: _Doc, obj: Any, path: Path_, allowed: set[str]) -> None:
    if not isinstance(obj, dict):
        raise doc.error(path, f"expected a mapping, got {_kind(obj)}")
    for key in obj:
        if key not in allowed:
            raise doc.error(
                (*path, key), f"unknown key '{key}' (expected one of: {', '.join(sorted(allowed))})"
            )


def _file(doc: _Doc, value: Any, path: Path_) -> Path:
    """A file named relative to the YAML file; it must exist."""
    name = _string(doc, value, path)
    file = doc.folder / name
    if not file.is_file():
        raise doc.error(path, f"no such file: {name} (looked in {doc.folder})")
    return file


def _pose(doc: _Doc, value: Any, path: Path_) -> np.ndarray:
    """A pose from ``{xyz: mm, zyx: deg | quat: [w, x, y, z]}``; metres inside."""
    if value is None:
        return np.eye(4)
    _check_keys(doc, value, path, KEYS["pose"])
    xyz = value.get("xyz")
    position = _numbers(doc, xyz, (*path, "xyz"), 3) / 1000.0 if xyz is not None else np.zeros(3)
    if "zyx" in value and "quat" in value:
        raise doc.error(path, "give the rotation either as 'zyx' or as 'quat', not both")
    rotation = np.eye(3)
    if "zyx" in value:
        angles = np.radians(_numbers(doc, value["zyx"], (*path, "zyx"), 3))
        rotation = rotation_from_zyx(*angles)
    elif "quat" in value:
        rotation = _quat_to_rotation(doc, _numbers(doc, value["quat"], (*path, "quat"), 4), path)
    return pose_from(rotation, position)


def _quat_to_rotation(doc: _Doc, q: np.ndarray, path: Path_) -> np.ndarray:
    norm = float(np.linalg.norm(q))
    if not 0.99 < norm < 1.01:
        raise doc.error((*path, "quat"), f"quaternion must be unit length, its norm is {norm:.6g}")
    return rotation_from_quaternion(q)


# --------------------------------------------------------------------------------------------
# Shapes


def _shapes(doc: _Doc, value: Any, path: Path_, links: set[str] | None = None) -> tuple[Shape, ...]:
    """Shapes of a list; ``links`` (robot collision models): the allowed ``link`` names."""
    return tuple(
        _shape(doc, item, (*path, i), links) for i, item in enumerate(_list(doc, value, path))
    )


def _shape(doc: _Doc, value: Any, path: Path_, links: set[str] | None) -> Shape:
    _check_keys(doc, value, path, KEYS["shape"])
    kinds = [k for k in PRIMITIVE_KINDS if k in value]
    if len(kinds) != 1:
        raise doc.error(path, f"give exactly one of {', '.join(PRIMITIVE_KINDS)}; got {kinds}")
    kind = kinds[0]
    where: Path_ = (*path, kind)
    spec = value[kind]
    _check_keys(doc, spec, where, KEYS[kind])
    pose = _pose(doc, value.get("pose"), (*path, "pose"))
    link = _shape_link(doc, value, path, links)
    if kind == "mesh":
        units = spec.get("units", "mm")
        if units not in ("mm", "m"):
            raise doc.error((*where, "units"), f"expected 'mm' or 'm', got {units!r}")
        file = _file(doc, _get(doc, spec, where, "file"), (*where, "file"))
        scale = 0.001 if units == "mm" else 1.0
        return Shape("mesh", pose, mesh=str(file), scale=scale, link=link)
    if kind == "capsule":
        return _capsule(doc, spec, where, pose, link)
    sizes = {
        "box": lambda: tuple(_numbers(doc, _get(doc, spec, where, "size"), (*where, "size"), 3)),
        "cylinder": lambda: (_size(doc, spec, where, "radius"), _size(doc, spec, where, "length")),
        "sphere": lambda: (_size(doc, spec, where, "radius"),),
    }
    size = tuple(float(s) / 1000.0 for s in sizes[kind]())
    if any(s <= 0 for s in size):
        raise doc.error(where, f"sizes must be positive, got {[s * 1000 for s in size]}")
    return Shape(kind, pose, size=size, link=link)  # type: ignore[arg-type]


def _size(doc: _Doc, spec: Any, path: Path_, key: str) -> float:
    return _positive(doc, _get(doc, spec, path, key), (*path, key))


def _shape_link(doc: _Doc, value: Any, path: Path_, links: set[str] | None) -> str:
    if links is None:
        if "link" in value:
            raise doc.error((*path, "link"), "'link' is only for a robot's collision shapes")
        return ""
    link = _string(doc, _get(doc, value, path, "link"), (*path, "link"))
    if link not in links:
        raise doc.error(
            (*path, "link"), f"unknown link {link!r} (links: {', '.join(sorted(links))})"
        )
    return link


def _capsule(doc: _Doc, spec: Any, path: Path_, pose: np.ndarray, link: str) -> Shape:
    """A capsule around the segment from-to: its own pose has Z along the segment, centred."""
    start = _numbers(doc, _get(doc, spec, path, "from"), (*path, "from"), 3) / 1000.0
    end = _numbers(doc, _get(doc, spec, path, "to"), (*path, "to"), 3) / 1000.0
    radius = _size(doc, spec, path, "radius") / 1000.0
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


_LIMIT_KEYS = {
    "velocity": "velocity_deg_s",
    "acceleration": "acceleration_deg_s2",
    "jerk": "jerk_deg_s3",
}


def _limits(doc: _Doc, value: Any, path: Path_, base: JointLimits | None, dof: int) -> JointLimits:
    _check_keys(doc, value, path, KEYS["limits"])
    fields: dict[str, np.ndarray] = {}
    position = value.get("position_deg")
    if position is not None:
        if not isinstance(position, list) or len(position) != dof:
            raise doc.error(
                (*path, "position_deg"), f"expected {dof} pairs [lower, upper] in degrees"
            )
        pairs = np.radians(
            [_numbers(doc, p, (*path, "position_deg", i), 2) for i, p in enumerate(position)]
        )
        for i, (lo, hi) in enumerate(pairs):
            if lo >= hi:
                raise doc.error((*path, "position_deg", i), "lower limit must be below upper limit")
        fields["lower"], fields["upper"] = pairs[:, 0], pairs[:, 1]
    for name, key in _LIMIT_KEYS.items():
        if key in value:
            values = np.radians(_numbers(doc, value[key], (*path, key), dof))
            if np.any(values <= 0):
                raise doc.error((*path, key), "limits must be positive")
            fields[name] = values
    names = ("lower", "upper", "velocity", "acceleration", "jerk")
    if base is None:
        missing = [n for n in names if n not in fields]
        if missing:
            raise doc.error(path, f"missing limits: {', '.join(missing)}")
        return JointLimits(**fields)
    return JointLimits(**{n: fields.get(n, getattr(base, n)) for n in names})


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


def load_robot_model(path: str | Path) -> RobotModel:
    """Read a robot library file (``stations/robots/<vendor>/<model>.yaml``)."""
    doc = _read_yaml(Path(path))
    _check_keys(doc, doc.value, (), KEYS["model"])
    return _model(doc, doc.value, ())


def _model(doc: _Doc, value: dict[str, Any], path: Path_) -> RobotModel:
    """A robot model from the library keys of ``value`` (a library file or an inline robot)."""
    vendor = _get(doc, value, path, "vendor")
    if vendor not in vendors.KNOWN:
        raise doc.error(
            (*path, "vendor"), f"unknown vendor {vendor!r} (known: {', '.join(vendors.KNOWN)})"
        )
    limits_value = _get(doc, value, path, "limits")
    home_value = _get(doc, value, path, "home_deg")
    kin_path: Path_ = (*path, "kinematics")
    kinematics, links = _kinematics(doc, _get(doc, value, path, "kinematics"), kin_path)
    dof = kinematics.dof
    limits = _limits(doc, limits_value, (*path, "limits"), None, dof)
    home = np.radians(_numbers(doc, home_value, (*path, "home_deg"), dof))
    if np.any(limits.violations(home)):
        raise doc.error((*path, "home_deg"), "home position lies outside the joint limits")
    if isinstance(kinematics, ChainKinematics):
        seeds = default_seeds(home, limits.lower, limits.upper)
        kinematics = ChainKinematics(kinematics.model, seeds, kinematics.coupling)
    sources = tuple(str(s) for s in _list(doc, value.get("sources"), (*path, "sources")))
    return RobotModel(
        name=str(value.get("name") or "robot"),
        vendor=str(vendor),
        kinematics=kinematics,
        limits=limits,
        home=home,
        controller_base=_pose(doc, value.get("controller_base"), (*path, "controller_base")),
        collision=_shapes(doc, value.get("collision"), (*path, "collision"), links),
        sources=sources,
        allowed_pairs=_pairs(doc, value.get("allowed_pairs"), (*path, "allowed_pairs"), links),
    )


def _kinematics(doc: _Doc, value: Any, path: Path_) -> tuple[Kinematics, set[str]]:
    """The kinematics and the names of the links collision shapes may attach to."""
    _check_keys(doc, value, path, KEYS["kinematics"])
    kind = _get(doc, value, path, "type")
    readers: dict[str, Callable[[_Doc, Any, Path_], tuple[Kinematics, set[str]]]] = {
        "opw": _opw,
        "ur": _ur,
        "dh": _dh,
        "urdf": _urdf,
    }
    if kind not in readers:
        raise doc.error(
            (*path, "type"),
            f"unsupported kinematics type {kind!r} (expected one of: opw, ur, dh, urdf)",
        )
    expected = {
        "opw": {*OPW_KEYS, "offsets_deg", "signs"},
        "ur": set(UR_KEYS),
        "dh": {"rows"},
        "urdf": {"file", "tip", "base"},
    }[kind] | {"type", "coupling"}
    for key in value:
        if key not in expected:
            raise doc.error((*path, key), f"'{key}' does not belong to kinematics of type {kind!r}")
    return readers[kind](doc, value, path)


def _chain_links(dof: int) -> set[str]:
    return {"base", *(f"link_{i}" for i in range(1, dof + 1))}


def _coupling(doc: _Doc, value: Any, path: Path_, dof: int) -> JointCoupling:
    terms = []
    for i, item in enumerate(_list(doc, value.get("coupling"), (*path, "coupling"))):
        where: Path_ = (*path, "coupling", i)
        _check_keys(doc, item, where, KEYS["coupling"])
        joint = _integer(doc, _get(doc, item, where, "joint"), (*where, "joint"), 1)
        source = _integer(doc, _get(doc, item, where, "from"), (*where, "from"), 1)
        factor = _integer(doc, item.get("factor", 1), (*where, "factor"))
        if joint > dof or source > dof or joint == source:
            raise doc.error(where, f"joints must be two different numbers in 1..{dof}")
        terms.append((joint - 1, source - 1, factor))
    try:
        return JointCoupling.from_terms(dof, terms)
    except ValueError as exc:
        raise doc.error((*path, "coupling"), str(exc)) from exc


def _lengths(doc: _Doc, value: Any, path: Path_, keys: tuple[str, ...]) -> dict[str, float]:
    return {k: _number(doc, _get(doc, value, path, k), (*path, k)) / 1000.0 for k in keys}


def _opw(doc: _Doc, value: Any, path: Path_) -> tuple[Kinematics, set[str]]:
    lengths = _lengths(doc, value, path, OPW_KEYS)
    offsets = np.radians(
        _numbers(doc, _get(doc, value, path, "offsets_deg"), (*path, "offsets_deg"), 6)
    )
    signs = _numbers(doc, _get(doc, value, path, "signs"), (*path, "signs"), 6)
    if not np.all(np.abs(signs) == 1):
        raise doc.error((*path, "signs"), f"signs must each be 1 or -1, got {signs.tolist()}")
    try:
        params = OPWParameters(
            **lengths, offsets=tuple(offsets.tolist()), signs=tuple(int(s) for s in signs)
        )
    except ValueError as exc:
        raise doc.error(path, str(exc)) from exc
    return OPWKinematics(params, _coupling(doc, value, path, 6)), _chain_links(6)


def _ur(doc: _Doc, value: Any, path: Path_) -> tuple[Kinematics, set[str]]:
    if "coupling" in value:
        raise doc.error((*path, "coupling"), "UR arms have no joint coupling")
    try:
        params = URParameters(**_lengths(doc, value, path, UR_KEYS))
    except ValueError as exc:
        raise doc.error(path, str(exc)) from exc
    return URKinematics(params), _chain_links(6)


def _dh(doc: _Doc, value: Any, path: Path_) -> tuple[Kinematics, set[str]]:
    rows_path: Path_ = (*path, "rows")
    rows = _list(doc, _get(doc, value, path, "rows"), rows_path)
    if not rows:
        raise doc.error(rows_path, "a DH table needs at least one row")
    table = []
    for i, row in enumerate(rows):
        where: Path_ = (*rows_path, i)
        _check_keys(doc, row, where, KEYS["dh_row"])
        table.append(
            (
                _number(doc, _get(doc, row, where, "a"), (*where, "a")) / 1000.0,
                math.radians(
                    _number(doc, _get(doc, row, where, "alpha_deg"), (*where, "alpha_deg"))
                ),
                _number(doc, _get(doc, row, where, "d"), (*where, "d")) / 1000.0,
                math.radians(_number(doc, row.get("theta_deg", 0), (*where, "theta_deg"))),
            )
        )
    from olp.kinematics.pinocchio_model import build_dh_model

    a, alpha, d, theta = (np.array(c) for c in zip(*table, strict=True))
    model = build_dh_model(a, alpha, d, theta)
    coupling = _coupling(doc, value, path, len(table))
    chain = ChainKinematics(model, np.zeros((1, len(table))), coupling, "dh")
    return chain, _chain_links(len(table))


def _urdf(doc: _Doc, value: Any, path: Path_) -> tuple[Kinematics, set[str]]:
    file = _file(doc, _get(doc, value, path, "file"), (*path, "file"))
    tip = _string(doc, _get(doc, value, path, "tip"), (*path, "tip"))
    base = value.get("base")
    from olp.kinematics.pinocchio_model import ChainError, load_urdf_model

    try:
        model = load_urdf_model(str(file), tip, None if base is None else str(base))
    except ChainError as exc:
        key = "base" if base is not None and str(base) in str(exc) else "tip"
        raise doc.error((*path, key), str(exc)) from exc
    except (ValueError, RuntimeError) as exc:  # pinocchio's errors for an unreadable file
        raise doc.error((*path, "file"), f"cannot read URDF {file.name}: {exc}") from exc
    coupling = _coupling(doc, value, path, model.nq)
    chain = ChainKinematics(model, np.zeros((1, model.nq)), coupling, f"urdf {file.name}")
    import pinocchio as pin

    links = {"base", *(f.name for f in model.frames if f.type == pin.FrameType.BODY)}
    return chain, links


def robot_library() -> list[str]:
    """Names of the bundled robot models, e.g. ``kuka/kr6_r900_sixx``."""
    root = data_path("stations", "robots")
    return sorted(str(p.relative_to(root).with_suffix("")) for p in root.glob("*/*.yaml"))


def load_library_robot(name: str) -> RobotModel:
    """A bundled robot model by name (see :func:`robot_library`); KeyError if unknown."""
    bundled = data_path("stations", "robots", *f"{name}.yaml".split("/"))
    if not bundled.is_file():
        raise KeyError(f"unknown robot model {name!r} (bundled: {', '.join(robot_library())})")
    return load_robot_model(bundled)


# --------------------------------------------------------------------------------------------
# Stations


def load_station(path: str | Path) -> Station:
    """Load a station YAML file. Raises :class:`StationError` with file:line:col on mistakes."""
    path = Path(path)
    doc = _read_yaml(path)
    top = doc.value
    _check_keys(doc, top, (), KEYS["station"])
    robot = _station_robot(doc, _get(doc, top, (), "robot"), ("robot",), path)
    tools, bodies = _tools(doc, _list(doc, top.get("tools"), ("tools",)), ("tools",))
    frames, parents = _frames(doc, _list(doc, top.get("frames"), ("frames",)), ("frames",))
    seen: set[str] = set()
    objects = (
        *_objects(doc, top.get("parts"), ("parts",), "part", frames, seen),
        *_objects(doc, top.get("fixtures"), ("fixtures",), "fixture", frames, seen),
    )
    names = {"base", *(s.link for s in robot.collision), *tools, *seen}
    return Station(
        name=str(top.get("name") or path.stem),
        robot=robot,
        tools=tools,
        frames=frames,
        source=str(path),
        tool_bodies=bodies,
        frame_parents=parents,
        objects=objects,
        allowed_pairs=_pairs(doc, top.get("allowed_pairs"), ("allowed_pairs",), names),
    )


def _pairs(doc: _Doc, value: Any, path: Path_, names: set[str]) -> tuple[tuple[str, str], ...]:
    """``allowed_pairs``: a list of [name, name], each one of ``names``."""
    out = []
    for i, pair in enumerate(_list(doc, value, path)):
        if not isinstance(pair, list) or len(pair) != 2 or pair[0] == pair[1]:
            raise doc.error((*path, i), f"expected two different names [A, B], got {pair!r}")
        for k, name in enumerate(pair):
            if not isinstance(name, str) or name not in names:
                known = ", ".join(sorted(names))
                raise doc.error((*path, i, k), f"unknown body {name!r} (known: {known})")
        out.append((str(pair[0]), str(pair[1])))
    return tuple(out)


def _station_robot(doc: _Doc, value: Any, path: Path_, station_path: Path) -> Robot:
    _check_keys(doc, value, path, KEYS["robot"])
    if "model" not in value:
        model = _model(doc, value, path)
        return model.place(_pose(doc, value.get("base"), (*path, "base")))
    extra = set(value) - {"model", "base", "home_deg", "limits"}
    if extra:
        key = sorted(extra)[0]
        raise doc.error(
            (*path, key),
            f"'{key}' belongs to an inline robot; with 'model' give only base, home_deg and limits",
        )
    model_name = _get(doc, value, path, "model")
    model_file = _find_model(str(model_name), station_path)
    if model_file is None:
        known = ", ".join(robot_library())
        raise doc.error((*path, "model"), f"unknown robot model {model_name!r} (bundled: {known})")
    model = load_robot_model(model_file)
    limits = model.limits
    if "limits" in value:
        limits = _limits(
            doc, value["limits"], (*path, "limits"), model.limits, model.kinematics.dof
        )
    home = model.home
    if "home_deg" in value:
        home = np.radians(
            _numbers(doc, value["home_deg"], (*path, "home_deg"), model.kinematics.dof)
        )
    if np.any(limits.violations(home)):
        raise doc.error((*path, "home_deg"), "home position lies outside the joint limits")
    return model.place(_pose(doc, value.get("base"), (*path, "base")), limits=limits, home=home)


def _find_model(name: str, station_path: Path) -> Path | None:
    """A model file next to the station (``my_robot.yaml``) or in the bundled library."""
    if name.endswith((".yaml", ".yml")):
        local = station_path.parent / name
        return local if local.is_file() else None
    bundled = data_path("stations", "robots", *f"{name}.yaml".split("/"))
    return bundled if bundled.is_file() else None


def _name_number(doc: _Doc, item: Any, where: Path_) -> tuple[str, int | None]:
    name = _get(doc, item, where, "name")
    if not isinstance(name, str) or not name:
        raise doc.error((*where, "name"), f"expected a non-empty name, got {name!r}")
    number = item.get("number")
    if number is not None:
        number = _integer(doc, number, (*where, "number"), 0)
    return name, number


def _tools(doc: _Doc, items: list[Any], path: Path_) -> tuple[dict[str, Tool], dict[str, ToolBody]]:
    tools: dict[str, Tool] = {}
    bodies: dict[str, ToolBody] = {}
    for i, item in enumerate(items):
        where: Path_ = (*path, i)
        _check_keys(doc, item, where, KEYS["tool"])
        name, number = _name_number(doc, item, where)
        if name in tools:
            raise doc.error((*where, "name"), f"duplicate name {name!r}")
        tools[name] = Tool(
            name=name, pose=_pose(doc, item.get("tcp"), (*where, "tcp")), number=number
        )
        mass = item.get("mass_kg")
        bodies[name] = ToolBody(
            mass=None if mass is None else _positive(doc, mass, (*where, "mass_kg")),
            shapes=_shapes(doc, item.get("geometry"), (*where, "geometry")),
        )
    return tools, bodies


def _frames(doc: _Doc, items: list[Any], path: Path_) -> tuple[dict[str, Frame], dict[str, str]]:
    """Frames with their world poses; a ``parent`` chains a frame to another (any order)."""
    local: dict[str, tuple[np.ndarray, int | None, Path_]] = {}
    parents: dict[str, str] = {}
    for i, item in enumerate(items):
        where: Path_ = (*path, i)
        _check_keys(doc, item, where, KEYS["frame"])
        name, number = _name_number(doc, item, where)
        if name in local:
            raise doc.error((*where, "name"), f"duplicate name {name!r}")
        local[name] = (_pose(doc, item.get("pose"), (*where, "pose")), number, where)
        if "parent" in item:
            parents[name] = _string(doc, item["parent"], (*where, "parent"))
    for name, parent in parents.items():
        if parent != "world" and parent not in local:
            raise doc.error(
                (*local[name][2], "parent"),
                f"unknown parent frame {parent!r} (frames: {', '.join(local)})",
            )
    world: dict[str, np.ndarray] = {}
    for name in local:
        world[name] = _world_pose(doc, name, local, parents, world, ())
    frames = {n: Frame(name=n, pose=world[n], number=local[n][1]) for n in local}
    return frames, {n: parents.get(n, "world") for n in local}


def _world_pose(
    doc: _Doc,
    name: str,
    local: dict[str, tuple[np.ndarray, int | None, Path_]],
    parents: dict[str, str],
    done: dict[str, np.ndarray],
    chain: tuple[str, ...],
) -> np.ndarray:
    if name in done:
        return done[name]
    if name in chain:
        cycle = " -> ".join((*chain[chain.index(name) :], name))
        raise doc.error((*local[name][2], "parent"), f"frame parents form a cycle: {cycle}")
    parent = parents.get(name, "world")
    above = (
        np.eye(4)
        if parent == "world"
        else _world_pose(doc, parent, local, parents, done, (*chain, name))
    )
    done[name] = above @ local[name][0]
    return done[name]


def _objects(
    doc: _Doc, value: Any, path: Path_, kind: str, frames: dict[str, Frame], seen: set[str]
) -> list[StationObject]:
    """Parts or fixtures placed in the world; names unique across both (``seen``)."""
    out = []
    for i, item in enumerate(_list(doc, value, path)):
        where: Path_ = (*path, i)
        _check_keys(doc, item, where, KEYS["object"])
        name = _string(doc, _get(doc, item, where, "name"), (*where, "name"))
        if name in seen:
            raise doc.error((*where, "name"), f"duplicate part or fixture name {name!r}")
        seen.add(name)
        frame = str(item.get("frame", "world"))
        if frame != "world" and frame not in frames:
            raise doc.error(
                (*where, "frame"),
                f"unknown frame {frame!r} (frames: {', '.join(frames) or 'none'})",
            )
        above = np.eye(4) if frame == "world" else frames[frame].pose
        assert above is not None
        shapes = _shapes(doc, _get(doc, item, where, "geometry"), (*where, "geometry"))
        if not shapes:
            raise doc.error((*where, "geometry"), f"a {kind} needs at least one shape")
        pose = above @ _pose(doc, item.get("pose"), (*where, "pose"))
        out.append(StationObject(name, kind, pose, shapes, frame))  # type: ignore[arg-type]
    return out
