"""Rendering a compiled program through a post: the template context, splitting into parts,
and located errors for what cannot be written.

:func:`render` builds the view once (:class:`olp.posts.view.ProgramView`), splits the steps by the
manifest's ``limits`` (finer until ``max_lines_per_file`` holds), and renders each file's
templates in the post's sandbox (:mod:`olp.posts.sandbox`). While a template walks ``steps``, the
step it is on is remembered, so that a number the post refuses (:mod:`olp.posts.numbers`) becomes
an error diagnostic on that instruction's source line; rendering goes on to find every such
number, and :class:`RenderError` carries them all. Nothing is returned while one remains.

Template context (every file)
-----------------------------
``program``
    ``name`` (legal name of this file's program: the whole program, a part, or the main),
    ``source`` (the program's file name without folders, escaped for a comment), ``main`` (the
    main program's name), ``params`` (the program's own parameters,
    :attr:`olp.ir.Program.params`: a post whose manifest says ``program_params: true`` writes
    them; empty in a part and in a split program's main), ``returns`` and ``returns_dims`` (the
    type of the program's result, :attr:`olp.ir.Program.returns`, None for a program without
    one; None in a part), ``language`` (the robot language the program was read from,
    :attr:`olp.ir.Program.language`: the KUKA templates write their INI fold only where it is
    not ``"krl"``, a KRL source's own INI being kept in its statements).
``split``
    True when the program was split (in parts and in the main).
``unit``
    ``name``, ``routine`` (the name of the routine to define: for the whole program or the main
    the option ``entry``, default the program's name; for a part the option ``part_routine``,
    a pattern like ``"{name}_run"``, default the part's name), ``index`` (0 for the whole
    program or the main, k for part k), ``count`` (number of parts, 0 when not split),
    ``is_part``, ``is_main`` (the whole program or the main).
``parts``
    In ``main_files``: the parts in call order, each ``{name, index, routine}``; else empty.
``steps``
    This file's instructions (:class:`olp.posts.view.PostStep`); empty in ``main_files``.
``routines``
    Where the post writes routines (``Post.writes_routines``): the program's routines, each
    a :class:`olp.posts.flow.RoutineSteps` (``routine``: the :class:`olp.ir.Routine`,
    ``steps``: its body as steps); else empty.
``tools`` / ``frames``
    The tools and frames this file's motions use (the main: all of the program's), each a
    :class:`~olp.posts.view.PostTool` / :class:`~olp.posts.view.PostFrame` with a legal unique
    name.
``vendor``
    What the post's ``context_values`` returns for this file (ABB's custom speed and zone data);
    it is given the routines' statements too (their parameters and local declarations as
    ``declare`` steps first).
``modal``
    A :class:`~olp.posts.view.Modal` change tracker: ``modal.changed("cdis", v)``; fresh for
    every file.
``station``, ``robot`` (``station.robot``), ``options``, ``post`` (``name``, ``vendor``).

Output never depends on the locale (Python's ``format`` is locale-independent), nor on hash seeds
(no set iteration reaches the text).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from olp import progress
from olp.compiled import BlockRows, PathBlock, StepBlocks, items_of, pieces
from olp.diagnostics import Diagnostic
from olp.errors import PostError
from olp.ir import is_motion
from olp.posts.flow import RoutineSteps, routine_statements, weave, weave_routines
from olp.posts.rows import PostRows
from olp.posts.text import basename
from olp.posts.view import (
    Allocation,
    Modal,
    Names,
    PostFrame,
    PostStep,
    PostTool,
    ProgramView,
    RowColumns,
)
from olp.transforms.split import SplitLimits, part_names, split_bounds, split_steps

if TYPE_CHECKING:
    from olp.compiled import CompiledProgram, Step
    from olp.posts.base import Post


class RenderError(Exception):
    """What a post could not write: error diagnostics, each on its instruction."""

    def __init__(self, diagnostics: Sequence[Diagnostic]) -> None:
        super().__init__("; ".join(d.message for d in diagnostics))
        self.diagnostics = tuple(diagnostics)


class TrackedSteps(list[PostStep | PostRows | RowColumns]):
    """A file's steps; iterating them tells the post which instruction is being written."""

    def __init__(self, steps: Sequence[PostStep | PostRows | RowColumns], post: Post) -> None:
        super().__init__(steps)
        self.post = post

    def __iter__(self) -> Iterator[PostStep | PostRows | RowColumns]:
        for step in super().__iter__():
            self.post.current_step = step
            yield step
        self.post.current_step = None


