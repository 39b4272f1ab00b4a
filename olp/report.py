"""The build report: JSON for CI tools (stable keys) and a short table for people.

Stable JSON keys (kept from the first release on): ``program``, ``post``, ``files``,
``cycle_time_s``, ``instructions`` (``index``, ``kind``, ``source``, ``joints_deg`` for motions,
``time_s``) and ``diagnostics`` (``severity``, ``kind``, ``message``, ``source``). New keys may be
added; these are not renamed or removed. Added since: ``path_length_m`` (total and per motion,
TCP travel) and ``start_s`` per instruction (its start time in the cycle), and for a program
with control flow ``paths`` (:func:`paths_dict`: the shortest and longest path's time and the
branch choices that give each, what was assumed, how loops were counted); there
``cycle_time_s`` is the longest path's time (the named path's, when ``--assume`` decides every
branch), while ``start_s`` and ``time_s`` follow the text, each instruction once; and
``untimed_motions``: how many motions the cycle time leaves out (to or from a target known only
at run time: ``cycle_time_s`` is then a lower bound).

The timing tables of ``olp time`` (:func:`timing_summary`, :func:`timing_table`,
:func:`sweep_table`) live here too.
"""

from __future__ import annotations

import json
import os
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from olp.api import BuildResult
from olp.errors import excerpt, line_of
from olp.ir import RuntimeMove, is_motion
from olp.passes.wording import quantity

if TYPE_CHECKING:
    from numpy.typing import NDArray

    from olp.compiled import CompiledProgram
    from olp.passes.timing.branches import Choice, PathTimes

SCHEMA_VERSION = 1


def report_dict(result: BuildResult) -> dict[str, Any]:
    """The JSON-ready report of a build."""
    compiled = result.compiled
    instructions = []
    start = 0.0
    for step in compiled.steps:
        ins = step.instruction
        item: dict[str, Any] = {
            "index": step.index,
            "kind": ins.kind,
            "source": ins.span.location,
            "start_s": round(start, 6),
            "time_s": round(step.duration, 6),
        }
        start += step.duration
        if is_motion(ins):
            item["joints_deg"] = (
                [round(float(v), 6) for v in np.degrees(step.joints)]
                if step.joints is not None
                else None
            )
            item["path_length_m"] = round(step.path_length, 9)
            item["skipped"] = step.skipped
        instructions.append(item)
    out: dict[str, Any] = {
        "schema": SCHEMA_VERSION,
        "program": compiled.program.name,
        "source": compiled.program.source,
        "station": compiled.station.name,
        "robot": compiled.station.robot.name,
        "post": result.post,
        "ok": result.ok,
        "files": [str(p) for p in result.written],
        "cycle_time_s": round(_cycle_time(compiled), 6) if compiled.ok else None,
        "path_length_m": round(_path_length(compiled), 9) if compiled.ok else None,
        "untimed_motions": untimed_motions(compiled),
        "instructions": instructions,
        "diagnostics": [d.to_json() for d in result.diagnostics],
    }
    if compiled.paths is not None:
        out["paths"] = paths_dict(compiled.paths)
    return out


def _cycle_time(compiled: CompiledProgram) -> float:
    """The cycle time: the text's, or with control flow the longest path's."""
    paths = compiled.paths
    if paths is not None and paths.longest is not None:
        return paths.longest.seconds
    return compiled.cycle_time


def paths_dict(paths: PathTimes) -> dict[str, Any]:
    """The report's ``paths``: ``shortest_s``/``longest_s`` (None when the program could not be
    walked, ``reason`` says why), ``shortest_choices``/``longest_choices`` (``source``
    file:line:column of the block, ``choice``, ``count``), ``decided``, ``assumed``, ``notes``."""
    ends = {"shortest": paths.shortest, "longest": paths.longest}
    out: dict[str, Any] = {
        "decided": paths.decided,
        "assumed": list(paths.assumed),
        "notes": list(paths.notes),
        "reason": paths.reason,
    }
    for name, end in ends.items():
        out[f"{name}_s"] = None if end is None else round(end.seconds, 6)
        out[f"{name}_choices"] = [] if end is None else [_choice(c) for c in end.choices]
    return out


