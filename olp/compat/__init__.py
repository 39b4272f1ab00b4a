"""RoboDK's Python API for the programs olp runs: ``robolink``, ``robodk`` and the newer
``robodk.robolink`` / ``robodk.robomath`` / ``robodk.robofileio`` / ``robodk.robodialogs``.

These names are importable **only inside a program olp runs** (:func:`importable`, entered by
:func:`olp.frontends.dsl.run_dsl` around the program): a finder placed first on
:data:`sys.meta_path` for the length of the run maps each RoboDK module name to its module here,
so a script written for RoboDK runs unchanged, even where a real RoboDK package is installed,
and nothing is written to site-packages. After the run the names are gone again.

The modules live in :mod:`olp.compat.robodk`; what each call does on olp (and what it cannot do
offline) is listed in ``docs/robodk.md``.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from types import ModuleType

ALIASES: dict[str, str] = {
    "robolink": "olp.compat.robodk.robolink",
    "robodk": "olp.compat.robodk",
    "robodk.robolink": "olp.compat.robodk.robolink",
    "robodk.robomath": "olp.compat.robodk.robomath",
    "robodk.robofileio": "olp.compat.robodk.robofileio",
    "robodk.robodialogs": "olp.compat.robodk.robodialogs",
}
"""The module name a RoboDK script imports -> the module of olp that answers it."""


class _AliasLoader(importlib.abc.Loader):
    """Loads a RoboDK module name as the (already importable) olp module behind it."""

    def __init__(self, target: str) -> None:
        self.target = target

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        return importlib.import_module(self.target)

    def exec_module(self, module: ModuleType) -> None:
        """The olp module is imported already: nothing to run."""


class _AliasFinder(importlib.abc.MetaPathFinder):
    """Finds exactly the names of :data:`ALIASES`, nothing else."""

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        real = ALIASES.get(fullname)
        if real is None:
            return None
        is_package = real == "olp.compat.robodk"
        return importlib.machinery.ModuleSpec(fullname, _AliasLoader(real), is_package=is_package)


@contextmanager
def importable() -> Iterator[None]:
    """Let ``import robolink`` (and the other RoboDK names) find olp's modules while the
    block runs; afterwards remove the finder and the names (restoring any module that held a
    name before)."""
    finder = _AliasFinder()
    saved = {name: sys.modules.pop(name) for name in ALIASES if name in sys.modules}
    sys.meta_path.insert(0, finder)
    try:
        yield
    finally:
        if finder in sys.meta_path:
            sys.meta_path.remove(finder)
        for name in ALIASES:
            sys.modules.pop(name, None)
        sys.modules.update(saved)


def note(call: str, reason: str) -> None:
    """Note at the script's line that ``call`` is not (fully) done by olp, and why."""
    from olp import dsl

    dsl.session().note(f"{call}: {reason}")
