"""--assume spellings and the folding of conditions (olp.passes.timing.conditions)."""

from __future__ import annotations

import pytest

from olp import ir
from olp.errors import UsageError
from olp.passes.timing.conditions import (
    UNKNOWN,
    Assumptions,
    Environment,
    environment,
    parse_assumptions,
)


def test_every_spelling_of_an_assumption() -> None:
    got = parse_assumptions(
        [
            "in3=true",
            "$IN[4] = off",
            "in[5]=1",
            "loop:12=5",
            "loop:Retry=0",
            "loop:C:\\KRC\\Sub.SRC:7=2",
            "Count=4",
            "speed=2.5",
            "Part.Kind=#Big",
            "slot[2]='A b'",
            "flag=FALSE",
        ]
    )
    assert got.inputs == {3: True, 4: False, 5: True}
    assert got.loops == {12: 5, "retry": 0, ("sub.src", 7): 2}
    assert got.names == {
        "count": 4,
        "speed": 2.5,
        "part.kind": "#big",
        "slot[2]": "A b",
        "flag": False,
    }
    assert got.given[1] == "$IN[4] = off"


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("in3", "expected NAME=VALUE"),
        ("=true", "expected NAME=VALUE"),
        ("in3=maybe", "an input is true or false, got 'maybe'"),
        ("loop:12=-1", "a loop's passes must be a whole number"),
        ("loop:12=two", "a loop's passes must be a whole number"),
        ("loop:=2", "expected loop:LINE=N or loop:LABEL=N"),
        ("count=four", "expected true, false, a number"),
        ("count=inf", "is not a finite number"),
        ("a;b=1", "is not a name, input or loop"),
    ],
)
def test_a_bad_assumption_is_a_usage_error_naming_it(text: str, words: str) -> None:
    with pytest.raises(UsageError) as caught:
        parse_assumptions([text])
    assert words in str(caught.value) and repr(text) in str(caught.value)


def binary(op: str, left: ir.Expr, right: ir.Expr) -> ir.BinaryOp:
    return ir.BinaryOp(op=op, left=left, right=right)


def const(value: bool | int | float | str) -> ir.Constant:
    return ir.Constant(value=value)


IN1, X = ir.DigitalInput(index=1), ir.Name(name="x")


def test_known_parts_decide_and_or_the_rest_stays_unknown() -> None:
    env = Environment({1: True}, {"n": 3})
    assert env.evaluate(binary("and", const(False), X)) is False
    assert env.evaluate(binary("or", X, IN1)) is True
    assert env.evaluate(binary("and", IN1, X)) is UNKNOWN
    assert env.evaluate(ir.UnaryOp(op="not", operand=IN1)) is False
    assert env.evaluate(binary("<", ir.Name(name="N"), const(4))) is True
    assert env.evaluate(binary("==", binary("*", ir.Name(name="n"), const(2)), const(6))) is True
    assert env.evaluate(binary("/", const(7), const(2))) is UNKNOWN  # languages differ
    assert env.evaluate(binary("/", const(6), const(2))) == 3
    assert env.evaluate(ir.DigitalInput(index=2)) is UNKNOWN
    enum = ir.Constant(value="BIG", enum=True)
    assert Environment({}, {"k": "#big"}).evaluate(binary("==", ir.Name(name="K"), enum)) is True


def test_declarations_fix_values_unless_the_program_assigns_them() -> None:
    twice = binary("*", ir.Name(name="passes"), const(2))
    nodes = (
        ir.Declare(name="Passes", type_name="INT", value=const(3)),
        ir.Declare(name="Twice", type_name="INT", value=twice),
        ir.Declare(name="Changed", type_name="INT", value=const(1)),
        ir.Assign(target=ir.Name(name="changed"), value=const(2)),
    )
    env = environment(nodes, Assumptions())
    assert env.names == {"passes": 3, "twice": 6}
    assert environment(nodes, Assumptions(names={"changed": 5})).names["changed"] == 5
