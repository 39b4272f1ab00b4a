"""Frontends: read a robot program (KUKA KRL, CSV, Python) and lower it to an ``ir.Program``.

Every frontend has one shape, :class:`Frontend`: a name, the file suffixes it reads, its options
type (a frozen dataclass whose fields may carry a command-line flag, see
:mod:`olp.frontends.options`) and one ``load`` function. :func:`olp.parse` picks the frontend by
the file's suffix, and the ``olp`` commands build their program options from the same table, so
a new input language is one module and one line in :data:`REGISTRY` (or an entry point in the
group ``olp.frontends`` of an installed package): no edit of the API or the command line.

The bundled frontends are declared in :mod:`olp.frontends.bundled` (light to import); their
readers are :mod:`olp.frontends.krl`, :mod:`olp.frontends.csv` and :mod:`olp.frontends.dsl`.
"""

from __future__ import annotations

import functools
import importlib
import sys
from collections.abc import Sequence
from dataclasses import dataclass, is_dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from olp.errors import UsageError

if TYPE_CHECKING:
    from importlib.metadata import EntryPoint

    from olp.diagnostics import Diagnostic, Severity
    from olp.ir import Program, SourceSpan
    from olp.station.model import Station


@dataclass(frozen=True, slots=True)
class ParsedProgram:
    """A program and what its frontend noted (e.g. KRL lines it read but does not lower)."""

    program: Program
    notes: tuple[Diagnostic, ...] = ()


class Frontend(Protocol):
    """One input language.

    ``NAME``: its registry name; ``TITLE``: what its programs are called in messages and help
    ("KRL programs"); ``SUFFIXES``: the file suffixes it reads, lower case with the dot;
    ``Options``: a frozen dataclass, every field defaulted (``Options()`` are the defaults);
    ``load``: read ``path`` with ``options`` (an ``Options``), consulting ``station`` where the
    language needs one (tool names, the home position). Bad input raises an
    :class:`~olp.errors.OlpError` with its span.
    """

    NAME: str
    TITLE: str
    SUFFIXES: tuple[str, ...]
    Options: type[Any]

    def load(self, path: Path, options: Any, station: Station | None) -> ParsedProgram: ...


REGISTRY: dict[str, Any] = {
    "krl": "olp.frontends.bundled:KrlFrontend",
    "csv": "olp.frontends.bundled:CsvFrontend",
    "python": "olp.frontends.bundled:PythonFrontend",
}
"""Frontend name -> the frontend (an object or class as :class:`Frontend`), or
``"module:attr"`` for one imported on first use. A class is instantiated without arguments."""

ENTRY_POINT_GROUP = "olp.frontends"


def frontends() -> dict[str, Frontend]:
    """Every frontend by name: the registry's, then installed packages' (a registered name is
    never replaced by an installed one)."""
    found = {name: _frontend(name, entry) for name, entry in REGISTRY.items()}
    for name, entry in _entry_points().items():
        if name not in found:
            found[name] = _frontend(name, entry)
    return found


def frontend_for(path: str | Path) -> Frontend:
    """The frontend that reads ``path``, by its suffix (any case); the first one that declares
    the suffix wins. A :class:`~olp.errors.UsageError` for a suffix none reads."""
    suffix = Path(path).suffix.lower()
    known = frontends()
    for frontend in known.values():
        if suffix in frontend.SUFFIXES:
            return frontend
    supported = ", ".join(s for f in known.values() for s in f.SUFFIXES)
    raise UsageError(f"{path}: unknown program type {suffix!r} (supported: {supported})")


def describe(frontend: Frontend) -> str:
    """``"KRL programs (.src)"``: a frontend's title and suffixes, for messages."""
    return f"{frontend.TITLE} ({', '.join(frontend.SUFFIXES)})"


def check_options(frontend: Frontend, options: object | None, path: str | Path) -> Any:
    """``options`` if they are ``frontend``'s, its defaults if None; else a
    :class:`~olp.errors.UsageError` naming both the options and the program's frontend."""
    if options is None:
        return frontend.Options()
    if isinstance(options, frontend.Options):
        return options
    owner = next((f for f in frontends().values() if isinstance(options, f.Options)), None)
    whose = f" (the options of {owner.TITLE})" if owner is not None else ""
    raise UsageError(
        f"{path}: {describe(frontend)} take {frontend.Options.__name__}, "
        f"not {type(options).__name__}{whose}"
    )


def _frontend(name: str, entry: Any) -> Frontend:
    if isinstance(entry, str):
        module, _, attr = entry.partition(":")
        entry = getattr(importlib.import_module(module), attr)
    if isinstance(entry, type):
        entry = entry()
    if not _is_frontend(entry):
        raise UsageError(
            f"frontend {name!r} is registered as {entry!r}, which lacks NAME, TITLE, SUFFIXES, "
            "an Options dataclass or load"
        )
    return entry


def _is_frontend(entry: object) -> bool:
    options = getattr(entry, "Options", None)
    suffixes = getattr(entry, "SUFFIXES", None)
    return (
        all(isinstance(getattr(entry, a, None), str) for a in ("NAME", "TITLE"))
        and isinstance(suffixes, tuple)
        and all(isinstance(s, str) and s.startswith(".") and s == s.lower() for s in suffixes)
        and isinstance(options, type)
        and is_dataclass(options)
        and callable(getattr(entry, "load", None))
    )


def _entry_points() -> dict[str, Any]:
    found: dict[str, Any] = {}
    for ep in _installed(tuple(sys.path)):
        try:
            found.setdefault(ep.name, ep.load())
        except Exception as exc:  # an installed package's import error: name it, do not crash
            msg = f"installed frontend {ep.name!r} ({ep.value}) failed to load: {exc}"
            raise UsageError(msg) from exc
    return found


@functools.lru_cache(maxsize=4)
def _installed(path: tuple[str, ...]) -> tuple[EntryPoint, ...]:
    """The group's entry points on ``path``: one scan of the installed packages per
    ``sys.path`` (a scan reads every package's metadata; a command looks several times)."""
    from importlib.metadata import entry_points

    del path  # the cache key: entry_points() reads sys.path itself
    return tuple(entry_points(group=ENTRY_POINT_GROUP))


class _Ignored(Protocol):
    """What every frontend reports for a line it read but did not lower."""

    @property
    def span(self) -> SourceSpan: ...

    @property
    def reason(self) -> str: ...


def ignored_notes(
    ignored: Sequence[_Ignored],
    severity: Severity = "info",
    prefix: str = "line not lowered",
) -> tuple[Diagnostic, ...]:
    """Diagnostics for what a frontend read but did not lower: ``"warning"`` where the
    statement is then missing from the output (nothing is dropped silently), ``"info"`` for
    what never belonged in it (a data list's type definitions)."""
    from olp.diagnostics import Diagnostic

    return tuple(
        Diagnostic(severity, "ignored", f"{prefix}: {item.reason}", item.span) for item in ignored
    )
