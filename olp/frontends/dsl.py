"""Python DSL frontend: run a ``.py`` robot program and record what it asks the robot to do.

The program is ordinary Python executed with the names of :mod:`olp.dsl` already defined
(``robot``, ``transl``, ``Pose``, ``param``...). **A .py program is code that olp runs, with
your rights**, like any script: only run programs you trust. :func:`load_dsl` (what ``olp
build``, ``check`` and ``time`` use) runs it in a child process with a time limit and reports
how it ended (:mod:`olp.frontends.dsl_process`); :func:`run_dsl` runs program text in the
calling process, for the child and for callers who already trust the text. Each call on
``robot`` records one IR instruction whose span is the user's call (file, line and column of
the innermost frame in the program file), so every later diagnostic points at the user's line.

While the program runs, RoboDK's module names (``robolink``, ``robodk``, ``robodk.robolink``,
``robodk.robomath`` ...) import olp's answers to them (:mod:`olp.compat`), so a RoboDK script
runs unchanged; after the run they are gone. A script that fills RoboDK program items builds
that program (:meth:`Session.built`).

Parameters come from the command line (``--set SPEED=50``) and are read with
``param("SPEED", default)``: text is converted to the type of the default (bool, int, float or
text; without a default an int, else a float, else the text). A ``--set`` name the program
never asks for is a :class:`~olp.errors.UsageError` (a typo must not pass silently).

Errors: a syntax error is a :class:`~olp.errors.ParseError`; a wrong DSL call (or RoboDK call,
:mod:`olp.compat`) and any other exception raised by the program a
:class:`~olp.frontends.dsl_process.ProgramRunError` (a ParseError printed as "error running
the program", with the exception's own type and message), each at the user's line (the innermost
traceback frame in the program file) with the line's text and a caret under the failing
expression, never a traceback dump; when the exception passed through several of the user's
own frames, the hint lists them (olp's and libraries' frames left out). ``sys.exit()`` /
``SystemExit(0)`` ends the program normally; a program that records no instruction at all is
an error (an empty robot program is never what was meant). Messages quote at most a short
excerpt of the program's text and values.
"""

from __future__ import annotations

import linecache
import math
import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from importlib.util import decode_source
from pathlib import Path
from traceback import walk_tb
from types import CodeType, FrameType, TracebackType
from typing import TYPE_CHECKING, Any

from olp import dsl, ir
from olp.errors import OlpError, ParseError, UsageError
from olp.frontends.bundled import DEFAULT_TIMEOUT, check_timeout
from olp.frontends.dsl_process import ProgramRunError, run_in_child

if TYPE_CHECKING:
    from olp.station.model import Station


@dataclass(frozen=True, slots=True)
class IgnoredLine:
    """A call olp recognised but did not lower (e.g. a linear acceleration): where and why."""

    span: ir.SourceSpan
    text: str
    reason: str


@dataclass(frozen=True, slots=True)
class ProgramWarning:
    """A warning the program reported with :func:`olp.dsl.warn` (e.g. a skipped target)."""

    span: ir.SourceSpan
    message: str


@dataclass(slots=True)
class ProgramRecord:
    """A program item the script made (RoboDK's ``AddProgram``): its instructions, and
    whether ``MakeProgram`` asked for it."""

    name: str
    instructions: list[ir.Instruction]
    made: bool = False


@dataclass(frozen=True, slots=True, kw_only=True)
class DslResult:
    """What a DSL run recorded: the program, ignored settings, the program's own warnings and
    the parameters it declared."""

    program: ir.Program
    ignored: tuple[IgnoredLine, ...] = ()
    warnings: tuple[ProgramWarning, ...] = ()
    params: tuple[str, ...] = ()


