"""A call of a routine olp did not read (another module's, an EXT one) may set the tool, base or
speeds; olp checks the next motion with the settings it knows and the posts write those again
before it, overriding what the routine set: the first motion after such a call carries a
warning that says so (it used to pass without a word)."""

from __future__ import annotations

from pathlib import Path

import olp

STATION = Path(__file__).resolve().parents[2] / "stations" / "kr6_milling_cell.yaml"

CELL = """DEF cell( )
EXT SetFrames(INT:IN, INT:IN)
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
$VEL.CP = 0.2
SetFrames(1, 2)
PTP {A1 10, A2 -90, A3 90, A4 0, A5 45, A6 0}
LIN {X 500, Y 0, Z 600, A 0, B 90, C 0}
END
"""

OWN = """DEF cell( )
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
$VEL.CP = 0.2
Settle( )
LIN {X 500, Y 0, Z 600, A 0, B 90, C 0}
END
DEF Settle( )
WAIT SEC 0.2
END
"""


def _warnings(tmp_path: Path, text: str) -> list[olp.Diagnostic]:
    source = tmp_path / "cell.src"
    source.write_text(text)
    result = olp.build(olp.load_station(STATION), source, post="kuka", collisions=None)
    return [
        d for d in result.diagnostics if d.severity == "warning" and "did not read" in d.message
    ]


def test_the_first_motion_after_an_unread_routine_says_what_olp_assumed(tmp_path: Path) -> None:
    (warning,) = _warnings(tmp_path, CELL)
    assert warning.span is not None and warning.span.line == 6  # the PTP right after the call
    assert "SetFrames at line 5" in warning.message
    assert "$TOOL, $BASE" in warning.message


def test_a_call_of_the_modules_own_routine_needs_no_such_warning(tmp_path: Path) -> None:
    assert _warnings(tmp_path, OWN) == []
