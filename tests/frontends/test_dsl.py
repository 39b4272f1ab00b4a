"""Python DSL: RoboDK pose conventions, what each call records, spans at the user's line,
parameters, station questions, located errors and fuzzing."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from olp import dsl, ir
from olp.errors import OlpError, ParseError, UsageError
from olp.frontends.dsl import DslResult, convert_param, load_dsl, run_dsl
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
HOME = "[0, -90, 90, 0, 0, 0]"


@pytest.fixture(scope="module")
def station() -> Station:
    return load_station(CELL)


def run(text: str, station: Station | None = None, **params: object) -> DslResult:
    return run_dsl(text, "prog.py", station, params)


def only(text: str, station: Station | None = None) -> ir.Instruction:
    (instruction,) = run(text, station).program.instructions
    return instruction


def error_of(text: str, station: Station | None = None, **params: object) -> ParseError:
    with pytest.raises(ParseError) as info:
        run(text, station, **params)
    return info.value


def matrix(pose: dsl.Mat) -> np.ndarray:
    return np.array(pose)


# ------------------------------------------------------------------------------------------------
# Poses: RoboDK's conventions, pinned


def _rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _ry(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def test_pose_is_transl_rotx_roty_rotz_in_degrees() -> None:
    # robomath.Pose: "H = transl(x,y,z)*rotx(rx*pi/180)*roty(ry*pi/180)*rotz(rz*pi/180)".
    x, y, z, rx, ry, rz = 10.0, -20.0, 30.0, 15.0, -40.0, 120.0
    pose = matrix(dsl.Pose(x, y, z, rx, ry, rz))
    expected = _rx(math.radians(rx)) @ _ry(math.radians(ry)) @ _rz(math.radians(rz))
    assert np.allclose(pose[:3, :3], expected, atol=1e-15)
    assert pose[:3, 3].tolist() == [x, y, z] and pose[3].tolist() == [0, 0, 0, 1]
    scipy = Rotation.from_euler("XYZ", [rx, ry, rz], degrees=True).as_matrix()
    assert np.allclose(pose[:3, :3], scipy, atol=1e-15)
    # ... and not RoboDK's other convention, xyzrpw_2_pose (rotz * roty * rotx).
    other = _rz(math.radians(rz)) @ _ry(math.radians(ry)) @ _rx(math.radians(rx))
    assert not np.allclose(pose[:3, :3], other, atol=1e-3)


def test_rotations_take_radians_and_compose_like_matrices() -> None:
    quarter = dsl.rotx(math.pi / 2)
    assert np.allclose(quarter * [0, 1, 0], [0, 0, 1])
    assert np.allclose(matrix(dsl.rotz(math.pi / 2))[:3, :3], _rz(math.pi / 2))
    assert np.allclose(matrix(dsl.roty(0.3))[:3, :3], _ry(0.3))
    composed = dsl.transl(1, 2, 3) * dsl.rotz(0.5)
    assert np.allclose(matrix(composed), matrix(dsl.transl([1, 2, 3])) @ matrix(dsl.rotz(0.5)))
    assert np.allclose(matrix(composed @ composed.inv()), np.eye(4), atol=1e-12)
    assert np.allclose(matrix(dsl.invH(composed)), np.linalg.inv(matrix(composed)))


def test_pos_setpos_offset_reltool() -> None:
    pose = dsl.Pose(100, 0, 0, 180, 0, 0)
    assert pose.Pos() == [100, 0, 0]
    same = pose.setPos([1, 2, 3])
    assert same is pose and pose.Pos() == [1, 2, 3]
    # RelTool moves along the pose's own axes (its Z points down here), Offset along the frame's.
    assert np.allclose(dsl.RelTool(pose, 0, 0, 10).Pos(), [1, 2, -7])
    assert np.allclose(pose.Offset(0, 0, 10).Pos(), [1, 2, 13])
    assert np.allclose(pose.VZ(), [0, 0, -1]) and np.allclose(pose.VX(), [1, 0, 0])
    assert (
        repr(dsl.Pose(1, 2, 3, 10, 20, 30)) == "Pose(1.000, 2.000, 3.000, 10.000, 20.000, 30.000)"
    )


# ------------------------------------------------------------------------------------------------
# What each call records (SI inside)


def test_moves_record_targets_in_si(station: Station) -> None:
    result = run(
        f"robot.MoveJ({HOME})\n"
        "robot.MoveL(Pose(500, 100, 400, 180, 0, 0))\n"
        "robot.MoveJ('home')\n"
        "t = AddTarget('above', Pose(400, 0, 500, 180, 0, 0))\n"
        "robot.MoveL('above')\n"
        "robot.MoveC(Pose(450, 50, 500, 180, 0, 0), t)\n",
        station,
    )
    joint, linear, home, named, circ = result.program.instructions
    assert isinstance(joint, ir.JointMove) and isinstance(joint.target, ir.JointTarget)
    assert np.allclose(joint.target.joints, np.radians([0, -90, 90, 0, 0, 0]))
    assert isinstance(linear, ir.LinearMove) and isinstance(linear.target, ir.CartesianTarget)
    assert linear.target.pose[:3, 3].tolist() == [0.5, 0.1, 0.4]
    assert isinstance(home.target, ir.JointTarget) and home.target.name == "home"  # type: ignore[union-attr]
    assert named.target.name == "above"  # type: ignore[union-attr]
    assert isinstance(circ, ir.CircularMove) and circ.target.name == "above"
    assert circ.via.pose[:3, 3].tolist() == [0.45, 0.05, 0.5]


def test_settings_carry_into_the_moves(station: Station) -> None:
    result = run(
        "robot.setSpeed(50, 90)\n"
        "robot.setRounding(5)\n"
        "robot.setPoseFrame('table')\n"
        "robot.MoveL(Pose(0, 0, 50, 180, 0, 0))\n"
        "robot.setSpeed(-1, -1, 2000)\n"
        "robot.setZoneData(-1)\n"
        "robot.setPoseTool(Pose(0, 0, 100, 0, 0, 0))\n"
        "robot.setPoseFrame(Pose(0, 500, 0, 0, 0, 90))\n"
        "robot.MoveL(Pose(0, 0, 50, 180, 0, 0))\n",
        station,
    )
    first, second = result.program.instructions
    assert isinstance(first, ir.LinearMove) and isinstance(second, ir.LinearMove)
    assert first.speed.linear == 0.05 and first.zone.radius == 0.005
    # 90 deg/s for every axis: a fraction of the fastest axis, so no axis exceeds 90 deg/s.
    fastest = float(np.max(station.robot.limits.velocity))
    assert first.speed.joint == pytest.approx(math.radians(90) / fastest, rel=1e-15)
    assert first.tool is station.tools["spindle"] and first.frame is station.frames["table"]
    assert first.speed.linear_acceleration is None and second.zone.is_fine
    assert second.speed == first.speed.__class__(
        linear=0.05, joint=first.speed.joint, linear_acceleration=2.0
    )
    assert second.tool.pose is not None and second.tool.pose[:3, 3].tolist() == [0, 0, 0.1]
    assert second.frame.pose is not None and second.frame.pose[:3, 3].tolist() == [0, 0.5, 0]
    assert result.ignored == ()


def test_io_waits_calls_comments_and_name() -> None:
    result = run(
        "robot.ProgramStart('Weld')\n"
        "robot.setDO(3, 1)\n"
        "robot.setDO('4', 'off')\n"
        "robot.waitDI(2, True)\n"
        "robot.Pause(250)\n"
        "robot.RunInstruction('SprayOn')\n"
        "robot.RunInstruction('TCP_On(1, 2)')\n"
        "robot.RunInstruction('done', INSTRUCTION_COMMENT)\n"
    )
    assert result.program.name == "Weld"
    assert list(result.program.instructions) == [
        ir.SetOutput(index=3, value=True, span=ir.SourceSpan("prog.py", 2, 1, 2, 18)),
        ir.SetOutput(index=4, value=False, span=ir.SourceSpan("prog.py", 3, 1, 3, 24)),
        ir.WaitInput(index=2, value=True, span=ir.SourceSpan("prog.py", 4, 1, 4, 22)),
        ir.Wait(seconds=0.25, span=ir.SourceSpan("prog.py", 5, 1, 5, 17)),
        ir.Call(name="SprayOn", span=ir.SourceSpan("prog.py", 6, 1, 6, 32)),
        ir.Call(name="TCP_On", args=("1", "2"), span=ir.SourceSpan("prog.py", 7, 1, 7, 37)),
        ir.Comment(text="done", span=ir.SourceSpan("prog.py", 8, 1, 8, 50)),
    ]


def test_defaults_without_a_station_are_flange_and_world() -> None:
    move = only("robot.MoveL(Pose(0, 0, 0, 0, 0, 0))")
    assert isinstance(move, ir.LinearMove)
    assert move.tool is ir.FLANGE and move.frame is ir.WORLD and move.speed == ir.Speed()
    named = only("robot.setPoseTool('spindle'); robot.MoveL(Pose(0, 0, 0, 0, 0, 0))")
    assert named.tool == ir.Tool(name="spindle")  # type: ignore[union-attr]


# ------------------------------------------------------------------------------------------------
# Spans: the user's call


def test_spans_point_at_the_call_in_the_program_file() -> None:
    result = run(
        "def corner(pose):\n"
        "    robot.MoveL(pose)\n"
        "\n"
        "name = 'åäö'; robot.MoveJ([1, 2, 3, 4, 5, 6])\n"
        "corner(Pose(0, 0, 0, 0, 0, 0))\n"
        "robot.MoveL(\n"
        "    Pose(0, 0, 0, 0, 0, 0))\n"
    )
    unicode, helper, multi = (i.span for i in result.program.instructions)
    # Columns count characters, not UTF-8 bytes.
    assert unicode == ir.SourceSpan("prog.py", 4, 15, 4, 46)
    # A call inside the program's own function: the line of that call.
    assert helper == ir.SourceSpan("prog.py", 2, 5, 2, 22)
    assert (multi.line, multi.column, multi.end_line) == (6, 1, None)


def test_every_span_is_in_the_program_file(tmp_path: Path) -> None:
    path = tmp_path / "p.py"
    path.write_text("for i in range(3):\n    robot.MoveL(transl(i, 0, 0))\n", encoding="utf-8")
    result = load_dsl(path)
    assert {(i.span.file, i.span.line) for i in result.program} == {(str(path), 2)}
    assert result.program.name == "p" and result.program.source == str(path)


# ------------------------------------------------------------------------------------------------
# Parameters


PARAMS = [
    # default, command-line text, value
    (50.0, "80", 80.0),
    (50.0, "1e2", 100.0),
    (6, "8", 8),
    ("Weld", "Spray 2", "Spray 2"),
    (False, "yes", True),
    (True, "OFF", False),
    (None, "7", 7),
    (None, "7.5", 7.5),
    (None, "abc", "abc"),
]


@pytest.mark.parametrize(("default", "raw", "value"), PARAMS)
def test_params_take_the_type_of_their_default(default: object, raw: str, value: object) -> None:
    converted = convert_param("P", raw, default)
    assert converted == value and type(converted) is type(value)


@pytest.mark.parametrize(
    ("default", "raw", "message"),
    [
        (6, "6.5", "expected an integer"),
        (1.0, "nan", "finite number"),
        (False, "2", "true or false"),
    ],
)
def test_bad_param_values_point_at_the_param_line(default: object, raw: str, message: str) -> None:
    error = error_of(f"x = 1\nN = param('N', {default!r})\n", N=raw)
    assert (error.span.line, error.span.column) == (2, 5)  # type: ignore[union-attr]
    assert message in error.message and f"--set N={raw}" in error.message


def test_param_rules() -> None:
    result = run("A = param('A', 1)\nB = param('B', 'x')\nrobot.MoveJ([A] * 6)\n", A="2")
    assert result.params == ("A", "B")
    assert np.allclose(result.program.instructions[0].target.joints, np.radians([2] * 6))  # type: ignore[union-attr]
    with pytest.raises(
        UsageError, match=r"--set C: the program has no such parameter \(it reads: A\)"
    ):
        run("A = param('A', 1)\n", C="1")
    assert "has no default" in error_of("x = param('X')\n").message
    # Library callers may pass Python values; they are taken as they are.
    assert run("robot.Pause(param('T', 1))", T=0.5).program.instructions[0].seconds == 0.0005  # type: ignore[union-attr]


# ------------------------------------------------------------------------------------------------
# Questions to the station


def test_joints_and_pose_follow_the_moves(station: Station) -> None:
    result = run(
        "robot.setPoseFrame('table')\n"
        "robot.MoveJ([10, -80, 100, 0, 30, 0])\n"
        "J = robot.Joints()\n"
        "target = Pose(100, 150, 60, 180, 0, 180)\n"
        "robot.MoveJ(target)\n"
        "P = robot.Pose()\n"
        "robot.RunInstruction(','.join(f'{v:.9f}' for v in J + P.Pos()), INSTRUCTION_COMMENT)\n"
        "robot.RunInstruction(str(robot.JointsHome()), INSTRUCTION_COMMENT)\n",
        station,
    )
    values = [float(v) for v in result.program.instructions[2].text.split(",")]  # type: ignore[union-attr]
    assert values[:6] == pytest.approx([10, -80, 100, 0, 30, 0], abs=1e-9)
    assert values[6:] == pytest.approx([100, 150, 60], abs=1e-6)
    assert result.program.instructions[3].text == "[0.0, -90.0, 90.0, 0.0, 0.0, 0.0]"  # type: ignore[union-attr]


def test_move_tests_use_robodk_codes(station: Station) -> None:
    result = run(
        "down = Pose(0, 0, 0, 180, 0, 180)\n"
        "robot.MoveJ(down.copy().setPos([160, -400, 300]))\n"
        "j = robot.Joints()\n"
        "codes = [robot.MoveL_Test(j, down.copy().setPos(p)) for p in\n"
        "         ([200, -400, 300], [80, -400, 300], [3000, -400, 300])]\n"
        "over = robot.canMoveL(down.copy().setPos([80, -400, 300]))\n"
        "far = robot.canReach(down.copy().setPos([3000, -400, 300]))\n"
        "joint = robot.canMoveJ(down.copy().setPos([80, -400, 300]))\n"
        "ik = robot.SolveIK(Pose(5000, 0, 400, 0, 90, 0))\n"
        "answers = (codes, bool(over), over.kind, bool(far), bool(joint), ik)\n"
        "robot.RunInstruction(repr(answers), INSTRUCTION_COMMENT)\n",
        station,
    )
    text = result.program.instructions[1].text  # type: ignore[union-attr]
    # Crossing over the robot's base: reachable, but not on a straight line (axis 1 would have
    # to pass its limit); the far point is not reachable at all.
    assert text == "([0, -1, -2], False, 'joint_limit', False, True, [])"


def test_solve_ik_returns_joints_whose_fk_is_the_pose(station: Station) -> None:
    result = run(
        "pose = Pose(500, 0, 400, 0, 90, 0)\n"
        "robot.MoveJ(robot.SolveIK(pose, [0, -60, 120, 0, 30, 0]))\n",
        station,
    )
    joints = result.program.instructions[0].target.joints  # type: ignore[union-attr]
    flange = np.linalg.inv(station.robot.base) @ station.robot.flange_poses(joints)
    assert np.allclose(flange[:3, 3], [0.5, 0, 0.4], atol=1e-9)
    assert np.allclose(flange[:3, :3], _ry(math.pi / 2), atol=1e-9)


def test_station_questions_without_a_station_are_located_errors() -> None:
    error = error_of("robot.MoveJ([0] * 6)\nq = robot.Joints()\n")
    assert error.span.line == 2 and "asks the station" in error.message  # type: ignore[union-attr]


# ------------------------------------------------------------------------------------------------
# Located errors

ERRORS = [
    # program, line, column, message
    ("robot.MoveJ(\n", 1, 12, "Python syntax error: '(' was never closed"),
    ("x = 1\n  y = 2\n", 2, None, "Python syntax error: unexpected indent"),
    ("robot.MoveL('nowhere')\n", 1, 1, "no target named 'nowhere' (known: home)"),
    ("robot.MoveL(Pose(1, 2, 3, 0, 0, 0) * 2)\n", 1, 1, "not a rigid transform"),
    ("robot.MoveL('a', 'b', 'c', 'd')\n", 1, 1, "TypeError"),
    ("robot.MoveJ([0, 0, 0])\n", 1, 1, "expected 6 joint values in degrees, got 3"),
    ("robot.MoveJ([float('nan')] * 6)\n", 1, 1, "expected finite numbers"),
    ("robot.MoveJ([10**400] * 6)\n", 1, 1, "expected finite numbers"),
    ("robot.MoveL({'x': 1})\n", 1, 1, "expected a pose (Mat), joints"),
    ("robot.setSpeed(0)\n", 1, 1, "linear speed (mm/s) must be > 0"),
    ("robot.Pause()\n", 1, 1, "Pause() without a time"),
    ("robot.waitDI(1, 1, 500)\n", 1, 1, "a timeout is not supported"),
    ("robot.RunInstruction('x = 1', INSTRUCTION_INSERT_CODE)\n", 1, 1, "run type 1"),
    ("robot.RunInstruction('bad call(')\n", 1, 1, "is not a program call"),
    ("robot.setDO(0, 1)\n", 1, 1, "expected an I/O number from 1 to 2147483647"),
    ("robot.setDO(1, 'maybe')\n", 1, 1, "expected 1/0, True/False or on/off"),
    ("robot.setPoseTool('torch')\n", 1, 1, "no tool named 'torch' (known: flange, spindle)"),
    ("p = Pose(0, 0, 0, 0, 0, 0).setPos([1, 2])\n", 1, 5, "setPos needs [x, y, z]"),
    ("AddTarget('a', [0] * 6)\nAddTarget('a', [1] * 6)\n", 2, 1, "'a' exists already"),
    ("def f():\n    return 1 / 0\n\nf()\n", 2, 12, "ZeroDivisionError: division by zero"),
    ("import olp_no_such_module\n", 1, 1, "ModuleNotFoundError"),
    ("raise SystemExit(3)\n", 1, 1, "the program exited with 3"),
    ("raise KeyError\n", 1, 1, "KeyError"),
    (
        "class E(Exception):\n    def __str__(self):\n        raise ValueError\nraise E\n",
        4,
        1,
        "E: (its message cannot be shown)",
    ),
]


@pytest.mark.parametrize(("text", "line", "column", "message"), ERRORS)
def test_errors_point_at_the_users_line(
    station: Station, text: str, line: int, column: int | None, message: str
) -> None:
    error = error_of(text, station)
    assert error.span is not None and error.span.file == "prog.py"
    assert error.span.line == line and error.span.column >= 1
    # Python's own syntax-error columns differ between versions; olp's are pinned.
    assert column is None or error.span.column == column
    assert message in error.message
    assert error.source_line == text.split("\n")[line - 1]
    assert "^" in error.format() and "Traceback" not in error.format()


def test_exit_zero_ends_the_program_normally() -> None:
    result = run("import sys\nrobot.Pause(1)\nsys.exit()\nrobot.Pause(2)\n")
    assert [i.seconds for i in result.program.instructions] == [0.001]  # type: ignore[union-attr]
    assert len(run("robot.Pause(1)\nraise SystemExit(0)\n").program) == 1


def test_undecodable_source_is_located() -> None:
    with pytest.raises(ParseError, match="not valid UTF-8") as info:
        run_dsl(b"robot.Pause(1)\nx = '\xff'\n", "prog.py")
    assert info.value.span.line == 2  # type: ignore[union-attr]
    with pytest.raises(ParseError, match="null bytes") as info:
        run_dsl(b"x = 1\x00\n", "prog.py")


def test_dsl_names_outside_a_run_explain_themselves() -> None:
    with pytest.raises(dsl.DslError, match="only work inside a program run by olp"):
        dsl.robot.MoveJ([0] * 6)
    # Inside a run, the imported names talk to that run.
    result = run("from olp.dsl import robot as r, param as p\nr.Pause(p('T', 3))\n")
    assert result.program.instructions[0] == ir.Wait(
        seconds=0.003, span=ir.SourceSpan("prog.py", 2, 1, 2, 19)
    )


def test_unreadable_file_is_a_usage_error(tmp_path: Path) -> None:
    with pytest.raises(UsageError, match="cannot read program"):
        load_dsl(tmp_path / "missing.py")


def test_program_warnings_are_recorded() -> None:
    result = run("x = 3\nwarn(f'target {x} skipped')\nrobot.MoveJ([0, 0, 0, 0, 0, 0])\n")
    (warning,) = result.warnings
    assert warning.message == "target 3 skipped" and warning.span.line == 2


# ------------------------------------------------------------------------------------------------
# Fuzzing: only located OlpErrors may escape

FUZZ = settings(
    max_examples=300,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
CALLS = [
    "robot.MoveJ", "robot.MoveL", "robot.MoveC", "robot.setSpeed", "robot.setSpeedJoints",
    "robot.setRounding", "robot.setPoseTool", "robot.setPoseFrame", "robot.AddTool",
    "robot.setDO", "robot.waitDI", "robot.Pause", "robot.RunInstruction", "robot.ProgramStart",
    "robot.SolveIK", "robot.MoveL_Test", "robot.MoveJ_Test", "robot.canMoveL", "robot.canReach",
    "Pose", "transl", "rotx", "Mat", "RelTool", "Offset", "AddTarget", "AddFrame", "warn",
]  # fmt: skip
ATOMS = (
    st.floats(allow_nan=True, allow_infinity=True)
    | st.integers(-(10**400), 10**400)
    | st.text(max_size=8)
    | st.none()
    | st.booleans()
)
VALUES = st.recursive(ATOMS, lambda inner: st.lists(inner, max_size=7), max_leaves=20)


def _check_escape(run_it: Any) -> None:
    try:
        run_it()
    except OlpError as exc:
        assert isinstance(exc, ParseError | UsageError), exc
        if isinstance(exc, ParseError):
            assert exc.span is not None and exc.span.line >= 1 and exc.span.column >= 1
        exc.format()


@given(st.binary(max_size=200))
@FUZZ
def test_fuzz_random_bytes(station: Station, data: bytes) -> None:
    _check_escape(lambda: run_dsl(data, "fuzz.py", station))


@given(call=st.sampled_from(CALLS), args=st.lists(VALUES, max_size=5))
@FUZZ
def test_fuzz_api_arguments(station: Station, call: str, args: list[object]) -> None:
    program = f"robot.MoveJ('home')\n{call}(*param('ARGS'))\n"
    _check_escape(lambda: run_dsl(program, "fuzz.py", station, {"ARGS": args}))


# A loop-free program touching most of the API; fuzzing replaces its literals only, so no
# mutation can make it loop or compute for long.
SEED = """\
robot.setSpeed(100, 90, -1, 500)
robot.setRounding(5)
robot.setPoseFrame('table')
t = AddTarget('t1', Pose(150, 160, 50, 180, 0, 180))
robot.MoveJ('home')
robot.MoveJ(t)
robot.MoveL(Offset(t.Pose(), 10, 0, 0))
robot.MoveC(Pose(160, 170, 50, 180, 0, 180), Pose(170, 160, 50, 180, 0, 180))
robot.MoveL([10, -80, 100, 0, 30, 0])
robot.setPoseTool(Pose(0, 0, 200, 0, 90, 0))
robot.setDO(2, 1)
robot.waitDI(3, 0)
robot.Pause(100)
robot.RunInstruction('TCP_On(1)')
robot.RunInstruction('note', 3)
j = robot.SolveIK(Pose(500, 0, 400, 0, 90, 0))
ok = robot.MoveL_Test([0, -90, 90, 0, 0, 0], transl(300, 0, 300))
robot.ProgramStart('Fuzzed')
"""
LITERALS = [
    "1e308", "-1e308", "float('nan')", "float('inf')", "10**400", "0", "-1", "1e-320",
    "'\\u00fc'", "''", "'\\x00'", "'TCP_On('", "[]", "None", "True", "[1e308] * 6",
]  # fmt: skip


@given(st.data())
@FUZZ
def test_fuzz_mutated_valid_program(station: Station, data: st.DataObject) -> None:
    import io
    import tokenize

    tokens = list(tokenize.generate_tokens(io.StringIO(SEED).readline))
    literals = [k for k, tok in enumerate(tokens) if tok.type in (tokenize.NUMBER, tokenize.STRING)]
    chosen = data.draw(st.lists(st.sampled_from(literals), min_size=1, max_size=4, unique=True))
    mutated = [
        (tok.type, data.draw(st.sampled_from(LITERALS)) if k in chosen else tok.string)
        for k, tok in enumerate(tokens)
    ]
    program = tokenize.untokenize(mutated)
    _check_escape(lambda: run_dsl(program, "fuzz.py", station))


def test_seed_program_runs_clean(station: Station) -> None:
    result = run_dsl(SEED, "fuzz.py", station)
    assert result.program.name == "Fuzzed" and len(result.program) == 10


def test_set_tool_takes_a_station_tool_number(station: Station) -> None:
    """Issue 16: ``robot.setTool(1)`` said "Mat needs 4 x 4 numbers, got shape ()"; a number
    is the station's tool of that controller number, an unknown one a located error."""
    move = only("robot.setTool(1)\nrobot.MoveJ('home')\n", station)
    assert move.tool is station.tools["spindle"]  # type: ignore[union-attr]
    error = error_of("x = 1\nrobot.setTool(7)\n", station)
    assert error.span is not None and error.span.line == 2
    assert "no tool number 7 (tools: 1 spindle)" in error.message
