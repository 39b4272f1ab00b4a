"""The KRL post writes control flow and data (issue 15, step 5); a post that does not yet stops
on them with an error naming the first one (RAPID and URScript: tests/posts/test_flow_posts.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.frontends.bundled import KrlOptions
from olp.frontends.krl import load_krl
from olp.ir_flow import leaves_and_blocks
from tests.krl_round_trip import comment_lines, keeps_in_order, statements

REPO = Path(__file__).resolve().parents[2]
CORPUS = REPO / "tests" / "corpus" / "krc" / "R1"
CONFIG = CORPUS / "System" / "$config.dat"
BUILDS = sorted(p.name for p in (CORPUS / "Program").glob("*.src") if p.stem != "home_check")


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def build(station: object, source: Path | ir.Program, post: str = "kuka") -> olp.api.BuildResult:
    options = KrlOptions(config_dat=CONFIG) if isinstance(source, Path) else None
    return olp.build(station, source, post=post, program_options=options, collisions=None)


def shape(program: ir.Program) -> list[str]:
    """The program's statements and blocks in order (declarations apart: KRL wants them first);
    motions and waits by kind, kept lines by their text (comments apart: :func:`comment_lines`)."""
    out = []
    for node in leaves_and_blocks(program.instructions):
        if not statements([node]):  # a comment, or the template's INI where the source has none
            continue
        if isinstance(node, ir.Verbatim):
            out.append(node.text.upper().replace(" ", ""))
        elif node.kind != "declare":
            out.append(node.kind)
    return out


def declared(program: ir.Program) -> set[str]:
    return {n.name.upper() for n in leaves_and_blocks(program.instructions) if n.kind == "declare"}


@pytest.mark.parametrize("name", BUILDS)
def test_krl_to_krl_keeps_every_statement(station: object, name: str, tmp_path: Path) -> None:
    source = load_krl(CORPUS / "Program" / name, CONFIG).program
    result = build(station, CORPUS / "Program" / name)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    for file, text in result.files.items():
        (tmp_path / file).write_text(text)
    (written,) = [f for f in result.files if f.endswith(".src")]
    again = load_krl(tmp_path / written, CONFIG).program  # the same controller's data
    assert shape(again) == shape(source)
    assert keeps_in_order(comment_lines(again), comment_lines(source))
    assert declared(again) == declared(source)
    assert len(list(again.motions())) == len(list(source.motions()))


@pytest.mark.parametrize("post", ["kuka", "abb", "ur", "fanuc"])
def test_every_post_writes_control_flow_unless_its_folder_predates_it(
    station: object, post: str, tmp_path: Path
) -> None:
    """Every bundled post writes pick_part.src's IF; a copy of its folder without
    ``flow: true`` (made before olp wrote control flow) stops, naming the first statement."""
    import shutil

    from olp.posts import find_post

    source = CORPUS / "Program" / "pick_part.src"
    assert not [d for d in build(station, source, post).diagnostics if d.kind == "control_flow"]
    folder = tmp_path / f"old_{post}"
    shutil.copytree(find_post(post).manifest.folder, folder)
    manifest = folder / "post.yaml"
    manifest.write_text(manifest.read_text().replace("flow: true\n", ""))
    result = build(station, source, str(folder))
    errors = [d for d in result.diagnostics if d.severity == "error"]
    assert [(d.kind, d.span.line if d.span else 0) for d in errors] == [("control_flow", 22)]
    assert "flow: true" in errors[0].message and not result.files


def down(x: float, speed: float, line: int) -> ir.LinearMove:
    pose = np.eye(4)
    pose[:3, :3] = np.diag([1.0, -1.0, -1.0])
    pose[:3, 3] = [x, -0.4, 0.3]
    span = ir.SourceSpan("t.src", line, 1)
    return ir.LinearMove(
        target=ir.CartesianTarget(pose=pose), speed=ir.Speed(linear=speed), span=span
    )


def test_settings_are_written_again_after_a_block(station: object) -> None:
    home = ir.JointMove(target=ir.JointTarget(joints=np.radians([0, -90, 90, 0, 45, 0])))
    block = ir.If(
        branches=(ir.Branch(condition=ir.DigitalInput(index=1), body=(down(0.45, 0.5, 3),)),),
        orelse=(down(0.5, 0.1, 5),),
        span=ir.SourceSpan("t.src", 2, 1),
    )
    program = ir.Program(
        name="p", instructions=(home, down(0.5, 0.1, 1), block, down(0.55, 0.1, 7))
    )
    lines = build(station, program).files["p.src"].replace("\r", "").splitlines()
    last = max(i for i, line in enumerate(lines) if line.startswith("LIN"))
    assert lines[lines.index("ENDIF") + 1 : last] == [
        "$BASE = $NULLFRAME ; world",
        "$TOOL = $NULLFRAME ; flange",
        "$VEL.CP = 0.10000",  # the then-branch ran at 0.5 m/s
    ]


def test_text_that_krl_cannot_hold_is_an_error(station: object) -> None:
    bad = ir.Assign(
        target=ir.Name(name="sText"),
        value=ir.Constant(value='a"; $OUT[1]=TRUE'),
        span=ir.SourceSpan("t.src", 4, 1),
    )
    result = build(station, ir.Program(name="p", instructions=(bad,)))
    errors = [
        (d.kind, d.span.line if d.span else 0) for d in result.diagnostics if d.severity == "error"
    ]
    assert errors == [("flow", 4)] and not result.files


def test_numbers_krl_cannot_hold_are_errors_not_crashes(station: object, tmp_path: Path) -> None:
    src = tmp_path / "big.src"
    src.write_text("DEF big( )\nDECL INT n\nn = " + "9" * 400 + "\nm = 3000000000\nEND\n")
    result = olp.build(station, src, collisions=None)
    found = [d for d in result.diagnostics if d.severity == "error"]
    assert [(d.kind, d.span.line if d.span else 0) for d in found] == [("flow", 3), ("flow", 4)]
    assert not result.files


def test_interrupts_and_triggers_are_written_back_as_krl(station: object) -> None:
    """KRL -> KRL keeps each interrupt and trigger as the source has it (DELAY in ms, PATH in
    mm), in place, a trigger before the motion it belongs to."""
    result = build(station, CORPUS / "Program" / "trigger_dispense.src")
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    lines = result.files["trigger_dispense.src"].replace("\r", "").splitlines()
    # the source's INI fold (written back as it has it, once) declares interrupt 3
    events = [line for line in lines if line.startswith(("INTERRUPT", "GLOBAL INTERRUPT", "TRIG"))]
    assert events == [
        "GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )",
        "INTERRUPT ON 3",
        "GLOBAL INTERRUPT DECL 12 WHEN $IN[31] == FALSE DO PRESSURE_LOST(2, #STOP)",
        "INTERRUPT DECL 14 WHEN $CYCFLAG[2] == FALSE DO VALVE_FAULT()",
        "INTERRUPT ON",
        "INTERRUPT DISABLE 14",
        "TRIGGER WHEN DISTANCE=0 DELAY=20 DO $OUT[21] = TRUE",
        "INTERRUPT ENABLE 14",
        "TRIGGER WHEN PATH=-15.5 DELAY=-40 DO BEAD_LOG(1) PRIO=-1",
        "TRIGGER WHEN PATH=5 ONSTART DELAY=0 DO $OUT[22] = TRUE",
        "TRIGGER WHEN DISTANCE=1 DELAY=0 DO $OUT[21] = FALSE",
        "INTERRUPT OFF 12",
        "INTERRUPT OFF",
    ]
    after = lines[lines.index("TRIGGER WHEN DISTANCE=1 DELAY=0 DO $OUT[21] = FALSE") + 1 :]
    assert next(line for line in after if line.startswith(("LIN", "PTP"))).startswith("LIN")


def event_program() -> ir.Program:
    at = ir.SourceSpan("t.src", 6, 1)
    trigger = ir.PathTrigger(action=ir.FunctionCall(name="GLUE_ON"), at="start", span=at)
    return ir.Program(name="p", instructions=(trigger, down(0.5, 0.1, 7)))


@pytest.mark.parametrize("post", ["abb", "ur", "fanuc"])
def test_other_posts_stop_on_a_trigger_naming_its_line(station: object, post: str) -> None:
    result = build(station, event_program(), post)
    errors = [d for d in result.diagnostics if d.severity == "error"]
    assert errors and all(d.span is not None and d.span.line == 6 for d in errors)
    assert "trigger" in errors[0].message and not result.files


def test_a_post_writing_flow_but_not_events_stops_on_their_line(station: object) -> None:
    """The base Post's check of instruction kinds covers a post that writes control flow but
    has not learnt interrupts and triggers: an error on the statement's line."""
    from olp.posts import find_post
    from olp.posts.base import Post

    kuka = find_post("kuka")
    kuka.KINDS = Post.KINDS  # type: ignore[misc]  # this instance only: as if it had not learnt them
    compiled = olp.compile(event_program(), station, collisions=None)  # type: ignore[arg-type]
    errors = [d for d in kuka.check(compiled) if d.severity == "error"]
    assert [(d.kind, d.span.line if d.span else 0) for d in errors] == [("unsupported", 6)]
    assert "trigger" in errors[0].message


