"""One table for every post: an instruction (or a small program) and what each post writes for
it, or the error it gives, in the spirit of sqlglot's ``validate_all``.

Each post compiles on a cell with a robot of its own brand (no foreign-robot warning). A row's
expected lines must appear, consecutively, among the written lines (stripped; LS line numbers
dropped); an :class:`Error` row expects that error kind on the row's instruction and no files.
Motion rows start from a ``READY`` joint position of each robot (no wrist singularity) and move
20 mm along the flange's Z axis and back: the positions below were checked by hand against that
geometry (e.g. the ABB tool's Z axis points along (0.707, 0, -0.707) at ready, so the target is
14.142 mm further in x and 14.142 mm lower).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.geometry import transl
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
CELLS = {
    "kuka": REPO / "stations" / "kr6_milling_cell.yaml",
    "abb": REPO / "stations" / "abb_irb120_pick_cell.yaml",
    "ur": REPO / "stations" / "ur5e_screw_cell.yaml",
    "fanuc": REPO / "stations" / "fanuc_m20ia_weld_cell.yaml",
}
POSTS = tuple(CELLS)
READY = {
    "kuka": [0, -90, 90, 0, 45, 0],
    "abb": [0, 0, 0, 0, 45, 0],
    "ur": [0, -90, 90, -90, -90, 0],
    "fanuc": [0, 0, 0, 0, -90, 0],
}


@dataclass(frozen=True)
class Error:
    """The post refuses the row: an error diagnostic of ``kind`` on the row's last instruction."""

    kind: str


Expected = Sequence[str] | Error
Make = Callable[[Station, str], Sequence[ir.Instruction]]


@dataclass(frozen=True)
class Row:
    make: Make
    write: Mapping[str, Expected]


def _ready(station: Station, post: str) -> ir.JointMove:
    return ir.JointMove(target=ir.JointTarget(joints=np.radians(READY[post])))


def _out_and_back(station: Station, post: str) -> list[ir.Instruction]:
    flange = station.robot.flange_poses(np.radians(READY[post]))
    away = ir.CartesianTarget(pose=flange @ transl(0.0, 0.0, 0.02))
    return [
        _ready(station, post),
        ir.LinearMove(target=away, speed=ir.Speed(linear=0.1), zone=ir.Zone(0.005)),
        ir.LinearMove(target=ir.CartesianTarget(pose=flange), speed=ir.Speed(linear=0.1)),
    ]


def _after_ready(*instructions: ir.Instruction) -> Make:
    return lambda station, post: [_ready(station, post), *instructions]


HALF_CIRCLES = [
    (transl(0.01, 0.0, 0.01), transl(0.0, 0.0, 0.02)),
    (transl(-0.01, 0.0, 0.01), transl(0.0, 0.0, 0.0)),
]
"""Half circles of radius 10 mm about the point 10 mm along the flange's z at READY, in its x-z
plane: via 10 mm along x and z, end 20 mm along z (the linear row's "away" point); then back
by the mirrored half circle."""
ARC_30 = [
    (
        transl(0.01 * np.sin(np.pi / 12), 0.0, 0.01 * (1 - np.cos(np.pi / 12))),
        transl(0.01 * np.sin(np.pi / 6), 0.0, 0.01 * (1 - np.cos(np.pi / 6))),
    )
]
"""The first 30° of the first half circle, its via point at 15° (the tool turns 30° with it)."""


def _arcs(
    *arcs: dict[str, object], points: list[tuple[np.ndarray, np.ndarray]] = HALF_CIRCLES
) -> Make:
    """From READY, one circular move per ``arcs`` (its extra fields) through ``points``."""

    def make(station: Station, post: str) -> list[ir.Instruction]:
        flange = station.robot.flange_poses(np.radians(READY[post]))
        out: list[ir.Instruction] = [_ready(station, post)]
        for (via, end), fields in zip(points, arcs, strict=False):
            out.append(
                ir.CircularMove(
                    target=ir.CartesianTarget(pose=flange @ end),
                    via=ir.CartesianTarget(pose=flange @ via),
                    speed=ir.Speed(linear=0.1),
                    **fields,  # type: ignore[arg-type]
                )
            )
        return out

    return make


