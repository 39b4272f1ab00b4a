"""The library API: ``olp.build(station, program, post="kuka")`` does what ``olp build`` does.

Stages, each a plain function: :func:`load_station`, :func:`parse` (file -> ir.Program),
:func:`compile` (resolve + timing -> CompiledProgram), :func:`render` / :func:`build`.
"""

from __future__ import annotations

import builtins
import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from olp.diagnostics import Diagnostic, has_errors
from olp.errors import UsageError
from olp.frontends import ParsedProgram, check_options, frontend_for
from olp.ir import Program
from olp.passes.collide import CollisionOptions
from olp.passes.resolve import CompiledProgram, ResolveOptions, resolve
from olp.station.loader import load_station as _load_station
from olp.station.model import Station

if TYPE_CHECKING:
    from olp.posts.base import Post


def load_station(path: str | Path) -> Station:
    """Load a station YAML file (see :mod:`olp.station.loader`)."""
    return _load_station(path)


def parse(
    path: str | Path, *, station: Station | None = None, options: object | None = None
) -> ParsedProgram:
    """Read a program file with the frontend of its suffix (see :mod:`olp.frontends`).

    ``options``: that frontend's options (its ``Options`` dataclass, e.g.
    :class:`~olp.frontends.bundled.CsvOptions` for a ``.csv`` toolpath,
    :class:`~olp.frontends.bundled.KrlOptions` for a ``.src`` program,
    :class:`~olp.frontends.bundled.DslOptions` for a ``.py`` program); None: its defaults.
    Another frontend's options are a :class:`UsageError` rather than silently unused.
    ``station``: what CSV and Python programs may consult (tools and frames by name, the home
    position, feasibility questions). A ``.py`` program is code: it runs (with the caller's
    rights) in a child process, killed after ``DslOptions.timeout`` seconds; see
    :mod:`olp.frontends.dsl_process`.
    """
    path = Path(path)
    frontend = frontend_for(path)
    return frontend.load(path, check_options(frontend, options, path), station)


_DEFAULT_COLLISIONS = CollisionOptions()
"""Collision checks run by default (pass ``collisions=None`` to skip them)."""


def compile(
    program: Program,
    station: Station,
    options: ResolveOptions | None = None,
    *,
    collisions: CollisionOptions | None = _DEFAULT_COLLISIONS,
    other_times: Mapping[str, float] | None = None,
) -> CompiledProgram:
    """Resolve, check collisions and time ``program`` on ``station``. Never raises on a bad
    program. ``collisions``: options of the collision check (default options if not given),
    or None to skip it; ``other_times``: seconds per non-motion instruction kind (see
    :data:`olp.passes.timing.DEFAULT_TIMES`)."""
    from olp.passes.timing import time_program

    compiled = resolve(program, station, options)
    if collisions is not None:
        from olp.passes.collide import check_collisions

        found = tuple(check_collisions(compiled, collisions))
        compiled = dataclasses.replace(compiled, diagnostics=compiled.diagnostics + found)
    return time_program(compiled, other_times) if compiled.ok else compiled


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
    post: str | Post = "kuka",
    out_dir: str | Path | None = None,
    name: str | None = None,
    *,
    options: ResolveOptions | None = None,
    program_options: object | None = None,
    collisions: CollisionOptions | None = _DEFAULT_COLLISIONS,
) -> BuildResult:
    """Compile ``program`` on ``station`` and render it through ``post``.

    ``options`` set the checks (e.g. ``ResolveOptions(skip_unreachable=True)``);
    ``program_options`` are the frontend's options for reading ``program`` when it is a file
    (see :func:`parse`; e.g. ``CsvOptions(frame="table")``, ``DslOptions(params={"SIDES": 6})``).
    Files are written to ``out_dir`` (if given) only when no error diagnostic remains.
    """
    from olp.posts import find_post
    from olp.posts.base import Post
    from olp.posts.render import RenderError

    if out_dir is not None:
        from olp.output import check_output_folder

        check_output_folder(out_dir)
    if not isinstance(station, Station):
        station = load_station(station)
    notes: tuple[Diagnostic, ...] = ()
    if not isinstance(program, Program):
        parsed = parse(program, station=station, options=program_options)
        program, notes = parsed.program, parsed.notes
    elif program_options is not None:
        raise UsageError("program_options are for reading a program file, not an ir.Program")
    writer = post if isinstance(post, Post) else find_post(post)
    compiled = compile(program, station, options, collisions=collisions)
    diagnostics = notes + compiled.diagnostics
    if not compiled.ok:
        return BuildResult(compiled, writer.name, diagnostics)
    compiled, prepared = writer.prepare(compiled)
    diagnostics = diagnostics + tuple(prepared) + tuple(writer.check(compiled))
    if has_errors(diagnostics):
        return BuildResult(compiled, writer.name, diagnostics)
    try:
        files = writer.render(compiled, name)
    except RenderError as exc:
        return BuildResult(compiled, writer.name, diagnostics + exc.diagnostics)
    written: builtins.list[Path] = []
    if out_dir is not None:
        written = writer.write(files, Path(out_dir))
    return BuildResult(compiled, writer.name, diagnostics, files, tuple(written))
