"""Errors for bad *input*: every one knows where in which file it happened.

Bad programs (unreachable targets, limits, collisions) are not errors but diagnostics
(:mod:`olp.diagnostics`). An :class:`OlpError` means olp could not read or understand its input,
or was used wrongly; the CLI turns it into exit code 2 and a located message.
"""

from __future__ import annotations

from olp.span import SourceSpan


class OlpError(Exception):
    """Base of all olp input errors.

    Parameters
    ----------
    message:
        What was expected and what was found.
    span:
        Where, if known.
    source_line:
        The text of the offending line, for the caret display.
    hint:
        Optional advice for the user.
    code:
        A stable name of the fault for programs, or None. :data:`INVALID_KRL` marks a program
        text the language itself refuses (the controller would too), as against one olp cannot
        read yet; it is shown in brackets after the kind (``parse error[invalid_krl]:``).
    """

    kind = "error"

    def __init__(
        self,
        message: str,
        span: SourceSpan | None = None,
        source_line: str | None = None,
        hint: str | None = None,
        code: str | None = None,
    ) -> None:
        super().__init__(message)
        self.message = message
        self.span = span
        self.source_line = source_line
        self.hint = hint
        self.code = code

    def format(self) -> str:
        """The message in compiler style: ``file:line:col: error: message`` (``error[code]:``
        when the error has a code, as diagnostics show their kind), line and caret."""
        where = f"{self.span}: " if self.span is not None else ""
        kind = self.kind if self.code is None else f"{self.kind}[{self.code}]"
        lines = [f"{where}{kind}: {self.message}"]
        if self.source_line is not None and self.span is not None:
            text = self.source_line.rstrip("\r\n").expandtabs(1)
            start = max(self.span.column - 1, 0)
            width = 1
            if self.span.end_line == self.span.line and self.span.end_column is not None:
                width = max(self.span.end_column - self.span.column, 1)
            text, start, width = excerpt(text, start, width)
            width = max(1, min(width, len(text) - start)) if start < len(text) else 1
            lines.append(f"    {text}")
            lines.append("    " + " " * start + "^" * width)
        if self.hint:
            lines.append(f"    hint: {self.hint}")
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.format()


INVALID_KRL = "invalid_krl"
"""The :attr:`OlpError.code` of a KRL text that is not KRL: the controller refuses it too."""


class ParseError(OlpError):
    """A program file could not be read (syntax, unknown statement, bad value)."""

    kind = "parse error"


class StationError(OlpError):
    """A station file (YAML, URDF, robot library entry) is invalid."""

    kind = "station error"


class PostError(OlpError):
    """A post-processor folder or template is invalid, or cannot express the program."""

    kind = "post error"


class UsageError(OlpError):
    """olp was called wrongly (unknown post, missing file, bad option)."""

    kind = "usage error"


EXCERPT_WIDTH = 120
"""Characters of a source line shown under an error: a 20 MB CSV line is not echoed in full."""


def excerpt(text: str, start: int, width: int, limit: int = EXCERPT_WIDTH) -> tuple[str, int, int]:
    """A window of at most ``limit`` printable characters of ``text`` around the columns
    ``start .. start + width`` (0-based), with ``...`` where it was cut; returns the window and
    the start and width of the caret in it. Control characters are shown as ``?``."""
    clean = "".join(ch if ch.isprintable() else "?" for ch in text[: start + limit + 1])
    if len(text) <= limit:
        return clean, start, width
    width = min(width, limit // 2)
    lo = max(0, min(start - limit // 3, len(text) - limit))
    hi = lo + limit
    head = "..." if lo > 0 else ""
    tail = "..." if hi < len(text) else ""
    window = clean[lo:hi]
    return head + window + tail, start - lo + len(head), width


def line_of(text: str, line: int) -> str | None:
    """The 1-based ``line`` of ``text``, or None if out of range."""
    lines = text.splitlines()
    return lines[line - 1] if 1 <= line <= len(lines) else None
