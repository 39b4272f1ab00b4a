"""A post's files written while the program streams past in windows (:mod:`olp.stream`): the
toolpath's rows go through the post's column writer window by window, straight to disk, and
the templates still frame every file.

How a file is made
------------------
A file (the whole program, or one part of a split one) is a template rendered around its rows.
Its steps are the few ordinary instructions before the toolpath (the joint move to its first
row) and *one* stand-in for all of its rows, :class:`SplicedRows` (a
:class:`~olp.posts.view.RowColumns` of the first piece). Every filter the templates apply to
that stand-in (the post's row writers: ``krl_rows``, ``krl_rows_dat``, ...) is intercepted:

1. when the part's rows begin, its templates are rendered once to *record* those calls (which
   filter, with which further arguments: the file's :class:`~olp.posts.view.Modal`, flags);
2. every window's rows are then given, as :class:`RowColumns`, to each recorded call, and its
   text goes to a scratch file of its own (line endings as the template's text gets them);
3. at the end, when the number of parts and so every name is known, the templates are rendered
   again, each intercepted call leaving a marker (and taking over the modal state the rows
   left), and the file is written as the template's text with each marker replaced by its
   scratch file.

The text is the one :func:`olp.posts.render.render` writes, byte for byte, for a post whose
templates write a run of toolpath rows as the row writer's output per rows item and nothing
between two rows items and compute nothing else in a file from its rows (it says so:
:attr:`~olp.posts.base.Post.STREAMS`; KUKA's, ABB's and UR's do), and without a
``max_lines_per_file`` limit (it needs the whole text): :func:`streams`. What a file's
``vendor`` context takes from its rows (ABB's speeddata and zonedata, declared before the
rows in order of first use) comes from the few rows the post names for it
(:meth:`~olp.posts.base.Post.context_rows`: the first row of each distinct speed and zone),
kept per part while the rows stream past; the context is computed from them when the
part's rows are all written (they are then dropped) and given to the file's render at the
end. The post's ``TRANSFORMS`` are applied to each window by
:mod:`olp.posts.stream_transforms` (UR's blend capping, with the neighbour rows across a
window boundary), where the post lists them (:attr:`~olp.posts.base.Post.WINDOW_TRANSFORMS`).
``tests/test_stream.py`` compares both builds. A template that writes a part's rows other
than through a filter applied to its rows item is a PostError, not a file with one row; a
filter that reads nothing of a rows item (ABB's and UR's indentation inside blocks) says so
(:attr:`~olp.posts.base.Post.STREAM_NEUTRAL_FILTERS`) and runs on the stand-in.

Posts whose templates compute a file's text from all of its rows (Fanuc: ``ls_moves`` over
the file's steps numbers its positions, ``ls_number_lines`` numbers the ``/MN`` lines and
``LINE_COUNT`` counts them) render each part whole instead
(:attr:`~olp.posts.base.Post.STREAM_PARTS`): their manifest bounds a part's instructions
(Fanuc: 3,000), so a part's rows are kept (copied out of their windows) until it is
complete, and it is then rendered as the whole build renders it. A part's text holds its
name, which depends on the number of parts (``_P1`` or ``_P01``), so that number is
counted first, by a pass that only reads the file (:func:`count_parts`); a program that
comes out in another number of parts is a PostError. A ``max_lines_per_file`` limit is
still checked on the whole text only: such a post builds whole.

Names: point names of toolpath rows follow the post's ``point_names`` pattern without being
kept in memory; the few names taken besides them (the program's, its parts', tools, frames,
the first motion's point) are taken as the whole-program render takes them, and a name that
would come out differently once the part names are known is a PostError rather than a
different text.
"""

from __future__ import annotations

import dataclasses
import re
import shutil
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO, TypeVar

import numpy as np
from numpy.typing import NDArray

from olp.compiled import BlockRows, CompiledProgram, PathBlock, Step, items_of
from olp.errors import PostError
from olp.ir import LinearPath, Program, is_motion
from olp.posts.base import Post, _bind
from olp.posts.render import (
    RenderError,
    Unit,
    _unique,
    _used,
    entry_names,
    line_endings,
    render_templates,
    unit_context,
)
from olp.posts.sandbox import PostSandbox, SafeText, make_environment
from olp.posts.text import basename
from olp.posts.view import (
    Allocation,
    BlockMotions,
    Modal,
    Names,
    PostFrame,
    PostStep,
    PostTool,
    ProgramView,
    RowColumns,
    row_changes,
)
from olp.transforms.split import SplitLimits, part_names

