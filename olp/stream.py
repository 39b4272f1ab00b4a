"""A big CSV toolpath built in windows of rows, in bounded memory, time linear in its length.

:func:`olp.build` hands a CSV program here when it has more than :data:`STREAM_ROWS` rows (or
when asked: ``olp build --chunk-rows N``) and the post can stream
(:func:`olp.posts.stream.streams`). The file is read in windows of whole reader blocks, at
least ``rows`` rows each (:class:`~olp.frontends.csv.CsvWindows`); each window goes through
the pipeline with what crosses its boundary carried over, and out through the post, before the
next is read:

* **resolve** starts from the previous window's last joints, so the configuration continues
  exactly as in one piece (the resolve pass solves a toolpath in batches from the joints
  before each anyway; windows are whole blocks of the reader, so the batches are the same);
* **checks and collisions** run on the window's joint paths (collision runs restart at a
  window boundary: two consecutive colliding rows on either side are two diagnostics);
* **timing**: :class:`~olp.passes.timing.window.WindowTimer` (a boundary inside a blended
  chain is timed with context on both sides, never as a stop);
* **the post** applies its transforms to the window with the rows next to its boundaries
  (:mod:`olp.posts.stream_transforms`: UR's blend capping; the next window is then read
  before the window is given, to know which is the last), checks the window and writes its
  rows (:class:`~olp.posts.stream.StreamedRender`) into a staging folder beside the output
  folder (:class:`~olp.output.StagedFolder`), which replaces the output folder only at the
  end, when no error remains; on any error it is removed: never a half-written output. A post
  that renders each part whole (Fanuc: :attr:`~olp.posts.base.Post.STREAM_PARTS`) first counts
  the parts in a pass that only reads the file. What the post says once per program (ABB's
  tool load, Fanuc's frame and tool notes: ``ONCE_PER_PROGRAM``) is kept once; what it says
  of the program's totals (UR's script length: ``TOTAL_KINDS``) is asked once at the end.

Diagnostics keep their source line (the CSV row) and their instruction index in the whole
program; instruction numbers in a message ("moves 12-14") are renumbered likewise. Per
severity the first :data:`MAX_DIAGNOSTICS` are kept, the others counted in one last note. A
streamed build returns a :class:`~olp.api.BuildResult` whose ``compiled`` holds no steps (the
program never is in memory whole) and whose ``streamed`` says what was built
(:class:`StreamSummary`); ``files`` is empty (the text is on disk only).
"""

from __future__ import annotations

import dataclasses
import re
import time
from collections import Counter
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from olp import progress
from olp.compiled import CompiledProgram, PathBlock, items_of
from olp.diagnostics import Diagnostic, has_errors
from olp.ir import Program, is_motion

if TYPE_CHECKING:
    from olp.api import BuildResult
    from olp.frontends.csv import CsvOptions
    from olp.passes.pipeline import BuildOptions
    from olp.posts.base import Post
    from olp.station.model import Station

STREAM_ROWS = 1_000_000
"""Rows from which ``olp build`` streams a CSV toolpath by itself."""

WINDOW_ROWS = 50_000
"""Rows per window of a streamed build (whole reader blocks: ~70k rows of a helix; a 1M-row
build then peaks near 300 MB)."""

MAX_DIAGNOSTICS = 1000
"""Diagnostics of each severity kept by a streamed build; the rest are counted."""


@dataclass(frozen=True, slots=True)
class StreamSummary:
    """What a streamed build did: ``instructions`` and ``motions`` (resolved: ``resolved``),
    ``cycle_time`` (s) and ``path_length`` (m of TCP travel; both 0 with errors), ``windows``
    and the seconds spent in each stage (``stages``)."""

    instructions: int
    motions: int
    resolved: int
    cycle_time: float
    path_length: float
    windows: int
    stages: Mapping[str, float] = field(default_factory=dict)


def window_rows(
    program: Path, post: Post, options: BuildOptions, chunk_rows: int | None
) -> int | None:
    """Rows per window for a streamed build of ``program`` through ``post``, or None to build it
    whole: a CSV file, a post that streams, no rows skipped or changed into joint moves
    (``ResolveOptions.skip_unreachable``, ``fallback_joint``: those become instructions of
    their own inside the toolpath), and ``chunk_rows`` rows per window (None: automatically,
    :data:`WINDOW_ROWS` from :data:`STREAM_ROWS` rows on; 0: never)."""
    from olp.posts.stream import streams

    if chunk_rows == 0 or program.suffix.lower() != ".csv" or not streams(post):
        return None
    if options.resolve.skip_unreachable or options.resolve.fallback_joint:
        return None
    if chunk_rows is not None:
        return chunk_rows
    return WINDOW_ROWS if count_lines(program) >= STREAM_ROWS else None


