"""KRL as the KR C4 pendant writes it: .src/.dat pairs, $config.dat, inline forms, spline WITH,
calls, FOR loops, _REL motions, HOME, and the diagnostics for what olp does not lower."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest

from olp import ir
from olp.errors import ParseError, UsageError
from olp.frontends.krl import (
    KrlData,
    KrlResult,
    StatusTurn,
    find_dat,
    load_config_dat,
    load_krl,
    parse_dat,
    parse_krl,
)
from olp.frontends.krl import lower as krl_lower
from olp.vendors.kuka import configuration_from_status_turn, frame_to_pose
from tests.krl_notes import own_notes

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
PICK = EXAMPLES / "pendant_pick.src"
GLUE = EXAMPLES / "pendant_glue.src"
CONFIG = EXAMPLES / "robot_config.dat"
FULL = "{X 1,Y 2,Z 3,A 0,B 0,C 0}"
AXES0 = "{A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}"


def program(*body: str, name: str = "t") -> str:
    return "\n".join([f"DEF {name} ( )", *body, "END", ""])


def dat(*body: str, name: str = "t") -> KrlData:
    return parse_dat("\n".join([f"DEFDAT {name} PUBLIC", *body, "ENDDAT", ""]), f"{name}.dat")


@pytest.fixture(scope="module")
def config() -> KrlData:
    return load_config_dat(CONFIG)


def parse(*body: str, data: KrlData | None = None, config: KrlData | None = None) -> KrlResult:
    return parse_krl(program(*body), "t.src", dat=data, config=config)


def parse_error(*body: str, data: KrlData | None = None, cfg: KrlData | None = None) -> ParseError:
    with pytest.raises(ParseError) as info:
        parse(*body, data=data, config=cfg)
    return info.value


def plain(result: KrlResult) -> list[ir.Instruction]:
    """The instructions as checks see them: each routine's body at its calls."""
    return [dataclasses.replace(i, span=ir.GENERATED) for i in result.program.expanded()]


def xyz_mm(motion: ir.Instruction) -> list[float]:
    assert isinstance(motion, ir.MOTION_TYPES) and isinstance(motion.target, ir.CartesianTarget)
    return [round(v * 1000, 6) for v in motion.target.pose[:3, 3]]


def pose(*xyzabc: float) -> np.ndarray:
    return frame_to_pose(list(xyzabc))


# ---- the pick-and-place program from the pendant ---------------------------------------------


@pytest.fixture(scope="module")
def pick(config: KrlData) -> KrlResult:
    return load_krl(PICK, config_dat=config)


def statements(result: KrlResult) -> list[ir.Instruction]:
    """The program's statements as checks see them, without the comments and the lines kept
    for the KRL post alone (its INI fold's, each inline form's $BWDSTART)."""
    return [
        i
        for i in result.program.expanded()
        if not isinstance(i, ir.Comment) and not getattr(i, "native_only", False)
    ]


def test_pick_reads_the_dat_and_config(pick: KrlResult) -> None:
    kinds = [(type(i).__name__, i.span.line) for i in statements(pick)]
    assert kinds == [
        ("Verbatim", 27),  # $H_POS=XHOME: kept as written (the controller's $IN_HOME)
        ("JointMove", 28),  # PTP XHOME
        ("Verbatim", 36),  # SET_CD_PARAMS (0): kept as written
        ("JointMove", 37),  # PTP XP1 C_PTP
        ("Verbatim", 44),
        ("LinearMove", 45),  # LIN XP2
        ("SetOutput", 48),
        ("Wait", 51),
        ("WaitInput", 54),
        ("Verbatim", 61),
        ("LinearMove", 62),  # LIN XP3 C_DIS C_DIS
        ("Verbatim", 69),
        ("JointMove", 70),  # PTP XP4 C_PTP
        ("Verbatim", 91),
        ("LinearMove", 92),  # place_part(), inlined
        ("SetOutput", 95),
        ("Wait", 97),
        ("Verbatim", 103),
        ("LinearMove", 104),
        ("Verbatim", 80),
        ("JointMove", 81),  # back in the main program: PTP XHOME
    ]
    assert pick.data_sources == (str(CONFIG), str(EXAMPLES / "pendant_pick.dat"))


