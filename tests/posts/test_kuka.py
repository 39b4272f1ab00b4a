"""The KRL post, pinned: table-driven (small IR programs -> expected .src/.dat lines), options
(named points in the .dat, indexed TOOL_DATA/BASE_DATA, PTP approximation), diagnostics, the
round trip through the KRL frontend (same targets, same joints, S/T respected), Status/Turn that
select the planned joints on random targets in every branch of every KUKA and ABB robot,
splitting, and golden files of USERS.md jobs 1-6.

Golden files: ``tests/golden/kuka/``. After a reviewed change, regenerate them with
``OLP_UPDATE_GOLDEN=1 python -m pytest tests/posts/test_kuka.py`` (the test then fails once, so
the variable can never pass CI by accident) and state the reason in the commit.
"""

from __future__ import annotations

import dataclasses
import math
import re
import shutil
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import olp
from olp import ir
from olp.compiled import CompiledProgram, Step
from olp.diagnostics import Diagnostic
from olp.errors import PostError
from olp.frontends.krl import load_krl
from olp.kinematics.base import turn_variants
from olp.kinematics.configuration import satisfies
from olp.posts import find_post
from olp.posts.base import Post
from olp.posts.kuka import NAME_RULE, krl_e6pos, krl_percent, krl_point_type
from olp.station.loader import load_library_robot, robot_library
from olp.station.model import Robot, Station
from olp.vendors import kuka
from tests.krl_round_trip import comment_lines, keeps_in_order, statements
from tests.posts.test_comment_folds import TEMPLATE_INI

GoldenCheck = Callable[..., None]

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
ABB_CELL = REPO / "stations" / "abb_irb120_pick_cell.yaml"
MILLING = REPO / "examples" / "milling.src"
PICK = Path(__file__).resolve().parent / "pick_irb120.src"
GOLDEN = REPO / "tests" / "golden" / "kuka"

DEG = math.pi / 180.0


def render(compiled: CompiledProgram, post: Post, name: str | None = None) -> dict[str, str]:
    """The post's files (its transforms applied)."""
    return post.render(compiled, name)


def post_diagnostics(compiled: CompiledProgram, post: Post) -> list[Diagnostic]:
    """What the post reports: its transforms' diagnostics, then its checks."""
    prepared, found = post.prepare(compiled)
    return found + post.check(prepared)


@pytest.fixture(scope="module")
def station() -> Station:
    return olp.load_station(CELL)


def _post(**options: Any) -> Post:
    return find_post("kuka", options={"ini_fold": False, **options})


def _pose(x: float, y: float, z: float, a: float, b: float, c: float) -> np.ndarray:
    return kuka.frame_to_pose([x, y, z, a, b, c])


def _compile(station: Station, instructions: Sequence[ir.Instruction]) -> CompiledProgram:
    compiled = olp.compile(ir.Program(name="Row", instructions=tuple(instructions)), station)
    assert compiled.ok, [d.format() for d in compiled.diagnostics]
    return compiled


def _body(text: str) -> list[str]:
    """The lines between the header comment and END of a .src (CRLF checked on the way)."""
    assert text.endswith("END\r\n") or text.endswith("END")
    assert "\n" not in text.replace("\r\n", "")
    lines = text.split("\r\n")
    start = next(i for i, line in enumerate(lines) if line.startswith("DEF ")) + 1
    if ";ENDFOLD (INI)" in lines:
        start = lines.index(";ENDFOLD (INI)")
    end = lines.index("END")
    return [line for line in lines[start + 1 : end] if line]


# --------------------------------------------------------------------------------------------
# Table: IR -> lines

Q0 = np.radians([107.78457, -44.9526, 141.64681, 107.66839, -87.93467, 6.3771])
TABLE_TOOL = ir.Tool(name="spindle")
TABLE = ir.Frame(name="table")
BASE = "$BASE = {FRAME: X 0.000,Y -1000.000,Z 0.000,A 0.0000,B 0.0000,C 0.0000} ; table"
TOOL = "$TOOL = {FRAME: X 466.604,Y -4.165,Z 109.636,A 0.0000,B 90.0000,C 0.0000} ; spindle"
AXIS = "A1 107.78457,A2 -44.95260,A3 141.64681,A4 107.66839,A5 -87.93467,A6 6.37710"
ST = r"S \d+,T \d+"
TOP = "X 0.000,Y 0.000,Z 6.350,A 180.0000,B 0.0000,C 180.0000"
SIDE = "X 276.225,Y 0.000,Z 6.350,A 180.0000,B 0.0000,C 180.0000"


