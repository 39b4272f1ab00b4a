"""Where something came from in a file: :class:`SourceSpan` (re-exported by :mod:`olp.ir`).

A module of its own, without numpy, so that errors (:mod:`olp.errors`) and ``olp --help`` stay
light.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class SourceSpan:
    """Where something came from: 1-based line and column (end exclusive, optional)."""

    file: str
    line: int
    column: int = 1
    end_line: int | None = None
    end_column: int | None = None

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"

    @property
    def location(self) -> str:
        """``file:line``, the form used in reports."""
        return f"{self.file}:{self.line}"


GENERATED = SourceSpan("<generated>", 0, 0)
"""Span for instructions made by a transform rather than read from a file."""