def test_pick_targets_are_the_named_points(pick: KrlResult) -> None:
    home, p1, p2, *_ = pick.program.expanded().motions()
    assert isinstance(home.target, ir.JointTarget) and home.target.name == "XHOME"
    np.testing.assert_allclose(home.target.joints, np.radians([0, -90, 90, 0, 30, 0]))
    assert isinstance(p1.target, ir.CartesianTarget) and p1.target.name == "XP1"
    np.testing.assert_allclose(p1.target.pose, pose(20.337, -110.5, 300, -90, 0, 180))
    assert p1.target.config == configuration_from_status_turn(2, 2)  # PTP: S/T apply
    assert isinstance(p2.target, ir.CartesianTarget) and p2.target.config is None  # LIN: not
    assert xyz_mm(p2) == [20.337, -110.5, 120.25]
    assert pick.status_turn[0] == StatusTurn(p1.span, 2, 2)
    assert [(s.span.line, s.status, s.turn) for s in pick.status_turn[3:4]] == [(70, 2, 3)]


def test_pick_speeds_and_zones_follow_the_motion_data(pick: KrlResult) -> None:
    got = [
        (m.span.line, m.speed.linear, m.speed.joint, m.speed.joint_acceleration, m.zone.radius)
        for m in pick.program.expanded().motions()
    ]
    assert got == [
        (28, 2.0, 1.0, 1.0, 0.0),  # PDEFAULT; $VEL.CP not set yet: the assumed default
        (37, 2.0, 1.0, 1.0, 0.1),  # PPDAT1 APO_DIST 100 mm, C_PTP
        (45, 0.5, 1.0, 1.0, 0.0),  # BAS(#CP_PARAMS,0.5)
        (62, 0.5, 1.0, 1.0, 0.02),  # LCPDAT2 APO_DIST 20 mm, C_DIS C_DIS
        (70, 0.5, 0.75, 0.8, 0.05),  # BAS(#PTP_PARAMS,75), PPDAT2 ACC 80 %, APO_DIST 50 mm
        (92, 0.2, 0.75, 0.8, 0.0),
        (104, 0.5, 0.75, 0.8, 0.0),
        (81, 0.5, 1.0, 1.0, 0.0),
    ]


def test_pick_tools_and_bases_come_from_config(pick: KrlResult) -> None:
    home, p1, *rest = pick.program.expanded().motions()
    assert (home.tool, home.frame) == (ir.FLANGE, ir.WORLD)  # FHOME: TOOL_NO 0, BASE_NO 0
    assert (p1.tool.name, p1.tool.number, p1.frame.name, p1.frame.number) == (
        "Gripper",
        1,
        "Table",
        1,
    )
    assert p1.tool.pose is not None and p1.frame.pose is not None
    np.testing.assert_allclose(p1.tool.pose, pose(185.5, 0, 12.5, 0, 90, 0))
    np.testing.assert_allclose(p1.frame.pose, pose(550, -400, 0, 0, 0, 0))
    frames = ["Table", "Table", "Conveyor", "Conveyor", "Conveyor", "world"]
    assert [m.frame.name for m in rest] == frames


def test_pick_io(pick: KrlResult) -> None:
    io = [i for i in plain(pick) if not isinstance(i, (*ir.MOTION_TYPES, ir.Verbatim, ir.Comment))]
    assert io == [
        ir.SetOutput(index=17, value=True),
        ir.Wait(seconds=0.5),
        ir.WaitInput(index=5, value=True),
        ir.SetOutput(index=17, value=False),
        ir.Wait(seconds=0.3),
    ]


def test_pick_lists_every_ignored_line_with_a_reason(pick: KrlResult) -> None:
    by_file: dict[str, list[tuple[int, str]]] = {}
    for item in pick.ignored:
        by_file.setdefault(Path(item.span.file).name, []).append((item.span.line, item.text))
        assert item.reason
    src = by_file.get("pendant_pick.src", [])
    # the INI fold's lines and each inline form's $BWDSTART: kept for the KRL post alone
    native = [(i.span.line, i.text) for i in pick.program.expanded() if i.kind == "verbatim"]
    native = [
        (line, text) for line, text in native if text.startswith(("$BWD", "GLOBAL", "I", "B"))
    ]
    assert native[:3] == [
        (12, "GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )"),
        (13, "INTERRUPT ON 3"),
        (14, "BAS (#INITMOV,0 )"),
    ]
    assert [line for line, text in native if text.startswith("$BWDSTART")] == [
        23,
        32,
        40,
        57,
        65,
        87,
        99,
        76,
    ]  # (76: the PTP HOME fold at the end of the main program, after the inlined routine's)
    assert not [line for line, text in src if text.startswith(("$BWD", "GLOBAL", "INTER", "BAS"))]
    kept = [(i.span.line, i.text) for i in statements(pick) if isinstance(i, ir.Verbatim)]
    lines = [36, 44, 61, 69, 91, 103]  # SET_CD_PARAMS: kept in the program as written
    homes = [(27, "$H_POS=XHOME")], [(80, "$H_POS=XHOME")]  # the pendant's PTP HOME folds
    assert kept == [*homes[0], *[(line, "SET_CD_PARAMS (0)") for line in lines], *homes[1]]
    assert not [line for line, text in src if text.startswith("SET_CD_PARAMS")]
    assert by_file["pendant_pick.dat"] == [
        (9, "EXT  BAS (BAS_COMMAND  :IN,REAL  :IN )"),
        (10, "DECL INT SUCCESS"),
    ]
    assert [line for line, _ in by_file["robot_config.dat"]] == [14, 15, 38]  # STRUC ENUM SIGNAL


