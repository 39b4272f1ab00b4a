"""CSV toolpaths -> :class:`olp.ir.Program`: one target per row, read in vectorised chunks.

Layouts (by the number of columns; lengths in the file's unit, angles in its angle unit)
------------------------------------------------------------------------------------------
* 3 columns ``x, y, z`` and 4 columns ``x, y, z, speed`` (USERS.md job 3). Every row keeps one
  orientation, :attr:`CsvOptions.orientation`: three angles in degrees in the file's Euler
  convention, or (``None``, the default) the orientation of the station's **home** position:
  the TCP of the chosen tool at the robot's home joints, expressed in the chosen frame. The
  station has no named targets; its home position is the reference target it does define, and it
  is what RoboDK's own XYZ importer uses (the robot's pose when the import starts).
* 6 columns ``x, y, z, a1, a2, a3`` and 7 columns with an integer **index** last (job 4). The
  angles follow :attr:`CsvOptions.euler`. The default ``"xyz"`` reads the columns as W, P, R
  (rotations about X, Y and Z) composed as ``R = Rz(R) · Ry(P) · Rx(W)``, i.e. Euler
  Z -> Y' -> X''. Source: RoboDK's ``ImportCSV_XYZWPR`` example builds each target as
  ``transl(x, y, z) * rotz(rz) * roty(ry) * rotx(rx)`` from columns ``x, y, z, rx, ry, rz, id``;
  Fanuc's W, P, R mean the same. Pinned against scipy's ``Rotation.from_euler`` in
  ``tests/frontends/test_csv.py``. The index becomes the target's name.

``euler`` is a scipy-style sequence: three axis letters naming the axis of each angle column in
file order; upper case is intrinsic (``"ZYX"``: ``Rz(c4) Ry(c5) Rx(c6)``, KUKA's A, B, C),
lower case extrinsic (``"xyz"``: ``Rz(c6) Ry(c5) Rx(c4)``). ``"wpr"`` and ``"abc"`` are aliases
of ``"xyz"`` and ``"ZYX"``.

Motions, speed, tool and frame
------------------------------
The first target is a joint move, the others linear moves (as RoboDK's importers do). A speed
column gives each row's TCP speed exactly (``Speed.linear``, m/s inside); posts write a speed
change only where it differs from the previous one. Without one, :attr:`CsvOptions.speed` (mm/s)
or the IR default applies. :attr:`CsvOptions.zone` (mm) rounds the linear moves but the last.
Targets are the TCP of :attr:`CsvOptions.tool` in :attr:`CsvOptions.frame`, both station names.
Defaults: the station's **first** tool (a CSV toolpath is the path of the tool, not of the
flange; the flange if the station has none) and the **world** frame (``"world"``).

Reading
-------
Header rows (leading rows none of whose cells is a number), the delimiter (``,`` ``;`` tab ``|``
or whitespace), a decimal comma (with a ``;``, tab or whitespace delimiter) and the units are
detected or given. Units come from header cells such as ``x [mm]``, ``x (m)``, ``x_in``,
``a [rad]``, ``speed [mm/min]``; without any, mm, degrees and mm/s. A unit given in the options
that contradicts the header is an error. Lines that are blank or start with ``#`` are skipped.
The header row right above the data names the columns: a first data row with another number
of cells, or a name olp knows over a column it reads as something else (``rz`` over the speed
column, ``a1..a6`` or ``j1..j6`` joint values, ``i, j, k`` tool vectors, quaternions, ``y``
first), is an error rather than a file read another way. A one-cell row above is a title.

The file is read in blocks of :attr:`CsvOptions.chunk_bytes` and each block is parsed by numpy
in one call, so memory stays bounded by the block size plus the arrays the result needs
(:func:`open_csv` streams those arrays without building IR objects). Only a block that holds an
error is re-read cell by cell, to report it. Every bad row raises
:class:`~olp.errors.ParseError` with file, line, column, the offending cell and what was
expected; no other exception escapes for bad file content.
"""

from __future__ import annotations

import io
import os
import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, BinaryIO

import numpy as np
from numpy.typing import NDArray

from olp import ir, progress
from olp.errors import ParseError, UsageError
from olp.frontends.bundled import ANGLE_UNITS, LENGTH_UNITS
from olp.frontends.bundled import CsvOptions as CsvOptions  # its home is light to import
from olp.geometry import inv, pose_from, rotx, roty, rotz

if TYPE_CHECKING:
    from olp.station.model import Station

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

LAYOUTS: dict[int, tuple[str, ...]] = {
    3: ("x", "y", "z"),
    4: ("x", "y", "z", "speed"),
    6: ("x", "y", "z", "a1", "a2", "a3"),
    7: ("x", "y", "z", "a1", "a2", "a3", "index"),
}
"""Column names by column count."""