_MAX_SPLIT_ROUNDS = 12
"""How often :func:`render` splits finer to meet ``max_lines_per_file`` before it gives up."""


def render(compiled: CompiledProgram, post: Post, name: str | None = None) -> dict[str, str]:
    """Render every file of ``post``: ``{file name: text}``. Raises :class:`RenderError` (with
    located diagnostics) for numbers that cannot be written, PostError for a broken post; writes
    nothing.

    Splits the program into parts when the manifest's ``limits`` ask for it (splitting finer
    until every file has at most ``max_lines_per_file`` lines).
    """
    manifest = post.manifest
    renderer = _Renderer(compiled, post, name)
    limits = manifest.limits
    for _ in range(_MAX_SPLIT_ROUNDS):
        parts = _split(compiled.steps, limits)
        if len(parts) > 1 and compiled.program.has_flow:
            raise RenderError([_no_split(compiled, len(parts))])
        post.problems, post.collecting = [], True
        try:
            files = renderer.render(parts)
        finally:
            post.collecting = False
        if post.problems:
            raise RenderError(_unique(post.problems))
        longest, lines = _longest(files, manifest.line_ending)
        if manifest.limits.max_lines is None or lines <= manifest.limits.max_lines:
            return files
        limits = _finer(limits, parts, lines, manifest.limits.max_lines, longest, renderer)
    raise PostError(f"post {manifest.name!r}: could not meet max_lines_per_file by splitting")


Part = Sequence["Step | BlockRows"]
"""One file's instructions: steps, and rows of toolpath blocks."""


def _split(steps: Sequence[Step], limits: SplitLimits) -> list[Part]:
    """:func:`~olp.transforms.split.split_steps` of ``steps``; a toolpath's rows stay rows of
    its block (:class:`~olp.compiled.BlockRows`), no step made per row."""
    if not isinstance(steps, StepBlocks):
        return list(split_steps(steps, limits))
    motions: list[bool] = []
    written: list[bool] = []
    for item in steps.blocks:
        if isinstance(item, PathBlock):
            motions += [True] * len(item)
            written += [True] * len(item)
        else:
            motions.append(is_motion(item.instruction))
            written.append(not item.skipped)
    return list(pieces(steps.blocks, split_bounds(motions, written, limits)))


def _count(part: Part) -> int:
    """The instructions of ``part`` that are written."""
    return sum(len(s) if isinstance(s, BlockRows) else int(not s.skipped) for s in part)


def _no_split(compiled: CompiledProgram, parts: int) -> Diagnostic:
    message = (
        f"the program would be split into {parts} parts to meet the post's limits, and olp does "
        "not split a program with control flow (a block cannot span two files)"
    )
    return Diagnostic("error", "split", message)


def _unique(found: Sequence[Diagnostic]) -> list[Diagnostic]:
    """One diagnostic per message and instruction (a number written in two files counts once)."""
    seen: set[tuple[str, int | None]] = set()
    out = []
    for diag in found:
        key = (diag.message, diag.index)
        if key not in seen:
            seen.add(key)
            out.append(diag)
    return out


def _longest(files: Mapping[str, str], ending: str) -> tuple[str, int]:
    counts = {f: text.count(ending) + (not text.endswith(ending)) for f, text in files.items()}
    fname = max(counts, key=lambda f: (counts[f], f))
    return fname, counts[fname]


def _finer(
    limits: SplitLimits,
    parts: list[Part],
    lines: int,
    max_lines: int,
    longest: str,
    renderer: _Renderer,
) -> SplitLimits:
    """Tighter instruction limits after a file came out with ``lines`` > ``max_lines``."""
    biggest = max(_count(p) for p in parts)
    if longest in renderer.main_file_names or biggest <= 1:
        raise PostError(
            f"post {renderer.manifest.name!r}: {longest} has {lines} lines, more than "
            f"max_lines_per_file {max_lines}, and splitting cannot make it shorter"
        )
    fewer = max(1, min(biggest - 1, math.floor(biggest * max_lines / lines)))
    return SplitLimits(limits.max_motions, fewer, limits.max_lines)