if TYPE_CHECKING:
    from olp.output import StagedFolder
    from olp.station.model import Station


def streams(post: Post) -> bool:
    """Whether ``post`` can write a streamed toolpath (see the module text)."""
    manifest = post.manifest
    return (
        post.STREAMS
        and post.COLUMNS
        and post.rows_enabled()
        and (not post.TRANSFORMS or post.WINDOW_TRANSFORMS is not None)
        and manifest.limits.max_lines is None
        and (not post.STREAM_PARTS or planned_parts(manifest.limits))
        and _point_pattern(post) is not None
    )


def planned_parts(limits: SplitLimits) -> bool:
    """Whether ``limits`` bound the instructions of a part (so that a part's rows may be
    kept to render it whole: :attr:`~olp.posts.base.Post.STREAM_PARTS`)."""
    return limits.max_motions is not None or limits.max_instructions is not None


def count_parts(programs: Iterable[Program], limits: SplitLimits) -> int:
    """The parts a program read in windows (``programs``) is split into by ``limits``, every
    instruction written (as the streamed build counts them: :class:`PartCounter`)."""
    counter, parts = PartCounter(limits), 1
    for program in programs:
        node: Any
        for node in program.instructions:
            if isinstance(node, LinearPath):
                parts += len(counter.rows(len(node)))
            else:
                parts += int(counter.step(is_motion(node), True))
    return parts


@dataclass(frozen=True, slots=True, eq=False)
class SplicedRows(RowColumns):
    """The stand-in for all of a file's toolpath rows while its templates are rendered."""


def _marker(k: int) -> str:
    return f"\x00olp-rows-{k}\x00"


_MARKER = re.compile("\x00olp-rows-([0-9]+)\x00")


@dataclass(slots=True, eq=False)
class _Call:
    """A row writer call recorded from a template: the bound filter and its further arguments."""

    template: str
    fn: Callable[..., Any]
    args: tuple[Any, ...]
    kwargs: dict[str, Any]
    body: Path
    handle: BinaryIO | None = None
    written: bool = False


class _Splicer:
    """Intercepts filters applied to a :class:`SplicedRows`: records them (``calls`` is a
    list) or, on the final render, replays their markers in order (``calls`` is a tuple)."""

    def __init__(self, scratch: Callable[[], Path]) -> None:
        self.scratch = scratch
        self.template = ""
        self.recording: list[_Call] | None = None
        self.replaying: Sequence[_Call] = ()
        self.position = 0

    def hit(self, fn: Callable[..., Any], args: tuple[Any, ...], kwargs: dict[str, Any]) -> Any:
        if self.recording is not None:
            call = _Call(self.template, fn, args[1:], kwargs, self.scratch())
            self.recording.append(call)
            return SafeText(_marker(len(self.recording) - 1))
        k = self.position
        self.position += 1
        recorded = self.replaying[k]
        for now, then in zip(args[1:], recorded.args, strict=False):
            if isinstance(now, Modal) and isinstance(then, Modal):
                now._last = dict(then._last)  # the state the rows left behind them
        return SafeText(_marker(k))


def _splicing_environment(post: Post, splicer: _Splicer) -> PostSandbox:
    def wrap(fn: Callable[..., Any]) -> Callable[..., Any]:
        def filter_(*args: Any, **kwargs: Any) -> Any:
            if args and isinstance(args[0], SplicedRows):
                return splicer.hit(fn, args, kwargs)
            return fn(*args, **kwargs)

        filter_.__name__ = getattr(fn, "__name__", "filter")
        return filter_

    neutral = post.STREAM_NEUTRAL_FILTERS
    filters = {
        name: _bind(fn, post) if name in neutral else wrap(_bind(fn, post))
        for name, fn in post.FILTERS.items()
    }
    return make_environment(post.manifest.folder, filters)