_DELIMITERS: tuple[str | None, ...] = (",", ";", "\t", "|", None)
# Both patterns are linear in the text: no two adjacent repeats can match the same characters
# (``[0-9]+\.?[0-9]*`` or ``\s*[)]?\s*`` backtrack quadratically on a long cell).
_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_UNIT = re.compile(
    r"(?:[\[(]\s*|_|\s)(mm|m|in|inch|deg|rad)(?:\s*/\s*(s|sec|min))?\s*(?:[\])]\s*)?$",
    re.IGNORECASE,
)
EXCERPT_CHARS = 40
"""Longest piece of a file's text a message quotes; the rest is summarised by its length."""
MAX_INDEX = 2**53 - 1
"""Largest index (in size) a 7-column row may give: every integer up to it survives the float
the row is read as, so the target's name is the number in the file."""


# ------------------------------------------------------------------------------------------------
# Results


@dataclass(frozen=True, slots=True)
class CsvLayout:
    """What was detected (or given) about a CSV file.

    SI values are ``length / length_divisor`` (m), ``angle * angle_scale`` (rad) and
    ``speed / speed_divisor`` (m/s).
    """

    columns: tuple[str, ...]
    delimiter: str | None
    decimal: str
    header_rows: int
    length_unit: str
    angle_unit: str
    speed_unit: str
    length_divisor: float
    angle_scale: float
    speed_divisor: float


@dataclass(frozen=True, slots=True, eq=False)
class CsvChunk:
    """Rows of one block: ``lines`` (n,) 1-based line numbers, ``values`` (n, columns) in the
    file's units, ``lengths`` (n,) characters per line (for spans)."""

    lines: IntArray
    values: FloatArray
    lengths: IntArray


@dataclass(frozen=True, slots=True)
class IgnoredLine:
    """A line olp recognised but did not lower (a header row): where, its text, and why."""

    span: ir.SourceSpan
    text: str
    reason: str


@dataclass(frozen=True, slots=True, kw_only=True)
class CsvResult:
    """What the CSV frontend read: the program, the header lines it skipped, the layout."""

    program: ir.Program
    layout: CsvLayout
    ignored: tuple[IgnoredLine, ...] = ()


# ------------------------------------------------------------------------------------------------
# Public entry points


def load_csv(
    path: str | os.PathLike[str],
    options: CsvOptions | None = None,
    station: Station | None = None,
) -> CsvResult:
    """Read a CSV toolpath file and lower it to a program named after the file.

    Parameters
    ----------
    path : the CSV file.
    options : see :class:`CsvOptions`.
    station : needed for the home orientation of XYZ files and to look tools and frames up;
        without it, names become references for the resolve pass and the default tool is the
        flange.

    Raises :class:`ParseError` for bad content, :class:`UsageError` for bad options or an
    unreadable file.
    """
    with open_csv(path, options) as stream:
        return _lower(stream, Path(path).stem, station)


def parse_csv(
    data: str | bytes,
    filename: str = "<string>",
    options: CsvOptions | None = None,
    station: Station | None = None,
) -> CsvResult:
    """:func:`load_csv` on text or bytes in memory; ``filename`` names it in spans."""
    raw = data.encode("utf-8") if isinstance(data, str) else data
    with CsvStream(io.BytesIO(raw), filename, options or CsvOptions()) as stream:
        return _lower(stream, Path(filename).stem, station)


def _lower(stream: CsvStream, name: str, station: Station | None) -> CsvResult:
    builder = _ProgramBuilder(stream, stream.options, station)
    for chunk in stream:
        builder.add(chunk)
        progress.advance(int(chunk.lines.size))
    return CsvResult(program=builder.program(name), layout=stream.layout, ignored=stream.ignored)