def _choice(choice: Choice) -> dict[str, Any]:
    block, _, taken = choice.text.partition("\t")
    return {"source": str(choice.span), "choice": f"{block} {taken}", "count": choice.count}


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
    runtime = sum(1 for s in steps if isinstance(s.instruction, RuntimeMove))
    unchecked = f", {runtime} more to run-time targets, not checked" if runtime else ""
    rows = [
        ("program", f"{compiled.program.name} ({compiled.program.source})"),
        ("station", f"{compiled.station.name} ({compiled.station.robot.name})"),
        ("instructions", f"{len(steps)} ({len(motions)} motions{unchecked})"),
        ("reachability", _verdict(len(motions), len(resolved), errors)),
        ("cycle time", _cycle_line(compiled, 2) if compiled.ok else "-"),
        *(_path_rows(compiled.paths) if compiled.ok and compiled.paths else []),
        (
            "path length",
            f"{_path_length(compiled) * 1000:.1f} mm of TCP travel" if compiled.ok else "-",
        ),
        ("diagnostics", f"{len(errors)} errors, {len(warnings)} warnings"),
    ]
    if result.written:
        rows.append(("written", written_line(result.written)))
    width = max(len(k) for k, _ in rows)
    text = "\n".join(f"{k.ljust(width)}  {v}" for k, v in rows)
    table = path_table(compiled.paths) if compiled.ok and compiled.paths else ""
    return f"{text}\n\n{table}" if table else text


def _cycle_line(compiled: CompiledProgram, decimals: int, pointer: bool = True) -> str:
    """The cycle time and how to read it: one number, or with control flow the range of its
    paths (:func:`path_table` lists the choices)."""
    paths = compiled.paths
    note = _timing_note(compiled, pointer)
    if paths is None:
        return f"{quantity(compiled.cycle_time, decimals)} s ({note})"
    if paths.shortest is None or paths.longest is None:
        text = quantity(compiled.cycle_time, decimals)
        return f"{text} s (the text in order, each instruction once: {paths.reason})"
    lo, hi = quantity(paths.shortest.seconds, decimals), quantity(paths.longest.seconds, decimals)
    if paths.decided:
        how = "the path --assume names" if paths.assumed else "the only path"
        return f"{hi} s ({how}; {note})"
    return f"{lo} .. {hi} s (shortest .. longest path, see below; {note})"


def _path_rows(paths: PathTimes) -> list[tuple[str, str]]:
    """The summary's rows on paths: what was assumed, how loops were counted."""
    rows = []
    if paths.assumed:
        rows.append(("assumed", ", ".join(paths.assumed)))
    rows += [("paths", note) for note in paths.notes]
    return rows


def path_table(paths: PathTimes) -> str:
    """The two ends of the range and the branch choices that give each, one choice a line;
    empty when one path was named (or none could be timed)."""
    if paths.decided or paths.shortest is None or paths.longest is None:
        return ""
    header = ("path", "time s", "branch choices")
    rows: list[tuple[str, str, str]] = [header]
    for name, end in (("shortest", paths.shortest), ("longest", paths.longest)):
        described = [c.describe() for c in end.choices] or ["(no open choice)"]
        rows.append((name, quantity(end.seconds, 3), described[0]))
        rows += [("", "", more) for more in described[1:]]
    return _columns(rows, right=(1,))


WRITTEN_NAMED = 3
"""How many written files the summary names; the others are counted (a split 1M-point program
is hundreds of files)."""


def written_line(paths: Sequence[Path]) -> str:
    """The first :data:`WRITTEN_NAMED` paths, then how many more and the folder they are in:
    ``out/P_1.src, out/P_1.dat, out/P_2.src and 397 more (400 files) in out/``."""
    named = ", ".join(str(p) for p in paths[:WRITTEN_NAMED])
    if len(paths) <= WRITTEN_NAMED:
        return named
    more = f"{named} and {len(paths) - WRITTEN_NAMED} more ({len(paths)} files)"
    try:
        folder = os.path.commonpath([os.fspath(p.parent) for p in paths])
    except ValueError:  # absolute and relative paths, or several drives: no one folder
        return more
    return f"{more} in {os.path.join(folder, '')}"


