"""CSV toolpaths from a careless or hostile user (issue 10, items 3 and 14): rows that do not
match their header, ragged rows, huge lines and cells, and text that made the reader's regular
expressions backtrack for minutes. Every one is a located ParseError with a bounded message."""

from __future__ import annotations

import signal
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from olp.errors import ParseError
from olp.frontends.csv import CsvOptions, parse_csv

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
DOWN = CsvOptions(orientation=(180.0, 0.0, 180.0))
MESSAGE_LIMIT = 300
"""No message or hint of a CSV error is longer than this, whatever the file holds."""


def error_of(data: str | bytes, options: CsvOptions = DOWN) -> ParseError:
    with pytest.raises(ParseError) as info:
        parse_csv(data, "t.csv", options)
    return info.value


@contextmanager
def finishes_within(seconds: float) -> Iterator[None]:
    """Fail (rather than hang for minutes) if the block takes longer than ``seconds``."""

    def expire(signum: int, frame: object) -> None:
        raise TimeoutError(f"took longer than {seconds} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


# ------------------------------------------------------------------------------------------------
# Item 3: rows against their header


HEADER_MISMATCH = [
    # text, line, column, message
    ("x,y,z\n400,5,0,500\n", 2, 9, "expected 3 cells like the header row on line 1"),
    ("x,y,z\n400,5,0,500\n", 2, 9, "found 4: the first extra cell is '500'"),
    ("x,y,z,speed\n400,5,0\n", 2, 8, "found 3: 1 cell missing at the end of the row"),
    ("x;y;z\n1;2;3;4\n", 2, 7, "the first extra cell is '4'"),
    ("x y z\n1  2  3  4\n", 2, 10, "the first extra cell is '4'"),
    ("x\ty\tz\ta\tb\tc\n1\t2\t3\t4\t5\t6\t7\n", 2, 13, "expected 6 cells"),
    ("Path 7b\nx [mm],y [mm],z [mm]\n1,2,3,40\n", 3, 7, "header row on line 2"),
    ("# CAM export\nx,y,z\n\n1,2,3,4\n", 4, 7, "3 cells like"),
]


@pytest.mark.parametrize(("text", "line", "column", "message"), HEADER_MISMATCH)
def test_rows_that_do_not_match_the_header_are_errors(
    text: str, line: int, column: int, message: str
) -> None:
    error = error_of(text)
    assert error.span is not None
    assert (error.span.line, error.span.column) == (line, column)
    assert message in error.message
    assert error.hint is not None and "header" in error.hint


MISNAMED = [
    # a header whose names say the file means something else: column, message
    ("x,y,z,rz\n1,2,3,4\n", 7, "the header names 'rz' (an angle) where olp reads a speed"),
    ("y,x,z\n1,2,3\n", 1, "names 'y' (the y coordinate) where olp reads the x coordinate"),
    ("a1,a2,a3,a4,a5,a6\n0,-90,90,0,0,0\n", 1, "names 'a1' (an angle) where olp reads the x"),
    ("x,y,z,i,j,k\n1,2,3,0,0,1\n", 7, "'i' (a tool direction vector component)"),
    ("x,y,z,qw,qx,qy,qz\n1,2,3,1,0,0,0\n", 7, "'qw' (a quaternion component)"),
    ("J1;J2;J3;J4;J5;J6\n0;-90;90;0;0;0\n", 1, "'J1' (a joint value)"),
    ("X [mm], Y [mm], Z [mm], ID\n1,2,3,4\n", 25, "'ID' (an index) where olp reads a speed"),
]


@pytest.mark.parametrize(("text", "column", "message"), MISNAMED)
def test_a_header_that_names_other_columns_is_an_error(
    text: str, column: int, message: str
) -> None:
    error = error_of(text, CsvOptions())
    assert error.span is not None and (error.span.line, error.span.column) == (1, column)
    assert message in error.message
    assert error.hint is not None and "reorder the columns" in error.hint


WELL_NAMED = [
    ("X [mm],Y [mm],Z [mm],F [mm/min]\n1,2,3,4\n", ("x", "y", "z", "speed")),
    ("x y z speed\n1 2 3 4\n", ("x", "y", "z", "speed")),
    ("X,Y,Z,W,P,R,ID\n1,2,3,4,5,6,7\n", ("x", "y", "z", "a1", "a2", "a3", "index")),
    ("x_mm;y_mm;z_mm;a;b;c\n1;2;3;4;5;6\n", ("x", "y", "z", "a1", "a2", "a3")),
    ("Pos X,Pos Y,Pos Z\n1,2,3\n", ("x", "y", "z")),
]


@pytest.mark.parametrize(("text", "columns"), WELL_NAMED)
def test_headers_that_name_olps_columns_are_read(text: str, columns: tuple[str, ...]) -> None:
    options = CsvOptions() if len(columns) >= 6 else DOWN
    assert parse_csv(text, "t.csv", options).layout.columns == columns


def test_a_title_row_above_the_data_is_not_a_header_of_columns() -> None:
    result = parse_csv("Toolpath\n1,2,3\n4,5,6\n", "t.csv", DOWN)
    assert len(result.program) == 2 and result.layout.columns == ("x", "y", "z")


def test_the_issue_file_is_refused_by_olp_build(tmp_path: Path) -> None:
    """``x,y,z`` over ``400,5,0,500`` built a move (500 read as a speed) with exit 0."""
    program = tmp_path / "rag.csv"
    program.write_text("x,y,z\n400,5,0,500\n400,50,0,500\n", encoding="ascii")
    done = subprocess.run(
        [sys.executable, "-m", "olp", "build", str(CELL), str(program), "-o", str(tmp_path / "o")],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert done.returncode == 2, done.stdout
    assert f"{program}:2:9: parse error: expected 3 cells like the header row" in done.stderr
    assert not (tmp_path / "o").exists()


RAGGED = [
    # a row whose cell count differs from the first data row's: line, column, message
    ("1,2,3\n4,5,6\n7,8,9,10\n", 3, 7, "found 4: the first extra cell is '10'"),
    ("1,2,3\n# note\n4,5\n", 3, 4, "found 2: 1 cell missing at the end of the row"),
    ("1 2 3\n4 5 6 7 8\n", 2, 7, "found 5: the first extra cell is '7'"),
    ("1,2,3,10\n1,2\n", 2, 4, "found 2: 2 cells missing at the end of the row"),
]


@pytest.mark.parametrize(("text", "line", "column", "message"), RAGGED)
def test_a_column_count_that_changes_is_an_error_at_the_cell(
    text: str, line: int, column: int, message: str
) -> None:
    error = error_of(text)
    assert error.span is not None
    assert (error.span.line, error.span.column) == (line, column)
    assert message in error.message


def test_a_ragged_row_in_a_later_block_keeps_its_line_and_column() -> None:
    rows = [f"{i},{i},{i}" for i in range(1, 400)]
    rows[300] = "301,301,301,301"
    options = CsvOptions(orientation=(180.0, 0.0, 180.0), chunk_bytes=256)
    error = error_of("\n".join(rows) + "\n", options)
    assert error.span is not None and (error.span.line, error.span.column) == (301, 13)
    assert "the first extra cell is '301'" in error.message


# ------------------------------------------------------------------------------------------------
# Item 14: bounded messages; no text makes the reader backtrack


HUGE = 20_000_000


def huge_inputs() -> list[tuple[str, bytes]]:
    return [
        ("20 MB cell", b"1,2,3\n1,2," + b"7" * HUGE + b"x\n"),
        ("20 MB extra cell", b"x,y,z\n1,2,3," + b"8" * HUGE + b"\n"),
        ("20 MB first row", b"1,2," + b"9" * HUGE + b"\n"),
        ("100k columns", b"1,2,3\n" + b",".join([b"1"] * 100_000) + b"\n"),
        ("400-digit number", b"1,2," + b"9" * 400 + b"\n"),
        ("20 MB header over a ragged row", b"x" * HUGE + b",y,z\n1,2,3,4\n"),
    ]


@pytest.mark.parametrize(
    ("name", "data"), huge_inputs(), ids=lambda v: v if isinstance(v, str) else ""
)
def test_messages_quote_a_bounded_excerpt(name: str, data: bytes) -> None:
    with finishes_within(30.0):
        error = error_of(data)
    assert error.span is not None and error.span.line >= 1
    assert len(error.message) < MESSAGE_LIMIT, error.message[:200]
    assert len(error.hint or "") < MESSAGE_LIMIT


def test_a_long_cell_that_is_almost_a_number_is_rejected_at_once() -> None:
    """``[0-9]+\\.?[0-9]*`` backtracked quadratically: 200,000 digits took about 20 minutes."""
    with finishes_within(10.0):
        error = error_of(b"1,2,3\n1,2," + b"9" * 200_000 + b"x\n")
    assert error.span is not None and (error.span.line, error.span.column) == (2, 5)
    assert "column 'z': expected a number, found '9999" in error.message


def test_a_header_cell_with_a_long_run_of_spaces_is_read_at_once() -> None:
    """``\\s*[)]?\\s*`` backtracked quadratically on a unit followed by many spaces."""
    header = "x mm" + " " * 200_000 + "z,y,z"
    with finishes_within(10.0):
        result = parse_csv(f"{header}\n1,2,3\n", "t.csv", DOWN)
    assert result.layout.length_unit == "mm" and len(result.program) == 1


# ------------------------------------------------------------------------------------------------
# Other small hostile files


OTHER = [
    # bytes, line, column, message
    (b"", 1, 1, "the CSV file is empty"),
    (b"\xef\xbb\xbf", 1, 1, "the CSV file is empty"),
    (b"x,y,z\n", 1, 1, "no data rows after the header rows"),
    (b"x,y,z", 1, 1, "no data rows after the header rows"),
    (b"1,2,3\n4,\x005,6\n", 2, 3, "column 'y': expected a number, found '\\x005'"),
    (b"1,2,3\n1e309,2,3\n", 2, 1, "column 'x': expected a finite number, found '1e309'"),
    (b"1,2,3\n4,\xff5,6\n", 2, 3, "column 'y': expected a number"),
    (b"1,2,3,0,0,0,1e300\n", 1, 13, "column 'index': expected an integer from"),
    (b"1,2,3,0,0,0,9007199254740993\n", 1, 13, "column 'index': expected an integer from"),
    (b'"1","2","3"\n', 1, 1, "no data rows after the header rows"),
]


@pytest.mark.parametrize(("data", "line", "column", "message"), OTHER)
def test_small_hostile_files_are_located_errors(
    data: bytes, line: int, column: int, message: str
) -> None:
    error = error_of(data, CsvOptions() if b"1e300" in data or b"993" in data else DOWN)
    assert error.span is not None
    assert (error.span.line, error.span.column) == (line, column)
    assert message in error.message


def test_quoted_numbers_get_a_hint() -> None:
    error = error_of(b'"1","2","3"\n')
    assert error.hint is not None and "remove the quotes" in error.hint


def test_the_largest_exact_index_still_names_its_target() -> None:
    result = parse_csv("1,2,3,0,0,0,9007199254740991\n", "t.csv")
    (move,) = result.program.motions()
    assert move.target.name == "9007199254740991"  # type: ignore[union-attr]