def load_dsl(
    path: str | os.PathLike[str],
    station: Station | None = None,
    params: Mapping[str, object] | None = None,
    *,
    timeout: float | None = DEFAULT_TIMEOUT,
) -> DslResult:
    """Run the DSL program at ``path`` in a child process and return what it recorded.

    Parameters
    ----------
    path : a ``.py`` file (any encoding Python accepts: UTF-8 or a PEP 263 cookie).
    station : the station the program asks (home, named tools and frames, joint limits,
        feasibility tests); without it those calls raise a located ParseError. The child gets
        a copy of this very station.
    params : ``--set`` values by name (text from the command line, or Python values that can
        be pickled).
    timeout : seconds the program may run (interpreter start included) before it is killed
        and reported at the line it was running; None for no limit.
    """
    check_timeout(timeout)
    filename = os.fspath(path)
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise UsageError(f"cannot read program {dsl.quote(filename)}: {exc.strerror}") from None
    return run_in_child(filename, data, station, params or {}, timeout)


def run_dsl(
    source: bytes | str,
    filename: str = "<string>",
    station: Station | None = None,
    params: Mapping[str, object] | None = None,
    *,
    catch_interrupts: bool = False,
) -> DslResult:
    """Run DSL program text **in this process**, without a time limit (see :func:`load_dsl`
    for untrusted files); ``filename`` names it in spans. ``catch_interrupts``: a
    KeyboardInterrupt is the program's own exception (in the child, where Ctrl-C never
    arrives) rather than the user stopping olp."""
    text = _decode(source, filename)
    code = _compile(text, filename)
    session = Session(filename, text, station, params)
    from olp.compat import importable

    with dsl.active(session), importable():
        _execute(code, session, catch_interrupts)
    unused = session.unused_params()
    if unused:
        declared = dsl.names_list(session.declared) or "none"
        raise UsageError(
            f"--set {dsl.names_list(unused)}: the program has no such parameter "
            f"(it reads: {declared})"
        )
    return _result(session, filename)


def _result(session: Session, filename: str) -> DslResult:
    """What the run recorded; the checks that need the finished run."""
    if not session.recorded():
        raise ProgramRunError(
            "the program recorded no robot instructions (no move, I/O, wait, call or comment)",
            ir.SourceSpan(filename, 1, 1),
            session.line_text(1),
            "a program that ends early (sys.exit) or skips every move would write an empty "
            "robot program",
        )
    try:
        return session.result()
    except dsl.DslError as exc:
        raise ParseError(str(exc), ir.SourceSpan(filename, 1, 1), session.line_text(1)) from None


# ------------------------------------------------------------------------------------------------
# Reading and compiling


def _decode(source: bytes | str, filename: str) -> str:
    if isinstance(source, str):
        return source
    try:
        return decode_source(source)
    except SyntaxError as exc:
        raise ParseError(
            f"cannot read the file: {exc.msg}", ir.SourceSpan(filename, 1, 1)
        ) from None
    except UnicodeDecodeError as exc:
        line = source.count(b"\n", 0, exc.start) + 1
        raise ParseError(
            f"the file is not valid UTF-8 (byte {source[exc.start]:#04x})",
            ir.SourceSpan(filename, line, 1),
            hint="save it as UTF-8 or declare its encoding (# -*- coding: ... -*-)",
        ) from None


def _compile(text: str, filename: str) -> CodeType:
    try:
        return compile(text, filename, "exec", dont_inherit=True)
    except SyntaxError as exc:
        raise _syntax_error(exc, text, filename) from None
    except (ValueError, MemoryError, RecursionError) as exc:
        raise ParseError(
            f"cannot compile the program: {exc}", ir.SourceSpan(filename, 1, 1)
        ) from None


def _syntax_error(exc: SyntaxError, text: str, filename: str) -> ParseError:
    lines = text.split("\n")
    line = exc.lineno if exc.lineno and 1 <= exc.lineno <= len(lines) else len(lines)
    column = max(exc.offset or 1, 1)
    end = exc.end_offset if exc.end_lineno == line and exc.end_offset else None
    span = ir.SourceSpan(filename, line, column, line if end else None, end)
    return ParseError(f"Python syntax error: {exc.msg}", span, lines[line - 1] if lines else None)


