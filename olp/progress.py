"""Progress of long work (a big toolpath's stages) on a terminal, and silence elsewhere.

Code that does long work opens a :func:`stage` and calls :func:`advance` as it goes; nothing is
shown unless a caller asked for it with :func:`showing` (the CLI does, on a terminal, without
``--quiet`` and outside CI). A library user who never calls :func:`showing` gets no output, and
the calls cost a context-variable lookup.

On a terminal each stage is one line, rewritten at most ten times a second while it runs
(``resolve   40,960/100,000 rows   81.2k rows/s   ETA 0.7 s``) and left as a summary when it
ends (``resolve   100,000 rows in 1.2 s (83.3k rows/s)``).
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from typing import TextIO

_REPORTER: ContextVar[Reporter | None] = ContextVar("olp_progress", default=None)

REFRESH_S = 0.1
"""Least time between two redraws of a running stage's line."""


@dataclass(slots=True)
class _Stage:
    name: str
    total: int | None
    unit: str
    started: float
    done: int = 0
    drawn: float = 0.0


class Reporter:
    """Draws stages on ``stream`` (a terminal); ``clock``: seconds, for tests."""

    def __init__(self, stream: TextIO, clock: Callable[[], float] = time.perf_counter) -> None:
        self.stream = stream
        self.clock = clock
        self.stages: list[_Stage] = []

    def start(self, name: str, total: int | None, unit: str) -> None:
        self.stages.append(_Stage(name, total, unit, self.clock()))
        self._draw(self.stages[-1], force=True)

    def advance(self, count: int) -> None:
        if self.stages:
            stage = self.stages[-1]
            stage.done += count
            self._draw(stage)

    def finish(self) -> None:
        stage = self.stages.pop()
        seconds = self.clock() - stage.started
        count = stage.total if stage.total is not None else stage.done
        text = f"{stage.name:<9} {count:,} {stage.unit} in {seconds:.1f} s"
        if count and seconds > 0:
            text += f" ({_rate(count / seconds)} {stage.unit}/s)"
        self.stream.write(f"\r\033[K{text}\n")
        self.stream.flush()

    def _draw(self, stage: _Stage, force: bool = False) -> None:
        now = self.clock()
        if not force and now - stage.drawn < REFRESH_S:
            return
        stage.drawn = now
        seconds = now - stage.started
        text = f"{stage.name:<9} {stage.done:,}"
        if stage.total is not None:
            text += f"/{stage.total:,}"
        text += f" {stage.unit}"
        if stage.done and seconds > 0:
            rate = stage.done / seconds
            text += f"   {_rate(rate)} {stage.unit}/s"
            if stage.total is not None and stage.total >= stage.done:
                text += f"   ETA {(stage.total - stage.done) / rate:.1f} s"
        self.stream.write(f"\r\033[K{text}")
        self.stream.flush()


def _rate(value: float) -> str:
    """A rate in three significant figures with a k/M suffix."""
    for scale, suffix in ((1e6, "M"), (1e3, "k")):
        if value >= scale:
            return f"{value / scale:.3g}{suffix}"
    return f"{value:.3g}"


@contextmanager
def showing(reporter: Reporter | None) -> Iterator[None]:
    """Report the stages opened inside this block to ``reporter`` (None: to nobody)."""
    token = _REPORTER.set(reporter)
    try:
        yield
    finally:
        _REPORTER.reset(token)


@contextmanager
def stage(name: str, total: int | None = None, unit: str = "rows") -> Iterator[None]:
    """A stage of long work: ``total`` units of ``unit`` if known."""
    reporter = _REPORTER.get()
    if reporter is None:
        yield
        return
    reporter.start(name, total, unit)
    try:
        yield
    finally:
        reporter.finish()


def advance(count: int) -> None:
    """``count`` more units of the running stage are done."""
    reporter = _REPORTER.get()
    if reporter is not None:
        reporter.advance(count)


def note(name: str, seconds: float, count: int | None = None, unit: str = "rows") -> None:
    """A finished stage's line for work timed elsewhere (the stages of a streamed build, which
    run window by window inside one stage): ``  resolve   1,000 rows in 1.2 s (833 rows/s)``."""
    reporter = _REPORTER.get()
    if reporter is None:
        return
    text = f"  {name:<9} "
    text += f"{seconds:.1f} s" if count is None else f"{count:,} {unit} in {seconds:.1f} s"
    if count and seconds > 0:
        text += f" ({_rate(count / seconds)} {unit}/s)"
    reporter.stream.write(f"\r\033[K{text}\n")
    reporter.stream.flush()


def terminal_reporter(quiet: bool, stream: TextIO | None = None) -> Reporter | None:
    """A reporter on standard error when a person watches it: a terminal, no ``--quiet``, and
    not under CI (the ``CI`` variable that CI services set)."""
    out = stream or sys.stderr
    if quiet or os.environ.get("CI") or not out.isatty():
        return None
    return Reporter(out)
