"""KRL -> KRL writes what the source said (issue 15): a module whose program is a function
(``DEFFCT``), and spline motions (``SPTP``/``SLIN``/``SCIRC``) to modelled and to run-time
targets keep their keyword.

The programs are olp's own, in the style of the KR C4 backups where the gaps were found (a
recovery function module of a milling cell, spline motions after a measured position).
"""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir
from olp.frontends.krl import load_krl, parse_krl
from olp.ir_flow import leaves, leaves_and_blocks

REPO = Path(__file__).resolve().parents[2]

RECOVER = """&ACCESS RVP
DEFFCT BOOL Recover(nStation:IN, nBase:IN)
   DECL INT nStation
   DECL INT nBase
   DECL BOOL bDone
   bDone = FALSE
   $VEL.CP = 0.2
   $TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}
   $BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}
   IF nStation == 2 THEN
      PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
      LIN {X 100, Y -100, Z 100, A 0, B 90, C 0}
      bDone = TRUE
   ENDIF
   RETURN bDone
ENDFCT
"""

SPLINES = """DEF splines( )
DECL E6POS pAt
$VEL.CP = 0.5
$APO.CDIS = 5
$TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}
$BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}
SPTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
SLIN {X 100, Y -100, Z 100, A 0, B 90, C 0} C_SPL
SCIRC {X 120, Y -80, Z 100, A 0, B 90, C 0}, {X 140, Y -100, Z 100, A 0, B 90, C 0}
LIN {X 100, Y -100, Z 120, A 0, B 90, C 0}
pAt = $POS_ACT
pAt.Z = pAt.Z + 10
SLIN pAt
LIN pAt
SPTP pAt C_SPL
END
"""


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def _build(station: object, folder: Path, name: str, text: str, post: str = "kuka") -> object:
    path = folder / name
    path.write_text(text)
    return olp.build(station, path, post=post, collisions=None)  # type: ignore[arg-type]


def _src(result: object) -> list[str]:
    errors = [d.format() for d in result.diagnostics if d.severity == "error"]  # type: ignore[attr-defined]
    assert not errors, errors
    (text,) = [t for n, t in result.files.items() if n.endswith(".src")]  # type: ignore[attr-defined]
    return [line.strip() for line in text.splitlines()]


# --------------------------------------------------------------------------------------------
# A module whose program is a function


def test_a_module_named_as_its_first_deffct_is_that_function() -> None:
    """The DEFFCT named as the file is the program (it was left out as a function nobody
    calls, with its motions, and an empty DEF written in its place)."""
    program = parse_krl(RECOVER, "Recover.src").program
    assert (program.name, program.returns) == ("Recover", "BOOL")
    assert [(p.name, p.type_name, p.direction) for p in program.params] == [
        ("nStation", "INT", "in"),
        ("nBase", "INT", "in"),
    ]
    kinds = [n.kind for n in leaves_and_blocks(program.instructions)]
    assert kinds == ["declare", "assign", "if", "joint", "linear", "assign", "return"]
    (ret,) = [n for n in leaves(program.instructions) if isinstance(n, ir.Return)]
    assert isinstance(ret.value, ir.Name) and ret.value.name == "bDone"


def test_a_function_program_is_written_as_a_deffct_and_reads_again(
    station: object, tmp_path: Path
) -> None:
    lines = _src(_build(station, tmp_path, "Recover.src", RECOVER))
    assert "DEFFCT BOOL Recover(nStation:IN, nBase:IN)" in lines
    assert lines[-1] == "ENDFCT" and "RETURN bDone" in lines and "END" not in lines
    assert not [line for line in lines if line.startswith(("DEF ", "BAS"))]
    again_dir = tmp_path / "again"
    again_dir.mkdir()
    (again_dir / "Recover.src").write_text("\n".join(lines) + "\n")
    again = load_krl(again_dir / "Recover.src").program
    source = parse_krl(RECOVER, "Recover.src").program
    assert (again.name, again.returns) == (source.name, source.returns)
    assert [(p.name, p.type_name, p.direction) for p in again.params] == [
        (p.name, p.type_name, p.direction) for p in source.params
    ]
    assert _kinds(again) == _kinds(source)


