"""A fifth post is one class, one template folder and one registry line (issue 11).

The post below writes the planned joints of every motion as CSV: it states its language's rules
as tables (the kinds it can write, the number format of a joint value, one filter) and inherits
everything else from the base: the checks, escaping, number checks, splitting, writing.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest

import olp
from olp import ir
from olp.cli import main
from olp.posts import REGISTRY, available_posts, find_post
from olp.posts.base import Filter, Post
from olp.posts.numbers import NumberFormat

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
MILLING = REPO / "examples" / "milling.src"


def _degrees(post: Post, joints: np.ndarray) -> str:
    return ",".join(post.number("joint", v) for v in np.degrees(joints))


class JointCsvPost(Post):
    """Planned joints of every motion, one CSV row each (degrees, controller convention)."""

    NAME = "jointcsv"
    LANGUAGE = "joint CSV"
    KINDS = frozenset({"joint", "linear", "comment"})
    NUMBERS: ClassVar[Mapping[str, NumberFormat]] = {
        **Post.NUMBERS,
        "joint": NumberFormat("joint value", "deg", 4, -720, 720),
    }
    FILTERS: ClassVar[Mapping[str, Filter]] = {**Post.FILTERS, "degrees": _degrees}


TEMPLATE = """\
motion,j1_deg,j2_deg,j3_deg,j4_deg,j5_deg,j6_deg
{% for s in steps if s.motion %}
{{ s.motion }},{{ s.joints | degrees }}
{% endfor %}
"""


@pytest.fixture
def registered(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "jointcsv"
    folder.mkdir()
    (folder / "post.yaml").write_text(
        "name: jointcsv\nvendor: jointcsv\ndescription: planned joints as CSV\n"
        "files: [{template: joints.csv.j2, name: '{name}.csv'}]\n"
    )
    (folder / "joints.csv.j2").write_text(TEMPLATE)
    monkeypatch.setattr(JointCsvPost, "FOLDER", folder)
    monkeypatch.setitem(REGISTRY, "jointcsv", JointCsvPost)  # the one registry line
    return folder


def test_a_fifth_post_builds_a_program(registered: Path, tmp_path: Path) -> None:
    assert available_posts()["jointcsv"] == registered
    assert isinstance(find_post("jointcsv"), JointCsvPost)
    result = olp.build(olp.load_station(CELL), MILLING, post="jointcsv", out_dir=tmp_path / "out")
    assert result.ok, [d.format() for d in result.diagnostics]
    rows = list(csv.reader(io.StringIO(result.files["Milling.csv"])))
    assert rows[0][0] == "motion" and len(rows) == 1 + 7
    planned = [s.joints for s in result.compiled.steps if s.joints is not None]
    written = np.radians(np.array([[float(v) for v in row[1:]] for row in rows[1:]]))
    assert np.allclose(written, planned, atol=np.radians(1e-4))
    assert (tmp_path / "out" / "Milling.csv").read_text() == result.files["Milling.csv"]


def test_the_base_reports_what_the_new_post_cannot_write(registered: Path) -> None:
    station = olp.load_station(CELL)
    home = ir.JointMove(target=ir.JointTarget(joints=station.robot.home))
    program = ir.Program(name="p", instructions=(home, ir.Wait(seconds=1.0)))
    result = olp.build(station, program, post="jointcsv")
    errors = [(d.kind, d.index) for d in result.diagnostics if d.severity == "error"]
    assert errors == [("unsupported", 1)] and result.files == {}
    assert "cannot write a wait instruction" in result.diagnostics[-1].message


def test_the_new_post_is_listed_by_olp_posts(
    registered: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["posts"]) == 0
    assert "jointcsv" in capsys.readouterr().out
