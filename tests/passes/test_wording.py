"""Numbers in diagnostics show what the check found."""

from __future__ import annotations

import numpy as np
import pytest

from olp.passes import wording


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (170.00001, "170.00001"),
        (-170.00001, "-170.00001"),
        (175.0, "175.00"),
        (170.0 + 5.7e-8, "170.0000001"),
        (float(np.degrees(np.radians(170.0) + 1e-9)), "170.0000001"),
    ],
)
def test_outside_prints_the_digits_that_leave_the_limits(value: float, text: str) -> None:
    assert wording.outside(value, -170.0, float(np.degrees(np.radians(170.0)))) == text


@pytest.mark.parametrize(
    ("value", "text"),
    [(float(np.degrees(np.radians(170.0))), "170"), (-190.0, "-190"), (170.5, "170.5"),
     (-0.0, "0"), (1e40, "1e+40"), (float("inf"), "inf")],
)  # fmt: skip
def test_exact_prints_a_limit_as_it_was_written(value: float, text: str) -> None:
    assert wording.exact(value) == text


def test_above_prints_a_need_larger_than_its_limit() -> None:
    assert wording.above(381.2, 381.0) == ("381.2", "381.0")
    assert wording.above(500.0, 381.0) == ("500", "381")


@pytest.mark.parametrize(
    ("fraction", "text"),
    [(0.0, "0%"), (1.0, "100%"), (0.37, "37%"), (0.003, "0.3%"), (0.9996, "99.96%"),
     (1e-9, "1e-07%")],
)  # fmt: skip
def test_percent_never_rounds_an_inner_point_to_an_end(fraction: float, text: str) -> None:
    assert wording.percent(fraction) == text


@pytest.mark.parametrize(
    ("value", "text"), [(4.5, "4.5"), (0.0004, "0.0004"), (1e8, "1e+08"), (0.0, "0.0")]
)
def test_quantity_is_short_and_never_a_false_zero(value: float, text: str) -> None:
    assert wording.quantity(value) == text