ROWS: dict[str, Row] = {
    "joint move to axis values": Row(
        lambda station, post: [_ready(station, post)],
        {
            "kuka": ["PTP {A1 0.00000,A2 -90.00000,A3 90.00000,A4 0.00000,A5 45.00000,A6 0.00000}"],
            "abb": ["MoveAbsJ p1\\NoEOffs, v250, fine, tool0;"],
            "ur": [
                "movej([0.000000, -1.570796, 1.570796, -1.570796, -1.570796, 0.000000], "
                "a=1.40000, v=3.14159, r=0.000000)"
            ],
            "fanuc": ["J P[1] 100% FINE    ;"],
        },
    ),
    "joint move at half speed": Row(
        lambda station, post: [
            ir.JointMove(
                target=ir.JointTarget(joints=np.radians(READY[post])),
                speed=ir.Speed(joint=0.5, joint_acceleration=0.25),
            )
        ],
        {
            "kuka": [f"$VEL_AXIS[{i}] = 50" for i in range(1, 7)]
            + [f"$ACC_AXIS[{i}] = 25" for i in range(1, 7)],
            "abb": ["MoveAbsJ p1\\NoEOffs, v250, fine, tool0;"],  # RAPID: TCP speed (warned)
            "ur": [
                "movej([0.000000, -1.570796, 1.570796, -1.570796, -1.570796, 0.000000], "
                "a=0.35000, v=1.57080, r=0.000000)"
            ],
            "fanuc": ["J P[1] 50% FINE    ;"],
        },
    ),
    "linear moves out and back, the first blended": Row(
        _out_and_back,
        {
            "kuka": [
                "$VEL.CP = 0.10000",
                "$APO.CDIS = 5.000",
                "LIN {X 515.711,Y -400.000,Z 847.574,A 0.0000,B 45.0000,C 0.0000,S 2,T 2} C_DIS",
                "LIN {X 501.569,Y -400.000,Z 833.431,A 0.0000,B 45.0000,C 0.0000,S 2,T 2}",
            ],
            "abb": [
                "MoveAbsJ p1\\NoEOffs, v250, fine, tool0;",
                "MoveL p2, v100, z5, tool0\\WObj:=world;",
                "MoveL p3, v100, fine, tool0\\WObj:=world;",
            ],
            "ur": [
                "movel(p[-0.491900, -0.133300, 0.467900, 2.221441, 2.221441, 0.000000], "
                "a=1.20000, v=0.10000, r=0.005000)",
                "movel(p[-0.491900, -0.133300, 0.487900, 2.221441, 2.221441, 0.000000], "
                "a=1.20000, v=0.10000, r=0.000000)",
            ],
            "fanuc": ["L P[2] 100mm/sec CNT5    ;", "L P[3] 100mm/sec FINE    ;"],
        },
    ),
    "digital output on": Row(
        _after_ready(ir.SetOutput(index=3, value=True)),
        {
            "kuka": ["$OUT[3] = TRUE"],
            "abb": ["SetDO do3, 1;"],
            "ur": ["set_digital_out(3, True)"],
            "fanuc": ["DO[3]=ON ;"],
        },
    ),
    "wait for an input to be off": Row(
        _after_ready(ir.WaitInput(index=4, value=False)),
        {
            "kuka": ["WAIT FOR NOT $IN[4]"],
            "abb": ["WaitDI di4, 0;"],
            "ur": ["while get_digital_in(4):", "sync()", "end"],
            "fanuc": ["WAIT DI[4]=OFF ;"],
        },
    ),
    "dwell": Row(
        _after_ready(ir.Wait(seconds=0.5)),
        {
            "kuka": ["WAIT SEC 0.500"],
            "abb": ["WaitTime \\InPos, 0.500;"],
            "ur": ["sleep(0.500)"],
            "fanuc": ["WAIT 0.50(sec) ;"],
        },
    ),
    "call with a number": Row(
        _after_ready(ir.Call(name="Grip", args=("1",))),
        {"kuka": ["Grip(1)"], "abb": ["Grip 1;"], "ur": ["Grip(1)"], "fanuc": ["CALL GRIP(1) ;"]},
    ),
    "comment of two lines": Row(
        _after_ready(ir.Comment(text="two\nlines")),
        {
            "kuka": ["; two", "; lines"],
            "abb": ["! two", "! lines"],
            "ur": ["# two", "# lines"],
            "fanuc": ["!two ;", "!lines ;"],
        },
    ),
    "output 0": Row(
        _after_ready(ir.SetOutput(index=0, value=True)),
        {
            "kuka": Error("io_range"),
            "abb": ["SetDO do0, 1;"],
            "ur": ["set_digital_out(0, True)"],
            "fanuc": Error("io_range"),
        },
    ),
    "output 10": Row(
        _after_ready(ir.SetOutput(index=10, value=False)),
        {
            "kuka": ["$OUT[10] = FALSE"],
            "abb": ["SetDO do10, 0;"],
            "ur": Error("io_range"),
            "fanuc": ["DO[10]=OFF ;"],
        },
    ),
    "call with a string": Row(
        _after_ready(ir.Call(name="Say", args=('"hello"',))),
        {
            "kuka": ['Say("hello")'],
            "abb": ['Say "hello";'],
            "ur": ['Say("hello")'],
            "fanuc": Error("call_argument"),
        },
    ),
    "call with a statement in an argument": Row(
        _after_ready(ir.Call(name="Grip", args=("1;MoveL p1",))),
        {post: Error("call_argument") for post in POSTS},
    ),
    "call with a 200,000-digit argument (matched in linear time)": Row(
        _after_ready(ir.Call(name="Grip", args=("9" * 200_000 + "x",))),
        {post: Error("call_argument") for post in POSTS},
    ),
    "call of an illegal name": Row(
        _after_ready(ir.Call(name="Spray On")),
        {post: Error("call_name") for post in POSTS},
    ),
    "comment with a control character": Row(
        _after_ready(ir.Comment(text="bell\x07")),
        {post: Error("comment") for post in POSTS},
    ),
    "circular move through three points": Row(
        _arcs({}),
        {
            "kuka": [
                "$ORI_TYPE = #VAR",
                "$CIRC_TYPE = #BASE",
                "CIRC {X 515.711,Y -400.000,Z 833.431,A 0.0000,B 45.0000,C 0.0000}, "
                "{X 515.711,Y -400.000,Z 847.574,A 0.0000,B 45.0000,C 0.0000,S 2,T 2}",
            ],
            "abb": ["MoveC p2_via, p2, v100, fine, tool0\\WObj:=world;"],
            "ur": [
                "movec(p[-0.491900, -0.123300, 0.477900, 2.221441, 2.221441, 0.000000], "
                "p[-0.491900, -0.133300, 0.467900, 2.221441, 2.221441, 0.000000], "
                "a=1.20000, v=0.10000, r=0.000000, mode=0)"
            ],
            "fanuc": ["C P[2]", ":  P[3] 100mm/sec FINE    ;"],
        },
    ),
    "circular move with a circular angle": Row(
        _arcs({"angle": np.radians(90.0)}),
        {
            "kuka": [
                "CIRC {X 515.711,Y -400.000,Z 833.431,A 0.0000,B 45.0000,C 0.0000}, "
                "{X 515.711,Y -400.000,Z 847.574,A 0.0000,B 45.0000,C 0.0000,S 2,T 2}, CA 90.0000"
            ],
            "abb": Error("arc_angle"),
            "ur": Error("arc_angle"),
            "fanuc": Error("arc_angle"),
        },
    ),
    "circular move turning the tool with the path": Row(
        _arcs({"orientation": ir.ArcOrientation.PATH_CONSTANT}, points=ARC_30),
        {
            "kuka": [
                "$ORI_TYPE = #CONSTANT",
                "$CIRC_TYPE = #PATH",
                "CIRC {X 503.640,Y -400.000,Z 831.842,A 0.0000,B 45.0000,C 0.0000}, "
                "{X 506.051,Y -400.000,Z 830.843,A 0.0000,B 45.0000,C 0.0000,S 2,T 2}",
            ],
            "abb": Error("arc_orientation"),
            "ur": [
                "movec(p[-0.491900, -0.130712, 0.487559, 2.221441, 2.221441, 0.000000], "
                "p[-0.491900, -0.128300, 0.486560, 2.221441, 2.221441, 0.000000], "
                "a=1.20000, v=0.10000, r=0.000000, mode=1)"
            ],
            "fanuc": Error("arc_orientation"),
        },
    ),
    "circular move blended into a circular move": Row(
        _arcs({"zone": ir.Zone(0.003)}, {}),
        {
            "kuka": [
                "$APO.CDIS = 3.000",
                "$ORI_TYPE = #VAR",
                "$CIRC_TYPE = #BASE",
                "CIRC {X 515.711,Y -400.000,Z 833.431,A 0.0000,B 45.0000,C 0.0000}, "
                "{X 515.711,Y -400.000,Z 847.574,A 0.0000,B 45.0000,C 0.0000,S 2,T 2} C_DIS",
                "CIRC {X 501.569,Y -400.000,Z 847.574,A 0.0000,B 45.0000,C 0.0000}, "
                "{X 501.569,Y -400.000,Z 833.431,A 0.0000,B 45.0000,C 0.0000,S 2,T 2}",
            ],
            "abb": [
                "MoveC p2_via, p2, v100, z3, tool0\\WObj:=world;",
                "MoveC p3_via, p3, v100, fine, tool0\\WObj:=world;",
            ],
            "ur": Error("arc_blend"),
            "fanuc": [
                "C P[2]",
                ":  P[3] 100mm/sec CNT3    ;",
                "C P[4]",
                ":  P[5] 100mm/sec FINE    ;",
            ],
        },
    ),
    "dwell too long to write": Row(
        _after_ready(ir.Wait(seconds=1e300)),
        {post: Error("number") for post in POSTS},
    ),
}


