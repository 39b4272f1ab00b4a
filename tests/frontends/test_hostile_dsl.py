"""Python programs from a careless or hostile user (issue 10, items 6 and 14): DSL calls with
wrong types or absurd values, huge strings and messages, and text that made the call parser
backtrack for hours. Each is a located error with a bounded message. These run the program in
this process (:func:`run_dsl`); the child process is tested in ``test_dsl_process.py``."""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

from olp import ir
from olp.errors import OlpError, ParseError
from olp.frontends.dsl import run_dsl
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
HOME = "robot.MoveJ([0, -90, 90, 0, 0, 0])\n"
LIMIT = 400
"""No message or hint of a DSL error is longer than this, whatever the program holds."""


@pytest.fixture(scope="module")
def station() -> Station:
    return load_station(CELL)


def error_of(text: str, station: Station | None = None) -> OlpError:
    with pytest.raises(OlpError) as info:
        run_dsl(text, "prog.py", station)
    return info.value


@contextmanager
def finishes_within(seconds: float) -> Iterator[None]:
    """Fail (rather than hang for hours) if the block takes longer than ``seconds``."""

    def expire(signum: int, frame: object) -> None:
        raise TimeoutError(f"took longer than {seconds} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


BIG = 1_000_000

UNBOUNDED = [
    # a program whose error once repeated a huge piece of its text; the line of the error
    ("raise ValueError('x' * BIG)", 1),
    ("import sys\nsys.exit('y' * BIG)", 2),
    ("robot.setPoseTool('t' * BIG)", 1),
    ("robot.setPoseFrame('f' * BIG)", 1),
    ("robot.RunInstruction('-' * BIG)", 1),
    ("robot.MoveJ('n' * BIG)", 1),
    ("AddTarget('a' * BIG, [0] * 6)\nAddTarget('a' * BIG, [0] * 6)", 2),
    ("param('p' * BIG)", 1),
    ("robot.setDO('1' * BIG, 1)", 1),
    ("robot.setDO(1, 'on' * BIG)", 1),
    ("E = type('E' * BIG, (Exception,), {})\nraise E('m')", 2),
    ("robot.RunInstruction('x', 'r' * BIG)", 1),
]


@pytest.mark.parametrize(("text", "line"), UNBOUNDED)
def test_messages_quote_a_bounded_excerpt(station: Station, text: str, line: int) -> None:
    error = error_of(f"BIG = {BIG}\n" + HOME + text + "\n", station)
    assert error.span is not None and error.span.line == line + 2
    assert len(error.message) < LIMIT, error.message[:200]
    assert len(error.hint or "") < LIMIT


def test_a_program_warning_is_bounded(station: Station) -> None:
    result = run_dsl(HOME + "warn('w' * 1_000_000)\n", "prog.py", station)
    (warning,) = result.warnings
    assert len(warning.message) < 600 and warning.message.endswith("(1000000 characters)")


def test_a_call_with_a_long_run_of_spaces_is_rejected_at_once() -> None:
    """``\\s*;?\\s*`` backtracked cubically: 2,000 spaces took 15 s, 20,000 about 4 hours."""
    with finishes_within(10.0):
        error = error_of("robot.RunInstruction('a' + ' ' * 20000 + 'x')\n")
    assert isinstance(error, ParseError) and "is not a program call" in error.message


CALLS = [
    ("SprayOn", "SprayOn", ()),
    ("  TCP_On(2) ; ", "TCP_On", ("2",)),
    ("Grip (1, 2)", "Grip", ("1", "2")),
    ("Open();", "Open", ()),
]


@pytest.mark.parametrize(("code", "name", "args"), CALLS)
def test_program_calls_still_read_as_before(code: str, name: str, args: tuple[str, ...]) -> None:
    (call,) = run_dsl(f"robot.RunInstruction({code!r})\n", "prog.py").program.instructions
    assert isinstance(call, ir.Call) and (call.name, call.args) == (name, args)


WRONG = [
    # program, line, column, message
    ("robot.MoveL(transl([5]))", 1, 13, "transl: expected [x, y, z] in mm, got 1 values"),
    ("robot.MoveL(transl([1, 2, 3, 4]))", 1, 13, "got 4 values"),
    ("robot.MoveL(transl('abc'))", 1, 13, "transl: expected a list of numbers, got str"),
    ("robot.MoveL(transl(5))", 1, 13, "transl: expected numbers, got NoneType"),
    ("robot.setDO(10**100, 1)", 1, 1, "expected an I/O number from 1 to 2147483647"),
    ("robot.setDO(0, 1)", 1, 1, "expected an I/O number from 1 to 2147483647"),
    ("robot.setDO(2**31, 1)", 1, 1, "expected an I/O number from 1 to 2147483647"),
    ("robot.setDO('1' * 10000, 1)", 1, 1, "expected an I/O number from 1 to 2147483647"),
    ("robot.setDO(1.5, 1)", 1, 1, "expected an I/O number"),
    ("robot.setDO(1, 10**5000)", 1, 1, "expected 1/0, True/False or on/off, got int"),
    ("robot.setDO(1, 2)", 1, 1, "expected 1/0, True/False or on/off, got int 2"),
    ("robot.waitDI(1, object())", 1, 1, "expected 1/0, True/False or on/off"),
    ("x = 1", 1, 1, "the program recorded no robot instructions"),
    ("", 1, 1, "the program recorded no robot instructions"),
]


@pytest.mark.parametrize(("text", "line", "column", "message"), WRONG)
def test_wrong_calls_and_absurd_values_are_located_errors(
    text: str, line: int, column: int, message: str
) -> None:
    error = error_of(text + "\n")
    assert error.span is not None and (error.span.line, error.span.column) == (line, column)
    assert message in error.message


def test_io_accepts_numpy_values() -> None:
    text = "import numpy as np\nrobot.setDO(np.int64(3), np.bool_(True))\nrobot.setDO('4', 0.0)\n"
    first, second = run_dsl(text, "prog.py").program.instructions
    assert isinstance(first, ir.SetOutput) and (first.index, first.value) == (3, True)
    assert isinstance(second, ir.SetOutput) and (second.index, second.value) == (4, False)


def test_a_value_whose_repr_fails_is_still_described() -> None:
    text = "class Bad:\n    def __repr__(self):\n        raise RuntimeError\nrobot.MoveJ(Bad())\n"
    error = error_of(text)
    assert error.span is not None and error.span.line == 4
    assert "got Bad (no repr)" in error.message


def test_a_translation_keeps_its_three_values() -> None:
    (move,) = run_dsl("robot.MoveL(transl(x for x in (1, 2, 3)))\n", "p.py").program.instructions
    assert isinstance(move, ir.LinearMove) and isinstance(move.target, ir.CartesianTarget)
    assert np.allclose(move.target.pose[:3, 3], [0.001, 0.002, 0.003])
