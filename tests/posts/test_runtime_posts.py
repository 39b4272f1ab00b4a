"""Motions to run-time targets through every post: written with the settings they run with
(also after a call), as the language names a pose variable, or refused on their line; user
text never becomes code."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import olp
from olp import ir
from olp.cli import main
from olp.frontends.bundled import KrlOptions
from olp.posts import find_post

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
HOME = "PTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}"
SETUP = ("$BASE = BASE_DATA[1]", "$TOOL = TOOL_DATA[1]", "$VEL.CP = 0.2", "$APO.CDIS = 5")
PATH = (
    "DEF path( )",
    "DECL E6POS xPath[3]",
    "DECL INT i",
    *SETUP,
    HOME,
    "LIN {X 500,Y 0,Z 400,A 0,B 90,C 0}",
    "i = 2",
    "SprayOff()",
    "LIN xPath[2] C_DIS",
    "LIN {X 520,Y 0,Z 400,A 0,B 90,C 0}",
    "END",
)
"""A run-time LIN right after a call (line 12) of an I/O routine the build vouches for
(``calls_keep_settings``): the post writes every setting again after a call, as after any
statement it does not model. (Without the vouch the LIN runs with the controller's settings:
tests/frontends/test_krl_unread_call.py.)"""


@pytest.fixture(scope="module")
def station() -> olp.Station:
    return olp.load_station(CELL)


def build(
    station: olp.Station, tmp_path: Path, lines: tuple[str, ...], post: str = "kuka"
) -> olp.api.BuildResult:
    path = tmp_path / "path.src"
    path.write_text("\n".join(lines) + "\n")
    options = KrlOptions(calls_keep_settings=("SprayOff",))
    return olp.build(station, path, post=post, program_options=options, collisions=None)


def errors(result: olp.api.BuildResult) -> list[tuple[str, int | None, str]]:
    return [
        (d.kind, d.span.line if d.span else None, d.message)
        for d in result.diagnostics
        if d.severity == "error"
    ]


def test_krl_writes_the_settings_before_a_run_time_motion_after_a_call(
    station: olp.Station, tmp_path: Path
) -> None:
    """The safety property: after ``SprayOff()`` the KRL post writes $BASE, $TOOL, $VEL.CP and
    $APO.CDIS again before ``LIN xPath[2] C_DIS``, as before any motion after a call (before,
    olp refused the motion: it kept the line and could not write its settings)."""
    result = build(station, tmp_path, PATH)
    assert result.ok, errors(result)
    src = result.files["path.src"].splitlines()
    call, motion = src.index("SprayOff()"), src.index("LIN xPath[2] C_DIS")
    between = src[call + 1 : motion]
    assert [line.split(" =")[0] for line in between] == ["$BASE", "$TOOL", "$VEL.CP", "$APO.CDIS"]


def test_rapid_moves_to_a_robtarget_array_element(station: olp.Station, tmp_path: Path) -> None:
    result = build(station, tmp_path, PATH, post="abb")
    assert result.ok, errors(result)
    lines = [line.strip() for line in result.files["path.mod"].splitlines()]
    assert "VAR robtarget xPath{3};" in lines
    assert "MoveL xPath{2}, v200, z5, spindle\\WObj:=table;" in lines


def test_ls_moves_to_the_position_register_of_the_element(
    station: olp.Station, tmp_path: Path
) -> None:
    result = build(station, tmp_path, PATH, post="fanuc")
    assert result.ok, errors(result)
    mn = result.files["PATH.ls"]
    assert "L PR[52:xPath_2] 200mm/sec CNT5    ;" in mn
    lines = mn.splitlines()
    at = next(k for k, line in enumerate(lines) if "PR[52:xPath_2]" in line)
    assert "UFRAME_NUM=1" in lines[at - 2] and "UTOOL_NUM=1" in lines[at - 1]


def test_ls_refuses_an_element_chosen_at_run_time(station: olp.Station, tmp_path: Path) -> None:
    lines = tuple("LIN xPath[i] C_DIS" if t == "LIN xPath[2] C_DIS" else t for t in PATH)
    lines = tuple("i = $IN[2]" if t == "i = 2" else t for t in lines)
    result = build(station, tmp_path, lines, post="fanuc")
    ((_, line, message),) = [e for e in errors(result) if e[0] == "runtime_target"]
    assert line == 12 and "indirect addressing" in message and not result.files


def test_urscript_refuses_with_the_reason(station: olp.Station, tmp_path: Path) -> None:
    result = build(station, tmp_path, PATH, post="ur")
    found = [e for e in errors(result) if e[0] == "runtime_target"]
    assert [line for _, line, _ in found] == [12] and "declares none" in found[0][2]
    assert not result.files


@pytest.mark.parametrize(("post", "refused"), [("abb", "not declared"), ("fanuc", "not declared")])
def test_a_name_the_program_does_not_declare_is_refused(
    station: olp.Station, tmp_path: Path, post: str, refused: str
) -> None:
    """``PTP XHOME`` without ``$config.dat``: KRL writes it back (the controller's
    ``$config.dat`` declares it); another language cannot tell what it is."""
    lines = ("DEF path( )", *SETUP, HOME, "PTP XHOME", HOME, "END")
    kuka = build(station, tmp_path, lines)
    assert kuka.ok and "PTP XHOME" in kuka.files["path.src"].splitlines()
    result = build(station, tmp_path, lines, post=post)
    ((_, line, message),) = [e for e in errors(result) if e[0] == "runtime_target"]
    assert line == 7 and refused in message


@pytest.mark.parametrize("post", ["kuka", "abb", "fanuc"])
def test_user_text_in_a_target_never_becomes_code(station: olp.Station, post: str) -> None:
    """A name that would end the statement and start another is an error, nothing written."""
    bad = ir.RuntimeMove(
        motion="linear",
        target=ir.Name(name="p\nLIN {X 0}"),
        span=ir.SourceSpan("p.src", 2, 1),
    )
    home = ir.JointMove(target=ir.JointTarget(joints=[0, -1.57, 1.57, 0, 0.5, 0]))
    program = ir.Program(name="p", instructions=(home, bad), source="p.src")
    result = olp.build(station, program, post=post, collisions=None)
    assert not result.ok and not result.files
    assert any(e[0] == "runtime_target" and e[1] == 2 for e in errors(result))


def test_a_template_folder_that_does_not_declare_it_refuses(
    station: olp.Station, tmp_path: Path
) -> None:
    """A copy of the templates made before olp wrote run-time motions would leave them out:
    without ``runtime_targets: true`` the motion is an error on its line."""
    folder = tmp_path / "old_kuka"
    shutil.copytree(find_post("kuka").manifest.folder, folder)
    manifest = folder / "post.yaml"
    manifest.write_text(manifest.read_text().replace("runtime_targets: true", ""))
    result = build(station, tmp_path, PATH, post=str(folder))
    ((_, line, message),) = [e for e in errors(result) if e[0] == "runtime_target"]
    assert line == 12 and "runtime_targets: true" in message


def test_olp_build_exit_codes(tmp_path: Path) -> None:
    """Warnings only: exit 0 and files written; a post that refuses the motion: exit 1."""
    program = tmp_path / "path.src"
    program.write_text("\n".join(PATH) + "\n")
    out = tmp_path / "out"
    assert main(["build", str(CELL), str(program), "-o", str(out), "--no-collisions", "-q"]) == 0
    assert (out / "path.src").is_file()
    refused = ["build", str(CELL), str(program), "--post", "ur", "-o", str(tmp_path / "ur")]
    assert main([*refused, "--no-collisions", "-q"]) == 1
    assert not (tmp_path / "ur").exists()


def test_the_pendant_home_without_config_dat_is_written_without_settings(
    station: olp.Station, tmp_path: Path
) -> None:
    """``PTP XHOME`` after the kept BAS runs with what that BAS sets: the KRL post writes the
    motion right after it, no setting in between, and every setting before the next motion;
    a post of another language refuses it (and the BAS)."""
    lines = (
        "DEF path( )",
        "PDAT_ACT=PDEFAULT",
        "FDAT_ACT=FHOME",
        "BAS (#PTP_PARAMS,100 )",
        "PTP  XHOME",
        *SETUP,
        "BAS (#VEL_PTP, 50)",
        "BAS (#ACC_PTP, 50)",
        HOME,
        "END",
    )
    result = build(station, tmp_path, lines)
    assert result.ok, errors(result)
    src = result.files["path.src"].splitlines()
    bas = src.index("BAS (#PTP_PARAMS,100 )")
    assert src[bas + 1] == "PTP XHOME" and src[bas + 2].startswith("$BASE = ")
    abb = build(station, tmp_path, lines, post="abb")
    assert any(e[0] == "runtime_target" and e[1] == 5 for e in errors(abb))


RELATIVE = (
    "DEF rel( )",
    "DECL E6POS xPick[2]",
    "DECL E6POS pUp={X 0,Y 0,Z 50,A 0,B 0,C 0}",
    *SETUP,
    HOME,
    "LIN xPick[1]",
    "LIN_REL {Z 50}",
    "LIN_REL pUp #TOOL",
    "LIN {Z 400} C_DIS",
    "PTP_REL {A6 15}",
    HOME,
    "END",
)
"""Motions relative to the end of a run-time one (lines 10 to 13): run-time targets too."""


def test_krl_writes_motions_relative_to_a_run_time_start_as_written(
    station: olp.Station, tmp_path: Path
) -> None:
    result = build(station, tmp_path, RELATIVE)
    assert result.ok, errors(result)
    src = result.files["rel.src"].splitlines()
    motions = [line for line in src if line.split(" ")[0] in ("LIN", "LIN_REL", "PTP_REL")]
    assert motions == [
        "LIN xPick[1]",
        "LIN_REL {Z 50}",
        "LIN_REL pUp #TOOL",
        "LIN {Z 400} C_DIS",
        "PTP_REL {A6 15}",
    ]
    warned = [d.span.line for d in result.diagnostics if d.kind == "runtime_target" and d.span]
    assert warned == [9, 10, 11, 12, 13]


@pytest.mark.parametrize("post", ["abb", "fanuc", "ur"])
def test_other_posts_refuse_a_target_relative_to_a_run_time_start(
    station: olp.Station, tmp_path: Path, post: str
) -> None:
    """RAPID would write ``MoveL pUp`` for ``LIN_REL pUp``: a motion to the offsets as a
    position. Every post but KRL refuses each relative motion on its line (RAPID's ``Offs``
    of ``CRobT()`` is not the same start: the robot's measured position, not the target the
    previous motion ends at)."""
    refused = {line for kind, line, _ in errors(build(station, tmp_path, RELATIVE, post=post))}
    assert {10, 11, 12, 13} <= refused
    messages = [m for k, line, m in errors(build(station, tmp_path, RELATIVE, post="abb"))]
    assert any("offsets from its start position in the tool frame" in m for m in messages)


def test_krl_reads_its_relative_motions_back_the_same(station: olp.Station, tmp_path: Path) -> None:
    from olp.frontends.krl import parse_krl

    written = build(station, tmp_path, RELATIVE).files["rel.src"]
    again = parse_krl(written, "rel.src").program
    relative = [n.relative for n in again if isinstance(n, ir.RuntimeMove)]
    assert relative == [None, "base", "tool", "start", "axes"]


def test_krl_writes_a_home_fold_of_several_bas_line_for_line(
    station: olp.Station, tmp_path: Path
) -> None:
    """The fold without ``$config.dat``: every line of it written, in order, the known
    ``BAS (#VEL_PTP,80 )`` among them, and nothing between the last BAS and ``PTP XHOME``."""
    fold = (
        "PDAT_ACT=PDEFAULT",
        "BAS (#PTP_DAT )",
        "FDAT_ACT=FHOME",
        "BAS (#FRAMES )",
        "BAS (#VEL_PTP,80 )",
        "PTP  XHOME",
    )
    lines = ("DEF path( )", *fold, *SETUP, "BAS (#VEL_PTP, 50)", "BAS (#ACC_PTP, 50)", HOME, "END")
    result = build(station, tmp_path, lines)
    assert result.ok, errors(result)
    src = result.files["path.src"].splitlines()
    start = src.index("PDAT_ACT = PDEFAULT")
    assert src[start : start + 6] == [
        "PDAT_ACT = PDEFAULT",
        "BAS (#PTP_DAT )",
        "FDAT_ACT = FHOME",
        "BAS (#FRAMES )",
        "BAS (#VEL_PTP,80 )",
        "PTP XHOME",
    ]
