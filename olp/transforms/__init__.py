"""Rewrites a target needs, as functions every post can share (STYLE.md: IR -> IR, not template
hacks).

* :mod:`olp.transforms.split`: cut a long program into parts that fit a controller's limits
  (motions or instructions per file); a main program calls the parts in order. Works on an
  :class:`olp.ir.Program` before compiling (:func:`~olp.transforms.split.split_program`) and on
  a compiled program's steps (:func:`~olp.transforms.split.split_steps`, what
  :func:`olp.posts.render.render` uses, so that splitting never changes the planned joints).
* :mod:`olp.transforms.blend`: blend capping (another module, same shape).

A transform never knows a brand: name rules come in as a function (a vendor's ``legal_name``).
"""

from __future__ import annotations

from typing import Any

__all__ = ["SplitLimits", "part_names", "split_bounds", "split_program", "split_steps"]


def __getattr__(name: str) -> Any:
    """The splitting names, imported on first use (``olp posts`` reads limits without numpy)."""
    if name in __all__:
        from olp.transforms import split

        return getattr(split, name)
    raise AttributeError(f"module 'olp.transforms' has no attribute {name!r}")