# ------------------------------------------------------------------------------------------------
# Running


def _execute(code: CodeType, session: Session, catch_interrupts: bool = False) -> None:
    try:
        exec(code, session.namespace())
    except SystemExit as exc:
        if exc.code not in (None, 0):
            shown = dsl.brief(exc.code)
            raise _located(exc, session, f"the program exited with {shown}") from exc
    except OlpError:
        raise
    except KeyboardInterrupt as exc:
        if not catch_interrupts:
            raise
        raise _located(exc, session, _message(exc)) from exc
    except BaseException as exc:
        raise _located(exc, session, _message(exc)) from exc


MESSAGE_CHARS = 300
"""Longest exception message of the program's that an error repeats."""
TRACE_FRAMES = 8
"""Most frames of the program's own traceback a hint lists (the innermost ones)."""


def _message(exc: BaseException) -> str:
    try:
        text = str(exc)
    except Exception:
        text = "(its message cannot be shown)"
    if len(text) > MESSAGE_CHARS:
        text = f"{text[:MESSAGE_CHARS]}... ({len(text)} characters)"
    if isinstance(exc, dsl.DslError):
        return text
    name = type(exc).__name__[: dsl.EXCERPT_CHARS]
    return f"{name}: {text}" if text else name


def _located(exc: BaseException, session: Session, message: str) -> ParseError:
    """A ParseError at the innermost frame of the program file in ``exc``'s traceback."""
    frame = _innermost(exc.__traceback__, session.filename)
    if frame is None:
        span = ir.SourceSpan(session.filename, 1, 1)
    else:
        span = session.position(frame.tb_frame.f_code, frame.tb_lasti, frame.tb_lineno)
    trace = _user_trace(exc.__traceback__, session)
    hint = f"the program's traceback (most recent call last):{trace}" if trace else None
    # The program was read; whatever stops it now (a wrong robot call or its own exception)
    # is an error running it, never a "parse error".
    return ProgramRunError(message, span, session.line_text(span.line), hint)


def _user_trace(tb: TracebackType | None, session: Session) -> str:
    """The frames of ``tb`` in the user's own files (not olp's, not the standard library's or
    installed packages'), one indented line each; empty when there are fewer than two."""
    frames = [(f.f_code.co_filename, line, f.f_code.co_name) for f, line in walk_tb(tb)]
    mine = [frame for frame in frames if _is_users(frame[0], session.filename)]
    if len(mine) < 2:
        return ""
    lines = []
    if len(mine) > TRACE_FRAMES:
        lines.append(f"... {len(mine) - TRACE_FRAMES} frames left out")
        mine = mine[-TRACE_FRAMES:]
    for filename, line, name in mine:
        text = session.line_text(line) if filename == session.filename else None
        code = (text or linecache.getline(filename, line)).strip()
        code = code if len(code) <= 80 else code[:80] + "..."
        lines.append(f"{filename}:{line} in {name[:60]}: {code}")
    return "".join("\n          " + line for line in lines)


_PREFIXES = {sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix}
_NOT_USERS = (*(Path(p).resolve() for p in _PREFIXES), Path(__file__).resolve().parents[1])
"""Folders whose files are not the user's: Python's own (standard library, installed
packages) and olp's."""


def _is_users(filename: str, program: str) -> bool:
    if filename == program:
        return True
    if filename.startswith("<"):
        return False
    try:
        resolved = Path(filename).resolve()
    except (OSError, ValueError):
        return False
    return not any(resolved.is_relative_to(folder) for folder in _NOT_USERS)


def _innermost(tb: TracebackType | None, filename: str) -> TracebackType | None:
    found = None
    while tb is not None:
        if tb.tb_frame.f_code.co_filename == filename:
            found = tb
        tb = tb.tb_next
    return found


# ------------------------------------------------------------------------------------------------
# The session a program talks to