def _path_length(compiled: CompiledProgram) -> float:
    return float(sum(step.path_length for step in compiled.steps))


UNTIMED_KINDS = frozenset({"runtime_target", "unknown_start"})
"""Diagnostic kinds of the motions the timing pass cannot time (:mod:`olp.passes.resolve`: a
motion to a run-time target and the motion after it): a cycle time without them is a lower
bound."""


def untimed_motions(compiled: CompiledProgram) -> int:
    """How many motions the cycle time leaves out (:data:`UNTIMED_KINDS`)."""
    return sum(1 for d in compiled.diagnostics if d.kind in UNTIMED_KINDS)


def _timing_note(compiled: CompiledProgram, pointer: bool = True) -> str:
    """How to read the cycle time: an estimate, an upper bound where zones became stops, a
    lower bound where motions to or from run-time targets are left out (neither with both)."""
    stops = sum(1 for d in compiled.diagnostics if d.kind == "zone_stop")
    untimed = untimed_motions(compiled)
    left_out = (
        f"{untimed} motion{'s' * (untimed > 1)} to or from run-time targets not timed"
        if untimed
        else ""
    )
    zones = f"{stops} zone{'s' * (stops > 1)} timed as exact stops" if stops else ""
    if untimed and stops:
        return f"incomplete, neither an upper nor a lower bound: {left_out}, {zones}"
    if untimed:
        return f"lower bound: {left_out}"
    if stops:
        return f"estimate; upper bound: {zones}"
    return "estimate; olp time says what it includes" if pointer else "estimate"


def timing_summary(compiled: CompiledProgram) -> str:
    """Program, station, cycle time and path length, one per line (``olp time``), then what the
    estimate includes and leaves out, once, in plain words (:func:`estimate_scope`)."""
    includes, excludes = estimate_scope(compiled)
    rows = [
        ("program", f"{compiled.program.name} ({compiled.program.source})"),
        ("station", f"{compiled.station.name} ({compiled.station.robot.name})"),
        ("cycle time", _cycle_line(compiled, 3, pointer=False)),
        *(_path_rows(compiled.paths) if compiled.paths else []),
        ("path length", f"{_path_length(compiled) * 1000:.1f} mm of TCP travel"),
        ("includes", includes),
        ("excludes", excludes),
    ]
    width = max(len(k) for k, _ in rows)
    indent = " " * (width + 2)
    text = "\n".join(
        textwrap.fill(v, 96, initial_indent=f"{k.ljust(width)}  ", subsequent_indent=indent)
        for k, v in rows
    )
    table = path_table(compiled.paths) if compiled.paths else ""
    return f"{text}\n\n{table}" if table else text


