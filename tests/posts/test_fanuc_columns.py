"""The LS post writes a toolpath's rows from columns (:mod:`olp.posts.fanuc_rows`, no step
per row): the same files as its templates write move by move, byte for byte, with the same
diagnostics in the same order, on programs that change tool and frame around and inside a
toolpath, mix CNT and FINE, go below the slowest LS speed, hold rows no CONFIG selects alone
(written as joints), position in a user frame and in World, and are split into parts."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import olp
from olp import ir
from olp.compiled import CompiledProgram, PathBlock, Step, StepBlocks
from olp.frontends.bundled import CsvOptions
from olp.geometry import inv, transl
from olp.posts import find_post
from olp.posts.base import Post
from olp.posts.fanuc import NUMBERS, FanucPost
from olp.posts.numbers import NumberFormat
from olp.posts.render import RenderError
from olp.station.model import Station
from olp.transforms.limits import SplitLimits
from tests.compile_once import CompileOnce

REPO = Path(__file__).resolve().parents[2]
KUKA_CELL = REPO / "stations" / "kr6_milling_cell.yaml"
FANUC_CELL = REPO / "stations" / "fanuc_m20ia_weld_cell.yaml"
PART_LIMITS = SplitLimits(max_instructions=300)
"""A file limit below the helix's rows, so the toolpath is cut between parts: the post's own
3000 would need thousands of rows (the build time grows with the rows)."""


def _forbidden(*args: object) -> None:
    raise AssertionError("a toolpath's rows were made into steps")


def _posts(
    post: Post | None = None, limits: SplitLimits | None = None, **options: Any
) -> tuple[Post, Post, Post]:
    """The post three ways: columns (the bundled folder), rows without columns (the PostRows
    writer) and the templates alone (``rows: false``); ``limits`` instead of the post's."""
    post = post or find_post("fanuc")
    manifest = dataclasses.replace(post.manifest, options={**post.manifest.options, **options})
    if limits is not None:
        manifest = dataclasses.replace(manifest, limits=limits)
    cls = type(post)
    rows_only = type("RowsOnly", (cls,), {"COLUMNS": False})
    return cls(manifest), rows_only(manifest), cls(dataclasses.replace(manifest, rows=False))


# --------------------------------------------------------------------------------------------
# A helix toolpath built from a CSV, as a user builds it


