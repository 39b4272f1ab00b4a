"""KRL -> KRL keeps every statement as the source had it (issue 15), three defects found on real
KR C4 backups: a data list's ``CONST`` lost in the written ``.dat``, a call with an aggregate
argument refused by the KUKA post, and the settings of a pendant fold ``PTP $POS_ACT`` written
only after it. The programs here are written for these tests in the pendant's style."""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir
from olp.frontends.bundled import KrlOptions

REPO = Path(__file__).resolve().parents[2]
STATION = REPO / "stations" / "kr6_milling_cell.yaml"
HOME = "PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}"


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(STATION)


def build(station: object, path: Path, post: str) -> olp.api.BuildResult:
    options = KrlOptions()
    return olp.build(station, path, post=post, collisions=None, program_options=options)


def module(folder: Path, name: str, body: str, dat: str | None = None) -> Path:
    if dat is not None:
        (folder / f"{name}.dat").write_text(dat)
    path = folder / f"{name}.src"
    path.write_text(f"DEF {name}( )\n{body}END\n")
    return path


def errors(result: olp.api.BuildResult) -> list[str]:
    return [d.format() for d in result.diagnostics if d.severity == "error"]


# ------------------------------------------------------------------------------------------
# 1. the declarations of the module's data list, written back with their attributes

WALLS = """DEFDAT walls PUBLIC
DECL CONST INT iWallSize=4
DECL GLOBAL CONST REAL rGap=1.5
DECL GLOBAL INT aHoles[3]
aHoles[2]=7
ENUM E_SIDE LEFT, RIGHT
DECL E_SIDE eSide=#RIGHT
DECL INT nUnused=0
ENDDAT
"""
WALLS_SRC = f"DECL INT nCount\n{HOME}\nnCount = iWallSize + aHoles[2]\nnCount = rGap + nCount\n"


def test_krl_writes_the_dat_declarations_as_the_source_had_them(
    station: object, tmp_path: Path
) -> None:
    """Before, ``DECL CONST INT iWallSize=4`` came out as ``DECL INT iWallSize=4``: a constant
    made writable on the controller."""
    path = module(tmp_path, "walls", WALLS_SRC + "eSide = #LEFT\n", WALLS)
    result = build(station, path, "kuka")
    assert result.ok, errors(result)
    dat = result.files["walls.dat"].split("\r\n")
    for line in (
        "DECL CONST INT iWallSize=4",
        "DECL GLOBAL CONST REAL rGap=1.5",
        "DECL GLOBAL INT aHoles[3]",
        "aHoles[2]=7",
        "DECL E_SIDE eSide=#RIGHT",
    ):
        assert line in dat


def test_a_global_of_a_list_without_public_is_not_exported(station: object, tmp_path: Path) -> None:
    """The post writes ``DEFDAT name PUBLIC``: a ``GLOBAL`` of a list without PUBLIC, which no
    other module sees, must not become visible to them there."""
    dat = WALLS.replace("DEFDAT walls PUBLIC", "DEFDAT walls")
    result = build(station, module(tmp_path, "walls", WALLS_SRC, dat), "kuka")
    assert result.ok, errors(result)
    lines = result.files["walls.dat"].split("\r\n")
    assert "DECL CONST REAL rGap=1.5" in lines and "DECL INT aHoles[3]" in lines
    assert not any("GLOBAL" in line for line in lines)


def test_rapid_declares_a_krl_constant_const(station: object, tmp_path: Path) -> None:
    """RAPID's ``CONST`` is a value fixed at declaration (:mod:`olp.posts.rapid_flow`); before,
    the constant became a ``PERS``, which the program may change."""
    result = build(station, module(tmp_path, "walls", WALLS_SRC, WALLS), "abb")
    assert result.ok, errors(result)
    (text,) = [t for n, t in result.files.items() if n.endswith(".mod")]
    module_part = text.split("PROC")[0]
    assert "CONST num iWallSize := 4;" in module_part
    assert "CONST num rGap := 1.5;" in module_part
    assert "PERS num aHoles{3} := [0, 7, 0];" in module_part


# ------------------------------------------------------------------------------------------
# 2. a call with an aggregate argument (a STRUC parameter)

BORE = f"{HOME}\nBoreHole({{rX 640.5, rY 42, rZ 0}}, 2)\nBoreHole({{ST_PT: rX 1, rY -2}}, 3)\n"


def test_krl_writes_an_aggregate_argument_as_it_stands(station: object, tmp_path: Path) -> None:
    """Before: ``call_argument`` error, nothing written."""
    result = build(station, module(tmp_path, "bore", BORE), "kuka")
    assert result.ok, errors(result)
    src = result.files["bore.src"].split("\r\n")
    assert "BoreHole({rX 640.5, rY 42, rZ 0}, 2)" in src
    assert "BoreHole({ST_PT: rX 1, rY -2}, 3)" in src