def _ptp(q: np.ndarray = Q0, **kw: Any) -> ir.JointMove:
    kw = {"tool": TABLE_TOOL, "frame": TABLE, **kw}
    return ir.JointMove(target=ir.JointTarget(joints=q), **kw)


def _lin(*xyzabc: float, move: type = ir.LinearMove, **kw: Any) -> Any:
    target = ir.CartesianTarget(pose=_pose(*xyzabc))
    return move(target=target, tool=TABLE_TOOL, frame=TABLE, **kw)


def _velocities(percent: str, acc: str) -> list[str]:
    return [f"$VEL_AXIS[{i}] = {percent}" for i in range(1, 7)] + [
        f"$ACC_AXIS[{i}] = {acc}" for i in range(1, 7)
    ]


ROWS: dict[str, tuple[list[ir.Instruction], list[str]]] = {
    "ptp to axis values is an E6AXIS aggregate": (
        [_ptp(speed=ir.Speed(joint=0.5, joint_acceleration=0.25))],
        [BASE, TOOL, *_velocities("50", "25"), f"PTP {{{AXIS}}}"],
    ),
    "lin is an E6POS with S and T; speed and zone once": (
        [
            _ptp(),
            _lin(0, 0, 6.35, 180, 0, 180, speed=ir.Speed(linear=0.1), zone=ir.Zone(0.005)),
            _lin(276.225, 0, 6.35, 180, 0, 180, speed=ir.Speed(linear=0.1), zone=ir.Zone(0.005)),
            _lin(0, 0, 6.35, 180, 0, 180, speed=ir.Speed(linear=0.02)),
        ],
        [
            BASE,
            TOOL,
            *_velocities("100", "100"),
            f"PTP {{{AXIS}}}",
            "$VEL.CP = 0.10000",
            "$APO.CDIS = 5.000",
            f"LIN {{{TOP},{ST}}} C_DIS",
            f"LIN {{{SIDE},{ST}}} C_DIS",
            "$VEL.CP = 0.02000",
            f"LIN {{{TOP},{ST}}}",
        ],
    ),
    "ptp to a Cartesian target is an E6POS with S and T": (
        [_lin(0, 0, 6.35, 180, 0, 180, move=ir.JointMove)],
        [BASE, TOOL, *_velocities("100", "100"), f"PTP {{{TOP},{ST}}}"],
    ),
    "orientation speed": (
        [_ptp(), _lin(0, 0, 6.35, 180, 0, 180, speed=ir.Speed(linear=0.1, angular=math.pi / 4))],
        [
            BASE,
            TOOL,
            *_velocities("100", "100"),
            f"PTP {{{AXIS}}}",
            "$VEL.CP = 0.10000",
            "$VEL.ORI1 = 45.000",
            "$VEL.ORI2 = 45.000",
            f"LIN {{{TOP},{ST}}}",
        ],
    ),
    "i/o, waits, calls and comments": (
        [
            ir.Comment(text="start"),
            ir.SetOutput(index=3, value=True),
            ir.Wait(seconds=0.5),
            ir.WaitInput(index=7, value=False),
            ir.WaitInput(index=8),
            ir.Call(name="SprayOn"),
            ir.Call(name="Tool_Change", args=("2", "TRUE")),
            ir.SetOutput(index=3, value=False),
        ],
        [
            "; start",
            "$OUT[3] = TRUE",
            "WAIT SEC 0.500",
            "WAIT FOR NOT $IN[7]",
            "WAIT FOR $IN[8]",
            "SprayOn()",
            "Tool_Change(2, TRUE)",
            "$OUT[3] = FALSE",
        ],
    ),
}


def _match(lines: list[str], expected: list[str]) -> None:
    assert len(lines) == len(expected), "\n".join(lines)
    for line, want in zip(lines, expected, strict=True):
        pattern = re.escape(want).replace(re.escape(ST), ST)
        assert re.fullmatch(pattern, line), f"{line!r} does not match {want!r}"