def estimate_scope(compiled: CompiledProgram) -> tuple[str, str]:
    """What the cycle time of ``compiled`` includes and what it leaves out, as two sentences in
    plain words, naming only the kinds of motion the program has (the model is
    :mod:`olp.passes.timing`'s default: jerk-limited path moves)."""
    moves = [s.instruction for s in compiled.steps if is_motion(s.instruction)]
    joint = [m for m in moves if m.kind == "joint"]
    path = [m for m in moves if m.kind != "joint"]
    on_ur = compiled.station.robot.vendor == "ur"
    parts = []
    if joint and on_ur:
        parts.append("joint moves as the movej trapezoid of the a and v the script writes")
    elif joint:
        blended = (
            " (blended ones cut their corners by their zones)"
            if any(not m.zone.is_fine for m in joint)
            else ""
        )
        parts.append(
            "joint moves at the shortest time within the robot's axis speed, acceleration and "
            f"jerk limits, scaled by the programmed percentages{blended}"
        )
    if path and on_ur:
        parts.append(
            "stop-to-stop linear and circular moves as the tool trapezoid of the a and v the "
            "script writes, blended ones like other robots' path moves"
        )
    elif path:
        accels = any(
            m.speed.linear_acceleration is not None or m.speed.angular_acceleration is not None
            for m in path
        )
        default = compiled.station.robot.limits.path_acceleration
        extra = ", path accelerations" if accels else ""
        if default is not None:
            extra += f", the controller's path acceleration of {default:g} m/s²"
        parts.append(
            "linear and circular moves at the shortest time within the axis limits (jerk "
            f"included) and the programmed TCP speed{extra}, zones rounded as blends"
        )
    parts.append("other instructions at fixed times (a wait its own)")
    excludes = (
        "the controller's look-ahead, interpolation cycle and filters, servo lag and "
        "settling at exact stops, payload and motor-torque limits, and the time of I/O and "
        "called routines beyond the fixed times"
    )
    unset = [m for m in path if m.speed.linear_acceleration is None]
    if unset and not on_ur and compiled.station.robot.limits.path_acceleration is None:
        excludes += (
            "; the controller's own path acceleration where the program sets none (unknown "
            "to the station: olp time --calibrate fits it from a recording)"
        )
    if compiled.paths is not None and compiled.paths.shortest is not None:
        excludes += (
            "; with control flow, a blend from one block into the next (across an IF, a loop's "
            "head or end) counts as an exact stop, and the path length and the per-instruction "
            "times follow the text, each instruction once"
        )
    untimed = untimed_motions(compiled)
    if untimed:
        excludes += (
            f"; {untimed} motion{'s' * (untimed > 1)} to a target known only at run time or "
            "from one (where the robot goes or comes from is unknown offline), so the total is "
            "a lower bound there"
        )
    stops = sum(1 for d in compiled.diagnostics if d.kind == "zone_stop")
    if stops:
        excludes += (
            f"; {stops} zone{'s' * (stops > 1)} that olp cannot blend (a joint move into a "
            "path move, or a UR movej) count as exact stops, so the total is an upper bound there"
        )
    return _sentence("; ".join(parts)), _sentence(excludes)


def _sentence(text: str) -> str:
    return text[:1].upper() + text[1:] + "."


def timing_table(compiled: CompiledProgram) -> str:
    """Per instruction: index, kind, source file:line, TCP path length (mm), time (s), with a
    total line (with control flow: each instruction once, in the text's order)."""
    header = ("#", "kind", "source", "path mm", "time s")
    rows = [
        (
            str(step.index),
            step.instruction.kind,
            f"{Path(step.instruction.span.file).name}:{step.instruction.span.line}",
            quantity(step.path_length * 1000, 2) if is_motion(step.instruction) else "",
            quantity(step.duration, 3),
        )
        for step in compiled.steps
    ]
    total = (
        "",
        "total" if compiled.paths is None else "text total",
        "",
        quantity(_path_length(compiled) * 1000, 2),
        quantity(compiled.cycle_time, 3),
    )
    return _columns([header, *rows, total], right=(0, 3, 4))


def sweep_table(
    linear: Sequence[float | None], joint: Sequence[float | None], times: NDArray[Any]
) -> str:
    """Cycle times (L, J) s as a table: rows linear speed (mm/s), columns joint speed (%);
    ``None`` speeds are the programmed ones, NaN times (not timed) show as ``-``."""
    corner = "mm/s \\ %"
    header = [corner, *("prog." if p is None else f"{p * 100:g}" for p in joint)]
    rows = [
        ["prog." if v is None else f"{v * 1000:g}", *(_seconds(t) for t in line)]
        for v, line in zip(linear, times, strict=True)
    ]
    title = "cycle time (s): rows TCP speed of path moves (mm/s), columns joint speed (%)"
    return title + "\n" + _columns([header, *rows], right=tuple(range(len(header))))


def _seconds(value: float) -> str:
    return "-" if not np.isfinite(value) else quantity(value, 2)


def _columns(rows: Sequence[Sequence[str]], right: tuple[int, ...]) -> str:
    """Rows of cells as aligned text columns (right-aligned where listed), two spaces apart."""
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    lines = []
    for row in rows:
        cells = [
            cell.rjust(w) if i in right else cell.ljust(w)
            for i, (cell, w) in enumerate(zip(row, widths, strict=True))
        ]
        lines.append("  ".join(cells).rstrip())
    return "\n".join(lines)


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
    shown, start, _ = excerpt(line.rstrip().expandtabs(1), max(span.column - 1, 0), 1)
    parts = [head, f"    {shown}", "    " + " " * start + "^"]
    return "\n".join(parts + ([rest] if rest else []))
