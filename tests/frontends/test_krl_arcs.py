"""KRL frontend: CIRC, CIRC_REL, SCIRC, CA, $ORI_TYPE / $CIRC_TYPE and arc approximation."""

from __future__ import annotations

import numpy as np
import pytest

from olp import ir
from olp.errors import ParseError
from olp.frontends.krl import KrlResult, parse_krl

START = "LIN {X 500,Y 0,Z 500,A 0,B 90,C 0}"
ARC = "CIRC {X 550,Y 50,Z 500}, {X 600,Y 0,Z 500}"


def parse(*body: str) -> KrlResult:
    text = "\n".join(["DEF t ( )", "$VEL.CP = 0.1", "$APO.CDIS = 4", *body, "END", ""])
    return parse_krl(text, "t.src")


def arc_of(result: KrlResult) -> ir.CircularMove:
    arcs = [i for i in result.program if isinstance(i, ir.CircularMove)]
    assert len(arcs) == 1
    return arcs[0]


def error_of(*body: str) -> ParseError:
    with pytest.raises(ParseError) as info:
        parse(*body)
    return info.value


def test_circ_without_ca_keeps_the_default_rule() -> None:
    arc = arc_of(parse(START, ARC))
    assert arc.angle is None and arc.orientation is ir.ArcOrientation.INTERPOLATE
    assert np.allclose(arc.via.pose[:3, 3], [0.55, 0.05, 0.5])
    assert np.allclose(arc.target.pose[:3, 3], [0.6, 0.0, 0.5])  # type: ignore[union-attr]
    # the via point's missing A, B, C come from the start, like the end point's
    assert np.allclose(arc.via.pose[:3, :3], arc.target.pose[:3, :3])  # type: ignore[union-attr]


@pytest.mark.parametrize("ca", ["90", "-45.5", "360", "-720"])
def test_ca_is_kept_in_radians(ca: str) -> None:
    arc = arc_of(parse(START, f"{ARC}, CA {ca}"))
    assert arc.angle == pytest.approx(np.radians(float(ca)))


def test_ca_errors_are_located() -> None:
    error = error_of(START, f"{ARC}, CA 0")
    assert error.span is not None and error.span.line == 5 and "must not be 0" in error.message
    error = error_of(START, "LIN {X 600,Y 0,Z 500}, CA 90")
    assert error.span is not None and error.span.line == 5 and "only CIRC" in error.message


def test_after_ca_the_start_of_the_next_move_is_unknown() -> None:
    error = error_of(START, f"{ARC}, CA 120", "LIN {X 700}")
    assert error.span is not None and error.span.line == 6
    assert "CA at line 5" in error.message


@pytest.mark.parametrize(
    ("ori", "circ", "rule"),
    [
        ("#VAR", "#BASE", ir.ArcOrientation.INTERPOLATE),
        ("#CONSTANT", "#BASE", ir.ArcOrientation.CONSTANT),
        ("#VAR", "#PATH", ir.ArcOrientation.PATH),
        ("#constant", "#path", ir.ArcOrientation.PATH_CONSTANT),
        ("#JOINT", "#BASE", ir.ArcOrientation.WRIST),
    ],
)
def test_ori_type_and_circ_type(ori: str, circ: str, rule: ir.ArcOrientation) -> None:
    arc = arc_of(parse(START, f"$ORI_TYPE = {ori}", f"$CIRC_TYPE = {circ}", ARC))
    assert arc.orientation is rule


def test_bad_orientation_types_are_located_errors() -> None:
    error = error_of("$ORI_TYPE = #SIDEWAYS")
    assert error.span is not None and error.span.line == 4 and "#CONSTANT" in error.message
    error = error_of("$CIRC_TYPE = 3")
    assert error.span is not None and error.span.line == 4 and "#PATH" in error.message


def test_lin_under_constant_orientation_gets_a_note() -> None:
    result = parse("$ORI_TYPE = #CONSTANT", START)
    assert any("#CONSTANT is not modelled for LIN" in n.message for n in result.notes)


def test_circ_rel_offsets_both_points_from_the_start() -> None:
    arc = arc_of(parse(START, "CIRC_REL {X 50,Y 50}, {X 100}"))
    assert np.allclose(arc.via.pose[:3, 3], [0.55, 0.05, 0.5])
    assert np.allclose(arc.target.pose[:3, 3], [0.6, 0.0, 0.5])  # type: ignore[union-attr]


@pytest.mark.parametrize("approx", ["C_DIS", "C_VEL", "C_ORI"])
def test_arc_approximation(approx: str) -> None:
    result = parse(START, f"{ARC} {approx}")
    assert arc_of(result).zone.radius == pytest.approx(0.004)


def test_scirc_with_the_inline_forms_ldat() -> None:
    ldat = (
        "DECL LDAT LCP={VEL 0.05,ACC 100,APO_DIST 2,ORI_TYP #CONSTANT,CIRC_TYP #PATH,JERK_FAC 50}"
    )
    with_list = (
        "WITH $VEL = SVEL_CP(0.05, , LCP), $ORI_TYPE = SORI_TYP(LCP), "
        "$CIRC_TYPE = SCIRC_TYP(LCP), $APO = SAPO(LCP)"
    )
    result = parse(ldat, START, f"SCIRC {{X 550,Y 50,Z 500}}, {{X 600,Y 0,Z 500}} {with_list}", ARC)
    scirc, circ = [i for i in result.program if isinstance(i, ir.CircularMove)]
    assert scirc.orientation is ir.ArcOrientation.PATH_CONSTANT
    assert scirc.speed.linear == pytest.approx(0.05)
    # WITH holds for its motion only: the CIRC after it has the defaults again
    assert circ.orientation is ir.ArcOrientation.INTERPOLATE
    assert any("SCIRC is planned like CIRC" in n.message for n in result.notes)