def count_lines(path: Path) -> int:
    """Line breaks in the file (an upper bound on its data rows, counted without parsing)."""
    count = 0
    with open(path, "rb") as file:
        while block := file.read(1 << 24):
            count += block.count(b"\n")
    return count


class _Findings:
    """The diagnostics of all windows: indices made the whole program's, program-level ones
    once, at most :data:`MAX_DIAGNOSTICS` per severity."""

    def __init__(self) -> None:
        self.kept: list[Diagnostic] = []
        self.counts: Counter[str] = Counter()
        self.seen: set[tuple[object, ...]] = set()
        self.errors = False

    def add(self, found: Iterable[Diagnostic], offset: int = 0) -> None:
        for diag in found:
            self.errors |= diag.severity == "error"
            if diag.index is None:
                key = (diag.severity, diag.kind, diag.message, diag.span)
                if key in self.seen:
                    continue
                self.seen.add(key)
            self.counts[diag.severity] += 1
            if self.counts[diag.severity] <= MAX_DIAGNOSTICS:
                self.kept.append(renumbered(diag, offset))

    def all(self) -> tuple[Diagnostic, ...]:
        more = {s: n - MAX_DIAGNOSTICS for s, n in self.counts.items() if n > MAX_DIAGNOSTICS}
        if not more:
            return tuple(self.kept)
        text = ", ".join(f"{n} {s}s" for s, n in sorted(more.items()))
        note = Diagnostic("info", "diagnostics_dropped", f"{text} more not shown")
        return (*self.kept, note)


_MOVES = re.compile(r"\b(moves? )([0-9]+)(?:-([0-9]+))?")


def renumbered(diag: Diagnostic, offset: int) -> Diagnostic:
    """``diag`` of a window whose first instruction is ``offset``, as the whole program's: its
    index and the instruction numbers its message names ("move 5", "moves 5-9")."""
    if offset == 0 or diag.index is None:
        return diag

    def shift(match: re.Match[str]) -> str:
        text = f"{match.group(1)}{int(match.group(2)) + offset}"
        return text if match.group(3) is None else f"{text}-{int(match.group(3)) + offset}"

    return dataclasses.replace(
        diag, index=diag.index + offset, message=_MOVES.sub(shift, diag.message)
    )


