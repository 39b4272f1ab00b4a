"""Run a Python DSL program in a child process with a time limit, and report how it ended.

A ``.py`` program is code: it runs with the user's rights, like any script. olp never runs it in
its own process. :func:`run_in_child` starts a fresh interpreter (:data:`sys.executable`) that
loads the program and runs it with :func:`olp.frontends.dsl.run_dsl`, so that ``os._exit``, a
crash, an endless loop or a stray thread cannot end, hang or silently empty an olp build. Every
end is reported honestly, as an :class:`~olp.errors.OlpError` at the program's file and line:

* the program finished: its :class:`~olp.frontends.dsl.DslResult` (or the located error of
  its own exception) comes back as a pickle in a private temporary folder, read by an
  unpickler that builds only olp data classes, numpy arrays and plain data; anything else
  (garbage, an object of the program's own class) is an error, never a crash of olp;
* it ran longer than ``timeout`` seconds: the child and every process it started are killed;
  the error names the line it was running (a :mod:`faulthandler` stack dump on ``SIGUSR1``);
* it ended the process itself before olp recorded its result (``os._exit(0)``), exited with
  another code, or was killed by a signal (a crash): an error, at the ``os._exit`` call or the
  crashing line when known.

Why :mod:`subprocess` and not :mod:`multiprocessing` with the spawn context: spawn re-imports
the caller's ``__main__`` module in the child (a script that calls ``olp.build`` without a
``__main__`` guard would run again there), and it gives no process group to kill the program's
own children with on a timeout. A ``python -c`` child does neither and reports its exit code
and signal directly.

The child's ``sys.path`` does not start with the working directory (a ``numpy.py`` lying there
is not imported) and does start with the folder that holds this olp, so the child runs the same
olp as the caller. The program gets the station as a pickle of the caller's
:class:`~olp.station.model.Station` (the same object, including stations built in memory, and
no second read of a file that may have changed), its ``--set`` values, ``sys.argv`` as
``python prog.py`` would set it, an empty stdin and the caller's stdout and stderr (its prints
reach the user as they happen, like any script's). ``PYTHONHASHSEED`` is 0 unless the user set
it, so a program that iterates over a set of strings writes the same robot program on every
run.
"""

from __future__ import annotations

import contextlib
import dataclasses
import enum
import os
import pickle
import re
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, NoReturn

from olp import ir
from olp.errors import OlpError, ParseError, PostError, StationError, UsageError
from olp.frontends.bundled import DEFAULT_TIMEOUT, check_timeout

if TYPE_CHECKING:
    from olp.frontends.dsl import DslResult
    from olp.station.model import Station

_REQUEST, _RESULT, _STACK, _CRASH, _EXIT = "request", "result", "stack", "crash", "exit"
_DUMP_WAIT = 2.0
"""Seconds the parent waits for the child's stack dump after a timeout before killing it."""
_TEXT_LIMIT = 1000
"""Longest message or hint accepted back from the child (it may be the program's own text)."""

_BOOT = (
    "import sys\n"
    "if sys.path and sys.path[0] == '':\n"
    "    del sys.path[0]\n"
    "from olp.frontends.dsl_process import child_main\n"
    "child_main(sys.argv[1])\n"
)
"""The child's ``-c`` code: ``python -c`` puts the working directory first on ``sys.path``;
it goes before anything but ``sys`` is imported."""


class ProgramRunError(ParseError):
    """A Python program failed while it ran: its own exception, a non-zero exit, a timeout,
    a crash. Located at the program's line, like every ParseError, but not called a parse
    error: the program was read; running it went wrong."""

    kind = "error running the program"


_ERRORS: dict[str, type[OlpError]] = {
    cls.__name__: cls
    for cls in (OlpError, ParseError, UsageError, StationError, PostError, ProgramRunError)
}


# ------------------------------------------------------------------------------------------------
# Parent


def run_in_child(
    path: str | os.PathLike[str],
    source: bytes,
    station: Station | None,
    params: Mapping[str, object],
    timeout: float | None = DEFAULT_TIMEOUT,
) -> DslResult:
    """Run the program ``source`` (read from ``path``) in a child process.

    Parameters
    ----------
    path : the program file, as spans name it.
    source : its bytes.
    station, params : as for :func:`olp.frontends.dsl.run_dsl`.
    timeout : seconds (> 0) before the child is killed; None for no limit.

    Raises the program's own located :class:`~olp.errors.OlpError`, a
    :class:`ProgramRunError` for a timeout, an early or failed exit, a crash or an unreadable
    result, or a :class:`~olp.errors.UsageError` when no child process can be started.
    """
    limit = check_timeout(timeout)
    program = _Program(os.fspath(path), source)
    # The program may have changed the folder's permissions: cleaning up must not fail olp.
    with tempfile.TemporaryDirectory(prefix="olp-dsl-", ignore_cleanup_errors=True) as folder:
        job = Path(folder).resolve()
        _write_request(job, program, station, params)
        code = _run(job, limit)
        return _outcome(job, program, code, limit)


