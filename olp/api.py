"""The library API: ``olp.build(station, program, post="kuka")`` does what ``olp build`` does.

Stages, each a plain function: :func:`load_station`, :func:`parse` (file -> ir.Program),
:func:`compile` (resolve + timing -> CompiledProgram), :func:`render` / :func:`build`.
"""

from __future__ import annotations

import builtins
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from olp.diagnostics import Diagnostic, has_errors
from olp.errors import UsageError
from olp.ir import Program
from olp.passes.resolve import CompiledProgram, ResolveOptions, resolve
from olp.station.loader import load_station as _load_station
from olp.station.model import Station


def load_station(path: str | Path) -> Station:
    """Load a station YAML file (see :mod:`olp.station.loader`)."""
    return _load_station(path)


@dataclass(frozen=True, slots=True)
class ParsedProgram:
    """A program and what its frontend noted (e.g. KRL lines it read but does not lower)."""

    program: Program
    notes: tuple[Diagnostic, ...] = ()


def parse(path: str | Path) -> ParsedProgram:
    """Read a program file; the frontend is chosen by suffix (``.src`` KRL)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".src":
        from olp.frontends.krl import load_krl

        result = load_krl(path)
        notes = tuple(
            Diagnostic("info", "ignored", f"line not lowered: {item.reason}", item.span)
            for item in result.ignored
        )
        return ParsedProgram(result.program, notes)
    raise UsageError(f"{path}: unknown program type {suffix!r} (supported: .src)")


def compile(
    program: Program, station: Station, options: ResolveOptions | None = None
) -> CompiledProgram:
    """Resolve and time ``program`` on ``station``. Never raises on a bad program."""
    from olp.passes.timing import time_program

    compiled = resolve(program, station, options)
    return time_program(compiled) if compiled.ok else compiled


@dataclass(frozen=True, slots=True)
class BuildResult:
    """What a build produced: the compiled program, rendered files and where they went."""

    compiled: CompiledProgram
    post: str
    diagnostics: tuple[Diagnostic, ...]
    files: Mapping[str, str] = field(default_factory=dict)
    written: tuple[Path, ...] = ()

    @property
    def ok(self) -> bool:
        return not has_errors(self.diagnostics)


def build(
    station: Station | str | Path,
    program: Program | str | Path,
    post: str = "kuka",
    out_dir: str | Path | None = None,
    name: str | None = None,
) -> BuildResult:
    """Compile ``program`` on ``station`` and render it through ``post``.

    Files are written to ``out_dir`` (if given) only when no error diagnostic remains.
    """
    from olp.post import find_post, render, write_files

    if not isinstance(station, Station):
        station = load_station(station)
    notes: tuple[Diagnostic, ...] = ()
    if not isinstance(program, Program):
        parsed = parse(program)
        program, notes = parsed.program, parsed.notes
    manifest = find_post(post)
    compiled = compile(program, station)
    diagnostics = notes + compiled.diagnostics
    if not compiled.ok:
        return BuildResult(compiled, manifest.name, diagnostics)
    from importlib import import_module

    vendor = import_module(f"olp.vendors.{manifest.vendor}") if manifest.vendor else None
    extra: builtins.list[Diagnostic] = getattr(vendor, "post_diagnostics", lambda _c: [])(compiled)
    diagnostics = diagnostics + tuple(extra)
    if has_errors(diagnostics):
        return BuildResult(compiled, manifest.name, diagnostics)
    files = render(compiled, manifest, name)
    written: builtins.list[Path] = []
    if out_dir is not None:
        written = write_files(files, Path(out_dir), manifest.encoding)
    return BuildResult(compiled, manifest.name, diagnostics, files, tuple(written))