class CsvWindows:
    """A CSV toolpath as a sequence of programs of at least ``rows`` rows each (whole blocks of
    the reader), in file order: the first holds the joint move to the first row, the others
    only linear moves; together they are the instructions :func:`load_csv` makes, in the same
    nodes (the last row of the last window stops). Only one window's arrays are held at a time.

    Use as a context manager; ``layout`` and ``ignored`` as in :class:`CsvResult`.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        options: CsvOptions | None,
        station: Station | None,
        rows: int,
    ) -> None:
        self.stream = open_csv(path, options)
        self.layout = self.stream.layout
        self.ignored = self.stream.ignored
        self.name = Path(path).stem
        self.rows = max(1, rows)
        try:
            self._builder = _ProgramBuilder(self.stream, self.stream.options, station)
        except BaseException:
            self.stream.close()
            raise

    def __enter__(self) -> CsvWindows:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stream.close()

    def __iter__(self) -> Iterator[ir.Program]:
        builder, pending = self._builder, 0
        for chunk in self.stream:
            if pending >= self.rows:  # rows follow: the window is not the last one
                yield builder.take(self.name)
                pending = 0
            builder.add(chunk)
            pending += int(chunk.lines.size)
            progress.advance(int(chunk.lines.size))
        yield builder.program(self.name)


def open_csv(path: str | os.PathLike[str], options: CsvOptions | None = None) -> CsvStream:
    """Open a CSV toolpath for streaming: ``.layout``, then iterate :class:`CsvChunk` arrays.

    Use as a context manager. Nothing but the arrays is built per row, so a file of any length
    streams in memory bounded by ``options.chunk_bytes`` and the arrays of one block.
    """
    try:
        file: BinaryIO = open(path, "rb")  # noqa: SIM115 - the stream closes it
    except OSError as exc:
        raise UsageError(f"cannot read CSV file {os.fspath(path)!r}: {exc.strerror}") from None
    return CsvStream(file, os.fspath(path), options or CsvOptions())


def rotations_from_euler(sequence: str, angles: FloatArray) -> FloatArray:
    """Rotation matrices (n, 3, 3) from angles (n, 3) in radians, in file column order.

    ``sequence`` as in :func:`olp.frontends.options.euler_sequence`: intrinsic (upper case)
    composes the column rotations left to right, extrinsic (lower case) right to left.
    """
    makers = {"x": rotx, "y": roty, "z": rotz}
    mats = [makers[axis.lower()](angles[:, i])[:, :3, :3] for i, axis in enumerate(sequence)]
    if sequence.isupper():
        result: FloatArray = mats[0] @ mats[1] @ mats[2]
    else:
        result = mats[2] @ mats[1] @ mats[0]
    return result


# ------------------------------------------------------------------------------------------------
# Streaming reader


@dataclass(frozen=True, slots=True)
class _Block:
    """Whole lines of text; ``text`` starts at 1-based line ``first_line``."""

    text: str
    first_line: int


class CsvStream:
    """Chunks of a CSV toolpath as numpy arrays, read from a binary file it closes
    (see :func:`open_csv`)."""

    def __init__(self, file: BinaryIO, filename: str, options: CsvOptions) -> None:
        self.filename = filename
        self.options = options
        self._file = file
        try:
            self._blocks = _text_blocks(self._file, self.filename, options.chunk_bytes)
            head = _Head(self._head_block(), self.filename, options)
        except BaseException:
            self.close()
            raise
        self.layout: CsvLayout = head.layout
        self.ignored: tuple[IgnoredLine, ...] = head.ignored
        self._first: _Block | None = head.rest

    def __enter__(self) -> CsvStream:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self._file.close()

    def _head_block(self) -> _Block:
        """The first block, extended until it holds the first data row (long headers)."""
        block = next(self._blocks, None)
        if block is None:
            raise ParseError("the CSV file is empty", ir.SourceSpan(self.filename, 1, 1))
        while not _holds_data(block, self.options.header):
            more = next(self._blocks, None)
            if more is None:
                break
            block = _Block(block.text + more.text, block.first_line)
        return block

    def __iter__(self) -> Iterator[CsvChunk]:
        block, self._first = self._first, None
        while block is not None:
            chunk = _parse_block(block, self.layout, self.filename)
            if chunk.lines.size:
                yield chunk
            block = next(self._blocks, None)


def _text_blocks(file: BinaryIO, filename: str, size: int) -> Iterator[_Block]:
    """Blocks of whole lines (cut after a newline byte, which never splits a UTF-8 character)."""
    rest = b""
    line = 1
    data = _strip_bom(file.read(size), filename)
    while data:
        data = rest + data
        cut = data.rfind(b"\n") + 1
        rest = data[cut:]
        if cut:
            yield _Block(_decode(data[:cut]), line)
            line += data.count(b"\n", 0, cut)
        data = file.read(size)
    if rest:
        yield _Block(_decode(rest), line)


def _holds_data(block: _Block, header: int | None) -> bool:
    """Whether ``block`` reaches the first data row (see :func:`_leading_content`)."""
    content = _leading_content(block, header)
    if header is not None:
        return len(content) > header
    return bool(content) and _has_number(content[-1][1])


def _strip_bom(data: bytes, filename: str) -> bytes:
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise ParseError(
            "the CSV file is UTF-16 encoded; olp reads UTF-8 (or ASCII) CSV files",
            ir.SourceSpan(filename, 1, 1),
            hint="save the file as 'CSV UTF-8'",
        )
    return data[3:] if data.startswith(b"\xef\xbb\xbf") else data


def _decode(data: bytes) -> str:
    # Numbers are ASCII: a stray byte in a header is only replaced; in a number it fails to
    # parse there and is reported with its line.
    return data.decode("utf-8", errors="replace")


# ------------------------------------------------------------------------------------------------
# Head: header rows, delimiter, decimal separator, units


class _Head:
    """Reads the leading rows of the first block and decides the layout.

    ``rest`` is the block without the header rows (None if nothing follows them).
    """

    def __init__(self, block: _Block, filename: str, options: CsvOptions) -> None:
        self.filename = filename
        self.options = options
        content = _leading_content(block, options.header)
        if not content:
            body = block.text.rstrip("\r\n")
            last = block.first_line + body.count("\n")
            raise self._error(
                "no data rows found: expected rows of 3, 4, 6 or 7 numbers",
                last,
                body.rsplit("\n", 1)[-1],
            )
        count = self._header_count(content)
        if count >= len(content):
            number, text = content[-1]
            raise self._error("no data rows after the header rows", number, text, _quote_hint(text))
        headers = content[:count]
        number, first = content[count]
        delimiter, decimal = self._separators(number, first, count)
        if headers:
            self._match_header(headers[-1], number, first, delimiter)
        cells = _split(first, delimiter)
        columns = LAYOUTS.get(len(cells))
        if columns is None:
            message = (
                f"found {len(cells)} columns; expected 3 (x, y, z), 4 (x, y, z, speed), 6 (x, y, "
                "z and three angles) or 7 (x, y, z, three angles and an index)"
            )
            raise self._error(message, number, first)
        if headers:
            self._match_names(headers[-1], columns, delimiter)
        self.layout = self._layout(columns, delimiter, decimal, headers)
        self.ignored = tuple(
            IgnoredLine(ir.SourceSpan(filename, n, 1), text.strip(), "header row")
            for n, text in headers
        )
        self.rest = _drop_lines(block, headers[-1][0] - block.first_line + 1 if headers else 0)

    def _error(self, message: str, line: int, text: str, hint: str | None = None) -> ParseError:
        return ParseError(message, ir.SourceSpan(self.filename, line, 1), text, hint)

    def _match_header(
        self, header: tuple[int, str], line: int, text: str, delimiter: str | None
    ) -> None:
        """The first data row has as many cells as the header row right above it, which names
        the columns. A different count means the rows are not what the header says (``x,y,z``
        over ``400,5,0,500`` must not become x, y, z and a speed). A one-cell row is a title."""
        number, names = header
        expected = len(_split(names.strip(), delimiter))
        if expected > 1 and len(_split(text, delimiter)) != expected:
            what = f"cells like the header row on line {number} ({_excerpt(names.strip())})"
            hint = "make every row match the header; start a title row with '#'"
            raise _count_error(text, line, delimiter, expected, what, self.filename, hint)

    def _match_names(
        self, header: tuple[int, str], columns: tuple[str, ...], delimiter: str | None
    ) -> None:
        """A header cell olp recognises names what olp reads in its column: ``speed`` over a
        4th column, an angle over the 4th to 6th. ``x,y,z,rz`` over four numbers, ``a1..a6``
        joint values or ``i,j,k`` tool vectors would otherwise be read as something else."""
        number, text = header
        spans = _cell_spans(text, delimiter)
        if len(spans) != len(columns):
            return
        for (start, end), column in zip(spans, columns, strict=True):
            kind = HEADER_NAMES.get(_base_name(text[start:end]))
            expected = _COLUMN_KINDS[column]
            if kind is None or kind == expected:
                continue
            cell = text[start:end].strip()
            column_at = start + text[start:end].index(cell) + 1 if cell else start + 1
            raise ParseError(
                f"the header names {_excerpt(cell)} ({_KIND_TEXT[kind]}) where olp reads "
                f"{_KIND_TEXT[expected]}: a row of {len(columns)} numbers is "
                f"{', '.join(columns)}",
                ir.SourceSpan(self.filename, number, column_at, number, column_at + len(cell)),
                text,
                "olp reads x, y, z (3 columns), then a speed (4), or three angles (6) and "
                "an index (7): reorder the columns; joint values, tool vectors and "
                "quaternions need converting",
            )

    def _header_count(self, content: list[tuple[int, str]]) -> int:
        if self.options.header is not None:
            return self.options.header
        count = 0
        while count < len(content) and not _has_number(content[count][1]):
            count += 1
        return count

    def _separators(self, line: int, text: str, headers: int) -> tuple[str | None, str]:
        given = self.options.delimiter
        delimiters = _DELIMITERS if given is None else (None if given == " " else given,)
        decimals = (".", ",") if self.options.decimal is None else (self.options.decimal,)
        for delimiter in delimiters:
            for decimal in decimals:
                cells = _split(text, delimiter)
                numeric = len(cells) >= 3 and all(_is_number(c, decimal) for c in cells)
                if decimal != delimiter and numeric:
                    return delimiter, decimal
        hint = None if headers else "if this is a header row, give the number of header rows"
        raise self._error(
            "cannot read the first data row as numbers separated by ',', ';', tab, '|' or spaces",
            line,
            text,
            hint,
        )

    def _layout(
        self,
        columns: tuple[str, ...],
        delimiter: str | None,
        decimal: str,
        headers: list[tuple[int, str]],
    ) -> CsvLayout:
        found = _HeaderUnits(self.filename, delimiter, columns)
        for line, text in headers:
            found.read(line, text)
        length = self._unit("length", self.options.units, found.units.get("length"), "mm")
        angle = self._unit("angle", self.options.angle_units, found.units.get("angle"), "deg")
        return CsvLayout(
            columns=columns,
            delimiter=delimiter,
            decimal=decimal,
            header_rows=len(headers),
            length_unit=length,
            angle_unit=angle,
            speed_unit=f"{length}/{found.per}",
            length_divisor=LENGTH_UNITS[length],
            angle_scale=ANGLE_UNITS[angle],
            speed_divisor=LENGTH_UNITS[length] * (60.0 if found.per == "min" else 1.0),
        )

    def _unit(
        self, kind: str, given: str | None, found: tuple[str, _Cell] | None, default: str
    ) -> str:
        if found is None:
            return given or default
        unit, cell = found
        if given is not None and given != unit:
            raise cell.error(f"the header gives {kind}s in {unit!r} but the options say {given!r}")
        return unit


def _leading_content(block: _Block, header: int | None) -> list[tuple[int, str]]:
    """(line number, text) of the content lines up to the first data row: the first one with
    a number, or the one after ``header`` rows. Stops there, so a huge block costs nothing."""
    content: list[tuple[int, str]] = []
    text, start, number = block.text, 0, block.first_line
    while start < len(text):
        end = text.find("\n", start)
        end = len(text) if end < 0 else end
        line = text[start:end].rstrip("\r")
        if _is_content(line):
            content.append((number, line))
            done = len(content) > header if header is not None else _has_number(line)
            if done:
                break
        start, number = end + 1, number + 1
    return content


def _drop_lines(block: _Block, count: int) -> _Block | None:
    if not count:
        return block
    parts = block.text.split("\n", count)
    return _Block(parts[count], block.first_line + count) if len(parts) > count else None


@dataclass(frozen=True, slots=True)
class _Cell:
    """Where a header cell is, to point an error at it."""

    span: ir.SourceSpan
    text: str

    def error(self, message: str) -> ParseError:
        return ParseError(message, self.span, self.text)


class _HeaderUnits:
    """Units named in header cells: one length and one angle unit per file, and whether the
    speed column is per second or per minute."""

    def __init__(self, filename: str, delimiter: str | None, columns: tuple[str, ...]) -> None:
        self.filename = filename
        self.delimiter = delimiter
        self.columns = columns
        self.units: dict[str, tuple[str, _Cell]] = {}
        self.per = "s"

    def read(self, line: int, text: str) -> None:
        spans = _cell_spans(text, self.delimiter)
        if len(spans) != len(self.columns):
            return
        for (start, end), column in zip(spans, self.columns, strict=True):
            match = _UNIT.search(" " + text[start:end].strip())
            if match is None:
                continue
            unit = {"inch": "in"}.get(match.group(1).lower(), match.group(1).lower())
            cell = _Cell(ir.SourceSpan(self.filename, line, start + 1), text)
            self._agree("angle" if column.startswith("a") else "length", unit, column, cell)
            if column == "speed" and match.group(2):
                self.per = "min" if match.group(2).lower() == "min" else "s"

    def _agree(self, kind: str, unit: str, column: str, cell: _Cell) -> None:
        expected = ANGLE_UNITS if kind == "angle" else LENGTH_UNITS
        if unit not in expected:
            raise cell.error(
                f"column {column!r}: {unit!r} is not a {kind} unit "
                f"(expected one of {', '.join(expected)})"
            )
        previous = self.units.get(kind)
        if previous is not None and previous[0] != unit:
            raise cell.error(
                f"column {column!r} is in {unit!r} but an earlier column is in "
                f"{previous[0]!r}; olp needs one length unit and one angle unit per file"
            )
        self.units.setdefault(kind, (unit, cell))


HEADER_NAMES: dict[str, str] = {
    "x": "x",
    "y": "y",
    "z": "z",
    **dict.fromkeys(("speed", "feed", "feedrate", "f", "v", "vel", "velocity"), "speed"),
    **dict.fromkeys(
        ("a", "b", "c", "w", "p", "r", "rx", "ry", "rz", "roll", "pitch", "yaw"), "angle"
    ),
    **dict.fromkeys(("alpha", "beta", "gamma", "a1", "a2", "a3"), "angle"),
    **dict.fromkeys(("index", "idx", "id", "nr", "no", "number"), "index"),
    **dict.fromkeys(("i", "j", "k", "nx", "ny", "nz", "vx", "vy", "vz"), "vector"),
    **dict.fromkeys(("qw", "qx", "qy", "qz", "q0", "q1", "q2", "q3", "q4"), "quaternion"),
    **dict.fromkeys(("a4", "a5", "a6", "j1", "j2", "j3", "j4", "j5", "j6"), "joint"),
}
"""Header cell names (without units, lower case) olp recognises, and what they name. A
recognised name over a column olp reads as something else is an error."""
_COLUMN_KINDS = {"x": "x", "y": "y", "z": "z", "speed": "speed", "index": "index"}
_COLUMN_KINDS.update(dict.fromkeys(("a1", "a2", "a3"), "angle"))
_KIND_TEXT = {
    "x": "the x coordinate",
    "y": "the y coordinate",
    "z": "the z coordinate",
    "speed": "a speed",
    "angle": "an angle",
    "index": "an index",
    "vector": "a tool direction vector component",
    "quaternion": "a quaternion component",
    "joint": "a joint value",
}


def _base_name(cell: str) -> str:
    """A header cell's name without its unit (``X [mm]`` -> ``x``), lower case."""
    text = " " + cell.strip().strip("\"'")
    match = _UNIT.search(text)
    return (text[: match.start()] if match else text).strip().lower()


