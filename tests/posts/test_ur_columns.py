"""The URScript post writes a toolpath from columns (a block's rows as arrays, no Step,
LinearMove or PostStep per row: :class:`olp.posts.view.RowColumns`), byte for byte the text of
the step path (the same post without its column writer) and of the per-move templates, with
the same diagnostics: tool and frame changes, speeds, accelerations, blends capped as arrays,
a stop before a wait, several toolpath nodes, a number that cannot be written."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import olp
from olp import ir
from olp.compiled import CompiledProgram, PathBlock, pieces
from olp.frontends.bundled import CsvOptions
from olp.geometry import transl
from olp.ir_flow import Branch, DigitalInput, If
from olp.posts import find_post
from olp.posts.rows import spell_column
from olp.posts.ur import UrPost, _blends_filter
from olp.posts.view import Names, PostStep, ProgramView, RowColumns, build_steps
from tests.compile_once import CompileOnce

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"


class _StepPath(UrPost):
    """The URScript post without its column writer: a toolpath's rows are made into steps."""

    COLUMNS = False


def _csv(tmp_path: Path, rows: int, chunk_bytes: int = 1 << 30, zone: float = 0.0) -> ir.Program:
    t = np.linspace(0.0, 4.0 * np.pi, rows)
    xyz = np.c_[100 + 60 * np.cos(t), 60 * np.sin(t), 20 + np.linspace(0.0, 30.0, rows)]
    csv = tmp_path / "helix.csv"
    np.savetxt(csv, xyz, fmt="%.4f", delimiter=",", header="x,y,z", comments="")
    options = CsvOptions(
        frame="table", orientation=(180.0, 0.0, 180.0), chunk_bytes=chunk_bytes, zone=zone
    )
    return olp.parse(csv, station=olp.load_station(CELL), options=options).program