def test_pick_without_config_moves_home_with_the_controller_settings() -> None:
    """Without ``$config.dat`` the two HOME folds (``FDAT_ACT=FHOME``, ``BAS(#PTP_PARAMS)``,
    ``PTP XHOME``) are motions to a target olp does not know, with the settings the kept BAS
    sets, and the reason names the missing file (before, olp stopped at the first one); the
    taught points between them are modelled."""
    result = load_krl(PICK)
    homes = [n for n in result.program.expanded() if isinstance(n, ir.RuntimeMove)]
    assert [(n.span.line, n.controller_settings) for n in homes] == [(28, True), (81, True)]
    assert all("$config.dat" in n.reason for n in homes)
    assert len(list(result.program.motions())) == 4


def test_tool_and_base_numbers_without_config_are_references(tmp_path: Path) -> None:
    shutil.copy(EXAMPLES / "pendant_pick.dat", tmp_path / "pendant_pick.dat")
    text = PICK.read_text().splitlines()
    body = [line for line in text[29:73]]  # P1 .. P4, no HOME folds
    (tmp_path / "pendant_pick.src").write_text(program(*body, name="pendant_pick"))
    result = load_krl(tmp_path / "pendant_pick.src")
    p1 = next(result.program.motions())
    assert p1.tool == ir.Tool(name="TOOL_DATA[1]", number=1)
    assert p1.frame == ir.Frame(name="BASE_DATA[1]", number=1)
    assert [m.frame.number for m in result.program.motions()] == [1, 1, 1, 2]


def test_config_without_the_tool_number_is_an_error(config: KrlData) -> None:
    error = parse_error("BAS(#TOOL, 5)", cfg=config)
    assert "TOOL_DATA[5]" in error.message and "robot_config.dat" in error.message


def test_tool_base_assignment_from_config(config: KrlData) -> None:
    result = parse("$TOOL = TOOL_DATA[2]", "$BASE=BASE_DATA[2]", f"PTP {FULL}", config=config)
    motion = next(result.program.motions())
    assert (motion.tool.name, motion.tool.number) == ("Glue gun", 2)
    assert motion.tool.pose is not None and motion.frame.pose is not None
    np.testing.assert_allclose(motion.tool.pose, pose(230, 0, 0, 0, 90, 0))
    np.testing.assert_allclose(motion.frame.pose, pose(0, 100, 100, 90, 0, 0))


# ---- finding and reading data lists -----------------------------------------------------------


def test_dat_found_in_any_case(tmp_path: Path) -> None:
    (tmp_path / "Weld.SRC").write_text(program("PTP XP1", name="Weld"))
    (tmp_path / "weld.dat").write_text(
        "DEFDAT weld\nDECL E6AXIS XP1={A1 1,A2 2,A3 3,A4 4,A5 5,A6 6}\nENDDAT\n"
    )
    assert find_dat(tmp_path / "Weld.SRC") == tmp_path / "weld.dat"
    ptp = next(load_krl(tmp_path / "Weld.SRC").program.motions())
    assert isinstance(ptp.target, ir.JointTarget) and ptp.target.name == "XP1"
    np.testing.assert_allclose(ptp.target.joints, np.radians([1, 2, 3, 4, 5, 6]))


def test_several_dats_differing_in_case_are_ambiguous(tmp_path: Path) -> None:
    (tmp_path / "a.SRC").write_text(program(f"LIN {FULL}", name="a"))
    (tmp_path / "A.DAT").write_text("DEFDAT a\nENDDAT\n")
    (tmp_path / "a.Dat").write_text("DEFDAT a\nENDDAT\n")
    if len(list(tmp_path.iterdir())) < 3:
        pytest.skip("case-insensitive file system")
    with pytest.raises(UsageError, match="several data lists"):
        load_krl(tmp_path / "a.SRC")


def test_missing_config_file_is_a_usage_error() -> None:
    with pytest.raises(UsageError):
        load_krl(PICK, config_dat=EXAMPLES / "no-such-config.dat")


