"""Module data in the IR (issue 15): the data-list variables a KRL program's statements use are
declared in the IR (``scope="module"`` for the module's own ``.dat``, ``"external"`` for another
module's GLOBAL data or ``$config.dat``), so every post's text declares what it uses.

Before, ``nCount = nCount + 1`` with ``DECL INT nCount=0`` in the ``.dat`` came out of the KUKA
post with an empty ``.dat`` (a module that does not compile, or that finds another module's
global of that name), and out of the RAPID and URScript posts with the name used undeclared.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import olp
from olp import ir
from olp.frontends.bundled import KrlOptions
from olp.frontends.krl import load_krl
from olp.ir_flow import leaves_and_blocks
from olp.posts.kuka_flow import krl_expr

REPO = Path(__file__).resolve().parents[2]
STATION = REPO / "stations" / "kr6_milling_cell.yaml"

SRC = """DEF count_parts( )
DECL INT nLocal
PTP {X 500, Y -400, Z 300, A 0, B 90, C 0}
$VEL.CP = 0.2
nCount = nCount + 1
nLocal = aSlots[2]
IF nCount > nLimit THEN
  LIN XP1
  sLast[] = "done"
ENDIF
END
"""

DAT = """DEFDAT count_parts PUBLIC
DECL INT nCount=0
DECL INT nLimit=3
DECL INT nUnused=7
DECL INT aSlots[3]
aSlots[2]=5
DECL CHAR sLast[8]
sLast[]="none"
DECL E6POS XP1={X 500.0,Y -300.0,Z 300.0,A 0.0,B 90.0,C 0.0,S 2,T 2,E1 0.0}
ENDDAT
"""

SHARED = """DEFDAT cellvars PUBLIC
DECL GLOBAL INT nShift=1
ENDDAT
"""


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(STATION)


def write(folder: Path, src: str = SRC, dat: str = DAT) -> Path:
    (folder / "count_parts.dat").write_text(dat)
    path = folder / "count_parts.src"
    path.write_text(src)
    return path


def spelled(decl: ir.Declare) -> tuple[str, tuple[tuple[str, str], ...]]:
    """A declaration's value and elements as KRL text (spans apart)."""
    value = "" if decl.value is None else krl_expr(decl.value)
    elements = tuple(
        (",".join("" if i is None else krl_expr(i) for i in at), krl_expr(v))
        for at, v in decl.elements
    )
    return value, elements


def declares(program: ir.Program) -> dict[str, ir.Declare]:
    return {n.name: n for n in leaves_and_blocks(program.instructions) if isinstance(n, ir.Declare)}


def build(station: object, path: Path, post: str, **options: object) -> olp.api.BuildResult:
    return olp.build(
        station,
        path,
        post=post,
        collisions=None,
        program_options=KrlOptions(**options),  # type: ignore[arg-type]
    )


def test_the_dat_variables_the_statements_use_are_module_data(tmp_path: Path) -> None:
    program = load_krl(write(tmp_path)).program
    found = declares(program)
    # Used by statements: declared with the data list's value, elements and GLOBAL flag.
    assert {k: v.scope for k, v in found.items()} == {
        "nCount": "module",
        "nLimit": "module",
        "aSlots": "module",
        "sLast": "module",
        "nLocal": "routine",
    }
    assert spelled(found["nCount"]) == ("0", ())
    assert spelled(found["aSlots"]) == ("", (("2", "5"),))
    assert spelled(found["sLast"]) == ("", (("", '"none"'),))
    assert found["nCount"].span.file.endswith("count_parts.dat")
    # Not used by a statement: nUnused, and XP1, whose value is in the motion.
    assert "nUnused" not in found and "XP1" not in found


def test_krl_writes_module_data_into_its_dat(station: object, tmp_path: Path) -> None:
    result = build(station, write(tmp_path), "kuka")
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    src, dat = result.files["count_parts.src"], result.files["count_parts.dat"]
    assert "DECL INT nLocal" in src and "nCount" not in src.split("PTP")[0]
    for line in ("DECL INT nCount=0", "DECL INT nLimit=3", "DECL INT aSlots[3]", "aSlots[2]=5"):
        assert line + "\r\n" in dat
    assert 'DECL CHAR sLast[8]\r\nsLast[]="none"\r\n' in dat
    # Read back, the written module declares the same data with the same values.
    out = tmp_path / "out"
    out.mkdir()
    for name, text in result.files.items():
        (out / name).write_bytes(text.encode("ascii"))
    again = declares(load_krl(out / "count_parts.src").program)
    first = declares(load_krl(tmp_path / "count_parts.src").program)
    assert again.keys() == first.keys()
    for name, decl in first.items():
        assert (spelled(again[name]), again[name].scope) == (spelled(decl), decl.scope)