@pytest.mark.parametrize("row", list(ROWS))
def test_table(row: str, station: Station) -> None:
    instructions, expected = ROWS[row]
    files = render(_compile(station, instructions), _post())
    _match(_body(files["Row.src"]), expected)
    assert files["Row.dat"] == "&ACCESS RVP\r\n&REL 1\r\nDEFDAT Row PUBLIC\r\nENDDAT\r\n"


def test_the_whole_src_layout(station: Station) -> None:
    text = render(_compile(station, [_ptp()]), find_post("kuka"))["Row.src"]
    lines = text.split("\r\n")
    assert lines[:4] == ["&ACCESS RVP", "&REL 1", "DEF Row( )", "; generated by olp from <memory>"]
    # the pendant's INI fold (KSS 8 new-module template)
    assert lines[4:15] == TEMPLATE_INI
    assert lines[-2:] == ["END", ""] and all(line == line.rstrip() for line in lines)


def test_named_points_in_the_dat(station: Station) -> None:
    compiled = _compile(
        station, [_ptp(), _lin(0, 0, 6.35, 180, 0, 180), _lin(0, 0, 6.35, 180, 0, 180)]
    )
    files = render(compiled, _post(points="dat"))
    assert _body(files["Row.src"])[-4:] == ["PTP XP1", "$VEL.CP = 0.25000", "LIN XP2", "LIN XP3"]
    dat = files["Row.dat"].split("\r\n")
    assert dat[:3] == ["&ACCESS RVP", "&REL 1", "DEFDAT Row PUBLIC"]
    _match(
        dat[3:7],
        [
            f"DECL E6AXIS XP1={{{AXIS}}}",
            f"DECL E6POS XP2={{{TOP},{ST}}}",
            f"DECL E6POS XP3={{{TOP},{ST}}}",
            "ENDDAT",
        ],
    )


def test_indexed_tool_and_base(station: Station) -> None:
    compiled = _compile(station, [_ptp(), _ptp(tool=ir.FLANGE, frame=ir.WORLD)])
    lines = _body(render(compiled, _post(frames="indexed"))["Row.src"])
    assert lines[:2] == ["$BASE = BASE_DATA[1] ; table", "$TOOL = TOOL_DATA[1] ; spindle"]
    assert "$BASE = $NULLFRAME ; world" in lines and "$TOOL = $NULLFRAME ; flange" in lines


def test_indexed_mode_needs_numbers(station: Station) -> None:
    shifted = np.eye(4)
    shifted[2, 3] = 0.1
    tool = ir.Tool(name="pen", pose=shifted)
    compiled = _compile(station, [dataclasses.replace(_ptp(), tool=tool)])
    with pytest.raises(PostError, match=r"tool 'pen' needs a number 1\.\.16"):
        render(compiled, _post(frames="indexed"))


def test_ptp_approximation_option(station: Station) -> None:
    moves = [_ptp(zone=ir.Zone(0.02)), _lin(0, 0, 6.35, 180, 0, 180, zone=ir.Zone(0.02))]
    compiled = _compile(station, moves)
    exact = _body(render(compiled, _post())["Row.src"])
    assert f"PTP {{{AXIS}}}" in exact and not any("CPTP" in line for line in exact)
    approx = _body(render(compiled, _post(ptp_approximation=50))["Row.src"])
    assert approx[-5:-3] == ["$APO.CPTP = 50", f"PTP {{{AXIS}}} C_PTP"]
    # the LIN after it still sets its distance: $APO.CDIS is tracked on its own
    assert approx[-2] == "$APO.CDIS = 20.000"


def _circular_program(station: Station) -> CompiledProgram:
    """A CIRC built by hand: resolve does not plan circles yet, the post must still write them."""
    start = _compile(station, [_ptp(), _lin(0, 0, 6.35, 180, 0, 180)])
    end = _compile(station, [_ptp(), _lin(276.225, 0, 6.35, 180, 0, 180)])
    circ = ir.CircularMove(
        target=ir.CartesianTarget(pose=_pose(276.225, 0, 6.35, 180, 0, 180)),
        via=ir.CartesianTarget(pose=_pose(138.1125, 50, 6.35, 180, 0, 180)),
        tool=TABLE_TOOL,
        frame=TABLE,
        zone=ir.Zone(0.002),
    )
    last = end.steps[1]
    step = Step(2, circ, last.joints, last.path, last.tool, last.frame)
    program = ir.Program(name="Row", instructions=(*start.program.instructions, circ))
    return dataclasses.replace(start, program=program, steps=(*start.steps, step))


