"""One table of bad input across stations, programs and the command line (issue 10): each row
is the files a careless or hostile user gives, the command, the exit code olp must end with,
and what its message must say, located at ``file:line:column`` where the input is a file.

Exit codes: 2 for bad input or usage (nothing is built), 1 for a program that cannot run on the
station (nothing is written). No row may end in a traceback: ``main`` returning at all, with the
expected code and message, is the check; the output folder must stay absent in every row.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from olp.cli import main

REPO = Path(__file__).resolve().parents[1]
CELL = (REPO / "stations" / "kr6_milling_cell.yaml").read_text()
ROBOT = "robot:\n  model: kuka/kr6_r900_sixx\n"
TOOL = ROBOT + "tools:\n  - {name: t, mass_kg: %s}\n"
KRL_HEAD = "DEF prog( )\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 45,A6 0}\n"
CSV_HEAD = "x,y,z\n"
DSL_HEAD = "from olp.dsl import *\nrobot.MoveJ(robot.JointsHome())\n"


@dataclass(frozen=True)
class Case:
    """Files (name -> text or bytes) written to a fresh folder, the ``olp`` arguments (``{d}`` is
    that folder), the exit code and a regex the printed messages must match."""

    files: dict[str, str | bytes]
    argv: list[str]
    code: int
    message: str
    extra: dict[str, str] = field(default_factory=dict)


def station(text: str | bytes, line: int, message: str) -> Case:
    """A bad station: ``olp check`` exits 2 with the error at ``cell.yaml:line``."""
    return Case(
        {"cell.yaml": text, "prog.src": KRL_HEAD + "END\n"},
        ["check", "{d}/cell.yaml", "{d}/prog.src"],
        2,
        rf"cell\.yaml:{line}:\d+: station error: .*{message}",
    )


def krl(body: str | bytes, code: int, message: str, *extra: str) -> Case:
    text = (KRL_HEAD + body + "\nEND\n") if isinstance(body, str) else body
    return Case(
        {"cell.yaml": CELL, "prog.src": text},
        ["build", "{d}/cell.yaml", "{d}/prog.src", "-o", "{d}/out", *extra],
        code,
        message,
    )


def csv(text: str | bytes, code: int, message: str, *extra: str) -> Case:
    return Case(
        {"cell.yaml": CELL, "path.csv": text},
        ["build", "{d}/cell.yaml", "{d}/path.csv", "-o", "{d}/out", "--frame", "table", *extra],
        code,
        message,
    )


def dsl(body: str, code: int, message: str, *extra: str) -> Case:
    return Case(
        {"cell.yaml": CELL, "prog.py": DSL_HEAD + body},
        ["build", "{d}/cell.yaml", "{d}/prog.py", "-o", "{d}/out", *extra],
        code,
        message,
    )


def cli(argv: list[str], code: int, message: str, **files: str) -> Case:
    base = {"cell.yaml": CELL, "prog.src": KRL_HEAD + "END\n"}
    return Case({**base, **files}, argv, code, message)


BUILD = ["build", "{d}/cell.yaml", "{d}/prog.src"]

CASES: dict[str, Case] = {
    # ---- stations ---------------------------------------------------------------------------
    "station: 400-digit integer": station(TOOL % ("9" * 400), 4, "more than 100 digits"),
    "station: not UTF-8": station(ROBOT.encode() + b"name: \xff\n", 3, "not UTF-8"),
    "station: control character": station(ROBOT + "name: a\x01b\n", 3, "U\\+0001"),
    "station: python tag": station(
        ROBOT + "name: !!python/name:os.system x\n", 3, "unsupported tag !!python/name"
    ),
    "station: unknown tag": station(ROBOT + "name: !foo x\n", 3, "unsupported tag !foo"),
    "station: !!int on text": station(TOOL % '!!int "abc"', 4, "not a whole number"),
    "station: bare =": station(TOOL % "=", 4, "expected a number .*got text '='"),
    "station: date-like value": station(TOOL % "2024-01-01", 4, "expected a number"),
    "station: recursive alias": station(ROBOT + "tools: &a\n  - *a\n", 4, "contains itself"),
    "station: alias bomb": station(
        ROBOT
        + "description:\n  - &a [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]\n"
        + "".join(
            f"  - &{chr(98 + k)} [{', '.join([f'*{chr(97 + k)}'] * 10)}]\n" for k in range(6)
        ),
        8,
        "expands to more than",
    ),
    "station: duplicate key": station(
        ROBOT + "robot:\n  model: abb/irb120\n", 3, "duplicate key 'robot'"
    ),
    "station: 1e308 mm": station(ROBOT + "  base: {xyz: [1e308, 0, 0]}\n", 3, "out of range"),
    "station: complex key": station(ROBOT + "? [a, b]\n: 1\n", 3, "'\\[a, b\\]'"),
    "station: unknown key": station(ROBOT + "robto: 1\n", 3, "robto"),
    "station: negative mass": station(TOOL % "-1", 4, "mass"),
    "station: mesh outside its folder": station(
        ROBOT + "parts:\n  - {name: p, geometry: [{mesh: {file: /etc/passwd}}]}\n",
        4,
        "outside",
    ),
    "station: mesh from /proc": station(
        ROBOT
        + "parts:\n  - {name: p, geometry: [{mesh: {file: ../../../../proc/self/environ}}]}\n",
        4,
        "outside|proc",
    ),
    "station: unknown robot": station("robot:\n  model: kuka/kr9000\n", 2, "kr9000"),
    "station: robot as a path": station(
        "robot:\n  model: ../../etc/passwd\n", 2, "unknown robot model '../../etc/passwd'"
    ),
    "station: empty file": station("", 1, "robot"),
    "station: joint ranges of a million degrees": station(
        ROBOT
        + "  limits:\n    position_deg: [[-170, 170], [-190, 45], [-120, 156], [-1e6, 1e6],"
        + " [-120, 120], [-1e6, 1e6]]\n",
        4,
        "combinations of turns",
    ),
    # ---- KRL programs -----------------------------------------------------------------------
    "krl: syntax error": krl("LIN {X 500,Y 0 Z 500}", 2, r"prog\.src:3:16: parse error"),
    "krl: unknown statement": krl("FOO BAR", 2, r"prog\.src:3:5: parse error"),
    "krl: no END": krl(KRL_HEAD.encode(), 2, r"prog\.src:\d+:\d+: parse error"),
    "krl: not KRL, a bare name": krl(
        "TODO", 2, r"prog\.src:3:1: parse error\[invalid_krl\]: a bare name is not a KRL"
    ),
    "krl: NUL byte": krl("LIN {X 500,\x00Y 0,Z 500}", 2, r"prog\.src:3:\d+: parse error"),
    "krl: huge line": krl("LIN {X " + "9" * 300_000 + "x}", 2, r"prog\.src:3:\d+: parse error"),
    "krl: a 300-digit target": krl(
        "LIN {X " + "9" * 300 + ",Y 0,Z 500,A 0,B 90,C 0}", 1, r"prog\.src:3:1: error\[unreach"
    ),
    "krl: target 1e40 mm away": krl(
        "LIN {X 1E40,Y 0,Z 500,A 0,B 90,C 0}", 1, r"prog\.src:3:1: error\["
    ),
    "krl: speed that prints as zero": krl(
        "$VEL.CP = 0.000004\nLIN {X 500,Y 0,Z 500,A 0,B 90,C 0}", 1, r"prog\.src:4:.*number"
    ),
    "krl: dwell of 1E300 s": krl("WAIT SEC 1E300", 1, r"prog\.src:3:1: error\[number\]"),
    "krl: tiny joint speed": krl(
        "$VEL_AXIS[1] = 0.000001\nPTP {A1 10,A2 -90,A3 90,A4 0,A5 45,A6 0}",
        1,
        r"prog\.src:\d+:\d+: error",
    ),
    # every file where the controller would find it given (without them: a run-time motion)
    "krl: unknown point": Case(
        {
            "cell.yaml": CELL,
            "prog.src": KRL_HEAD + "PTP XNOWHERE\nEND\n",
            "prog.dat": "DEFDAT prog\nENDDAT\n",
            "config.dat": "DEFDAT $CONFIG\nENDDAT\n",
        },
        [
            *("build", "{d}/cell.yaml", "{d}/prog.src", "-o", "{d}/out"),
            *("--config-dat", "{d}/config.dat"),
        ],
        2,
        r"prog\.src:3:\d+: .*XNOWHERE",
    ),
    "krl: S out of range": krl(
        "PTP {X 500,Y 0,Z 500,A 0,B 90,C 0,S 99,T 0}", 2, r"prog\.src:3:\d+: .*S"
    ),
    "krl: joint limit": krl(
        "PTP {A1 170.00001,A2 -90,A3 90,A4 0,A5 45,A6 0}", 1, r"prog\.src:3:1: .*170\.00001"
    ),
    "krl: output 0": krl("$OUT[0] = TRUE", 2, r"prog\.src:3:6: parse error: the index of \$OUT"),
    "krl: output 5000": krl("$OUT[5000] = TRUE", 1, r"prog\.src:3:1: error\[io_range\]"),
    # ---- CSV toolpaths ----------------------------------------------------------------------
    "csv: more cells than the header": csv(
        CSV_HEAD + "400,5,0,500\n", 2, r"path\.csv:2:\d+: parse error: .*3 cells"
    ),
    "csv: fewer cells than the header": csv(CSV_HEAD + "400,5\n", 2, r"path\.csv:2:\d+:"),
    "csv: ragged row later": csv(
        CSV_HEAD + "400,5,500\n400,6,500,7\n", 2, r"path\.csv:3:\d+: parse error"
    ),
    "csv: empty file": csv("", 2, r"path\.csv:1:1: parse error"),
    "csv: header only": csv(CSV_HEAD, 2, r"path\.csv:\d+:\d+: parse error"),
    "csv: text in a number cell": csv(CSV_HEAD + "400,abc,500\n", 2, r"path\.csv:2:\d+: .*numbers"),
    "csv: 1e309": csv(CSV_HEAD + "400,1e309,500\n", 2, r"path\.csv:2:\d+: parse error"),
    "csv: nan": csv(CSV_HEAD + "400,nan,500\n", 2, r"path\.csv:2:\d+: parse error"),
    "csv: a 20 MB line": csv(
        CSV_HEAD + "400,5," + "9" * 2_000_000 + "x\n", 2, r"path\.csv:2:\d+: parse error"
    ),
    "csv: far target": csv(CSV_HEAD + "400,0,500\n400,0,1e40\n", 1, r"path\.csv:3:\d+: error"),
    "csv: known header over another column": csv(
        "x,y,z,rz\n400,0,500,1\n", 2, r"path\.csv:1:\d+: parse error"
    ),
    # ---- Python programs --------------------------------------------------------------------
    "dsl: the program's own exception": dsl(
        "raise RuntimeError('boom')\n", 2, r"prog\.py:3:\d+: .*RuntimeError: boom"
    ),
    "dsl: os._exit(0)": dsl("import os\nos._exit(0)\n", 2, r"prog\.py:4:\d+: .*os\._exit"),
    "dsl: timeout": dsl(
        "while True:\n    pass\n",
        2,
        r"prog\.py:[34]:\d+: .*did not finish within 1 s",
        "--timeout",
        "1",
    ),
    "dsl: syntax error": dsl("robot.MoveJ(\n", 2, r"prog\.py:\d+:\d+: "),
    "dsl: call with a statement": dsl(
        "robot.RunInstruction('Grip(1;MoveAbsJ x)')\n",
        1,
        r"prog\.py:3:\d+: error\[call_argument\]",
        "--post",
        "abb",
    ),
    "dsl: pause of 1e308 ms": dsl("robot.Pause(1e308)\n", 1, r"prog\.py:3:\d+: error\[number\]"),
    # ---- the command line -------------------------------------------------------------------
    "cli: unknown post": cli([*BUILD, "--post", "nope"], 2, "unknown post 'nope'"),
    "cli: a bare name is not a local folder": cli(
        [*BUILD, "--post", "kuka_line3", "-o", "{d}/out"],
        2,
        r"name it as a path: \./kuka_line3",
        **{"kuka_line3/post.yaml": "name: x\n"},
    ),
    "cli: post folder without post.yaml": cli(
        [*BUILD, "--post", "{d}/empty/"], 2, "has no post.yaml"
    ),
    "cli: -o is a file": cli([*BUILD, "-o", "{d}/prog.src"], 2, "is a file, not a folder"),
    "cli: -o is the working folder": cli([*BUILD, "-o", "."], 2, "as a whole"),
    "cli: --report is a folder": cli(
        [*BUILD, "-o", "{d}/out", "--report", "{d}"], 2, "--report .*: is a folder"
    ),
    "cli: --sarif is a folder": cli(
        ["check", "{d}/cell.yaml", "{d}/prog.src", "--sarif", "{d}"], 2, "is a folder"
    ),
    "cli: --trajectory is a folder": cli(
        ["time", "{d}/cell.yaml", "{d}/prog.src", "--trajectory", "{d}"], 2, "is a folder"
    ),
    "cli: two options, one file": cli(
        [*BUILD, "--report", "{d}/r.json", "--sarif", "{d}/r.json"], 2, "name the same path"
    ),
    "cli: station is a folder": cli(["check", "{d}", "{d}/prog.src"], 2, "is a folder, not"),
    "cli: program missing": cli(["check", "{d}/cell.yaml", "{d}/nope.src"], 2, "no such file"),
    "cli: unknown program type": cli(
        ["check", "{d}/cell.yaml", "{d}/prog.txt"], 2, "unknown program type", **{"prog.txt": "x"}
    ),
    "cli: --set without =": cli([*BUILD, "--set", "SPEED"], 2, "NAME=VALUE"),
    "cli: --set on a KRL program": cli([*BUILD, "--set", "A=1"], 2, "Python programs"),
    "cli: negative clearance": cli([*BUILD, "--clearance", "-1"], 2, "clearance"),
    "cli: NaN clearance": cli([*BUILD, "--clearance", "nan"], 2, "clearance"),
    "cli: zero timeout": cli(
        ["check", "{d}/cell.yaml", "{d}/p.py", "--timeout", "0"],
        2,
        "--timeout",
        **{"p.py": DSL_HEAD},
    ),
    "cli: bad orientation": cli(
        ["check", "{d}/cell.yaml", "{d}/p.csv", "--orientation", "1,2"],
        2,
        "--orientation",
        **{"p.csv": CSV_HEAD + "400,0,500\n"},
    ),
    "cli: bad sweep": cli(
        ["time", "{d}/cell.yaml", "{d}/prog.src", "--sweep-linear", "50,abc"], 2, "sweep-linear"
    ),
    "cli: bad dt": cli(["time", "{d}/cell.yaml", "{d}/prog.src", "--dt", "0"], 2, "--dt"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_bad_input(
    name: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    case = CASES[name]
    for file, content in case.files.items():
        path = tmp_path / file
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)
    (tmp_path / "empty").mkdir()
    monkeypatch.chdir(tmp_path)
    code = main([arg.replace("{d}", str(tmp_path)) for arg in case.argv])
    printed = capsys.readouterr()
    text = printed.err + printed.out
    assert code == case.code, text[-2000:]
    assert re.search(case.message, text), text[-2000:]
    assert "Traceback" not in text
    assert not (tmp_path / "out").exists()
    assert max(len(line) for line in text.splitlines() or [""]) < 2000  # nothing echoed whole


def test_the_table_covers_stations_programs_and_the_command_line() -> None:
    kinds = {name.split(":")[0] for name in CASES}
    assert kinds == {"station", "krl", "csv", "dsl", "cli"} and len(CASES) >= 60
