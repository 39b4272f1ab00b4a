"""The station file format as a JSON Schema (draft 2020-12): what ``olp schema station`` prints.

Editors that understand JSON Schema (VS Code's YAML extension, JetBrains IDEs) complete and check
station files with it: save the output and point the editor at it (e.g. a first line
``# yaml-language-server: $schema=station.schema.json``). The loader
(:mod:`olp.station.loader`) takes the allowed keys of every mapping from here, so the two cannot
drift apart; it also checks what a schema cannot (known robot models, files that exist, joint
counts, frame parents, limits that hold the home position) and names the line of each mistake.

Units in the file: millimetres and degrees (as on vendor datasheets); kilograms for masses.
"""

from __future__ import annotations

import json
from typing import Any

_NUMBER = {"type": "number"}
_XYZ = {"type": "array", "items": _NUMBER, "minItems": 3, "maxItems": 3}


def _numbers(description: str, count: int | None = None) -> dict[str, Any]:
    out: dict[str, Any] = {"type": "array", "items": _NUMBER, "description": description}
    if count is not None:
        out.update(minItems=count, maxItems=count)
    return out


def _object(props: dict[str, Any], required: tuple[str, ...] = (), **extra: Any) -> dict[str, Any]:
    out: dict[str, Any] = {"type": "object", "properties": props, "additionalProperties": False}
    if required:
        out["required"] = list(required)
    out.update(extra)
    return out


def _ref(name: str) -> dict[str, str]:
    return {"$ref": f"#/$defs/{name}"}


_POSE = _object(
    {
        "xyz": {**_XYZ, "description": "position, mm"},
        "zyx": {**_XYZ, "description": "rotation Rz(a)·Ry(b)·Rx(c), degrees (KUKA A, B, C)"},
        "quat": _numbers("rotation as a unit quaternion [w, x, y, z]", 4),
    },
    description="A pose: position in mm and an optional rotation (zyx or quat, not both).",
)
_POSE["not"] = {"required": ["zyx", "quat"]}

_PRIMITIVES: dict[str, Any] = {
    "box": _object({"size": {**_XYZ, "description": "edge lengths, mm"}}, ("size",)),
    "cylinder": _object(
        {"radius": _NUMBER, "length": _NUMBER},
        ("radius", "length"),
        description="along Z of its pose, centred; mm",
    ),
    "sphere": _object({"radius": _NUMBER}, ("radius",), description="mm"),
    "capsule": _object(
        {"from": _XYZ, "to": _XYZ, "radius": _NUMBER},
        ("from", "to", "radius"),
        description="the points within radius of the segment from-to, mm (in its pose's frame)",
    ),
    "mesh": _object(
        {
            "file": {
                "type": "string",
                "description": "STL/OBJ/PLY/GLB (at most 64 MiB), relative to this file and "
                "inside its folder (see allow_outside_paths); not flat: its convex hull collides",
            },
            "units": {"enum": ["mm", "m"], "description": "units of the file (default mm)"},
        },
        ("file",),
    ),
}

_SHAPE = _object(
    {
        **_PRIMITIVES,
        "pose": _ref("pose"),
        "link": {"type": "string", "description": "robot collision only: the link it moves with"},
    },
    description="Exactly one of box, cylinder, sphere, capsule or mesh, placed by pose.",
    oneOf=[{"required": [kind]} for kind in _PRIMITIVES],
)

_LIMITS = _object(
    {
        "position_deg": {
            "type": "array",
            "items": _numbers("[lower, upper], degrees", 2),
            "description": "per joint [lower, upper] in the controller's convention, degrees",
        },
        "velocity_deg_s": _numbers("per joint, deg/s"),
        "acceleration_deg_s2": _numbers("per joint, deg/s²"),
        "jerk_deg_s3": _numbers("per joint, deg/s³"),
        "path_acceleration_m_s2": {
            "type": "number",
            "exclusiveMinimum": 0,
            "description": "the controller's own TCP path acceleration, m/s², for path moves "
            "whose program sets none (KUKA $ACC.CP's default; not for UR arms, whose script "
            "states a= on every movel); olp time --calibrate fits it",
        },
    },
    description="Joint limits; in a station they override the model's joint by joint list.",
)