@pytest.mark.parametrize(
    ("args", "ok"),
    [
        (("#CHK_HOME", "#PGNO_GET", "DMY[]", "0"), True),  # the controller's own cell.src
        (("$OUT[PGNO_REQ]", "TRUE", "0.2"), True),
        (("nPos[1,k]",), True),
        (("DMY[];LIN {X 0}",), False),
        (("DMY[1]) ; x",), False),
        (('DMY["a"]',), False),
    ],
)
def test_the_krl_post_writes_array_arguments_and_nothing_else(
    station: object, args: tuple[str, ...], ok: bool
) -> None:
    call = ir.Call(name="P00", args=args, span=ir.SourceSpan("t.src", 3, 1))
    result = build(station, ir.Program(name="p", instructions=(call,)))
    errors = [d.kind for d in result.diagnostics if d.severity == "error"]
    assert errors == ([] if ok else ["call_argument"])
    if ok:
        assert f"P00({', '.join(args)})" in result.files["p.src"]


def test_the_error_names_an_interrupt_with_its_article(station: object) -> None:
    at = ir.SourceSpan("t.src", 4, 1)
    switch = ir.InterruptSwitch(action="on", priority=5, span=at)
    program = ir.Program(name="p", instructions=(switch, down(0.5, 0.1, 7)))
    errors = [d for d in build(station, program, "abb").diagnostics if d.severity == "error"]
    assert "cannot write an interrupt instruction" in errors[0].message


