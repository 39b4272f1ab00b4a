"""Python programs run in a child process with a time limit (issue 10, item 6): every way a
program can end is reported at its line, the result comes back intact (``--set``, station
questions), olp's own process survives anything the program does, and commands that only read
never run a ``.py`` file."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from olp import ir
from olp.api import build, parse
from olp.errors import OlpError, ParseError, UsageError
from olp.frontends.bundled import DslOptions
from olp.frontends.dsl import load_dsl, run_dsl
from olp.frontends.dsl_process import ProgramRunError
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
HOME = "robot.MoveJ([0, -90, 90, 0, 0, 0])\n"


@pytest.fixture(scope="module")
def station() -> Station:
    return load_station(CELL)


def program(tmp_path: Path, text: str, name: str = "prog.py") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def child_error(path: Path, station: Station | None = None, **options: object) -> OlpError:
    with pytest.raises(OlpError) as info:
        load_dsl(path, station, **options)  # type: ignore[arg-type]
    return info.value


def olp_cli(
    *args: str | Path, cwd: Path, env: dict[str, str] | None = None
) -> subprocess.CompletedProcess[str]:
    """``olp ARGS`` in a fresh process (a program that ends its process must not end pytest)."""
    return subprocess.run(
        [sys.executable, "-m", "olp", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
        timeout=120,
    )


# ------------------------------------------------------------------------------------------------
# How a program ends


def test_os_exit_0_is_an_error_and_nothing_is_written(tmp_path: Path) -> None:
    """On main, ``os._exit(0)`` ended olp itself: exit code 0 and no robot program."""
    path = program(tmp_path, HOME + "import os\nos._exit(0)\n")
    done = olp_cli("build", CELL, path, "-o", tmp_path / "out", cwd=tmp_path)
    assert done.returncode == 2
    assert f"{path}:3:1: error running the program: os._exit(0) ended the program's" in done.stderr
    assert "nothing was built" in done.stderr
    assert not (tmp_path / "out").exists()


def test_another_exit_code_is_reported(tmp_path: Path) -> None:
    path = program(tmp_path, HOME + "import os\n\nos._exit(3)\n")
    done = olp_cli("check", CELL, path, cwd=tmp_path)
    assert done.returncode == 2
    assert f"{path}:4:1: error running the program: os._exit(3) ended" in done.stderr


def test_a_program_that_runs_too_long_is_stopped_at_its_line(tmp_path: Path) -> None:
    path = program(tmp_path, HOME + "n = 0\nwhile True:\n    n += 1\n")
    start = time.monotonic()
    error = child_error(path, timeout=1.5)
    assert time.monotonic() - start < 30
    assert isinstance(error, ProgramRunError) and error.span is not None
    assert "did not finish within 1.5 s" in error.message
    assert error.span.line in (3, 4) and "while it ran line" in error.message
    assert error.hint is not None and "--timeout" in error.hint


def test_the_cli_takes_a_timeout(tmp_path: Path) -> None:
    path = program(tmp_path, HOME + "import time\ntime.sleep(60)\n")
    done = olp_cli("check", CELL, path, "--timeout", "1", cwd=tmp_path)
    assert done.returncode == 2
    assert f"{path}:3:1: error running the program: the program did not finish within 1 s" in (
        done.stderr
    )


def test_the_library_takes_a_timeout(tmp_path: Path, station: Station) -> None:
    path = program(tmp_path, HOME + "import time\ntime.sleep(60)\n")
    with pytest.raises(ProgramRunError, match="did not finish within 1 s"):
        parse(path, station=station, options=DslOptions(timeout=1))
    with pytest.raises(ProgramRunError, match="did not finish within 1 s"):
        build(station, path, program_options=DslOptions(timeout=1.0))


@pytest.mark.parametrize("value", ["0", "-1", "nan"])
def test_a_timeout_must_be_positive(tmp_path: Path, value: str) -> None:
    path = program(tmp_path, HOME)
    done = olp_cli("check", CELL, path, f"--timeout={value}", cwd=tmp_path)
    assert done.returncode == 2 and "--timeout must be a positive number" in done.stderr


def test_a_crash_is_reported_with_its_signal_and_line(tmp_path: Path) -> None:
    path = program(tmp_path, HOME + "import ctypes\nctypes.string_at(0)\n")
    done = olp_cli("check", CELL, path, cwd=tmp_path)
    assert done.returncode == 2
    expected = f"{path}:3:1: error running the program: the program's Python process was killed"
    assert f"{expected} by SIGSEGV while it ran line 3" in done.stderr


def test_processes_the_program_started_end_with_it(tmp_path: Path) -> None:
    """A background process the program starts must not outlive the build (nor a timeout)."""
    pid_file = tmp_path / "pid"
    text = (
        HOME + "import subprocess, sys\n"
        "p = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(30)'])\n"
        f"open({str(pid_file)!r}, 'w').write(str(p.pid))\n"
    )
    load_dsl(program(tmp_path, text))
    pid = int(pid_file.read_text())
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and _alive(pid):
        time.sleep(0.05)
    assert not _alive(pid)


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie waiting for its new parent to reap it does not)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state != "Z"


def test_an_exception_points_at_the_users_line_with_the_users_frames(tmp_path: Path) -> None:
    text = (
        "def corner(i):\n"
        "    return helper(i)\n"
        "\n"
        "def helper(i):\n"
        "    return robot.MoveL(transl(0, 0, 1 / i))\n"
        "\n" + HOME + "for i in range(3, -1, -1):\n"
        "    corner(i)\n"
    )
    path = program(tmp_path, text)
    error = child_error(path)
    assert isinstance(error, ProgramRunError)
    assert error.message == "ZeroDivisionError: division by zero"
    assert error.span == ir.SourceSpan(str(path), 5, 37, 5, 42)
    assert error.format().startswith(f"{path}:5:37: error running the program: ZeroDivision")
    assert error.hint is not None
    trace = error.hint.splitlines()[1:]
    assert [line.strip().split(" in ")[0] for line in trace] == [
        f"{path}:9",
        f"{path}:2",
        f"{path}:5",
    ]
    assert "olp" + os.sep not in error.hint and "site-packages" not in error.hint


def test_a_keyboard_interrupt_raised_by_the_program_is_its_error(tmp_path: Path) -> None:
    path = program(tmp_path, HOME + "raise KeyboardInterrupt\n")
    done = olp_cli("check", CELL, path, cwd=tmp_path)
    assert done.returncode == 2
    assert f"{path}:2:1: error running the program: KeyboardInterrupt" in done.stderr


def test_a_program_that_records_nothing_is_an_error(tmp_path: Path) -> None:
    error = child_error(program(tmp_path, "import sys\nx = 1\nsys.exit()\n"))
    assert isinstance(error, ProgramRunError) and "recorded no robot instructions" in error.message


# ------------------------------------------------------------------------------------------------
# What travels between the processes


IN_CHILD = (
    "f = sys._getframe()\n"
    "while f is not None and not isinstance(f.f_locals.get('job'), pathlib.Path):\n"
    "    f = f.f_back\n"
    "if f is not None and (f.f_locals['job'] / 'request').exists():\n"
    "    folder = f.f_locals['job']\n"
)
"""Only in olp's child process (its entry point holds the ``job`` folder) does a test program
write into that folder."""


def test_the_parent_survives_garbage_in_the_result(tmp_path: Path) -> None:
    text = (
        HOME + "import os, sys, pathlib\n" + IN_CHILD + "    pathlib.Path(folder, "
        "'result').write_bytes(b'not a pickle')\n"
        "    os._exit(0)\n"
    )
    error = child_error(program(tmp_path, text))
    assert isinstance(error, ProgramRunError)
    assert "cannot read the program's result back" in error.message


def test_the_result_cannot_run_code_in_olp(tmp_path: Path) -> None:
    marker = tmp_path / "ran"
    text = (
        HOME + "import os, sys, pickle, pathlib\n"
        "class Evil:\n"
        "    def __reduce__(self):\n"
        f"        return (os.system, ('touch {marker}',))\n" + IN_CHILD + "    pathlib.Path("
        "folder, 'result').write_bytes(pickle.dumps(('ok', Evil())))\n"
        "    os._exit(0)\n"
    )
    error = child_error(program(tmp_path, text))
    assert "cannot read the program's result back" in error.message
    assert "system" in error.message and not marker.exists()


def test_set_parameters_reach_the_program(tmp_path: Path, station: Station) -> None:
    weld = REPO / "examples" / "weld_polygon.py"
    six = load_dsl(weld, station)
    eight = load_dsl(weld, station, {"SIDES": "8", "NAME": "Eight"})
    assert len(eight.program) == len(six.program) + 2 and eight.program.name == "Eight"
    error = child_error(weld, station, params={"SIDE": "8"})
    assert isinstance(error, UsageError)
    assert error.message.startswith("--set SIDE: the program has no such parameter")


def test_station_questions_get_the_same_answers_in_the_child(station: Station) -> None:
    """feasibility_grid.py asks canMoveL, SolveIK and Joints: the child, with its copy of the
    station, records exactly what the program records in this process."""
    path = REPO / "examples" / "feasibility_grid.py"
    inside = run_dsl(path.read_bytes(), str(path), station)
    child = load_dsl(path, station)
    assert _summary(child.program) == _summary(inside.program)
    assert [w.message for w in child.warnings] == [w.message for w in inside.warnings]


def _summary(prog: ir.Program) -> list[tuple[object, ...]]:
    rows: list[tuple[object, ...]] = []
    for instruction in prog.instructions:
        target = getattr(instruction, "target", None)
        values = getattr(target, "pose", None)
        values = getattr(target, "joints", None) if values is None else values
        shown = None if values is None else np.round(np.asarray(values), 12).tolist()
        rows.append((type(instruction).__name__, instruction.span, shown))
    return rows


def test_a_program_built_in_the_child_writes_the_same_robot_code(station: Station) -> None:
    path = REPO / "examples" / "weld_polygon.py"
    inside = build(station, run_dsl(path.read_bytes(), str(path), station).program)
    child = build(station, path)
    assert child.ok and child.files == inside.files


def test_the_program_sees_argv_as_a_script_would(tmp_path: Path) -> None:
    path = program(tmp_path, HOME + "import sys\nrobot.RunInstruction(repr(sys.argv), 3)\n")
    comment = load_dsl(path).program.instructions[-1]
    assert isinstance(comment, ir.Comment) and comment.text == repr([str(path)])


def test_the_programs_output_reaches_the_user(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    text = HOME + "import sys\nprint('to stdout')\nprint('to stderr', file=sys.stderr)\n"
    load_dsl(program(tmp_path, text))
    out, err = capfd.readouterr()
    assert "to stdout" in out and "to stderr" in err


def test_the_same_program_records_the_same_order_in_every_run(tmp_path: Path) -> None:
    """Set order of strings depends on the hash seed, random per process unless fixed: each
    child runs with the same one, so two olp processes record the same program."""
    names = ", ".join(repr(f"step_{i}") for i in range(12))
    text = HOME + f"for name in {{{names}}}:\n    robot.RunInstruction(name, INSTRUCTION_COMMENT)\n"
    path = program(tmp_path, text)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONHASHSEED"}
    show = (
        "import sys; from olp.frontends.dsl import load_dsl; "
        "print([i.text for i in load_dsl(sys.argv[1]).program.instructions[1:]])"
    )
    orders = [
        subprocess.run(
            [sys.executable, "-c", show, str(path)],
            capture_output=True,
            text=True,
            env=env,
            cwd=tmp_path,
            timeout=120,
            check=True,
        ).stdout
        for _ in range(2)
    ]
    assert "step_0" in orders[0] and orders[0] == orders[1]


# ------------------------------------------------------------------------------------------------
# Code from the working directory


MODULES = ("numpy", "yaml", "jinja2", "pickle", "olp_helpers", "sitecustomize", "kuka", "post")


def _plant(folder: Path) -> Path:
    """Modules named like what olp imports, each leaving a mark when imported."""
    marks = folder / "marks"
    marks.mkdir()
    for name in MODULES:
        (folder / f"{name}.py").write_text(
            f"open({str(marks / name)!r}, 'w').close()\n", encoding="utf-8"
        )
    return marks


@pytest.mark.parametrize("command", [["posts"], ["robots"], ["schema", "station"]])
def test_commands_that_only_read_run_no_python_file(tmp_path: Path, command: list[str]) -> None:
    marks = _plant(tmp_path)
    olp = Path(sys.executable).parent / "olp"
    done = subprocess.run(
        [str(olp), *command], capture_output=True, text=True, cwd=tmp_path, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert not list(marks.iterdir())


def test_the_programs_process_imports_nothing_from_the_working_directory(tmp_path: Path) -> None:
    marks = _plant(tmp_path)
    path = program(tmp_path, HOME)
    olp = Path(sys.executable).parent / "olp"
    done = subprocess.run(
        [str(olp), "check", str(CELL), str(path)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert not list(marks.iterdir())


def test_in_process_runs_stay_available_for_trusted_text(station: Station) -> None:
    result = run_dsl(HOME, "prog.py", station)
    assert len(result.program) == 1
    with pytest.raises(KeyboardInterrupt):
        run_dsl(HOME + "raise KeyboardInterrupt\n", "prog.py", station)
    with pytest.raises(ParseError):
        run_dsl("x = 1\n", "prog.py", station)


def test_a_circular_move_comes_back_from_the_child(tmp_path: Path, station: Station) -> None:
    """A circular move holds an :class:`~olp.ir.ArcOrientation` (an enumeration): the result
    reader took only olp's data classes, so every program with a MoveC failed to come back."""
    text = (
        "robot.setPoseFrame('table')\n"
        "robot.MoveJ(Pose(0, 0, 100, 180, 0, 180))\n"
        "robot.MoveC(Pose(50, 50, 100, 180, 0, 180), Pose(100, 0, 100, 180, 0, 180))\n"
    )
    result = load_dsl(program(tmp_path, text), station)
    arc = result.program.instructions[-1]
    assert isinstance(arc, ir.CircularMove) and isinstance(arc.orientation, ir.ArcOrientation)
    assert arc == run_dsl(text, str(tmp_path / "prog.py"), station).program.instructions[-1]


