"""CSV frontend: jobs 3 and 4, layout detection, Euler conventions, located errors, streaming,
bounded memory and fuzzing."""

from __future__ import annotations

import math
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from olp import ir
from olp.errors import OlpError, ParseError, UsageError
from olp.frontends.csv import (
    CsvOptions,
    CsvResult,
    load_csv,
    open_csv,
    parse_csv,
    rotations_from_euler,
)
from olp.geometry import inv
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
DOWN = (180.0, 0.0, 180.0)


@pytest.fixture(scope="module")
def station() -> Station:
    return load_station(CELL)


def parse(text: str | bytes, station: Station | None = None, **options: object) -> CsvResult:
    if "orientation" not in options and station is None:
        options["orientation"] = DOWN
    return parse_csv(text, "t.csv", CsvOptions(**options), station)  # type: ignore[arg-type]


def positions(result: CsvResult) -> np.ndarray:
    return np.array([pose_of(m)[:3, 3] for m in result.program.motions()])


def pose_of(move: ir.Instruction) -> np.ndarray:
    assert isinstance(move, ir.JointMove | ir.LinearMove)
    assert isinstance(move.target, ir.CartesianTarget)
    return move.target.pose


def parse_error(text: str | bytes, **options: object) -> ParseError:
    with pytest.raises(ParseError) as info:
        parse(text, **options)
    return info.value


# ------------------------------------------------------------------------------------------------
# Layout detection: delimiter, decimal separator, header rows, units


DETECT = [
    # text, delimiter, decimal, header rows, length unit, first row in metres
    ("1,2,3\n", ",", ".", 0, "mm", (0.001, 0.002, 0.003)),
    ("1;2;3\n", ";", ".", 0, "mm", (0.001, 0.002, 0.003)),
    ("1\t2\t3\n", "\t", ".", 0, "mm", (0.001, 0.002, 0.003)),
    ("1|2|3\n", "|", ".", 0, "mm", (0.001, 0.002, 0.003)),
    ("  1   2  3  \n", None, ".", 0, "mm", (0.001, 0.002, 0.003)),
    ("1,5;2,5;-3,5\n", ";", ",", 0, "mm", (0.0015, 0.0025, -0.0035)),
    ("1,5\t2\t3\n", "\t", ",", 0, "mm", (0.0015, 0.002, 0.003)),
    ("x,y,z\n1,2,3\n", ",", ".", 1, "mm", (0.001, 0.002, 0.003)),
    ("Path 7b\nx [m],y [m],z [m]\n1,2,3\n", ",", ".", 2, "m", (1.0, 2.0, 3.0)),
    ("\ufeffx (in);y (in);z (in)\r\n1;2;3\r\n", ";", ".", 1, "in", (0.0254, 0.0508, 0.0762)),
    ("# made by CAM\n\n  \n1e2,+2.5,.5\n", ",", ".", 0, "mm", (0.1, 0.0025, 0.0005)),
    ("x_mm y_mm z_mm\n9 0 0\n", None, ".", 1, "mm", (0.009, 0.0, 0.0)),
]


@pytest.mark.parametrize(("text", "delimiter", "decimal", "headers", "unit", "first"), DETECT)
def test_layout_is_detected(
    text: str,
    delimiter: str | None,
    decimal: str,
    headers: int,
    unit: str,
    first: tuple[float, ...],
) -> None:
    result = parse(text)
    layout = result.layout
    assert (layout.delimiter, layout.decimal, layout.header_rows) == (delimiter, decimal, headers)
    assert layout.length_unit == unit and layout.columns == ("x", "y", "z")
    # Exact: 9 mm is 0.009 m, not 0.009000000000000001.
    assert positions(result)[0].tolist() == pytest.approx(first, rel=1e-15, abs=0)
    assert len(result.ignored) == headers
    assert all(item.reason == "header row" for item in result.ignored)


def test_given_options_override_detection() -> None:
    result = parse("1;2;3\n", delimiter=";", decimal=".", units="m", header=0)
    assert positions(result)[0].tolist() == [1.0, 2.0, 3.0]
    result = parse("x y z\n1 2 3\n", delimiter=" ", header=1)
    assert positions(result)[0].tolist() == [0.001, 0.002, 0.003]


def test_speed_units_from_the_header() -> None:
    per_min = parse("x,y,z,F [mm/min]\n0,0,0,600\n1,0,0,1200\n")
    assert [m.speed.linear for m in per_min.program.motions()] == [0.01, 0.02]
    assert per_min.layout.speed_unit == "mm/min"
    per_s = parse("x [m],y [m],z [m],speed [m/s]\n0,0,0,0.5\n")
    assert next(per_s.program.motions()).speed.linear == 0.5