OPW_KEYS: tuple[str, ...] = ("a1", "a2", "b", "c1", "c2", "c3", "c4")
UR_KEYS: tuple[str, ...] = ("d1", "a2", "a3", "d4", "d5", "d6")

_COUPLING: dict[str, Any] = {
    "type": "array",
    "description": "model joint += factor × controller joint (Fanuc: joint 3 from 2, factor 1)",
    "items": _object(
        {
            "joint": {"type": "integer", "minimum": 1},
            "from": {"type": "integer", "minimum": 1},
            "factor": {"type": "integer"},
        },
        ("joint", "from"),
    ),
}

_KINEMATICS = _object(
    {
        "type": {"enum": ["opw", "ur", "dh", "urdf"]},
        **{k: {**_NUMBER, "description": "OPW (a2: or UR DH) length, mm"} for k in OPW_KEYS},
        **{k: {**_NUMBER, "description": "UR DH length, mm"} for k in UR_KEYS if k != "a2"},
        "offsets_deg": _numbers("OPW: theta_model = q·sign - offset, degrees", 6),
        "signs": {"type": "array", "items": {"enum": [1, -1]}, "minItems": 6, "maxItems": 6},
        "rows": {
            "type": "array",
            "description": "DH: standard (distal) DH rows; joint value adds to theta",
            "items": _object(
                {"a": _NUMBER, "alpha_deg": _NUMBER, "d": _NUMBER, "theta_deg": _NUMBER},
                ("a", "alpha_deg", "d"),
            ),
        },
        "file": {
            "type": "string",
            "description": "URDF: file, relative to this file and inside its folder",
        },
        "tip": {"type": "string", "description": "URDF: the flange link (tool0)"},
        "base": {"type": "string", "description": "URDF: the base link (default: the root)"},
        "coupling": _COUPLING,
    },
    ("type",),
    description="opw: a1 a2 b c1 c2 c3 c4 offsets_deg signs; ur: d1 a2 a3 d4 d5 d6; "
    "dh: rows; urdf: file tip [base].",
)

_PAIRS: dict[str, Any] = {
    "type": "array",
    "description": "pairs of bodies never checked against each other (they touch by design)",
    "items": {
        "type": "array",
        "items": {"type": "string", "minLength": 1},
        "minItems": 2,
        "maxItems": 2,
    },
}

_MODEL_PROPS: dict[str, Any] = {
    "name": {"type": "string"},
    "vendor": {"enum": ["kuka", "abb", "fanuc", "ur"]},
    "sources": {"type": "array", "items": {"type": "string"}},
    "kinematics": _KINEMATICS,
    "limits": _LIMITS,
    "home_deg": _numbers("home joints, degrees"),
    "controller_base": {
        **_ref("pose"),
        "description": "the controller's robot base frame in the mounting frame",
    },
    "collision": {"type": "array", "items": _ref("shape")},
    "allowed_pairs": {**_PAIRS, "description": "link pairs whose shapes overlap in every position"},
}

ROBOT_MODEL = _object(
    _MODEL_PROPS,
    ("name", "vendor", "kinematics", "limits", "home_deg"),
    description="A robot library file (stations/robots/<vendor>/<model>.yaml).",
)

_STATION_ROBOT = _object(
    {
        "model": {
            "type": "string",
            "description": "library name (vendor/model) or a .yaml file inside this file's folder",
        },
        "base": _ref("pose"),
        **_MODEL_PROPS,
    },
    description="Either model (plus base, home_deg, limits overrides) or a whole inline model.",
    oneOf=[
        {
            "required": ["model"],
            "propertyNames": {"enum": ["model", "base", "home_deg", "limits"]},
        },
        {
            "required": ["kinematics", "vendor", "limits", "home_deg"],
            "not": {"required": ["model"]},
        },
    ],
)

_NAME = {"type": "string", "minLength": 1}
_NUMBER_ID = {"type": "integer", "minimum": 0}

