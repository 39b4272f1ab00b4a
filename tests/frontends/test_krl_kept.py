"""Nothing a KRL program says is dropped silently (issue 15): what olp does not model is kept as
written (:class:`olp.ir.Verbatim`) or is a warning, never only an info line."""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir
from olp.frontends.bundled import KrlOptions
from olp.frontends.krl import load_krl, parse_krl

REPO = Path(__file__).resolve().parents[2]
STATION = REPO / "stations" / "kr6_milling_cell.yaml"
CORPUS = REPO / "tests" / "corpus" / "krc" / "R1"
CONFIG = REPO / "examples" / "robot_config.dat"


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(STATION)


def build(station: object, path: Path, post: str = "kuka") -> olp.api.BuildResult:
    options = KrlOptions(config_dat=CONFIG)
    return olp.build(station, path, post=post, program_options=options, collisions=None)


def test_path_acceleration_reaches_the_krl_output(station: object) -> None:
    """``$ACC.CP = 2.0`` is a motion parameter olp models (issue 13): the KRL post writes it
    with the path speed, before the first LIN."""
    result = build(station, REPO / "examples" / "facing_mill.src")
    assert result.ok
    src = result.files["Facing_Mill.src"].splitlines()
    assert "$ACC.CP = 2.0000" in src
    assert src.index("$ACC.CP = 2.0000") < next(i for i, t in enumerate(src) if t.startswith("LIN"))


@pytest.mark.parametrize(
    ("post", "written"),
    [
        ("abb", "PathAccLim TRUE \\AccMax:=2.000, TRUE \\DecelMax:=2.000;"),
        ("ur", "a=2.00000"),
        ("fanuc", None),
    ],
)
def test_the_path_acceleration_reaches_another_vendor(
    station: object, post: str, written: str | None
) -> None:
    """Written where the language can say it, a warning on the first LIN where it cannot."""
    result = build(station, REPO / "examples" / "facing_mill.src", post)
    assert not [d for d in result.diagnostics if d.severity == "error"]
    text = "".join(result.files.values())
    warned = [d for d in result.diagnostics if d.kind == "acceleration"]
    if written is None:
        assert len(warned) == 1 and "TCP path acceleration" in warned[0].message
    else:
        assert written in text and not warned


def test_calls_with_effects_and_the_checks_of_their_results_are_kept() -> None:
    result = load_krl(CORPUS / "Program" / "rsi_correction.src", CONFIG)
    kinds = [(n.kind, n.span.line) for n in result.program.instructions]
    assert [k for k in kinds if k[0] in ("assign", "if")] == [
        ("assign", 14),  # ret=RSI_CREATE(...)
        ("if", 15),  # IF (ret <> RSIOK) THEN HALT ENDIF
        ("assign", 18),
        ("if", 19),
        ("assign", 23),
        ("if", 24),
    ]
    create = result.program.instructions[[k for k, _ in kinds].index("assign", 2)]
    assert isinstance(create, ir.Assign) and isinstance(create.value, ir.FunctionCall)
    assert create.value.name == "RSI_CREATE" and len(create.value.args) == 3
    check = next(n for n in result.program.instructions if isinstance(n, ir.If))
    (halt,) = check.branches[0].body
    assert isinstance(halt, ir.Verbatim) and halt.text == "HALT"


def test_the_krl_post_writes_the_calls_and_their_checks(station: object) -> None:
    result = build(station, CORPUS / "Program" / "rsi_correction.src")
    lines = result.files["rsi_correction.src"].replace("\r", "").splitlines()
    start = lines.index('ret = RSI_CREATE("RSI_Ethernet.rsix", CONTID, TRUE)')
    assert lines[start + 1 : start + 5] == [
        "IF ret <> RSIOK THEN",
        "HALT",
        "ENDIF",
        "ret = RSI_ON(#RELATIVE)",
    ]


def test_no_statement_of_the_program_is_dropped_at_info_level(station: object) -> None:
    for name in ("pendant_pick.src", "facing_mill.src"):
        result = build(station, REPO / "examples" / name)
        src = str(REPO / "examples" / name)
        ours = [d for d in result.diagnostics if d.span and d.span.file == src]
        quiet = [d for d in ours if d.severity == "info" and d.kind in ("ignored", "verbatim")]
        assert all(d.kind == "verbatim" for d in quiet), [d.format() for d in quiet]
        # facing_mill's one kept line was $ACC.CP, which olp now models (issue 13)
        assert quiet or name == "facing_mill.src"
        # the pendant's $BWDSTART and INI lines are kept for the KRL post (issue 15)
        assert not any(d.kind == "ignored" and d.severity == "warning" for d in result.diagnostics)
    other = build(station, REPO / "examples" / "pendant_pick.src", "abb").diagnostics
    warned = [d.message for d in other if d.kind == "ignored" and d.severity == "warning"]
    assert any("$BWDSTART only matters when stepping backwards" in m for m in warned)


