"""A FOR loop that only sets motion settings is written back as a loop (issue 15).

``FOR ax = 1 TO 6 $VEL_AXIS[ax] = 20 ENDFOR`` (the pendant programs of palletising cells set
their axis speeds so) was unrolled: olp modelled each axis's value, but the KRL output held no
FOR/ENDFOR, and where a motion with the controller's settings came next it held one
``$VEL_AXIS[ax] = 20`` outside any loop (it set one axis, with whatever ``ax`` held, and did
not read again: "the index of $VEL_AXIS must be a constant number"). Now the KUKA post writes
the loop where it stands, as written; olp still unrolls it into the motion settings, so the
next motion is checked and timed with the loop's values, and other posts write those values
with the motion, as before.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import olp
from olp import ir
from olp.frontends.krl import load_krl

REPO = Path(__file__).resolve().parents[2]
STATION = REPO / "stations" / "kr6_milling_cell.yaml"
HEAD = """DEF cell( )
DECL INT ax
$TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}
$BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
"""
LOOP = """;FOLD slow axes
FOR ax = 1 TO 6 ; every axis
  $VEL_AXIS[ax] = 20
  $ACC_AXIS[ax] = 40 ; gently
ENDFOR
;ENDFOLD
"""
UNROLLED = (
    ";FOLD slow axes\n; every axis\n"
    + "".join(f"$VEL_AXIS[{n}] = 20\n" for n in range(1, 7))
    + "".join(f"$ACC_AXIS[{n}] = 40\n" for n in range(1, 7))
    + "; gently\n;ENDFOLD\n"
)
"""The same settings, one line per axis: what other posts write must not change."""
TAIL = "PTP {A1 30, A2 -90, A3 90, A4 0, A5 45, A6 0}\nEND\n"
LOOP_LINES = ["FOR ax = 1 TO 6", "$VEL_AXIS[ax] = 20", "$ACC_AXIS[ax] = 40", "ENDFOR"]


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(STATION)


def write(tmp_path: Path, text: str, folder: str = "in") -> Path:
    path = tmp_path / folder / "cell.src"
    path.parent.mkdir(exist_ok=True)
    path.write_text(text)
    return path


def build(station: object, path: Path, post: str = "kuka") -> olp.BuildResult:
    result = olp.build(station, path, post=post, collisions=None)  # type: ignore[arg-type]
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    return result


def kept(program: ir.Program) -> list[str]:
    return [n.text for n in program if isinstance(n, ir.Verbatim)]


def test_the_loop_is_kept_in_place_and_its_values_reach_the_next_motion(tmp_path: Path) -> None:
    result = load_krl(write(tmp_path, HEAD + LOOP + TAIL))
    nodes = list(result.program)
    assert kept(result.program) == LOOP_LINES
    lines = [n for n in nodes if isinstance(n, ir.Verbatim)]
    assert all(n.native_only and n.modelled for n in lines)  # a modelled motion follows
    assert [n.span.line for n in lines] == [7, 8, 9, 10]
    first, second = result.program.motions()
    assert nodes.index(first) < nodes.index(lines[0]) and nodes.index(lines[-1]) < nodes.index(
        second
    )
    assert second.speed.joint == pytest.approx(0.2)
    assert second.speed.joint_acceleration == pytest.approx(0.4)
    assert not [i for i in result.ignored if i.span.line == 7]  # no "written out 6 times"


def test_the_kuka_post_writes_the_loop_and_the_same_values_before_the_motion(
    station: object, tmp_path: Path
) -> None:
    slow = build(station, write(tmp_path, HEAD + LOOP + TAIL))
    text = slow.files["cell.src"]
    lines = [line.strip() for line in text.splitlines()]
    at = lines.index("FOR ax = 1 TO 6")
    assert lines[at : at + 6] == [
        "FOR ax = 1 TO 6",
        "; every axis",
        "$VEL_AXIS[ax] = 20",
        "$ACC_AXIS[ax] = 40",
        "; gently",
        "ENDFOR",
    ]
    after = lines[at + 6 : next(k for k, line in enumerate(lines) if line.startswith("PTP {A1 30"))]
    assert [f"$VEL_AXIS[{n}] = 20" for n in range(1, 7)] == [
        line for line in after if line.startswith("$VEL_AXIS")
    ]
    assert text.count("$VEL_AXIS[ax]") == 1  # once, in the loop
    # the loop's values time the motion after it, as the same settings axis by axis do
    same = build(station, write(tmp_path, HEAD + UNROLLED + TAIL, "unrolled"))
    fast = build(station, write(tmp_path, HEAD + TAIL, "fast"))
    duration = slow.compiled.steps[-1].duration
    assert duration == pytest.approx(same.compiled.steps[-1].duration)
    assert duration > 1.2 * fast.compiled.steps[-1].duration


@pytest.mark.parametrize("post", ["abb", "ur"])
def test_other_posts_write_what_they_wrote_for_the_unrolled_settings(
    station: object, tmp_path: Path, post: str
) -> None:
    looped = build(station, write(tmp_path, HEAD + LOOP + TAIL), post)
    unrolled = build(station, write(tmp_path, HEAD + UNROLLED + TAIL, "unrolled"), post)
    assert looped.files == unrolled.files
    assert not [d for d in looped.diagnostics if d.kind == "ignored"]


def test_the_written_loop_reads_again_to_the_same_settings(station: object, tmp_path: Path) -> None:
    result = build(station, write(tmp_path, HEAD + LOOP + TAIL))
    out = tmp_path / "out"
    out.mkdir()
    for name, text in result.files.items():
        (out / name).write_text(text)
    again = load_krl(out / "cell.src").program
    source = load_krl(tmp_path / "in" / "cell.src").program
    assert kept(again) == kept(source) == LOOP_LINES
    assert [m.speed for m in again.motions()] == [m.speed for m in source.motions()]


def test_a_loop_before_a_motion_with_the_controllers_settings_stays_a_loop(
    station: object, tmp_path: Path
) -> None:
    """After a call of a routine olp did not read, the motion runs with the controller's
    settings: the statements olp absorbed before it are kept as written, and this loop was kept
    as its body alone (``$VEL_AXIS[ax] = 50`` outside any loop). A loop no motion olp models
    follows (there, or at the end of the module) is left out of other posts with a warning."""
    text = (
        "DEF cell( )\nDECL INT ax\nSetup( )\n"
        "FOR ax = 1 TO 6\n  $VEL_AXIS[ax] = 50\nENDFOR\n"
        "PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}\n"
        "FOR ax = 1 TO 6\n  $ACC_AXIS[ax] = 30\nENDFOR\nEND\n"
    )
    path = write(tmp_path, text)
    written = build(station, path).files["cell.src"]
    body = [line.strip() for line in written.splitlines()]
    start = body.index("Setup()")
    assert body[start : start + 9] == [
        "Setup()",
        "FOR ax = 1 TO 6",
        "$VEL_AXIS[ax] = 50",
        "ENDFOR",
        "PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}",
        "FOR ax = 1 TO 6",
        "$ACC_AXIS[ax] = 30",
        "ENDFOR",
        "END",
    ]
    program = load_krl(path).program
    assert not any(n.modelled for n in program if isinstance(n, ir.Verbatim))
    rapid = olp.build(station, path, post="abb", collisions=None)  # type: ignore[arg-type]
    warned = {d.span.line for d in rapid.diagnostics if d.kind == "ignored" and d.span}
    assert warned == {4, 5, 6, 8, 9, 10}


def test_the_motion_after_the_loop_writes_its_settings_again(
    station: object, tmp_path: Path
) -> None:
    """olp holds one joint speed, the smallest axis percent; a loop that sets another percent
    per axis leaves the controller with others than olp checked, even where that smallest one
    does not change: the motion after the loop writes its settings again, olp's values."""
    loops = (
        "FOR ax = 1 TO 6\n  $VEL_AXIS[ax] = 10\nENDFOR\n"
        "PTP {A1 10, A2 -90, A3 90, A4 0, A5 45, A6 0}\n"
        "FOR ax = 1 TO 6\n  $VEL_AXIS[ax] = 10 * ax\nENDFOR\n"
    )
    written = build(station, write(tmp_path, HEAD + loops + TAIL)).files["cell.src"]
    after = written[written.rindex("ENDFOR") : written.index("PTP {A1 30")]
    assert "$VEL_AXIS[6] = 10" in after.splitlines()


