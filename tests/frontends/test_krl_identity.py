"""KRL -> KRL keeps every statement (issue 15): a program the KUKA post writes reads again to
the same statements, in the same order, as its source gave.

Each program here is olp's own, in the style of the KR C4 backups where the gaps were found:
a module with parameters that other modules call, nested FOR loops with jumps and motion
settings, and signal names from ``$config.dat``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir
from olp.frontends.bundled import KrlOptions
from olp.frontends.krl import load_krl
from olp.ir_flow import leaves_and_blocks
from tests.krl_round_trip import statements

REPO = Path(__file__).resolve().parents[2]
STATION = REPO / "stations" / "kr6_milling_cell.yaml"


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(STATION)


def shape(program: object) -> list[str]:
    """Statements and blocks in order, declarations apart: kind, or the text of a kept line
    (comments and the template's INI lines apart: :func:`tests.krl_round_trip.statements`)."""
    out = []
    nodes = leaves_and_blocks(program.instructions)  # type: ignore[attr-defined]
    for node in statements(nodes):
        if node.kind == "verbatim":
            out.append(node.text.upper().replace(" ", ""))
        elif node.kind != "declare":
            out.append(node.kind)
    return out


def build(station: object, tmp_path: Path, text: str, name: str = "cell.src", **options: object):  # type: ignore[no-untyped-def]
    source = tmp_path / "in" / name
    source.parent.mkdir(exist_ok=True)
    source.write_text(text)
    krl = KrlOptions(**options)  # type: ignore[arg-type]
    return olp.build(station, source, post="kuka", program_options=krl, collisions=None)


def read_again(result: object, tmp_path: Path, **options: object) -> object:
    """The written ``.src`` (and ``.dat``) read again by the KRL frontend."""
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    for name, text in result.files.items():  # type: ignore[attr-defined]
        (out / name).write_text(text)
    (src,) = [n for n in result.files if n.lower().endswith(".src")]  # type: ignore[attr-defined]
    return load_krl(out / src, **options).program  # type: ignore[arg-type]


# --------------------------------------------------------------------------------------------
# Nested FOR loops, a jump back into the inner one, $APO.CDIS written inside the loop

STACKER = """DEF stacker( )
DECL INT nRow
DECL INT nCol
DECL INT iAx
DECL E6POS pDrop
$VEL.CP = 0.5
$APO.CDIS = 20
$TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}
$BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
FOR nRow = 1 TO 2
  FOR nCol = 1 TO 3
    retry:
    pDrop = {X 100, Y -100, Z 100, A 0, B 90, C 0}
    pDrop.Y = pDrop.Y + 40 * nCol
    FOR iAx = 1 TO 6
      $VEL_AXIS[iAx] = 40
    ENDFOR
    PTP pDrop
    LIN {X 120, Y -60, Z 80, A 0, B 90, C 0} C_DIS
    LIN {X 120, Y -60, Z 40, A 0, B 90, C 0}
    IF $IN[4] THEN
      GOTO retry
    ENDIF
  ENDFOR
ENDFOR
END
"""


def test_nested_loops_with_a_jump_back_read_again_the_same(station: object, tmp_path: Path) -> None:
    """The post writes ``$APO.CDIS`` inside the loop, before the C_DIS motion that uses it; read
    again, the exact-stop PTP before it does not depend on it (it stopped the reading with
    "$APO.CDIS differs between the paths of the FOR")."""
    result = build(station, tmp_path, STACKER)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    again = read_again(result, tmp_path)
    assert shape(again) == shape(result.compiled.program)  # type: ignore[attr-defined]


BRANCHED_CDIS = """DEF cell( )
$VEL.CP = 0.5
$TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}
$BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
IF $IN[2] THEN
  $APO.CDIS = 5
ELSE
  $APO.CDIS = 10
ENDIF
LIN {X 100, Y -100, Z 100, A 0, B 90, C 0}
LIN {X 120, Y -60, Z 80, A 0, B 90, C 0} C_DIS
END
"""


def test_a_c_dis_motion_after_paths_that_disagree_runs_with_the_controllers_distance(
    tmp_path: Path,
) -> None:
    """Paths that disagree on ``$APO.CDIS`` (each keeps its line as written): the exact stop
    after them runs with olp's settings, the next motion that approximates with it runs with
    the distance the controller holds (it used to stop the reading at its line: the program is
    valid, and the controller approximates with whichever the path set)."""
    path = tmp_path / "cell.src"
    path.write_text(BRANCHED_CDIS)
    program = load_krl(path).program
    nodes = list(leaves_and_blocks(program.instructions))
    kept = [(n.text, n.span.line) for n in nodes if isinstance(n, ir.Verbatim)]
    assert kept == [("$APO.CDIS = 5", 7), ("$APO.CDIS = 10", 9)]
    exact, approximated = nodes[-2:]
    assert isinstance(exact, ir.LinearMove) and exact.span.line == 11
    assert isinstance(approximated, ir.RuntimeMove) and approximated.controller_settings
    assert approximated.span.line == 12 and "$APO.CDIS differs" in approximated.reason


# --------------------------------------------------------------------------------------------
# A program with parameters of its own: a module other modules call

GRIP_MODULE = """&ACCESS RVP
DEF SetGrip(nSlot:IN, bClose:IN, rWait:IN, nResult:OUT)
DECL INT nSlot
DECL BOOL bClose
DECL REAL rWait
DECL INT nResult
DECL INT nTry
nTry = 0
IF bClose THEN
  $OUT[nSlot] = TRUE
ELSE
  $OUT[nSlot] = FALSE
ENDIF
WAIT SEC 0.2
nResult = nSlot * 10 + nTry
END
"""


def test_the_programs_parameters_are_in_the_ir(tmp_path: Path) -> None:
    path = tmp_path / "SetGrip.src"
    path.write_text(GRIP_MODULE)
    program = load_krl(path).program
    params = [(p.name, p.type_name, p.direction, p.span.line) for p in program.params]
    assert params == [
        ("nSlot", "INT", "in", 3),
        ("bClose", "BOOL", "in", 4),
        ("rWait", "REAL", "in", 5),
        ("nResult", "INT", "out", 6),
    ]
    declared = [n.name for n in program.instructions if n.kind == "declare"]
    assert declared == ["nTry"]  # the parameters' DECL lines type them, not locals


def test_the_krl_post_writes_the_programs_parameters(station: object, tmp_path: Path) -> None:
    result = build(station, tmp_path, GRIP_MODULE, "SetGrip.src")
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    assert not [d for d in result.diagnostics if "parameters" in d.message]
    lines = result.files["SetGrip.src"].splitlines()
    assert lines[2] == "DEF SetGrip(nSlot:IN, bClose:IN, rWait:IN, nResult:OUT)"
    assert lines[4:9] == [
        "DECL INT nSlot",
        "DECL BOOL bClose",
        "DECL REAL rWait",
        "DECL INT nResult",
        "DECL INT nTry",
    ]
    again = read_again(result, tmp_path)
    written = [(p.name, p.type_name, p.direction) for p in again.params]  # type: ignore[attr-defined]
    assert written == [
        ("nSlot", "INT", "in"),
        ("bClose", "BOOL", "in"),
        ("rWait", "REAL", "in"),
        ("nResult", "INT", "out"),
    ]
    assert shape(again) == shape(result.compiled.program)  # type: ignore[attr-defined]


def test_an_array_parameter_stays_an_array(station: object, tmp_path: Path) -> None:
    """``DEF Show(sText[]:IN)`` with ``DECL CHAR sText[]``: the open extent is kept in the IR
    and written back (it was written ``sText:IN`` and ``DECL CHAR sText``: a scalar)."""
    text = "DEF Show(sText[]:IN, nLen:IN)\nDECL CHAR sText[]\nINT nLen\nnLen = 2\nEND\n"
    result = build(station, tmp_path, text, "Show.src")
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    (text_param, _) = result.compiled.program.params  # type: ignore[attr-defined]
    assert text_param.dims == (None,)
    lines = result.files["Show.src"].splitlines()
    assert lines[2] == "DEF Show(sText[]:IN, nLen:IN)"
    assert lines[4:6] == ["DECL CHAR sText[]", "DECL INT nLen"]


@pytest.mark.parametrize("post", ["abb", "ur", "fanuc"])
def test_other_posts_refuse_a_program_with_parameters(
    station: object, tmp_path: Path, post: str
) -> None:
    """RAPID, URScript and LS programs are entry points started without arguments (see each
    post's ``PROGRAM_PARAMS``): a located error naming the parameters, nothing written."""
    source = tmp_path / "SetGrip.src"
    source.write_text(GRIP_MODULE)
    result = olp.build(station, source, post=post, collisions=None)  # type: ignore[arg-type]
    (error,) = [d for d in result.diagnostics if d.kind == "program_params"]
    assert error.severity == "error" and not result.files
    assert error.span is not None and (error.span.file, error.span.line) == (str(source), 3)
    assert "(nSlot, bClose, rWait, nResult)" in error.message


def test_a_copied_kuka_folder_without_the_flag_refuses_them(
    station: object, tmp_path: Path
) -> None:
    """A template folder copied before olp wrote program parameters would write ``DEF
    SetGrip( )``: without ``program_params: true`` the post refuses the program."""
    import shutil

    folder = tmp_path / "my_kuka"
    shutil.copytree(REPO / "posts" / "kuka", folder)
    manifest = folder / "post.yaml"
    manifest.write_text(manifest.read_text().replace("\nprogram_params: true", ""))
    source = tmp_path / "SetGrip.src"
    source.write_text(GRIP_MODULE)
    result = olp.build(station, source, post=str(folder), collisions=None)  # type: ignore[arg-type]
    (error,) = [d for d in result.diagnostics if d.kind == "program_params"]
    assert "program_params: true" in error.message and not result.files


# --------------------------------------------------------------------------------------------
# Signal names from $config.dat

CONFIG = """DEFDAT $CONFIG
SIGNAL InCintaLlena $IN[5]
SIGNAL InPinza $IN[6]
SIGNAL OutVacio $OUT[2]
ENDDAT
"""

CONVEYOR = """DEF conveyor( )
SIGNAL sLocal $IN[7]
$VEL.CP = 0.5
$TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}
$BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
WAIT FOR InPinza
IF InCintaLlena AND NOT sLocal THEN
  OutVacio = TRUE
  LIN {X 100, Y -100, Z 100, A 0, B 90, C 0}
ENDIF
WAIT FOR NOT sLocal
OutVacio = FALSE
$OUT[3] = TRUE
END
"""


def _conveyor(station: object, tmp_path: Path, post: str = "kuka") -> object:
    config = tmp_path / "$config.dat"
    config.write_text(CONFIG)
    source = tmp_path / "conveyor.src"
    source.write_text(CONVEYOR)
    options = KrlOptions(config_dat=config)
    return olp.build(station, source, post=post, program_options=options, collisions=None)


def test_the_krl_post_writes_signal_names_where_the_source_used_them(
    station: object, tmp_path: Path
) -> None:
    """Names declared in ``$config.dat`` are written as the user wrote them; a SIGNAL of the
    module itself (not written back) and a bit read by number are written by number."""
    result = _conveyor(station, tmp_path)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]  # type: ignore[attr-defined]
    lines = result.files["conveyor.src"].splitlines()  # type: ignore[attr-defined]
    assert "WAIT FOR InPinza" in lines
    assert "IF InCintaLlena AND NOT $IN[7] THEN" in lines
    assert lines.count("OutVacio = TRUE") == lines.count("OutVacio = FALSE") == 1
    assert "WAIT FOR NOT $IN[7]" in lines and "$OUT[3] = TRUE" in lines
    again = read_again(result, tmp_path, config_dat=tmp_path / "$config.dat")
    assert shape(again) == shape(result.compiled.program)  # type: ignore[attr-defined]


@pytest.mark.parametrize(("post", "written"), [("abb", "di5"), ("ur", "get_digital_in(5)")])
def test_other_posts_write_the_signals_by_number(
    station: object, tmp_path: Path, post: str, written: str
) -> None:
    result = _conveyor(station, tmp_path, post)
    text = "".join(result.files.values())  # type: ignore[attr-defined]
    assert written in text and "InCintaLlena" not in text and "OutVacio" not in text
