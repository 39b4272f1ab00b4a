"""``olp time STATION PROGRAM``: the estimated cycle time, per instruction and over speed sweeps;
the joint trajectory as CSV and as a plot.

A sweep overrides the programmed speeds of *every* motion: ``--sweep-linear`` sets the TCP speed
of every path move (LIN, CIRC), ``--sweep-joint`` the joint speed (% of each axis' maximum) of
every joint move. Accelerations and orientation-speed limits stay as programmed. Without one of
the two options, that dimension keeps the programmed speeds.

``olp time STATION --calibrate LOG.csv [--output OVERRIDE.yaml]`` fits the station robot's
per-axis velocity, acceleration and jerk limits, and the controller's path acceleration from
its straight-line moves (of the ``--calibrate-tool`` TCP), to a recorded joint trajectory (olp's
own trajectory CSV, or a UR RTDE recording) and writes them as a station override (printed
without ``--output``), with the residual of re-timing the recording with them
(:mod:`olp.passes.timing.calibrate`).

A program with branches and loops is timed per path: the shortest and the longest path, with
the branch choices that give each, or the path ``--assume`` names (inputs ``in3=true``,
variables ``count=4``, loop passes ``loop:12=5``; :mod:`olp.passes.timing.branches`). The table
per instruction follows the text, each instruction once; ``--trajectory`` and ``--plot`` follow
the path when every choice is decided (unrolled, :mod:`olp.passes.timing.unroll`), else the
text, and say which on stderr.

Exit codes as for ``olp build``: 0 timed, 1 the program has errors, 2 bad input.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

from olp.commands.common import EXIT_OK, EXIT_PROGRAM_ERRORS, print_diagnostics, require_files
from olp.commands.options import (
    add_assume_option,
    add_check_options,
    add_collision_options,
    add_program,
    add_program_options,
    build_options,
    parse_program,
)
from olp.errors import UsageError

if TYPE_CHECKING:
    from olp.compiled import CompiledProgram
    from olp.passes.pipeline import BuildOptions

NAME = "time"
HELP = "estimate a program's cycle time: per instruction, speed sweeps, trajectory CSV and plot"

OVERRIDABLE = ("set_output", "wait_input", "call", "comment")
"""Instruction kinds whose default time ``--time KIND=SECONDS`` may override."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("station", help="station YAML file")
    add_program(parser, optional=True)
    parser.add_argument(
        "--calibrate",
        metavar="LOG.csv",
        help="instead of a program: fit the robot's joint velocity, acceleration and jerk "
        "limits (and the controller's path acceleration, from its straight-line moves) to this "
        "recorded trajectory (time_s + j1_deg.. columns, or UR RTDE's timestamp + "
        "actual_q_0..) and print them as a station override",
    )
    parser.add_argument(
        "--output", metavar="YAML", help="with --calibrate: write the station override here"
    )
    parser.add_argument(
        "--calibrate-tool",
        metavar="NAME",
        help="with --calibrate: the station tool whose TCP ran the recorded path moves (to find "
        "them and fit the path acceleration; default: the flange)",
    )
    parser.add_argument(
        "--sweep-linear",
        metavar="MM_S,...",
        help="TCP speeds (mm/s) for every path move, e.g. 50,100,200: a cycle-time table",
    )
    parser.add_argument(
        "--sweep-joint",
        metavar="PCT,...",
        help="joint speeds (%% of the axes' maximum) for every joint move, e.g. 25,50,100",
    )
    parser.add_argument("--trajectory", metavar="CSV", help="write the sampled trajectory here")
    parser.add_argument(
        "--dt", type=float, default=0.01, help="trajectory sampling step in s (default: 0.01)"
    )
    parser.add_argument("--plot", metavar="PNG", help="plot joint positions and velocities here")
    parser.add_argument(
        "--time",
        action="append",
        default=[],
        metavar="KIND=SECONDS",
        help="time charged for an instruction kind (set_output, wait_input, call, comment) or a "
        "named call (call:NAME); repeatable, e.g. --time call:SprayOn=1.5",
    )
    add_assume_option(parser)
    add_check_options(parser)
    add_collision_options(parser)
    add_program_options(parser)
    parser.add_argument(
        "-q", "--quiet", action="store_true", help="results only: no table, progress or warnings"
    )


