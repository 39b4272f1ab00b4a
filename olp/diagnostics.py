"""Diagnostics: what the checks found wrong (or worth saying) about a program on a station.

Checks never raise on a bad program; they return diagnostics. Errors block output.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from olp.ir import SourceSpan

Severity = Literal["error", "warning", "info"]


@dataclass(frozen=True, slots=True, eq=False)
class Diagnostic:
    """One finding.

    ``kind`` is a stable machine-readable name (``unreachable``, ``joint_limit``,
    ``configuration_change``, ...). ``index`` is the instruction index in the program, ``joints``
    the joint values involved (rad, controller convention) where relevant.
    """

    severity: Severity
    kind: str
    message: str
    span: SourceSpan | None = None
    index: int | None = None
    joints: NDArray[np.float64] | None = None
    hint: str | None = None

    def format(self) -> str:
        """Compiler-style text: ``file:line:col: error[kind]: message``."""
        where = f"{self.span}: " if self.span is not None else ""
        text = f"{where}{self.severity}[{self.kind}]: {self.message}"
        if self.index is not None:
            text += f" (instruction {self.index})"
        if self.hint:
            text += f"\n    hint: {self.hint}"
        return text

    def to_json(self) -> dict[str, Any]:
        """The report form; keys ``severity``, ``kind``, ``message``, ``source`` are stable."""
        out: dict[str, Any] = {
            "severity": self.severity,
            "kind": self.kind,
            "message": self.message,
            "source": self.span.location if self.span is not None else None,
            "index": self.index,
        }
        if self.joints is not None:
            out["joints_deg"] = [round(float(v), 6) for v in np.degrees(self.joints)]
        if self.hint:
            out["hint"] = self.hint
        return out


def has_errors(diagnostics: tuple[Diagnostic, ...] | list[Diagnostic]) -> bool:
    """True if any diagnostic is an error (which blocks output)."""
    return any(d.severity == "error" for d in diagnostics)
