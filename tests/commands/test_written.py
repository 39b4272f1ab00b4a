"""The summary's ``written`` line names a few files and counts the rest (issue 11): a split
1M-point build must not print 400 file names."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest

from olp.cli import main
from olp.posts import find_post
from olp.report import WRITTEN_NAMED, written_line

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
MILLING = REPO / "examples" / "milling.src"


def _written(output: str) -> str:
    lines = [line for line in output.splitlines() if line.startswith("written")]
    assert len(lines) == 1, output
    return lines[0].removeprefix("written").strip()


def _build(tmp_path: Path, *options: str) -> list[Path]:
    """``olp build`` job 5; the files it wrote, from its report."""
    report = tmp_path / "report.json"
    assert main(["build", str(CELL), str(MILLING), "--report", str(report), *options]) == 0
    return [Path(p) for p in json.loads(report.read_text(encoding="utf-8"))["files"]]


def _one_motion_per_file(tmp_path: Path) -> Path:
    """The KUKA post, split after every motion: job 5 becomes a main module and 7 parts."""
    folder = tmp_path / "kuka_split"
    shutil.copytree(find_post("kuka").manifest.folder, folder)
    manifest = folder / "post.yaml"
    text = manifest.read_text(encoding="utf-8")
    manifest.write_text(re.sub(r"max_motions_per_file: \d+", "max_motions_per_file: 1", text))
    return folder


def test_a_split_build_names_three_files_and_counts_the_rest(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, post = tmp_path / "out", _one_motion_per_file(tmp_path)
    written = _build(tmp_path, "--post", str(post), "-o", str(out))
    line = _written(capsys.readouterr().out)
    assert len(written) == 16 and all(p.parent == out and p.is_file() for p in written)
    assert line == (
        ", ".join(str(p) for p in written[:WRITTEN_NAMED])
        + f" and {len(written) - WRITTEN_NAMED} more ({len(written)} files) in {out}/"
    )


def test_a_small_build_names_every_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    written = _build(tmp_path, "-o", str(tmp_path / "out"))
    assert _written(capsys.readouterr().out) == ", ".join(str(p) for p in written)
    assert [p.suffix for p in written] == [".src", ".dat"]


@pytest.mark.parametrize(
    ("count", "expected"),
    [
        (1, "out/P0.src"),
        (3, "out/P0.src, out/P1.src, out/P2.src"),
        (4, "out/P0.src, out/P1.src, out/P2.src and 1 more (4 files) in out/"),
        (400, "out/P0.src, out/P1.src, out/P2.src and 397 more (400 files) in out/"),
    ],
)
def test_the_written_line_format(count: int, expected: str) -> None:
    assert written_line([Path("out") / f"P{i}.src" for i in range(count)]) == expected


def test_files_in_no_one_folder_are_counted_without_one() -> None:
    paths = [Path("a/P1.src"), Path("a/P2.src"), Path("b/P3.src"), Path("/abs/P4.src")]
    assert written_line(paths) == "a/P1.src, a/P2.src, b/P3.src and 1 more (4 files)"
