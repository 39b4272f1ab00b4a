"""Constructs of real KR C4 backups (``benchmarks/krl_corpus.py --backups``) that olp could not
read or write back before: each test program is written for olp in the style of the backups, the
KRL post writes it, and the written module reads again with the same statements."""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir
from olp.frontends.krl import load_krl
from olp.frontends.krl.native import is_ini_line
from olp.ir_flow import leaves_and_blocks

REPO = Path(__file__).resolve().parents[2]

MATRIX_MODULE = """\
&ACCESS RVO
DEF MatrixTools( )
   REAL rRot[3,3]
   REAL rAngle
   rAngle = 0
   RowAngle(rRot[,], rAngle)
END

DEF RowAngle(rMat[,]:OUT, rA:OUT)
   REAL rMat[,], rA
   rA = rMat[2,1] + rMat[1,1]
END
"""

LIBRARY_MODULE = """\
&ACCESS RV1
DEFFCT REAL SpindleRpm(rCutSpeed:IN, rDiameter:IN)
   REAL rCutSpeed
   REAL rDiameter
   RETURN (rCutSpeed*1000)/(3.14*rDiameter)
ENDFCT

DEFFCT INT Clamp(nValue:IN)
   INT nValue
   IF nValue > 100 THEN
      RETURN 100
   ENDIF
   RETURN nValue
ENDFCT
"""


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def _written(station: object, folder: Path, name: str, text: str) -> tuple[ir.Program, str]:
    """The program olp reads from ``text`` (saved as ``name``) and the KRL it writes."""
    src = folder / name
    src.write_text(text, encoding="latin-1")
    result = olp.build(station, src, post="kuka", collisions=None)  # type: ignore[arg-type]
    assert result.ok, [d.message for d in result.diagnostics if d.severity == "error"]
    (written,) = [t for n, t in result.files.items() if n.lower().endswith(".src")]
    return load_krl(src).program, written


def _shape(program: ir.Program) -> list[str]:
    """Every statement of the program and its routines, in order, by kind (comments apart, and
    the INI lines the KRL post writes from its template where the source has none)."""
    nodes = [*program.instructions, *(n for r in program.routines for n in r.body)]
    kept = (n for n in leaves_and_blocks(nodes) if n.kind != "comment" and not is_ini_line(n))
    return [n.kind for n in kept]


def _read_again(folder: Path, name: str, written: str) -> ir.Program:
    again = folder / "again"
    again.mkdir()
    (again / name).write_text(written, encoding="latin-1")
    return load_krl(again / name).program


def test_a_two_dimensional_array_parameter_is_read_and_written_back(
    station: object, tmp_path: Path
) -> None:
    program, written = _written(station, tmp_path, "MatrixTools.src", MATRIX_MODULE)
    routine = program.routine("RowAngle")
    assert routine is not None
    assert [(p.name, len(p.dims), p.direction) for p in routine.params] == [
        ("rMat", 2, "out"),
        ("rA", 0, "out"),
    ]
    assert "DEF RowAngle(rMat[,]:OUT, rA:OUT)" in written
    assert _shape(_read_again(tmp_path, "MatrixTools.src", written)) == _shape(program)


def test_a_module_of_functions_only_is_written_without_an_empty_program_of_its_name(
    station: object, tmp_path: Path
) -> None:
    program, written = _written(station, tmp_path, "SpindleRpm.src", LIBRARY_MODULE)
    assert [r.name for r in program.routines] == ["SpindleRpm", "Clamp"]
    heads = [line for line in written.splitlines() if line.startswith(("DEF", "GLOBAL"))]
    assert heads == [
        "DEFFCT REAL SpindleRpm(rCutSpeed:IN, rDiameter:IN)",
        "DEFFCT INT Clamp(nValue:IN)",
    ]
    again = _read_again(tmp_path, "SpindleRpm.src", written)
    assert [r.name for r in again.routines] == ["SpindleRpm", "Clamp"]
    assert _shape(again) == _shape(program)


SETTINGS_MODULE = """\
&ACCESS RV
DEF ApplySpeed(nPercent:IN, bSlow:IN)
   INT nPercent
   BOOL bSlow
   IF bSlow THEN
      $OV_PRO = nPercent / 2
   ELSE
      $OV_PRO = nPercent
   ENDIF
END
"""


def test_the_programs_own_parameters_are_a_warning_at_its_def_line(
    station: object, tmp_path: Path
) -> None:
    src = tmp_path / "ApplySpeed.src"
    src.write_text(SETTINGS_MODULE, encoding="latin-1")
    result = olp.build(station, src, post="kuka", collisions=None)  # type: ignore[arg-type]
    (said,) = [d for d in result.diagnostics if "program's parameters" in d.message]
    assert (said.severity, said.kind, said.span.line) == ("warning", "ignored", 2)
    assert "(nPercent, bSlow) are not kept" in said.message


TOOL_SETUP_MODULE = """\
&ACCESS RV
DEF ToolSetup( )
   $VEL.CP = 0.2
   $APO.CDIS = 5
   $BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}
   $TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}
   LIN {X 100, Y -100, Z 100, A 0, B 90, C 0}
   $BASE = $NULLFRAME
   IF $IN[3] THEN
      $TOOL = $NULLFRAME
   ENDIF
END
"""


def test_settings_no_motion_runs_with_are_a_warning_not_a_silent_drop(
    station: object, tmp_path: Path
) -> None:
    src = tmp_path / "ToolSetup.src"
    src.write_text(TOOL_SETUP_MODULE, encoding="latin-1")
    result = olp.build(station, src, post="kuka", collisions=None)  # type: ignore[arg-type]
    lost = [d for d in result.diagnostics if "no motion of the program runs with" in d.message]
    # the settings before the LIN are written with it; those after it are not written at all
    assert [(d.severity, d.span.line) for d in lost] == [("warning", 8), ("warning", 10)]