@pytest.mark.parametrize(
    ("body", "line", "message"),
    [
        (["DECL E6POS XP1={X 1}", "PTP XP1"], 3, "does not belong in a data list"),
        (["DECL E6POS XP1={X 1,,}"], 2, "unexpected ','"),
        (["DECL E6POS XP1={X 1}", "ENDDAT", "DEFDAT b", ""], 4, "exactly one DEFDAT"),
    ],
)
def test_dat_errors_point_into_the_dat(body: list[str], line: int, message: str) -> None:
    with pytest.raises(ParseError) as info:
        dat(*body)
    assert info.value.span is not None
    assert (info.value.span.file, info.value.span.line) == ("t.dat", line)
    assert message in info.value.message


def test_values_from_the_dat_are_located_in_the_dat() -> None:
    data = dat("DECL E6POS XP1={X 1,Y 2,Z 3,A 0,B 0,Q 0}")
    error = parse_error("PTP XP1", data=data)
    assert error.span is not None and (error.span.file, error.span.line) == ("t.dat", 2)
    assert (
        "'Q'" in error.message and error.source_line == "DECL E6POS XP1={X 1,Y 2,Z 3,A 0,B 0,Q 0}"
    )


def test_dat_values_arrays_and_assignments() -> None:
    data = dat(
        "DECL GLOBAL REAL SPEED=0.25",
        "DECL INT N=3",
        "DECL FRAME OFFS[4]",
        "OFFS[2]={X 10}",
        "OFFS[2].Y = N * 2",
        "DECL E6POS XP1={X 1,Y 2,Z 3,A 0,B 0,C 0}",
        "XP1.Z = 7.5",
    )
    result = parse("$VEL.CP = SPEED", "LIN XP1", "LIN XP1:OFFS[2]", data=data)
    first, second = result.program.motions()
    assert first.speed.linear == 0.25 and xyz_mm(first) == [1.0, 2.0, 7.5]
    assert xyz_mm(second) == [11.0, 8.0, 7.5]  # geometric operator: OFFS[2] in XP1's frame


# ---- spline inline forms ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def glue(config: KrlData) -> KrlResult:
    return load_krl(GLUE, config_dat=config)


def test_spline_inline_forms(glue: KrlResult) -> None:
    got = [
        (type(m).__name__, m.span.line, m.speed.linear, m.speed.joint, m.zone.radius, m.tool.name)
        for m in glue.program.motions()
    ]
    assert got == [
        ("JointMove", 19, 2.0, 1.0, 0.0, "flange"),
        ("JointMove", 26, 2.0, 0.8, 0.03, "Glue gun"),  # C_SPL with PPDAT1 APO_DIST 30
        ("LinearMove", 32, 0.1, 1.0, 0.0, "Glue gun"),
        ("LinearMove", 39, 0.05, 1.0, 0.005, "Glue gun"),
        ("CircularMove", 45, 0.05, 1.0, 0.005, "Glue gun"),
        ("JointMove", 52, 2.0, 1.0, 0.0, "flange"),
    ]
    circ = list(glue.program.motions())[4]
    assert isinstance(circ, ir.CircularMove) and circ.via.name == "XP4"
    assert circ.target.name == "XP5"
    assert list(glue.program.motions())[1].speed.joint_acceleration == 0.6


def test_spline_with_items_olp_does_not_model_are_kept_before_their_motion(
    glue: KrlResult,
) -> None:
    """Payload, gear jerk and collision-detection tolerances of the pendant's spline forms are
    written back for the controller, just before the motion (the KRL post writes a PTP with
    its settings before it, not the WITH)."""
    line_26 = [(n.kind, getattr(n, "text", "")) for n in glue.program if n.span.line == 26]
    assert line_26 == [
        ("verbatim", "$LOAD = SLOAD(FP1.TOOL_NO)"),
        ("verbatim", "$GEAR_JERK[1] = SGEAR_JERK(PPDAT1)"),
        ("verbatim", "$COLLMON_TOL_PRO[1] = USE_CM_PRO_VALUES(0)"),
        ("joint", ""),
    ]
    assert not [i for i in glue.ignored if i.span.line == 26]


def test_with_values_hold_for_their_motion_only() -> None:
    data = dat("DECL LDAT LD={VEL 0.1,APO_DIST 3}")
    result = parse(
        "$VEL.CP = 1",
        f"SLIN {FULL} WITH $VEL = SVEL_CP(0.2, , LD), $APO = SAPO(LD) C_SPL",
        f"LIN {FULL}",
        data=data,
    )
    first, second = result.program.motions()
    assert (first.speed.linear, first.zone.radius) == (0.2, 0.003)
    assert (second.speed.linear, second.zone.radius) == (1.0, 0.0)
    assert [n.span.line for n in own_notes(result.notes)] == [4]
    assert "only" in own_notes(result.notes)[0].message