def _quote_hint(text: str) -> str | None:
    unquoted = text.replace('"', "").replace("'", "")
    if unquoted != text and _has_number(unquoted):
        return "olp reads plain numbers: remove the quotes around them"
    return None


def _excerpt(text: str) -> str:
    """``text`` quoted for a message, cut to :data:`EXCERPT_CHARS` characters (a 20 MB row
    must not become a 20 MB message)."""
    if len(text) <= EXCERPT_CHARS:
        return repr(text)
    return f"{text[:EXCERPT_CHARS]!r}... ({len(text)} characters)"


def _is_content(line: str) -> bool:
    stripped = line.strip()
    return bool(stripped) and not stripped.startswith("#")


def _has_number(text: str) -> bool:
    return any(_NUMBER.fullmatch(cell) for cell in re.split(r"[,;\t|\s]+", text.strip()))


def _is_number(cell: str, decimal: str) -> bool:
    text = cell.strip()
    if decimal == ",":
        text = text.replace(",", ".")
    return _NUMBER.fullmatch(text) is not None


def _split(text: str, delimiter: str | None) -> list[str]:
    return text.split() if delimiter is None else text.split(delimiter)


def _cell_spans(text: str, delimiter: str | None) -> list[tuple[int, int]]:
    """(start, end) character offsets of each cell of a line."""
    if delimiter is None:
        return [m.span() for m in re.finditer(r"\S+", text)]
    spans, start = [], 0
    for cell in text.split(delimiter):
        spans.append((start, start + len(cell)))
        start += len(cell) + len(delimiter)
    return spans


