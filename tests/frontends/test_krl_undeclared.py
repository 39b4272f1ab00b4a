"""Names no file olp read declares (issue 15): public backups often lack the module's .dat or
the controller's ``$config.dat``. Where such a file was not given, an undeclared name is a value
known only when the program runs (a warning per name at its first use; motions to it are
:class:`olp.ir.RuntimeMove`, a BAS reading it is kept as written, a ``$BASE`` set from it is
kept and leaves the base unknown); with every file given it stays the located error it is (the
controller's compiler refuses it too). A function nothing declares: a warning, written as it
stands. The programs are written for olp in the style of the pallet and pendant cells."""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir
from olp.errors import ParseError
from olp.frontends.bundled import KrlOptions
from olp.frontends.krl import KrlData, KrlResult, load_config_dat, parse_dat, parse_krl
from olp.ir_flow import leaves_and_blocks
from tests.krl_notes import own_notes

REPO = Path(__file__).resolve().parents[2]
CONFIG = REPO / "examples" / "robot_config.dat"
STATION = REPO / "stations" / "kr6_milling_cell.yaml"
HOME = "PTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}"
SETUP = ("$BASE = BASE_DATA[1]", "$TOOL = TOOL_DATA[1]", "$VEL.CP = 0.2", "$APO.CDIS = 5", HOME)
STACK = (
    "DECL INT nRow, nTier",
    *SETUP,
    "nRow = $IN[3]",
    "readyPos = xStackBase",
    "readyPos.X = readyPos.X + pOffset[nRow,nTier].X",
    "PTP readyPos C_DIS",
    "LIN readyPos",
)
"""A pallet stack's approach (lines 2-12): readyPos, xStackBase and pOffset are declared in the
module's .dat or in $config.dat, neither of which the backup holds."""


@pytest.fixture(scope="module")
def config() -> KrlData:
    return load_config_dat(CONFIG)


def empty_dat(name: str = "t") -> KrlData:
    return parse_dat(f"DEFDAT {name}\nENDDAT\n", f"{name}.dat")


def lower(*body: str, dat: KrlData | None = None, config: KrlData | None = None) -> KrlResult:
    return parse_krl("\n".join(["DEF t( )", *body, "END", ""]), "t.src", dat=dat, config=config)


def nodes(result: KrlResult) -> list[object]:
    return list(leaves_and_blocks(result.program.instructions))


def runtime(result: KrlResult) -> list[ir.RuntimeMove]:
    return [n for n in nodes(result) if isinstance(n, ir.RuntimeMove)]


def warned(result: KrlResult) -> dict[str, tuple[int, int]]:
    """The name each note is about -> (line, column) of the note."""
    return {n.message.split(" ")[0]: (n.span.line, n.span.column) for n in own_notes(result.notes)}


def test_a_point_of_a_missing_data_list_is_a_run_time_motion_with_one_warning_per_name() -> None:
    result = lower(*STACK)
    ptp, lin = runtime(result)
    assert (ptp.motion, lin.motion) == ("joint", "linear")
    assert ptp.target == ir.Name(name="readyPos", span=ptp.target.span)
    assert ptp.zone.radius == pytest.approx(0.005) and ptp.tool.number == 1
    assert "XSTACKBASE is not declared in t.src" in ptp.reason
    # once per name, at its first use: readyPos's is the assignment's target (line 9)
    assert warned(result) == {"readyPos": (9, 1), "xStackBase": (9, 12), "pOffset": (10, 27)}
    first = own_notes(result.notes)[0].message
    assert "no .dat file beside it; no $config.dat given" in first
    assert "cannot check what depends on it" in first
    assert "put t.dat beside the module / pass --config-dat to check these" in first


def test_with_every_file_given_an_undeclared_point_stays_a_located_error(config: KrlData) -> None:
    with pytest.raises(ParseError, match="XSTACKBASE is not declared") as info:
        lower(*STACK, dat=empty_dat(), config=config)
    assert info.value.span is not None and info.value.span.line == 11


