"""Long runs of plain LIN motions become one ir.LinearPath: the same moves, the same files.

The reference in each test is the same program read with the run threshold out of reach (every
motion an ordinary move, as before the dense node); the dense reading must give equal moves
(targets, speeds, zones, tools, frames, spans) and byte-identical files on every post.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

import olp
from olp import ir
from olp.api import BuildResult
from olp.errors import ParseError
from olp.frontends.krl import KrlResult, parse_krl, rows
from olp.station.model import Station
from tests.compile_once import CompileOnce

REPO = Path(__file__).resolve().parents[2]
HEADER = [
    "DEF Helix ( )",
    "$BASE = {FRAME: X 0.000,Y -1000.000,Z 0.000,A 0.000,B 0.000,C 0.000}",
    "$TOOL = {FRAME: X 466.604,Y -4.165,Z 109.636,A -0.000,B 90.000,C 0.000}",
    "$VEL.CP = 0.05",
    "$APO.CDIS = 0.5",
    "PTP {A1 107.78457,A2 -44.95260,A3 141.64681,A4 107.66839,A5 -87.93467,A6 6.37710}",
]


def lin(i: int, n: int, approx: str = " C_DIS") -> str:
    """Row ``i`` of ``n`` of a helix the KR 6 milling cell reaches (mm, deg, in the table)."""
    t = 40 * math.pi * i / n
    x, y, z = 100 + 60 * math.cos(t), 60 * math.sin(t), 20 + 30 * i / n
    return f"LIN {{X {x:.3f},Y {y:.3f},Z {z:.3f},A -180.000,B 0.000,C -180.000}}{approx}"


def helix_program(n: int) -> str:
    """``n`` LINs with feed changes, exact stops, a comment, partial targets and an $ACC.CP."""
    out = list(HEADER)
    for i in range(n):
        if i % 700 == 0:
            out.append(f"$VEL.CP = {0.02 + i / n * 0.05:.5f}")
        if i == n // 2:
            out.append("; half way")
        if i == n // 3:
            out.append("$ACC.CP = 1.5")
        if i % 1000 == 999:
            out.append("LIN {Z 60} C_DIS")  # a partial target: the rest from the previous one
        out.append(lin(i, n, "" if i % 97 == 0 else " C_DIS"))
    return "\n".join([*out, "END", ""])


def read(text: str, monkeypatch: pytest.MonkeyPatch, dense: bool, fast: bool = True) -> KrlResult:
    with monkeypatch.context() as patch:
        if not dense:
            patch.setattr(rows, "DENSE_MIN_ROWS", 10**12)
        return parse_krl(text, "helix.src", fast_path=fast)


def kinds(result: KrlResult) -> list[tuple[str, int]]:
    return [
        (type(n).__name__, len(n) if isinstance(n, ir.LinearPath) else 1)
        for n in result.program.instructions
    ]


@pytest.fixture(scope="module")
def station() -> Station:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


@pytest.fixture(scope="module")
def both() -> tuple[KrlResult, KrlResult]:
    text = helix_program(5000)
    with pytest.MonkeyPatch.context() as patch:
        return read(text, patch, dense=True), read(text, patch, dense=False)


def test_a_long_program_reads_as_linear_paths_with_the_same_moves(
    both: tuple[KrlResult, KrlResult],
) -> None:
    dense, plain = both
    paths = [n for n in dense.program.instructions if isinstance(n, ir.LinearPath)]
    # Split only where the IR changes: $ACC.CP (held once per path) at row 1666, and the
    # comment half way, kept in place (issue 15).
    assert [len(p) for p in paths] == [1667, 835, 2503]
    comments = [n for n in plain.program.instructions if isinstance(n, ir.Comment)]
    assert [(c.text, c.span.line) for c in comments] == [("half way", 2514)]
    assert all(
        isinstance(n, ir.LinearMove | ir.JointMove | ir.Comment) for n in plain.program.instructions
    )
    assert len(dense.program) == len(plain.program) == 5007
    assert list(dense.program) == list(plain.program)
    assert dense.ignored == plain.ignored and dense.notes == plain.notes


@pytest.fixture(scope="module")
def compile_once() -> CompileOnce:
    """Each program of ``both`` compiled once for all the posts."""
    return CompileOnce()


@pytest.mark.parametrize("post", ["kuka", "abb", "ur", "fanuc"])
def test_a_long_program_builds_byte_identical_files_on_every_post(
    both: tuple[KrlResult, KrlResult], station: Station, post: str, compile_once: CompileOnce
) -> None:
    dense, plain = both
    with compile_once:
        built: list[BuildResult] = [
            olp.build(station, r.program, post, collisions=None) for r in (dense, plain)
        ]
    assert built[0].ok and built[0].files
    assert built[0].files == built[1].files
    assert [repr(d) for d in built[0].diagnostics] == [repr(d) for d in built[1].diagnostics]


def test_the_grammar_path_reads_the_same_linear_paths(monkeypatch: pytest.MonkeyPatch) -> None:
    text = helix_program(300)
    fast = read(text, monkeypatch, dense=True)
    assert read(text, monkeypatch, dense=True, fast=False) == fast
    # the comment half way stays in place: 50 rows before it are too few for a LinearPath
    assert kinds(fast) == [
        ("JointMove", 1),
        ("LinearPath", 100),
        *[("LinearMove", 1)] * 50,
        ("Comment", 1),
        ("LinearPath", 150),
    ]


def test_short_runs_stay_moves(monkeypatch: pytest.MonkeyPatch) -> None:
    n = rows.DENSE_MIN_ROWS
    short = read("\n".join([*HEADER, *(lin(i, n) for i in range(n - 1)), "END"]), monkeypatch, True)
    assert {k for k, _ in kinds(short)} == {"JointMove", "LinearMove"}
    exact = read("\n".join([*HEADER, *(lin(i, n) for i in range(n)), "END"]), monkeypatch, True)
    assert kinds(exact) == [("JointMove", 1), ("LinearPath", n)]


@pytest.mark.parametrize(
    ("between", "why"),
    [
        ("  " + lin(5, 9), "indented: a LinearPath row starts in column 1"),
        ("LIN XP1 C_DIS", "a named target"),
        ("$TOOL = {FRAME: X 400,Y 0,Z 100,A 0,B 90,C 0}", "another tool"),
        ("$VEL_AXIS[1] = 50", "a joint speed a LinearPath cannot hold"),
        ("$OUT[3] = TRUE", "an instruction between"),
        ("WAIT SEC 0.5", "an instruction between"),
    ],
)
def test_what_ends_a_run(between: str, why: str, monkeypatch: pytest.MonkeyPatch) -> None:
    n = 200
    body = [lin(i, n) for i in range(n)]
    body.insert(100, between)
    decl = ["DECL E6POS XP1={X 150,Y 0,Z 30,A -180,B 0,C -180}"] if "XP1" in between else []
    text = "\n".join([*HEADER[:1], *decl, *HEADER[1:], *body, "END"])
    dense, plain = read(text, monkeypatch, True), read(text, monkeypatch, False)
    assert list(dense.program) == list(plain.program), why
    paths = [size for kind, size in kinds(dense) if kind == "LinearPath"]
    assert paths == [100, 100] if not between.startswith(("$TOOL", "$VEL_AXIS")) else [100], why


def test_a_row_diagnostic_names_its_line(station: Station, monkeypatch: pytest.MonkeyPatch) -> None:
    n = 100
    body = [lin(i, n) for i in range(n)]
    body[70] = "LIN {X 2500.000,Y 0.000,Z 20.000,A -180.000,B 0.000,C -180.000} C_DIS"
    text = "\n".join([*HEADER, *body, "END"])
    dense = read(text, monkeypatch, True)
    assert kinds(dense)[1] == ("LinearPath", n)
    built = olp.build(station, dense.program, "kuka", collisions=None)
    errors = [d for d in built.diagnostics if d.severity == "error"]
    assert errors and errors[0].span == ir.SourceSpan("helix.src", 77, 1, 77, len(body[70]) + 1)
    assert errors[0].index == 71


CAM_ROWS = [lin(i, 80) for i in range(80)]


@pytest.mark.parametrize(
    "before",
    [
        [],
        ["$ORI_TYPE = #CONSTANT"],
        ["SLIN {X 150,Y 0,Z 30,A -180,B 0,C -180} WITH $VEL.CP = 0.1"],
        ["$APO = {CDIS 0.0}", "BAS(#INITMOV, 0)"],
        ["RETURN"],
        ["GOTO skip"],
        ["IF $IN[1] THEN", "$VEL.CP = 0.1", "ENDIF"],
    ],
)
def test_rows_read_as_the_grammar_reads_them(
    before: list[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    body = [*before, *CAM_ROWS, *(["skip:"] if "GOTO skip" in before else [])]
    for header in (HEADER, HEADER[:3] + HEADER[5:]):  # with and without $VEL.CP, $APO.CDIS
        text = "\n".join([*header, *body, "END"])
        assert outcome(text, True) == outcome(text, False)


@pytest.mark.parametrize("wrap", [("FOR I = 1 TO 3", "ENDFOR"), ("IF $IN[1] THEN", "ENDIF")])
def test_rows_in_loops_and_blocks(wrap: tuple[str, str]) -> None:
    text = "\n".join([*HEADER, "DECL INT I", wrap[0], *CAM_ROWS, wrap[1], "END"])
    assert outcome(text, True) == outcome(text, False)


def outcome(text: str, fast: bool) -> KrlResult | tuple[str, object]:
    try:
        return parse_krl(text, "t.src", fast_path=fast)
    except ParseError as error:
        return error.message, error.span


def test_rows_with_windows_line_ends_and_every_number_form() -> None:
    numbers = ["-0.000", "+2.5", "1e3", "1.5E-3", ".5", "12.", "7", "-180"]
    odd = [
        f"LIN {{X {a},Y {b},Z 30.000,A -180.000,B 0.000,C {c}}}{z}"
        for a, b, c, z in zip(
            numbers, reversed(numbers), numbers[3:] + numbers[:3], ["", " C_DIS"] * 4, strict=True
        )
    ]
    text = "\r\n".join([*HEADER, *CAM_ROWS[:40], *odd, *CAM_ROWS[40:], "END", ""])
    fast = outcome(text, True)
    assert isinstance(fast, KrlResult) and ("LinearPath", 88) in kinds(fast)
    assert fast == outcome(text, False)