# ------------------------------------------------------------------------------------------------
# Body: one numpy call per block; a cell-by-cell pass only to report an error


def _parse_block(block: _Block, layout: CsvLayout, filename: str) -> CsvChunk:
    chunk = _parse_fast(block, layout)
    if chunk is None:
        chunk = _parse_slow(block, layout, filename)
    _check_values(chunk, block, layout, filename)
    return chunk


def _parse_fast(block: _Block, layout: CsvLayout) -> CsvChunk | None:
    """The whole block in one ``np.loadtxt`` call when it holds only plain rows; None when it
    has blank or comment lines, stray carriage returns or anything numpy rejects."""
    text = block.text
    body = text[:-1] if text.endswith("\n") else text
    if not body.strip() or "#" in body or "\n\n" in body or body.startswith("\n"):
        return None
    body = body.replace("\r\n", "\n")
    if "\r" in body:
        return None
    if layout.decimal == ",":
        body = body.replace(",", ".")
    values = _loadtxt(io.StringIO(body), layout)
    count = body.count("\n") + 1
    if values is None or values.shape[0] != count:
        return None
    lines = np.arange(block.first_line, block.first_line + count, dtype=np.int64)
    return CsvChunk(lines, values, _line_lengths(body))


def _line_lengths(body: str) -> IntArray:
    """Length of each line of ``body`` (lines joined by newlines), vectorised on its bytes.

    Bytes, not characters: for a non-ASCII row only the caret width of a message can be off.
    """
    raw = np.frombuffer(body.encode("utf-8"), dtype=np.uint8)
    ends = np.flatnonzero(raw == 10)
    starts = np.concatenate([[0], ends + 1])
    stops = np.concatenate([ends, [raw.size]])
    lengths: IntArray = (stops - starts).astype(np.int64)
    return lengths


