"""The README's layout section names every module and package in ``olp/``.

A module added without a line in the layout fails here, so the map a new engineer reads stays the
tree they find.
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _layout_block() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    start = text.index("## Layout")
    block = text[start:]
    return block[block.index("```") + 3 : block.index("```", block.index("```") + 3)]


def _entries() -> list[str]:
    names = []
    for path in sorted((ROOT / "olp").iterdir()):
        if path.name.startswith((".", "__pycache__")) or path.name.endswith(".egg-info"):
            continue
        if path.is_dir() and (path / "__init__.py").exists():
            names.append(path.name + "/")
        elif path.suffix == ".py":
            names.append(path.name)
    return names


def test_every_olp_entry_is_in_the_readme_layout() -> None:
    block = _layout_block()
    words = set(re.findall(r"[\w.]+/?", block))
    missing = [name for name in _entries() if name not in words]
    assert not missing, f"README layout misses {missing}"


def test_the_layout_names_nothing_that_is_gone() -> None:
    block = _layout_block()
    listed = re.findall(r"^  ([\w]+(?:\.py|/))", block, flags=re.MULTILINE)
    gone = [name for name in listed if not (ROOT / "olp" / name.rstrip("/")).exists()]
    assert not gone, f"README layout names {gone}, which olp/ no longer has"
