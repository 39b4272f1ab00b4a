"""A toolpath written by a post's column writer (a block's rows as arrays, no step per row:
:class:`olp.posts.view.RowColumns`) is the text the per-move templates write, byte for byte,
with the same errors on the same rows; and its numbers are spelled as the post's
:class:`~olp.posts.numbers.NumberFormat` spells each one."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.compiled import CompiledProgram, PathBlock
from olp.frontends.bundled import CsvOptions
from olp.geometry import transl
from olp.posts import REGISTRY, find_post
from olp.posts.base import Post
from olp.posts.numbers import NumberError, NumberFormat, format_number
from olp.posts.rows import number_column, spell_column
from olp.transforms.limits import SplitLimits
from tests.compile_once import CompileOnce

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
COLUMN_POSTS = ["kuka", "abb"]  # column writers that split files (UR: test_ur_columns.py)
PART_LIMITS = SplitLimits(max_motions=300)
"""A file limit below a toolpath's rows, so the block is cut between parts: the posts' own 5000
would need 5000 rows (the build time grows with the rows)."""

EDGES = [0.0, -0.0, -0.0004, -0.0005, 0.0005, 0.00049999, 1e-320, -1e-320, 2.5, -2.5, 0.125]
EDGES += [1e15, -1e17, 123456789.0125, 0.0015, 1.0005, 2.675, 1e300, -1e301, 0.5, -0.5, 9.9995]


def _values() -> np.ndarray:
    rng = np.random.default_rng(7)
    ties = np.round(rng.normal(0.0, 100.0, 20_000), 3) + 0.0005  # halves at 3 and 4 decimals
    ties4 = np.round(rng.normal(0.0, 100.0, 20_000), 4) + 0.00005
    return np.concatenate(
        [rng.normal(0, 1000, 50_000), rng.normal(0, 1, 20_000), ties, ties4, EDGES]
    )


@pytest.mark.parametrize("decimals", range(7))
@pytest.mark.parametrize("compact", [False, True])
def test_a_column_is_spelled_as_each_number_is(decimals: int, compact: bool) -> None:
    values = _values()
    expected = [f"{v:.{decimals}f}" for v in values.tolist()]  # Python's correct rounding
    expected = [t[1:] if t.startswith("-") and float(t) == 0.0 else t for t in expected]
    if compact and decimals:
        expected = [t.rstrip("0").rstrip(".") for t in expected]
    assert spell_column(values, decimals, compact).tolist() == expected
    fmt = NumberFormat("x", "", decimals, compact=compact)
    sane = values[np.abs(values) <= 1e300]
    assert spell_column(sane, decimals, compact).tolist() == [
        format_number(v, fmt) for v in sane.tolist()
    ]


def _formats() -> list[NumberFormat]:
    return [fmt for name in sorted(REGISTRY) for fmt in find_post(name).NUMBERS.values()]


@pytest.mark.parametrize("fmt", _formats(), ids=lambda f: f.what)
def test_a_column_is_checked_as_each_number_is(fmt: NumberFormat) -> None:
    rng = np.random.default_rng(3)
    for scale in (1e-6, 1e-3, 1.0, 1e3, 1e6, 1e9, 1e40):
        for values in (rng.normal(0.0, scale, 500), np.abs(rng.normal(0.0, scale, 500))):
            texts, ok = number_column(values, fmt)
            try:
                expected = [format_number(v, fmt) for v in values.tolist()]
            except NumberError:
                assert not ok
                continue
            assert ok and texts.tolist() == expected
    assert not number_column(np.array([1.0, np.nan]), fmt)[1]


def _toolpath(rows: int, tmp_path: Path) -> ir.Program:
    """A helix of ``rows`` rows as one dense node with a speed and a zone changing every few
    rows, an orientation speed and accelerations; before it a move with another tool and
    frame, a comment, and after it a wait and a LIN."""
    station = olp.load_station(CELL)
    t = np.linspace(0.0, 8.0 * np.pi, rows)
    xyz = np.c_[100 + 60 * np.cos(t), 60 * np.sin(t), 20 + np.linspace(0.0, 30.0, rows)]
    csv = tmp_path / "helix.csv"
    np.savetxt(csv, xyz, fmt="%.4f", delimiter=",", header="x,y,z", comments="")
    options = CsvOptions(frame="table", orientation=(180.0, 0.0, 180.0), chunk_bytes=1 << 30)
    program = olp.parse(csv, station=station, options=options).program
    (node,) = [n for n in program.instructions if isinstance(n, ir.LinearPath)]
    k = np.arange(len(node))
    node = dataclasses.replace(
        node,
        speeds=0.02 + 0.005 * ((k // 7) % 5),
        zones=0.001 * ((k // 5) % 3),
        angular=np.radians(45.0),
        acceleration=2.5,
        angular_acceleration=np.radians(300.0),
    )
    table, spindle = station.frames["table"], station.tools["spindle"]
    assert table.pose is not None
    other = ir.Frame(name="fixture", pose=table.pose @ transl(0.0, 0.0, 0.01))
    first = node.move(0)
    lead = dataclasses.replace(first, frame=other, tool=ir.Tool(name="probe", pose=spindle.pose))
    head = [lead, ir.Comment(text="toolpath")]
    tail = [ir.Wait(seconds=0.5), node.move(len(node) - 1).with_zone(0.0)]
    rest = [n for n in program.instructions if not isinstance(n, ir.LinearPath)]
    return program.replace_instructions([*rest, *head, node, *tail])


def _both(
    post_name: str, program: ir.Program, limits: SplitLimits | None = None, **options: object
) -> tuple[olp.BuildResult, ...]:
    station = olp.load_station(CELL)
    post = _post(post_name, limits)
    manifest = dataclasses.replace(post.manifest, options={**post.manifest.options, **options})
    columns = type(post)(manifest)
    template = type(post)(dataclasses.replace(manifest, rows=False))
    with CompileOnce():
        return olp.build(station, program, columns), olp.build(station, program, template)


@pytest.mark.parametrize("post", COLUMN_POSTS)
def test_a_toolpath_is_written_by_columns_as_the_templates_write_it(
    post: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    program = _toolpath(800, tmp_path)
    columns, template = _both(post, program, PART_LIMITS)
    assert columns.ok, [d.format() for d in columns.diagnostics]
    assert len(columns.files) > 2  # split: the block is cut between files
    assert columns.files == template.files
    assert [d.format() for d in columns.diagnostics] == [d.format() for d in template.diagnostics]
    # The column build made no step per row: the same build again, with that forbidden.
    monkeypatch.setattr(PathBlock, "steps", _forbidden)
    monkeypatch.setattr(CompiledProgram, "flat", _forbidden)
    station = olp.load_station(CELL)
    assert olp.build(station, program, _post(post, PART_LIMITS)).files == columns.files


def _post(name: str, limits: SplitLimits | None = None) -> Post:
    """The bundled post ``name``, with ``limits`` instead of its own where given."""
    post = find_post(name)
    if limits is None:
        return post
    return type(post)(dataclasses.replace(post.manifest, limits=limits))


def _forbidden(*args: object) -> None:
    raise AssertionError("a toolpath's rows were made into steps")


def test_kuka_named_points_of_a_toolpath_are_written_by_columns(tmp_path: Path) -> None:
    columns, template = _both("kuka", _toolpath(300, tmp_path), points="dat")
    assert columns.ok, [d.format() for d in columns.diagnostics]
    assert columns.files == template.files
    assert "DECL E6POS XP301=" in "".join(columns.files.values())


@pytest.mark.parametrize("post", COLUMN_POSTS)
def test_a_number_the_column_writer_cannot_write_is_an_error_on_its_row(
    post: str, tmp_path: Path
) -> None:
    program = _toolpath(40, tmp_path)
    nodes = list(program.instructions)
    at = next(k for k, n in enumerate(nodes) if isinstance(n, ir.LinearPath))
    node = nodes[at]
    assert isinstance(node, ir.LinearPath)
    speeds = np.array(node.speeds)
    speeds[[4, 9]] = 1e-9
    nodes[at] = dataclasses.replace(node, speeds=speeds)
    columns, template = _both(post, program.replace_instructions(nodes))
    errors = [(d.kind, d.index, d.message) for d in columns.diagnostics if d.severity == "error"]
    assert [index for _, index, _ in errors] == [at + 4, at + 9]
    assert errors == [
        (d.kind, d.index, d.message) for d in template.diagnostics if d.severity == "error"
    ]
