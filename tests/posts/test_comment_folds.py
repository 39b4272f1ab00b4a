"""Comments and pendant folds read from KRL, on every post (issue 15): KRL -> KRL writes them
back as they were (a fold as read, the source's INI fold once), the other posts write a plain
comment through their escaping and a fold as its title; user text never becomes code."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.frontends.csv import CsvOptions

REPO = Path(__file__).resolve().parents[2]
CELLS = {
    "kuka": REPO / "stations" / "kr6_milling_cell.yaml",
    "abb": REPO / "stations" / "abb_irb120_pick_cell.yaml",
    "ur": REPO / "stations" / "ur5e_screw_cell.yaml",
    "fanuc": REPO / "stations" / "fanuc_m20ia_weld_cell.yaml",
}
MARK = {"kuka": ";", "abb": "!", "ur": "#", "fanuc": "!"}
HOSTILE = 'q1\nq2 "x" ; {{ 7*7 }} {% if 1 %} %} */ MoveL p,v,fine,tool0; movel(p[0,0,0,0,0,0])'
FOLD = 'FOLD PTP P1 "q3" {{ x }} */ Vel=100 %;%{PE}%R 8.3.31,%MKUKATPBASIS,%CMOVE'


@pytest.fixture(scope="module")
def stations() -> dict[str, object]:
    return {post: olp.load_station(path) for post, path in CELLS.items()}


def _lines(result: olp.api.BuildResult) -> list[str]:
    return [
        line for text in result.files.values() for line in text.replace("\r\n", "\n").split("\n")
    ]


def _comment_line(post: str, line: str) -> bool:
    body = re.sub(r"^\s*\d+:\s*", "", line) if post == "fanuc" else line.strip()
    return body.startswith(MARK[post])


@pytest.mark.parametrize("post", list(CELLS))
def test_source_comments_and_folds_stay_comment_lines(
    stations: dict[str, object], post: str
) -> None:
    station = stations[post]
    home = ir.JointMove(target=ir.JointTarget(joints=station.robot.home))  # type: ignore[attr-defined]
    nodes = (
        ir.Comment(text=HOSTILE, from_source=True),
        ir.Comment(text=FOLD, fold="open", from_source=True),
        home,
        ir.Comment(text="ENDFOLD", fold="close", from_source=True),
    )
    program = ir.Program(name="T", instructions=nodes, source="t.src")
    result = olp.build(station, program, post=post)  # type: ignore[arg-type]
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    marked = [line for line in _lines(result) if re.search("q[123]|7\\*7|movel|MoveL p,", line)]
    assert marked and all(_comment_line(post, line) for line in marked), marked
    assert sum("q1" in line for line in marked) == 1 and sum("q2" in line for line in marked) == 1
    folds = [line for line in marked if "q3" in line]
    if post == "kuka":  # written back as read: the pendant shows its fold again
        ours = [line.strip() for line in _lines(result) if "q3" in line or line == ";ENDFOLD"]
        assert ours == [f";{FOLD}", ";ENDFOLD"]
    else:  # the title alone: no pendant record, no closing line
        assert len(folds) == 1 and "%{PE}" not in folds[0] and "PTP P1" in folds[0]
        assert not any("ENDFOLD" in line for line in _lines(result))


def test_a_source_comment_the_encoding_lacks_is_a_warning_a_made_one_an_error(
    stations: dict[str, object],
) -> None:
    station = stations["abb"]
    home = ir.JointMove(target=ir.JointTarget(joints=station.robot.home))  # type: ignore[attr-defined]
    read = ir.Program(name="T", instructions=(ir.Comment(text="señal", from_source=True), home))
    result = olp.build(station, read, post="abb")  # type: ignore[arg-type]
    assert result.ok and any("! se?al" in line for line in _lines(result))
    assert [d.kind for d in result.diagnostics if d.severity == "warning"].count("comment") == 1
    made = ir.Program(name="T", instructions=(ir.Comment(text="señal"), home))
    refused = olp.build(station, made, post="abb")  # type: ignore[arg-type]
    assert [d.kind for d in refused.diagnostics if d.severity == "error"] == ["comment"]


PENDANT = """DEF fold_ini( )
;FOLD INI;%{PE}
  ;FOLD BASISTECH INI
    GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )
    INTERRUPT ON 3
    BAS (#INITMOV,0 )
  ;ENDFOLD (BASISTECH INI)
;ENDFOLD (INI)
;FOLD PTP P1 Vel=50 % PDAT1;%{PE}%R 8.3.31,%MKUKATPBASIS,%CMOVE,%VPTP,%P 1:PTP, 2:P1
$BWDSTART=FALSE
$VEL_AXIS[1]=50
PTP {A1 10,A2 -90,A3 90,A4 0,A5 30,A6 0} ; approach
;ENDFOLD
END
"""
"""A pendant program of the author's own: the INI fold, one inline-form fold."""


def test_krl_to_krl_writes_the_source_ini_once_and_folds_around_their_motion(
    stations: dict[str, object], tmp_path: Path
) -> None:
    path = tmp_path / "fold_ini.src"
    path.write_text(PENDANT)
    result = olp.build(stations["kuka"], path, post="kuka")  # type: ignore[arg-type]
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    lines = [line.strip() for line in _lines(result)]
    assert sum(line.startswith("GLOBAL INTERRUPT DECL 3") for line in lines) == 1
    assert lines.count("BAS (#INITMOV,0 )") == 1 and lines.count(";FOLD INI;%{PE}") == 1
    start = lines.index(
        ";FOLD PTP P1 Vel=50 % PDAT1;%{PE}%R 8.3.31,%MKUKATPBASIS,%CMOVE,%VPTP,%P 1:PTP, 2:P1"
    )
    fold = lines[start : lines.index(";ENDFOLD", start) + 1]
    assert fold[1] == "$BWDSTART=FALSE" and "$VEL_AXIS[1] = 50" in fold
    assert fold[-3:] == [
        next(line for line in fold if line.startswith("PTP")),
        "; approach",
        ";ENDFOLD",
    ]
    other = olp.build(stations["kuka"], path, post="abb")  # type: ignore[arg-type]
    warned = [d.message for d in other.diagnostics if d.kind == "ignored"]
    assert len(warned) == 4 and not [d for d in other.diagnostics if d.severity == "error"]


TEMPLATE_INI = [
    ";FOLD INI;%{PE}",
    "  ;FOLD BASISTECH INI",
    "    GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )",
    "    INTERRUPT ON 3",
    "    BAS (#INITMOV,0 )",
    "  ;ENDFOLD (BASISTECH INI)",
    "  ;FOLD USER INI",
    "    ;Make your modifications here",
    "",
    "  ;ENDFOLD (USER INI)",
    ";ENDFOLD (INI)",
]
"""The KUKA post's template INI fold, line for line (posts/kuka/program.src.j2)."""

SETTINGS_MODULE = """DEF ToolChange( )
; no INI here: another module calls this one with its speeds set
$VEL.CP = 0.25
$TOOL = {X 0, Y 0, Z 150, A 0, B 0, C 0}
$BASE = {X 600, Y 0, Z 200, A 0, B 0, C 0}
PTP {A1 10,A2 -90,A3 90,A4 0,A5 30,A6 0}
LIN {X 100, Y 50, Z 120, A 0, B 90, C 0}
END
"""


def test_a_krl_program_without_an_ini_fold_is_written_without_one(
    stations: dict[str, object], tmp_path: Path
) -> None:
    """A KRL source without an INI fold gets none (issue 15: KRL -> KRL writes what the source
    had): the template's BAS(#INITMOV) would reset the speeds and accelerations of the module
    that calls this one. The motions' settings are still written before the first motion that
    uses them (olp writes them itself): tool, base and axis speeds before the PTP, the path
    speed before the LIN."""
    path = tmp_path / "ToolChange.src"
    path.write_text(SETTINGS_MODULE)
    result = olp.build(stations["kuka"], path, post="kuka")  # type: ignore[arg-type]
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    lines = [line.strip() for line in result.files["ToolChange.src"].splitlines()]
    assert not [line for line in lines if "INI" in line.upper() and line.startswith(";FOLD")]
    assert not [line for line in lines if line.startswith(("BAS", "INTERRUPT", "GLOBAL INT"))]
    ptp = next(k for k, line in enumerate(lines) if line.startswith("PTP"))
    lin = next(k for k, line in enumerate(lines) if line.startswith("LIN"))
    before_ptp = [line.split(" =")[0] for line in lines[:ptp] if line.startswith("$")]
    assert before_ptp == [
        "$BASE",
        "$TOOL",
        *(f"$VEL_AXIS[{i}]" for i in range(1, 7)),
        *(f"$ACC_AXIS[{i}]" for i in range(1, 7)),
    ]
    assert [line for line in lines[ptp:lin] if line.startswith("$")] == ["$VEL.CP = 0.25000"]


@pytest.mark.parametrize("source", ["examples/path_xyz.csv", "examples/points_to_program.py"])
def test_a_program_from_csv_or_python_gets_the_template_ini(
    stations: dict[str, object], source: str
) -> None:
    """Programs that are not KRL have no INI of their own: the post writes its template's,
    exactly as before."""
    options = CsvOptions(frame="table", orientation=(180.0, 0.0, 180.0))
    given = {"program_options": options} if source.endswith(".csv") else {}
    result = olp.build(stations["kuka"], REPO / source, post="kuka", **given)  # type: ignore[arg-type]
    (src,) = [text for name, text in result.files.items() if name.endswith(".src")]
    lines = src.split("\r\n")
    start = lines.index(";FOLD INI;%{PE}")
    assert lines[start : start + len(TEMPLATE_INI)] == TEMPLATE_INI


def test_a_program_built_in_python_gets_the_template_ini(stations: dict[str, object]) -> None:
    home = ir.JointMove(target=ir.JointTarget(joints=np.radians([10, -90, 90, 0, 30, 0])))
    program = ir.Program(name="built", instructions=(home,))
    result = olp.build(stations["kuka"], program, post="kuka")  # type: ignore[arg-type]
    lines = result.files["built.src"].split("\r\n")
    start = lines.index(";FOLD INI;%{PE}")
    assert lines[start : start + len(TEMPLATE_INI)] == TEMPLATE_INI