def test_a_loop_that_leaves_a_statement_is_still_written_out(tmp_path: Path) -> None:
    """A setting olp keeps as written (an output) in the body: the loop is written out pass by
    pass, as before, with its warning."""
    loop = "FOR ax = 1 TO 2\n  $VEL_AXIS[ax] = 20\n  $OUT[ax] = TRUE\nENDFOR\n"
    result = load_krl(write(tmp_path, HEAD + loop + TAIL))
    assert [n.index for n in result.program if isinstance(n, ir.SetOutput)] == [1, 2]
    assert not kept(result.program)
    (unrolled,) = [i for i in result.ignored if i.span.line == 6]
    assert "written out 2 times" in unrolled.reason


def test_a_loop_over_an_external_axis_is_written_out_at_every_call(tmp_path: Path) -> None:
    """``$VEL_AXIS[7]`` is reported as not lowered: the loop is written out pass by pass, at the
    second call of its routine too, where the report is not made again."""
    text = (
        HEAD.replace("DECL INT ax\n", "")
        + "Slow( )\nPTP {A1 10, A2 -90, A3 90, A4 0, A5 45, A6 0}\nSlow( )\n"
        + TAIL
        + "DEF Slow( )\nDECL INT ax\nFOR ax = 1 TO 7\n  $VEL_AXIS[ax] = 20\nENDFOR\nEND\n"
    )
    result = load_krl(write(tmp_path, text))
    assert not kept(result.program.expanded())
    assert [i.span.line for i in result.ignored if "written out 7 times" in i.reason] == [12]