def test_unknown_with_function_is_an_error() -> None:
    line = f"SLIN {FULL} WITH $VEL = MY_VEL(1)"
    error = parse_error(line)
    assert "MY_VEL" in error.message and error.span is not None
    assert (error.span.line, error.span.column) == (2, line.index("$VEL") + 1)


# ---- calls, loops, relative motions, home -----------------------------------------------------

APPROACH = [
    "DEF approach (target :IN, height :IN)",
    "  DECL E6POS target, above",
    "  DECL REAL height",
    "  above = target",
    "  above.Z = target.Z + height",
    "  LIN above C_DIS",
    "  LIN target",
    "END",
]


def test_calls_whose_motions_differ_are_written_out_with_constant_arguments() -> None:
    text = program(
        "$VEL.CP = 0.1",
        "$APO.CDIS = 2",
        "approach({X 10,Y 20,Z 30,A 0,B 0,C 0}, 50)",
        "approach(XP1, 25)",
        "gripper_open(1, , #FAST)",
    )
    data = dat("DECL E6POS XP1={X 100,Y 0,Z 0,A 0,B 0,C 180,S 2,T 2}")
    result = parse_krl(text + "\n".join(APPROACH) + "\n", "t.src", dat=data)
    motions = list(result.program.motions())
    assert [xyz_mm(m) for m in motions] == [[10, 20, 80], [10, 20, 30], [100, 0, 25], [100, 0, 0]]
    assert [m.span.line for m in motions] == [13, 14, 13, 14]  # the callee's lines
    assert [m.zone.radius for m in motions] == [0.002, 0.0, 0.002, 0.0]
    assert result.program.instructions[-1] == ir.Call(
        name="gripper_open",
        args=("1", "", "#FAST"),
        may_move=True,
        span=ir.SourceSpan("t.src", 6, 1, 6, 25),
    )
    # LIN target goes to another point at each call: one routine text cannot say both, so
    # approach is written out at its calls (the DECL of line 9 is kept as an ir.Declare)
    (written_out,) = result.ignored
    assert written_out.span.line == 8 and not result.program.routines
    assert "written out at each of its 2 calls" in written_out.reason
    assert "line 13 differs between the calls at lines 4 and 5" in written_out.reason


def test_call_with_a_runtime_argument_explains_at_the_use() -> None:
    text = program("DECL E6POS p", "$VEL.CP = 1", "approach(p, 10)") + "\n".join(APPROACH)
    with pytest.raises(ParseError) as info:
        parse_krl(text, "t.src")
    error = info.value
    assert error.span is not None and error.span.line == 11  # LIN above, inside approach
    assert "'p' in the call at t.src:4" in error.message


def test_out_parameters_are_copied_back() -> None:
    text = program("DECL INT k", "k = 1", "bump(k)", "bump(k)", "WAIT SEC k") + (
        "DEF bump(n :OUT)\n  n = n + 1\nEND\n"
    )
    kept = [i for i in plain(parse_krl(text)) if not isinstance(i, ir.Declare | ir.Assign)]
    assert kept == [ir.Wait(seconds=3.0)]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        ("DEF a()\n  b()\nEND\nDEF b()\n  a()\nEND\n", "recursive call of a (T -> A -> B -> A)"),
        ("DEF a()\n  t()\nEND\n", "recursive call of t (T -> A -> T)"),
        ("DEFFCT INT a()\n  RETURN 1\nENDFCT\n", "a is a function"),
        ("DEF a(x :IN)\nEND\n", "takes 1 argument(s), found 2"),
    ],
)
def test_call_errors(extra: str, message: str) -> None:
    call = "a(1, 2)" if "x :IN" in extra else "a()"
    with pytest.raises(ParseError, match=message.replace("(", r"\(").replace(")", r"\)")):
        parse_krl(program(call) + extra, "t.src")


def test_for_loops_with_constant_bounds_are_unrolled() -> None:
    result = parse(
        "DECL INT i",
        "DECL E6POS p",
        "$VEL.CP = 0.5",
        "p = {X 0,Y 0,Z 0,A 0,B 0,C 0}",
        "FOR i = 10 TO 1 STEP -3",
        "  p.X = i * 10",
        "  LIN p",
        "  FOR i2 = 1 TO 2",
        "    WAIT SEC i2 / 2",
        "  ENDFOR",
        "ENDFOR",
        "FOR i = 1 TO 5",
        "  LIN p",
        "  EXIT",
        "  LIN p",
        "ENDFOR",
        "FOR i = 1 TO 0",
        "  LIN p",
        "ENDFOR",
    )
    xs = [xyz_mm(m)[0] for m in result.program.motions()]
    assert xs == [100, 70, 40, 10, 10]
    waits = [i.seconds for i in result.program if isinstance(i, ir.Wait)]
    assert waits == [0.0, 1.0] * 4  # INT / INT truncates in KRL
    ignored = {(i.span.line, i.reason.split(":")[0]) for i in result.ignored}
    assert (16, "not reached") in ignored  # after EXIT
    assert any(line == 18 and "0 times" in reason for line, reason in ignored)


