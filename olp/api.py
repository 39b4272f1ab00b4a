"""The library API: ``olp.build(station, program, post="kuka")`` does what ``olp build`` does.

Stages, each a plain function: :func:`load_station`, :func:`parse` (file -> ir.Program),
:func:`compile` (the pass pipeline -> CompiledProgram), :func:`build` (compile, then a post).
"""

from __future__ import annotations

import builtins
import dataclasses
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from olp.compiled import CompiledProgram
from olp.diagnostics import Diagnostic, has_errors
from olp.errors import UsageError
from olp.frontends.dsl_process import DEFAULT_TIMEOUT as DSL_TIMEOUT
from olp.ir import Program, SourceSpan
from olp.passes.collide import CollisionOptions
from olp.passes.resolve import ResolveOptions
from olp.station.loader import load_station as _load_station
from olp.station.model import Station

if TYPE_CHECKING:
    from olp.frontends.csv import CsvOptions
    from olp.passes.pipeline import BuildOptions, Pass
    from olp.posts.base import Post


def load_station(path: str | Path) -> Station:
    """Load a station YAML file (see :mod:`olp.station.loader`)."""
    return _load_station(path)


@dataclass(frozen=True, slots=True)
class ParsedProgram:
    """A program and what its frontend noted (e.g. KRL lines it read but does not lower)."""

    program: Program
    notes: tuple[Diagnostic, ...] = ()