def _helix(rows: int, tmp_path: Path) -> ir.Program:
    """A helix of ``rows`` rows in the table frame (UF 1), speeds and zones changing every few
    rows (FINE, CNT1, CNT2; 20..40 mm/sec, and rows at 0.4 mm/sec, below LS's least); before
    it a move in an unnumbered frame (UF 0) with tool 2, a comment, and after it a wait and a
    move with tool 2 again."""
    station = olp.load_station(KUKA_CELL)
    t = np.linspace(0.0, 8.0 * np.pi, rows)
    xyz = np.c_[100 + 60 * np.cos(t), 60 * np.sin(t), 20 + np.linspace(0.0, 30.0, rows)]
    csv = tmp_path / "helix.csv"
    np.savetxt(csv, xyz, fmt="%.4f", delimiter=",", header="x,y,z", comments="")
    options = CsvOptions(frame="table", orientation=(180.0, 0.0, 180.0), chunk_bytes=1 << 30)
    program = olp.parse(csv, station=station, options=options).program
    (node,) = [n for n in program.instructions if isinstance(n, ir.LinearPath)]
    k = np.arange(len(node))
    speeds = 0.02 + 0.005 * ((k // 7) % 5)
    speeds[k % 97 == 5] = 0.0004
    node = dataclasses.replace(node, speeds=speeds, zones=0.001 * ((k // 5) % 3))
    table, spindle = station.frames["table"], station.tools["spindle"]
    assert table.pose is not None
    fixture = ir.Frame(name="fixture", pose=table.pose @ transl(0.0, 0.0, 0.01))
    probe = ir.Tool(name="probe", pose=spindle.pose, number=2)
    first = node.move(0)
    lead = dataclasses.replace(first, frame=fixture, tool=probe)
    head = [lead, ir.Comment(text="toolpath")]
    tail = [ir.Wait(seconds=0.5), node.move(len(node) - 1).with_zone(0.0).with_tool(probe)]
    rest = [n for n in program.instructions if not isinstance(n, ir.LinearPath)]
    return program.replace_instructions([*rest, *head, node, *tail])


def test_a_helix_is_written_by_columns_as_the_templates_write_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    count = 700
    program = _helix(count, tmp_path)
    station = olp.load_station(KUKA_CELL)
    with CompileOnce():
        results = [olp.build(station, program, post) for post in _posts(limits=PART_LIMITS)]
    columns, rows, template = results
    assert columns.ok, [d.format() for d in columns.diagnostics]
    assert len(columns.files) == 4  # split in three parts and a main: the toolpath is cut
    text = "".join(columns.files.values())
    for piece in ("UFRAME_NUM=0 ;", "UFRAME_NUM=1 ;", "UTOOL_NUM=2 ;", "CNT2    ;", "FINE    ;"):
        assert piece in text
    assert " 1mm/sec " in text and "\tUF : 1, UT : 1,\t\tCONFIG : '" in text
    for other in (rows, template):
        assert columns.files == other.files
        assert [d.format() for d in columns.diagnostics] == [d.format() for d in other.diagnostics]
    raised = [d for d in columns.diagnostics if d.kind == "speed_raised"]
    assert len(raised) == len(range(5, count, 97))
    # The column build made no step per row: the same build again, with that forbidden.
    monkeypatch.setattr(PathBlock, "steps", _forbidden)
    monkeypatch.setattr(CompiledProgram, "flat", _forbidden)
    again = olp.build(station, program, _posts(limits=PART_LIMITS)[0])
    assert again.files == columns.files
    assert [d.format() for d in again.diagnostics] == [d.format() for d in columns.diagnostics]


# --------------------------------------------------------------------------------------------
# A compiled program made by hand: rows with chosen joints on the M-20iA


@dataclasses.dataclass(frozen=True)
class Run:
    """A toolpath's rows: planned joints (n, 6) rad in ``frame`` with ``tool``."""

    joints: np.ndarray
    frame: ir.Frame
    tool: ir.Tool
    speeds: np.ndarray
    zones: np.ndarray


def _weld() -> Station:
    return olp.load_station(FANUC_CELL)


def _sweep(count: int, seed: int, odd: bool = True) -> np.ndarray:
    """Planned joints (count, 6) rad near the torch-down pose, with (``odd``) rows no CONFIG
    selects alone: J3 at 200° (J3 - 360° also fits the M-20iA's range) and J5 at 0 (a wrist
    singularity)."""
    rng = np.random.default_rng(seed)
    q = np.radians([0.0, 10.0, -20.0, 0.0, -60.0, 0.0]) + rng.normal(0.0, 0.2, (count, 6))
    if odd:
        q[3::11, 2] = np.radians(200.0)
        q[7::13, 4] = 0.0
    return q


def _row_node(robot: Any, run: Run, first_line: int) -> ir.LinearPath:
    assert run.frame.pose is not None and run.tool.pose is not None
    poses = inv(run.frame.pose) @ robot.flange_poses(run.joints) @ run.tool.pose
    n = len(run.joints)
    return ir.LinearPath(
        poses=poses,
        speeds=run.speeds,
        zones=run.zones,
        lines=np.arange(first_line, first_line + n),
        tool=run.tool,
        frame=run.frame,
        source="rows.csv",
    )


def _handmade(runs: list[Run]) -> CompiledProgram:
    """A program of toolpaths (one block each) with a joint move between them and a comment
    and a wait after the first, compiled by hand with the runs' joints."""
    station = _weld()
    robot = station.robot
    items: list[Step | PathBlock] = []
    nodes: list[ir.Instruction | ir.LinearPath] = []
    index, line = 0, 1
    for k, run in enumerate(runs):
        node = _row_node(robot, run, line)
        items.append(PathBlock(index, node, run.tool, run.frame, joints=run.joints))
        nodes.append(node)
        index, line = index + len(node), line + len(node)
        between: list[ir.Instruction] = [ir.Comment(text=f"run {k}"), ir.Wait(seconds=0.25)]
        if k % 2 == 0:
            between.append(
                ir.JointMove(
                    target=ir.JointTarget(joints=run.joints[-1]),
                    tool=run.tool,
                    frame=run.frame,
                    span=ir.SourceSpan("rows.csv", line),
                )
            )
        for ins in between:
            joints = run.joints[-1] if isinstance(ins, ir.JointMove) else None
            tool = run.tool if joints is not None else None
            frame = run.frame if joints is not None else None
            items.append(Step(index, ins, joints=joints, tool=tool, frame=frame))
            nodes.append(ins)
            index += 1
    program = ir.Program(name="rows", instructions=tuple(nodes), source="rows.csv")
    return CompiledProgram(program, station, robot.home.copy(), StepBlocks(items))


def _runs(rows: int) -> list[Run]:
    station = _weld()
    torch = station.tools["torch"]
    other = ir.Tool(name="torch2", pose=torch.pose @ transl(0.0, 0.0, 0.02), number=3)
    table, fixture = station.frames["weld_table"], station.frames["fixture"]
    assert table.pose is not None
    unnumbered = ir.Frame(name="jig", pose=table.pose @ transl(0.05, 0.0, 0.0))
    k = np.arange(rows)
    speeds = 0.0125 + 0.0005 * (k % 4)  # 12.5 .. 14 mm/sec: halves round up
    zones = np.where(k % 3 == 0, 0.0, 0.0005 + 0.0005 * (k % 7))  # FINE, CNT1..CNT4
    zones[k % 17 == 4] = 0.25  # 250 mm: CNT100
    slow = speeds.copy()
    slow[1::5] = 0.0003  # below 1 mm/sec
    return [
        Run(_sweep(rows, 1), table, torch, speeds, zones),
        Run(_sweep(rows, 2), unnumbered, torch, slow, zones),
        Run(_sweep(rows, 3, odd=False), fixture, other, speeds[::-1].copy(), zones[::-1].copy()),
        Run(_sweep(rows, 4), fixture, other, speeds, zones),
    ]


def _render(post: Post, compiled: CompiledProgram) -> tuple[dict[str, str], list[str]]:
    compiled, found = post.prepare(post.render_form(compiled))
    diagnostics = [*found, *post.check(compiled)]
    try:
        files = post.render(compiled, prepared=True)
    except RenderError as exc:
        files, diagnostics = {}, [*diagnostics, *exc.diagnostics]
    return files, [d.format() for d in diagnostics]


@pytest.mark.parametrize("limit", [None, 40])
def test_handmade_rows_are_written_by_columns_as_the_templates_write_them(
    limit: int | None, monkeypatch: pytest.MonkeyPatch
) -> None:
    compiled = _handmade(_runs(60))
    columns, rows, template = _posts()
    if limit is not None:
        limits = dataclasses.replace(columns.manifest.limits, max_instructions=limit)
        columns, rows, template = (
            type(p)(dataclasses.replace(p.manifest, limits=limits))
            for p in (columns, rows, template)
        )
    expected = _render(template, compiled)
    assert _render(rows, compiled) == expected
    monkeypatch.setattr(PathBlock, "steps", _forbidden)
    monkeypatch.setattr(CompiledProgram, "flat", _forbidden)
    files, diagnostics = _render(columns, compiled)
    assert (files, diagnostics) == expected
    assert len(files) == (1 if limit is None else 8)
    text = "".join(files.values())
    for piece in ("UFRAME_NUM=0 ;", "UFRAME_NUM=2 ;", "UTOOL_NUM=3 ;", "CNT100    ;", "\tJ1="):
        assert piece in text
    assert " 14mm/sec " in text and " 13mm/sec " in text  # 13.5 rounds half up
    assert sum("joint_position" in d for d in diagnostics) > 10
    assert sum("speed_raised" in d for d in diagnostics) == 12


def test_a_number_the_column_writer_cannot_write_is_an_error_on_its_row() -> None:
    """A post whose L speed tops out at 13 mm/sec: the rows faster than that are errors on
    their own lines, the same as the templates report them."""
    tight = type(
        "TightFanuc",
        (FanucPost,),
        {"NUMBERS": {**NUMBERS, "linear": NumberFormat("L/C speed", "mm/sec", 0, 1, 13)}},
    )
    compiled = _handmade(_runs(30)[:1])
    columns, _, template = _posts(tight(find_post("fanuc").manifest))
    files, diagnostics = _render(columns, compiled)
    assert not files
    errors = [d for d in diagnostics if "error" in d]
    assert len(errors) == 14  # the rows at 13.5 and 14 mm/sec (k % 4 in 2, 3)
    assert (files, diagnostics) == _render(template, compiled)
