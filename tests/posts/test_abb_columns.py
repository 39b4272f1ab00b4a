"""The RAPID post writes a toolpath from its columns (:class:`olp.posts.view.RowColumns`: no
step per row) exactly as its templates write the same moves one by one: the same files, byte
for byte, the same diagnostics in the same order; and its confdata columns are the confdata the
per-step computation gives."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.compiled import BlockRows, CompiledProgram, PathBlock, items_of
from olp.frontends.bundled import CsvOptions
from olp.posts import find_post
from olp.posts.abb import AbbPost, first_uses
from olp.posts.base import Post
from olp.posts.rows import spell_column
from olp.posts.view import Names, ProgramView, RowColumns
from olp.vendors.abb import confdata
from tests.compile_once import CompileOnce
from tests.posts.test_row_columns import PART_LIMITS, _forbidden, _post, _toolpath

REPO = Path(__file__).resolve().parents[2]
KR6_CELL = REPO / "stations" / "kr6_milling_cell.yaml"
ABB_CELL = REPO / "stations" / "abb_irb120_pick_cell.yaml"


# --------------------------------------------------------------------------------------------
# confdata as columns


def _boundary_joints(rng: np.random.Generator, rows: int) -> np.ndarray:
    """Joint rows (rows, 6) rad with axes 1, 4 and 6 on, just below and just above multiples
    of 90° (the quadrant boundaries of cf1, cf4, cf6) and axis 5 around 0 (the cfx wrist
    bit)."""
    q = rng.uniform(-np.pi, np.pi, (rows, 6))
    quarters = rng.integers(-4, 5, (rows, 3)) * (np.pi / 2)
    offsets = rng.choice([0.0, 1e-13, -1e-13, 1e-11, -1e-11, 1e-9, -1e-9, 1e-6, -1e-6], (rows, 3))
    q[:, [0, 3, 5]] = quarters + offsets
    q[::3, 4] = rng.choice([0.0, -0.0, 1e-12, -1e-12, 1e-6, -1e-6], q[::3, 4].shape)
    return q


@pytest.mark.parametrize("cell", [ABB_CELL, KR6_CELL])
def test_confdata_columns_are_the_confdata_of_each_step(cell: Path) -> None:
    robot = olp.load_station(cell).robot
    rng = np.random.default_rng(11)
    joints = np.concatenate(
        [rng.uniform(-2 * np.pi, 2 * np.pi, (2000, 6)), _boundary_joints(rng, 3000)]
    )
    post = find_post("abb")
    columns = post.step_columns(robot, joints)["confdata"]
    per_step = [v["confdata"] for v in post.step_values(robot, joints)]
    one_by_one = [tuple(int(c) for c in confdata(robot, q)) for q in joints]
    assert columns.shape == (len(joints), 4)
    assert [tuple(row) for row in columns.tolist()] == per_step == one_by_one
    # the boundaries are really crossed: several quadrants on every axis
    assert all(len(set(columns[:, k].tolist())) >= 8 for k in range(3))
    assert set(columns[:, 3].tolist()) >= {0, 1}


def test_a_row_of_columns_is_the_step_the_templates_see(tmp_path: Path) -> None:
    """:meth:`RowColumns.at` (the step of an error's row) holds the confdata as
    :meth:`AbbPost.step_values` gives it: a tuple of four integers."""
    program = _toolpath(50, tmp_path)
    station = olp.load_station(KR6_CELL)
    post = find_post("abb")
    compiled = olp.compile(program, station)
    view = ProgramView(compiled, post)
    flat = ProgramView(compiled.flat(), post)
    (block,) = [b for b in items_of(compiled.steps) if isinstance(b, PathBlock)]
    allocation = view.allocate(Names(post.NAME_RULE, ()))
    (rows,) = view.unit_steps([BlockRows(block, 0, len(block))], allocation)
    assert isinstance(rows, RowColumns)
    for k in (0, 17, len(block) - 1):
        expected = flat.motions[block.start + k].vendor
        assert rows.at(k).vendor == expected
        assert isinstance(expected["confdata"], tuple) and len(expected["confdata"]) == 4


# --------------------------------------------------------------------------------------------
# Text: columns against the templates


def _both(
    post: Post, station: olp.Station, program: ir.Program
) -> tuple[olp.BuildResult, olp.BuildResult]:
    """The program built by the post as it is, and by the same templates without the row
    writer (each move a template pass)."""
    manifest = post.manifest
    template = type(post)(dataclasses.replace(manifest, rows=False))
    with CompileOnce():
        columns = olp.build(station, program, type(post)(manifest))
        return columns, olp.build(station, program, template)


def _assert_same(
    post: Post,
    station: olp.Station,
    program: ir.Program,
    monkeypatch: pytest.MonkeyPatch,
    ok: bool = True,
) -> dict[str, str]:
    columns, template = _both(post, station, program)
    assert columns.ok == ok, [d.format() for d in columns.diagnostics]
    assert columns.files == template.files
    assert [d.format() for d in columns.diagnostics] == [d.format() for d in template.diagnostics]
    # the column build made no step per row: the same build again, with that forbidden
    with monkeypatch.context() as m:
        m.setattr(PathBlock, "steps", _forbidden)
        m.setattr(CompiledProgram, "flat", _forbidden)
        again = olp.build(station, program, type(post)(post.manifest))
    assert again.files == columns.files
    assert [d.format() for d in again.diagnostics] == [d.format() for d in columns.diagnostics]
    return dict(columns.files)


def test_a_toolpath_with_changes_is_written_by_columns(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Custom speeds with an orientation limit (``_o45``), custom zones, a path acceleration,
    a move with another tool and frame before the toolpath; more rows than a file holds (a
    smaller file limit): split in parts."""
    station = olp.load_station(KR6_CELL)
    post = _post("abb", PART_LIMITS)
    files = _assert_same(post, station, _toolpath(800, tmp_path), monkeypatch)
    assert len(files) > 2
    text = "".join(files.values())
    for piece in ("_o45", "PathAccLim TRUE", "LOCAL CONST zonedata z", "\\WObj:=fixture"):
        assert piece in text


def _predefined(program: ir.Program) -> ir.Program:
    """The toolpath with predefined speeds (v20, v100) and zones (fine, z1, z5) and one custom
    of each, no orientation speed and no acceleration."""
    nodes = list(program.instructions)
    at = next(k for k, n in enumerate(nodes) if isinstance(n, ir.LinearPath))
    node = nodes[at]
    assert isinstance(node, ir.LinearPath)
    k = np.arange(len(node))
    speeds = np.choose((k // 9) % 3, [0.02, 0.1, 0.02117])
    zones = np.choose((k // 4) % 4, [0.0, 0.001, 0.005, 0.0125])
    nodes[at] = dataclasses.replace(
        node, speeds=speeds, zones=zones, angular=None, acceleration=None, angular_acceleration=None
    )
    return program.replace_instructions(nodes)


def test_predefined_speed_and_zone_data_by_columns(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    station = olp.load_station(KR6_CELL)
    program = _predefined(_toolpath(400, tmp_path))
    files = _assert_same(find_post("abb"), station, program, monkeypatch)
    text = "".join(files.values())
    for piece in (", v20, z1,", ", v100, z5,", ", v21_17, z12_5,", ", fine, "):
        assert piece in text
    # the lead move (another tool and frame) keeps the path acceleration; the toolpath unsets it
    assert "PathAccLim FALSE, FALSE;" in text


def _abb_toolpaths(tmp_path: Path) -> ir.Program:
    """On the IRB 120 cell: two toolpaths in two frames (conveyor; table, which is wobj0) with a
    wait between them, the second with a path acceleration and another tool."""
    station = olp.load_station(ABB_CELL)
    t = np.linspace(0.0, 4.0 * np.pi, 700)
    xyz = np.c_[40 * np.cos(t), 40 * np.sin(t), 30 + np.linspace(0.0, 20.0, t.size)]
    csv = tmp_path / "circle.csv"
    programs = []
    for frame, offset in (("conveyor", (0.0, 0.0, 0.0)), ("table", (300.0, 50.0, 150.0))):
        np.savetxt(csv, xyz + offset, fmt="%.4f", delimiter=",", header="x,y,z", comments="")
        # tilted: with the tool straight down axis 4 stays at ~1e-16 rad, which the timing
        # pass's divisions overflow on (a warning, an error under pytest)
        options = CsvOptions(frame=frame, orientation=(165.0, 10.0, 180.0), zone=1.0)
        programs.append(olp.parse(csv, station=station, options=options).program)
    (node,) = [n for n in programs[1].instructions if isinstance(n, ir.LinearPath)]
    suction = station.tools["suction"]
    assert suction.pose is not None
    second = dataclasses.replace(
        node, tool=ir.Tool(name="gripper", pose=suction.pose), acceleration=1.5
    )
    first = list(programs[0].instructions)
    return programs[0].replace_instructions([*first, ir.Wait(seconds=0.2), second])


def test_toolpaths_on_an_abb_cell_by_columns(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    station = olp.load_station(ABB_CELL)
    files = _assert_same(find_post("abb"), station, _abb_toolpaths(tmp_path), monkeypatch)
    text = "".join(files.values())
    for piece in ("suction\\WObj:=conveyor;", "gripper;", "PathAccLim TRUE"):
        assert piece in text


def test_split_parts_by_columns(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A smaller file limit: the toolpaths are cut between many parts."""
    folder = tmp_path / "abb_small"
    shutil.copytree(find_post("abb").manifest.folder, folder)
    text = (folder / "post.yaml").read_text()
    (folder / "post.yaml").write_text(
        text.replace("max_motions_per_file: 5000", "max_motions_per_file: 333")
    )
    post = find_post(str(folder))
    assert isinstance(post, AbbPost)
    station = olp.load_station(ABB_CELL)
    files = _assert_same(post, station, _abb_toolpaths(tmp_path), monkeypatch)
    assert len(files) > 5


# --------------------------------------------------------------------------------------------
# Errors on their rows


def _with_node(program: ir.Program, **changes: object) -> ir.Program:
    nodes = list(program.instructions)
    at = next(k for k, n in enumerate(nodes) if isinstance(n, ir.LinearPath))
    nodes[at] = dataclasses.replace(nodes[at], **changes)
    return program.replace_instructions(nodes)


def test_speeds_and_zones_that_cannot_be_written_are_errors_on_their_rows(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    program = _toolpath(60, tmp_path)
    (node,) = [n for n in program.instructions if isinstance(n, ir.LinearPath)]
    speeds, zones = np.array(node.speeds), np.array(node.zones)
    speeds[[4, 9, 30]] = 1e-9  # written as 0 mm/s
    zones[[7, 31]] = 1e9  # beyond a RAPID num
    program = _with_node(program, speeds=speeds, zones=zones)
    station = olp.load_station(KR6_CELL)
    _assert_same(find_post("abb"), station, program, monkeypatch, ok=False)
    columns = olp.build(station, program, "abb")
    start = next(k for k, n in enumerate(program.instructions) if isinstance(n, ir.LinearPath))
    rows = {d.index - start for d in columns.diagnostics if d.kind == "number"}
    assert rows == {4, 7, 9, 30, 31}


def test_a_path_acceleration_that_cannot_be_written_is_an_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    program = _with_node(_toolpath(30, tmp_path), acceleration=0.05)  # PathAccLim: >= 0.1
    _assert_same(find_post("abb"), olp.load_station(KR6_CELL), program, monkeypatch, ok=False)


# --------------------------------------------------------------------------------------------
# Pieces


def test_first_uses() -> None:
    values, index = first_uses(np.array([0.5, 0.2, 0.5, -0.0, 0.0, 0.2, 0.7]))
    assert values.tolist() == [0.5, 0.2, 0.0, 0.7]
    assert index.tolist() == [0, 1, 0, 2, 2, 1, 3]


def test_check_rows_says_of_a_toolpath_what_check_instruction_says_of_its_moves(
    tmp_path: Path,
) -> None:
    station = olp.load_station(KR6_CELL)
    compiled = olp.compile(_toolpath(40, tmp_path), station)
    post = find_post("abb")
    blocks = [b for b in items_of(compiled.steps) if isinstance(b, PathBlock)]
    assert blocks
    for block in blocks:
        rows = [d for s in block.steps() for d in post.check_instruction(s, compiled)]
        assert post.check_rows(block, compiled) == rows


def test_the_speed_names_of_columns_are_those_of_speed_name(tmp_path: Path) -> None:
    """Many distinct speeds, some a hair from a predefined one (v100: 0.1 m/s)."""
    rng = np.random.default_rng(5)
    program = _toolpath(321, tmp_path)
    (node,) = [n for n in program.instructions if isinstance(n, ir.LinearPath)]
    near = 0.1 + rng.choice([-1e-9, 0.0, 1e-7], 20)
    speeds = np.concatenate([np.round(rng.uniform(0.001, 0.25, len(node) - near.size), 5), near])
    program = _with_node(program, speeds=speeds, angular=None)
    station = olp.load_station(KR6_CELL)
    columns, template = _both(find_post("abb"), station, program)
    assert columns.ok, [d.format() for d in columns.diagnostics if d.severity == "error"]
    assert columns.files == template.files
    assert ", v100, " in "".join(columns.files.values())


@pytest.mark.parametrize("decimals", [6, 7, 9, 10, 11])
def test_many_decimals_are_spelled_as_each_number_is(decimals: int) -> None:
    """Decimals beyond the one-table look-up (ABB's quaternions: 9) are spelled in two parts."""
    rng = np.random.default_rng(decimals)
    values = np.concatenate(
        [
            rng.uniform(-1.0, 1.0, 20_000),
            np.round(rng.uniform(-1.0, 1.0, 5_000), decimals),
            np.round(rng.normal(0.0, 100.0, 5_000), decimals - 1) + 0.5 * 10.0**-decimals,
            [0.0, -0.0, 1.0, -1.0, 1e-12, -1e-12, 0.5, 10.0**-decimals],
        ]
    )
    expected = [f"{v:.{decimals}f}" for v in values.tolist()]
    expected = [t[1:] if t.startswith("-") and float(t) == 0.0 else t for t in expected]
    assert spell_column(values, decimals).tolist() == expected
