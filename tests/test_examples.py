"""The example programs of USERS.md jobs 1, 2, 3, 4, 6 and 11 build end to end and do their job."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.api import BuildResult
from olp.cli import main
from olp.frontends.bundled import CsvOptions, DslOptions
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[1]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
EXAMPLES = REPO / "examples"


@pytest.fixture(scope="module")
def station() -> Station:
    return olp.load_station(CELL)


def build(station: Station, name: str, **params: object) -> BuildResult:
    result = olp.build(station, EXAMPLES / name, program_options=DslOptions(params=params))
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    return result


def instructions(result: BuildResult) -> list[ir.Instruction]:
    return list(result.compiled.program.instructions)


def position_mm(move: ir.Instruction) -> np.ndarray:
    assert isinstance(move, ir.MOTION_TYPES) and isinstance(move.target, ir.CartesianTarget)
    return move.target.pose[:3, 3] * 1000.0


# ------------------------------------------------------------------------------------------------
# Job 1: weld a polygon


def test_job1_weld_polygon_sequence(station: Station) -> None:
    result = build(station, "weld_polygon.py")
    program = instructions(result)
    assert result.compiled.program.name == "WeldPolygon"
    kinds = [i.kind for i in program]
    assert kinds == ["joint", "joint", "linear", "call"] + ["linear"] * 6 + [
        "call",
        "linear",
        "joint",
    ]
    on, off = program[3], program[10]
    assert isinstance(on, ir.Call) and on.name == "SprayOn"
    assert isinstance(off, ir.Call) and off.name == "SprayOff"
    seam = program[4:10]
    assert all(m.speed.linear == 0.020 for m in seam)  # type: ignore[union-attr]
    assert [m.zone.radius for m in seam] == [0.01] * 5 + [0.0]  # type: ignore[union-attr]
    assert all(m.tool.name == "torch" and m.frame.name == "table" for m in seam)  # type: ignore[union-attr]
    # Corners of a regular hexagon of radius 100 mm around the reference (150, 160, 20).
    corners = np.array([position_mm(program[2])] + [position_mm(m) for m in seam])
    assert np.allclose(np.linalg.norm(corners[:, :2] - [150, 160], axis=1), 100.0)
    assert np.allclose(corners[0], corners[-1]) and np.allclose(corners[:, 2], 20.0)
    assert "SprayOn()" in result.files["WeldPolygon.src"]


def test_job1_parameters_from_the_command_line(tmp_path: Path) -> None:
    out = tmp_path / "out"
    params = ["SIDES=8", "DRY_RUN=true", "NAME=Seam2", "SPEED=35"]
    sets = [arg for param in params for arg in ("--set", param)]
    code = main(
        ["build", str(CELL), str(EXAMPLES / "weld_polygon.py"), "-o", str(out), "-q", *sets]
    )
    assert code == 0
    src = (out / "Seam2.src").read_text()
    assert "SprayOn" not in src and "SprayOff" not in src
    # 8 sides: 8 rounded seam moves after the first corner, at 35 mm/s.
    assert src.count(" C_DIS") == 7 and "$VEL.CP = 0.03500" in src


# ------------------------------------------------------------------------------------------------
# Job 2: points to program, linear where possible


def test_job2_linear_moves_fall_back_to_joint_moves(station: Station) -> None:
    result = build(station, "points_to_program.py")
    moves = instructions(result)
    assert moves[0].kind == "joint" and moves[1].kind == "joint"
    points = moves[1:]
    assert len(points) == 11
    xs = [position_mm(m)[0] for m in points]
    assert np.allclose(xs, np.linspace(400, -400, 11))
    kinds = [m.kind for m in points]
    # Over the robot's base a straight line is impossible: those points became joint moves.
    assert "joint" in kinds[1:] and kinds.count("linear") >= 6
    assert all(np.allclose(m.target.pose[:3, :3], np.diag([-1, 1, -1])) for m in points)  # type: ignore[union-attr]


def test_job2_every_kept_linear_move_is_feasible_alone(station: Station) -> None:
    result = build(station, "points_to_program.py", N=21)
    steps = result.compiled.steps
    for step in steps[1:]:
        if step.instruction.kind != "linear":
            continue
        start = steps[step.index - 1].joints
        assert start is not None
        probe = ir.Program(
            name="probe",
            instructions=(ir.JointMove(target=ir.JointTarget(joints=start)), step.instruction),
        )
        assert olp.compile(probe, station).ok


# ------------------------------------------------------------------------------------------------
# Jobs 3 and 4: CSV toolpaths


def test_job3_csv_speeds_change_only_where_they_change(tmp_path: Path) -> None:
    out = tmp_path / "out"
    args = ["--frame", "table", "--orientation", "180,0,180", "-o", str(out), "-q"]
    assert main(["build", str(CELL), str(EXAMPLES / "path_xyz.csv"), *args]) == 0
    src = (out / "path_xyz.src").read_text()
    speeds = re.findall(r"\$VEL\.CP = ([0-9.]+)", src)
    assert speeds == ["0.02000", "0.02117", "0.25000"]
    assert src.count("LIN {") == 6 and src.count("PTP {") == 1


def test_job4_csv_unreachable_target_reported_then_skipped(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    csv = str(EXAMPLES / "targets_xyzwpr.csv")
    args = ["--frame", "table", "-o", str(tmp_path / "out")]
    assert main(["build", str(CELL), csv, *args]) == 1
    assert f"{csv}:9:1: error[unreachable" in capsys.readouterr().err
    assert main(["build", str(CELL), csv, *args, "--skip-unreachable"]) == 0
    err = capsys.readouterr().err
    assert f"{csv}:9:1: warning[unreachable]: skipped" in err and "2000,0,6.35" in err
    src = (tmp_path / "out" / "targets_xyzwpr.src").read_text()
    assert src.count("LIN {") + src.count("PTP {") == 7


# ------------------------------------------------------------------------------------------------
# Job 6: feasibility grid


def test_job6_grid_outcomes_are_what_the_station_says(station: Station) -> None:
    result = build(station, "feasibility_grid.py")
    program = instructions(result)
    # the program's own warnings, one per skipped target (posts may warn about other things)
    warnings = [d for d in result.diagnostics if d.severity == "warning" and d.kind == "program"]
    comment = next(i for i in program if isinstance(i, ir.Comment))
    linear, joint, skipped = (int(n) for n in re.findall(r"\d+", comment.text))
    moves = [m.kind for m in program if ir.is_motion(m)]
    # Two more joint moves than grid targets: home at the start and at the end.
    assert (linear, joint + 2) == (moves.count("linear"), moves.count("joint"))
    assert linear > 0 and joint > 0 and skipped == len(warnings) > 0
    assert linear + joint + skipped == 25
    spindle, table = station.tools["spindle"], station.frames["table"]
    source = (EXAMPLES / "feasibility_grid.py").read_text().split("\n")
    warn_line = next(n for n, text in enumerate(source, 1) if "warn(" in text)
    for warning in warnings:
        assert warning.span is not None and warning.span.line == warn_line
        dx, dy = (float(v) for v in re.findall(r"at ([-+]\d+), ([-+]\d+) mm", warning.message)[0])
        # Independently: no move at all reaches the skipped target.
        target = np.diag([-1.0, 1.0, -1.0, 1.0])
        target[:3, 3] = [(150 + dx) / 1000, (160 + dy) / 1000, 0.05]
        move = ir.JointMove(target=ir.CartesianTarget(pose=target), tool=spindle, frame=table)
        assert not olp.compile(ir.Program(name="probe", instructions=(move,)), station).ok


# ------------------------------------------------------------------------------------------------
# Job 11: pick and place with a multi-cup gripper


@pytest.mark.parametrize("cups", [2, 3])
def test_job11_each_cup_picks_and_places_its_part(station: Station, cups: int) -> None:
    result = build(station, "pick_and_place.py", CUPS=cups)
    program = instructions(result)
    calls = [(k, i) for k, i in enumerate(program) if isinstance(i, ir.Call)]
    assert [c.name for _, c in calls].count("TCP_On") == 6
    assert [c.name for _, c in calls].count("TCP_Off") == 6
    for k, call in calls:
        cup = int(call.args[0])
        assert 1 <= cup <= cups
        down, pause = program[k - 1], program[k + 1]
        assert isinstance(down, ir.LinearMove) and down.tool.name == f"cup{cup}"
        expected = "table_a" if call.name == "TCP_On" else "table_b"
        assert down.frame.name == expected
        assert isinstance(pause, ir.Wait) and pause.seconds == 0.2
    # Picks start with cup 1 in every batch; places follow the picks of their batch.
    names = [c.name for _, c in calls]
    assert names[:cups] == ["TCP_On"] * cups and names[cups : 2 * cups] == ["TCP_Off"] * cups


# ------------------------------------------------------------------------------------------------
# Every example: spans inside its own file


@pytest.mark.parametrize(
    ("name", "options"),
    [
        ("weld_polygon.py", {}),
        ("points_to_program.py", {}),
        ("feasibility_grid.py", {}),
        ("pick_and_place.py", {}),
        ("path_xyz.csv", {"frame": "table", "orientation": (180.0, 0.0, 180.0)}),
        ("targets_xyzwpr.csv", {"frame": "table"}),
    ],
)
def test_every_instruction_has_a_span_in_its_file(
    station: Station, name: str, options: dict[str, object]
) -> None:
    path = EXAMPLES / name
    csv = CsvOptions(**options) if name.endswith(".csv") else None  # type: ignore[arg-type]
    program = olp.parse(path, station=station, options=csv).program
    lines = path.read_text(encoding="utf-8").split("\n")
    assert len(program) > 0
    for instruction in program:
        span = instruction.span
        assert span.file == str(path) and 1 <= span.line <= len(lines)
        assert lines[span.line - 1].strip() and span.column >= 1


# ------------------------------------------------------------------------------------------------
# Command-line options that do not fit


@pytest.mark.parametrize(
    ("program", "options", "message"),
    [
        ("path_xyz.csv", ["--orientation", "1,2"], "expected three angles in degrees"),
        ("path_xyz.csv", ["--orientation=-180,0,x"], "expected three angles in degrees"),
        ("path_xyz.csv", ["--set", "A=1"], "--set is for Python programs (.py), not .csv"),
        ("weld_polygon.py", ["--set", "1X=3"], "expected NAME=VALUE"),
        ("weld_polygon.py", ["--set", "SIDES=3", "--set", "SIDES=4"], "--set SIDES is given twice"),
        ("weld_polygon.py", ["--frame", "table"], "--frame is for CSV toolpaths (.csv), not .py"),
        ("path_xyz.csv", ["--euler", "xyx", "--tool", "torch"], "tool 'torch' is not in the"),
    ],
)
def test_bad_options_exit_2_with_a_message(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    program: str,
    options: list[str],
    message: str,
) -> None:
    args = ["build", str(CELL), str(EXAMPLES / program), "-o", str(tmp_path / "out"), *options]
    assert main(args) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_orientation_with_a_leading_minus(tmp_path: Path) -> None:
    args = ["--frame", "table", "--orientation=-180,0,-180", "-o", str(tmp_path / "out"), "-q"]
    assert main(["build", str(CELL), str(EXAMPLES / "path_xyz.csv"), *args]) == 0


# ------------------------------------------------------------------------------------------------
# Job 12: edit a program as data


def test_job12_edit_program(station: Station) -> None:
    import importlib.util

    spec = importlib.util.spec_from_file_location("edit_program", EXAMPLES / "edit_program.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    original = olp.parse(EXAMPLES / "pick_and_place.py", station=station).program
    edited = module.edit(original)
    assert any(m.speed.linear > 0.1 for m in original.motions())
    assert all(m.speed.linear <= 0.1 for m in edited.motions())
    assert not any(isinstance(i, ir.Wait) for i in edited)
    calls = [k for k, i in enumerate(edited.instructions) if isinstance(i, ir.Call)]
    pairs = list(zip(calls[::2], calls[1::2], strict=True))
    assert pairs and all(
        edited.instructions[b].name == "LogStep" and b == a + 1  # type: ignore[union-attr]
        for a, b in pairs
    )
    result = olp.build(station, edited, post="kuka")
    (src,) = [text for name, text in result.files.items() if name.endswith(".src")]
    assert result.ok and src.count("LogStep()") == len(pairs)