def test_a_long_loop_still_works() -> None:
    result = parse(
        "$VEL.CP = 1",
        "DECL E6POS p",
        f"p = {FULL}",
        "FOR i = 1 TO 10000",
        "  p.X = i / 100.0",
        "  LIN p",  # the target depends on the counter: unrolled
        "ENDFOR",
    )
    assert len(list(result.program.motions())) == 10000
    (unrolled,) = [i for i in result.ignored if i.span.line == 5]
    assert "written out 10000 times" in unrolled.reason


def test_a_loop_whose_body_does_not_depend_on_its_counter_stays_a_loop() -> None:
    result = parse("$VEL.CP = 1", "FOR i = 1 TO 10000", f"  LIN {FULL}", "ENDFOR")
    (block,) = result.program.instructions
    assert isinstance(block, ir.For) and len(result.program) == 1 and not result.ignored


def test_loop_limits(monkeypatch: pytest.MonkeyPatch) -> None:
    error = parse_error("FOR i = 1 TO 2000000", "ENDFOR")
    assert "2,000,000 times" in error.message and error.span is not None
    monkeypatch.setattr(krl_lower, "MAX_LOWERED_STATEMENTS", 500)
    body = ("FOR i = 1 TO 100", "  FOR j = 1 TO 100", "    WAIT SEC i + j", "  ENDFOR", "ENDFOR")
    error = parse_error(*body)  # the waits depend on the counters: unrolled
    assert "more than 500 statements" in error.message


def test_for_with_a_runtime_bound_is_a_block() -> None:
    result = parse("DECL INT n", "$VEL.CP = 1", "FOR i = 1 TO n", f"  LIN {FULL}", "ENDFOR")
    block = result.program.instructions[-1]
    assert isinstance(block, ir.For) and block.variable == "i"
    assert block.stop == ir.Name(name="n", span=block.stop.span)
    assert [(i.kind, i.span.line) for i in block.body] == [("linear", 5)]
    # the counter is known only at run time: the speed it sets is kept as written, and held
    result = parse("DECL INT n", "FOR i = 1 TO n", "  $VEL.CP = i", "ENDFOR", f"LIN {FULL}")
    loop, move = result.program.instructions[-2:]
    assert isinstance(loop, ir.For) and isinstance(loop.body[0], ir.Verbatim)
    assert "i counts the FOR loop at line 3" in loop.body[0].reason
    assert isinstance(move, ir.RuntimeMove) and move.controller_settings


def test_variables_assigned_in_skipped_blocks_become_unknown() -> None:
    result = parse("DECL REAL v", "v = 0.5", "IF $IN[1] THEN", "  v = 1", "ENDIF", "$VEL.CP = v")
    kept = result.program.instructions[-1]  # a value of the run: kept as written
    assert isinstance(kept, ir.Verbatim) and kept.span.line == 7
    assert "IF at line 4" in kept.reason


@pytest.mark.parametrize("block", ["IF $IN[1] THEN", "WHILE $IN[2]", "LOOP", "SWITCH n\nCASE 1"])
def test_control_flow_with_motion_is_lowered_to_a_block(block: str) -> None:
    end = {"IF": "ENDIF", "WHILE": "ENDWHILE", "LOOP": "ENDLOOP", "SWITCH": "ENDSWITCH"}
    keyword = block.split()[0]
    result = parse("$VEL.CP = 1", block, f"  LIN {FULL}", end[keyword])
    (node,) = result.program.instructions
    assert node.kind == keyword.lower() and node.span.line == 3
    (move,) = result.program  # iterating a program walks into its blocks
    assert isinstance(move, ir.LinearMove) and move.span.line == 4 + (keyword == "SWITCH")


def test_relative_motions() -> None:
    result = parse(
        "$VEL.CP = 1",
        f"PTP {AXES0}",
        "PTP_REL {A1 10, A3 -5}",
        "LIN {X 100,Y 0,Z 50,A 0,B 0,C 180}",
        "LIN_REL {Z 10}",
        "LIN_REL {Z 10} #TOOL",  # the tool's Z points down (C 180)
        "LIN_REL {X 5, C 90} C_DIS #BASE",
        "CIRC_REL {X 10,Y 10}, {X 20}",
    )
    _, rel, _, up, down, turn, circ = result.program.motions()
    assert isinstance(rel.target, ir.JointTarget)
    np.testing.assert_allclose(np.degrees(rel.target.joints), [10, -90, 85, 0, 30, 0])
    assert xyz_mm(up) == [100, 0, 60] and xyz_mm(down) == [100, 0, 50]
    assert isinstance(turn.target, ir.CartesianTarget)
    # #BASE: the rotation C 90 is about the base's X axis: Rx(90) @ Rx(180) = Rx(-90)
    np.testing.assert_allclose(turn.target.pose, pose(105, 0, 50, 0, 0, -90), atol=1e-12)
    assert isinstance(circ, ir.CircularMove)
    assert [round(v * 1000, 6) for v in circ.via.pose[:3, 3]] == [115, 10, 50]
    assert xyz_mm(circ) == [125, 0, 50]