def test_another_modules_variable_is_referred_to_not_declared(
    station: object, tmp_path: Path
) -> None:
    shared = tmp_path / "cellvars.dat"
    shared.write_text(SHARED)
    src = SRC.replace("nLocal = aSlots[2]", "nLocal = nShift")
    path = write(tmp_path, src)
    program = load_krl(path, data_lists=[shared]).program
    external = declares(program)["nShift"]
    assert (external.scope, external.value, external.exported) == ("external", None, True)
    kuka = build(station, path, "kuka", data_lists=[shared])
    assert kuka.ok
    assert "nShift" not in kuka.files["count_parts.dat"]
    assert "nLocal = nShift" in kuka.files["count_parts.src"]
    for post in ("abb", "ur", "fanuc"):
        other = build(station, path, post, data_lists=[shared])
        errors = [d for d in other.diagnostics if d.severity == "error"]
        assert not other.files, post
        assert any(
            "nShift is declared in another module's data list (cellvars.dat:2)" in e.message
            for e in errors
        ), (post, [d.format() for d in errors])


def test_rapid_keeps_module_data_persistent(station: object, tmp_path: Path) -> None:
    result = build(station, write(tmp_path), "abb")
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    (text,) = [t for n, t in result.files.items() if n.endswith(".mod")]
    module_part = text.split("PROC")[0]
    for line in (
        "PERS num nCount := 0;",
        "PERS num nLimit := 3;",
        "PERS num aSlots{3} := [0, 5, 0];",
        'PERS string sLast := "none";',
    ):
        assert line in module_part
    assert "VAR num nLocal;" in text.split("PROC")[1]


def test_urscript_warns_that_assigned_module_data_restarts(station: object, tmp_path: Path) -> None:
    result = build(station, write(tmp_path), "ur")
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    (text,) = result.files.values()
    for line in ("global nCount = 0", "global aSlots = [0, 5, 0]", 'global sLast = "none"'):
        assert line in text
    warned = sorted(d.message.split()[0] for d in result.diagnostics if d.kind == "module_data")
    assert warned == ["nCount", "sLast"]  # assigned; nLimit and aSlots are only read


def test_ls_leaves_module_data_registers_to_the_controller(station: object, tmp_path: Path) -> None:
    src = SRC.replace('  sLast[] = "done"\n', "").replace("nLocal = aSlots[2]", "nLocal = 2")
    result = build(station, write(tmp_path, src), "fanuc")
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    (text,) = [t for n, t in result.files.items() if n.lower().endswith(".ls")]
    assert "R[101:nCount]=R[101:nCount]+1" in text
    assert "R[101:nCount]=0" not in text and "R[102:nLimit]=3" not in text
    notes = [d for d in result.diagnostics if d.kind == "module_data"]
    assert [d.message.split()[0] for d in notes] == ["nCount", "nLimit"]
    assert "R[101:nCount]" in notes[0].message and "= 0" in notes[0].message


def test_a_krl_folder_copied_before_module_data_stops(station: object, tmp_path: Path) -> None:
    folder = tmp_path / "my_kuka"
    shutil.copytree(REPO / "posts" / "kuka", folder)
    manifest = folder / "post.yaml"
    manifest.write_text(manifest.read_text().replace("module_data: true", "module_data: false"))
    result = build(station, write(tmp_path), str(folder))
    errors = [d for d in result.diagnostics if d.kind == "module_data"]
    assert not result.files and errors and "module_data: true" in errors[0].message


def test_a_name_in_a_kept_line_is_declared_too(station: object, tmp_path: Path) -> None:
    src = SRC.replace("nLocal = aSlots[2]", "MY_LOG(nUnused) ; an external routine")
    result = build(station, write(tmp_path, src), "kuka")
    assert result.ok
    assert "DECL INT nUnused=7" in result.files["count_parts.dat"]
