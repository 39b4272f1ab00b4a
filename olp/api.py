"""The library API: ``olp.build(station, program, post="kuka")`` does what ``olp build`` does.

Stages, each a plain function: :func:`load_station`, :func:`parse` (file -> ir.Program),
:func:`compile` (the pass pipeline -> CompiledProgram), :func:`build` (compile, then a post).
"""

from __future__ import annotations

import builtins
import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from olp.compiled import CompiledProgram
from olp.diagnostics import Diagnostic, has_errors
from olp.errors import UsageError
from olp.frontends import ParsedProgram, check_options, frontend_for
from olp.ir import Program
from olp.passes.collide import CollisionOptions
from olp.passes.resolve import ResolveOptions
from olp.station.loader import load_station as _load_station
from olp.station.model import Station

if TYPE_CHECKING:
    from olp.passes.pipeline import BuildOptions, Pass
    from olp.posts.base import Post
    from olp.stream import StreamSummary


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
    from olp.passes.pipeline import PIPELINE, run_passes

    opts = _build_options(options, collisions)
    if other_times is not None:
        opts = dataclasses.replace(opts, other_times=other_times)
    return run_passes(program, station, opts, PIPELINE if passes is None else passes)


def _build_options(
    options: BuildOptions | ResolveOptions | None, collisions: CollisionOptions | object | None
) -> BuildOptions:
    """``options`` as :class:`BuildOptions` (a bare ResolveOptions is its resolve part), with
    ``collisions`` where given."""
    from olp.passes.pipeline import BuildOptions

    if isinstance(options, ResolveOptions):
        options = BuildOptions(resolve=options)
    opts = options or BuildOptions()
    if collisions is not _DEFAULT:
        assert collisions is None or isinstance(collisions, CollisionOptions)
        opts = dataclasses.replace(opts, collisions=collisions)
    return opts


@dataclass(frozen=True, slots=True)
class BuildResult:
    """What a build produced: the compiled program, rendered files and where they went.

    A streamed build (:mod:`olp.stream`) holds no steps in ``compiled`` and no ``files`` (the
    text went to disk window by window); ``streamed`` summarises it.
    """

    compiled: CompiledProgram
    post: str
    diagnostics: tuple[Diagnostic, ...]
    files: Mapping[str, str] = field(default_factory=dict)
    written: tuple[Path, ...] = ()
    streamed: StreamSummary | None = None

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
    program_options: object | None = None,
    collisions: CollisionOptions | object | None = _DEFAULT,
    passes: tuple[Pass, ...] | None = None,
    chunk_rows: int | None = None,
) -> BuildResult:
    """Compile ``program`` on ``station`` and render it through ``post``.

    ``options``, ``passes`` and ``collisions`` as for :func:`compile` (e.g.
    ``BuildOptions(resolve=ResolveOptions(skip_unreachable=True))``); ``program_options`` are
    the frontend's options for reading ``program`` when it is a file (see :func:`parse`; e.g.
    ``CsvOptions(frame="table")``, ``DslOptions(params={"SIDES": 6})``).
    Files are written to ``out_dir`` (if given) only when no error diagnostic remains.
    ``chunk_rows``: a CSV toolpath written to ``out_dir`` through a post that streams is built
    in windows of this many rows, in bounded memory (:mod:`olp.stream`); None: so from
    :data:`olp.stream.STREAM_ROWS` rows on; 0: never.
    """
    from olp.posts import find_post
    from olp.posts.base import Post
    from olp.posts.render import RenderError

    if out_dir is not None:
        from olp.output import check_output_folder

        check_output_folder(out_dir)
    if not isinstance(station, Station):
        station = load_station(station)
    writer = post if isinstance(post, Post) else find_post(post)
    if not isinstance(program, Program) and out_dir is not None and passes is None:
        from olp.stream import build_streamed, window_rows

        opts = _build_options(options, collisions)
        rows = window_rows(Path(program), writer, opts, chunk_rows)
        if rows is not None:
            csv_options = check_options(frontend_for(Path(program)), program_options, Path(program))
            return build_streamed(
                station, Path(program), writer, Path(out_dir), name, opts, csv_options, rows
            )
    notes: tuple[Diagnostic, ...] = ()
    if not isinstance(program, Program):
        from olp import progress

        with progress.stage("read"):
            parsed = parse(program, station=station, options=program_options)
        program, notes = parsed.program, parsed.notes
    elif program_options is not None:
        raise UsageError("program_options are for reading a program file, not an ir.Program")
    compiled = compile(program, station, options, passes=passes, collisions=collisions)
    diagnostics = notes + compiled.diagnostics
    if not compiled.ok:
        return BuildResult(compiled, writer.name, diagnostics)
    # The post walks the steps several times: a toolpath's rows are made into steps once here,
    # unless its row writer takes them as columns (Post.render_form).
    compiled, prepared = writer.prepare(writer.render_form(compiled))
    checked = [*prepared, *writer.check(compiled), *writer.renamed(compiled.program, name)]
    diagnostics = diagnostics + tuple(checked)
    if has_errors(diagnostics):
        return BuildResult(compiled, writer.name, diagnostics)
    from olp import progress

    with progress.stage("write", len(compiled.steps)):
        try:
            files = writer.render(compiled, name, prepared=True)
        except RenderError as exc:
            return BuildResult(compiled, writer.name, diagnostics + exc.diagnostics)
        written: builtins.list[Path] = []
        if out_dir is not None:
            written = writer.write(files, Path(out_dir))
    return BuildResult(compiled, writer.name, diagnostics, files, tuple(written))
