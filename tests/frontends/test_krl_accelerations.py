"""KRL path and orientation accelerations: ``$ACC.CP`` (m/s²) and ``$ACC.ORI1`` (deg/s²) are
motion state, carried by the following path moves (a separate file: the KRL control-flow tests
are being restructured elsewhere)."""

from __future__ import annotations

import math

import pytest

from olp import ir
from olp.errors import ParseError
from olp.frontends.krl import parse_krl

PROGRAM = """DEF acc( )
$VEL.CP = 0.25
$APO.CDIS = 1
LIN {X 500, Y 0, Z 500, A 0, B 90, C 0}
$ACC.CP = 0.5
$ACC.ORI1 = 90
LIN {X 530, Y 0, Z 500, A 0, B 90, C 0}
$ACC = {CP 1.5, ORI1 45, ORI2 45}
LIN {X 560, Y 0, Z 500, A 0, B 90, C 0}
END
"""


def test_acc_cp_and_ori1_carry_into_the_moves() -> None:
    result = parse_krl(PROGRAM, "acc.src")
    first, second, third = [m.speed for m in result.program.motions()]
    assert first.linear_acceleration is None and first.angular_acceleration is None
    assert second.linear_acceleration == 0.5
    assert second.angular_acceleration == pytest.approx(math.radians(90), rel=1e-15)
    assert third.linear_acceleration == 1.5
    assert third.angular_acceleration == pytest.approx(math.radians(45), rel=1e-15)
    (kept,) = [i for i in result.program if isinstance(i, ir.Verbatim)]
    assert kept.span.line == 8 and "ORI2" in kept.reason  # nothing lost: written back as is


@pytest.mark.parametrize("line", ["$ACC.CP = 0", "$ACC.ORI1 = -5"])
def test_a_non_positive_acceleration_is_a_located_error(line: str) -> None:
    text = PROGRAM.replace("$ACC.CP = 0.5", line)
    with pytest.raises(ParseError) as info:
        parse_krl(text, "acc.src")
    assert info.value.span is not None and info.value.span.line == 5
    assert "must be > 0" in str(info.value)