def test_units_that_contradict_the_header_are_errors() -> None:
    error = parse_error("x [m],y [m],z [m]\n1,2,3\n", units="mm")
    assert (error.span.line, error.span.column) == (1, 1)  # type: ignore[union-attr]
    assert "header gives lengths in 'm' but the options say 'mm'" in error.message
    error = parse_error("x (m);y (m);z (mm)\n1;2;3\n")
    assert error.span.column == 13 and "earlier column is in 'm'" in error.message  # type: ignore[union-attr]
    error = parse_error("x [deg],y,z\n1,2,3\n")
    assert "'deg' is not a length unit" in error.message


def test_angle_units_in_radians() -> None:
    result = parse("x,y,z,a [rad],b [rad],c [rad]\n0,0,0,3.141592653589793,0,0\n", orientation=None)
    assert result.layout.angle_unit == "rad"
    assert np.allclose(pose_of(result.program.instructions[0])[:3, :3], np.diag([1, -1, -1]))


# ------------------------------------------------------------------------------------------------
# Euler conventions (job 4: Z -> Y' -> X'' by default)

SEQUENCES = [a + b + c for a in "xyz" for b in "xyz" for c in "xyz" if a != b != c]


@pytest.mark.parametrize("sequence", SEQUENCES + [s.upper() for s in SEQUENCES])
def test_euler_sequences_match_scipy(sequence: str) -> None:
    angles = np.random.default_rng(len(sequence) + sum(map(ord, sequence))).uniform(
        -180, 180, (50, 3)
    )
    expected = Rotation.from_euler(sequence, angles, degrees=True).as_matrix()
    assert np.allclose(rotations_from_euler(sequence, np.radians(angles)), expected, atol=1e-12)


def test_default_reads_wpr_like_robodk_import_csv_xyzwpr() -> None:
    # RoboDK's ImportCSV_XYZWPR example: transl(x, y, z) * rotz(rz) * roty(ry) * rotx(rx).
    w, p, r = 10.0, -20.0, 30.0
    result = parse(f"1,2,3,{w},{p},{r},7\n", orientation=None)
    c, s = np.cos, np.sin
    rx, ry, rz = np.radians([w, p, r])
    rot_x = np.array([[1, 0, 0], [0, c(rx), -s(rx)], [0, s(rx), c(rx)]])
    rot_y = np.array([[c(ry), 0, s(ry)], [0, 1, 0], [-s(ry), 0, c(ry)]])
    rot_z = np.array([[c(rz), -s(rz), 0], [s(rz), c(rz), 0], [0, 0, 1]])
    pose = pose_of(result.program.instructions[0])
    assert np.allclose(pose[:3, :3], rot_z @ rot_y @ rot_x, atol=1e-15)
    assert pose[:3, 3].tolist() == [0.001, 0.002, 0.003]
    abc = parse(f"1,2,3,{r},{p},{w},7\n", orientation=None, euler="abc")
    assert np.allclose(pose_of(abc.program.instructions[0]), pose, atol=1e-15)


@pytest.mark.parametrize("bad", ["xy", "xxz", "xYz", "abcd", "uvw", ""])
def test_bad_euler_sequences_are_usage_errors(bad: str) -> None:
    with pytest.raises(UsageError, match="Euler sequence"):
        CsvOptions(euler=bad)


# ------------------------------------------------------------------------------------------------
# Job 3: XYZ (+ speed)


JOB3 = """x,y,z,speed
0,0,100,250
# plunge
0,0,6.35,20

276.225,0,6.35,21.17
276.225,323.85,6.35,21.17
0,0,106.35,250
"""


def test_job3_moves_speeds_spans_and_zones() -> None:
    result = parse(JOB3, zone=2.0)
    moves = list(result.program.motions())
    assert [m.kind for m in moves] == ["joint"] + ["linear"] * 4
    assert [m.span.line for m in moves] == [2, 4, 6, 7, 8]
    assert [m.span.end_column for m in moves] == [len(line) + 1 for line in (
        "0,0,100,250", "0,0,6.35,20", "276.225,0,6.35,21.17", "276.225,323.85,6.35,21.17",
        "0,0,106.35,250",
    )]  # fmt: skip
    # Every row keeps its exact speed (mm/s -> m/s by division).
    assert [m.speed.linear for m in moves] == [0.25, 0.02, 0.02117, 0.02117, 0.25]
    # The rows after the first are one dense toolpath node: arrays, no object per row.
    first, path = result.program.instructions
    assert isinstance(first, ir.JointMove) and isinstance(path, ir.LinearPath)
    assert path.speeds.tolist() == [0.02, 0.02117, 0.02117, 0.25] and len(result.program) == 5
    # The joint move and the last move stop exactly; the linear moves between are rounded.
    assert [m.zone.radius for m in moves] == [0.0, 0.002, 0.002, 0.002, 0.0]
    assert result.program.name == "t" and result.program.source == "t.csv"


