"""Posts write the program's routines (issue 15): KRL DEF/DEFFCT back (KRL -> KRL keeps every
statement of every routine), a routine once for all its calls only where one text says what
every call does, and never an OUT parameter passed by value.

The expected files under tests/routines/expected/ are golden files: a change needs a stated
reason in the commit (regenerate with ``OLP_UPDATE_GOLDEN=1``; the test then fails once).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import olp
from olp import ir
from olp.frontends.krl import load_krl
from olp.ir_flow import leaves_and_blocks
from tests.krl_round_trip import comment_lines, keeps_in_order, statements

REPO = Path(__file__).resolve().parents[2]
ROUTINES = REPO / "tests" / "routines"
PALLETISE = ROUTINES / "palletise.src"
EXPECTED = ROUTINES / "expected"


@pytest.fixture(scope="module")
def station() -> Any:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def build(station: Any, source: Path | ir.Program, post: str = "kuka") -> olp.api.BuildResult:
    return olp.build(station, source, post=post, collisions=None)


def golden(post: str, files: dict[str, str]) -> None:
    folder = EXPECTED / post
    if os.environ.get("OLP_UPDATE_GOLDEN"):
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
        for name, text in files.items():
            (folder / name).write_bytes(text.encode("ascii"))
        pytest.fail("golden files rewritten: review them, then run again without the variable")
    assert sorted(files) == sorted(p.name for p in folder.iterdir())
    for name, text in files.items():
        assert text == (folder / name).read_bytes().decode("ascii"), name


def shape(nodes: Any) -> list[str]:
    """Statements and blocks in order, declarations apart; kept lines by their text."""
    out = []
    for node in statements(leaves_and_blocks(nodes)):  # comments apart: comment_lines
        if isinstance(node, ir.Verbatim):
            out.append(node.text.upper().replace(" ", ""))
        elif node.kind != "declare":
            out.append(node.kind)
    return out


def signature(routine: ir.Routine) -> tuple[Any, ...]:
    params = tuple((p.name, p.type_name, p.direction, len(p.dims)) for p in routine.params)
    locals_ = tuple((d.name, d.type_name) for d in routine.declarations)
    return routine.name, params, locals_, routine.returns, routine.exported


def test_kuka_writes_the_routines(station: Any) -> None:
    result = build(station, PALLETISE)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    golden("kuka", result.files)


def test_krl_to_krl_keeps_every_statement_of_every_routine(station: Any, tmp_path: Path) -> None:
    source = load_krl(PALLETISE).program
    result = build(station, PALLETISE)
    for name, text in result.files.items():
        (tmp_path / name).write_text(text)
    again = load_krl(tmp_path / "palletise.src").program
    assert shape(again.instructions) == shape(source.instructions)
    assert [signature(r) for r in again.routines] == [signature(r) for r in source.routines]
    for ours, theirs in zip(again.routines, source.routines, strict=True):
        assert shape(ours.body) == shape(theirs.body), ours.name
    assert keeps_in_order(comment_lines(again), comment_lines(source))
    counted = sum(len(statements(leaves_and_blocks(r.body))) for r in source.routines)
    assert counted == 21  # the routines hold statements: the comparison above is not empty
    assert len(list(again.expanded().motions())) == len(list(source.expanded().motions()))


def test_a_copied_folder_without_routines_writes_them_out_and_refuses_parameters(
    station: Any, tmp_path: Path
) -> None:
    """A template folder copied before olp wrote routines would drop them: the post writes
    each routine's body at its calls instead (exact without parameters), and refuses one with
    parameters, whose meaning would change."""
    from olp.posts import find_post

    folder = tmp_path / "old_kuka"
    shutil.copytree(find_post("kuka").manifest.folder, folder)
    manifest = folder / "post.yaml"
    manifest.write_text(manifest.read_text().replace("routines: true\n", ""))
    source = (
        "DEF p( )\n$VEL.CP = 0.2\n$TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}\n"
        "$BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}\nPTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}\n"
        "Up()\nUp()\nEND\n"
        "DEF Up( )\nLIN {X 100, Y -100, Z 100, A 0, B 90, C 0}\nWAIT SEC 1\nEND\n"
    )
    path = tmp_path / "p.src"
    path.write_text(source)
    old = olp.build(station, path, post=str(folder), collisions=None)
    assert old.ok and "DEF Up" not in old.files["p.src"]
    assert old.files["p.src"].count("WAIT SEC 1") == 2
    new = build(station, path)
    assert new.files["p.src"].count("DEF Up()") == 1 and new.files["p.src"].count("Up()") == 3
    refused = olp.build(station, PALLETISE, post=str(folder), collisions=None)
    errors = [d for d in refused.diagnostics if d.severity == "error"]
    assert {d.span.line for d in errors if d.span} == {40, 51}  # PlacePart, Gripper
    assert all("takes parameters" in d.message for d in errors) and not refused.files


def turning_program(station: Any) -> ir.Program:
    """A routine whose PTP has no configuration: from A6 at +170 deg it resolves to +180,
    from -170 to -180, which KUKA's Turn tells apart."""
    joints = np.radians([0, -80, 100, 0, 40, 180])
    pose = station.robot.flange_poses(joints)
    inside = ir.JointMove(target=ir.CartesianTarget(pose=pose), span=ir.SourceSpan("t.src", 9))

    def start(a6: float, line: int) -> ir.JointMove:
        target = ir.JointTarget(joints=np.radians([0, -80, 100, 0, 40, a6]))
        return ir.JointMove(target=target, span=ir.SourceSpan("t.src", line))

    calls = [ir.RoutineCall(name="Turn", span=ir.SourceSpan("t.src", n)) for n in (3, 5)]
    body = [start(170, 2), calls[0], start(-170, 4), calls[1]]
    routine = ir.Routine(name="Turn", body=[inside], span=ir.SourceSpan("t.src", 8))
    return ir.Program(name="t", instructions=body, routines=[routine], source="t.src")