class _Renderer:
    """Renders one compiled program through one post, for a given split."""

    def __init__(self, compiled: CompiledProgram, post: Post, name: str | None):
        self.compiled = compiled
        self.post = post
        self.manifest = post.manifest
        self.rule = post.NAME_RULE
        self.name = self.rule.legal(name or compiled.program.name)
        self.view = ProgramView(compiled, post)
        self.env = post.environment()
        self.source = post.plain_text(basename(compiled.program.source))
        self.main_file_names: set[str] = set()

    def render(self, parts: list[Part]) -> dict[str, str]:
        split = len(parts) > 1
        rule = self.rule
        unit_names = part_names(self.name, len(parts), rule.legal, rule.max_length) if split else []
        reserved = [*self.post.PREDEFINED_NAMES, *self.post.reserved_names(self.compiled)]
        names = Names(rule, [self.name, *unit_names, *reserved])
        options = self.manifest.options
        entry, routines = entry_names(names, options, self.name, unit_names)
        allocation = self.view.allocate(names)
        if not split:
            out = self._files(self.manifest.files, self._unit(parts[0], allocation, 0, 0, entry))
            progress.advance(_count(parts[0]))
            return out
        main = self._unit((), allocation, 0, len(parts), entry)
        main["parts"] = [
            {"name": n, "index": k + 1, "routine": r}
            for k, (n, r) in enumerate(zip(unit_names, routines, strict=True))
        ]
        main["tools"], main["frames"] = _used(allocation, _everything(self.compiled.steps))
        main_files = self._files(self.manifest.main_files, main)
        self.main_file_names = set(main_files)
        files: dict[str, str] = {}
        for k, (steps, unit_name) in enumerate(zip(parts, unit_names, strict=True)):
            unit = self._unit(steps, allocation, k + 1, len(parts), routines[k], unit_name)
            files.update(self._files(self.manifest.files, unit, clash=files.keys() | main_files))
            progress.advance(_count(steps))
        return {**main_files, **files}

    def _unit(
        self,
        steps: Part,
        allocation: Allocation,
        index: int,
        count: int,
        routine: str,
        unit_name: str | None = None,
    ) -> dict[str, Any]:
        view: Sequence[Any] = self.view.unit_steps(steps, allocation)
        every = view  # a routine's motions are among these
        routines: list[RoutineSteps] = []
        if self.post.WRITES_FLOW and self.compiled.program.has_flow:
            # a program with control flow is rendered from steps only (Post.columns_enabled)
            language = self.compiled.program.language
            own = language is not None and language == self.post.VERBATIM  # write empty arms
            if self.post.writes_routines():
                lines = self.post.comment_node_lines
                routines = weave_routines(self.compiled.program, view, lines, own)
            view = weave(self.compiled.program, view, own)
        program = self.compiled.program
        whole = index == 0
        unit = Unit(
            unit_name or self.name,
            self.name,
            self.source,
            index,
            count,
            routine,
            program.params if whole else (),
            program.returns if whole else None,
            program.returns_dims if whole else (),
            program.language,
            program.exported and whole,
        )
        return unit_context(
            self.post, self.compiled.station, unit, allocation, view, routines, every
        )

    def _files(
        self,
        entries: Sequence[tuple[str, str]],
        context: dict[str, Any],
        clash: Any = frozenset(),
    ) -> dict[str, str]:
        return render_templates(self.post, self.env, entries, context, clash)


@dataclass(frozen=True, slots=True)
class Unit:
    """What a file's context says of its program: ``name`` (this file's program), ``main``
    (the main program's name), ``source`` (escaped), ``index`` (0: the whole program or the
    main, k: part k), ``count`` (parts; 0: not split) and the ``routine`` it defines."""

    name: str
    main: str
    source: str
    index: int
    count: int
    routine: str
    params: tuple[Any, ...] = ()
    """The program's own parameters (:attr:`olp.ir.Program.params`; a streamed build has none:
    a program with parameters is never streamed, as it has flow)."""
    returns: str | None = None
    """The type of the program's result (:attr:`olp.ir.Program.returns`; never streamed)."""
    returns_dims: tuple[Any, ...] = ()
    language: str | None = None
    """The language the program was read from (:attr:`olp.ir.Program.language`; a streamed
    build reads CSV, None)."""
    exported: bool = False
    """The source marks the program visible to other modules (:attr:`olp.ir.Program.exported`;
    the whole program or the main only, never a part)."""


