"""Careless or hostile station input is a located StationError, never a traceback, a hang or a
silently different station (issue 10, items 8, 9 and 14).

The tables are data only, to be lifted into one bad-input table across stations, programs and
the command line: ``BAD_STATIONS`` rows are (id, station text, line, message fragment);
``BAD_STATION_FILES`` rows add the files beside the station (name -> content, see
:func:`_make`). Every row fails on the main branch before issue 10: there it loads (a
different station than written), raises something else, or names the mistake differently.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from olp.cli import main
from olp.errors import StationError
from olp.station.loader import load_station

REPO = Path(__file__).resolve().parents[2]
ROBOT = "robot:\n  model: kuka/kr6_r900_sixx\n"
TOOL = ROBOT + "tools:\n  - {name: t, mass_kg: %s}\n"
INLINE = (
    "robot:\n"
    "  vendor: {vendor}\n"
    "  kinematics: {{type: opw, a1: 25, a2: -35, b: 0, c1: 400, c2: 455, c3: 420, c4: 80,\n"
    "    offsets_deg: [0, -90, 0, 0, 0, 0], signs: {signs}{extra}}}\n"
    "  limits:\n"
    "    position_deg: [[-170, 170], [-190, 45], [-120, 156], [-185, 185], [-120, 120],\n"
    "      [-350, 350]]\n"
    "    velocity_deg_s: [360, 300, 360, 381, 388, 615]\n"
    "    acceleration_deg_s2: [900, 750, 900, 952.5, 970, 1537.5]\n"
    "    jerk_deg_s3: [9000, 7500, 9000, 9525, 9700, 15375]\n"
    "  home_deg: [0, -90, 90, 0, 0, 0]\n"
)


def _inline(vendor: str = "kuka", signs: str = "[-1, 1, 1, -1, 1, -1]", extra: str = "") -> str:
    return INLINE.format(vendor=vendor, signs=signs, extra=extra)


def _bomb(levels: int, width: int) -> str:
    """A billion-laughs document: level k holds ``width`` aliases of level k - 1."""
    lines = [ROBOT, "description:\n", f"  - &l0 [{', '.join(['lol'] * width)}]\n"]
    for k in range(1, levels):
        lines.append(f"  - &l{k} [{', '.join([f'*l{k - 1}'] * width)}]\n")
    return "".join(lines)


BAD_STATIONS: list[tuple[str, str | bytes, int, str]] = [
    # YAML itself (item 8)
    ("400-digit integer", TOOL % ("9" * 400), 4, "has more than 100 digits"),
    ("not UTF-8", ROBOT.encode() + b"name: \xff\xfe\n", 3, "not UTF-8 text: byte 0xFF"),
    ("control character", ROBOT + "name: a\x01b\n", 3, "character U+0001 (a control character)"),
    (
        "python tag",
        ROBOT + "name: !!python/name:os.system x\n",
        3,
        "unsupported tag !!python/name:os.system",
    ),
    ("unknown tag", ROBOT + "name: !foo x\n", 3, "unsupported tag !foo"),
    ("core tag on wrong text", TOOL % '!!int "abc"', 4, "'abc' is not a whole number (!!int)"),
    ("binary tag", ROBOT + "name: !!binary aGk=\n", 3, "unsupported tag !!binary"),
    ("set tag", ROBOT + "name: !!set {a}\n", 3, "unsupported tag !!set"),
    ("bare =", TOOL % "=", 4, "expected a number (a mass in kg), got text '='"),
    ("date-like value", TOOL % "2024-01-01", 4, "expected a number (a mass in kg), got text"),
    ("sexagesimal", TOOL % "1:30", 4, "got text '1:30'"),
    ("leading zero (octal in YAML 1.1)", ROBOT + "  base: {xyz: [0100, 0, 0]}\n", 3, "ambiguous"),
    ("recursive alias", ROBOT + "tools: &a\n  - *a\n", 4, "alias *a contains itself"),
    ("alias bomb", _bomb(8, 4), 11, "alias *l6 expands to more than 50000 values"),
    ("deep nesting", ROBOT + "name: " + "[" * 80 + "]" * 80 + "\n", 3, "nested more than 64"),
    ("undefined alias", ROBOT + "name: *nope\n", 3, "alias *nope names no anchor"),
    (
        "duplicate top-level key",
        ROBOT + "robot:\n  model: abb/irb120\n",
        3,
        "duplicate key 'robot' (first given at line 1)",
    ),
    ("duplicate nested key", ROBOT + "  base: {xyz: [0, 0, 0], xyz: [1, 0, 0]}\n", 3, "'xyz'"),
    ("duplicate key in a list item", ROBOT + "tools:\n  - name: a\n    name: b\n", 5, "'name'"),
    ("merge key", ROBOT + "  <<: {base: {}}\n", 3, "merge keys ('<<') are not supported"),
    ("complex key", ROBOT + "? [a, b]\n: 1\n", 3, "a key must be plain text, not '[a, b]'"),
    ("two documents", ROBOT + "---\n" + ROBOT, 3, "expected a single document"),
    ("syntax", "name: x\nrobot: [1, 2\n", 3, "invalid YAML"),
    # numbers: the user's text and what is wrong with it (item 14)
    ("1e308 mm", ROBOT + "  base: {xyz: [1e308, 0, 0]}\n", 3, "'1e308' is out of range for a len"),
    ("inf mm", ROBOT + "  base: {xyz: [.inf, 0, 0]}\n", 3, "expected a finite number (a length"),
    ("nan degrees", ROBOT + "  base: {zyx: [.nan, 0, 0]}\n", 3, "got '.nan'"),
    ("25-digit length", ROBOT + "  base: {xyz: [" + "9" * 25 + ", 0, 0]}\n", 3, "out of range"),
    ("huge quaternion", ROBOT + "  base: {quat: [1e300, 0, 0, 0]}\n", 3, "quaternion component"),
    ("quaternion not unit", ROBOT + "  base: {quat: [1, 1, 0, 0]}\n", 3, "unit length"),
    ("true as a number", ROBOT + "  base: {xyz: [true, 0, 0]}\n", 3, "got true/false 'true'"),
    ("list of 2 for 3", ROBOT + "  base: {xyz: [1, 2]}\n", 3, "got a list of 2 '[1, 2]'"),
    ("text for a list", ROBOT + "  base: {xyz: '1, 2, 3'}\n", 3, "got text"),
    ("home of wrong length", ROBOT + "  home_deg: [0, 0]\n", 3, "expected a list of 6 numbers"),
    ("zero mass", TOOL % "0", 4, "expected a positive number (a mass in kg), got '0'"),
    ("negative mass", TOOL % "-1", 4, "expected a positive number"),
    ("huge mass", TOOL % "1e9", 4, "'1e9' is out of range for a mass in kg"),
    ("tool number huge", ROBOT + "tools:\n  - {name: t, number: 1e3}\n", 4, "whole number"),
    (
        "tool number beyond a controller integer",
        ROBOT + "tools:\n  - {name: t, number: 99999999999999999999}\n",
        4,
        "out of range (expected 0 to 2147483647)",
    ),
    ("tool number negative", ROBOT + "tools:\n  - {name: t, number: -1}\n", 4, "out of range"),
    (
        "zero joint speed",
        ROBOT + "  limits:\n    velocity_deg_s: [0, 1, 1, 1, 1, 1]\n",
        4,
        "'0' is out of range for a joint speed in deg/s",
    ),
    (
        "absurd joint acceleration",
        ROBOT + "  limits:\n    acceleration_deg_s2: [1e12, 1, 1, 1, 1, 1]\n",
        4,
        "out of range for a joint acceleration",
    ),
    (
        "limit pair of three",
        ROBOT
        + "  limits:\n    position_deg: [[0, 1, 2], [0, 1], [0, 1], [0, 1], [0, 1], [0, 1]]\n",
        4,
        "expected a list of 2 numbers",
    ),
    ("limits as a list", ROBOT + "  limits: [1, 2]\n", 3, "expected a mapping, got a list"),
    ("zero sphere", ROBOT + "tools:\n  - {name: t, geometry: [{sphere: {radius: 0}}]}\n", 4, "pos"),
    (
        "huge box",
        ROBOT + "tools:\n  - {name: t, geometry: [{box: {size: [1, 1, 1e7]}}]}\n",
        4,
        "out of range for a size in mm",
    ),
    # wrong types and names
    ("robot as a list", "robot: [1, 2]\n", 1, "expected a mapping, got a list '[1, 2]'"),
    ("model as a list", "robot:\n  model: [kuka]\n", 2, "expected a non-empty text, got a list"),
    ("model out of the library", "robot:\n  model: kuka/../../x\n", 2, "unknown robot model"),
    ("station name a list", ROBOT + "name: [a]\n", 3, "expected a non-empty text, got a list"),
    ("tool name a number", ROBOT + "tools:\n  - {name: 5}\n", 4, "got a number '5'"),
    ("tool name with a newline", ROBOT + 'tools:\n  - {name: "a\\nLIN"}\n', 4, "U+000A"),
    ("tool name with a bidi override", ROBOT + 'tools:\n  - {name: "a\\u202eb"}\n', 4, "U+202E"),
    ("tool name too long", ROBOT + f"tools:\n  - {{name: {'x' * 101}}}\n", 4, "at most 100"),
    ("tools as a mapping", ROBOT + "tools: {name: t}\n", 3, "expected a list, got a mapping"),
    ("tool as text", ROBOT + "tools: [spindle]\n", 3, "expected a mapping, got text 'spindle'"),
    ("frame parent a list", ROBOT + "frames:\n  - {name: a, parent: [b]}\n", 4, "got a list"),
    (
        "part frame a list",
        ROBOT + "parts:\n  - {name: p, frame: [b], geometry: [{sphere: {radius: 1}}]}\n",
        4,
        "expected a non-empty text, got a list '[b]'",
    ),
    ("description a list", ROBOT + "description: [a]\n", 3, "expected a non-empty text"),
    ("shape without a kind", ROBOT + "tools:\n  - {name: t, geometry: [{}]}\n", 4, "got none"),
    (
        "mesh units cm",
        ROBOT + "parts:\n  - {name: p, geometry: [{mesh: {file: a.stl, units: cm}}]}\n",
        4,
        "expected 'mm' or 'm', got 'cm'",
    ),
    ("outside paths as yes", ROBOT + "allow_outside_paths: yes\n", 3, "expected true or false"),
    # inline robots
    ("vendor a list", _inline(vendor="[kuka]"), 2, "unknown vendor '[kuka]'"),
    (
        "kinematics type a list",
        _inline().replace("type: opw", "type: [opw]"),
        3,
        "unsupported kinematics type '[opw]'",
    ),
    ("signs of 2", _inline(signs="[1, 2, 1, 1, 1, 1]"), 4, "out of range (expected -1 to 1)"),
    ("signs text", _inline(signs="'+-++-+'"), 4, "expected six signs, each 1 or -1"),
    (
        "coupling factor beyond int64",
        _inline(extra=", coupling: [{joint: 3, from: 2, factor: 99999999999999999999}]"),
        4,
        "out of range (expected -100 to 100)",
    ),
    (
        "coupling joint beyond the arm",
        _inline(extra=", coupling: [{joint: 7, from: 2}]"),
        4,
        "out of range (expected 1 to 6)",
    ),
]


@pytest.mark.parametrize(
    ("text", "line", "fragment"),
    [row[1:] for row in BAD_STATIONS],
    ids=[row[0] for row in BAD_STATIONS],
)
def test_bad_station_is_a_located_error(
    tmp_path: Path, text: str | bytes, line: int, fragment: str
) -> None:
    path = tmp_path / "cell.yaml"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    with pytest.raises(StationError) as info:
        load_station(path)
    error = info.value
    assert fragment in error.message
    assert error.span is not None and (error.span.file, error.span.line) == (str(path), line)
    assert "Node(" not in error.message and "datetime" not in error.message


# --------------------------------------------------------------------------------------------
# Files a station names (item 9): meshes and URDFs inside the station's folder, read safely.

TETRA = "v 0 0 0\nv 100 0 0\nv 0 100 0\nv 0 0 100\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
FLAT = "v 0 0 0\nv 100 0 0\nv 0 100 0\nv 100 100 0\nf 1 2 3\nf 2 4 3\n"
FIFO, FOLDER, DEVNULL = "<fifo>", "<folder>", "<devnull>"


def _mesh_station(file: str, allow: bool = False) -> str:
    head = "allow_outside_paths: true\n" if allow else ""
    return head + ROBOT + f"fixtures:\n  - name: f\n    geometry:\n      - mesh: {{file: {file}}}\n"


URDF_CONTINUOUS = (
    "<robot name='r'><link name='a'/><link name='b'/>"
    "<joint name='j' type='continuous'><parent link='a'/><child link='b'/>"
    "<axis xyz='0 0 1'/></joint></robot>"
)
URDF_STATION = (
    "robot:\n  vendor: ur\n  kinematics: {type: urdf, file: %s, tip: b}\n"
    "  limits: {position_deg: [[-1, 1]], velocity_deg_s: [1], acceleration_deg_s2: [1],"
    " jerk_deg_s3: [1]}\n  home_deg: [0]\n"
)

BAD_STATION_FILES: list[tuple[str, str, dict[str, str], int, str]] = [
    ("mesh up and out", _mesh_station("../a.obj"), {"../a.obj": TETRA}, 6, "lies outside the"),
    (
        "mesh symlink out",
        _mesh_station("link.obj"),
        {"../a.obj": TETRA, "link.obj": "->../a.obj"},
        6,
        "lies outside the folder",
    ),
    ("mesh FIFO", _mesh_station("pipe.stl"), {"pipe.stl": FIFO}, 6, "not a regular file"),
    ("mesh folder", _mesh_station("dir.stl"), {"dir.stl": FOLDER}, 6, "a folder, not a file"),
    (
        "mesh device, even when outside paths are allowed",
        _mesh_station("null.stl", allow=True),
        {"null.stl": DEVNULL},
        7,
        "olp never reads /proc, /sys or /dev",
    ),
    ("mesh empty", _mesh_station("a.stl"), {"a.stl": ""}, 6, "the file is empty"),
    ("mesh not a mesh", _mesh_station("a.stl"), {"a.stl": "hello\n"}, 6, "no triangles"),
    (
        "mesh malformed",
        _mesh_station("a.obj"),
        {"a.obj": "v 0 0 0\nf 1 2 9\n"},
        6,
        "not a readable",
    ),
    ("mesh flat", _mesh_station("a.obj"), {"a.obj": FLAT}, 6, "it is flat"),
    ("mesh far away", _mesh_station("a.obj"), {"a.obj": TETRA.replace("100", "1e7")}, 6, "1e+04 m"),
    ("mesh of another type", _mesh_station("a.txt"), {"a.txt": TETRA}, 6, "unsupported mesh type"),
    ("mesh missing", _mesh_station("a.stl"), {}, 6, "no such file: a.stl"),
    ("URDF up and out", URDF_STATION % "../r.urdf", {"../r.urdf": "<robot/>"}, 3, "outside"),
    ("URDF continuous joint", URDF_STATION % "r.urdf", {"r.urdf": URDF_CONTINUOUS}, 3, "continu"),
    ("URDF FIFO", URDF_STATION % "r.urdf", {"r.urdf": FIFO}, 3, "not a regular file"),
    ("robot file up and out", "robot:\n  model: ../r.yaml\n", {"../r.yaml": "x: 1\n"}, 2, "outsid"),
]


def _make(folder: Path, files: dict[str, str]) -> None:
    """Files relative to ``folder``: text, ``->target`` (a symbolic link), FIFO, FOLDER or
    DEVNULL (a symbolic link to the null device)."""
    for name, content in files.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if content == FIFO:
            os.mkfifo(path)
        elif content == FOLDER:
            path.mkdir()
        elif content == DEVNULL:
            path.symlink_to(os.devnull)
        elif content.startswith("->"):
            path.symlink_to(content[2:])
        else:
            path.write_text(content, encoding="utf-8")


@pytest.mark.parametrize(
    ("text", "files", "line", "fragment"),
    [row[1:] for row in BAD_STATION_FILES],
    ids=[row[0] for row in BAD_STATION_FILES],
)
def test_bad_file_named_by_a_station_is_a_located_error(
    tmp_path: Path, text: str, files: dict[str, str], line: int, fragment: str
) -> None:
    folder = tmp_path / "cell"
    folder.mkdir()
    _make(folder, files)
    path = folder / "cell.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(StationError) as info:
        load_station(path)
    error = info.value
    assert fragment in error.message
    assert error.span is not None and (error.span.file, error.span.line) == (str(path), line)


def test_mesh_too_big_is_refused_before_reading(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr("olp.station.meshes.MAX_MESH_BYTES", len(TETRA) - 1)
    _make(tmp_path, {"a.obj": TETRA})
    path = tmp_path / "cell.yaml"
    path.write_text(_mesh_station("a.obj"), encoding="utf-8")
    with pytest.raises(StationError, match="larger than"):
        load_station(path)


def test_outside_paths_when_the_station_allows_them(tmp_path: Path) -> None:
    folder = tmp_path / "cell"
    folder.mkdir()
    _make(folder, {"../a.obj": TETRA, "link.obj": "->../a.obj"})
    for name in ("../a.obj", "link.obj", str(tmp_path / "a.obj")):
        path = folder / "cell.yaml"
        path.write_text(_mesh_station(name, allow=True), encoding="utf-8")
        (shape,) = load_station(path).objects[0].shapes
        assert shape.mesh == str((tmp_path / "a.obj").resolve())


def test_mesh_hull_is_read_once_at_load(tmp_path: Path) -> None:
    """The checked hull travels with the shape (metres), so collision checks need not read
    the file again; a symbolic link inside the folder is fine."""
    _make(tmp_path, {"meshes/a.obj": TETRA, "b.obj": "->meshes/a.obj"})
    path = tmp_path / "cell.yaml"
    path.write_text(_mesh_station("b.obj"), encoding="utf-8")
    (shape,) = load_station(path).objects[0].shapes
    assert shape.hull is not None
    assert shape.hull.vertices.shape == (4, 3) and shape.hull.faces.shape == (4, 3)
    assert shape.hull.vertices.max() == pytest.approx(0.1)  # 100 mm in the file
    assert not shape.hull.vertices.flags.writeable


def test_long_frame_chain_loads(tmp_path: Path) -> None:
    """Frame parents are followed in a loop: 3000 chained frames, each listed before its
    parent, do not overflow the stack."""
    frames = "".join(
        f"  - {{name: f{i}, parent: f{i - 1}, pose: {{xyz: [1, 0, 0]}}}}\n"
        for i in range(2999, 0, -1)
    )
    path = tmp_path / "cell.yaml"
    path.write_text(ROBOT + "frames:\n  - {name: f0}\n" + frames, encoding="utf-8")
    pose = load_station(path).frames["f2999"].pose
    assert pose is not None and pose[0, 3] == pytest.approx(2.999)


@pytest.mark.parametrize(
    ("row", "where"), [("duplicate top-level key", ":3:1:"), ("python tag", ":3:7:")]
)
def test_command_line_exits_2_with_the_location(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], row: str, where: str
) -> None:
    (text,) = [r[1] for r in BAD_STATIONS if r[0] == row]
    station = tmp_path / "cell.yaml"
    station.write_text(str(text), encoding="utf-8")
    program = str(REPO / "examples" / "milling.src")
    assert main(["check", str(station), program, "-q"]) == 2
    assert f"{station}{where} station error:" in capsys.readouterr().err
