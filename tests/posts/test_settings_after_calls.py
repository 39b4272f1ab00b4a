"""A called routine or a kept line may change the controller's tool, base, speed or zone, so the
first motion after one writes all its settings again (olp.posts.view.OPAQUE_KINDS).

Before, ``PTP A; Foo(); LIN B`` with the same tool and base came out as ``Foo()`` then ``LIN B``
alone: B ran with whatever tool and base ``Foo`` left.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir

REPO = Path(__file__).resolve().parents[2]
TOOL_FORWARD = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
SETTINGS = {
    "kuka": ("$TOOL = ", "$BASE = ", "$VEL.CP = "),
    "ur": ("set_tcp(",),
    "fanuc": ("UTOOL_NUM", "UFRAME_NUM"),
}


def pose(y_mm: float) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = TOOL_FORWARD
    out[:3, 3] = [0.5, y_mm / 1000, 0.3]
    return out


def program(between: ir.Node) -> ir.Program:
    tool = ir.Tool(name="probe", pose=np.eye(4), number=1)
    frame = ir.Frame(name="world", pose=np.eye(4), number=1)
    moves = [
        ir.LinearMove(target=ir.CartesianTarget(pose=pose(y)), tool=tool, frame=frame).with_speed(
            linear=0.1
        )
        for y in (-300, -250, -200)
    ]
    start = ir.JointMove(target=ir.CartesianTarget(pose=pose(-350)), tool=tool, frame=frame)
    return ir.Program(name="calls", instructions=(start, moves[0], between, moves[1], moves[2]))


CASES = [
    *((post, ir.Call(name="Foo")) for post in sorted(SETTINGS)),
    ("kuka", ir.Verbatim(text="BAS(#TOOL, 2)", language="krl")),  # a KRL line: KUKA only
]


@pytest.mark.parametrize(("post", "between"), CASES, ids=lambda c: getattr(c, "kind", c))
def test_the_motion_after_a_call_writes_its_settings_again(post: str, between: ir.Node) -> None:
    station = olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")
    result = olp.build(station, program(between), post=post, collisions=None)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    text = "\n".join(result.files.values()).upper()  # LS writes CALL FOO
    marker = "FOO" if isinstance(between, ir.Call) else "BAS(#TOOL, 2)"
    after = text[text.index(marker) :]
    before_next_move = after[: min(after.index(m) for m in ("LIN", "MOVEL", "L P[") if m in after)]
    for setting in SETTINGS[post]:
        assert setting.upper() in before_next_move, (setting, before_next_move)
    # Between the two moves after it, nothing changes: nothing is written again.
    last = after[after.index(marker) + len(marker) :]
    second = last[
        last.index("LIN" if post == "kuka" else "MOVEL" if post == "ur" else "L P[") + 3 :
    ]
    for setting in SETTINGS[post]:
        assert setting.upper() not in second[: second.find("LIN") if post == "kuka" else 200]