def test_a_missing_dat_alone_is_enough(config: KrlData) -> None:
    """``$config.dat`` given, no .dat beside the module (a milling job's ``LIN lfPrePos[1]``):
    the warning names the .dat only."""
    result = lower(*SETUP, "LIN lfPrePos[1] C_DIS", config=config)
    (lin,) = runtime(result)
    assert isinstance(lin.target, ir.Index) and lin.zone.radius == pytest.approx(0.005)
    (note,) = result.notes
    assert "put t.dat beside the module to check these" in note.message
    assert "--config-dat" not in note.message


def test_a_spline_motion_with_its_own_settings_to_an_undeclared_grid_point() -> None:
    body = ("DECL INT r, c", *SETUP, "r = $IN[1]", "c = $IN[2]")
    motion = "SPTP approach[r,c] WITH $TOOL = TOOL_DATA[2], $BASE = BASE_DATA[3], $VEL.CP = 2"
    (sptp,) = runtime(lower(*body, motion, "PTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}"))
    assert (sptp.tool.number, sptp.frame.number) == (2, 3)


def test_the_inline_form_record_of_a_missing_file_keeps_its_bas() -> None:
    """``FDAT_ACT = FPOUNCE`` (FPOUNCE in no file olp read) then ``BAS(#PTP_PARAMS,100)``: the
    BAS is kept as written, the assignment it reads is written before it, and the motion
    right after it runs with the controller's settings (as ``FDAT_ACT = FHOME`` does)."""
    pounce = "DECL E6AXIS XPOUNCE={A1 10,A2 -80,A3 90,A4 0,A5 20,A6 0}"
    module = parse_dat(f"DEFDAT t\n{pounce}\nENDDAT\n", "t.dat")
    body = ("PDAT_ACT = PDEFAULT", "FDAT_ACT = FPOUNCE", "BAS(#PTP_PARAMS,100)", "PTP XPOUNCE")
    result = lower(*body, dat=module)
    (ptp,) = runtime(result)
    assert ptp.controller_settings and "BAS(#PTP_PARAMS) at line 4" in ptp.reason
    (kept,) = [n for n in nodes(result) if isinstance(n, ir.Verbatim)]
    assert kept.text == "BAS(#PTP_PARAMS,100)" and "FPOUNCE is not declared" in kept.reason
    assigned = [n.target for n in nodes(result) if isinstance(n, ir.Assign)]
    assert [getattr(t, "name", None) for t in assigned] == ["PDAT_ACT", "FDAT_ACT"]
    assert set(warned(result)) == {"FPOUNCE"}  # PDEFAULT is every $config.dat's: not a typo


def test_the_inline_form_record_is_an_error_when_every_file_is_given(config: KrlData) -> None:
    body = ("FDAT_ACT = FPOUNCE", "BAS(#PTP_PARAMS,100)", "PTP XHOME")
    with pytest.raises(ParseError, match="FPOUNCE is not declared") as info:
        lower(*body, dat=empty_dat(), config=config)
    assert info.value.span is not None and info.value.span.line == 3


PALLET = (
    "DECL INT nActive",
    "nActive = $IN[4]",
    "$BASE = palletBase[nActive].frame",
    "$TOOL = TOOL_DATA[1]",
)


def test_a_base_set_from_an_undeclared_name_is_kept_and_leaves_the_base_unknown() -> None:
    """``$BASE = palletBase[nActive].frame``: kept as written; a motion before the base is set
    again runs with the base the controller then holds (a run-time motion with the
    controller's settings, naming that line: olp checks nothing of it; before, an error);
    after ``$BASE = BASE_DATA[1]`` the motions are lowered as usual."""
    held = lower(*PALLET, "$VEL.CP = 0.2", HOME)
    (move,) = [n for n in nodes(held) if isinstance(n, ir.RuntimeMove)]
    assert move.controller_settings and "$BASE is set at line 4 from a value" in move.reason
    assert not list(held.program.motions())
    result = lower(*PALLET, "$BASE = BASE_DATA[1]", "$VEL.CP = 0.2", HOME)
    kept = [n for n in nodes(result) if isinstance(n, ir.Verbatim)]
    assert [n.text for n in kept] == ["$BASE = palletBase[nActive].frame"]
    assert "value known only at run time" in kept[0].reason
    (move,) = result.program.motions()
    assert move.frame.number == 1 and move.tool.number == 1
    assert set(warned(result)) == {"palletBase"}


