"""Shared by the post tests: comparing output with golden files.

``OLP_UPDATE_GOLDEN=1`` rewrites the golden files and then fails on purpose, so an update can
never pass CI unreviewed.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable, Mapping
from pathlib import Path

import pytest

GoldenCheck = Callable[..., None]


def _check_golden(folder: Path, files: Mapping[str, bytes], *, whole_folder: bool = True) -> None:
    """Compare ``files`` (name -> bytes) with ``folder``; ``whole_folder``: the folder holds
    exactly these files (else only the named files are compared)."""
    if os.environ.get("OLP_UPDATE_GOLDEN") == "1":
        if whole_folder:
            shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True, exist_ok=True)
        for name, data in files.items():
            (folder / name).write_bytes(data)
        pytest.fail(f"{folder} updated: review the diff, then run again without OLP_UPDATE_GOLDEN")
    if whole_folder:
        assert sorted(files) == sorted(p.name for p in folder.iterdir())
    for name, data in files.items():
        assert data == (folder / name).read_bytes(), f"{folder.name}/{name} differs from its golden"


@pytest.fixture
def golden() -> GoldenCheck:
    """The golden-file check (see :func:`_check_golden`)."""
    return _check_golden
