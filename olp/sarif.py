"""Diagnostics as SARIF 2.1.0, the format CI systems read to show findings on source lines.

One run, tool ``olp``, one rule per diagnostic kind; severities map error -> ``error``,
warning -> ``warning``, info -> ``note``. Paths are written as given (relative paths stay
relative, which is what code-scanning uploads expect).
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from typing import Any

from olp.diagnostics import Diagnostic

SARIF_SCHEMA = (
    "https://docs.oasis-open.org/sarif/sarif/v2.1.0/errata01/os/schemas/sarif-schema-2.1.0.json"
)
_LEVELS = {"error": "error", "warning": "warning", "info": "note"}


def sarif_dict(diagnostics: Iterable[Diagnostic], version: str = "0") -> dict[str, Any]:
    """The SARIF log (a JSON-ready dict) of ``diagnostics``."""
    items = list(diagnostics)
    kinds = sorted({d.kind for d in items})
    results = [_result(d, kinds.index(d.kind)) for d in items]
    driver = {
        "name": "olp",
        "version": version,
        "rules": [{"id": kind, "name": kind} for kind in kinds],
    }
    return {
        "$schema": SARIF_SCHEMA,
        "version": "2.1.0",
        "runs": [{"tool": {"driver": driver}, "results": results}],
    }


def _result(diagnostic: Diagnostic, rule_index: int) -> dict[str, Any]:
    text = diagnostic.message + (f" (hint: {diagnostic.hint})" if diagnostic.hint else "")
    result: dict[str, Any] = {
        "ruleId": diagnostic.kind,
        "ruleIndex": rule_index,
        "level": _LEVELS[diagnostic.severity],
        "message": {"text": text},
    }
    span = diagnostic.span
    if span is not None and span.line >= 1:
        region: dict[str, int] = {"startLine": span.line, "startColumn": max(span.column, 1)}
        result["locations"] = [
            {"physicalLocation": {"artifactLocation": {"uri": span.file}, "region": region}}
        ]
    if diagnostic.index is not None:
        result["properties"] = {"instruction": diagnostic.index}
    return result


def sarif_json(diagnostics: Iterable[Diagnostic], version: str = "0") -> str:
    """The SARIF log as deterministic JSON text."""
    return json.dumps(sarif_dict(diagnostics, version), indent=2, sort_keys=True) + "\n"
