"""What a post's templates see: modal-state tracking (and, with the post classes, the view of
every compiled step)."""

from __future__ import annotations

from typing import Any

import numpy as np


class Modal:
    """Tracks modal controller state while a template is rendered.

    ``changed(key, value)`` is True when ``value`` differs from the last value recorded under
    ``key`` (or none was), and records it. Arrays compare by value, tools and frames by name
    and pose.
    """

    def __init__(self) -> None:
        self._last: dict[str, Any] = {}

    def changed(self, key: str, value: Any) -> bool:
        return changed(self._last, key, value)

    def forget(self, key: str) -> str:
        """Drop ``key`` (e.g. after a call that may change the state); renders as ''."""
        self._last.pop(key, None)
        return ""


def changed(last: dict[str, Any], key: str, value: Any) -> bool:
    """Whether ``value`` differs from ``last[key]`` (or there is none); records it."""
    same = key in last and _same(last[key], value)
    last[key] = value
    return not same


def _same(a: Any, b: Any) -> bool:
    if hasattr(a, "pose") and hasattr(b, "pose"):
        return bool(a.name == b.name and np.array_equal(a.pose, b.pose))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return bool(np.array_equal(a, b))
    return bool(a == b)