def parse(
    path: str | Path,
    *,
    station: Station | None = None,
    params: Mapping[str, object] | None = None,
    csv_options: CsvOptions | None = None,
    krl_config_dat: str | Path | None = None,
    timeout: float | None = DSL_TIMEOUT,
) -> ParsedProgram:
    """Read a program file; the frontend is chosen by suffix (see :data:`FRONTENDS`).

    A ``.py`` program is code: it runs (with the caller's rights) in a child process, killed
    after ``timeout`` seconds (None: no limit); see :mod:`olp.frontends.dsl_process`.
    ``station``: what CSV and Python programs may consult (tools and frames by name, the home
    position, feasibility questions); ``params``: ``--set`` values for a Python program;
    ``csv_options``: how to read a CSV toolpath; ``krl_config_dat``: the controller's
    ``$config.dat`` for TOOL_DATA/BASE_DATA/HOME values. Options a frontend does not take are a
    :class:`UsageError` rather than silently unused.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    frontend = FRONTENDS.get(suffix)
    if frontend is None:
        known = ", ".join(FRONTENDS)
        raise UsageError(f"{path}: unknown program type {suffix!r} (supported: {known})")
    if params and suffix != ".py":
        raise UsageError(f"--set parameters are for Python programs, not {suffix} files")
    if csv_options is not None and suffix != ".csv":
        raise UsageError(f"CSV options are for .csv toolpaths, not {suffix} files")
    if krl_config_dat is not None and suffix != ".src":
        raise UsageError(f"--config-dat is for KRL .src programs, not {suffix} files")
    context = _ParseContext(station, params or {}, csv_options, krl_config_dat, timeout)
    return frontend(path, context)


@dataclass(frozen=True, slots=True)
class _ParseContext:
    station: Station | None
    params: Mapping[str, object]
    csv_options: CsvOptions | None
    krl_config_dat: str | Path | None = None
    timeout: float | None = DSL_TIMEOUT


def _parse_krl(path: Path, context: _ParseContext) -> ParsedProgram:
    from olp.frontends.krl import load_krl

    result = load_krl(path, config_dat=context.krl_config_dat)
    remarks = tuple(
        Diagnostic("warning", "krl_note", note.message, note.span) for note in result.notes
    )
    return ParsedProgram(result.program, _ignored_notes(result.ignored) + remarks)


def _parse_csv(path: Path, context: _ParseContext) -> ParsedProgram:
    from olp.frontends.csv import load_csv

    result = load_csv(path, context.csv_options, context.station)
    return ParsedProgram(result.program, _ignored_notes(result.ignored))


def _parse_dsl(path: Path, context: _ParseContext) -> ParsedProgram:
    from olp.frontends.dsl import load_dsl

    result = load_dsl(path, context.station, context.params, timeout=context.timeout)
    warnings = tuple(
        Diagnostic("warning", "program", item.message, item.span) for item in result.warnings
    )
    return ParsedProgram(result.program, _ignored_notes(result.ignored) + warnings)


class _Ignored(Protocol):
    """What every frontend reports for a line it read but did not lower."""

    @property
    def span(self) -> SourceSpan: ...

    @property
    def reason(self) -> str: ...


def _ignored_notes(ignored: Sequence[_Ignored]) -> tuple[Diagnostic, ...]:
    """Info diagnostics for what a frontend read but did not lower."""
    return tuple(
        Diagnostic("info", "ignored", f"line not lowered: {item.reason}", item.span)
        for item in ignored
    )


FRONTENDS: dict[str, Callable[[Path, _ParseContext], ParsedProgram]] = {
    ".src": _parse_krl,
    ".csv": _parse_csv,
    ".py": _parse_dsl,
}
"""Program file suffix -> frontend."""


_DEFAULT = object()
"""Marks a keyword the caller did not give."""


def compile(
    program: Program,
    station: Station,
    options: BuildOptions | ResolveOptions | None = None,
    *,
    passes: tuple[Pass, ...] | None = None,
    collisions: CollisionOptions | object | None = _DEFAULT,
    other_times: Mapping[str, float] | None = None,
) -> CompiledProgram:
    """``program`` on ``station`` through the pass pipeline (resolve, collisions, timing: see
    :mod:`olp.passes.pipeline`); never raises on a bad program.

    ``options``: a :class:`~olp.passes.pipeline.BuildOptions` (a bare
    :class:`~olp.passes.resolve.ResolveOptions` is taken as its ``resolve`` part);
    ``passes``: another pipeline, e.g. with a pass of your own. ``collisions`` (None: no
    collision check) and ``other_times`` override the options' fields where given.
    """
    from olp.passes.pipeline import PIPELINE, BuildOptions, run_passes

    if isinstance(options, ResolveOptions):
        options = BuildOptions(resolve=options)
    opts = options or BuildOptions()
    if collisions is not _DEFAULT:
        assert collisions is None or isinstance(collisions, CollisionOptions)
        opts = dataclasses.replace(opts, collisions=collisions)
    if other_times is not None:
        opts = dataclasses.replace(opts, other_times=other_times)
    return run_passes(program, station, opts, PIPELINE if passes is None else passes)


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
    options: BuildOptions | ResolveOptions | None = None,
    params: Mapping[str, object] | None = None,
    csv_options: CsvOptions | None = None,
    krl_config_dat: str | Path | None = None,
    collisions: CollisionOptions | object | None = _DEFAULT,
    timeout: float | None = DSL_TIMEOUT,
    passes: tuple[Pass, ...] | None = None,
) -> BuildResult:
    """Compile ``program`` on ``station`` and render it through ``post``.

    ``options``, ``passes`` and ``collisions`` as for :func:`compile` (e.g.
    ``BuildOptions(resolve=ResolveOptions(skip_unreachable=True))``); ``params``,
    ``csv_options`` and ``timeout`` (seconds a ``.py`` program may run) go to :func:`parse`
    when ``program`` is a file. Files are written to
    ``out_dir`` (if given) only when no error diagnostic remains.
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
        parsed = parse(
            program,
            station=station,
            params=params,
            csv_options=csv_options,
            krl_config_dat=krl_config_dat,
            timeout=timeout,
        )
        program, notes = parsed.program, parsed.notes
    writer = post if isinstance(post, Post) else find_post(post)
    compiled = compile(program, station, options, passes=passes, collisions=collisions)
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