FORGE = """
from olp.dsl import session
from olp import ir


def forged(cls, **values):
    obj = object.__new__(cls)  # no constructor: none of its checks run
    for key, value in values.items():
        object.__setattr__(obj, key, value)
    return obj


robot.MoveJ([0, -90, 90, 0, 30, 0])
session().record(forged(ir.{cls}, span=ir.SourceSpan("prog.py", 14, 1), {fields}))
"""


@pytest.mark.parametrize(
    ("cls", "fields", "why"),
    [
        (
            "Verbatim",
            "text='WAIT SEC 1\\nLIN {X 0,Y 0,Z 0,A 0,B 0,C 0}', language='krl', reason='', "
            "native_only=False, modelled=False, kind='verbatim'",
            "must be one line",
        ),
        ("Wait", "seconds=-5.0, kind='wait'", "Wait"),
    ],
)
def test_an_instruction_forged_in_the_child_is_an_error_not_output(
    station: Station, tmp_path: Path, cls: str, fields: str, why: str
) -> None:
    """The child's result is unpickled without running the IR's checks; the parent makes every
    object again through its constructor, so a forged one is a located error on the program."""
    path = program(tmp_path, FORGE.replace("{cls}", cls).replace("{fields}", fields))
    error = child_error(path, station)
    assert "does not allow" in str(error) and why in str(error)
    done = olp_cli("build", CELL, path, "--post", "kuka", "-o", tmp_path / "out", cwd=tmp_path)
    assert done.returncode == 2 and not (tmp_path / "out").exists()