class _Program:
    """The program's file name and lines, to point errors found outside the child at them."""

    def __init__(self, filename: str, source: bytes) -> None:
        self.filename = filename
        self.source = source
        self.lines = source.decode("utf-8", errors="replace").split("\n")

    def error(self, message: str, line: int = 1, hint: str | None = None) -> ProgramRunError:
        line = line if 1 <= line <= len(self.lines) else 1
        text = self.lines[line - 1].rstrip("\r") if self.lines else None
        return ProgramRunError(message, ir.SourceSpan(self.filename, line, 1), text, hint)


def _write_request(
    job: Path, program: _Program, station: Station | None, params: Mapping[str, object]
) -> None:
    request = {
        "filename": program.filename,
        "source": program.source,
        "station": station,
        "params": dict(params),
    }
    try:
        data = pickle.dumps(request, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception as exc:
        raise UsageError(
            "the station or the parameters cannot be passed to the program's process: "
            + _short(str(exc))
        ) from None
    try:
        (job / _REQUEST).write_bytes(data)
    except OSError as exc:
        raise UsageError(f"cannot write olp's temporary files in {job}: {exc.strerror}") from None


def _run(job: Path, timeout: float | None) -> int | None:
    """Run the child to its end; its exit code (negative: a signal), or None on a timeout."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    env = dict(os.environ)
    here = str(Path(__file__).resolve().parents[2])
    env["PYTHONPATH"] = os.pathsep.join(p for p in (here, env.get("PYTHONPATH")) if p)
    env.setdefault("PYTHONHASHSEED", "0")
    posix = os.name == "posix"
    try:
        child = subprocess.Popen(
            [sys.executable, "-c", _BOOT, str(job)],
            stdin=subprocess.DEVNULL,
            env=env,
            start_new_session=posix,
        )
    except (OSError, ValueError) as exc:
        raise UsageError(
            f"cannot start a Python process ({sys.executable!r}) to run the program: {exc}"
        ) from None
    if not posix:
        return _run_elsewhere(child, timeout)
    watchdog = _Watchdog(child.pid, job, timeout)
    try:
        os.waitid(os.P_PID, child.pid, os.WEXITED | os.WNOWAIT)
    finally:
        watchdog.stop()
        # The child is ended but not yet reaped, so its pid (and process group id) cannot
        # have been reused: this kills only what the program left running.
        with contextlib.suppress(OSError):
            os.killpg(child.pid, signal.SIGKILL)
        code = child.wait()
    return None if watchdog.fired else code


class _Watchdog:
    """After ``timeout`` seconds: ask the child for its stack, then kill its process group."""

    def __init__(self, pid: int, job: Path, timeout: float | None) -> None:
        self.pid = pid
        self.job = job
        self.fired = False
        self._timer = None if timeout is None else threading.Timer(timeout, self._fire)
        if self._timer is not None:
            self._timer.daemon = True
            self._timer.start()

    def stop(self) -> None:
        if self._timer is not None:
            self._timer.cancel()
            self._timer.join()

    def _running(self) -> bool:
        try:
            return os.waitid(os.P_PID, self.pid, os.WEXITED | os.WNOWAIT | os.WNOHANG) is None
        except ChildProcessError:
            return False

    def _fire(self) -> None:
        if not self._running():
            return
        self.fired = True
        with contextlib.suppress(OSError):
            os.kill(self.pid, signal.SIGUSR1)
        dump, size, deadline = self.job / _STACK, -1, time.monotonic() + _DUMP_WAIT
        while time.monotonic() < deadline and self._running():
            time.sleep(0.02)
            now = dump.stat().st_size if dump.exists() else 0
            if now and now == size:
                break
            size = now
        with contextlib.suppress(OSError):
            os.killpg(self.pid, signal.SIGKILL)


def _run_elsewhere(child: subprocess.Popen[bytes], timeout: float | None) -> int | None:
    """Without POSIX process groups and signals: a timeout kills the child only."""
    try:
        return child.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        return None
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


def _outcome(job: Path, program: _Program, code: int | None, timeout: float | None) -> DslResult:
    if code is None:
        line, where = _where(job / _STACK, program.filename)
        raise program.error(
            f"the program did not finish within {timeout:g} s; olp stopped it{where}",
            line,
            "give it more time with --timeout SECONDS if it is meant to run that long",
        )
    if code < 0:
        raise _signal_error(job, program, -code)
    result = job / _RESULT
    if code != 0 or not result.exists():
        raise _exit_error(job, program, code)
    return _decode(result, program)


def _signal_error(job: Path, program: _Program, number: int) -> ProgramRunError:
    try:
        name = signal.Signals(number).name
    except ValueError:
        name = f"signal {number}"
    line, where = _where(job / _CRASH, program.filename)
    hint = "SIGKILL usually means the system ran out of memory" if name == "SIGKILL" else None
    return program.error(f"the program's Python process was killed by {name}{where}", line, hint)


def _exit_error(job: Path, program: _Program, code: int) -> ProgramRunError:
    marker = _read_text(job / _EXIT).split()
    if len(marker) == 2 and marker[0].isdigit():
        return program.error(
            f"os._exit({marker[1]}) ended the program's process before olp recorded its "
            "result; nothing was built",
            int(marker[0]),
            "end the program by returning from it (or sys.exit())",
        )
    return program.error(
        f"the program's Python process exited with code {code} before olp recorded its "
        "result; nothing was built"
    )


_FRAME = re.compile(r'\s*File "([^"\n]*)", line (\d+) in ([^\n]*)')


def _where(dump: Path, filename: str) -> tuple[int, str]:
    """The program line a faulthandler dump shows first (innermost), and a phrase for it."""
    for text in _read_text(dump).splitlines():
        match = _FRAME.fullmatch(text)
        if match and match.group(1) == filename:
            line = int(match.group(2))
            return line, f" while it ran line {line} (in {match.group(3)[:60]})"
    return 1, ""


def _read_text(path: Path, limit: int = 1 << 16) -> str:
    try:
        with path.open("rb") as file:
            return file.read(limit).decode("utf-8", errors="replace")
    except OSError:
        return ""


def _decode(path: Path, program: _Program) -> DslResult:
    from olp.frontends.dsl import DslResult

    try:
        with path.open("rb") as file:
            payload = _Unpickler(file).load()
    except Exception as exc:
        raise program.error(
            f"olp cannot read the program's result back from its process ({_short(str(exc))})",
            hint="the program may have written into olp's temporary folder",
        ) from None
    if isinstance(payload, tuple) and len(payload) == 2:
        kind, value = payload
        if kind == "ok" and isinstance(value, DslResult) and isinstance(value.program, ir.Program):
            return _rebuilt_result(value, program)
        if kind == "error" and isinstance(value, dict):
            raise _error_from(value, program)
    raise program.error("the program's process sent back something that is not a result")


def _rebuilt_result(result: DslResult, program: _Program) -> DslResult:
    """``result`` made again through the constructors of its data classes.

    Unpickling sets an object's fields without running its checks (``__post_init__``), and the
    child ran the user's code, which can forge an instruction no constructor would make (a
    one-line statement holding a line break, a negative wait). Rebuilding runs every check, so
    what the passes and posts receive keeps the IR's invariants; a forged object is an error
    on the program."""
    try:
        rebuilt: DslResult = _rebuilt(result)
    except (ValueError, TypeError, AttributeError) as exc:  # (a forged object lacking a field)
        raise program.error(
            f"the program's result holds an instruction olp's IR does not allow: "
            f"{_short(str(exc))}",
            hint="build the program with the robot's methods, not by setting object fields",
        ) from None
    return rebuilt


def _rebuilt(value: Any) -> Any:
    """``value`` with every data class made again by its constructor (recursively)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        fields = {
            f.name: _rebuilt(getattr(value, f.name)) for f in dataclasses.fields(value) if f.init
        }
        return type(value)(**fields)
    if isinstance(value, tuple):
        return tuple(_rebuilt(item) for item in value)
    if isinstance(value, list):
        return [_rebuilt(item) for item in value]
    if isinstance(value, dict):
        return {key: _rebuilt(item) for key, item in value.items()}
    return value


