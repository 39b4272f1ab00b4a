"""The build report: JSON for CI tools (stable keys) and a short table for people.

Stable JSON keys (kept from the first release on): ``program``, ``post``, ``files``,
``cycle_time_s``, ``instructions`` (``index``, ``kind``, ``source``, ``joints_deg`` for motions,
``time_s``) and ``diagnostics`` (``severity``, ``kind``, ``message``, ``source``). New keys may be
added; these are not renamed or removed.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from olp.api import BuildResult
from olp.errors import line_of
from olp.ir import is_motion

SCHEMA_VERSION = 1


def report_dict(result: BuildResult) -> dict[str, Any]:
    """The JSON-ready report of a build."""
    compiled = result.compiled
    instructions = []
    for step in compiled.steps:
        ins = step.instruction
        item: dict[str, Any] = {
            "index": step.index,
            "kind": ins.kind,
            "source": ins.span.location,
            "time_s": round(step.duration, 6),
        }
        if is_motion(ins):
            item["joints_deg"] = (
                [round(float(v), 6) for v in np.degrees(step.joints)]
                if step.joints is not None
                else None
            )
            item["path_length_m"] = round(step.path_length, 9)
            item["skipped"] = step.skipped
        instructions.append(item)
    return {
        "schema": SCHEMA_VERSION,
        "program": compiled.program.name,
        "source": compiled.program.source,
        "station": compiled.station.name,
        "robot": compiled.station.robot.name,
        "post": result.post,
        "ok": result.ok,
        "files": [str(p) for p in result.written],
        "cycle_time_s": round(compiled.cycle_time, 6) if compiled.ok else None,
        "instructions": instructions,
        "diagnostics": [d.to_json() for d in result.diagnostics],
    }


def report_json(result: BuildResult) -> str:
    """The report as deterministic JSON text (sorted keys, fixed rounding)."""
    return json.dumps(report_dict(result), indent=2, sort_keys=True, ensure_ascii=False) + "\n"


def summary(result: BuildResult) -> str:
    """A short human summary: program, counts, reachability verdict, cycle time, files."""
    compiled = result.compiled
    steps = compiled.steps
    motions = [s for s in steps if is_motion(s.instruction)]
    resolved = [s for s in motions if s.joints is not None]
    errors = [d for d in result.diagnostics if d.severity == "error"]
    warnings = [d for d in result.diagnostics if d.severity == "warning"]
    rows = [
        ("program", f"{compiled.program.name} ({compiled.program.source})"),
        ("station", f"{compiled.station.name} ({compiled.station.robot.name})"),
        ("instructions", f"{len(steps)} ({len(motions)} motions)"),
        ("reachability", _verdict(len(motions), len(resolved), errors)),
        (
            "cycle time",
            f"{compiled.cycle_time:.2f} s (estimate; zones timed as stops)" if compiled.ok else "-",
        ),
        ("diagnostics", f"{len(errors)} errors, {len(warnings)} warnings"),
    ]
    if result.written:
        rows.append(("written", ", ".join(str(p) for p in result.written)))
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"{k.ljust(width)}  {v}" for k, v in rows)


def _verdict(total: int, resolved: int, errors: list[Any]) -> str:
    if not errors:
        return f"all {total} motions feasible"
    return f"{resolved} of {total} motions feasible, {len(errors)} errors: nothing written"


def format_diagnostic(diagnostic: Any, sources: dict[str, str]) -> str:
    """A diagnostic with its source line and a caret, if the source text is at hand."""
    text: str = diagnostic.format()
    span = diagnostic.span
    if span is None or span.file not in sources:
        return text
    line = line_of(sources[span.file], span.line)
    if line is None:
        return text
    head, _, rest = text.partition("\n")
    caret = " " * max(span.column - 1, 0) + "^"
    parts = [head, f"    {line.rstrip()}", f"    {caret}"]
    return "\n".join(parts + ([rest] if rest else []))
