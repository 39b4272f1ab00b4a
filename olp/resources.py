"""Where olp's data files (grammars, posts, stations) live, installed or in a checkout."""

from __future__ import annotations

from pathlib import Path

_PACKAGE_DIR = Path(__file__).resolve().parent


def data_path(*parts: str) -> Path:
    """The path of a shipped data file or folder, e.g. ``data_path("grammars", "krl.lark")``.

    An installed wheel carries the data under ``olp/_data/`` (see ``pyproject.toml``); an editable
    checkout has it at the repository root, beside the ``olp`` package. The installed location wins
    when it exists. The returned path is not checked for existence in the checkout case.
    """
    installed = _PACKAGE_DIR.joinpath("_data", *parts)
    if installed.exists():
        return installed
    return _PACKAGE_DIR.parent.joinpath(*parts)