def _error_from(data: dict[str, Any], program: _Program) -> OlpError:
    cls = _ERRORS.get(str(data.get("kind")), ProgramRunError)
    span = data.get("span")
    line = data.get("source_line")
    hint = data.get("hint")
    return cls(
        _short(str(data.get("message"))),
        span if isinstance(span, ir.SourceSpan) else ir.SourceSpan(program.filename, 1, 1),
        line if isinstance(line, str) else None,
        _short(hint) if isinstance(hint, str) else None,
    )


def _short(text: str) -> str:
    return text if len(text) <= _TEXT_LIMIT else f"{text[:_TEXT_LIMIT]}... ({len(text)} chars)"


_NUMPY = {
    ("numpy", "dtype"),
    ("numpy", "ndarray"),
    ("numpy._core.numeric", "_frombuffer"),
    ("numpy.core.numeric", "_frombuffer"),
    ("numpy._core.multiarray", "_reconstruct"),
    ("numpy.core.multiarray", "_reconstruct"),
    ("numpy._core.multiarray", "scalar"),
    ("numpy.core.multiarray", "scalar"),
}
_BUILTINS = {"set", "frozenset", "complex", "slice", "bytearray"}


def _plain(module: str, name: str) -> bool:
    builtin = module == "builtins" and name in _BUILTINS
    return builtin or (module == "numpy.dtypes" and name.endswith("DType"))