def test_verbatim_is_one_line() -> None:
    span = ir.GENERATED
    with pytest.raises(ir.FlowError, match="one line"):
        ir.Verbatim(text="$ACC.CP = 2\nPTP {A1 0}", language="krl", span=span)
    with pytest.raises(ir.FlowError, match="statement"):
        ir.Verbatim(text="  ", language="krl")


def test_a_motion_to_where_the_robot_is_is_kept_as_written() -> None:
    from olp.frontends.krl import parse_krl

    result = parse_krl("DEF p( )\nPTP $POS_ACT\nPTP $AXIS_ACT C_PTP\nWAIT SEC 1\nEND\n")
    kept = [(i.kind, getattr(i, "text", ""), i.span.line) for i in result.program]
    assert kept == [
        ("verbatim", "PTP $POS_ACT", 2),
        ("verbatim", "PTP $AXIS_ACT C_PTP", 3),
        ("wait", "", 4),
    ]


def test_a_copied_post_may_leave_foreign_lines_out_with_a_warning(
    station: object, tmp_path: Path
) -> None:
    import shutil

    folder = tmp_path / "abb_drop"
    shutil.copytree(REPO / "posts" / "abb", folder)
    manifest = folder / "post.yaml"
    text = manifest.read_text().replace("options:\n", "options:\n  foreign_verbatim: drop\n", 1)
    manifest.write_text(text)
    # $ADVANCE is kept as written ($ACC.CP, the example before, is now modelled: issue 13)
    program = tmp_path / "facing_mill.src"
    mill = (REPO / "examples" / "facing_mill.src").read_text()
    program.write_text(mill.replace("$ACC.CP = 2.0", "$ADVANCE = 3"))
    result = build(station, program, str(folder))
    assert result.ok and result.files
    (dropped,) = [d for d in result.diagnostics if d.kind == "verbatim_dropped"]
    assert dropped.severity == "warning" and "'$ADVANCE = 3' (line 12)" in dropped.message
    assert "ADVANCE" not in "".join(result.files.values())


def test_an_output_olp_cannot_number_or_value_is_kept_as_written(tmp_path: Path) -> None:
    """``$OUT[nOut] = bState`` (a PLC handshake with numbers from variables) is a statement of
    the program: kept for the KRL post, never dropped; a known index and value still make a
    SetOutput."""
    path = tmp_path / "io.src"
    path.write_text(
        "DEF io( )\nDECL INT nOut\nDECL BOOL bState\nnOut = $IN[7]\nbState = $IN[8]\n"
        "$OUT[nOut] = TRUE\n$OUT[5] = bState\n$OUT[5] = TRUE\nEND\n"
    )
    program = load_krl(path).program
    kept = [(n.span.line, n.text) for n in program if isinstance(n, ir.Verbatim)]
    assert kept == [(6, "$OUT[nOut] = TRUE"), (7, "$OUT[5] = bState")]
    assert [n for n in program if isinstance(n, ir.SetOutput)] == [
        ir.SetOutput(index=5, value=True, span=ir.SourceSpan(str(path), 8, 1, 8, 15))
    ]


HERE_PROGRAM = (
    "DEF here( )\nDECL E6POS pAct\npAct = $POS_ACT\n{between}"
    "SPTP pAct WITH $VEL_AXIS[1]=10, $VEL_AXIS[2]=10\nPTP XHOME\nEND\n"
)


def test_a_motion_to_a_variable_given_pos_act_is_kept_as_no_motion(tmp_path: Path) -> None:
    """``pAct = $POS_ACT`` then ``SPTP pAct WITH ...``: the restart "to itself" of real cells.
    With no motion in between it moves to where the robot stands: kept, nothing to check."""
    path = tmp_path / "here.src"
    path.write_text(HERE_PROGRAM.format(between=""))
    program = load_krl(path, CORPUS / "System" / "$config.dat").program
    kept = [(n.span.line, n.reason) for n in program if isinstance(n, ir.Verbatim)]
    assert kept == [(4, "moves to where the robot already is (pAct = $POS_ACT): no motion")]
    assert [n.span.line for n in program.motions()] == [5]