def test_job3_orientation_defaults_to_the_home_tcp_in_the_frame(station: Station) -> None:
    result = parse("0,0,0\n100,0,0\n", station, frame="table")
    spindle, table = station.tools["spindle"], station.frames["table"]
    assert spindle.pose is not None and table.pose is not None
    home_tcp = station.robot.flange_poses(station.robot.home) @ spindle.pose
    expected = (inv(table.pose) @ home_tcp)[:3, :3]
    for move in result.program.motions():
        assert np.allclose(pose_of(move)[:3, :3], expected, atol=1e-12)
        assert move.tool is spindle and move.frame is table


def test_given_orientation_uses_the_euler_convention() -> None:
    wpr = parse("0,0,0\n", orientation=(90.0, 0.0, 0.0))
    assert np.allclose(
        pose_of(wpr.program.instructions[0])[:3, :3], [[1, 0, 0], [0, 0, -1], [0, 1, 0]]
    )
    abc = parse("0,0,0\n", orientation=(90.0, 0.0, 0.0), euler="ZYX")
    assert np.allclose(
        pose_of(abc.program.instructions[0])[:3, :3], [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    )


def test_tool_and_frame_defaults_and_names(station: Station) -> None:
    default = parse("0,0,0\n", station, orientation=DOWN).program.instructions[0]
    assert isinstance(default, ir.JointMove)
    assert default.tool is station.tools["spindle"] and default.frame is ir.WORLD
    flange = parse("0,0,0\n", station, orientation=DOWN, tool="flange").program.instructions[0]
    assert flange.tool is ir.FLANGE  # type: ignore[union-attr]
    with pytest.raises(
        UsageError, match=r"tool 'torch' is not in the station \(tools: flange, spindle\)"
    ):
        parse("0,0,0\n", station, tool="torch")
    with pytest.raises(UsageError, match=r"frames: world, table"):
        parse("0,0,0\n", station, frame="pallet")
    # Without a station, names are references the resolve pass looks up.
    ref = parse("0,0,0\n", tool="spindle", frame="table").program.instructions[0]
    assert ref.tool == ir.Tool(name="spindle") and ref.frame == ir.Frame(name="table")  # type: ignore[union-attr]


def test_xyz_without_station_or_orientation_is_a_usage_error() -> None:
    with pytest.raises(UsageError, match="home position"):
        parse_csv("0,0,0\n", "t.csv")
    with pytest.raises(UsageError, match="orientation option is for XYZ files"):
        parse("1,2,3,0,0,0\n", orientation=DOWN)


def test_default_speed_option() -> None:
    assert next(parse("0,0,0\n").program.motions()).speed == ir.Speed()
    assert next(parse("0,0,0\n", speed=40.0).program.motions()).speed.linear == 0.04


# ------------------------------------------------------------------------------------------------
# Job 4: XYZWPR (+ index)


def test_job4_index_names_the_targets() -> None:
    result = parse("x,y,z,w,p,r,id\n0,0,0,180,0,0,10\n1,0,0,180,0,0,-3\n", orientation=None)
    names = [m.target.name for m in result.program.motions()]
    assert names == ["10", "-3"]
    assert result.layout.columns[-1] == "index"


def test_job4_example_reports_and_skips_by_line(station: Station) -> None:
    from olp.api import compile
    from olp.passes.resolve import ResolveOptions

    result = load_csv(REPO / "examples" / "targets_xyzwpr.csv", CsvOptions(frame="table"), station)
    far = [m for m in result.program.motions() if m.target.name == "40"]
    assert len(far) == 1 and far[0].span.line == 9
    strict = compile(result.program, station)
    assert [(d.severity, d.span.line) for d in strict.diagnostics if d.span] == [("error", 9)]
    lenient = compile(result.program, station, ResolveOptions(skip_unreachable=True))
    assert lenient.ok and [d.span.line for d in lenient.diagnostics if d.span] == [9]


# ------------------------------------------------------------------------------------------------
# Located errors

ERRORS = [
    # text, line, column, message
    ("1,2,3\n4,x,6\n", 2, 3, "column 'y': expected a number, found 'x'"),
    ("1,2,3\n4, 1_000 ,6\n", 2, 4, "column 'y': expected a number, found '1_000'"),
    ("1,2,3\n4,5\n", 2, 4, "expected 3 columns (x, y, z), found 2: 1 cell missing at the end"),
    (
        "1,2,3\n4,5,6,7\n",
        2,
        7,
        "expected 3 columns (x, y, z), found 4: the first extra cell is '7'",
    ),
    ("1,2,3\n4,,6\n", 2, 3, "column 'y': expected a number, found nothing"),
    ("1,2,3\nnan,5,6\n", 2, 1, "column 'x': expected a finite number, found 'nan'"),
    ("1,2,3\n1,-inf,6\n", 2, 3, "column 'y': expected a finite number, found '-inf'"),
    ("1,2,3\n1,2,1e400\n", 2, 5, "column 'z': expected a finite number, found '1e400'"),
    ("1,2,3,10\n1,2,3,-5\n", 2, 7, "column 'speed': expected a finite speed > 0, found '-5'"),
    ("1,2,3,10\n1,2,3,0\n", 2, 7, "column 'speed': expected a finite speed > 0, found '0'"),
    ("1,2,3,10\n1,2,3,5e-324\n", 2, 7, "expected a finite speed > 0, found '5e-324'"),
    ("1,2,3,4,5,6,7\n1,2,3,4,5,6,7.5\n", 2, 13, "column 'index': expected an integer"),
    ("1,2,3\n4,5,6\r7,8,9\n", 2, 9, "expected 3 columns (x, y, z), found 5"),
    ("1,2,3\n4,5,6\x00\n", 2, 5, "column 'z': expected a number, found '6\\x00'"),
    ("1,2,3\n4,5,6e\n", 2, 5, "found '6e'"),
    ("1,2,3\n4,5,\u0663\n", 2, 5, "found '\u0663'"),
    ("1,2,3\nx,y,z\n", 2, 1, "column 'x': expected a number, found 'x'"),
    ("", 1, 1, "the CSV file is empty"),
    ("\n\n# only comments\n", 3, 1, "no data rows found"),
    ("x,y,z\n", 1, 1, "no data rows after the header rows"),
    ("1,2,3,4,5\n", 1, 1, "found 5 columns; expected 3 (x, y, z)"),
    ("1 ; 2 , 3\n", 1, 1, "cannot read the first data row as numbers"),
]


@pytest.mark.parametrize(("text", "line", "column", "message"), ERRORS)
def test_errors_are_located(
    station: Station, text: str, line: int, column: int, message: str
) -> None:
    with pytest.raises(ParseError) as info:
        parse(text, station)
    error = info.value
    assert error.span is not None and error.span.file == "t.csv"
    assert (error.span.line, error.span.column) == (line, column)
    assert message in error.message
    lines = text.split("\n")
    if line <= len(lines) and lines[line - 1].strip():
        assert error.source_line == lines[line - 1].rstrip("\r").split("\r")[0] or "\r" in text
        assert "^" in error.format()


def test_utf16_files_are_rejected_with_a_hint() -> None:
    error = parse_error("1,2,3\n".encode("utf-16"))
    assert "UTF-16" in error.message and error.hint and "UTF-8" in error.hint


def test_errors_in_later_blocks_keep_their_line() -> None:
    rows = [f"{i},{i},{i}" for i in range(1, 60)]
    rows[49] = "50,5O,50"
    text = "x,y,z\n" + "\n".join(rows) + "\n"
    error = parse_error(text, chunk_bytes=16)
    assert (error.span.line, error.span.column) == (51, 4)  # type: ignore[union-attr]
    assert error.source_line == "50,5O,50"


def test_unreadable_file_is_a_usage_error(tmp_path: Path) -> None:
    with pytest.raises(UsageError, match="cannot read CSV file"):
        load_csv(tmp_path / "missing.csv")


# ------------------------------------------------------------------------------------------------
# Streaming: block size never changes the result; memory follows the block size

ROW_VALUES = st.floats(-1e6, 1e6, allow_nan=False).map(lambda v: round(v, 3))
SEPARATORS = st.sampled_from(["\n", "\r\n"])


@given(
    rows=st.lists(st.tuples(ROW_VALUES, ROW_VALUES, ROW_VALUES), min_size=1, max_size=30),
    extras=st.lists(st.sampled_from(["", "# note", "   "]), max_size=30),
    newline=SEPARATORS,
    delimiter=st.sampled_from([",", ";", "\t", " "]),
    chunk=st.integers(1, 200),
)
@settings(max_examples=150, deadline=None)
def test_any_block_size_reads_the_same_values_and_lines(
    rows: list[tuple[float, float, float]],
    extras: list[str],
    newline: str,
    delimiter: str,
    chunk: int,
) -> None:
    lines, expected_lines = [], []
    for i, row in enumerate(rows):
        if i < len(extras) and i > 0:
            lines.append(extras[i])
        lines.append(delimiter.join(repr(v) for v in row))
        expected_lines.append(len(lines))
    text = newline.join(lines) + newline
    result = parse(text, chunk_bytes=chunk)
    moves = list(result.program.motions())
    assert [m.span.line for m in moves] == expected_lines
    assert positions(result).tolist() == [[v / 1000.0 for v in row] for row in rows]


def _stream_peak(path: Path, rows: int) -> int:
    """Write ``rows`` XYZ+speed rows to ``path``; the traced peak memory of streaming them."""
    data = np.random.default_rng(rows).uniform(-500, 500, (rows, 4))
    data[:, 3] = np.abs(data[:, 3]) + 1
    np.savetxt(path, data, fmt="%.4f", delimiter=",", header="x,y,z,speed", comments="")
    count = 0
    tracemalloc.start()
    with open_csv(path, CsvOptions(chunk_bytes=1 << 16)) as stream:
        for chunk in stream:
            count += chunk.values.shape[0]
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert count == rows
    return peak


def test_streaming_memory_is_bounded_by_the_block(tmp_path: Path) -> None:
    small = _stream_peak(tmp_path / "small.csv", 10_000)
    large = _stream_peak(tmp_path / "large.csv", 100_000)
    # Ten times the rows, (nearly) the same peak: memory follows the 64 kB block, not the
    # 3.7 MB file (reading the whole file at once would need several times its size).
    assert large < 1.3 * small, (small, large)
    assert large < (tmp_path / "large.csv").stat().st_size / 4


# ------------------------------------------------------------------------------------------------
# Fuzzing: only located OlpErrors may escape

FUZZ = settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
SEEDS = [
    (REPO / "examples" / "path_xyz.csv").read_text(),
    (REPO / "examples" / "targets_xyzwpr.csv").read_text(),
]
NASTY = [
    "nan", "inf", "-1e400", "1e308", "1e-320", "\u00e9", "\u0663", "\x00", ";", ",", "\r", "\n",
    "#", " ", "\t", "1,5", "\ufeff", '"1"',
]  # fmt: skip


def _check_escape(data: bytes | str, station: Station) -> None:
    try:
        parse_csv(data, "fuzz.csv", None, station)
    except OlpError as exc:
        assert isinstance(exc, ParseError), exc
        assert exc.span is not None and exc.span.line >= 1 and exc.span.column >= 1
        exc.format()


@given(st.binary(max_size=300))
@FUZZ
def test_fuzz_random_bytes(station: Station, data: bytes) -> None:
    _check_escape(data, station)


@given(st.data())
@FUZZ
def test_fuzz_mutated_valid_files(station: Station, data: st.DataObject) -> None:
    text = data.draw(st.sampled_from(SEEDS))
    for _ in range(data.draw(st.integers(1, 6))):
        at = data.draw(st.integers(0, len(text)))
        cut = data.draw(st.integers(0, 4))
        insert = data.draw(st.sampled_from(NASTY) | st.text(max_size=3))
        text = text[:at] + insert + text[at + cut :]
    _check_escape(text, station)


EXTREME = st.floats(allow_nan=True, allow_infinity=True) | st.integers(-(10**400), 10**400)


@given(st.lists(EXTREME, min_size=3, max_size=7))
@FUZZ
def test_fuzz_extreme_numbers(station: Station, values: list[float]) -> None:
    _check_escape(",".join(str(v) for v in values) + "\n", station)


def test_huge_but_finite_values_lower_without_overflow() -> None:
    result = parse("1e308,0,0,1e308,1e308,-1e308\n", orientation=None)
    pose = pose_of(result.program.instructions[0])
    assert pose[0, 3] == 1e305 and np.all(np.isfinite(pose))
    assert math.isclose(abs(np.linalg.det(pose[:3, :3])), 1.0, rel_tol=1e-9)
