"""Helpers shared by the ``olp`` commands: exit codes, file checks, diagnostic printing
(their shared options are in :mod:`olp.commands.options`)."""

from __future__ import annotations

import sys
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from olp.diagnostics import Diagnostic

EXIT_OK, EXIT_PROGRAM_ERRORS, EXIT_BAD_INPUT = 0, 1, 2


def require_files(*paths: str) -> None:
    """Raise a UsageError naming the first path that is not a readable file, and why."""
    import os

    from olp.errors import UsageError

    for path in paths:
        file = Path(path)
        if file.is_dir():
            raise UsageError(f"{path}: is a folder, not a file")
        if not file.exists():
            raise UsageError(f"no such file: {path}")
        if not file.is_file():
            raise UsageError(f"{path}: is not a regular file")
        if not os.access(file, os.R_OK):
            raise UsageError(f"{path}: no permission to read it")


def print_diagnostics(diagnostics: Iterable[Diagnostic], *sources: str, quiet: bool) -> None:
    """Errors always, warnings unless quiet, to stderr, with source line and caret."""
    from olp.report import format_diagnostic

    texts = _read_sources(sources)
    for diag in diagnostics:
        if diag.severity == "error" or (not quiet and diag.severity == "warning"):
            print(format_diagnostic(diag, texts), file=sys.stderr)


def _read_sources(paths: Iterable[str]) -> dict[str, str]:
    out = {}
    for path in paths:
        try:
            out[path] = Path(path).read_text(encoding="utf-8", errors="replace")
        except OSError:
            continue
    return out