def test_with_every_file_given_the_base_stays_an_error(config: KrlData) -> None:
    with pytest.raises(ParseError, match="cannot evaluate \\$BASE"):
        lower(*PALLET, "$BASE = BASE_DATA[1]", HOME, dat=empty_dat(), config=config)


def test_a_misspelt_name_never_passes_silently(config: KrlData) -> None:
    """A condition olp keeps as written does not need the value: the misspelling (nCuont for
    nCount) is a warning with every file given too (the controller's compiler refuses it)."""
    body = ("DECL INT nCount", HOME, "nCount = 1", "IF nCuont > 3 THEN", "$OUT[3] = TRUE", "ENDIF")
    for files in ({}, {"dat": empty_dat(), "config": config}):
        result = lower(*body, **files)  # type: ignore[arg-type]
        assert warned(result) == {"nCuont": (5, 4)}
    assert "refuses a name nothing declares" in own_notes(result.notes)[0].message


def test_a_function_nothing_declares_is_a_warning_and_kept_as_written() -> None:
    """``nPart = fnNextPart(1)``: the controller may hold the function in another module; olp
    warns once. A DEFFCT of the module, an EXTFCT and KRL's own functions are not warned."""
    routines = "DEFFCT INT fnOwn(n:IN)\nDECL INT n\nRETURN n + 1\nENDFCT\n"
    text = "\n".join(
        [
            "DEF t( )",
            "EXTFCT INT fnElsewhere(n:IN)",
            "DECL INT nPart",
            HOME,
            "nPart = fnNextPart(1)",
            "nPart = fnNextPart(2) + fnOwn(1) + fnElsewhere(2) + ABS(nPart)",
            "END",
            routines,
        ]
    )
    result = parse_krl(text, "t.src", dat=empty_dat())
    assert warned(result) == {"fnNextPart(...)": (5, 9)}
    assert "another module" in own_notes(result.notes)[0].message
    (first, _second) = [n for n in nodes(result) if isinstance(n, ir.Assign)]
    assert first.value == ir.FunctionCall(
        name="fnNextPart",
        args=(ir.Constant(value=1, span=first.value.args[0].span),),  # type: ignore[union-attr]
        span=first.value.span,
    )


def test_krl_to_krl_writes_the_undeclared_names_as_they_stand(tmp_path: Path) -> None:
    src = tmp_path / "stack.src"
    body = [PALLET[0], *STACK, *PALLET[1:], "$BASE = BASE_DATA[1]", HOME]
    src.write_text("\n".join(["DEF stack( )", *body, "END", ""]))
    result = olp.build(
        olp.load_station(STATION), src, post="kuka", program_options=KrlOptions(), collisions=None
    )
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    lines = [line.strip() for line in result.files["stack.src"].splitlines()]
    for line in (
        "readyPos = xStackBase",
        "readyPos.X = readyPos.X + pOffset[nRow,nTier].X",
        "$BASE = palletBase[nActive].frame",
    ):
        assert line in lines
    assert any(line.startswith("PTP readyPos") for line in lines)
    assert any(line.startswith("LIN readyPos") for line in lines)
    warnings = [d for d in result.diagnostics if d.kind == "krl_note"]
    assert {d.message.split(" ")[0] for d in warnings} == {
        "readyPos",
        "xStackBase",
        "pOffset",
        "palletBase",
    }
    assert all(d.severity == "warning" for d in warnings)