class PartCounter:
    """Where a split begins, counted as :func:`olp.transforms.split.split_bounds` counts, one
    instruction or one run of rows at a time."""

    def __init__(self, limits: SplitLimits) -> None:
        self.limits = limits
        self.motions = 0
        self.all = 0

    def room(self) -> float:
        caps = [float("inf")]
        if self.limits.max_motions is not None:
            caps.append(self.limits.max_motions - self.motions)
        if self.limits.max_instructions is not None:
            caps.append(self.limits.max_instructions - self.all)
        return max(min(caps), 0.0)

    def rows(self, n: int) -> list[int]:
        """Offsets (within ``n`` written motions) where a new part begins."""
        cuts: list[int] = []
        i = 0
        while True:
            room = self.room()
            if room >= n - i:
                self.motions += n - i
                self.all += n - i
                return cuts
            i += int(room) if self.all > 0 else max(int(room), 1)
            cuts.append(i)
            self.motions = self.all = 0

    def step(self, motion: bool, written: bool) -> bool:
        """Whether a new part begins before this instruction."""
        if not written:
            return False
        cut = False
        over_motions = motion and self.limits.max_motions is not None
        over_motions = over_motions and self.motions >= (self.limits.max_motions or 0)
        over_all = self.limits.max_instructions is not None and self.all >= (
            self.limits.max_instructions or 0
        )
        if (over_motions or over_all) and self.all > 0:
            cut = True
            self.motions = self.all = 0
        self.motions += int(motion)
        self.all += 1
        return cut


@dataclass(slots=True, eq=False)
class _Part:
    """One file's content: its ordinary steps (in part 1, the instructions before the toolpath),
    the stand-in of its rows and their row writer calls, the change state of its rows."""

    steps: list[PostStep] = field(default_factory=list)
    placeholder: SplicedRows | None = None
    calls: list[_Call] = field(default_factory=list)
    last: dict[str, Any] = field(default_factory=dict)
    context: list[SplicedRows] = field(default_factory=list)
    vendor: Any = None
    rows: list[RowColumns] = field(default_factory=list)


@dataclass(slots=True)
class _Named:
    """The names taken besides the rows': entry, routines, the head's points, tool, frame."""

    entry: str
    routines: list[str]
    allocation: Allocation
    tool: PostTool | None
    frame: PostFrame | None
    firsts: list[str]