def _varied(tmp_path: Path, rows: int = 400) -> ir.Program:
    """One toolpath node with speeds changing every few rows, zones of which many are capped
    (larger than half the distance between the points), a path acceleration; before it a move
    with another tool and frame and a comment, after it a wait and a LIN."""
    program = _csv(tmp_path, rows)
    station = olp.load_station(CELL)
    (node,) = [n for n in program.instructions if isinstance(n, ir.LinearPath)]
    k = np.arange(len(node))
    node = dataclasses.replace(
        node,
        speeds=0.02 + 0.005 * ((k // 7) % 5),
        zones=0.004 * ((k // 5) % 3),
        angular=np.radians(45.0),
        acceleration=2.5,
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


def _several(tmp_path: Path) -> ir.Program:
    """A toolpath read as several nodes (small chunks), 1 mm zones, and a call between two of
    them (the robot stops before it) with another tool after it."""
    program = _csv(tmp_path, 300, chunk_bytes=2048, zone=1.0)
    nodes = list(program.instructions)
    at = [k for k, n in enumerate(nodes) if isinstance(n, ir.LinearPath)]
    assert len(at) > 2
    station = olp.load_station(CELL)
    spindle = station.tools["spindle"]
    assert spindle.pose is not None
    other = ir.Tool(name="long", pose=spindle.pose @ transl(0.0, 0.0, 0.02))
    second = nodes[at[1]]
    assert isinstance(second, ir.LinearPath)
    nodes[at[1]] = dataclasses.replace(second, tool=other)
    nodes.insert(at[1], ir.Call(name="Clean"))
    return program.replace_instructions(nodes)


def _builds(program: ir.Program, post: UrPost | None = None) -> tuple[Any, Any, Any]:
    """The program built by the column writer, the step path and the per-move templates."""
    station = olp.load_station(CELL)
    ur = find_post("ur")
    assert isinstance(ur, UrPost)
    manifest = ur.manifest
    templates = UrPost(dataclasses.replace(manifest, rows=False))
    with CompileOnce():
        return (
            olp.build(station, program, post or ur),
            olp.build(station, program, _StepPath(manifest)),
            olp.build(station, program, templates),
        )


def _forbidden(*args: object) -> None:
    raise AssertionError("a toolpath's rows were made into steps")


PROGRAMS = [
    (_varied, ("set_tcp(", "a=2.50000, v=0.03000", "# toolpath", "sleep(0.500)")),
    (_several, ("  Clean()\n  set_tcp(", "r=0.001000", "r=0.000000")),
]
"""Each program, and what it must make the post write (the rows exercise those paths)."""


@pytest.mark.parametrize(("make", "pieces_written"), PROGRAMS)
def test_a_toolpath_is_written_from_columns_as_the_step_path_writes_it(
    make: Any, pieces_written: tuple[str, ...], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    program = make(tmp_path)
    columns, steps, templates = _builds(program)
    assert columns.ok, [d.format() for d in columns.diagnostics]
    assert columns.files == steps.files == templates.files
    shown = [d.format() for d in columns.diagnostics]
    assert shown == [d.format() for d in steps.diagnostics]
    assert shown == [d.format() for d in templates.diagnostics]
    assert any(d.kind == "blend_capped" for d in columns.diagnostics)
    text = "".join(columns.files.values())
    assert all(piece in text for piece in pieces_written)
    assert text.count("set_tcp(") == 3  # the approach's tool, the other tool, the first again
    # The column build made no step per row: the same build again, with that forbidden.
    monkeypatch.setattr(PathBlock, "steps", _forbidden)
    monkeypatch.setattr(CompiledProgram, "flat", _forbidden)
    again = olp.build(olp.load_station(CELL), program, find_post("ur"))
    assert again.files == columns.files
    assert [d.format() for d in again.diagnostics] == shown


def test_capped_blends_of_a_toolpath_are_written_as_arrays(tmp_path: Path) -> None:
    """The radii written are the capped ones, and the capped toolpath is still one node."""
    program = _varied(tmp_path, 60)
    columns = _builds(program)[0]
    capped = [d for d in columns.diagnostics if d.kind == "blend_capped"]
    assert len(capped) > 5
    asked = next(n for n in program.instructions if isinstance(n, ir.LinearPath))
    node = next(n for n in columns.compiled.program.instructions if isinstance(n, ir.LinearPath))
    assert len(node) == len(asked) and np.sum(node.zones < asked.zones) == len(capped)
    (script,) = columns.files.values()
    radii = [line.rsplit("r=", 1)[1] for line in script.splitlines() if "movel(" in line]
    written = [r.rstrip(")") for r in radii[1 : 1 + len(node)]]
    assert written == spell_column(node.zones, 6).tolist()


@pytest.mark.parametrize("rows", [[4, 9], [0]])
def test_a_number_the_column_writer_cannot_write_is_an_error_on_its_row(
    rows: list[int], tmp_path: Path
) -> None:
    program = _varied(tmp_path, 40)
    nodes = list(program.instructions)
    at = next(k for k, n in enumerate(nodes) if isinstance(n, ir.LinearPath))
    node = nodes[at]
    assert isinstance(node, ir.LinearPath)
    speeds = np.array(node.speeds)
    speeds[rows] = 1e-9
    nodes[at] = dataclasses.replace(node, speeds=speeds, acceleration=1e-9)
    columns, _, templates = _builds(program.replace_instructions(nodes))
    errors = [(d.kind, d.index, d.message) for d in columns.diagnostics if d.severity == "error"]
    assert {index for _, index, _ in errors} == set(range(at, at + len(node)))  # a= on every row
    assert [m for _, i, m in errors if "speed" in m] == [
        m for _, i, m in errors if i - at in rows and "speed" in m
    ]
    assert len([e for e in errors if "speed" in e[2]]) == len(rows)
    assert errors == [
        (d.kind, d.index, d.message) for d in templates.diagnostics if d.severity == "error"
    ]
    assert columns.files == templates.files == {}


def test_a_toolpath_inside_control_flow_keeps_its_block(tmp_path: Path) -> None:
    """Control flow is written from steps (no columns), and the blend before a block
    boundary is stopped in the toolpath's arrays: the IF's body stays conditional."""
    program = _csv(tmp_path, 30)
    (node,) = [n for n in program.instructions if isinstance(n, ir.LinearPath)]
    node = node.with_zones(0.002)
    rest = [n for n in program.instructions if not isinstance(n, ir.LinearPath)]
    after = node.move(0)
    branch = Branch(condition=DigitalInput(index=1), body=(node,))
    flow = program.replace_instructions([*rest, If(branches=(branch,)), after])
    as_moves = Branch(condition=branch.condition, body=tuple(node))
    moves = program.replace_instructions([*rest, If(branches=(as_moves,)), after])
    columns, steps, _ = _builds(flow)
    assert columns.ok, [d.format() for d in columns.diagnostics]
    assert columns.files == steps.files == olp.build(olp.load_station(CELL), moves, "ur").files
    lines = [line.strip() for line in "".join(columns.files.values()).splitlines()]
    start = lines.index("if get_digital_in(1):")
    end = lines.index("end", start)
    assert sum(line.startswith("movel(") for line in lines[start:end]) == len(node)
    assert lines[end] == "end" and lines[end - 1].endswith("r=0.000000)")
    assert lines[end - 2].endswith("r=0.002000)")
    stopped = [d for d in columns.diagnostics if d.kind == "blend_stopped"]
    assert [d.index for d in stopped] == [len(rest) + len(node) - 1]
    prepared = columns.compiled.program.instructions[len(rest)]
    assert isinstance(prepared, If)
    (kept,) = prepared.branches[0].body
    assert isinstance(kept, ir.LinearPath) and kept.zones[-1] == 0.0


def test_the_blend_radii_filter_reads_a_toolpath_as_columns(tmp_path: Path) -> None:
    """``steps | ur_blend_radii(station)`` of a folder made before gives the same radii for a
    file's view with a toolpath as :class:`RowColumns` as for its steps one by one."""
    station = olp.load_station(CELL)
    compiled = olp.compile(_varied(tmp_path, 50), station)
    post = find_post("ur")
    view = ProgramView(compiled, post)
    items = view.unit_steps(
        pieces(compiled.steps.blocks, [(0, len(compiled.steps))])[0],  # type: ignore[attr-defined]
        view.allocate(Names(post.NAME_RULE, ())),
    )
    assert any(isinstance(i, RowColumns) for i in items)
    one_by_one = build_steps(compiled, post)
    assert all(isinstance(s, PostStep) for s in one_by_one)
    assert _blends_filter(post, items, station) == _blends_filter(post, one_by_one, station)
    motions = [s for s in one_by_one if s.joints is not None]
    assert len(_blends_filter(post, items, station)) == len(motions) > 50


@pytest.mark.parametrize("decimals", range(9))
def test_numbers_at_and_next_to_ties_are_spelled_as_python_spells_them(decimals: int) -> None:
    """Columns of 6 to 8 decimals (UR's positions) take another way through the tables; and a
    value whose product with ``10**decimals`` rounds to a half is rounded by the product's
    exact error (CSV coordinates in mm with 4 decimals are such halves in metres)."""
    rng = np.random.default_rng(11)
    ties = np.round(rng.normal(0.0, 10.0, 10_000), decimals) + 0.5 * 10.0**-decimals
    mm = np.round(rng.normal(0.0, 300.0, 10_000), 4) / 1000.0
    values = np.concatenate(
        [
            rng.normal(0.0, 2.0, 10_000),
            ties,
            np.nextafter(ties, np.inf),
            np.nextafter(ties, -np.inf),
            mm,
            [0.0, -0.0, -4e-9, 1e-9, 123.4567895, 0.5, -0.5, 2.5, -2.5],
        ]
    )
    expected = [f"{v:.{decimals}f}" for v in values.tolist()]
    expected = [t[1:] if t.startswith("-") and float(t) == 0.0 else t for t in expected]
    assert spell_column(values, decimals).tolist() == expected


def test_every_entry_of_the_spelling_tables_is_python_s_spelling() -> None:
    """The integers and fractions the column spelling looks up (made from tables of digits)."""
    whole = np.arange(140_000, dtype=np.float64)
    assert spell_column(whole, 0).tolist() == [str(k) for k in range(140_000)]
    fifths = np.arange(100_000) / 1e5 + 7.0
    assert spell_column(fifths, 5).tolist() == [f"{v:.5f}" for v in fifths.tolist()]