_TOOL = _object(
    {
        "name": _NAME,
        "number": _NUMBER_ID,
        "description": {"type": "string"},
        "tcp": _ref("pose"),
        "mass_kg": {"type": "number", "exclusiveMinimum": 0},
        "geometry": {"type": "array", "items": _ref("shape")},
    },
    ("name",),
    description="A tool: its TCP in the flange frame, optional mass and geometry.",
)

_FRAME = _object(
    {
        "name": _NAME,
        "number": _NUMBER_ID,
        "description": {"type": "string"},
        "pose": _ref("pose"),
        "parent": {"type": "string", "description": "the frame this pose is given in"},
    },
    ("name",),
    description="A user frame / work object: pose in its parent frame (default world).",
)

_OBJECT = _object(
    {
        "name": _NAME,
        "description": {"type": "string"},
        "frame": {"type": "string", "description": "station frame the pose is given in"},
        "pose": _ref("pose"),
        "geometry": {"type": "array", "items": _ref("shape"), "minItems": 1},
    },
    ("name", "geometry"),
)

_TARGET = _object(
    {
        "name": _NAME,
        "description": {"type": "string"},
        "frame": {"type": "string", "description": "station frame the pose is given in"},
        "pose": {**_ref("pose"), "description": "the TCP in the frame (any tool), mm and deg"},
        "joints_deg": _numbers("controller joints, degrees"),
    },
    ("name",),
    description="A named target: a Cartesian pose in a frame, or joints (exactly one).",
    oneOf=[{"required": ["pose"]}, {"required": ["joints_deg"]}],
)

STATION: dict[str, Any] = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "olp station",
    "description": "A robot cell for olp. Lengths in mm, angles in degrees, masses in kg.",
    **_object(
        {
            "name": {"type": "string"},
            "description": {"type": "string"},
            "allow_outside_paths": {
                "type": "boolean",
                "default": False,
                "description": "true: files this station names (meshes, a robot file, a URDF) "
                "may lie outside its folder (absolute paths, '..', symbolic links out of it). "
                "Default false: such a file is an error. /proc, /sys, /dev, devices and FIFOs "
                "are never read either way.",
            },
            "robot": _STATION_ROBOT,
            "tools": {"type": "array", "items": _ref("tool")},
            "frames": {"type": "array", "items": _ref("frame")},
            "parts": {"type": "array", "items": _ref("object")},
            "fixtures": {"type": "array", "items": _ref("object")},
            "targets": {"type": "array", "items": _ref("target")},
            "allowed_pairs": {**_PAIRS, "description": "links, tools, parts that may touch"},
        },
        ("robot",),
    ),
    "$defs": {
        "pose": _POSE,
        "shape": _SHAPE,
        "tool": _TOOL,
        "frame": _FRAME,
        "object": _OBJECT,
        "target": _TARGET,
        "robot_model": ROBOT_MODEL,
    },
}
"""The JSON Schema of a station file."""


def keys(schema: dict[str, Any]) -> set[str]:
    """The keys a mapping described by ``schema`` may hold."""
    return set(schema["properties"])


KEYS: dict[str, set[str]] = {
    "station": keys(STATION),
    "robot": keys(_STATION_ROBOT),
    "model": keys(ROBOT_MODEL),
    "kinematics": keys(_KINEMATICS),
    "limits": keys(_LIMITS),
    "pose": keys(_POSE),
    "shape": keys(_SHAPE),
    "tool": keys(_TOOL),
    "frame": keys(_FRAME),
    "object": keys(_OBJECT),
    "target": keys(_TARGET),
    "coupling": keys(_COUPLING["items"]),
    "dh_row": keys(_KINEMATICS["properties"]["rows"]["items"]),
    **{kind: keys(schema) for kind, schema in _PRIMITIVES.items()},
}
"""Allowed keys per kind of mapping, for the loader."""

PRIMITIVE_KINDS: tuple[str, ...] = tuple(_PRIMITIVES)


def station_schema_json() -> str:
    """The station JSON Schema as indented JSON text (deterministic key order)."""
    return json.dumps(STATION, indent=2, ensure_ascii=False) + "\n"