def run(args: argparse.Namespace) -> int:
    from olp import progress
    from olp.api import compile, load_station

    if args.calibrate is not None or args.program is None:
        return calibrate(args)
    if args.output is not None or args.calibrate_tool is not None:
        raise UsageError("--output and --calibrate-tool go with --calibrate")
    require_files(args.station, args.program)
    linear = _speed_list(args.sweep_linear, "--sweep-linear", "mm/s", 1e-3)
    joint = _speed_list(args.sweep_joint, "--sweep-joint", "%", 1e-2, upper=1.0)
    other_times = parse_times(args.time)
    options = build_options(args, other_times)
    if not (math.isfinite(args.dt) and args.dt > 0):
        raise UsageError(f"--dt must be a positive number of seconds, got {args.dt}")
    _check_paths(args)
    if args.plot:
        from olp.trajectory import require_matplotlib

        require_matplotlib()
    station = load_station(args.station)
    with progress.showing(progress.terminal_reporter(args.quiet)):
        with progress.stage("read"):
            parsed = parse_program(args, station)
        compiled = compile(parsed.program, station, options)
    print_diagnostics(parsed.notes + compiled.diagnostics, args.program, quiet=args.quiet)
    if not compiled.ok:
        return EXIT_PROGRAM_ERRORS
    _print_results(compiled, args.quiet)
    if linear or joint:
        _print_sweep(compiled, linear, joint, options, args.quiet)
    _write_outputs(compiled, args, options)
    return EXIT_OK


def calibrate(args: argparse.Namespace) -> int:
    """``--calibrate``: fit, print the fit and write (or print) the station override."""
    from pathlib import Path

    from olp.api import load_station
    from olp.output import check_output_file
    from olp.passes.timing.calibrate import fit_limits, override_yaml, read_recording
    from olp.trajectory import write_atomic

    if args.calibrate is None or args.program is not None:
        raise UsageError("give either a program to time or --calibrate LOG.csv, not both")
    require_files(args.station, args.calibrate)
    output = check_output_file(args.output, "--output") if args.output else None
    station = load_station(args.station)
    text = Path(args.calibrate).read_text(encoding="utf-8", errors="replace")
    recording = read_recording(text, args.calibrate, station.robot.dof)
    tool = None
    if args.calibrate_tool is not None:
        found = station.tools.get(args.calibrate_tool)
        if found is None or found.pose is None:
            known = ", ".join(sorted(station.tools)) or "none"
            raise UsageError(
                f"--calibrate-tool: the station has no tool {args.calibrate_tool!r} (its tools: "
                f"{known})"
            )
        tool = found.pose
    fitted = fit_limits(recording, station, tool)
    override = override_yaml(fitted, Path(args.calibrate).name)
    path = (
        f", path acceleration {fitted.path_acceleration:.3f} m/s² from {fitted.path_moves} "
        "path move(s)"
        if fitted.path_acceleration is not None
        else ", no path move (no path acceleration)"
    )
    print(
        f"fitted {station.robot.name} to {fitted.moves} recorded move(s){path}: re-timed "
        f"{fitted.retimed:.3f} s against {fitted.recorded:.3f} s recorded "
        f"(residual {fitted.residual * 100:+.2f} %)"
    )
    if output is None:
        print(override, end="")
    else:
        write_atomic(output, override.encode("utf-8"))
        if not args.quiet:
            print(f"written: {output}")
    return EXIT_OK


def _check_paths(args: argparse.Namespace) -> None:
    from olp.output import check_distinct, check_output_file

    paths = [
        (f"--{o}", check_output_file(getattr(args, o), f"--{o}") if getattr(args, o) else None)
        for o in ("trajectory", "plot")
    ]
    check_distinct(paths)


def _speed_list(
    text: str | None, option: str, unit: str, to_si: float, upper: float | None = None
) -> list[float]:
    """Comma-separated positive speeds in ``unit``, converted by ``to_si`` (empty if absent)."""
    if text is None:
        return []
    try:
        values = [float(part) * to_si for part in text.split(",")]
    except ValueError:
        msg = f"{option}: expected numbers in {unit} separated by commas, got {text!r}"
        raise UsageError(msg) from None
    bad = [v / to_si for v in values if not (math.isfinite(v) and v > 0)]
    bad += [v / to_si for v in values if upper is not None and v > upper]
    if bad:
        limit = f" and at most {upper / to_si:g}" if upper is not None else ""
        raise UsageError(f"{option}: speeds must be > 0{limit} {unit}, got {bad[0]:g}")
    return values