def _loadtxt(source: io.StringIO | list[str], layout: CsvLayout) -> FloatArray | None:
    try:
        values = np.loadtxt(
            source, delimiter=layout.delimiter, ndmin=2, dtype=np.float64, comments=None
        )
    except ValueError:
        return None
    if values.shape[1] != len(layout.columns):
        return None
    result: FloatArray = values
    return result


def _parse_slow(block: _Block, layout: CsvLayout, filename: str) -> CsvChunk:
    """Skip blank and comment lines; on bad content, find the first bad cell and raise."""
    numbers: list[int] = []
    rows: list[str] = []
    for i, raw in enumerate(block.text.split("\n")):
        line = raw.rstrip("\r")
        if _is_content(line):
            numbers.append(block.first_line + i)
            rows.append(line)
    columns = len(layout.columns)
    if not rows:
        return CsvChunk(np.empty(0, np.int64), np.empty((0, columns)), np.empty(0, np.int64))
    numeric = [r.replace(",", ".") for r in rows] if layout.decimal == "," else rows
    values = _loadtxt(numeric, layout)
    if values is None or values.shape[0] != len(rows):
        for number, row in zip(numbers, rows, strict=True):
            _check_row(row, number, layout, filename)
        raise ParseError(
            "cannot read these rows as numbers",
            ir.SourceSpan(filename, numbers[0], 1),
            rows[0],
        )
    lengths = np.array([len(r) for r in rows], dtype=np.int64)
    return CsvChunk(np.array(numbers, dtype=np.int64), values, lengths)