def test_one_motion_resolved_two_ways_is_an_error_not_a_pick(station: Any) -> None:
    result = build(station, turning_program(station))
    (error,) = [d for d in result.diagnostics if d.severity == "error"]
    assert error.kind == "routine_configuration" and error.span and error.span.line == 9
    assert "call at line 5" in error.message and "call at line 3" in error.message
    assert not result.files


def test_one_configuration_at_every_call_is_written_once(station: Any) -> None:
    program = turning_program(station)
    same = ir.JointMove(target=ir.JointTarget(joints=np.radians([0, -80, 100, 0, 40, 170])))
    program = ir.Program(
        name="t",
        instructions=(same, program.instructions[1], same, program.instructions[3]),
        routines=program.routines,
        source="t.src",
    )
    result = build(station, program)
    assert result.ok
    assert result.files["t.src"].count("DEF Turn()") == 1


SCREW = ROUTINES / "screw_cell.src"


@pytest.fixture(scope="module")
def ur_station() -> Any:
    return olp.load_station(REPO / "stations" / "ur5e_screw_cell.yaml")


def test_urscript_writes_the_routines_as_functions(ur_station: Any) -> None:
    result = build(ur_station, SCREW, "ur")
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    golden("ur", result.files)
    text = result.files["screw_cell.script"]
    assert text.count("  def Shake(nTimes):") == 1 and text.count("  Shake(") == 2


def test_urscript_refuses_an_out_parameter_the_routine_changes(station: Any) -> None:
    """URScript passes by value: PlacePart's ``nCount:OUT`` (incremented) would silently stop
    counting in the caller, so it is an error on the routine; Report's OUT parameter, only read,
    is written (by value is exact there)."""
    result = build(station, PALLETISE, "ur")
    errors = [d for d in result.diagnostics if d.severity == "error" and d.kind == "flow"]
    by_value = [d for d in errors if "passed by reference (OUT)" in d.message]
    assert [(d.span.line, "nCount" in d.message) for d in by_value if d.span] == [(40, True)]
    assert not result.files


def test_a_post_without_routines_refuses_parameters_and_names_what_it_leaves_out(
    station: Any,
) -> None:
    """LS does not write routines yet: a routine's body at each call is exact only without
    parameters, so PlacePart and Gripper are errors, and the functions and the handler no call
    runs are warnings naming them (never a silent drop)."""
    result = build(station, PALLETISE, "fanuc")
    errors = [d for d in result.diagnostics if d.kind == "routine"]
    assert sorted(d.span.line for d in errors if d.span) == [40, 51]
    left_out = [d for d in result.diagnostics if d.kind == "routine_not_written"]
    assert [d.severity for d in left_out] == ["warning"] * 3
    assert sorted(d.span.line for d in left_out if d.span) == [57, 65, 70]
    assert not result.files


SORT = ROUTINES / "sort_abb.src"


@pytest.fixture(scope="module")
def abb_station() -> Any:
    return olp.load_station(REPO / "stations" / "abb_irb120_pick_cell.yaml")


