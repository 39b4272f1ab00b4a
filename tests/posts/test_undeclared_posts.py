"""Names and functions nothing in the program declares (issue 15), through every post: the KRL
post writes them as they stand (the controller holds their declarations); RAPID, URScript and
LS cannot (nothing declares them there): a located error naming the name and its line, and
nothing written. Programs in the style of a pallet cell whose backup lacks the .dat."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import olp
from olp.api import BuildResult

REPO = Path(__file__).resolve().parents[2]
STATION = REPO / "stations" / "kr6_milling_cell.yaml"
HEAD = (
    "DEF cell( )",
    "DECL INT nPart",
    "$BASE = BASE_DATA[1]",
    "$TOOL = TOOL_DATA[1]",
    "$VEL.CP = 0.2",
    "PTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}",
)
PROGRAMS = {
    "variable": ("IF nLayerCount > 3 THEN", "nPart = 1", "ENDIF"),
    "point": ("PTP xPalletReady",),
    "function": ("nPart = fnNextPart(1)",),
}
"""The statement(s) after :data:`HEAD`; the undeclared name is on line 7."""
NAMES = {"variable": "nLayerCount", "point": "xPalletReady", "function": "fnNextPart"}


@pytest.fixture(scope="module")
def station() -> Any:
    return olp.load_station(STATION)


def build(station: Any, tmp_path: Path, what: str, post: str) -> BuildResult:
    src = tmp_path / "cell.src"
    src.write_text("\n".join([*HEAD, *PROGRAMS[what], "END", ""]))
    return olp.build(station, src, post=post, collisions=None)


@pytest.mark.parametrize("what", sorted(PROGRAMS))
def test_the_kuka_post_writes_them_as_they_stand(station: Any, tmp_path: Path, what: str) -> None:
    result = build(station, tmp_path, what, "kuka")
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    text = result.files["cell.src"]
    assert PROGRAMS[what][0] in text.splitlines()
    (warning,) = [d for d in result.diagnostics if d.kind == "krl_note"]
    assert warning.severity == "warning" and warning.span is not None
    assert warning.span.line == 7 and warning.message.startswith(NAMES[what])


@pytest.mark.parametrize("what", sorted(PROGRAMS))
@pytest.mark.parametrize("post", ["abb", "ur", "fanuc"])
def test_other_posts_stop_on_them_naming_the_name_and_line(
    station: Any, tmp_path: Path, what: str, post: str
) -> None:
    result = build(station, tmp_path, what, post)
    errors = [d for d in result.diagnostics if d.severity == "error"]
    assert not result.ok and not result.files
    assert any(
        d.span is not None and d.span.line == 7 and NAMES[what] in d.message for d in errors
    ), [d.format() for d in errors]


def test_a_function_of_the_module_is_written(station: Any, tmp_path: Path) -> None:
    """The module's own DEFFCT is a function of the program: RAPID and URScript write it and
    its call."""
    src = tmp_path / "cell.src"
    function = "DEFFCT INT fnNextPart(n:IN)\nDECL INT n\nRETURN n + 1\nENDFCT\n"
    src.write_text("\n".join([*HEAD, "nPart = fnNextPart(1)", "END", function]))
    for post, call in (("abb", "nPart := fnNextPart(1);"), ("ur", "nPart = fnNextPart(1)")):
        result = olp.build(station, src, post=post, collisions=None)
        assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
        (text,) = result.files.values()
        assert call in [line.strip() for line in text.splitlines()]
