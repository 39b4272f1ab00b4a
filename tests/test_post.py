"""The generic post: manifests, locale-free numbers, atomic writes that leave nothing half-done."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from olp.errors import PostError, UsageError
from olp.post import available_posts, find_post, num, write_files


def test_kuka_is_listed_and_loads() -> None:
    assert "kuka" in available_posts()
    manifest = find_post("kuka")
    assert manifest.vendor == "kuka" and manifest.line_ending == "\r\n"
    assert [name for _, name in manifest.files] == ["{name}.src", "{name}.dat"]


def test_a_user_folder_works_as_a_post(tmp_path: Path) -> None:
    folder = tmp_path / "kuka_line3"
    shutil.copytree(find_post("kuka").folder, folder)
    assert find_post(str(folder)).folder == folder


def test_unknown_post_names_the_known_ones() -> None:
    with pytest.raises(UsageError, match="kuka"):
        find_post("nope")


@pytest.mark.parametrize(
    ("value", "decimals", "text"),
    [
        (0.0, 3, "0.000"),
        (-0.0, 3, "0.000"),
        (-0.0004, 3, "0.000"),
        (-0.0005, 3, "-0.001"),
        (1234.56789, 2, "1234.57"),
        (1e-12, 5, "0.00000"),
    ],
)
def test_num_is_fixed_point_without_negative_zero(value: float, decimals: int, text: str) -> None:
    assert num(value, decimals) == text


def test_write_files_is_all_or_nothing_on_encoding_errors(tmp_path: Path) -> None:
    with pytest.raises(PostError, match="cannot be written in ascii"):
        write_files({"a.src": "fine\n", "b.src": "caf\u00e9\n"}, tmp_path / "out", "ascii")
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_write_files_replaces_atomically_and_leaves_no_temp_files(tmp_path: Path) -> None:
    out = tmp_path / "out"
    write_files({"a.src": "one\n"}, out)
    write_files({"a.src": "two\n"}, out)
    assert (out / "a.src").read_text() == "two\n"
    assert sorted(p.name for p in out.iterdir()) == ["a.src"]
