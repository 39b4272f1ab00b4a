"""One program built through several posts compiles once: :class:`CompileOnce`.

The tests that compare posts (columns against templates, dense against plain moves) build the
same program on the same station through several posts; :func:`olp.build` compiles it each
time, and the compile (resolve, collisions, timing) is most of a build and does not depend on
the post. Inside a ``with CompileOnce():`` block, ``olp.build`` compiles a program once and
renders that compiled program through each post. Safe because the IR and the compiled
program are frozen and the passes deterministic; arguments are matched by identity (the same
objects, kept alive by the memo, so an id is never reused), never by value.
"""

from __future__ import annotations

from types import TracebackType
from typing import Any

import pytest

from olp import api


class CompileOnce:
    """A memo of :func:`olp.api.compile` by the identity of its arguments, active (patched into
    :mod:`olp.api`, where :func:`olp.build` calls it) inside ``with`` blocks; reusable across
    blocks (a module-scoped fixture may hold one)."""

    def __init__(self) -> None:
        self._done: dict[tuple[object, ...], tuple[tuple[Any, ...], Any]] = {}
        self._patch: pytest.MonkeyPatch | None = None
        self.compiled = 0
        """How many compiles ran (the rest came from the memo)."""

    def __enter__(self) -> CompileOnce:
        assert self._patch is None, "CompileOnce is not re-entrant"
        original = api.compile

        def compile_once(*args: Any, **kwargs: Any) -> Any:
            keep = (*args, *kwargs.values())
            key = (*map(id, args), *((name, id(value)) for name, value in sorted(kwargs.items())))
            if key not in self._done:
                self._done[key] = (keep, original(*args, **kwargs))
                self.compiled += 1
            return self._done[key][1]

        self._patch = pytest.MonkeyPatch()
        self._patch.setattr(api, "compile", compile_once)
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        assert self._patch is not None
        self._patch.undo()
        self._patch = None