def test_a_held_pos_act_is_stale_after_a_motion(tmp_path: Path) -> None:
    """After a motion, pAct is a position only the run knows: the SPTP to it is a motion to a
    run-time target (not checked, with a warning from the passes), not taken as "no motion"."""
    path = tmp_path / "here.src"
    path.write_text(HERE_PROGRAM.format(between="PTP XHOME\n"))
    result = load_krl(path, CORPUS / "System" / "$config.dat")
    (moved,) = [n for n in result.program if isinstance(n, ir.RuntimeMove)]
    assert moved.span.line == 5 and moved.target == ir.Name(name="pAct", span=moved.target.span)
    assert "pAct" in moved.reason


def test_a_held_pos_act_is_stale_after_a_block_that_may_move(tmp_path: Path) -> None:
    """After a block that may move the robot, pAct is known only when the program runs: a
    motion to a run-time target with the settings in effect (its WITH's), which the KRL post
    writes before it (before, olp stopped: the posts wrote settings only before the motions
    they modelled)."""
    path = tmp_path / "here.src"
    path.write_text(HERE_PROGRAM.format(between="IF $IN[3] THEN\nPTP XHOME\nENDIF\n"))
    program = load_krl(path, CORPUS / "System" / "$config.dat").program
    (moved,) = [n for n in program if isinstance(n, ir.RuntimeMove)]
    assert moved.motion == "joint" and moved.speed.joint == pytest.approx(0.1)


def test_a_held_pos_act_is_stale_after_a_plain_motion() -> None:
    """A plain LIN between ``pAct = $POS_ACT`` and ``LIN pAct`` moves the robot away: the LIN
    back is a motion to a run-time target, not "where the robot already is" (the simple
    motions olp reads on its fast path were not counted, so it was kept as no motion, and the
    next motion was taken to start at the LIN's end)."""
    text = (
        "DEF h( )\nDECL E6POS pAct\n$BASE = $NULLFRAME\n$TOOL = $NULLFRAME\n$VEL.CP = 0.2\n"
        "PTP {A1 0,A2 -90,A3 90,A4 0,A5 45,A6 0}\npAct = $POS_ACT\n"
        "LIN {X 500,Y 0,Z 600,A 0,B 90,C 0}\nLIN pAct\nEND\n"
    )
    program = parse_krl(text, "h.src").program
    assert [n for n in program if isinstance(n, ir.Verbatim)] == []
    (back,) = [n for n in program if isinstance(n, ir.RuntimeMove)]
    assert back.span.line == 9 and "$POS_ACT" in back.reason


def test_after_a_call_that_may_move_a_with_motion_is_kept_as_written(tmp_path: Path) -> None:
    """Another module's routine may move the robot and set any setting: the SPTP with its
    WITH runs with the settings the controller then holds for all it does not set itself, so
    it is kept as written (WITH and all), and the PTP after it runs with the controller's
    settings too (nothing set them again)."""
    path = tmp_path / "here.src"
    path.write_text(HERE_PROGRAM.format(between="GO_SOMEWHERE()\n"))
    program = load_krl(path, CORPUS / "System" / "$config.dat").program
    kept = [n.text for n in program if isinstance(n, ir.Verbatim)]
    assert kept == ["SPTP pAct WITH $VEL_AXIS[1]=10, $VEL_AXIS[2]=10"]
    (home,) = [n for n in program if isinstance(n, ir.RuntimeMove)]
    assert home.controller_settings and "GO_SOMEWHERE at line 4" in home.reason


@pytest.mark.parametrize("again", ["$TOOL = $NULLFRAME", "$TOOL = TOOL_DATA[1]"])
def test_a_tool_set_again_after_a_branch_is_known_even_if_one_path_had_it(
    tmp_path: Path, again: str
) -> None:
    """The inline forms set the tool before every motion; after an IF whose paths leave
    different tools, setting it again settles it, also to the tool one of the paths had (a
    real palletizing program stopped here: its next fold set Tool[0] again)."""
    path = tmp_path / "tools.src"
    path.write_text(
        "DEF tools( )\n$TOOL = $NULLFRAME\nIF $IN[1] THEN\n$TOOL = TOOL_DATA[1]\nENDIF\n"
        f"{again}\nPTP XHOME\nEND\n"
    )
    program = load_krl(path, CORPUS / "System" / "$config.dat").program
    assert [m.span.line for m in program.motions()] == [7]