@pytest.mark.parametrize("post", ["abb", "ur", "fanuc"])
def test_other_posts_refuse_a_function_program_on_its_return(
    station: object, tmp_path: Path, post: str
) -> None:
    result = _build(station, tmp_path, "Recover.src", RECOVER, post)
    (error,) = [d for d in result.diagnostics if d.kind == "program_returns"]  # type: ignore[attr-defined]
    assert error.severity == "error" and error.span.line == 15
    assert "program Recover is a function giving a BOOL" in error.message
    assert not result.files  # type: ignore[attr-defined]


def test_a_function_program_without_a_file_name_stays_the_first_def() -> None:
    """Text given without a file name: the first DEF is the program, as before."""
    result = parse_krl("DEFFCT INT F( )\nRETURN 1\nENDFCT\nDEF main( )\nWAIT SEC 1\nEND\n")
    assert (result.program.name, result.program.returns) == ("main", None)


def test_the_ir_refuses_result_extents_without_a_result_type() -> None:
    dims = (ir.Constant(value=8),)
    with pytest.raises(ir.IRError, match="returns_dims without a result type"):
        ir.Program(name="p", instructions=(), returns_dims=dims)
    with pytest.raises(ir.IRError, match="a type name or None"):
        ir.Program(name="p", instructions=(), returns="")


# --------------------------------------------------------------------------------------------
# Spline motions


def test_spline_motions_are_marked_in_the_ir() -> None:
    program = parse_krl(SPLINES, "splines.src").program
    moves = [n for n in program if ir.is_motion(n) or isinstance(n, ir.RuntimeMove)]
    assert [(n.kind, n.spline) for n in moves] == [
        ("joint", True),
        ("linear", True),
        ("circular", True),
        ("linear", False),
        ("runtime_move", True),
        ("runtime_move", False),
        ("runtime_move", True),
    ]


def test_spline_motions_keep_their_keyword_in_krl(station: object, tmp_path: Path) -> None:
    """SPTP/SLIN/SCIRC are other motions on the controller than PTP/LIN/CIRC (settings,
    approximation): KRL -> KRL writes the keyword the source had, to modelled and to run-time
    targets, approximated with C_SPL at the $APO.CDIS olp writes before."""
    lines = _src(_build(station, tmp_path, "splines.src", SPLINES))
    motions = [line.split(" {")[0].split(" p")[0] for line in lines if _is_motion(line)]
    assert motions == ["SPTP", "SLIN", "SCIRC", "LIN", "SLIN", "LIN", "SPTP"]
    assert next(line for line in lines if line.startswith("SLIN {")).endswith(" C_SPL")
    assert "SPTP pAt C_SPL" in lines and "$APO.CDIS = 5.000" in lines


def test_spline_motions_are_plain_motions_for_other_posts(station: object, tmp_path: Path) -> None:
    text = SPLINES.split("pAt = $POS_ACT")[0] + "END\n"
    result = _build(station, tmp_path, "splines.src", text, "abb")
    (mod,) = [t for n, t in result.files.items() if n.endswith(".mod")]  # type: ignore[attr-defined]
    kinds = [line.split()[0] for line in mod.splitlines() if line.strip().startswith("Move")]
    assert kinds == ["MoveAbsJ", "MoveL", "MoveC", "MoveL"]


def _kinds(program: ir.Program) -> list[str]:
    return [n.kind for n in leaves_and_blocks(program.instructions) if n.kind != "comment"]


def _is_motion(line: str) -> bool:
    return line.split(" ")[0] in ("PTP", "LIN", "CIRC", "SPTP", "SLIN", "SCIRC")


# --------------------------------------------------------------------------------------------
# The data list's type definitions

TYPED_SRC = """DEF cell( )
mClamp.nForce = 5
eSide = #right
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
END
"""