class _Clock:
    """Seconds per stage."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}
        self._start = 0.0

    def start(self) -> None:
        self._start = time.perf_counter()

    def stop(self, stage: str) -> None:
        now = time.perf_counter()
        self.seconds[stage] = self.seconds.get(stage, 0.0) + now - self._start
        self._start = now


@dataclass(slots=True)
class _Totals:
    instructions: int = 0
    motions: int = 0
    resolved: int = 0
    cycle_time: float = 0.0
    path_length: float = 0.0
    windows: int = 0

    def add_checked(self, window: CompiledProgram) -> None:
        self.windows += 1
        for item in items_of(window.steps):
            if isinstance(item, PathBlock):
                self.instructions += len(item)
                self.motions += len(item)
                self.resolved += len(item) if item.joints is not None else 0
            else:
                self.instructions += 1
                motion = is_motion(item.instruction)
                self.motions += int(motion)
                self.resolved += int(motion and item.joints is not None)

    def add_timed(self, window: CompiledProgram) -> None:
        self.cycle_time += window.cycle_time
        for item in items_of(window.steps):
            if isinstance(item, PathBlock):
                self.path_length += 0.0 if item.lengths is None else float(np.sum(item.lengths))
            else:
                self.path_length += item.path_length


def build_streamed(
    station: Station,
    path: Path,
    post: Post,
    out_dir: Path,
    name: str | None,
    options: BuildOptions,
    program_options: CsvOptions | None,
    rows: int,
) -> BuildResult:
    """Build the CSV toolpath ``path`` window by window (see the module text); the files
    replace ``out_dir`` only when no error remains."""
    from olp.api import BuildResult
    from olp.frontends import ignored_notes
    from olp.frontends.csv import CsvWindows
    from olp.output import StagedFolder
    from olp.posts.render import RenderError

    findings, totals, clock = _Findings(), _Totals(), _Clock()
    staged = StagedFolder(out_dir)
    written: tuple[Path, ...] = ()
    try:
        with CsvWindows(path, program_options, station, rows) as windows:
            findings.add(ignored_notes(windows.ignored))
            program_name = name or windows.name
            asked = Program(name=windows.name, instructions=(), source=str(path))
            findings.add(post.renamed(asked, name))
            from olp.posts.stream import StreamedRender

            planned = None
            if post.STREAM_PARTS:
                clock.start()
                planned = _planned_parts(path, program_options, station, rows, post)
                clock.stop("read")
            writer = StreamedRender(post, staged, station, program_name, str(path), planned)
            run = _Run(station, options, post, writer, findings, totals, clock)
            estimate = count_lines(path) - windows.layout.header_rows
            with progress.stage("build", estimate, "rows"):
                run.all(windows)
        if not findings.errors:
            try:
                clock.start()
                writer.finish()
                written = tuple(staged.commit())
                clock.stop("write")
            except RenderError as exc:
                findings.add(exc.diagnostics)
    finally:
        staged.discard()
    for stage, seconds in clock.seconds.items():
        progress.note(stage, seconds, totals.instructions)
    diagnostics = findings.all()
    summary = StreamSummary(
        totals.instructions,
        totals.motions,
        totals.resolved,
        totals.cycle_time if not has_errors(diagnostics) else 0.0,
        totals.path_length if not has_errors(diagnostics) else 0.0,
        totals.windows,
        dict(clock.seconds),
    )
    program = Program(name=name or path.stem, instructions=(), source=str(path))
    compiled = CompiledProgram(program, station, station.robot.home.copy(), (), diagnostics)
    return BuildResult(compiled, post.name, diagnostics, {}, written, streamed=summary)


def _planned_parts(
    path: Path, options: CsvOptions | None, station: Station, rows: int, post: Post
) -> int:
    """The parts the program will be split into (a first pass that reads the file only)."""
    from olp.frontends.csv import CsvWindows
    from olp.posts.stream import count_parts

    with CsvWindows(path, options, station, rows) as windows, progress.showing(None):
        return count_parts(windows, post.manifest.limits)


class _Run:
    """The windows through the pipeline, one after the other."""

    def __init__(
        self,
        station: Station,
        options: BuildOptions,
        post: Post,
        writer: object,
        findings: _Findings,
        totals: _Totals,
        clock: _Clock,
    ) -> None:
        from olp.passes.timing.window import WindowTimer

        self.station, self.options, self.post = station, options, post
        self.writer = writer
        self.findings, self.totals, self.clock = findings, totals, clock
        self.start = station.robot.home.copy()
        self.offset = 0
        self.offsets: list[int] = []
        self.once: set[tuple[str, str]] = set()
        limits = station.robot.limits
        self.timer = WindowTimer(options.other_times, options.timing, limits.path_acceleration)
        self.transforms = [make(post) for make in post.WINDOW_TRANSFORMS or ()]

    def all(self, windows: Iterable[Program]) -> None:
        peek = bool(self.transforms)  # they need to know which window is the last
        for window, is_last in _quietly(windows, self.clock, peek):
            checked = self.check(window)
            self.offsets.append(self.offset)
            size = len(checked.steps)
            if not self.findings.errors:
                self.clock.start()
                timed = self.timer.push(checked)
                self.clock.stop("time")
                if timed is not None:
                    self.emit(timed, self.offsets[-2], checked, is_last)
            self.offset += size
            progress.advance(size)
            self.clock.start()
        if not self.findings.errors:
            self.clock.start()
            last = self.timer.finish()
            self.clock.stop("time")
            if last is not None:
                self.emit(last, self.offsets[-1])
            self.findings.add(self.post.check_totals(self.totals.resolved))

    def check(self, window: Program) -> CompiledProgram:
        """Resolve, flow and collision passes on one window, from the previous one's joints."""
        from olp.passes.collide import collision_pass
        from olp.passes.flow import flow_pass
        from olp.passes.resolve import resolve_pass

        compiled = dataclasses.replace(
            CompiledProgram.start(window, self.station), start_joints=self.start
        )
        with progress.showing(None):
            for stage, step in (
                ("resolve", resolve_pass),
                ("flow", flow_pass),
                ("collide", collision_pass),
            ):
                self.clock.start()
                compiled = step(compiled, self.options)
                self.clock.stop(stage)
        self.findings.add(compiled.diagnostics, self.offset)
        self.totals.add_checked(compiled)
        self.start = _last_joints(compiled, self.start)
        return dataclasses.replace(compiled, diagnostics=())

    def emit(
        self,
        timed: CompiledProgram,
        offset: int,
        following: CompiledProgram | None = None,
        last: bool = True,
    ) -> None:
        """A timed window: its timing findings, the post's transforms (``following``: the
        next window, checked; ``last``: it is the last) and checks, its rows written."""
        from olp.posts.stream import StreamedRender

        self.findings.add(timed.diagnostics, offset)
        self.clock.start()
        for transform in self.transforms:
            timed, found = transform.apply(timed, following, last)
            self.findings.add(found, offset)
        found = self.program_once(self.post.check(timed))
        self.findings.add(found, offset)
        self.clock.stop("check")
        if self.findings.errors:
            return
        self.totals.add_timed(timed)
        assert isinstance(self.writer, StreamedRender)
        with progress.showing(None):
            self.writer.add(timed, offset)
        self.clock.stop("write")

    def program_once(self, found: list[Diagnostic]) -> list[Diagnostic]:
        """A window's post diagnostics without those the post gives once per program and an
        earlier window gave, nor those it gives from the program's totals
        (:attr:`~olp.posts.base.Post.ONCE_PER_PROGRAM`, ``TOTAL_KINDS``)."""
        once, totals = self.post.ONCE_PER_PROGRAM, self.post.TOTAL_KINDS
        out = []
        for diag in found:
            key = (diag.kind, diag.message)
            if diag.kind in totals or (diag.kind in once and key in self.once):
                continue
            if diag.kind in once:
                self.once.add(key)
            out.append(diag)
        return out


