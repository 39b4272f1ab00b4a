"""The RoboDK-style scripts of examples/robodk/ (issue 16) run unchanged on bundled stations
with named items and build for every post that can express them.

Each script runs in this process (:func:`run_dsl`), is compiled once and rendered through every
post. A post that cannot describe the robot (KRL and RAPID write configuration bits only OPW
arms have; KRL's Status bits need KUKA's A3 convention) is an expected PostError row, as the
house style allows. One script also goes through ``olp build`` (the child process)."""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp.cli import main
from olp.errors import PostError
from olp.frontends.dsl import run_dsl
from olp.posts import find_post
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples" / "robodk"
ALL = ("kuka", "abb", "ur", "fanuc")
OPW_ONLY = ("ur", "fanuc")
"""Posts for a robot without OPW configuration flags (a UR arm or a DH chain)."""

CASES = [
    ("offline_programming.py", "robodk_kr6_cell", ALL, "WeldHexagon"),
    ("points_to_program.py", "robodk_kr6_cell", ALL, "PointsToProgram"),
    ("csv_xyz.py", "robodk_kr6_cell", ALL, "points_xyz"),
    ("csv_xyzwpr.py", "robodk_kr6_cell", ALL, "ImportXYZWPR"),
    ("move_feasibility.py", "robodk_kr6_cell", ALL, "FeasibilityGrid"),
    ("cycle_time.py", "robodk_kr6_cell", ALL, "CycleTime"),
    ("tool_change.py", "robodk_kr6_cell", ALL, "ToolChange"),
    ("pick_and_place.py", "robodk_kr6_cell", ALL, "PickAndPlace"),
    ("modify_program.py", "robodk_kr6_cell", ALL, "Modified"),
    ("drawing.py", "robodk_kr6_cell", ALL, "DrawOLP"),
    ("several_robots.py", "robodk_kr6_cell", ALL, "Weld_KUKA"),
    ("several_robots.py", "fanuc_m20ia_weld_cell", ("abb", "ur", "fanuc"), "Weld_Fanuc"),
    ("several_robots.py", "ur5e_screw_cell", OPW_ONLY, "Weld_Universal"),
    ("dh_robot.py", "robodk_dh_arm", OPW_ONLY, "DHArm"),
]

_STATIONS: dict[str, Station] = {}


def _station(name: str) -> Station:
    if name not in _STATIONS:
        _STATIONS[name] = olp.load_station(REPO / "stations" / f"{name}.yaml")
    return _STATIONS[name]


def test_at_least_twelve_scripts() -> None:
    assert len({case[0] for case in CASES}) >= 12
    assert {case[0] for case in CASES} == {p.name for p in EXAMPLES.glob("*.py")}


@pytest.mark.parametrize(
    ("script", "station", "posts", "name"), CASES, ids=[f"{c[0]}@{c[1]}" for c in CASES]
)
def test_script_builds_for_every_post_that_can_express_it(
    script: str, station: str, posts: tuple[str, ...], name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    path = EXAMPLES / script
    cell = _station(station)
    result = run_dsl(path.read_bytes(), str(path), cell)
    assert result.program.name == name
    compiled = olp.compile(result.program, cell)
    assert compiled.ok, [d.format() for d in compiled.diagnostics if d.severity == "error"]
    for post_name in ALL:
        post = find_post(post_name)
        prepared, found = post.prepare(compiled)
        errors = [d.format() for d in (*found, *post.check(prepared)) if d.severity == "error"]
        if post_name in posts:
            assert not errors, (post_name, errors)
            files = post.render(prepared, None)
            assert files and all(text for text in files.values())
        else:
            with pytest.raises(PostError, match="cannot describe robot"):
                assert not errors
                post.render(prepared, None)


def test_csv_xyzwpr_skips_the_unreachable_row_by_index(capsys: pytest.CaptureFixture[str]) -> None:
    path = EXAMPLES / "csv_xyzwpr.py"
    result = run_dsl(path.read_bytes(), str(path), _station("robodk_kr6_cell"))
    (warning,) = result.warnings
    assert "TargetReachError" in warning.message and warning.span.line == 28
    assert "Skipped targets: [13]" in capsys.readouterr().out


def test_cycle_time_table_comes_from_olps_timing(capsys: pytest.CaptureFixture[str]) -> None:
    path = EXAMPLES / "cycle_time.py"
    run_dsl(path.read_bytes(), str(path), _station("robodk_kr6_cell"))
    rows = [
        line.split("|") for line in capsys.readouterr().out.splitlines() if "Program OK" in line
    ]
    times = [float(row[2].split()[0]) for row in rows]
    assert len(times) == 6 and all(t > 0 for t in times)
    assert times[0] > times[-1]  # slower speeds take longer


def test_a_script_builds_through_olp_build(tmp_path: Path) -> None:
    station = REPO / "stations" / "robodk_kr6_cell.yaml"
    script = EXAMPLES / "offline_programming.py"
    code = main(["build", str(station), str(script), "--post", "fanuc", "-o", str(tmp_path), "-q"])
    assert code == 0
    text = "".join(p.read_text() for p in sorted(tmp_path.iterdir()))
    assert "ARCSTART" in text.upper() and "UTOOL_NUM=1" in text.replace(" ", "")


def test_tools_a_script_adds_get_fanuc_tool_numbers() -> None:
    """The probe tool_change.py adds is numbered after the station's three tools: UT 4."""
    path = EXAMPLES / "tool_change.py"
    cell = _station("robodk_kr6_cell")
    result = olp.build(cell, run_dsl(path.read_bytes(), str(path), cell).program, post="fanuc")
    text = "".join(result.files.values()).replace(" ", "")
    assert result.ok and "UTOOL_NUM=4" in text and "UTOOL_NUM=2" in text
