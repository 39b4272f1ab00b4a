"""``--assume`` and the cycle time per path on the command line: the range with its branch
choices in the summaries, the named path, the JSON report, and bad assumptions."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import olp
from olp.cli import main
from olp.passes.pipeline import BuildOptions
from olp.passes.timing.conditions import parse_assumptions

REPO = Path(__file__).resolve().parents[2]
CELL = str(REPO / "stations" / "kr6_milling_cell.yaml")

BRANCHES = """DEF br( )
  DECL INT n
  $VEL.CP = 0.2
  PTP {X 500, Y -400, Z 300, A 0, B 90, C 0}
  LIN {X 500, Y -400, Z 300, A 0, B 90, C 0}
  IF $IN[3] THEN
    LIN {X 500, Y -300, Z 300, A 0, B 90, C 0}
  ELSE
    LIN {X 500, Y -200, Z 300, A 0, B 90, C 0}
  ENDIF
  FOR n = 1 TO 3
    LIN {X 500, Y -300, Z 350, A 0, B 90, C 0}
    LIN {X 500, Y -300, Z 300, A 0, B 90, C 0}
  ENDFOR
  WHILE $IN[4]
    WAIT SEC 0.5
  ENDWHILE
END
"""


@pytest.fixture()
def source(tmp_path: Path) -> str:
    path = tmp_path / "br.src"
    path.write_text(BRANCHES)
    return str(path)


def _paths(source: str, *assume: str) -> tuple[float, float]:
    station = olp.load_station(CELL)
    options = BuildOptions(assume=parse_assumptions(assume))
    compiled = olp.compile(olp.parse(source, station=station).program, station, options)
    assert compiled.paths is not None
    assert compiled.paths.shortest is not None and compiled.paths.longest is not None
    return compiled.paths.shortest.seconds, compiled.paths.longest.seconds


def test_time_shows_the_range_and_the_choices_of_each_end(
    source: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["time", CELL, source]) == 0
    out = capsys.readouterr().out
    lo, hi = _paths(source)
    assert f"cycle time   {lo:.3f} .. {hi:.3f} s (shortest .. longest path" in out
    assert "paths        WHILE at br.src:15 counted as 1 pass" in out
    table = out[out.index("path      time s") :].splitlines()
    assert table[1].split() == ["shortest", f"{lo:.3f}", "IF", "at", "br.src:6", "taken"]
    assert table[2].split() == ["longest", f"{hi:.3f}", "IF", "at", "br.src:6", "not", "taken"]
    assert "a blend from one block into the next" in " ".join(out.split())
    assert "text total" in out


def test_assume_names_one_path(source: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["time", CELL, source, "--assume", "in3=false", "--assume", "loop:15=3"]) == 0
    out = capsys.readouterr().out
    named, same = _paths(source, "in3=false", "loop:15=3")
    assert named == same and named == pytest.approx(_paths(source, "in3=false")[1] + 1.0)
    assert f"cycle time   {named:.3f} s (the path --assume names" in out
    assert "assumed      in3=false, loop:15=3" in out
    assert "path      time s" not in out and "counted as 1 pass" not in out


def test_check_report_carries_the_paths(source: str, tmp_path: Path) -> None:
    report = tmp_path / "r.json"
    assert main(["check", CELL, source, "--report", str(report), "-q"]) == 0
    paths = json.loads(report.read_text())["paths"]
    lo, hi = _paths(source)
    assert (paths["shortest_s"], paths["longest_s"]) == (round(lo, 6), round(hi, 6))
    assert json.loads(report.read_text())["cycle_time_s"] == round(hi, 6)
    assert paths["shortest_choices"] == [
        {"source": f"{source}:6:3", "choice": "IF taken", "count": 1}
    ]
    assert paths["decided"] is False and paths["notes"][0].startswith("WHILE at br.src:15")


@pytest.mark.parametrize(
    ("assume", "words"),
    [
        ("in3=perhaps", "an input is true or false, got 'perhaps'"),
        ("loop:16=2", "no loop of the program is on line 16"),
        ("in7=true", "no condition of the program reads it"),
    ],
)
def test_a_bad_assumption_stops_with_a_usage_error(
    source: str, assume: str, words: str, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "out"
    assert main(["build", CELL, source, "-o", str(out), "--assume", assume]) == 2
    err = capsys.readouterr().err
    assert words in err and "Traceback" not in err
    assert not out.exists()


def test_time_help_explains_the_spelling(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["time", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "--assume NAME=VALUE" in out and "loop:12=5" in out and "in3=true" in out


JUMPS = """DEF jump( )
  $VEL.CP = 0.2
  PTP {X 500, Y -400, Z 300, A 0, B 90, C 0}
again:
  LIN {X 500, Y -300, Z 300, A 0, B 90, C 0}
  IF $IN[3] THEN
    GOTO again
  ENDIF
END
"""


def test_a_program_that_jumps_says_its_time_is_the_texts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "jump.src"
    path.write_text(JUMPS)
    assert main(["time", CELL, str(path), "-q"]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "(the text in order, each instruction once: olp does not time the paths of a " in out
    assert "program that jumps (GOTO at jump.src:7))" in out
    assert "path time s" not in out and "counts as an exact stop" not in out