def test_rapid_writes_procs_and_funcs_with_inout(abb_station: Any) -> None:
    """KRL's ``nCount:OUT`` is RAPID's ``INOUT num nCount`` (by reference), ``:IN`` a plain
    parameter; a DEFFCT is a FUNC; the module passes the independent RAPID checker."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        from rapidchecker.cli import check_file

    result = build(abb_station, SORT, "abb")
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    golden("abb", result.files)
    text = result.files["sort_abb.mod"].replace("\r\n", "\n")
    assert "  PROC Drop(num nBin, INOUT num nCount)" in text
    assert "  FUNC bool Enough(num nHave)" in text
    assert [str(e) for e in check_file(text)] == []


def test_rapid_refuses_a_value_for_an_inout_parameter(abb_station: Any, tmp_path: Path) -> None:
    source = SORT.read_text().replace("Drop(3, nSorted)", "Drop(3, 7)")
    path = tmp_path / "sort_abb.src"
    path.write_text(source)
    result = build(abb_station, path, "abb")
    (error,) = [d for d in result.diagnostics if d.severity == "error"]
    assert error.span is not None and error.span.line == 11
    assert "nCount of Drop is INOUT: the call must give it a variable" in error.message


CORPUS = REPO / "tests" / "corpus" / "krc" / "R1"
CORPUS_FILES = sorted(p.name for p in (CORPUS / "Program").glob("*.src") if p.stem != "home_check")


@pytest.mark.parametrize("name", CORPUS_FILES)
def test_krl_to_krl_keeps_the_routines_of_the_corpus(
    station: Any, name: str, tmp_path: Path
) -> None:
    """Every routine the KRL corpus's files hold comes back from the KRL post with the same
    parameters, locals, result type and statements (the main body: test_krl_flow_post.py)."""
    from olp.frontends.bundled import KrlOptions

    config = CORPUS / "System" / "$config.dat"
    path = CORPUS / "Program" / name
    source = load_krl(path, config).program
    result = olp.build(
        station, path, post="kuka", program_options=KrlOptions(config_dat=config), collisions=None
    )
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    for file, text in result.files.items():
        (tmp_path / file).write_text(text)
    (written,) = [f for f in result.files if f.endswith(".src")]
    again = load_krl(tmp_path / written).program
    assert [signature(r) for r in again.routines] == [signature(r) for r in source.routines]
    for ours, theirs in zip(again.routines, source.routines, strict=True):
        assert shape(ours.body) == shape(theirs.body), ours.name


def test_written_out_locals_may_not_share_a_name(station: Any, tmp_path: Path) -> None:
    """Written out at its call (LS), Tally's own ``n`` would be the program's ``n``: an error;
    KRL keeps them apart, and so does the KUKA post, which writes the routine."""
    source = (
        "DEF p( )\nDECL INT n\nn = 5\nTally()\nWAIT SEC 1\nEND\n"
        "DEF Tally( )\nDECL INT n\nn = 1\nEND\n"
    )
    path = tmp_path / "p.src"
    path.write_text(source)
    result = build(station, path, "fanuc")
    (error,) = [d for d in result.diagnostics if d.kind == "routine"]
    assert error.span is not None and error.span.line == 8
    assert "same variable as the program's" in error.message
    assert build(station, path, "kuka").ok


def test_named_points_of_the_routines_are_in_the_dat(station: Any, tmp_path: Path) -> None:
    """``points: dat``: a routine's motions refer to named points, which the module's data list
    (shared by every DEF of the module) must declare like the main program's; before, the
    routines' points were declared nowhere and the module did not compile. Every name a
    motion uses is declared once, and a routine's point holds its first call's values."""
    from olp.posts import find_post

    folder = tmp_path / "named"
    shutil.copytree(find_post("kuka").manifest.folder, folder)
    manifest = folder / "post.yaml"
    manifest.write_text(manifest.read_text().replace("points: inline", "points: dat"))
    result = olp.build(station, PALLETISE, post=str(folder), collisions=None)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    src, dat = (result.files[f"palletise.{ext}"].split("\r\n") for ext in ("src", "dat"))
    used = [w for line in src for w in line.split() if w.startswith("XP") or w.startswith("XA")]
    used = [w.rstrip(",") for w in used]
    declared = [line.split()[2].split("=")[0] for line in dat if line.startswith("DECL E6")]
    assert sorted(set(used)) == sorted(declared) and len(declared) == len(set(declared))
    routine_lines = src[src.index("DEF PickPart()") :]
    assert any(line.startswith(("LIN XP", "PTP XP")) for line in routine_lines)