EMPTY_ARMS = """DEF empty_arms( )
DECL INT nStep
nStep = 0
IF $IN[3] THEN
  nStep = 1
ENDIF
IF $IN[1] THEN
  $OUT[2] = TRUE
ELSE

ENDIF
SWITCH nStep
CASE 1
  $OUT[3] = TRUE
DEFAULT
ENDSWITCH
END
"""


@pytest.mark.parametrize("post", ["kuka", "abb"])
def test_an_else_or_default_the_source_leaves_empty_is_kept_in_its_own_language(
    station: object, post: str, tmp_path: Path
) -> None:
    """A KRL ``ELSE`` or ``DEFAULT`` with nothing under it is written back by the KRL post (KRL
    to KRL keeps every statement); another language's post leaves the empty arm out."""
    src = tmp_path / "empty_arms.src"
    src.write_text(EMPTY_ARMS)
    program = load_krl(src).program
    switch = next(n for n in program.instructions if isinstance(n, ir.Switch))
    assert switch.has_default and not switch.default
    result = olp.build(station, src, post=post, collisions=None)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    (text,) = [t for f, t in result.files.items() if f.endswith((".src", ".mod"))]
    lines = [line.strip().upper() for line in text.replace("\r", "").splitlines()]
    if post == "kuka":
        assert lines[lines.index("ELSE") + 1] == "ENDIF"
        assert lines[lines.index("DEFAULT") + 1] == "ENDSWITCH"
    else:
        assert "ELSE" not in lines and "DEFAULT:" not in lines