@pytest.mark.parametrize("post", ["abb", "ur", "fanuc"])
def test_other_posts_refuse_an_aggregate_argument_on_its_line(
    station: object, tmp_path: Path, post: str
) -> None:
    """Their flow writers declare no structure: the located error of before."""
    result = build(station, module(tmp_path, "bore", BORE), post)
    found = [d for d in result.diagnostics if d.kind == "call_argument"]
    assert not result.files and found and found[0].span is not None
    assert found[0].span.line == 3


@pytest.mark.parametrize(
    "argument",
    ["{rX 1; PTP HOME}", "{rX 1}) ; x", "{rX f(1)}", '{s[] "a"b"}', "{a {b {c 1}}}"],
)
def test_krl_refuses_an_aggregate_that_could_end_the_call(
    station: object, tmp_path: Path, argument: str
) -> None:
    from olp.posts.kuka import KukaPost

    assert not KukaPost.CALL_ARGUMENTS.allows(argument)


# ------------------------------------------------------------------------------------------
# 3. the pendant fold moving to where the robot is

FOLD = """DECL INT nPick
;FOLD PTP $POS_ACT Vel=100 %
   $BWDSTART = FALSE
   PDAT_ACT = PSTART
   FDAT_ACT = FSTART
   BAS(#PTP_PARAMS, PDAT_ACT.VEL)
   SET_CD_PARAMS (0)
   PTP $POS_ACT
;ENDFOLD
nPick = 2
"""
FOLD_DAT = """DEFDAT fold
DECL PDAT PSTART={VEL 40.000,ACC 60.000,APO_DIST 100.000,APO_MODE #CDIS,GEAR_JERK 100.000}
DECL FDAT FSTART={TOOL_NO 0,BASE_NO 0,IPO_FRAME #BASE,POINT2[] " "}
ENDDAT
"""


def test_the_fold_settings_are_written_before_ptp_pos_act(station: object, tmp_path: Path) -> None:
    """Before, ``PTP $POS_ACT`` was kept as a line of its own and the fold's settings went out
    only before the next motion olp modelled: the controller ran it with the previous ones."""
    path = module(tmp_path, "fold", FOLD + HOME + "\n", FOLD_DAT)
    result = build(station, path, "kuka")
    assert result.ok, errors(result)
    src = result.files["fold.src"].split("\r\n")
    here = src.index("PTP $POS_ACT")
    for setting in ("$VEL_AXIS[1] = 40", "$ACC_AXIS[6] = 60", "$TOOL = $NULLFRAME ; flange"):
        assert setting in src[:here]
    assert src.index("SET_CD_PARAMS (0)") < here < src.index("nPick = 2")
    moves = [n for n in result.compiled.program if isinstance(n, ir.RuntimeMove)]
    assert [(m.motion, m.speed.joint, m.span.line) for m in moves] == [("joint", 0.4, 9)]


def test_the_fold_settings_reach_a_last_ptp_pos_act(station: object, tmp_path: Path) -> None:
    """With no motion after it, the settings reached no output at all."""
    result = build(station, module(tmp_path, "fold", FOLD, FOLD_DAT), "kuka")
    assert result.ok, errors(result)
    src = result.files["fold.src"].split("\r\n")
    assert src.index("$VEL_AXIS[1] = 40") < src.index("PTP $POS_ACT")


@pytest.mark.parametrize("post", ["abb", "ur", "fanuc"])
def test_other_posts_stop_on_the_fold_ptp_pos_act(
    station: object, tmp_path: Path, post: str
) -> None:
    """They cannot name ``$POS_ACT``: an error on its line (before, a kept KRL line: an error
    too, or left out with a warning by --drop-foreign-verbatim)."""
    path = module(tmp_path, "fold", FOLD + HOME + "\n", FOLD_DAT)
    result = build(station, path, post)
    found = [d for d in result.diagnostics if d.severity == "error" and d.span is not None]
    assert not result.files
    assert [(d.kind, d.span.line) for d in found if d.span.line == 9] == [("runtime_target", 9)]


def test_krl_round_trip_keeps_every_line(station: object, tmp_path: Path) -> None:
    """The three together, read back: the constant, the call and the fold's motion are there
    as they were."""
    body = FOLD.replace("nPick = 2\n", "nPick = iWallSize\n") + BORE
    dat = FOLD_DAT.replace("ENDDAT", "DECL CONST INT iWallSize=4\nENDDAT")
    first = build(station, module(tmp_path, "fold", body, dat), "kuka")
    assert first.ok, errors(first)
    out = tmp_path / "out"
    out.mkdir()
    for name, text in first.files.items():
        (out / name).write_bytes(text.encode("ascii"))
    again = build(station, out / "fold.src", "kuka")
    assert again.ok, errors(again)
    src = again.files["fold.src"].split("\r\n")
    assert "DECL CONST INT iWallSize=4" in again.files["fold.dat"].split("\r\n")
    assert "BoreHole({rX 640.5, rY 42, rZ 0}, 2)" in src and "PTP $POS_ACT" in src
    assert src.index("$VEL_AXIS[1] = 40") < src.index("PTP $POS_ACT")