class _Unpickler(pickle.Unpickler):
    """Builds only olp's data classes and enumerations (the IR, e.g. a circular move's
    :class:`~olp.ir.ArcOrientation`, the result), numpy arrays and plain data: the result file
    is written by a process that ran the user's code, so nothing else (no function call, no
    other class) may come out of it. An enumeration is looked up by value, which runs nothing."""

    def find_class(self, module: str, name: str) -> Any:
        if module == "olp" or module.startswith("olp."):
            found = super().find_class(module, name)
            olp_type = isinstance(found, type) and (
                dataclasses.is_dataclass(found) or issubclass(found, enum.Enum)
            )
            if olp_type:
                return found
        elif (module, name) in _NUMPY or _plain(module, name):
            return super().find_class(module, name)
        raise pickle.UnpicklingError(f"the result holds a {module}.{name[:60]} object")


# ------------------------------------------------------------------------------------------------
# Child


def child_main(folder: str) -> None:
    """The child's entry point: run the requested program, write its result, exit at once.

    It exits with ``os._exit`` so that threads the program left running and ``atexit``
    handlers it registered cannot keep the process alive or change its exit code.
    """
    job = Path(folder)
    real_exit = os._exit
    request = pickle.loads((job / _REQUEST).read_bytes())
    filename = request["filename"]
    sys.argv = [filename]
    dumps = _arm_faulthandler(job)
    _watch_exit(job, filename, real_exit)
    payload = _run_program(request)
    try:
        data = pickle.dumps(payload, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception as exc:
        error = ProgramRunError(
            f"the program's result cannot be sent back to olp: {_short(str(exc))}",
            ir.SourceSpan(filename, 1, 1),
        )
        data = pickle.dumps(("error", _error_data(error)), protocol=pickle.HIGHEST_PROTOCOL)
    partial = job / (_RESULT + ".part")
    partial.write_bytes(data)
    partial.replace(job / _RESULT)
    for stream in (sys.stdout, sys.stderr, *dumps):
        with contextlib.suppress(Exception):
            stream.flush()
    real_exit(0)


def _run_program(request: Mapping[str, Any]) -> tuple[str, object]:
    from olp.frontends.dsl import run_dsl

    try:
        result = run_dsl(
            request["source"],
            request["filename"],
            request["station"],
            request["params"],
            catch_interrupts=True,
        )
    except OlpError as exc:
        return "error", _error_data(exc)
    return "ok", result


def _error_data(exc: OlpError) -> dict[str, object]:
    return {
        "kind": type(exc).__name__,
        "message": exc.message,
        "span": exc.span,
        "source_line": exc.source_line,
        "hint": exc.hint,
    }


def _arm_faulthandler(job: Path) -> tuple[IO[bytes], ...]:
    """Stack dumps: on a crash (SIGSEGV, SIGFPE, SIGABRT, SIGBUS, SIGILL) and on SIGUSR1 (the
    parent's timeout). faulthandler writes from C, so even a program stuck in a loop answers."""
    import faulthandler

    crash = (job / _CRASH).open("wb")
    faulthandler.enable(file=crash, all_threads=False)
    if not hasattr(signal, "SIGUSR1"):
        return (crash,)
    stack = (job / _STACK).open("wb")
    faulthandler.register(signal.SIGUSR1, file=stack, all_threads=False)
    return crash, stack


def _watch_exit(job: Path, filename: str, real_exit: Callable[[int], NoReturn]) -> None:
    """Make ``os._exit`` note the program line that called it before it ends the process."""

    def exit_noting_caller(status: int) -> NoReturn:
        frame = sys._getframe(1)
        while frame.f_back is not None and frame.f_code.co_filename != filename:
            frame = frame.f_back
        line = frame.f_lineno if frame.f_code.co_filename == filename else 1
        with contextlib.suppress(Exception):
            (job / _EXIT).write_text(f"{line} {int(status)}\n", encoding="ascii")
            for stream in (sys.stdout, sys.stderr):
                stream.flush()
        real_exit(status)

    os._exit = exit_noting_caller