class Session:
    """One run of a DSL program: its source, the station, the parameters and the recording."""

    def __init__(
        self,
        filename: str,
        text: str,
        station: Station | None = None,
        params: Mapping[str, object] | None = None,
    ) -> None:
        self.filename = filename
        self.lines = text.split("\n")
        self.station = station
        self.params = dict(params or {})
        self.declared: list[str] = []
        self.name = Path(filename).stem
        self.instructions: list[ir.Instruction] = []
        self.ignored: list[IgnoredLine] = []
        self.warnings: list[ProgramWarning] = []
        self.targets: dict[str, dsl.Target] = {}
        self.programs: list[ProgramRecord] = []
        self.compat: Any = None
        self._tool_numbers: dict[str, int] = {}
        self._noted: set[tuple[ir.SourceSpan, str]] = set()
        self.robot = dsl.Robot(self)
        self._positions: dict[CodeType, list[tuple[Any, ...]]] = {}

    def namespace(self) -> dict[str, Any]:
        """The globals a program runs with: the public names of :mod:`olp.dsl`, and ``robot``
        bound to this run."""
        names = {name: getattr(dsl, name) for name in dsl.__all__}
        names["robot"] = self.robot
        return {
            "__name__": "__main__",
            "__file__": self.filename,
            "__builtins__": __builtins__,
            **names,
        }

    def tool_number(self, name: str) -> int:
        """The controller number of a tool the program defines: the same for the same name,
        else the next one above every station tool's and every earlier program tool's (posts
        that address tools by number, Fanuc's ``UTOOL_NUM``, need one)."""
        if name not in self._tool_numbers:
            station_numbers = (
                [t.number or 0 for t in self.station.tools.values()] if self.station else []
            )
            used = [0, *station_numbers, *self._tool_numbers.values()]
            self._tool_numbers[name] = max(used) + 1
        return self._tool_numbers[name]

    def recorded(self) -> bool:
        """Whether the run recorded any instruction (on the robot or in a program item)."""
        return bool(self.instructions) or any(p.instructions for p in self.programs)

    def built(self) -> tuple[str, list[ir.Instruction]]:
        """The program olp builds: the robot's own recording, or, when the script filled
        program items (RoboDK's ``AddProgram``), that program; the robot's moves were then its
        simulation (noted). Several filled programs need ``MakeProgram`` on one of them."""
        filled = [p for p in self.programs if p.instructions]
        if not filled:
            return self.name, self.instructions
        made = [p for p in filled if p.made]
        chosen = made[-1] if made else filled[0] if len(filled) == 1 else None
        if chosen is None:
            names = dsl.names_list([p.name for p in filled])
            raise dsl.DslError(
                f"the script filled {len(filled)} programs ({names}); olp builds one program "
                "per run: call MakeProgram() on the one to build"
            )
        if self.instructions:
            first = next((i.span for i in self.instructions if i.span is not None), None)
            if first is not None:
                reason = (
                    f"the robot's own moves were simulated only; olp builds program "
                    f"{dsl.quote(chosen.name)}"
                )
                text = (self.line_text(first.line) or "").strip()
                self.ignored.append(IgnoredLine(first, text, reason))
        return chosen.name, chosen.instructions

    def note(self, reason: str) -> None:
        """A call olp honours only partly or not at all (a GUI pop-up, a live connection):
        noted once per line in the build output."""
        span = self.span()
        if (span, reason) not in self._noted:
            self._noted.add((span, reason))
            self.ignored.append(
                IgnoredLine(span, (self.line_text(span.line) or "").strip(), reason)
            )

    def result(self) -> DslResult:
        name, instructions = self.built()
        program = ir.Program(name=name, instructions=tuple(instructions), source=self.filename)
        return DslResult(
            program=program,
            ignored=tuple(self.ignored),
            warnings=tuple(self.warnings),
            params=tuple(self.declared),
        )

    # ---- spans
    def span(self) -> ir.SourceSpan:
        """Where the user's code called the DSL: the innermost frame of the program file."""
        frame: FrameType | None = sys._getframe(1)
        while frame is not None and frame.f_code.co_filename != self.filename:
            frame = frame.f_back
        if frame is None:
            return ir.SourceSpan(self.filename, 1, 1)
        return self.position(frame.f_code, frame.f_lasti, frame.f_lineno)

    def position(self, code: CodeType, lasti: int, lineno: int | None) -> ir.SourceSpan:
        """The span (1-based characters) of the bytecode instruction at ``lasti`` of ``code``:
        the whole call expression, from Python's position table (Python >= 3.11)."""
        positions = self._positions.get(code)
        if positions is None and hasattr(code, "co_positions"):
            positions = self._positions[code] = list(code.co_positions())
        index = lasti // 2
        entry = positions[index] if positions and 0 <= index < len(positions) else ()
        line, end_line, col, end_col = (*entry, None, None, None, None)[:4]
        line = line or lineno or 1
        if col is None:
            return ir.SourceSpan(self.filename, line, 1)
        start = self._chars(line, col) + 1
        if end_line != line or end_col is None:
            return ir.SourceSpan(self.filename, line, start)
        return ir.SourceSpan(self.filename, line, start, line, self._chars(line, end_col) + 1)

    def _chars(self, line: int, byte_offset: int) -> int:
        # The position table counts UTF-8 bytes; spans count characters.
        text = self.line_text(line) or ""
        return len(text.encode("utf-8")[:byte_offset].decode("utf-8", errors="ignore"))

    def line_text(self, line: int) -> str | None:
        return self.lines[line - 1] if 1 <= line <= len(self.lines) else None

    # ---- recording
    def record(self, instruction: ir.Instruction) -> None:
        self.instructions.append(instruction)

    def ignore(self, reason: str) -> None:
        span = self.span()
        self.ignored.append(IgnoredLine(span, (self.line_text(span.line) or "").strip(), reason))

    def warn(self, message: str) -> None:
        self.warnings.append(ProgramWarning(self.span(), message))

    # ---- parameters
    def param(self, name: str, default: object = None) -> Any:
        if not isinstance(name, str) or not name.isidentifier():
            raise dsl.DslError(f"param: the name must be an identifier like 'SPEED', got {name!r}")
        if name not in self.declared:
            self.declared.append(name)
        if name in self.params:
            return convert_param(name, self.params[name], default)
        if default is None:
            raise dsl.DslError(f"parameter {name} has no default: give it with --set {name}=VALUE")
        return default

    def unused_params(self) -> list[str]:
        return [name for name in self.params if name not in self.declared]