def parse_times(items: list[str]) -> dict[str, float]:
    """``KIND=SECONDS`` items as a time table for :func:`olp.passes.timing.time_program`."""
    table = {}
    for item in items:
        kind, sep, value = item.partition("=")
        kind = kind.strip()
        if not sep or not (kind in OVERRIDABLE or (kind.startswith("call:") and kind[5:])):
            known = ", ".join(OVERRIDABLE)
            raise UsageError(
                f"--time {item!r}: expected KIND=SECONDS, KIND one of {known}, call:NAME"
            )
        try:
            seconds = float(value)
        except ValueError:
            raise UsageError(f"--time {item!r}: {value!r} is not a number of seconds") from None
        if not (math.isfinite(seconds) and seconds >= 0):
            raise UsageError(f"--time {item!r}: the time must be >= 0 s")
        table[kind] = seconds
    return table


def _print_results(compiled: CompiledProgram, quiet: bool) -> None:
    from olp.report import timing_summary, timing_table

    print(timing_summary(compiled))
    if not quiet:
        print()
        print(timing_table(compiled))


def _print_sweep(
    compiled: CompiledProgram,
    linear: list[float],
    joint: list[float],
    options: BuildOptions,
    quiet: bool,
) -> None:
    from olp.passes.timing import path_sweep, speed_sweep
    from olp.report import sweep_table

    rows: list[float | None] = list(linear) or [None]
    columns: list[float | None] = list(joint) or [None]
    show = not quiet and sys.stderr.isatty()
    report = _progress if show else None
    if compiled.paths is not None:  # control flow: per path, as the cycle time above
        ends = path_sweep(compiled, rows, columns, options, progress=report)
        tables = [("shortest path", ends[..., 0]), ("longest path", ends[..., 1])]
    else:
        tables = [("", speed_sweep(compiled, rows, columns, options.other_times, progress=report))]
    if show:
        print("\r\033[K", end="", file=sys.stderr, flush=True)
    for which, table in tables:
        print()
        title = f"{which}: " if which else ""
        print(title + sweep_table(rows, columns, table))


def _progress(done: int, total: int) -> None:
    print(f"\rtiming speeds {done}/{total}", end="", file=sys.stderr, flush=True)


def _write_outputs(
    compiled: CompiledProgram, args: argparse.Namespace, options: BuildOptions
) -> None:
    if not (args.trajectory or args.plot):
        return
    from olp.trajectory import instruction_starts, plot_trajectory, sample_program, write_csv

    if compiled.paths is not None:
        compiled, said = path_program(compiled, options)
        if not args.quiet:
            print(said, file=sys.stderr)
    sampled = sample_program(compiled, args.dt)
    writers: dict[str, Callable[[str], object]] = {
        "trajectory": lambda path: write_csv(sampled, path),
        "plot": lambda path: plot_trajectory(sampled, path, instruction_starts(compiled)),
    }
    for option, write in writers.items():
        path = getattr(args, option)
        if path:
            write(path)
            if not args.quiet:
                print(f"written: {path}")


def path_program(compiled: CompiledProgram, options: BuildOptions) -> tuple[CompiledProgram, str]:
    """The program a trajectory of ``compiled`` (with control flow) is sampled from: the path
    every choice names, unrolled and compiled as a straight program
    (:mod:`olp.passes.timing.unroll`), else the text; and a sentence that says which."""
    import dataclasses

    from olp.api import compile
    from olp.passes.timing.conditions import Assumptions
    from olp.passes.timing.unroll import unroll

    text = "the trajectory follows the text, each instruction once: "
    paths = compiled.paths
    if paths is None or not paths.decided:
        return compiled, text + "the program has open choices (name one path with --assume)"
    unrolled = unroll(compiled.program, options.assume)
    if unrolled.program is None:
        return compiled, text + unrolled.reason
    plain = dataclasses.replace(options, assume=Assumptions())
    straight = compile(unrolled.program, compiled.station, plain)
    if not straight.ok:
        first = next(d for d in straight.diagnostics if d.severity == "error")
        return compiled, text + f"the path's own run has errors ({first.message})"
    return straight, (
        f"the trajectory follows the path named: {len(straight.steps)} instructions, "
        f"{straight.cycle_time:.3f} s"
    )