@pytest.fixture(scope="module")
def stations() -> dict[str, Station]:
    return {post: olp.load_station(path) for post, path in CELLS.items()}


def _lines(files: Mapping[str, str]) -> list[str]:
    out = []
    for text in files.values():
        for line in text.replace("\r\n", "\n").split("\n"):
            out.append(re.sub(r"^\s*\d+:", "", line).strip())
    return out


def _contains(lines: Sequence[str], expected: Sequence[str]) -> bool:
    n = len(expected)
    return any(list(lines[i : i + n]) == list(expected) for i in range(len(lines) - n + 1))


CASES = [(name, post) for name, row in ROWS.items() for post in row.write]


@pytest.mark.parametrize(("name", "post"), CASES, ids=[f"{n} / {p}" for n, p in CASES])
def test_all_posts(stations: dict[str, Station], name: str, post: str) -> None:
    row = ROWS[name]
    instructions = tuple(row.make(stations[post], post))
    program = ir.Program(name="Row", instructions=instructions)
    result = olp.build(stations[post], program, post=post)
    expected = row.write[post]
    errors = [(d.kind, d.index) for d in result.diagnostics if d.severity == "error"]
    if isinstance(expected, Error):
        assert errors == [(expected.kind, len(instructions) - 1)]
        assert result.files == {}
        return
    assert errors == [], [d.format() for d in result.diagnostics]
    lines = _lines(result.files)
    assert _contains(lines, [line.strip() for line in expected]), "\n".join(lines)


def test_every_row_names_every_post() -> None:
    assert all(set(row.write) == set(POSTS) for row in ROWS.values())