def test_circular_moves(station: Station) -> None:
    compiled = _circular_program(station)
    via = "X 138.113,Y 50.000,Z 6.350,A 180.0000,B 0.0000,C 180.0000"
    inline = _body(render(compiled, _post())["Row.src"])
    # the first arc states its orientation rule: the controller's state is not olp's to assume
    arc = f"CIRC {{{via}}}, {{{SIDE},{ST}}} C_DIS"
    _match(inline[-4:], ["$APO.CDIS = 2.000", "$ORI_TYPE = #VAR", "$CIRC_TYPE = #BASE", arc])
    named = render(compiled, _post(points="dat"))
    assert _body(named["Row.src"])[-1] == "CIRC XA3, XP3 C_DIS"
    assert f"DECL E6POS XA3={{{via}}}" in named["Row.dat"].split("\r\n")


# --------------------------------------------------------------------------------------------
# Diagnostics


def test_diagnostics(station: Station) -> None:
    moves = [
        _ptp(speed=ir.Speed(joint=0.005), zone=ir.Zone(0.01)),
        ir.Call(name="Spray-On"),
        ir.Call(name="SprayOn"),
        _ptp(speed=ir.Speed(joint=0.1463)),
    ]
    compiled = _compile(station, moves)
    found = [(d.severity, d.kind, d.index) for d in post_diagnostics(compiled, find_post("kuka"))]
    assert found == [
        ("warning", "zone_dropped", 0),
        ("error", "joint_speed", 0),
        ("error", "call_name", 1),
        ("warning", "joint_speed", 3),
    ]


@pytest.mark.parametrize(
    ("fraction", "text"), [(1.0, "100"), (0.1463, "14"), (0.29, "29"), (0.5, "50"), (0.004, "1")]
)
def test_axis_percent_is_whole_and_rounded_down(fraction: float, text: str) -> None:
    assert krl_percent(_post(), fraction) == text


def test_an_error_diagnostic_writes_nothing(station: Station, tmp_path: Path) -> None:
    program = ir.Program(name="Bad", instructions=(_ptp(), ir.Call(name="Spray On")))
    result = olp.build(station, program, post="kuka", out_dir=tmp_path / "out")
    assert not result.ok and not (tmp_path / "out").exists()


# --------------------------------------------------------------------------------------------
# Round trip through the KRL frontend


def _motions(program: ir.Program) -> list[ir.Motion]:
    return list(program.motions())


def _same_targets(first: list[ir.Motion], second: list[ir.Motion]) -> None:
    assert [m.kind for m in first] == [m.kind for m in second]
    for a, b in zip(first, second, strict=True):
        if isinstance(a.target, ir.CartesianTarget):
            assert isinstance(b.target, ir.CartesianTarget)
            # mm within 1e-6, and the rotation to the same precision at a 1 m lever arm
            assert np.allclose(a.target.pose[:3, 3], b.target.pose[:3, 3], rtol=0, atol=1e-9)
            assert np.allclose(a.target.pose[:3, :3], b.target.pose[:3, :3], rtol=0, atol=1e-9)
        else:
            assert isinstance(a.target, ir.JointTarget) and isinstance(b.target, ir.JointTarget)
            assert np.allclose(a.target.joints, b.target.joints, rtol=0, atol=1e-6 * DEG)
        # the speed that governs the motion: $VEL.CP for LIN/CIRC, $VEL_AXIS/$ACC_AXIS for PTP
        if a.kind == "joint":
            assert a.speed.joint == pytest.approx(b.speed.joint, abs=1e-9)
            assert a.speed.joint_acceleration == pytest.approx(b.speed.joint_acceleration, abs=1e-9)
        else:
            assert a.speed.linear == pytest.approx(b.speed.linear, abs=1e-9)
        assert a.zone.radius == pytest.approx(b.zone.radius, abs=1e-9)
        assert a.tool.pose is not None and b.tool.pose is not None
        assert np.allclose(a.tool.pose, b.tool.pose, rtol=0, atol=1e-9)
        assert a.frame.pose is not None and b.frame.pose is not None
        assert np.allclose(a.frame.pose, b.frame.pose, rtol=0, atol=1e-9)


