"""What real controller files declare (issue 15, step 3): declarations without DECL, array
parameters, modules of functions only, array results, STRUC members sized by constants, the
spline _REL motions, ON_ERROR_PROCEED. Every test here failed on main before this change."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from olp import ir
from olp.frontends.krl import load_config_dat, load_krl, parse_dat, parse_krl

REPO = Path(__file__).resolve().parents[2]
CONTROLLER = REPO / "tests" / "corpus" / "krc" / "R1"
CONFIG = CONTROLLER / "System" / "$config.dat"


def test_a_controllers_config_dat_reads() -> None:
    config = load_config_dat(CONFIG)
    # E6AXIS XHOME={...} and FRAME REF_TOOL={...} are written without DECL on a controller
    for name in ("XHOME", "XHOME1", "REF_TOOL", "TOOL_DATA", "BASE_DATA", "NCYCLECOUNT"):
        assert name in config.values
    types = {i.span.line for i in config.ignored if i.text.lstrip().startswith(("STRUC", "GLOBAL"))}
    assert {34, 35} <= types  # STRUC members sized by a constant (CHAR TEXT[MAX_MSG_LEN]) read


def test_config_dat_home_position_is_used(tmp_path: Path) -> None:
    src = tmp_path / "go_home.src"
    src.write_text("DEF go_home( )\nPTP XHOME\nEND\n")
    (home,) = load_krl(src, CONFIG).program
    assert isinstance(home, ir.JointMove) and isinstance(home.target, ir.JointTarget)
    np.testing.assert_allclose(np.degrees(home.target.joints), [0, -90, 90, 0, 30, 0])


def test_structure_types_without_decl_in_a_program() -> None:
    result = parse_krl(
        "DEF p( )\nFRAME lfOffset\nE6AXIS lHome={A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}\n"
        "lfOffset={X 10,Y 0,Z 0,A 0,B 0,C 0}\nPTP lHome\nEND\n"
    )
    (move,) = result.program.motions()
    assert isinstance(move.target, ir.JointTarget) and move.target.name == "lHome"
    kinds = [(i.kind, getattr(i, "type_name", None)) for i in result.program]
    assert kinds[:2] == [("declare", "FRAME"), ("declare", "E6AXIS")]


def test_array_parameters_and_array_results() -> None:
    result = parse_krl(
        'DEF p( )\nDECL CHAR sText[40]\nsText[]="done"\nShow(sText[], 3)\nEND\n'
        "DEF Show(sMsg[]:IN, nLevel:IN)\nDECL CHAR sMsg[40]\nDECL INT nLevel\n"
        "$OUT[80]=TRUE\nEND\n"
        'DEFFCT CHAR[128] Text(nNumber:IN)\nDECL INT nNumber\nRETURN "x"\nENDFCT\n'
    )
    kinds = [i.kind for i in result.program.expanded() if i.kind not in ("declare", "assign")]
    assert kinds == ["set_output"]  # Show(sMsg[]:IN, ...) at its call
    show, text = result.program.routines
    assert [(p.name, p.type_name, len(p.dims), p.direction) for p in show.params] == [
        ("sMsg", "CHAR", 1, "in"),
        ("nLevel", "INT", 0, "in"),
    ]
    assert (text.returns, len(text.returns_dims)) == ("CHAR", 1)


def test_a_module_of_functions_only_is_an_empty_program_with_every_function_kept() -> None:
    path = CONTROLLER / "Program" / "msg_lib.src"
    result = load_krl(path, CONFIG)
    assert (result.program.name, len(result.program)) == ("msg_lib", 0)
    functions = [(r.name, r.returns, r.exported) for r in result.program.routines]
    assert functions == [
        ("MsgNotify", "INT", True),
        ("MsgText", "CHAR", True),
        ("MsgClear", "BOOL", True),
    ]
    returns = [n for r in result.program.routines for n in r.body if isinstance(n, ir.Return)]
    assert len(returns) == 3 and all(r.value is not None for r in returns)


def test_the_program_is_the_first_def_even_after_functions() -> None:
    result = parse_krl("DEFFCT INT F( )\nRETURN 1\nENDFCT\nDEF main( )\nWAIT SEC 1\nEND\n")
    assert result.program.name == "main" and [i.kind for i in result.program] == ["wait"]


def test_spline_rel_motions() -> None:
    result = parse_krl(
        "DEF p( )\n$VEL.CP=0.1\nSPTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}\nSPTP_REL {A1 10}\n"
        "SLIN {X 100,Y 0,Z 200,A 0,B 90,C 0}\nSLIN_REL {Z 50} C_SPL\nEND\n"
    )
    _, turned, _, up = result.program
    assert isinstance(turned, ir.JointMove) and isinstance(turned.target, ir.JointTarget)
    np.testing.assert_allclose(np.degrees(turned.target.joints), [10, -90, 90, 0, 30, 0])
    assert isinstance(up, ir.LinearMove) and isinstance(up.target, ir.CartesianTarget)
    np.testing.assert_allclose(up.target.pose[:3, 3], [0.1, 0.0, 0.25])


def test_on_error_proceed_is_kept_as_written() -> None:
    result = parse_krl("DEF p( )\nON_ERROR_PROCEED\nWAIT SEC 1\nEND\n")
    kept, _ = result.program
    assert isinstance(kept, ir.Verbatim) and (kept.text, kept.span.line) == ("ON_ERROR_PROCEED", 2)


def test_declarations_a_data_list_writes_without_decl() -> None:
    data = parse_dat(
        "DEFDAT X\nEXT P9 (P9_CMD :IN,CHAR [] :OUT)\nBOOL bFlag\nINT $ACT_GROUP='B0001'\n"
        "LOAD LOAD_X={M 2.0,CM {X 1.0,Y 0.0,Z 0.0,A 0.0,B 0.0,C 0.0},J {X 0.1,Y 0.1,Z 0.1}}\n"
        "ENDDAT\n"
    )
    assert {"BFLAG", "$ACT_GROUP", "LOAD_X"} <= set(data.values)
