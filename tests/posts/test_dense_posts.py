"""A CSV toolpath (dense: ``ir.LinearPath`` nodes) is written by every post exactly as the same
moves given one by one: the dense node changes how olp holds a toolpath, never what it writes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.frontends.bundled import CsvOptions
from olp.posts import REGISTRY

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"


def _helix(path: Path, rows: int) -> None:
    t = np.linspace(0.0, 4.0 * np.pi, rows)
    xyz = np.c_[100 + 60 * np.cos(t), 60 * np.sin(t), 20 + np.linspace(0.0, 30.0, rows)]
    speeds = np.where(np.arange(rows) < rows // 2, 20.0, 35.0)  # one feed change
    np.savetxt(
        path, np.c_[xyz, speeds], fmt="%.4f", delimiter=",", header="x,y,z,speed", comments=""
    )


def _per_move(program: ir.Program) -> ir.Program:
    """The program with every dense node given as its moves, one object each."""
    return program.replace_instructions(list(program))


@pytest.mark.parametrize("post", sorted(REGISTRY))
@pytest.mark.parametrize("zone", [0.0, 1.0])
def test_a_dense_toolpath_is_written_as_its_moves(post: str, zone: float, tmp_path: Path) -> None:
    station = olp.load_station(CELL)
    csv = tmp_path / "helix.csv"
    _helix(csv, 60)
    # Small chunks: the toolpath is several LinearPath nodes, as a large file is.
    options = CsvOptions(frame="table", orientation=(180.0, 0.0, 180.0), zone=zone, chunk_bytes=512)
    program = olp.parse(csv, station=station, options=options).program
    assert sum(isinstance(n, ir.LinearPath) for n in program.instructions) > 1
    dense = olp.build(station, program, post)
    moves = olp.build(station, _per_move(program), post)
    assert dense.ok and moves.ok, [d.format() for d in (*dense.diagnostics, *moves.diagnostics)]
    assert dense.files == moves.files
    assert [d.format() for d in dense.diagnostics] == [d.format() for d in moves.diagnostics]