TYPED_DAT = """DEFDAT cell PUBLIC
GLOBAL STRUC ClampData INT nForce, REAL rOpen, BOOL bShut
ENUM SideKind left, right
DECL GLOBAL ClampData mClamp={nForce 2, rOpen 10.5, bShut FALSE}
DECL SideKind eSide=#left
ENDDAT
"""


def test_struc_and_enum_of_the_data_list_are_written_back(station: object, tmp_path: Path) -> None:
    """A DECL of a STRUC or ENUM type does not compile without its type: the module's own
    definitions are written into the .dat, before the declarations (they were left out with
    an info line), and read again the same."""
    (tmp_path / "cell.dat").write_text(TYPED_DAT)
    result = _build(station, tmp_path, "cell.src", TYPED_SRC)
    assert not [d for d in result.diagnostics if d.kind == "ignored"]  # type: ignore[attr-defined]
    dat = result.files["cell.dat"].splitlines()  # type: ignore[attr-defined]
    assert dat[3:7] == [
        "GLOBAL STRUC ClampData INT nForce, REAL rOpen, BOOL bShut",
        "ENUM SideKind left, right",
        "DECL GLOBAL CLAMPDATA mClamp={nForce 2, rOpen 10.5, bShut FALSE}",
        "DECL SIDEKIND eSide=#left",
    ]
    assert not [line for line in _src(result) if "STRUC" in line or "ENUM" in line]
    again = tmp_path / "again"
    again.mkdir()
    for name, text in result.files.items():  # type: ignore[attr-defined]
        (again / name).write_text(text)
    types = [n.text for n in load_krl(again / "cell.src").program if isinstance(n, ir.Verbatim)]
    assert types == [
        "GLOBAL STRUC ClampData INT nForce, REAL rOpen, BOOL bShut",
        "ENUM SideKind left, right",
    ]


def test_other_posts_leave_type_definitions_out_with_a_warning(
    station: object, tmp_path: Path
) -> None:
    (tmp_path / "cell.dat").write_text(TYPED_DAT)
    result = _build(station, tmp_path, "cell.src", TYPED_SRC, "abb")
    warned = [d.span.line for d in result.diagnostics if d.kind == "ignored"]  # type: ignore[attr-defined]
    assert warned == [2, 3]
    errors = {d.span.line for d in result.diagnostics if d.severity == "error"}  # type: ignore[attr-defined]
    assert errors == {2, 3, 4, 5}  # the variables of those types and their uses, as before


# --------------------------------------------------------------------------------------------
# What a module written as its whole logic needs besides (found in the function modules)

PATH_SRC = """DEF cell(nI:IN)
DECL INT nI
DECL CHAR sText[20]
DECL INT nOffset
$VEL.CP = 0.2
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
LIN xPath[nI]
nOffset = 0
SWRITE(sText[], $DATE.HOUR, nOffset, "%d", $DATE.MINUTE)
END
"""

PATH_DAT = """DEFDAT cell PUBLIC
DECL E6POS xPath[2]
xPath[1]={X 500, Y 0, Z 400, A 0, B 90, C 0}
xPath[2]={X 500, Y 50, Z 400, A 0, B 90, C 0}
ENDDAT
"""


def test_the_data_a_run_time_motion_reads_is_declared_and_components_are_arguments(
    station: object, tmp_path: Path
) -> None:
    """``LIN xPath[nI]``: the written .dat declares xPath (it was left out, so the module did
    not compile); a call's argument may be a component (``$DATE.HOUR``: it stopped the post
    with call_argument)."""
    (tmp_path / "cell.dat").write_text(PATH_DAT)
    result = _build(station, tmp_path, "cell.src", PATH_SRC)
    lines = _src(result)
    assert 'SWRITE(sText[], $DATE.HOUR, nOffset, "%d", $DATE.MINUTE)' in lines
    dat = result.files["cell.dat"].splitlines()  # type: ignore[attr-defined]
    assert dat[3:6] == PATH_DAT.splitlines()[1:4]