def _quietly(
    windows: Iterable[Program], clock: _Clock, peek: bool
) -> Iterator[tuple[Program, bool]]:
    """The windows, each read without progress of its own (the build's stage counts rows),
    and whether it is the last; ``peek``: the next window is read before one is given (else
    every window is given as not the last)."""
    it = iter(windows)
    window = _read(it, clock)
    while window is not None:
        if not peek:
            yield window, False
            window = _read(it, clock)
            continue
        following = _read(it, clock)
        yield window, following is None
        window = following


def _read(it: Iterator[Program], clock: _Clock) -> Program | None:
    clock.start()
    with progress.showing(None):
        window = next(it, None)
    clock.stop("read")
    return window


def _last_joints(compiled: CompiledProgram, before: NDArray[np.float64]) -> NDArray[np.float64]:
    """The joints after a window's last resolved motion (``before`` if none resolved)."""
    for item in reversed(items_of(compiled.steps)):
        if isinstance(item, PathBlock):
            if item.joints is not None:
                return np.array(item.joints[-1])
        elif item.joints is not None and is_motion(item.instruction):
            return np.array(item.joints)
    return before


def streamed_summary(result: BuildResult) -> str:
    """The build summary of a streamed build (as :func:`olp.report.summary` prints one)."""
    from olp.report import written_line

    done = result.streamed
    assert done is not None
    errors = sum(d.severity == "error" for d in result.diagnostics)
    warnings = sum(d.severity == "warning" for d in result.diagnostics)
    compiled = result.compiled
    rows = [
        ("program", f"{compiled.program.name} ({compiled.program.source})"),
        ("station", f"{compiled.station.name} ({compiled.station.robot.name})"),
        ("instructions", f"{done.instructions} ({done.motions} motions, {done.windows} windows)"),
        ("reachability", f"{done.resolved} of {done.motions} motions resolved"),
        ("cycle time", f"{done.cycle_time:.2f} s" if result.ok else "-"),
        ("path length", f"{done.path_length * 1000:.1f} mm of TCP travel" if result.ok else "-"),
        ("diagnostics", f"{errors} errors, {warnings} warnings"),
    ]
    if result.written:
        rows.append(("written", written_line(result.written)))
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"{k.ljust(width)}  {v}" for k, v in rows)