def unit_context(
    post: Post,
    station: Any,
    unit: Unit,
    allocation: Allocation,
    view: Sequence[Any],
    routines: Sequence[RoutineSteps] = (),
    every: Sequence[Any] | None = None,
) -> dict[str, Any]:
    """The template context of one file whose steps are ``view`` (see the module text), with
    the program's ``routines`` where the post writes them; ``every``: the file's steps before
    weaving (a routine's motions among them), for its tools and frames."""
    tools, frames = _used(allocation, view if every is None else every)
    vendor = post.context_values([*routine_statements(routines), *view])
    written = [RoutineSteps(r.routine, TrackedSteps(post.group(r.steps), post)) for r in routines]
    return {
        "program": {
            "name": unit.name,
            "source": unit.source,
            "main": unit.main,
            "params": unit.params,
            "returns": unit.returns,
            "returns_dims": unit.returns_dims,
            "language": unit.language,
            "exported": unit.exported,
        },
        "split": unit.count > 0,
        "unit": {
            "name": unit.name,
            "routine": unit.routine,
            "index": unit.index,
            "count": unit.count,
            "is_part": unit.index > 0,
            "is_main": unit.index == 0,
        },
        "parts": [],
        "steps": TrackedSteps(post.group(view), post),
        "routines": written,
        "tools": tools,
        "frames": frames,
        "vendor": vendor,
        "station": station,
        "robot": station.robot,
        "options": post.manifest.options,
        "post": {"name": post.manifest.name, "vendor": post.manifest.vendor},
    }


def render_templates(
    post: Post,
    env: Any,
    entries: Sequence[tuple[str, str]],
    context: dict[str, Any],
    clash: Any = frozenset(),
) -> dict[str, str]:
    """Each template of ``entries`` (template, file name pattern) rendered in ``env`` with
    ``context`` (a fresh :class:`~olp.posts.view.Modal` each), line endings made the post's:
    ``{file name: text}``. A file name in ``clash`` or written twice is a PostError."""
    import jinja2

    manifest = post.manifest
    files: dict[str, str] = {}
    for template, pattern in entries:
        context["modal"] = Modal()
        post.current_step = None
        try:
            text = env.get_template(template).render(**context)
        except jinja2.TemplateError as exc:
            path = manifest.folder / template
            where = post.current_step
            at = f" (writing {where.source})" if where is not None else ""
            line = _template_line(exc, path)
            raise PostError(f"{path}:{line}: template error{at}: {exc}") from exc
        fname = pattern.format(name=context["program"]["name"])
        if fname in files or fname in clash:
            raise PostError(f"post {manifest.name!r} writes {fname} twice")
        files[fname] = line_endings(text, manifest.line_ending)
    return files


def _template_line(exc: Exception, path: Path) -> int | str:
    """The template line an error came from: syntax errors carry it; for runtime errors Jinja
    rewrites the traceback so that a frame points into the template file."""
    line = getattr(exc, "lineno", None)
    tb = exc.__traceback__
    while tb is not None:
        if Path(tb.tb_frame.f_code.co_filename) == path:
            line = tb.tb_lineno
        tb = tb.tb_next
    return line if line is not None else "?"


def _used(allocation: Allocation, steps: Sequence[Any]) -> tuple[list[PostTool], list[PostFrame]]:
    """The distinct tools and frames of the motions of ``steps`` (steps, a file's view items,
    toolpath blocks or their rows), in order of first use."""
    tools: dict[str, PostTool] = {}
    frames: dict[str, PostFrame] = {}
    for s in steps:
        if isinstance(s, RowColumns):
            tools.setdefault(s.tool_item.name, s.tool_item)
            frames.setdefault(s.frame_item.name, s.frame_item)
        elif isinstance(s, PathBlock):
            named = allocation.blocks.get(s.start)
            if named is not None:
                tools.setdefault(named.tool.name, named.tool)
                frames.setdefault(named.frame.name, named.frame)
        elif s.index in allocation.tools:
            tools.setdefault(allocation.tools[s.index].name, allocation.tools[s.index])
            frames.setdefault(allocation.frames[s.index].name, allocation.frames[s.index])
    return list(tools.values()), list(frames.values())


def _everything(steps: Sequence[Step]) -> Sequence[Any]:
    """The steps and toolpath blocks of a whole program."""
    return items_of(steps)


def line_endings(text: str, ending: str) -> str:
    """``text`` with every line's trailing blanks dropped and lines ended by ``ending``."""
    lines = text.replace("\r\n", "\n").split("\n")
    return ending.join(line.rstrip() for line in lines)


def entry_names(
    names: Names, options: Mapping[str, Any], name: str, unit_names: Sequence[str]
) -> tuple[str, list[str]]:
    """The program's entry routine name (the post option ``entry``, else ``name``) and each
    part's routine name (the option ``part_routine``, a ``{name}`` pattern, else the part's),
    taken from ``names`` in this order (a streamed build takes them as the whole render does)."""
    entry = names.take(str(options["entry"])) if "entry" in options else name
    routines = [
        names.take(str(options.get("part_routine", "{name}")).format(name=n))
        if "part_routine" in options
        else n
        for n in unit_names
    ]
    return entry, routines