class StreamedRender:
    """Writes ``post``'s files of one streamed program into ``staged``: :meth:`add` each timed
    window (instruction indices from ``offset``), then :meth:`finish`."""

    def __init__(
        self,
        post: Post,
        staged: StagedFolder,
        station: Station,
        name: str,
        source: str,
        planned: int | None = None,
    ) -> None:
        self.post = post
        self.planned = planned
        """Parts the program will have, where the post renders each part whole
        (:attr:`~olp.posts.base.Post.STREAM_PARTS`; None: it splices rows)."""
        self.done: list[str] = []
        self.manifest = post.manifest
        self.staged = staged
        self.station = station
        self.name = post.NAME_RULE.legal(name)
        self.source = post.plain_text(basename(source))
        self.ending = self.manifest.line_ending
        pattern = _point_pattern(post)
        assert pattern is not None
        self.pattern = pattern
        self.splicer = _Splicer(staged.scratch)
        self.env = _splicing_environment(post, self.splicer)
        self.counter = PartCounter(self.manifest.limits)
        self.parts: list[_Part] = [_Part()]
        self.head: list[Step] = []
        self.head_program: CompiledProgram | None = None
        self.view: ProgramView | None = None
        self.named: _Named | None = None
        self.number = 0
        self.rows_started = False
        self.first_block: PathBlock | None = None
        self.firsts: list[int] = []
        post.problems, post.collecting = [], True

    # ------------------------------------------------------------------------------------
    # Windows

    def add(self, window: CompiledProgram, offset: int) -> None:
        """Write the instructions of a timed window whose first is instruction ``offset``."""
        for item in items_of(window.steps):
            if isinstance(item, PathBlock):
                self._block(dataclasses.replace(item, start=item.start + offset), window)
            else:
                self._step(dataclasses.replace(item, index=item.index + offset), window)

    def _step(self, step: Step, window: CompiledProgram) -> None:
        if self.rows_started:
            raise PostError(
                f"instruction {step.index} ({step.instruction.kind}) inside a streamed toolpath: "
                "build this program whole (olp build --chunk-rows 0)"
            )
        written = not step.skipped
        if self.counter.step(is_motion(step.instruction), written):
            raise PostError("a streamed program split before its toolpath: build it whole")
        self.head.append(step)
        if self.head_program is None:
            head = Program(name=window.program.name, instructions=(), source=window.program.source)
            self.head_program = dataclasses.replace(window, program=head, steps=())

    def _block(self, block: PathBlock, window: CompiledProgram) -> None:
        if block.joints is None:
            raise PostError(f"instruction {block.start}: an unresolved toolpath is not written")
        if not self.rows_started:
            self._begin(window, block)
        motions = BlockMotions(
            block,
            self.number + 1,
            self._frame_pose(block),
            self.post.step_columns(self.station.robot, block.joints),
        )
        self.firsts.append(self.number + 1)
        self.number += len(block)
        lo = 0
        for cut in self.counter.rows(len(block)):
            if cut > lo:
                self._rows(BlockRows(block, lo, cut), motions)
            self._settle(self.parts[-1])
            if self.planned is not None:
                self._render_part(len(self.parts) - 1)
            self.parts.append(_Part())
            lo = cut
        self._rows(BlockRows(block, lo, len(block)), motions)

    def _begin(self, window: CompiledProgram, block: PathBlock) -> None:
        """The instructions before the toolpath as post steps, with provisional names."""
        self.rows_started = True
        self.first_block = block
        program = self.head_program or window
        self.view = ProgramView(dataclasses.replace(program, steps=tuple(self.head)), self.post)
        self.number = len(self.view.motions)
        self.named = self._names(self._unit_names(self.planned or 0), [self.number + 1])
        part = self.parts[0]
        for step in self.head:
            view_step = self._head_step(step, self.named.allocation, part.last)
            if view_step is not None:
                part.steps.append(view_step)

    def _head_step(
        self, step: Step, allocation: Allocation, last: dict[str, Any]
    ) -> PostStep | None:
        assert self.view is not None
        ins = step.instruction
        if not is_motion(ins):
            lines = self.post.comment_node_lines(ins) if ins.kind == "comment" else ()
            return PostStep(step.index, ins.kind, ins.span.location, ins, comment=lines)
        if step.index not in self.view.motions:
            return None
        return self.view._motion_step(step, allocation, last)

    def _frame_pose(self, block: PathBlock) -> Any:
        assert self.view is not None
        return self.view._frame_pose(block.frame)

    def _rows(self, piece: BlockRows, motions: BlockMotions) -> None:
        part = self.parts[-1]
        rows = self._columns(piece, motions, part.last)
        if self.planned is not None:
            if part.placeholder is None:
                part.placeholder = _stand_in(rows)
            part.rows.append(_owned(rows, 0, len(rows), RowColumns))
            return
        if part.placeholder is None:
            part.placeholder = _stand_in(rows)
            part.calls = self._record(part)
        part.context += [_stand_in(rows, k) for k in self.post.context_rows(rows)]
        for call in part.calls:
            self._write(call, call.fn(rows, *call.args, **call.kwargs))

    def _columns(self, piece: BlockRows, motions: BlockMotions, last: dict[str, Any]) -> RowColumns:
        """A piece of a block as columns, change flags over this file's rows (as
        :meth:`ProgramView._rows` computes them)."""
        assert self.named is not None and self.named.tool is not None
        assert self.named.frame is not None
        new_tool, new_frame, new_speed, new_zone = row_changes(piece, last)
        first = motions.number + piece.lo
        names = self._row_names(first, len(piece))
        return RowColumns(
            piece,
            motions,
            names,  # type: ignore[arg-type]  # an array of names: indexed, never copied whole
            self.named.tool,
            self.named.frame,
            new_tool,
            new_frame,
            new_speed,
            new_zone,
        )

    def _row_names(self, first: int, count: int) -> NDArray[np.str_]:
        prefix, suffix = self.pattern
        numbers = np.arange(first, first + count, dtype=np.int64).astype(np.str_)
        names = np.strings.add(np.strings.add(prefix, numbers), suffix)
        if not Names(self.post.NAME_RULE, ())._all_legal_as_is(names.tolist()):
            raise PostError(
                f"point names {names[0]}..{names[-1]} are not legal as they are: build this "
                "program whole (olp build --chunk-rows 0)"
            )
        return names

    # ------------------------------------------------------------------------------------
    # Recording and writing the rows' calls

    def _record(self, part: _Part) -> list[_Call]:
        """Render the part's templates once to learn which row writer calls its rows get."""
        calls: list[_Call] = []
        self.splicer.recording = calls
        try:
            for template, pattern in self.manifest.files:
                self.splicer.template = template
                context = self._context(part, len(self.parts), 0, self.named)
                render_templates(self.post, self.env, [(template, pattern)], context)
        finally:
            self.splicer.recording = None
        if not calls:
            raise PostError(
                f"post {self.manifest.name!r}: no template writes the toolpath's rows through a "
                "row writer filter applied to them, so they cannot be streamed: build the "
                "program whole (olp build --chunk-rows 0)"
            )
        for call in calls:
            call.handle = open(call.body, "wb")  # noqa: SIM115 - closed in finish()
        return calls

    def _write(self, call: _Call, text: str) -> None:
        assert call.handle is not None
        data = line_endings(str(text), self.ending)
        if call.written:
            data = self.ending + data
        call.written = True
        call.handle.write(self._encode(data, call.template))

    def _encode(self, text: str, where: str) -> bytes:
        encoding = self.manifest.encoding
        try:
            return text.encode(encoding)
        except UnicodeEncodeError as exc:
            bad = text[exc.start : exc.end]
            raise PostError(f"{where}: character {bad!r} cannot be written in {encoding}") from exc

    # ------------------------------------------------------------------------------------
    # The end: names, templates, files

    def finish(self) -> list[str]:
        """Render every file's templates with the final names, splice the rows in, and write
        the files into the staged folder; returns their names. Raises :class:`RenderError`
        for numbers that cannot be written (nothing is then to be committed)."""
        post = self.post
        for part in self.parts:
            self._settle(part)
        if post.problems:
            raise RenderError(_unique(post.problems))
        if not self.rows_started:
            self._begin_without_rows()
        count = len(self.parts) if len(self.parts) > 1 else 0
        unit_names = self._unit_names(len(self.parts))
        named = self._names(unit_names, self.firsts)
        self._check_names(named, unit_names)
        if self.planned is not None:
            if len(self.parts) != self.planned:
                raise PostError(
                    f"a streamed program came out in {len(self.parts)} parts, not the "
                    f"{self.planned} planned: build it whole (olp build --chunk-rows 0)"
                )
            self._render_part(len(self.parts) - 1)
        written: list[str] = []
        main_files: set[str] = set()
        if count:
            main_files = set(self._main(named, unit_names))
            written += sorted(main_files)
        if self.planned is not None:
            if main_files & set(self.done):
                raise PostError(f"post {self.manifest.name!r} writes a file twice")
            post.collecting = False
            if post.problems:
                raise RenderError(_unique(post.problems))
            return written + self.done
        for k, part in enumerate(self.parts):
            index = k + 1 if count else 0
            unit_name = unit_names[k] if count else self.name
            routine = named.routines[k] if count else named.entry
            written += self._part_files(part, index, count, unit_name, routine, named, main_files)
        post.collecting = False
        if post.problems:
            raise RenderError(_unique(post.problems))
        return written

    def _settle(self, part: _Part) -> None:
        """A part whose rows are all written: its scratch files closed, and its ``vendor``
        context computed from the rows kept for it (which are then dropped)."""
        _close(part)
        if part.context:
            with_rows: list[Any] = [*part.steps, *part.context]
            part.vendor = self.post.context_values(with_rows)
            part.context = []

    def _unit_names(self, parts: int) -> list[str]:
        """The names of ``parts`` parts (none when the program is one file)."""
        if parts <= 1:
            return []
        rule = self.post.NAME_RULE
        return part_names(self.name, parts, rule.legal, rule.max_length)

    def _render_part(self, k: int) -> None:
        """Where the post renders each part whole (:attr:`planned`): part ``k``'s files, from
        its steps and its rows, kept for it alone, into the staged folder."""
        assert self.named is not None and self.planned is not None
        if k >= self.planned:
            raise PostError(
                f"a streamed program came out in more parts than the {self.planned} planned: "
                "build it whole (olp build --chunk-rows 0)"
            )
        part, named = self.parts[k], self.named
        count = self.planned if self.planned > 1 else 0
        unit_names = self._unit_names(self.planned)
        name, routine = (unit_names[k], named.routines[k]) if count else (self.name, named.entry)
        unit = Unit(name, self.name, self.source, k + 1 if count else 0, count, routine)
        steps: list[Any] = [*part.steps, *part.rows]
        context = unit_context(self.post, self.station, unit, named.allocation, steps)
        files = render_templates(self.post, self.env, self.manifest.files, context, set(self.done))
        for fname, text in files.items():
            self.staged.add(fname, self._encode(text, fname))
            self.done.append(fname)
        part.rows = []

    def _begin_without_rows(self) -> None:
        """A program of ordinary instructions only (a one-row toolpath)."""
        self.rows_started = True
        program = self.head_program
        assert program is not None
        self.view = ProgramView(dataclasses.replace(program, steps=tuple(self.head)), self.post)
        self.named = self._names(self._unit_names(self.planned or 0), [])
        part = self.parts[0]
        for step in self.head:
            view_step = self._head_step(step, self.named.allocation, part.last)
            if view_step is not None:
                part.steps.append(view_step)

    def _names(self, unit_names: list[str], firsts: Sequence[int]) -> _Named:
        """Take the names the whole-program render takes, in its order (part names reserved
        first): the head's, then each block's first point name (``firsts``: their motion
        numbers) and the first block's tool and frame; the rows' other names are not taken
        (:meth:`_check_names`)."""
        assert self.view is not None
        post, options = self.post, self.manifest.options
        head = self.head_program
        reserved = [*post.PREDEFINED_NAMES, *(post.reserved_names(head) if head else ())]
        names = Names(post.NAME_RULE, [self.name, *unit_names, *reserved])
        entry, routines = entry_names(names, options, self.name, unit_names)
        allocation = self.view.allocate(names)
        prefix, suffix = self.pattern
        taken: list[str] = []
        tool = frame = None
        for k, number in enumerate(firsts):
            taken.append(names.take(f"{prefix}{number}{suffix}"))
            if k == 0:
                block = self.first_block
                assert block is not None
                pose = self.view._frame_pose(block.frame)
                tool, frame = self.view._tool_frame(block.tool, block.frame, pose, names, {})
        return _Named(entry, routines, allocation, tool, frame, taken)

    def _check_names(self, named: _Named, unit_names: list[str]) -> None:
        """The final names must be the provisional ones the rows were written with, and no
        name taken may be a row's point name."""
        early = self.named
        assert early is not None
        same = (
            early.tool is None
            or (
                named.tool is not None
                and named.frame is not None
                and early.frame is not None
                and named.tool.name == early.tool.name
                and named.frame.name == early.frame.name
            )
        ) and [p for p, _ in early.allocation.points.values()] == [
            p for p, _ in named.allocation.points.values()
        ]
        prefix, suffix = self.pattern
        expected = [f"{prefix}{n}{suffix}" for n in self.firsts]
        if not same or named.firsts != expected or self._row_clash(named, unit_names):
            raise PostError(
                "a name olp generates for this program depends on how it is split into parts: "
                "build it whole (olp build --chunk-rows 0)"
            )

    def _row_clash(self, named: _Named, unit_names: list[str]) -> bool:
        """Whether a name other than the rows' own is one of the rows' point names."""
        if not self.firsts:
            return False
        prefix, suffix = self.pattern
        shape = re.compile(re.escape(prefix) + "([1-9][0-9]*)" + re.escape(suffix), re.IGNORECASE)
        others = [self.name, named.entry, *unit_names, *named.routines]
        others += [p for pair in named.allocation.points.values() for p in pair if p]
        others += [t.name for t in (named.tool, named.frame) if t is not None]
        low, high = self.firsts[0], self.number
        for name in others:
            match = shape.fullmatch(name)
            if match and low <= int(match.group(1)) <= high:
                return True
        return False

    def _context(self, part: _Part, index: int, count: int, named: _Named | None) -> dict[str, Any]:
        assert named is not None
        steps: list[Any] = list(part.steps)
        if part.placeholder is not None:
            steps.append(part.placeholder)
        name = self.name if index == 0 or count == 0 else f"{self.name}_P{index}"
        unit = Unit(name, self.name, self.source, index, count, named.entry)
        return unit_context(self.post, self.station, unit, named.allocation, steps)

    def _main(self, named: _Named, unit_names: list[str]) -> list[str]:
        count = len(unit_names)
        unit = Unit(self.name, self.name, self.source, 0, count, named.entry)
        context = unit_context(self.post, self.station, unit, named.allocation, ())
        context["parts"] = [
            {"name": n, "index": k + 1, "routine": r}
            for k, (n, r) in enumerate(zip(unit_names, named.routines, strict=True))
        ]
        used: list[Any] = [s for s in self.parts[0].steps]
        if self.parts[0].placeholder is not None:
            used.append(self.parts[0].placeholder)
        context["tools"], context["frames"] = _used(named.allocation, used)
        files = render_templates(self.post, self.env, self.manifest.main_files, context)
        for fname, text in files.items():
            self.staged.add(fname, self._encode(text, fname))
        return list(files)

    def _part_files(
        self,
        part: _Part,
        index: int,
        count: int,
        unit_name: str,
        routine: str,
        named: _Named,
        clash: set[str],
    ) -> list[str]:
        steps: list[Any] = list(part.steps)
        if part.placeholder is not None:
            steps.append(part.placeholder)
        unit = Unit(unit_name, self.name, self.source, index, count, routine)
        out = []
        for template, pattern in self.manifest.files:
            own = [c for c in part.calls if c.template == template]
            self.splicer.replaying, self.splicer.position = own, 0
            context = unit_context(self.post, self.station, unit, named.allocation, steps)
            if part.vendor is not None:
                context["vendor"] = part.vendor
            files = render_templates(self.post, self.env, [(template, pattern)], context, clash)
            ((fname, text),) = files.items()
            if self.splicer.position != len(own):
                raise PostError(
                    f"{template}: the template's row writers differ between two renders of "
                    "one file: build this program whole (olp build --chunk-rows 0)"
                )
            self._assemble(fname, text, own)
            out.append(fname)
        return out

    def _assemble(self, fname: str, text: str, calls: Sequence[_Call]) -> None:
        """The file: the template's text with each marker replaced by its scratch file."""
        pieces = _MARKER.split(text)
        with self.staged.create(fname) as handle:
            handle.write(self._encode(pieces[0], fname))
            for k in range(1, len(pieces), 2):
                body = calls[int(pieces[k])].body
                with open(body, "rb") as source:
                    shutil.copyfileobj(source, handle, 1 << 20)
                body.unlink()
                handle.write(self._encode(pieces[k + 1], fname))


