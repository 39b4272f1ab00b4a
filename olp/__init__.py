"""olp: an offline-programming compiler for industrial robots.

    import olp
    station = olp.load_station("stations/kr6_milling_cell.yaml")
    result = olp.build(station, "examples/milling.src", post="kuka", out_dir="out")

The public names are loaded on first use, so ``import olp`` (and ``olp --help``) stays fast.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "BuildOptions",
    "BuildResult",
    "build",
    "compile",
    "ir",
    "load_station",
    "parse",
    "posts",
]


def __getattr__(name: str) -> Any:
    if name in {"build", "compile", "load_station", "parse", "BuildResult"}:
        from olp import api

        return getattr(api, name)
    if name == "BuildOptions":
        from olp.passes.pipeline import BuildOptions

        return BuildOptions
    if name == "posts":
        import olp.posts as posts

        return posts
    if name == "ir":
        import olp.ir as ir

        return ir
    raise AttributeError(f"module 'olp' has no attribute {name!r}")