@pytest.mark.parametrize(
    ("body", "because"),
    [
        (["LIN_REL {X 10}"], "no earlier Cartesian target"),
        ([f"PTP {FULL}", "PTP_REL {A1 5}"], "went to a Cartesian position"),
        ([f"PTP {AXES0}", "LIN_REL {X 1}"], "went to axis values"),
    ],
)
def test_relative_motion_without_a_known_start(body: list[str], because: str) -> None:
    error = parse_error("$VEL.CP = 1", *body)
    assert because in error.message and error.span is not None
    assert error.span.line == len(body) + 2


def test_home(config: KrlData) -> None:
    result = parse("$H_POS = XHOME", "PTP $H_POS", "PTP XHOME C_PTP", config=config)
    first, second = result.program.motions()
    assert isinstance(first.target, ir.JointTarget) and isinstance(second.target, ir.JointTarget)
    assert (first.target.name, second.target.name) == (None, "XHOME")
    np.testing.assert_allclose(first.target.joints, np.radians([0, -90, 90, 0, 30, 0]))
    np.testing.assert_array_equal(first.target.joints, second.target.joints)
    assert "$machine.dat" in parse_error("PTP $H_POS").message


def test_home_without_config_dat_is_a_motion_to_a_run_time_target() -> None:
    """Every KR C4 ``$config.dat`` declares XHOME; without it olp keeps ``PTP XHOME`` as a
    motion to a target it does not know (never a guessed home), and the reason names the
    missing ``$config.dat``. Another undeclared name is one too, with a warning naming it
    (tests/frontends/test_krl_undeclared.py); with every file given it is an error."""
    (home,) = [n for n in parse("PTP XHOME").program if isinstance(n, ir.RuntimeMove)]
    assert home.motion == "joint" and home.target == ir.Name(name="XHOME", span=home.target.span)
    assert "$config.dat" in home.reason and "--config-dat" in home.reason
    result = parse("PTP XHOMEX")
    assert [n.message.split(" ")[0] for n in own_notes(result.notes)] == ["XHOMEX"]
    error = parse_error("PTP XHOMEX", data=dat(), cfg=load_config_dat(CONFIG))
    assert "XHOMEX is not declared" in error.message


def test_signals_from_config(config: KrlData) -> None:
    result = parse(
        "GRIPPER_CLOSE = TRUE", "WAIT FOR PART_GRIPPED", "WAIT FOR NOT PART_GRIPPED", config=config
    )
    assert plain(result) == [  # by number, with the name the program used (issue 15)
        ir.SetOutput(index=17, value=True, signal="GRIPPER_CLOSE"),
        ir.WaitInput(index=5, value=True, signal="PART_GRIPPED"),
        ir.WaitInput(index=5, value=False, signal="PART_GRIPPED"),
    ]


@pytest.mark.parametrize(
    ("body", "line", "column", "message"),
    [
        ([f"SPTP {FULL} C_VEL"], 2, 1, "C_SPL"),
        ([f"LIN {FULL} #TOOL"], 2, len(f"LIN {FULL} #"), "only the _REL motions"),
        (["$IPO_MODE = #TCP"], 2, 13, "#TCP"),
        (["BAS(#PTP_PARAMS, 100)"], 2, 1, "FDAT_ACT"),
    ],
)
def test_lowering_errors(body: list[str], line: int, column: int, message: str) -> None:
    """(Every file given: without a ``$config.dat``, the FDAT_ACT a BAS reads would be one the
    controller holds, and the BAS kept as written.)"""
    error = parse_error(*body, data=dat(), cfg=load_config_dat(CONFIG))
    assert error.span is not None and (error.span.line, error.span.column) == (line, column)
    assert message in error.message