def _write(files: dict[str, str], folder: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in files.items():
        (folder / name).write_bytes(text.encode("ascii"))


ROUND_TRIP = REPO / "tests" / "posts" / "round_trip.src"


@pytest.mark.parametrize("points", ["inline", "dat"])
@pytest.mark.parametrize("source", [MILLING, ROUND_TRIP], ids=["milling", "round_trip"])
def test_round_trip(points: str, source: Path, station: Station, tmp_path: Path) -> None:
    original = load_krl(source).program
    compiled = olp.compile(original, station)
    assert compiled.ok, [d.format() for d in compiled.diagnostics]
    _write(render(compiled, _post(points=points)), tmp_path)
    again = load_krl(tmp_path / f"{compiled.program.name}.src")
    _same_targets(_motions(original), _motions(again.program))
    assert [i.kind for i in statements(again.program)] == [i.kind for i in statements(original)]
    assert keeps_in_order(comment_lines(again.program), comment_lines(original))
    # the same joint solutions: planned again, and selected by the written S and T
    replanned = olp.compile(again.program, station)
    for a, b in zip(compiled.motion_steps(), replanned.motion_steps(), strict=True):
        assert np.allclose(a.joints, b.joints, rtol=0, atol=1e-6)  # type: ignore[arg-type]
    # one S/T per E6POS written: every motion but the PTPs to axis values
    post = _post()
    e6pos = [s for s in compiled.motion_steps() if krl_point_type(post, _kind_view(s)) == "E6POS"]
    assert len(again.status_turn) == len(e6pos)


def _kind_view(step: Step) -> Any:
    ins = step.instruction
    cartesian = isinstance(getattr(ins, "target", None), ir.CartesianTarget)
    return type("View", (), {"kind": ins.kind, "cartesian": cartesian, "vendor": {}})()


def test_written_status_and_turn_select_the_planned_joints_after_reading_back(
    station: Station, tmp_path: Path
) -> None:
    compiled = olp.compile(load_krl(ROUND_TRIP).program, station)
    _write(render(compiled, _post(points="dat")), tmp_path)
    again = load_krl(tmp_path / "RoundTrip.src")
    lines = (tmp_path / "RoundTrip.src").read_text().splitlines()
    # point name (LIN XP2 -> XP2) -> the S/T the frontend read from its DECL
    steps = {lines[st.span.line - 1].split()[1]: st for st in again.status_turn}
    motions = [s for s in compiled.motion_steps() if not s.skipped]
    names = [f"XP{n}" for n in range(1, len(motions) + 1)]
    checked = 0
    for name, step in zip(names, motions, strict=True):
        if name not in steps:
            continue  # an E6AXIS point
        read = steps[name]
        assert read.status is not None and read.turn is not None
        config = kuka.configuration_from_status_turn(read.status, read.turn)
        _assert_selects(station.robot, step, config)
        checked += 1
    assert checked >= 5


def _assert_selects(robot: Robot, step: Step, config: ir.Configuration) -> None:
    assert step.tool is not None and step.frame is not None and step.joints is not None
    flange = robot.flange_poses(step.joints)
    candidates = _candidates(robot, flange)
    chosen = candidates[satisfies(config, candidates, robot)]
    assert chosen.shape[0] >= 1
    assert np.allclose(chosen, step.joints, rtol=0, atol=1e-6)


def _candidates(robot: Robot, flange: np.ndarray) -> np.ndarray:
    """Every IK solution of a flange pose inside the joint limits, turn variants included."""
    sols = robot.solve(flange[None])[0]
    variants = turn_variants(sols, robot.limits.lower, robot.limits.upper).reshape(-1, robot.dof)
    finite = np.all(np.isfinite(variants), axis=-1)
    ok = finite & ~np.any(robot.limits.violations(np.where(finite[:, None], variants, 0)), axis=-1)
    return variants[ok]


# --------------------------------------------------------------------------------------------
# Configuration proof: random targets in every branch of every KUKA and ABB robot


def planned_in_every_branch(robot: Robot, rng: np.random.Generator, per_branch: int) -> np.ndarray:
    """Joint vectors (N, 6) in the limits, ``per_branch`` for each IK branch that has them."""
    lower, upper = robot.limits.lower, robot.limits.upper
    q = rng.uniform(lower, upper, (per_branch * 6, robot.dof))
    sols = robot.solve(robot.flange_poses(q))  # (N, 8, 6)
    out = []
    for branch in range(sols.shape[1]):
        variants = turn_variants(sols[:, branch], lower, upper)  # (N, K, 6)
        for row in variants:
            good = row[np.all(np.isfinite(row), axis=-1)]
            good = good[~np.any(robot.limits.violations(good), axis=-1)] if good.size else good
            if good.shape[0]:
                out.append(good[rng.integers(good.shape[0])])
            if len(out) % per_branch == 0 and len(out) >= per_branch * (branch + 1):
                break
    return np.array(out)


def compiled_for(robot: Robot, joints: np.ndarray) -> CompiledProgram:
    """PTP moves to the Cartesian poses of ``joints`` (N, 6) with exactly those joints planned."""
    station = Station(name="proof", robot=robot)
    poses = robot.flange_poses(joints)
    instructions = [
        ir.JointMove(target=ir.CartesianTarget(pose=_rigid(p)), tool=ir.FLANGE, frame=ir.WORLD)
        for p in poses
    ]
    steps = tuple(
        Step(i, ins, q, q[None], ir.FLANGE, ir.WORLD)
        for i, (ins, q) in enumerate(zip(instructions, joints, strict=True))
    )
    program = ir.Program(name="Proof", instructions=tuple(instructions))
    return CompiledProgram(program, station, robot.home.copy(), steps)


def _rigid(pose: np.ndarray) -> np.ndarray:
    u, _, vt = np.linalg.svd(pose[:3, :3])
    out = pose.copy()
    out[:3, :3] = u @ vt
    return out


ARMS = [name for name in robot_library() if name.split("/")[0] in ("kuka", "abb")]
NUMBER = r"(-?\d+\.\d+)"
E6POS = re.compile(
    rf"PTP \{{X {NUMBER},Y {NUMBER},Z {NUMBER},A {NUMBER},B {NUMBER},C {NUMBER},S (\d+),T (\d+)\}}"
)
E6AXIS = re.compile(r"PTP \{" + ",".join(rf"A{i} {NUMBER}" for i in range(1, 7)) + r"\}")


@pytest.mark.parametrize("name", ARMS)
def test_status_and_turn_select_the_planned_joints(name: str) -> None:
    """Through the written text: the pose and S/T of every PTP, solved with olp's IK, select the
    planned joints and no others; where T cannot (an ABB axis 6 of ±400° has two turns of one
    sign), the PTP is written with the planned axis values instead."""
    robot = load_library_robot(name).place()
    joints = planned_in_every_branch(robot, np.random.default_rng(7), 12)
    text = render(compiled_for(robot, joints), _post())["Proof.src"]
    lines = [line for line in text.split("\r\n") if line.startswith("PTP")]
    assert len(lines) == len(joints)
    branches, by_axes = set(), 0
    for line, planned in zip(lines, joints, strict=True):
        branches.add(robot.branch_of(planned))
        axes = E6AXIS.fullmatch(line)
        if axes is not None:
            assert kuka.turn_ambiguous(planned, robot.limits.lower, robot.limits.upper)
            assert np.allclose(np.radians([float(v) for v in axes.groups()]), planned, atol=1e-7)
            by_axes += 1
            continue
        values = E6POS.fullmatch(line)
        assert values is not None, line
        pose = kuka.frame_to_pose([float(v) for v in values.groups()[:6]])
        config = kuka.configuration_from_status_turn(int(values[7]), int(values[8]))
        candidates = _candidates(robot, pose)
        chosen = candidates[satisfies(config, candidates, robot)]
        # The written pose and S/T select one solution: the planned one. (The pose is rounded
        # to 1 µm and 0.0001°, which moves joints near a singularity by up to ~1e-4 rad; other
        # solutions differ by whole branches or turns.)
        assert chosen.shape[0] >= 1
        assert np.max(np.abs(chosen - planned)) < 1e-3, (line, np.degrees(planned))
    assert len(branches) == 8
    assert (by_axes > 0) == name.startswith("abb/")  # KUKA's own ranges never need it


@pytest.mark.parametrize("name", ["fanuc/m20ia", "ur/ur5e"])
def test_robots_without_kuka_status_are_a_post_error(name: str) -> None:
    robot = load_library_robot(name).place()
    compiled = compiled_for(robot, robot.home[None])
    with pytest.raises(PostError, match="cannot describe robot"):
        render(compiled, _post())


# --------------------------------------------------------------------------------------------
# Splitting


def _split_post(tmp_path: Path, limit: int, **options: Any) -> Post:
    folder = tmp_path / "kuka_small"
    shutil.copytree(find_post("kuka").manifest.folder, folder)
    text = (folder / "post.yaml").read_text()
    text = text.replace("max_motions_per_file: 5000", f"max_motions_per_file: {limit}")
    for key, value in options.items():
        text = re.sub(rf"(\n  {key}: )\S+", rf"\g<1>{value}", text)
    (folder / "post.yaml").write_text(text)
    return find_post(str(folder))


@pytest.mark.parametrize("points", ["inline", "dat"])
def test_split_parts_are_called_in_order_and_read_back_whole(
    points: str, station: Station, tmp_path: Path
) -> None:
    original = load_krl(MILLING).program
    compiled = olp.compile(original, station)
    files = render(compiled, _split_post(tmp_path, 3, points=points))
    assert sorted(files) == [
        "Milling.dat",
        "Milling.src",
        "Milling_P1.dat",
        "Milling_P1.src",
        "Milling_P2.dat",
        "Milling_P2.src",
        "Milling_P3.dat",
        "Milling_P3.src",
    ]
    main = files["Milling.src"].split("\r\n")
    assert [line for line in main if line.startswith("Milling_P")] == [
        "Milling_P1()",
        "Milling_P2()",
        "Milling_P3()",
    ]
    assert ";FOLD INI;%{PE}" not in main  # milling.src has no INI fold: none is written
    assert not any("FOLD INI" in files[f"Milling_P{k}.src"] for k in (1, 2, 3))
    # every part sets its own base, tool and speed before its first motion
    for k in (1, 2, 3):
        body = _body(files[f"Milling_P{k}.src"])
        assert body[0].startswith("$BASE = ") and body[1].startswith("$TOOL = ")
        assert body[2].startswith(("$VEL_AXIS[1]", "$VEL.CP"))
    _write(files, tmp_path / "out")
    motions = [
        m
        for k in (1, 2, 3)
        for m in _motions(load_krl(tmp_path / "out" / f"Milling_P{k}.src").program)
    ]
    _same_targets(_motions(original), motions)


# --------------------------------------------------------------------------------------------
# Vendor spelling used by the post


def test_krl_spelling_of_points() -> None:
    pose = kuka.frame_to_pose([1.5, -2.25, 300.0, -180.0, 0.0, 90.0])
    assert krl_e6pos(_post(), pose, 6, 27) == (
        "X 1.500,Y -2.250,Z 300.000,A 180.0000,B 0.0000,C 90.0000,S 6,T 27"
    )


@pytest.mark.parametrize(("name", "legal"), [("END", "END_"), ("lin", "lin_"), ("Lin2", "Lin2")])
def test_keywords_are_not_names(name: str, legal: str) -> None:
    assert NAME_RULE.legal(name) == legal
    assert NAME_RULE.is_legal(legal) and (name == legal or not NAME_RULE.is_legal(name))


@pytest.mark.parametrize(
    ("a6", "limit", "ambiguous"),
    [(-4.0, 350.0, False), (-4.0, 400.0, True), (100.0, 400.0, False), (-100.0, 400.0, False)],
)
def test_turn_ambiguity(a6: float, limit: float, ambiguous: bool) -> None:
    """T is a sign per axis: A6 = -4° and -364° are both negative, A6 = 100° and -260° differ."""
    q = np.radians([0.0, -90.0, 90.0, 0.0, 45.0, a6])
    lower = np.radians([-170, -190, -120, -185, -120, -limit])
    upper = np.radians([170, 45, 156, 185, 120, limit])
    assert bool(kuka.turn_ambiguous(q, lower, upper)) is ambiguous
