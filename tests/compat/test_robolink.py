"""``robolink`` / ``robodk.robolink`` on olp (issue 16): the modules exist only inside a run,
RoboDK's constants, the item tree over a station with named items, run modes with
TargetReachError, move tests, kinematics, program items and their instructions, notes for what
olp cannot do, and errors at the script's own line.

Each test's docstring quotes the RoboDK API reference (``robodk/robolink.py``) for the units,
argument order and return shape it pins. Scripts run in this process (:func:`run_dsl`)."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from olp import ir
from olp.errors import ParseError
from olp.frontends.dsl import DslResult, run_dsl
from olp.frontends.dsl_process import ProgramRunError
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
HEADER = (
    "from robolink import *\nfrom robodk import *\nRDK = Robolink()\n"
    "def near(a, b):\n    return max(abs(x - y) for x, y in zip(a, b, strict=True)) < 1e-6\n"
)
"""Five lines every script below starts with (so a body's line n is line n + 5); ``near``
compares lists of floats."""


@pytest.fixture(scope="module")
def cell() -> Station:
    return load_station(REPO / "stations" / "robodk_kr6_cell.yaml")


def run(cell: Station, body: str, **params: object) -> DslResult:
    return run_dsl(HEADER + body, "prog.py", cell, params)


def failure(cell: Station, body: str, **params: object) -> ParseError:
    with pytest.raises(ParseError) as info:
        run(cell, body, **params)
    return info.value


def moves(result: DslResult) -> list[Any]:
    return [i for i in result.program.instructions if ir.is_motion(i)]


# ------------------------------------------------------------------------------------------------
# The modules


def test_the_modules_exist_only_inside_a_run(cell: Station) -> None:
    assert importlib.util.find_spec("robolink") is None
    body = (
        "import robodk.robolink, robodk.robomath, robodk.robofileio, robodk.robodialogs\n"
        "import robolink as old\n"
        "assert old.Robolink is robodk.robolink.Robolink\n"
        "assert robodk.robomath.Pose is Pose and robodk.robolink.robomath is robodk.robomath\n"
        "RDK.Item('', ITEM_TYPE_ROBOT).MoveJ(RDK.Item('Home'))\n"
    )
    run(cell, body)
    assert "robolink" not in sys.modules and "robodk" not in sys.modules
    assert importlib.util.find_spec("robolink") is None


def test_olp_modules_win_over_an_installed_robodk(cell: Station) -> None:
    fake = type(sys)("robolink")
    sys.modules["robolink"] = fake
    try:
        run(
            cell,
            "assert Robolink.__module__ == 'olp.compat.robodk.robolink'\nRDK.Finish()\n"
            "RDK.Item('', ITEM_TYPE_ROBOT).Pause(10)\n",
        )
        assert sys.modules["robolink"] is fake
    finally:
        del sys.modules["robolink"]


def test_constants_have_robodk_values(cell: Station) -> None:
    """robolink: ITEM_TYPE_STATION=1 ROBOT=2 FRAME=3 TOOL=4 OBJECT=5 TARGET=6 PROGRAM=8;
    RUNMODE_SIMULATE=1 ... MAKE_ROBOTPROG=3; INS_TYPE_MOVE=0 MOVEC=1 PAUSE=6; MOVE_TYPE_JOINT=1
    LINEAR=2; INSTRUCTION_CALL_PROGRAM=0 COMMENT=3; COLLISION_OFF=0 ON=1."""
    from olp.compat.robodk import robolink as rl

    assert (rl.ITEM_TYPE_STATION, rl.ITEM_TYPE_ROBOT, rl.ITEM_TYPE_FRAME, rl.ITEM_TYPE_TOOL) == (
        1,
        2,
        3,
        4,
    )
    assert (rl.ITEM_TYPE_OBJECT, rl.ITEM_TYPE_TARGET, rl.ITEM_TYPE_PROGRAM) == (5, 6, 8)
    assert (rl.RUNMODE_SIMULATE, rl.RUNMODE_QUICKVALIDATE, rl.RUNMODE_MAKE_ROBOTPROG) == (1, 2, 3)
    assert (rl.INS_TYPE_MOVE, rl.INS_TYPE_MOVEC, rl.INS_TYPE_PAUSE) == (0, 1, 6)
    assert (rl.MOVE_TYPE_JOINT, rl.MOVE_TYPE_LINEAR, rl.MOVE_TYPE_CIRCULAR) == (1, 2, 3)
    assert (rl.INSTRUCTION_CALL_PROGRAM, rl.INSTRUCTION_COMMENT) == (0, 3)
    assert (rl.COLLISION_OFF, rl.COLLISION_ON) == (0, 1)
    assert issubclass(rl.TargetReachError, Exception)


# ------------------------------------------------------------------------------------------------
# The item tree


def test_item_tree_names_types_parents(cell: Station) -> None:
    """Item(name, itemtype): the item, or an invalid one (Valid() False); Parent/Childs;
    ItemList(filter, list_names)."""
    body = (
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        "assert robot.Type() == ITEM_TYPE_ROBOT and robot.Name() == 'KUKA KR 6 R900 sixx'\n"
        "assert robot.Parent().Name() == 'KUKA KR 6 R900 sixx Base'\n"
        "assert [t.Name() for t in robot.Childs()] == ['Torch', 'Pen', 'Gripper']\n"
        "assert RDK.Item('Pallet A').Parent() == RDK.Item('Table')\n"
        "assert RDK.Item('Target 1').Parent().Name() == 'Table'\n"
        "assert RDK.Item('Home').Parent().Type() == ITEM_TYPE_STATION\n"
        "assert not RDK.Item('Nothing').Valid() and not RDK.Item('Table', ITEM_TYPE_TOOL).Valid()\n"
        "assert RDK.ItemList(ITEM_TYPE_FRAME, True) == ['KUKA KR 6 R900 sixx Base', 'Table',"
        " 'Pallet A', 'Pallet B']\n"
        "assert RDK.ItemList(ITEM_TYPE_TARGET, True)[:2] == ['Target 1', 'Approach']\n"
        "assert len(RDK.ItemList(ITEM_TYPE_OBJECT)) == 1\n"
        "robot.Pause(1)\n"
    )
    run(cell, body)


def test_a_call_on_an_invalid_item_is_located(cell: Station) -> None:
    error = failure(cell, "x = 1\nRDK.Item('Nothing').Pose()\n")
    assert isinstance(error, ProgramRunError) and error.span is not None
    assert error.span.line == 7 and "not valid" in error.message


def test_poses_are_relative_to_the_parent_in_mm(cell: Station) -> None:
    """Item.Pose(): "the relative position (pose) of an object, target or reference frame ...
    with respect to its parent"; PoseAbs(): "with respect to the station reference"."""
    body = (
        "a = RDK.Item('Pallet A')\n"
        "assert a.Pose().Pos() == [0, 250, 0] and a.PoseAbs().Pos() == [450, 250, -100]\n"
        "t = RDK.Item('Target 1')\n"
        "assert t.Pose().Pos() == [0, 0, 100] and t.PoseAbs().Pos() == [450, 0, 0]\n"
        "assert near(t.Pose().VZ(), [0, 0, -1]) and t.isJointTarget() == 0\n"
        "h = RDK.Item('Home')\n"
        "assert h.isJointTarget() == 1 and near(h.Joints().list(), [0, -90, 90, 0, 45, 0])\n"
        "b = RDK.Item('Pallet B')\n"
        "b.setPose(transl(0, -200, 10))\n"
        "assert near(b.PoseAbs().Pos(), [450, -200, -90])\n"
        "RDK.Item('', ITEM_TYPE_ROBOT).Pause(1)\n"
    )
    result = run(cell, body)
    assert any("moves for this script only" in i.reason for i in result.ignored)


def test_moves_to_station_targets_use_their_frame(cell: Station) -> None:
    """MoveJ(target item): a Cartesian target keeps its pose in its own frame; a joint target
    is its joints (degrees in the station file, radians in olp)."""
    body = (
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        "robot.setTool(1)\n"
        "robot.MoveJ(RDK.Item('Home'))\n"
        "robot.MoveJ(RDK.Item('Approach'))\n"
        "robot.MoveL(RDK.Item('Target 1'))\n"
    )
    home, approach, down = moves(run(cell, body))
    assert isinstance(home.target, ir.JointTarget) and home.target.name == "Home"
    assert np.allclose(np.degrees(home.target.joints), [0, -90, 90, 0, 45, 0])
    assert isinstance(approach.target, ir.CartesianTarget) and approach.frame.name == "Table"
    assert np.allclose(approach.target.pose[:3, 3], [0, 0, 0.250])
    assert approach.frame is cell.frames["Table"] and approach.tool is cell.tools["Torch"]
    assert isinstance(down, ir.LinearMove) and down.target.name == "Target 1"


def test_added_targets_frames_and_poses(cell: Station) -> None:
    """AddTarget(name, itemparent, itemrobot) / AddFrame(name, itemparent): new items under
    their parent; setPose in the parent (mm), setPoseFrame(pose) relative to the robot base."""
    body = (
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        "frame = RDK.AddFrame('Jig', RDK.Item('Table'))\n"
        "frame.setPose(transl(0, 100, 0))\n"
        "target = RDK.AddTarget('T1', frame, robot)\n"
        "target.setPose(transl(0, 0, 80) * rotx(pi))\n"
        "assert near(target.PoseAbs().Pos(), [450, 100, -20])\n"
        "assert [c.Name() for c in frame.Childs()] == ['T1'] and target.Parent() == frame\n"
        "robot.setTool(1)\n"
        "robot.MoveJ(target)\n"
        "robot.setPoseFrame(transl(500, 0, 0))\n"
        "assert robot.PoseFrame().Pos() == [500, 0, 0]\n"
    )
    (move,) = moves(run(cell, body))
    assert move.frame.name == "Jig" and np.allclose(move.frame.pose[:3, 3], [0.45, 0.1, -0.1])
    assert move.target.name == "T1" and np.allclose(move.target.pose[:3, 3], [0, 0, 0.08])


def test_tools_by_item_number_and_pose_get_controller_numbers(cell: Station) -> None:
    """setPoseTool(tool): "robot tool as an item, or a pose"; olp also takes a tool number.
    Tools the script defines get the next free controller number (station tools are 1-3)."""
    body = (
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        "robot.setTool(2)\n"
        "robot.MoveJ(RDK.Item('Home'))\n"
        "robot.setPoseTool(RDK.Item('Gripper'))\n"
        "robot.MoveJ(RDK.Item('Home'))\n"
        "robot.setPoseTool(transl(0, 0, 100))\n"
        "robot.MoveJ(RDK.Item('Home'))\n"
        "probe = robot.AddTool(transl(0, 0, 150), 'Probe')\n"
        "assert probe.Parent() == robot and probe.PoseTool().Pos() == [0, 0, 150]\n"
        "robot.MoveJ(RDK.Item('Home'))\n"
    )
    tools = [m.tool for m in moves(run(cell, body))]
    assert [t.name for t in tools[:2]] == ["Pen", "Gripper"] and tools[0].number == 2
    assert (tools[2].number, tools[3].name, tools[3].number) == (4, "Probe", 5)
    assert np.allclose(tools[2].pose[:3, 3], [0, 0, 0.1])
    error = failure(cell, "RDK.Item('', ITEM_TYPE_ROBOT).setTool(9)\n")
    assert error.span.line == 6 and "no tool number 9 (tools: 1 Torch, 2 Pen, 3 Gripper)" in (
        error.message
    )


def test_item_user_pick_takes_the_only_one_or_the_named_one(cell: Station) -> None:
    body = (
        "robot = RDK.ItemUserPick('Select a robot', ITEM_TYPE_ROBOT)\n"
        "frame = RDK.ItemUserPick('Select a frame', ITEM_TYPE_FRAME)\n"
        "robot.setPoseFrame(frame)\n"
        "robot.MoveJ(RDK.Item('Home'))\n"
    )
    (move,) = moves(run(cell, body, PICK_FRAME="Pallet B"))
    assert move.frame.name == "Pallet B"
    error = failure(cell, body)
    assert error.span.line == 7 and "choose one with --set PICK_FRAME=NAME" in error.message


# ------------------------------------------------------------------------------------------------
# Run modes, move tests, kinematics

UNREACHABLE = "transl(0, 0, 2000) * RDK.Item('Target 1').Pose()"


def test_simulate_mode_raises_target_reach_error_and_skips(cell: Station) -> None:
    """Robolink.setRunMode: RUNMODE_SIMULATE "performs the simulation moving the robot
    (default)"; a move the robot cannot make raises TargetReachError."""
    body = (
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        "robot.setPoseFrame(RDK.Item('Table'))\n"
        "robot.MoveJ(RDK.Item('Home'))\n"
        "try:\n"
        f"    robot.MoveJ({UNREACHABLE})\n"
        "except TargetReachError:\n"
        "    robot.RunInstruction('skipped', INSTRUCTION_COMMENT)\n"
    )
    result = run(cell, body)
    assert [i.kind for i in result.program.instructions] == ["joint", "comment"]
    (warning,) = result.warnings
    assert warning.span.line == 10 and "TargetReachError" in warning.message
    assert "out of the robot's reach" in warning.message
    uncaught = failure(
        cell,
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        f"robot.MoveJ(RDK.Item('Home'))\nrobot.MoveJ({UNREACHABLE})\n",
    )
    assert isinstance(uncaught, ProgramRunError) and uncaught.span.line == 8
    assert uncaught.message.startswith("TargetReachError: MoveJ:")


def test_program_mode_records_unchecked(cell: Station) -> None:
    """RUNMODE_MAKE_ROBOTPROG "makes the robot program": moves are not simulated."""
    body = (
        "RDK.setRunMode(RUNMODE_MAKE_ROBOTPROG)\n"
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        f"robot.MoveJ({UNREACHABLE})\n"
    )
    result = run(cell, body)
    assert len(moves(result)) == 1 and not result.warnings


def test_collision_checking_follows_set_collision_active(cell: Station) -> None:
    """setCollisionActive(COLLISION_ON); MoveJ_Test: "returns 0 if the movement is free of
    collision or any other issues. Otherwise it returns the number of pairs of objects that
    collided"; in simulate mode a colliding MoveJ raises TargetReachError."""
    body = (
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        "robot.setPoseFrame(RDK.Item('Table'))\n"
        "robot.setTool(1)\n"
        "home = RDK.Item('Home').Joints()\n"
        "into = transl(0, 0, -130) * RDK.Item('Target 1').Pose()\n"
        "j = robot.SolveIK(into, None, robot.PoseTool(), robot.PoseFrame())\n"
        "assert robot.MoveJ_Test(home, j) == 0\n"
        "robot.setJoints(home)\n"
        "robot.MoveJ(into)\n"
        "assert RDK.setCollisionActive(COLLISION_ON) == COLLISION_OFF\n"
        "assert robot.MoveJ_Test(home, j) >= 1\n"
        "robot.setJoints(home)\n"
        "try:\n"
        "    robot.MoveJ(into)\n"
        "    raise AssertionError('no TargetReachError')\n"
        "except TargetReachError as e:\n"
        "    assert 'Table top' in str(e), str(e)\n"
    )
    assert len(moves(run(cell, body))) == 1


def test_move_tests_return_robodk_codes_and_place_the_robot(cell: Station) -> None:
    """MoveL_Test: "returns 0 if the movement is free of collision or any other issues ...
    If the robot can not reach the target pose it returns -2. If the robot can reach the
    target but it can not make a linear movement it returns -1"; the robot "will be placed at
    the destination pose" (Joints() then gives its joints)."""
    body = (
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        "robot.setPoseFrame(RDK.Item('Table'))\n"
        "robot.setTool(1)\n"
        "approach = RDK.Item('Approach')\n"
        "start = approach.Joints()\n"
        "down = RDK.Item('Target 1').Pose()\n"
        "assert robot.MoveL_Test(start, down) == 0\n"
        "assert near(robot.Pose().Pos(), [0, 0, 100])\n"
        "placed = robot.Joints().list()\n"
        f"assert robot.MoveL_Test(start, {UNREACHABLE}) == -2\n"
        "assert robot.MoveL_Test(start, transl(-800, 0, 0) * down) == -1\n"
        "assert robot.Joints().list() == placed\n"
        "robot.Pause(1)\n"
    )
    run(cell, body)


def test_solve_fk_ik_joints_config(cell: Station) -> None:
    """SolveFK(joints, tool, reference): the flange "with respect to the robot base reference";
    SolveIK(pose, joints_approx, tool, reference) returns a Mat of joints, an empty Mat when
    there is no solution; SolveIK_All: "a 2D matrix [N x M], where N is the number of degrees
    of freedom (robot joints) and M is the number of solutions"; JointsConfig: "[REAR,
    LOWERARM, FLIP, turns]"."""
    body = (
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        "j = [10, -80, 100, 20, 40, -30]\n"
        "pose = robot.SolveFK(j)\n"
        "sol = robot.SolveIK(pose, j)\n"
        "assert len(sol.list()) == 6 and near(sol.list(), j)\n"
        "tool = transl(0, 0, 100)\n"
        "assert robot.SolveFK(j, tool).Pos() == (pose * tool).Pos()\n"
        "assert len(robot.SolveIK(transl(5000, 0, 0)).list()) == 0\n"
        "assert robot.JointsConfig(j).list() == [0, 0, 0, 0]\n"
        "assert robot.JointsConfig([10, -80, 100, 20, -40, -30]).list()[2] == 1\n"
        "lower, upper, kind = robot.JointLimits()\n"
        "assert near([lower.list()[2], upper.list()[2], kind], [-120, 156, 0])\n"
        "assert len(robot.JointPoses(j)) == 7 and robot.JointPoses(j)[0].Pos() == [0, 0, 0]\n"
        "sols = robot.SolveIK_All(pose)\n"
        "assert sols.size(0) == 6 and len(sols) >= 4\n"
        "assert all(near(robot.SolveFK(s).Pos(), pose.Pos()) for s in sols)\n"
        "robot.Pause(1)\n"
    )
    run(cell, body)


def test_speeds_and_rounding_units(cell: Station) -> None:
    """setSpeed(speed_linear mm/s, speed_joints deg/s, ...); setRounding(mm), -1 exact."""
    body = (
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        "robot.setSpeed(200)\n"
        "robot.setRounding(5)\n"
        "robot.MoveJ(RDK.Item('Home'))\n"
    )
    (move,) = moves(run(cell, body))
    assert math.isclose(move.speed.linear, 0.2) and math.isclose(move.zone.radius, 0.005)


def test_move_c_records_the_dsl_circular_move(cell: Station) -> None:
    """MoveC(target1, target2): "target1: pose along the circle movement, target2: final
    circle target"; olp records the DSL's circular move, checked in simulate mode."""
    body = (
        "RDK.setRunMode(RUNMODE_MAKE_ROBOTPROG)\n"
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        "robot.setPoseFrame(RDK.Item('Table'))\n"
        "t = RDK.Item('Target 1').Pose()\n"
        "robot.MoveC(transl(50, 50, 0) * t, transl(100, 0, 0) * t)\n"
    )
    (move,) = moves(run(cell, body))
    assert isinstance(move, ir.CircularMove)
    assert np.allclose(move.via.pose[:3, 3], [0.05, 0.05, 0.1])
    assert np.allclose(move.target.pose[:3, 3], [0.1, 0, 0.1])
    simulated = (
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        "robot.setPoseFrame(RDK.Item('Table'))\n"
        "robot.setTool(1)\n"
        "t = RDK.Item('Target 1').Pose()\n"
        "robot.MoveJ(transl(-50, 0, 0) * t)\n"
        "robot.MoveC(transl(0, 50, 0) * t, transl(50, 0, 0) * t)\n"
        "try:\n"
        "    robot.MoveC(transl(0, 500, 0) * t, transl(3000, 0, 0) * t)\n"
        "except TargetReachError:\n"
        "    pass\n"
    )
    result = run(cell, simulated)
    assert [m.kind for m in moves(result)] == ["joint", "circular"]
    assert len(result.warnings) == 1 and result.warnings[0].span.line == 13


# ------------------------------------------------------------------------------------------------
# Program items


PROGRAM = (
    "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
    "prog = RDK.AddProgram('Cell', robot)\n"
    "prog.setPoseFrame(RDK.Item('Table'))\n"
    "prog.setPoseTool(RDK.Item('Torch'))\n"
    "prog.MoveJ(RDK.Item('Home'))\n"
    "prog.MoveJ(RDK.Item('Approach'))\n"
    "prog.MoveL(RDK.Item('Target 1'))\n"
    "prog.Pause(300)\n"
    "prog.MoveJ(RDK.Item('Approach'))\n"
)


def test_program_items_build_the_program(cell: Station) -> None:
    result = run(cell, PROGRAM + "robot.MoveJ(RDK.Item('Home'))\n")
    assert result.program.name == "Cell"
    assert [i.kind for i in result.program.instructions] == [
        "joint",
        "joint",
        "linear",
        "wait",
        "joint",
    ]
    (noted,) = result.ignored
    assert noted.span.line == 15 and "simulated only; olp builds program 'Cell'" in noted.reason


def test_instruction_access_and_editing(cell: Station) -> None:
    """Instruction(ins_id): "(name, instype, movetype, isjointtarget, target, joints)", a move
    with both its pose and its joints;
    setInstruction(ins_id, name, instype, movetype, isjointtarget, target, joints);
    InstructionDelete(ins_id) is True when it deleted; InstructionCount()."""
    body = PROGRAM + (
        "assert prog.InstructionCount() == 5\n"
        "name, kind, move, isjoint, pose, joints = prog.Instruction(0)\n"
        "assert (kind, move, isjoint) == (INS_TYPE_MOVE, MOVE_TYPE_JOINT, 1)\n"
        "assert near(robot.SolveFK(joints, robot.Childs()[0].PoseTool(),"
        " RDK.Item('Table').PoseAbs()).Pos(), pose.Pos())\n"
        "assert near(joints.list(), [0, -90, 90, 0, 45, 0])\n"
        "name, kind, move, isjoint, pose, joints = prog.Instruction(2)\n"
        "assert (move, isjoint) == (MOVE_TYPE_LINEAR, 0) and near(pose.Pos(), [0, 0, 100])\n"
        "assert near(robot.SolveIK(pose, joints, RDK.Item('Torch').PoseTool(),"
        " RDK.Item('Table').PoseAbs()).list(), joints.list())\n"
        "assert prog.Instruction(3)[1] == INS_TYPE_PAUSE\n"
        "prog.setInstruction(2, name, kind, MOVE_TYPE_JOINT, 0, transl(0, 0, -2) * pose, None)\n"
        "assert prog.InstructionDelete(3) and not prog.InstructionDelete(10)\n"
        "assert prog.InstructionCount() == 4\n"
    )
    kinds = [(i.kind, getattr(i, "frame", None)) for i in run(cell, body).program.instructions]
    assert [k for k, _ in kinds] == ["joint", "joint", "joint", "joint"]
    edited = run(cell, body).program.instructions[2]
    assert np.allclose(edited.target.pose[:3, 3], [0, 0, 0.098])  # type: ignore[union-attr]
    assert edited.frame.name == "Table"  # type: ignore[union-attr]


def test_update_returns_robodk_tuple_from_olps_passes(cell: Station) -> None:
    """Update(): "[valid_instructions, program_time, program_distance, valid_ratio,
    readable_msg]": instructions, seconds, mm of TCP travel, 0..1, text."""
    body = PROGRAM + (
        "valid, seconds, mm, ratio, msg = prog.Update()\n"
        "assert (valid, ratio, msg) == (5, 1.0, 'Program OK'), (valid, ratio, msg)\n"
        "assert 0.3 < seconds < 30 and 100 < mm < 5000, (seconds, mm)\n"
        f"prog.MoveJ({UNREACHABLE})\n"
        "valid, seconds, mm, ratio, msg = prog.Update()\n"
        "assert valid == 5 and ratio < 1 and 'reach' in msg, (valid, ratio, msg)\n"
        "prog.InstructionDelete(5)\n"
        "matrix, errors = prog.InstructionList()\n"
        "assert matrix.size() == (7, 5) and errors == 0\n"
        "assert matrix.tr().rows[2][6] == 2 and matrix.tr().rows[3][6] == 0\n"
    )
    run(cell, body)


def test_several_programs_need_make_program(cell: Station) -> None:
    two = PROGRAM + "other = RDK.AddProgram('Other', robot)\nother.MoveJ(RDK.Item('Home'))\n"
    error = failure(cell, two)
    assert "filled 2 programs (Cell, Other)" in error.message and "MakeProgram" in error.message
    result = run(cell, two + "assert other.MakeProgram()[0]\n")
    assert result.program.name == "Other" and len(result.program.instructions) == 1


# ------------------------------------------------------------------------------------------------
# Notes and errors


def test_what_olp_cannot_do_is_noted_at_its_line(cell: Station) -> None:
    body = (
        "RDK.Render(False)\n"
        "RDK.ShowMessage('hello')\n"
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        "for i in range(3):\n"
        "    robot.Connect()\n"
        "robot.MoveJ(RDK.Item('Home'))\n"
    )
    notes = [(i.span.line, i.reason.split(":")[0]) for i in run(cell, body).ignored]
    assert notes == [(6, "Render"), (7, "ShowMessage"), (10, "Connect")]  # once per line
    error = failure(cell, "RDK.setRunMode(RUNMODE_RUN_ROBOT)\n")
    assert error.span.line == 6 and "olp runs offline" in error.message


def test_errors_in_a_script_point_at_its_line_with_its_own_traceback(cell: Station) -> None:
    body = (
        "def corner(i):\n"
        "    return RDK.Item('Target %i' % i).Pose()\n"
        "\n"
        "def path():\n"
        "    return [corner(i) for i in range(1, 3)]\n"
        "\n"
        "path()\n"
    )
    error = failure(cell, body)
    assert isinstance(error, ProgramRunError) and error.kind == "error running the program"
    assert error.span.line == 7 and "Pose: the item is not valid" in error.message
    assert error.hint is not None
    trace = error.hint.splitlines()[1:]
    assert [line.split(" in ")[0].strip() for line in trace] == [
        "prog.py:12",
        "prog.py:10",
        "prog.py:10",
        "prog.py:7",
    ]
    assert "olp" not in error.hint.replace("prog.py", "")
    own = failure(cell, "x = {}\nx['missing']\n")
    assert own.span.line == 7 and own.message == "KeyError: 'missing'"


def test_help_of_olp_dsl_lists_every_robot_method() -> None:
    """Issue 16: ``help(olp.dsl)`` did not list the robot's methods."""
    import pydoc

    from olp import dsl

    text = pydoc.render_doc(dsl, renderer=pydoc.plaintext)
    for cls in (dsl.Robot, dsl.Mat, dsl.Target):
        assert f"class {cls.__name__}" in text
        public = [n for n in vars(cls) if not n.startswith("_") and callable(getattr(cls, n))]
        missing = [n for n in public if f"{n}(self" not in text and f"{n} = " not in text]
        assert not missing, (cls.__name__, missing)


def test_a_pose_read_back_keeps_its_tool_and_frame(cell: Station) -> None:
    """``program.setPoseTool(robot.PoseTool())`` (RoboDK's CSV example) keeps the station's
    tool, and with it its controller number, instead of defining a new one; likewise frames;
    ``robot.getLink(ITEM_TYPE_FRAME)`` is the robot's active frame (its base frame at first)."""
    body = (
        "robot = RDK.Item('', ITEM_TYPE_ROBOT)\n"
        "robot.setPoseTool(RDK.Item('Pen'))\n"
        "frame = robot.getLink(ITEM_TYPE_FRAME)\n"
        "assert frame.Name() == 'KUKA KR 6 R900 sixx Base', frame\n"
        "assert robot.getLink(ITEM_TYPE_TOOL).Name() == 'Pen'\n"
        "prog = RDK.AddProgram('P', robot)\n"
        "prog.setPoseTool(robot.PoseTool())\n"
        "prog.setPoseFrame(RDK.Item('Table').Pose())\n"
        "prog.MoveJ(RDK.Item('Home'))\n"
        "prog.setPoseTool(eye(4))\n"
        "prog.MoveJ(RDK.Item('Home'))\n"
    )
    first, second = moves(run(cell, body))
    assert first.tool is cell.tools["Pen"] and first.frame is cell.frames["Table"]
    assert second.tool is ir.FLANGE


def test_file_dialogs_take_the_file_from_the_command_line(cell: Station, tmp_path: Path) -> None:
    """robodialogs.getOpenFileName opens a dialog in RoboDK; on olp ``--set OPEN_FILE=PATH``
    answers it (noted), and without one it is an error naming the parameter."""
    points = tmp_path / "points.csv"
    points.write_text("1,2,3\n", encoding="utf-8")
    body = (
        "from robodk.robodialogs import getOpenFileName\n"
        "from robodk.robofileio import LoadList\n"
        "path = getOpenFileName(RDK.getParam('PATH_OPENSTATION'))\n"
        "assert LoadList(path) == [[1.0, 2.0, 3.0]]\n"
        "RDK.Item('', ITEM_TYPE_ROBOT).Pause(1)\n"
    )
    result = run(cell, body, OPEN_FILE=str(points))
    assert [i.span.line for i in result.ignored] == [8]
    error = failure(cell, body)
    assert error.span.line == 8 and "--set OPEN_FILE=PATH" in error.message


def test_instruction_select_inserts_after_the_selected_instruction(cell: Station) -> None:
    """InstructionSelect(ins_id): "New instructions will be added after the selected
    instruction" (RoboDK's PrintProgramInstructions example adds a call after each one)."""
    body = PROGRAM + (
        "prog.InstructionSelect(1)\n"
        "prog.RunInstruction('AfterApproach')\n"
        "prog.RunInstruction('Second')\n"
        "assert prog.InstructionSelect() == 3\n"
        "prog.InstructionDelete(0)\n"
        "prog.RunInstruction('Third')\n"
    )
    kinds = [getattr(i, "name", i.kind) for i in run(cell, body).program.instructions]
    assert kinds == ["joint", "AfterApproach", "Second", "Third", "linear", "wait", "joint"]
    error = failure(cell, PROGRAM + "prog.setParam(0)\n")
    assert error.span.line == 15 and "Instruction/setInstruction" in error.message