def test_a_spline_block_is_kept_as_written_and_the_start_after_it_is_unknown() -> None:
    """``SPLINE ... ENDSPLINE`` (before: an error): each line kept as written for the KRL post,
    its comments as comments, the settings olp absorbed before it kept before it, a note that
    it is not checked; a LIN_REL after it moves from where the block left the robot."""
    body = [
        "$VEL.CP = 0.3",
        "SPLINE ; seam",
        f"  SPL {FULL} WITH $VEL.CP = 0.5",
        "  SLIN {X 2,Y 3,Z 4,A 0,B 0,C 0}",
        "ENDSPLINE",
        "LIN_REL {Z 50}",
    ]
    result = parse(*body)
    kept = [(n.text, n.span.line) for n in result.program if isinstance(n, ir.Verbatim)]
    assert kept == [
        ("$VEL.CP = 0.3", 2),
        ("SPLINE", 3),
        (f"SPL {FULL} WITH $VEL.CP = 0.5", 4),
        ("SLIN {X 2,Y 3,Z 4,A 0,B 0,C 0}", 5),
        ("ENDSPLINE", 6),
    ]
    assert [n.text for n in result.program if isinstance(n, ir.Comment)] == [" seam"]
    assert any("SPLINE block (lines 3-6) kept as written" in n.message for n in result.notes)
    (rel,) = [n for n in result.program if isinstance(n, ir.RuntimeMove)]
    assert rel.relative == "base" and rel.span.line == 7


def test_status_out_of_range_is_located() -> None:
    line = "PTP {E6POS: X 1,Y 2,Z 3,A 0,B 0,C 0,S 40,T 2}"
    error = parse_error(line)
    assert error.span is not None and error.span.column == line.index("40") + 1
    assert "S 40" in error.message


def test_integer_division_and_constants() -> None:
    result = parse("CONST INT n = 7", "WAIT SEC n / 2", "WAIT SEC 7.0 / 2", "WAIT SEC (0 - n) / -2")
    assert [i.seconds for i in result.program if isinstance(i, ir.Wait)] == [3.0, 3.5, 3.0]
    assert result.ignored == ()


def target_values(motion: ir.Motion) -> np.ndarray:
    target = motion.target
    return target.pose if isinstance(target, ir.CartesianTarget) else target.joints


def test_pendant_files_in_other_case_and_crlf(tmp_path: Path, pick: KrlResult) -> None:
    """KRL is case-insensitive and controllers write CRLF: the same program must come out."""
    for name in ("pendant_pick.src", "pendant_pick.dat", "robot_config.dat"):
        text = (EXAMPLES / name).read_text().swapcase()
        (tmp_path / name.upper()).write_bytes(text.replace("\n", "\r\n").encode("cp1252"))
    result = load_krl(tmp_path / "PENDANT_PICK.SRC", config_dat=tmp_path / "ROBOT_CONFIG.DAT")
    ours_all, theirs_all = result.program.expanded(), pick.program.expanded()
    assert len(ours_all) == len(theirs_all)
    assert [r.name for r in result.program.routines] == [
        r.name.swapcase() for r in pick.program.routines
    ]
    for ours, theirs in zip(ours_all, theirs_all, strict=True):
        assert (type(ours), ours.span.line) == (type(theirs), theirs.span.line)
        if isinstance(ours, ir.MOTION_TYPES) and isinstance(theirs, ir.MOTION_TYPES):
            assert (ours.speed, ours.zone) == (theirs.speed, theirs.zone)
            assert (ours.tool.number, ours.frame.number) == (
                theirs.tool.number,
                theirs.frame.number,
            )
            np.testing.assert_array_equal(target_values(ours), target_values(theirs))
        elif isinstance(ours, ir.Verbatim | ir.Comment) and isinstance(theirs, type(ours)):
            assert ours.text == theirs.text.swapcase()  # kept as written, in its own case
        else:
            assert dataclasses.replace(ours, span=theirs.span) == theirs
    assert [i.span.line for i in result.ignored] == [i.span.line for i in pick.ignored]


def test_one_config_serves_many_programs(config: KrlData) -> None:
    changed = parse("TOOL_DATA[1] = {X 1}", "BAS(#TOOL, 1)", f"PTP {FULL}", config=config)
    assert next(changed.program.motions()).tool.pose is not None
    untouched = parse("BAS(#TOOL, 1)", f"PTP {FULL}", config=config)
    tool = next(untouched.program.motions()).tool
    assert tool.pose is not None
    np.testing.assert_allclose(tool.pose, pose(185.5, 0, 12.5, 0, 90, 0))


def test_sptp_approximates_with_c_dis_as_with_c_spl() -> None:
    """``SPTP X C_DIS`` (written by real KR C4 programs) approximates like ``SPTP X C_SPL``:
    with the $APO.CDIS distance."""
    spl = parse("$APO.CDIS = 20", f"SPTP {FULL} C_SPL", f"SPTP {FULL} C_DIS").program
    zones = [m.zone for m in spl.motions()]
    assert zones == [ir.Zone(0.02), ir.Zone(0.02)]