def _check_row(text: str, line: int, layout: CsvLayout, filename: str) -> None:
    """Raise a located ParseError for the first bad cell of one row (or its column count)."""
    spans = _cell_spans(text, layout.delimiter)
    expected = len(layout.columns)
    if len(spans) != expected:
        what = f"columns ({', '.join(layout.columns)})"
        raise _count_error(text, line, layout.delimiter, expected, what, filename)
    for (start, end), column in zip(spans, layout.columns, strict=True):
        if not _is_number(text[start:end], layout.decimal):
            what = "an integer" if column == "index" else "a number"
            raise _cell_error(text, line, (start, end), filename, f"expected {what}", column)


def _count_error(
    text: str,
    line: int,
    delimiter: str | None,
    expected: int,
    what: str,
    filename: str,
    hint: str | None = None,
) -> ParseError:
    """A row with the wrong number of cells, pointing at the first extra cell or at the end of
    the row where cells are missing."""
    spans = _cell_spans(text, delimiter)
    found = len(spans)
    if found > expected:
        start, end = spans[expected]
        cell = text[start:end]
        column = start + len(cell) - len(cell.lstrip()) + 1
        detail = f"the first extra cell is {_excerpt(cell.strip())}"
        width = max(len(cell.strip()), 1)
        span = ir.SourceSpan(filename, line, column, line, column + width)
    else:
        column = len(text.rstrip()) + 1
        missing = expected - found
        detail = f"{missing} cell{'s' if missing > 1 else ''} missing at the end of the row"
        span = ir.SourceSpan(filename, line, column)
    return ParseError(f"expected {expected} {what}, found {found}: {detail}", span, text, hint)


def _cell_error(
    text: str, line: int, cell: tuple[int, int], filename: str, expected: str, column: str
) -> ParseError:
    raw = text[cell[0] : cell[1]]
    found = raw.strip()
    col = cell[0] + len(raw) - len(raw.lstrip()) + 1
    shown = _excerpt(found) if found else "nothing"
    return ParseError(
        f"column {column!r}: {expected}, found {shown}",
        ir.SourceSpan(filename, line, col, line, col + max(len(found), 1)),
        text,
    )


def _check_values(chunk: CsvChunk, block: _Block, layout: CsvLayout, filename: str) -> None:
    """Reject NaN and infinities (numpy reads them), speeds <= 0 and non-integer indices."""
    expected = ["a finite number"] * len(layout.columns)
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(chunk.values)
        if "speed" in layout.columns:
            col = layout.columns.index("speed")
            # In SI: a denormal mm/s value would become 0 m/s.
            bad[:, col] |= ~(chunk.values[:, col] / layout.speed_divisor > 0)
            expected[col] = "a finite speed > 0"
        if "index" in layout.columns:
            index = chunk.values[:, -1]
            bad[:, -1] |= (np.floor(index) != index) | (np.abs(index) > MAX_INDEX)
            expected[-1] = f"an integer from -{MAX_INDEX} to {MAX_INDEX}"
    if not np.any(bad):
        return
    row, col = (int(v) for v in np.unravel_index(int(np.argmax(bad)), bad.shape))
    line = int(chunk.lines[row])
    text = block.text.split("\n")[line - block.first_line].rstrip("\r")
    cell = _cell_spans(text, layout.delimiter)[col]
    raise _cell_error(text, line, cell, filename, f"expected {expected[col]}", layout.columns[col])


# ------------------------------------------------------------------------------------------------
# Lowering to the IR


def _tool(name: str | None, station: Station | None) -> ir.Tool:
    if name == "flange":
        return ir.FLANGE
    tools: Mapping[str, ir.Tool] = station.tools if station is not None else {}
    if name is None:
        return next(iter(tools.values()), ir.FLANGE)
    if station is None:
        return ir.Tool(name=name)
    if name not in tools:
        raise UsageError(f"tool {name!r} is not in the station (tools: flange, {', '.join(tools)})")
    return tools[name]


def _frame(name: str | None, station: Station | None) -> ir.Frame:
    if name is None or name == "world":
        return ir.WORLD
    if station is None:
        return ir.Frame(name=name)
    if name not in station.frames:
        known = ", ".join(["world", *station.frames])
        raise UsageError(f"frame {name!r} is not in the station (frames: {known})")
    return station.frames[name]


