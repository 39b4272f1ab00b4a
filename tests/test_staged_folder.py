"""StagedFolder: output written piece by piece replaces the folder only when committed."""

from __future__ import annotations

from pathlib import Path

import pytest

from olp.errors import UsageError
from olp.output import MANIFEST, StagedFolder, write_folder


def test_pieces_appear_only_on_commit(tmp_path: Path) -> None:
    out = tmp_path / "out"
    write_folder({"A.src": b"old", "A_P1.src": b"old part"}, out)
    (out / "mine.txt").write_bytes(b"the user's")
    staged = StagedFolder(out)
    with staged.create("A.src") as handle:
        handle.write(b"new ")
        assert (out / "A.src").read_bytes() == b"old"
        handle.write(b"text")
    scratch = staged.scratch()
    scratch.write_bytes(b"working")
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "A.src", "A_P1.src", "mine.txt"]
    written = staged.commit()
    assert written == [out / "A.src"]
    assert (out / "A.src").read_bytes() == b"new text"
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "A.src", "mine.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_discard_leaves_the_old_folder_and_no_staging(tmp_path: Path) -> None:
    out = tmp_path / "out"
    write_folder({"A.src": b"old"}, out)
    staged = StagedFolder(out)
    with staged.create("A.src") as handle:
        handle.write(b"half")
    staged.discard()
    staged.discard()
    assert (out / "A.src").read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_a_name_twice_or_not_plain_is_refused(tmp_path: Path) -> None:
    staged = StagedFolder(tmp_path / "out")
    try:
        staged.add("A.src", b"a")
        with pytest.raises(UsageError, match="twice"):
            staged.add("A.src", b"b")
        with pytest.raises(UsageError, match="plain file name"):
            staged.create("../A.src")
    finally:
        staged.discard()
    assert not (tmp_path / "out").exists()
