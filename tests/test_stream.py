"""A CSV toolpath built in windows (olp.stream) writes what the whole-program build writes, times
it the same, and writes nothing while an error remains."""

from __future__ import annotations

import filecmp
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

import olp
import olp.stream
from olp.diagnostics import Diagnostic
from olp.frontends.csv import CsvOptions
from olp.passes.pipeline import BuildOptions
from olp.passes.timing import TimingOptions
from olp.posts import find_post
from olp.stream import renumbered, window_rows

ROOT = Path(__file__).resolve().parents[1]
CELL = ROOT / "stations" / "kr6_milling_cell.yaml"

# Reader blocks of ~1,400 rows and windows of at least 2,000 rows: several windows, cut
# inside the post's parts (5,000 motions each) and inside the resolve pass's batches.
BLOCK_BYTES = 40_000
WINDOW = 2_000


@pytest.fixture(scope="module")
def station() -> olp.Station:
    return olp.load_station(CELL)


def helix_csv(
    path: Path,
    points: int,
    speeds: bool = True,
    turns: float = 2.0,
    pair: tuple[float, float] = (50.0, 80.0),
) -> Path:
    """A helix in the table frame (mm), with a speed column that changes every 1,500 rows
    between the two speeds of ``pair`` (mm/s)."""
    t = np.linspace(0.0, 2.0 * np.pi * turns, points)
    xyz = np.c_[100 + 60 * np.cos(t), 60 * np.sin(t), 20 + np.linspace(0.0, 30.0, points)]
    if speeds:
        speed = np.where((np.arange(points) // 1500) % 2 == 0, *pair)
        np.savetxt(path, np.c_[xyz, speed], fmt="%.4f", delimiter=",", header="x,y,z,speed")
    else:
        np.savetxt(path, xyz, fmt="%.4f", delimiter=",", header="x,y,z")
    text = path.read_text().removeprefix("# ")
    path.write_text(text)
    return path


def options(zone: float = 0.0) -> CsvOptions:
    return CsvOptions(
        frame="table", orientation=(180.0, 0.0, 180.0), zone=zone, chunk_bytes=BLOCK_BYTES
    )


def both(
    station: olp.Station,
    csv: Path,
    out: Path,
    post: object = "kuka",
    zone: float = 0.0,
    build: BuildOptions | None = None,
    window: int = WINDOW,
) -> tuple[olp.BuildResult, olp.BuildResult]:
    """The whole-program build and the streamed one, into ``out/whole`` and ``out/windows``."""
    kw = {"program_options": options(zone), "options": build}
    whole = olp.build(station, csv, post, out / "whole", chunk_rows=0, **kw)  # type: ignore[arg-type]
    streamed = olp.build(station, csv, post, out / "windows", chunk_rows=window, **kw)  # type: ignore[arg-type]
    assert whole.streamed is None and streamed.streamed is not None
    assert streamed.streamed.windows >= 3
    return whole, streamed


def same_files(a: Path, b: Path) -> None:
    names = sorted(p.name for p in a.iterdir())
    assert names == sorted(p.name for p in b.iterdir())
    assert len(names) > 3  # a main module and parts
    _, mismatch, errors = filecmp.cmpfiles(a, b, names, shallow=False)
    assert mismatch == [] and errors == []


@pytest.mark.parametrize("points", ["inline", "dat"])
def test_streamed_krl_is_byte_identical_and_timed_the_same(
    station: olp.Station, tmp_path: Path, points: str
) -> None:
    csv = helix_csv(tmp_path / "helix.csv", 12_000)
    post = find_post("kuka", {"points": points})
    whole, streamed = both(station, csv, tmp_path, post)
    assert whole.ok and streamed.ok
    same_files(tmp_path / "whole", tmp_path / "windows")
    assert streamed.streamed is not None
    assert streamed.streamed.cycle_time == pytest.approx(whole.compiled.cycle_time, rel=1e-12)
    assert streamed.streamed.instructions == len(whole.compiled.steps) == 12_000
    assert [d.format() for d in streamed.diagnostics] == [d.format() for d in whole.diagnostics]


def test_a_blended_window_boundary_is_timed_as_in_one_piece(
    station: olp.Station, tmp_path: Path
) -> None:
    """Without the jerk layer (which is chain-wide: one smoothing window, one uniform
    slow-down per chain) the context around a blended boundary gives the one-piece law."""
    csv = helix_csv(tmp_path / "helix.csv", 8_000, speeds=False, turns=1.0)
    no_jerk = BuildOptions(timing=TimingOptions(path_jerk=False))
    whole, streamed = both(station, csv, tmp_path, zone=0.5, build=no_jerk)
    assert whole.ok and streamed.ok and streamed.streamed is not None
    assert streamed.streamed.cycle_time == pytest.approx(whole.compiled.cycle_time, rel=1e-6)
    assert not [d for d in streamed.diagnostics if d.kind == "zone_stop"]
    same_files(tmp_path / "whole", tmp_path / "windows")


def test_with_the_jerk_layer_a_blended_toolpath_stays_within_half_a_percent(
    station: olp.Station, tmp_path: Path
) -> None:
    """The jerk layer's chain-wide terms are taken per window (measured: -0.05% to -0.4%)."""
    csv = helix_csv(tmp_path / "helix.csv", 5_000, speeds=False, turns=0.6)
    whole, streamed = both(station, csv, tmp_path, zone=0.5, window=1_000)
    assert streamed.streamed is not None
    assert streamed.streamed.cycle_time == pytest.approx(whole.compiled.cycle_time, rel=5e-3)


def diagnostics(result: olp.BuildResult) -> list[str]:
    return sorted(d.format() for d in result.diagnostics)


def test_streamed_rapid_is_byte_identical_with_each_parts_speed_and_zone_data(
    station: olp.Station, tmp_path: Path
) -> None:
    """Custom speeddata and zonedata (not predefined: v57_5, z0_7) are declared per module
    in order of first use, before its rows; a part that starts inside one speed's run and
    meets the other in a later window declares both, as the whole build does. (Parts of
    2,000 motions, to keep the blended build small.)"""
    csv = helix_csv(tmp_path / "helix.csv", 5_000, pair=(57.5, 83.25))
    post = copied_post(tmp_path, "abb", "max_motions_per_file: 5000", "max_motions_per_file: 2000")
    whole, streamed = both(station, csv, tmp_path, post, zone=0.7, window=1_000)
    assert whole.ok and streamed.ok
    same_files(tmp_path / "whole", tmp_path / "windows")
    part = (tmp_path / "windows" / "helix_P2.mod").read_text()
    assert "speeddata v83_25 :=" in part and "speeddata v57_5 :=" in part
    assert "zonedata z0_7 :=" in part
    assert diagnostics(streamed) == diagnostics(whole)  # tool_load once per tool


def test_streamed_urscript_caps_blends_across_window_boundaries(
    station: olp.Station, tmp_path: Path
) -> None:
    """Every blend of the helix is capped to half the distance to its neighbours; at a
    window boundary the neighbour is in the next window (a window capped alone would stop
    there: r=0), and the program's last move stops."""
    csv = helix_csv(tmp_path / "helix.csv", 4_000)
    whole, streamed = both(station, csv, tmp_path, "ur", zone=0.7, window=1_000)
    assert whole.ok and streamed.ok
    names = sorted(p.name for p in (tmp_path / "whole").iterdir())
    assert names == sorted(p.name for p in (tmp_path / "windows").iterdir())
    for name in names:
        assert (tmp_path / "whole" / name).read_bytes() == (
            tmp_path / "windows" / name
        ).read_bytes()
    capped = [d.format() for d in streamed.diagnostics if d.kind == "blend_capped"]
    assert len(capped) >= 900  # the first MAX_DIAGNOSTICS warnings are kept
    assert (
        capped == [d.format() for d in whole.diagnostics if d.kind == "blend_capped"][: len(capped)]
    )
    too_long = [d.message for d in streamed.diagnostics if d.kind == "program_too_long"]
    assert too_long == [] or too_long[0].startswith("4000 motions")


def test_streamed_urscript_without_blends_has_the_same_diagnostics(
    station: olp.Station, tmp_path: Path
) -> None:
    """``program_too_long`` counts the whole program's motions, once."""
    csv = helix_csv(tmp_path / "helix.csv", 6_000)
    whole, streamed = both(station, csv, tmp_path, "ur")
    assert (tmp_path / "whole" / "helix.script").read_bytes() == (
        tmp_path / "windows" / "helix.script"
    ).read_bytes()
    assert diagnostics(streamed) == diagnostics(whole)
    assert [d.message[:13] for d in streamed.diagnostics if d.kind == "program_too_long"] == [
        "6000 motions "
    ]


def test_streamed_ls_renders_each_part_whole(station: olp.Station, tmp_path: Path) -> None:
    """Fanuc parts (3,000 instructions) are numbered P[1].. each, their /MN lines numbered
    and counted (LINE_COUNT) over the part's whole text: each part is rendered whole from
    its rows, the number of parts (and so their names) counted before."""
    csv = helix_csv(tmp_path / "helix.csv", 12_000)
    whole, streamed = both(station, csv, tmp_path, "fanuc")
    assert whole.ok and streamed.ok
    same_files(tmp_path / "whole", tmp_path / "windows")
    assert sorted(p.name for p in (tmp_path / "windows").iterdir())[-1] == "HELIX_P4.ls"
    assert diagnostics(streamed) == diagnostics(whole)  # the UFRAME/UTOOL notes once


def copied_post(tmp_path: Path, name: str, old: str, new: str) -> object:
    """The bundled post ``name`` from a copy of its folder whose post.yaml says ``new``
    instead of ``old``."""
    folder = tmp_path / f"{name}_copy"
    shutil.copytree(ROOT / "posts" / name, folder)
    manifest = folder / "post.yaml"
    text = manifest.read_text()
    assert old in text
    manifest.write_text(text.replace(old, new))
    return find_post(str(folder))


def test_an_error_in_a_late_window_writes_nothing(station: olp.Station, tmp_path: Path) -> None:
    csv = helix_csv(tmp_path / "helix.csv", 9_000)
    lines = csv.read_text().splitlines()
    lines[7_001] = "900.0,0.0,20.0,50.0"  # out of reach, in the fourth window
    csv.write_text("\n".join(lines) + "\n")
    out = tmp_path / "windows"
    out.mkdir()
    (out / "old.src").write_text("old")
    whole = olp.build(
        station, csv, "kuka", tmp_path / "whole", program_options=options(), chunk_rows=0
    )
    streamed = olp.build(station, csv, "kuka", out, program_options=options(), chunk_rows=WINDOW)
    assert not streamed.ok and streamed.written == ()
    assert sorted(p.name for p in out.iterdir()) == ["old.src"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["helix.csv", "windows"]  # no staging
    errors = [d for d in streamed.diagnostics if d.severity == "error"]
    assert errors and errors[0].span is not None and errors[0].span.line == 7_002
    assert errors[0].index == 7_000
    assert [d.format() for d in errors] == [
        d.format() for d in whole.diagnostics if d.severity == "error"
    ]


def test_window_rows_decides_when_to_stream(
    station: olp.Station, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    csv = helix_csv(tmp_path / "helix.csv", 3_000)
    build = BuildOptions()
    kuka, abb = find_post("kuka"), find_post("abb")
    assert window_rows(csv, kuka, build, None) is None  # small: whole
    assert window_rows(csv, kuka, build, 500) == 500
    assert window_rows(csv, kuka, build, 0) is None
    assert window_rows(csv, abb, build, 500) == 500  # per-file speed data: kept per part
    limit = "max_instructions_per_file: 3000"
    lined = copied_post(tmp_path, "fanuc", limit, limit + "\n  max_lines_per_file: 9999")
    assert window_rows(csv, lined, build, 500) is None  # the whole text's lines counted
    monkeypatch.setattr(olp.stream, "STREAM_ROWS", 2_000)
    assert window_rows(csv, kuka, build, None) == olp.stream.WINDOW_ROWS
    result = olp.build(station, csv, "kuka", tmp_path / "out", program_options=options())
    assert result.ok and result.streamed is not None


def test_instruction_numbers_in_messages_are_the_whole_programs() -> None:
    found = Diagnostic(
        "error", "collision", "moves 3-5: a hits b (first at 10% of move 3)", None, 3
    )
    moved = renumbered(found, 1000)
    assert moved.index == 1003
    assert moved.message == "moves 1003-1005: a hits b (first at 10% of move 1003)"
    assert renumbered(found, 0) is found


def test_the_cli_streams_with_chunk_rows(tmp_path: Path) -> None:
    from olp.cli import main

    csv = helix_csv(tmp_path / "helix.csv", 3_000)
    args = ["build", str(CELL), str(csv), "--frame", "table", "--orientation", "180,0,180"]
    assert main([*args, "-o", str(tmp_path / "a"), "--chunk-rows", "1000", "-q"]) == 0
    assert main([*args, "-o", str(tmp_path / "b"), "--chunk-rows", "0", "-q"]) == 0
    names = sorted(os.listdir(tmp_path / "a"))
    assert names == sorted(os.listdir(tmp_path / "b"))
    for name in names:
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()


def test_progress_shows_the_build_and_each_stage_with_its_rate(
    station: olp.Station, tmp_path: Path
) -> None:
    import io

    from olp import progress

    csv = helix_csv(tmp_path / "helix.csv", 3_000)
    shown = io.StringIO()
    with progress.showing(progress.Reporter(shown)):
        out = tmp_path / "out"
        olp.build(station, csv, "kuka", out, program_options=options(), chunk_rows=WINDOW)
    lines = [line.rsplit("\r\033[K", 1)[-1] for line in shown.getvalue().split("\n")]
    assert any(line.startswith("build") and "rows/s" in line for line in lines)
    for stage in ("read", "resolve", "collide", "time", "write"):
        assert any(line.split()[:1] == [stage] and "3,000 rows in" in line for line in lines)


def test_a_streamed_program_renamed_to_fit_the_language_is_a_warning_as_a_whole_one(
    station: olp.Station, tmp_path: Path
) -> None:
    """A KRL module name has at most 24 characters: the streamed build, like the whole one,
    says that it writes the program under a shorter name (other modules call it by name)."""
    csv = helix_csv(tmp_path / "helix_toolpath_for_the_second_fixture.csv", 12_000)
    results = both(station, csv, tmp_path)
    for result in results:
        (renamed,) = [d for d in result.diagnostics if d.kind == "renamed"]
        assert "written as helix_toolpath_for_the_s:" in renamed.message
