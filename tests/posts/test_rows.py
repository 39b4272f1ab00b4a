"""A post's row writer (:mod:`olp.posts.rows`) writes runs of linear moves exactly as its
templates write them one by one: the same files, byte for byte, and the same errors on the same
lines. Each program is rendered both ways (the folder's ``rows: true``, and the same folder with
``rows: false``)."""

from __future__ import annotations

import dataclasses
import itertools
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.frontends.bundled import CsvOptions
from olp.geometry import inv, transl
from olp.posts import find_post
from olp.posts.base import Post
from olp.posts.rows import PostRows, group_rows
from olp.posts.view import build_steps

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
ROW_POSTS = ["kuka", "ur", "abb", "fanuc"]  # posts with a row writer
PIECES = {
    "kuka": ("$BASE = ", "$TOOL = ", "$VEL.ORI1", "$APO.CDIS", "C_DIS", "WAIT SEC", "; halfway"),
    "ur": ("set_tcp(", "movel(", "r=0.001000", "v=0.03000", "sleep(", "# halfway"),
    "fanuc": ("UFRAME_NUM=", "UTOOL_NUM=", "mm/sec CNT1", "CONFIG : '", "WAIT", "!halfway"),
    "abb": ("LOCAL CONST robtarget", "MoveL ", "\\WObj:=", "_o45", "WaitTime", "! halfway"),
}
"""What the varied program must make each post write (the rows exercise those paths)."""


def _moves(rows: int, tmp_path: Path) -> ir.Program:
    t = np.linspace(0.0, 2.0 * np.pi, rows)
    xyz = np.c_[100 + 60 * np.cos(t), 60 * np.sin(t), 20 + np.linspace(0.0, 10.0, rows)]
    csv = tmp_path / "path.csv"
    np.savetxt(csv, xyz, fmt="%.4f", delimiter=",", header="x,y,z", comments="")
    options = CsvOptions(frame="table", orientation=(180.0, 0.0, 180.0))
    program = olp.parse(csv, station=olp.load_station(CELL), options=options).program
    return program.replace_instructions(list(program))


def _varied(program: ir.Program) -> ir.Program:
    """Speeds, zones, an orientation speed, another frame and an inline tool within the run,
    and a comment and a wait that break it."""
    station = olp.load_station(CELL)
    table, spindle = station.frames["table"], station.tools["spindle"]
    assert table.pose is not None
    other = ir.Frame(name="fixture", pose=table.pose @ transl(0.0, 0.0, 0.01))
    inline = ir.Tool(name="TOOL_DATA[3]", pose=spindle.pose, number=3)
    out: list[ir.Node] = []
    for k, node in enumerate(program.instructions):
        if isinstance(node, ir.LinearMove) and isinstance(node.target, ir.CartesianTarget):
            move = node.with_speed(linear=0.02 + 0.01 * (k // 7)).with_zone(0.001 * (k % 3))
            if k % 11 == 0:
                move = move.with_speed(angular=np.radians(45.0))
            if 20 <= k < 30:
                pose = inv(other.pose) @ table.pose @ node.target.pose  # type: ignore[operator]
                move = dataclasses.replace(move, target=ir.CartesianTarget(pose=pose), frame=other)
            if 30 <= k < 35:
                move = move.with_tool(inline)
            out.append(move)
            if k == 40:
                out.append(ir.Comment(text="halfway"))
            if k == 45:
                out.append(ir.Wait(seconds=0.5))
        else:
            out.append(node)
    return program.replace_instructions(out)


def _both(
    post_name: str, program: ir.Program, **options: object
) -> tuple[olp.BuildResult, olp.BuildResult]:
    station = olp.load_station(CELL)
    post = find_post(post_name)
    if options:
        manifest = dataclasses.replace(post.manifest, options={**post.manifest.options, **options})
        post = type(post)(manifest)
    assert post.rows_enabled(), "the bundled folder must use its row writer"
    template = type(post)(dataclasses.replace(post.manifest, rows=False))
    return olp.build(station, program, post), olp.build(station, program, template)


@pytest.mark.parametrize("post", ROW_POSTS)
def test_rows_are_written_as_the_templates_write_them(post: str, tmp_path: Path) -> None:
    program = _varied(_moves(60, tmp_path))
    rows, template = _both(post, program)
    assert rows.ok, [d.format() for d in rows.diagnostics]
    assert rows.files == template.files
    text = "".join(rows.files.values())
    for piece in PIECES[post]:
        assert piece in text


def test_kuka_named_points_rows_are_written_as_the_templates_write_them(tmp_path: Path) -> None:
    """``points: dat``: the LINs name their points and the .dat declares them (krl_rows_dat)."""
    rows, template = _both("kuka", _varied(_moves(40, tmp_path)), points="dat")
    assert rows.ok, [d.format() for d in rows.diagnostics]
    assert rows.files == template.files
    dat = next(text for name, text in rows.files.items() if name.endswith(".dat"))
    src = next(text for name, text in rows.files.items() if name.endswith(".src"))
    assert "DECL E6POS XP40={X " in dat and "LIN XP40" in src


# Fanuc writes an L speed below 1 mm/sec as 1mm/sec with a warning (speed_raised), no error.
@pytest.mark.parametrize("post", ["kuka", "ur", "abb"])
def test_a_number_the_writer_cannot_write_is_an_error_on_its_row(post: str, tmp_path: Path) -> None:
    program = _moves(12, tmp_path)
    slow = [
        m.with_speed(linear=1e-9) if k in (4, 9) and isinstance(m, ir.LinearMove) else m
        for k, m in enumerate(program.instructions)
    ]
    rows, template = _both(post, program.replace_instructions(slow))
    errors = [(d.kind, d.index, d.message) for d in rows.diagnostics if d.severity == "error"]
    assert [index for _, index, _ in errors] == [4, 9]
    assert errors == [
        (d.kind, d.index, d.message) for d in template.diagnostics if d.severity == "error"
    ]


def test_runs_of_linear_moves_are_grouped_and_nothing_else(tmp_path: Path) -> None:
    station = olp.load_station(CELL)
    compiled = olp.compile(_varied(_moves(50, tmp_path)), station)
    steps = build_steps(compiled, find_post("kuka"))
    grouped = group_rows(steps)
    flat = [s for item in grouped for s in (item.steps if isinstance(item, PostRows) else (item,))]
    assert flat == steps
    assert all(
        isinstance(item, PostRows) or item.kind != "linear" for item in grouped
    )  # maximal runs: no linear move is left alone between rows
    kinds = [item.kind for item in grouped]
    assert "rows" in kinds and all(a != "rows" or b != "rows" for a, b in itertools.pairwise(kinds))


def test_a_folder_without_rows_gets_one_step_per_move() -> None:
    post = find_post("kuka")
    plain = type(post)(dataclasses.replace(post.manifest, rows=False))
    assert post.rows_enabled() and not plain.rows_enabled()
    assert not Post(dataclasses.replace(post.manifest)).rows_enabled()  # no row writer