@pytest.mark.parametrize("head", ["GLOBAL DEF marked( )", "DEF marked( )"])
def test_the_program_keeps_the_global_mark_its_source_gives_it(
    station: object, head: str, tmp_path: Path
) -> None:
    """``GLOBAL DEF`` on a module's first routine changes nothing on the controller (that
    routine is visible to other modules anyway), but KRL to KRL keeps the line as it was."""
    src = tmp_path / "marked.src"
    src.write_text(f"{head}\n$OUT[1] = TRUE\nEND\n")
    result = olp.build(station, src, post="kuka", collisions=None)
    assert result.ok
    lines = result.files["marked.src"].replace("\r", "").splitlines()
    assert [line for line in lines if "DEF" in line] == [head]


@pytest.mark.parametrize(
    ("stem", "post", "written"),
    [
        ("pick_and_place_station_two", "kuka", "pick_and_place_station_t"),
        ("pick_and_place_station", "kuka", None),
        ("pick", "fanuc", None),  # Fanuc writes names in upper case: not a rename
    ],
)
def test_a_program_written_under_another_name_is_a_warning(
    station: object, stem: str, post: str, written: str | None, tmp_path: Path
) -> None:
    """A module renamed to fit the language (KRL: 24 characters) is no longer found by the
    modules that call it by its old name: the build says so instead of renaming in silence."""
    src = tmp_path / f"{stem}.src"
    src.write_text(f"DEF {stem}( )\n$OUT[1] = TRUE\nEND\n")
    result = olp.build(station, src, post=post, collisions=None)
    renamed = [d for d in result.diagnostics if d.kind == "renamed"]
    if written is None:
        assert renamed == []
    else:
        (warning,) = renamed
        assert warning.severity == "warning" and f"written as {written}:" in warning.message
        assert f"{written}.src" in result.files


HEADS = """DEF heads( )
DECL POS xGrid[2,3]
DECL CHAR sName[12]
sName[] = "cell"
Fill(xGrid[,])
Show(sName[])
END

DEF Fill(xPath[]:OUT)
DECL POS xPath[,]
xPath[1,1] = {X 0,Y 0,Z 0,A 0,B 0,C 0}
END

DEF Show(sText:IN)
CHAR sText[]
$OUT[1] = TRUE
END
"""


def test_routine_heads_mark_array_parameters_as_the_source_does(
    station: object, tmp_path: Path
) -> None:
    """KRL to KRL writes a head's brackets as read (``xPath[]`` of a two-dimensional array,
    ``sText`` of a string) rather than one position per declared dimension."""
    src = tmp_path / "heads.src"
    src.write_text(HEADS)
    params = {p.name: p for r in load_krl(src).program.routines for p in r.params}
    assert (params["xPath"].head_dims, len(params["xPath"].dims)) == (1, 2)
    assert (params["sText"].head_dims, len(params["sText"].dims)) == (0, 1)
    result = olp.build(station, src, post="kuka", collisions=None)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    heads = [line for line in result.files["heads.src"].splitlines() if line.startswith("DEF ")]
    assert heads == ["DEF heads( )", "DEF Fill(xPath[]:OUT)", "DEF Show(sText:IN)"]