class _ProgramBuilder:
    """Turns chunks into IR: the first row is a joint move (the robot must first get to the
    path), every later chunk of rows one :class:`~olp.ir.LinearPath` (arrays, no object per
    row), sharing the tool, frame and zone."""

    def __init__(self, stream: CsvStream, options: CsvOptions, station: Station | None) -> None:
        self.stream = stream
        self.options = options
        self.layout = stream.layout
        self.tool = _tool(options.tool, station)
        self.frame = _frame(options.frame, station)
        self.zone = options.zone / 1000.0
        self.nodes: list[ir.Node] = []
        self.started = False
        has_angles = len(self.layout.columns) >= 6
        if has_angles and options.orientation is not None:
            raise UsageError(
                "an orientation option is for XYZ files; this file has angles in every row"
            )
        self.rotation = None if has_angles else self._fixed_rotation(station)
        self.default_speed = 0.25 if options.speed is None else options.speed / 1e3

    def _fixed_rotation(self, station: Station | None) -> FloatArray:
        if self.options.orientation is not None:
            angles = np.radians(np.array([self.options.orientation]))
            fixed: FloatArray = rotations_from_euler(self.options.euler, angles)[0]
            return fixed
        if station is None or self.tool.pose is None or self.frame.pose is None:
            raise UsageError(
                "an XYZ CSV keeps the orientation of the station's home position, which needs "
                "the station (and its tool and frame); or give the orientation "
                "(--orientation 'W,P,R' in degrees)"
            )
        robot = station.robot
        tcp = robot.flange_poses(robot.home) @ self.tool.pose
        home: FloatArray = (inv(self.frame.pose) @ tcp)[:3, :3]
        return home

    def add(self, chunk: CsvChunk) -> None:
        poses = self._poses(chunk)
        speeds = self._speeds(chunk)
        labels = self._labels(chunk)
        lines, widths = chunk.lines, chunk.lengths
        if not self.started:
            self.started = True
            self.nodes.append(self._first(poses[0], speeds[0], labels, lines[0], widths[0]))
            poses, speeds, lines, widths = poses[1:], speeds[1:], lines[1:], widths[1:]
            labels = None if labels is None else labels[1:]
        if lines.size == 0:
            return
        self.nodes.append(
            ir.LinearPath(
                poses=poses,
                speeds=speeds,
                zones=np.full(lines.size, self.zone),
                lines=lines,
                tool=self.tool,
                frame=self.frame,
                source=self.stream.filename,
                widths=widths,
                labels=labels,
            )
        )

    def _first(
        self,
        pose: FloatArray,
        speed: float,
        labels: IntArray | None,
        line: int,
        width: int,
    ) -> ir.JointMove:
        name = None if labels is None else str(int(labels[0]))
        span = ir.SourceSpan(self.stream.filename, int(line), 1, int(line), int(width) + 1)
        return ir.JointMove(
            target=ir.CartesianTarget(pose=pose, name=name),
            speed=ir.Speed(linear=float(speed)),
            tool=self.tool,
            frame=self.frame,
            span=span,
        )

    def _poses(self, chunk: CsvChunk) -> FloatArray:
        values = chunk.values
        position = values[:, :3] / self.layout.length_divisor
        if self.rotation is not None:
            rotation = np.broadcast_to(self.rotation, (values.shape[0], 3, 3))
        else:
            angles = values[:, 3:6] * self.layout.angle_scale
            rotation = rotations_from_euler(self.options.euler, angles)
        return pose_from(rotation, position)

    def _speeds(self, chunk: CsvChunk) -> FloatArray:
        """Speeds (n,) m/s: the speed column, or the default for every row."""
        if "speed" not in self.layout.columns:
            return np.full(chunk.lines.size, self.default_speed)
        speeds: FloatArray = (
            chunk.values[:, self.layout.columns.index("speed")] / self.layout.speed_divisor
        )
        return speeds

    def _labels(self, chunk: CsvChunk) -> IntArray | None:
        """The index column as integer target names (n,), or None."""
        if "index" not in self.layout.columns:
            return None
        labels: IntArray = chunk.values[:, -1].astype(np.int64)
        return labels

    def take(self, name: str) -> ir.Program:
        """The nodes made so far as a program, and a fresh start for the next ones (rows
        follow them: their last row keeps its zone)."""
        nodes, self.nodes = self.nodes, []
        return ir.Program(name=name, instructions=tuple(nodes), source=self.stream.filename)

    def program(self, name: str) -> ir.Program:
        """The program; the robot stops at the last row."""
        last = self.nodes[-1] if self.nodes else None
        if isinstance(last, ir.LinearPath) and last.zones[-1] > 0:
            zones = last.zones.copy()
            zones[-1] = 0.0
            self.nodes[-1] = last.with_zones(zones)
        return ir.Program(name=name, instructions=tuple(self.nodes), source=self.stream.filename)