def convert_param(name: str, raw: object, default: object) -> Any:
    """A ``--set`` value as the type of the parameter's default.

    Text (from the command line) becomes a bool (``true/false/yes/no/on/off/1/0``), an int, a
    float (finite) or stays text, following the default; without a default an int, else a
    float, else the text. Python values (library callers) are taken as they are.
    """
    if not isinstance(raw, str):
        return raw
    if isinstance(default, bool):
        word = raw.strip().lower()
        if word not in dsl.TRUE_WORDS | dsl.FALSE_WORDS:
            raise dsl.DslError(f"--set {name}={raw}: expected true or false (default {default})")
        return word in dsl.TRUE_WORDS
    if isinstance(default, str):
        return raw
    value = _guess(raw)
    if isinstance(default, int) and not isinstance(value, int):
        raise dsl.DslError(f"--set {name}={raw}: expected an integer (default {default})")
    if isinstance(default, float):
        if not isinstance(value, int | float) or not math.isfinite(value):
            raise dsl.DslError(f"--set {name}={raw}: expected a finite number (default {default})")
        return float(value)
    return value


def _guess(text: str) -> object:
    """Command-line text as an int, else a float, else the text itself."""
    stripped = text.strip()
    for kind in (int, float):
        try:
            return kind(stripped)
        except ValueError:
            continue
    return text
