"""Load a station from YAML (mm and degrees, as on vendor datasheets) into SI values.

Every mistake is a :class:`~olp.errors.StationError` naming the file, line, column and key.

Station file::

    name: kr6_milling
    robot:
      model: kuka/kr6_r900_sixx        # stations/robots/<vendor>/<model>.yaml
      base: {xyz: [0, 0, 0], zyx: [0, 0, 0]}
      home_deg: [0, -90, 90, 0, 0, 0]  # optional, else the model's
    tools:
      - {name: spindle, number: 1, tcp: {xyz: [466.6, -4.2, 109.6], zyx: [0, 90, 0]}}
    frames:
      - {name: table, number: 1, pose: {xyz: [0, -1000, 0]}}

A pose is ``{xyz: [x, y, z]}`` in mm with an optional rotation, either ``zyx: [a, b, c]`` in
degrees meaning ``Rz(a)·Ry(b)·Rx(c)`` (the order of KUKA's A, B, C) or ``quat: [w, x, y, z]``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import yaml

from olp import vendors
from olp.errors import StationError, line_of
from olp.geometry import pose_from, rotation_from_zyx
from olp.ir import Frame, SourceSpan, Tool
from olp.kinematics.opw import OPWParameters
from olp.resources import data_path
from olp.station.model import JointLimits, Robot, Station

Path_ = tuple[str | int, ...]


@dataclass(frozen=True, slots=True)
class _Doc:
    """A parsed YAML document with the source position of every key path."""

    value: Any
    marks: dict[Path_, tuple[int, int]]
    file: str
    text: str

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


def _numbers(doc: _Doc, value: Any, path: Path_, count: int) -> np.ndarray:
    if not isinstance(value, list) or len(value) != count:
        raise doc.error(path, f"expected a list of {count} numbers, got {value!r}")
    return np.array([_number(doc, v, (*path, i)) for i, v in enumerate(value)])


def _check_keys(doc: _Doc, obj: Any, path: Path_, allowed: set[str]) -> None:
    if not isinstance(obj, dict):
        raise doc.error(path, f"expected a mapping, got {_kind(obj)}")
    for key in obj:
        if key not in allowed:
            raise doc.error(
                (*path, key), f"unknown key '{key}' (expected one of: {', '.join(sorted(allowed))})"
            )


def _pose(doc: _Doc, value: Any, path: Path_) -> np.ndarray:
    """A pose from ``{xyz: mm, zyx: deg | quat: [w, x, y, z]}``; metres inside."""
    if value is None:
        return np.eye(4)
    _check_keys(doc, value, path, {"xyz", "zyx", "quat"})
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
    w, x, y, z = q / norm
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


# --------------------------------------------------------------------------------------------
# Robot library entries


_OPW_KEYS = ("a1", "a2", "b", "c1", "c2", "c3", "c4")


def _opw(doc: _Doc, value: Any, path: Path_) -> OPWParameters:
    _check_keys(doc, value, path, {"type", *_OPW_KEYS, "offsets_deg", "signs"})
    kind = _get(doc, value, path, "type")
    if kind != "opw":
        raise doc.error((*path, "type"), f"unsupported kinematics type {kind!r} (expected 'opw')")
    lengths = {k: _number(doc, _get(doc, value, path, k), (*path, k)) / 1000.0 for k in _OPW_KEYS}
    offsets = np.radians(
        _numbers(doc, _get(doc, value, path, "offsets_deg"), (*path, "offsets_deg"), 6)
    )
    signs = _numbers(doc, _get(doc, value, path, "signs"), (*path, "signs"), 6)
    if not np.all(np.abs(signs) == 1):
        raise doc.error((*path, "signs"), f"signs must each be 1 or -1, got {signs.tolist()}")
    return OPWParameters(
        **lengths, offsets=tuple(offsets.tolist()), signs=tuple(int(s) for s in signs)
    )


_LIMIT_KEYS = {
    "velocity": "velocity_deg_s",
    "acceleration": "acceleration_deg_s2",
    "jerk": "jerk_deg_s3",
}


def _limits(doc: _Doc, value: Any, path: Path_, base: JointLimits | None) -> JointLimits:
    _check_keys(doc, value, path, {"position_deg", *_LIMIT_KEYS.values()})
    fields: dict[str, np.ndarray] = {}
    position = value.get("position_deg")
    if position is not None:
        if not isinstance(position, list) or len(position) != 6:
            raise doc.error((*path, "position_deg"), "expected 6 pairs [lower, upper] in degrees")
        pairs = np.radians(
            [_numbers(doc, p, (*path, "position_deg", i), 2) for i, p in enumerate(position)]
        )
        for i, (lo, hi) in enumerate(pairs):
            if lo >= hi:
                raise doc.error((*path, "position_deg", i), "lower limit must be below upper limit")
        fields["lower"], fields["upper"] = pairs[:, 0], pairs[:, 1]
    for name, key in _LIMIT_KEYS.items():
        if key in value:
            values = np.radians(_numbers(doc, value[key], (*path, key), 6))
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
    """A robot library entry (before placement in a station)."""

    name: str
    vendor: str
    kinematics: OPWParameters
    limits: JointLimits
    home: np.ndarray


def load_robot_model(path: Path) -> RobotModel:
    """Read a robot library file (``stations/robots/<vendor>/<model>.yaml``)."""
    doc = _read_yaml(path)
    top = doc.value
    _check_keys(doc, top, (), {"name", "vendor", "kinematics", "limits", "home_deg", "sources"})
    vendor = str(_get(doc, top, (), "vendor"))
    if vendor not in vendors.KNOWN:
        raise doc.error(
            ("vendor",), f"unknown vendor {vendor!r} (known: {', '.join(vendors.KNOWN)})"
        )
    return RobotModel(
        name=str(_get(doc, top, (), "name")),
        vendor=vendor,
        kinematics=_opw(doc, _get(doc, top, (), "kinematics"), ("kinematics",)),
        limits=_limits(doc, _get(doc, top, (), "limits"), ("limits",), None),
        home=np.radians(_numbers(doc, _get(doc, top, (), "home_deg"), ("home_deg",), 6)),
    )


def robot_library() -> list[str]:
    """Names of the bundled robot models, e.g. ``kuka/kr6_r900_sixx``."""
    root = data_path("stations", "robots")
    return sorted(str(p.relative_to(root).with_suffix("")) for p in root.glob("*/*.yaml"))


# --------------------------------------------------------------------------------------------
# Stations


def load_station(path: str | Path) -> Station:
    """Load a station YAML file. Raises :class:`StationError` with file:line:col on mistakes."""
    path = Path(path)
    doc = _read_yaml(path)
    top = doc.value
    _check_keys(doc, top, (), {"name", "robot", "tools", "frames", "description"})
    robot = _station_robot(doc, _get(doc, top, (), "robot"), ("robot",), path)
    tools = _named(
        doc,
        top.get("tools") or [],
        ("tools",),
        "tcp",
        lambda n, p, k: Tool(name=n, pose=p, number=k),
    )
    frames = _named(
        doc,
        top.get("frames") or [],
        ("frames",),
        "pose",
        lambda n, p, k: Frame(name=n, pose=p, number=k),
    )
    name = str(top.get("name") or path.stem)
    return Station(name=name, robot=robot, tools=tools, frames=frames, source=str(path))


def _station_robot(doc: _Doc, value: Any, path: Path_, station_path: Path) -> Robot:
    _check_keys(doc, value, path, {"model", "base", "home_deg", "limits"})
    model_name = _get(doc, value, path, "model")
    model_file = _find_model(str(model_name), station_path)
    if model_file is None:
        known = ", ".join(robot_library())
        raise doc.error((*path, "model"), f"unknown robot model {model_name!r} (bundled: {known})")
    model = load_robot_model(model_file)
    limits = model.limits
    if "limits" in value:
        limits = _limits(doc, value["limits"], (*path, "limits"), model.limits)
    home = model.home
    if "home_deg" in value:
        home = np.radians(_numbers(doc, value["home_deg"], (*path, "home_deg"), 6))
    if np.any(limits.violations(home)):
        raise doc.error((*path, "home_deg"), "home position lies outside the joint limits")
    return Robot(
        name=model.name,
        vendor=model.vendor,
        kinematics=model.kinematics,
        limits=limits,
        home=home,
        base=_pose(doc, value.get("base"), (*path, "base")),
        flange_in_tool0=vendors.flange_in_tool0(model.vendor),
    )


def _find_model(name: str, station_path: Path) -> Path | None:
    """A model file next to the station (``my_robot.yaml``) or in the bundled library."""
    if name.endswith((".yaml", ".yml")):
        local = station_path.parent / name
        return local if local.is_file() else None
    bundled = data_path("stations", "robots", *f"{name}.yaml".split("/"))
    return bundled if bundled.is_file() else None


_T = TypeVar("_T", Tool, Frame)


def _named(
    doc: _Doc,
    items: Any,
    path: Path_,
    pose_key: str,
    make: Callable[[str, np.ndarray, int | None], _T],
) -> dict[str, _T]:
    if not isinstance(items, list):
        raise doc.error(path, f"expected a list, got {_kind(items)}")
    out: dict[str, _T] = {}
    for i, item in enumerate(items):
        where: Path_ = (*path, i)
        _check_keys(doc, item, where, {"name", "number", pose_key, "description"})
        name = _get(doc, item, where, "name")
        if not isinstance(name, str) or not name:
            raise doc.error((*where, "name"), f"expected a non-empty name, got {name!r}")
        if name in out:
            raise doc.error((*where, "name"), f"duplicate name {name!r}")
        number = item.get("number")
        if number is not None and (
            isinstance(number, bool) or not isinstance(number, int) or number < 0
        ):
            raise doc.error((*where, "number"), f"expected a whole number >= 0, got {number!r}")
        out[name] = make(name, _pose(doc, item.get(pose_key), (*where, pose_key)), number)
    return out