def _close(part: _Part) -> None:
    """Close the scratch files of a part whose rows are all written."""
    for call in part.calls:
        if call.handle is not None:
            call.handle.close()
            call.handle = None


_R = TypeVar("_R", bound=RowColumns)


def _stand_in(rows: RowColumns, row: int = 0) -> SplicedRows:
    """The stand-in of a file's rows: row ``row`` of ``rows``, its arrays copied (a part's
    stand-in lives to the end of the build; it must not keep a whole block alive)."""
    return _owned(rows, row, row + 1, SplicedRows)


def _owned(rows: RowColumns, lo: int, hi: int, kind: type[_R]) -> _R:
    """Rows ``lo`` to ``hi`` of ``rows`` as a ``kind`` of their own, their arrays copied (so
    that they do not keep their window's block alive)."""
    piece, motions = rows.piece, rows.motions
    block, k, n = piece.block, piece.lo + lo, hi - lo
    assert block.joints is not None and block.path is not None and block.ends is not None
    node = block.node.rows(k, k + n)

    def own(values: Any) -> Any:
        return None if values is None else np.array(values)

    node = dataclasses.replace(
        node,
        poses=own(node.poses),
        speeds=own(node.speeds),
        zones=own(node.zones),
        lines=own(node.lines),
        widths=own(node.widths),
        labels=own(node.labels),
    )
    first = 0 if k == 0 else int(block.ends[k - 1])
    small = PathBlock(
        block.start + k,
        node,
        block.tool,
        block.frame,
        np.array(block.joints[k : k + n]),
        np.array(block.path[first : int(block.ends[k + n - 1]) + 1]),
        np.array(block.ends[k : k + n]) - first,
    )
    columns = {key: np.array(value[k : k + n]) for key, value in motions.columns.items()}
    return kind(
        BlockRows(small, 0, n),
        BlockMotions(small, motions.number + k, motions.frame_pose, columns),
        [str(name) for name in rows.names[lo:hi]],
        rows.tool_item,
        rows.frame_item,
        rows.new_tool and lo == 0,
        rows.new_frame and lo == 0,
        np.array(rows.new_linear_speed[lo:hi]),
        np.array(rows.new_zone[lo:hi]),
    )


def _point_pattern(post: Post) -> tuple[str, str] | None:
    """The post's ``point_names`` pattern as (prefix, suffix) around ``{n}``, or None when it
    is not of that form."""
    pattern = str(post.manifest.options.get("point_names", "P{n}"))
    if pattern.count("{n}") != 1 or re.search(r"[{}]", pattern.replace("{n}", "")):
        return None
    prefix, suffix = pattern.split("{n}")
    return prefix, suffix
