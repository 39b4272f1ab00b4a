"""Output paths are checked before anything is written, an output folder is replaced as one set,
and files get the umask's modes (issue 10, items 10 and 11)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from olp.cli import main
from olp.errors import UsageError
from olp.output import MANIFEST, check_output_folder, write_file, write_folder

REPO = Path(__file__).resolve().parents[1]
CELL = str(REPO / "stations" / "kr6_milling_cell.yaml")
MILLING = str(REPO / "examples" / "milling.src")


@pytest.fixture
def umask_022() -> Iterator[None]:
    old = os.umask(0o022)
    yield
    os.umask(old)


def _listing(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


# --------------------------------------------------------------------------------------------
# The command line: every output path checked first, exit 2 with the path


def test_o_naming_a_file_is_exit_2_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / "out.txt"
    target.write_text("mine")
    assert main(["build", CELL, MILLING, "-o", str(target), "--quiet"]) == 2
    assert "is a file, not a folder" in capsys.readouterr().err
    assert target.read_text() == "mine"


def test_o_below_a_file_is_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "plain").write_text("x")
    assert main(["build", CELL, MILLING, "-o", str(tmp_path / "plain" / "out")]) == 2
    assert "is not a folder" in capsys.readouterr().err


@pytest.mark.parametrize("option", ["--report", "--sarif"])
def test_a_report_naming_a_folder_is_exit_2_before_any_code_is_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], option: str
) -> None:
    out = tmp_path / "out"
    code = main(["build", CELL, MILLING, "-o", str(out), option, str(tmp_path), "--quiet"])
    assert code == 2
    assert f"{option} {tmp_path}: is a folder" in capsys.readouterr().err
    assert not out.exists()


def test_check_and_time_check_their_outputs_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["check", CELL, MILLING, "--sarif", str(tmp_path), "--quiet"]) == 2
    assert main(["time", CELL, MILLING, "--trajectory", str(tmp_path), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"--sarif {tmp_path}: is a folder" in err
    assert f"--trajectory {tmp_path}: is a folder" in err


def test_two_options_naming_one_file_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    same = str(tmp_path / "r.json")
    assert main(["check", CELL, MILLING, "--report", same, "--sarif", same]) == 2
    assert "name the same path" in capsys.readouterr().err


def test_the_working_directory_cannot_be_the_output_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    for path in (".", "..", str(tmp_path)):
        with pytest.raises(UsageError, match="as a whole"):
            check_output_folder(path)
    assert check_output_folder("out") == Path("out")


def test_a_station_that_is_a_folder_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["check", str(tmp_path), MILLING]) == 2
    assert f"{tmp_path}: is a folder, not a file" in capsys.readouterr().err


# --------------------------------------------------------------------------------------------
# One set: stale parts go, the user's files stay, a kill leaves the old set whole


def test_parts_of_an_earlier_larger_build_are_removed_and_user_files_kept(
    tmp_path: Path,
) -> None:
    out = tmp_path / "out"
    write_folder({"Prog.src": b"main", "Prog_P1.src": b"1", "Prog_P2.src": b"2"}, out)
    (out / "notes.txt").write_text("my notes")
    (out / "cad").mkdir()
    (out / "cad" / "part.stl").write_text("solid")
    write_folder({"Prog.src": b"new main"}, out)
    assert _listing(out) == {
        MANIFEST: json.dumps({"files": ["Prog.src"]}, indent=1).encode() + b"\n",
        "Prog.src": b"new main",
        "notes.txt": b"my notes",
    }
    assert (out / "cad" / "part.stl").read_text() == "solid"
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def test_a_build_into_an_existing_folder_without_a_manifest_keeps_its_files(
    tmp_path: Path,
) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "Prog.src").write_bytes(b"hand-written")
    (out / "other.src").write_bytes(b"other")
    write_folder({"Prog.src": b"generated"}, out)
    assert (out / "Prog.src").read_bytes() == b"generated"
    assert (out / "other.src").read_bytes() == b"other"


_KILLER = """
import os, signal, sys
from pathlib import Path
import olp.output as output

real = output._write_new
count = 0

def write_then_die(path, data):
    global count
    real(path, data)
    count += 1
    if count == 2:
        os.kill(os.getpid(), signal.SIGKILL)

output._write_new = write_then_die
output.write_folder({"A.src": b"new A", "A_P1.src": b"new 1", "A_P2.src": b"new 2"}, sys.argv[1])
"""


def test_a_kill_while_writing_leaves_the_old_set_whole(tmp_path: Path) -> None:
    out = tmp_path / "out"
    write_folder({"A.src": b"old A", "A_P1.src": b"old 1"}, out)
    before = _listing(out)
    run = subprocess.run([sys.executable, "-c", _KILLER, str(out)], timeout=120)
    assert run.returncode == -signal.SIGKILL
    assert _listing(out) == before
    leftovers = [p for p in tmp_path.iterdir() if p.name != "out"]
    assert len(leftovers) == 1 and leftovers[0].name.startswith(".out.olp-")
    write_folder({"A.src": b"third"}, out)
    assert [p.name for p in tmp_path.iterdir()] == ["out"]
    assert (out / "A.src").read_bytes() == b"third"
    assert not (out / "A_P1.src").exists()


def test_files_and_folders_follow_the_umask(tmp_path: Path, umask_022: None) -> None:
    out = tmp_path / "out"
    write_folder({"A.src": b"x"}, out)
    report = write_file(tmp_path / "report.json", b"{}")
    assert (out / "A.src").stat().st_mode & 0o777 == 0o644
    assert out.stat().st_mode & 0o777 == 0o755
    assert report.stat().st_mode & 0o777 == 0o644
    os.umask(0o002)
    write_file(report, b"{}")
    assert report.stat().st_mode & 0o777 == 0o664


def test_a_replaced_folder_keeps_its_permission_bits(tmp_path: Path, umask_022: None) -> None:
    out = tmp_path / "out"
    write_folder({"A.src": b"x"}, out)
    out.chmod(0o775)
    write_folder({"A.src": b"y"}, out)
    assert out.stat().st_mode & 0o777 == 0o775


def test_output_names_must_be_plain_file_names(tmp_path: Path) -> None:
    for name in ("../escape.src", "a/b.src", MANIFEST, ".."):
        with pytest.raises(UsageError):
            write_folder({name: b"x"}, tmp_path / "out")
    assert not (tmp_path / "escape.src").exists()


def test_trajectory_files_follow_the_umask(tmp_path: Path, umask_022: None) -> None:
    from olp.trajectory import write_atomic

    written = write_atomic(tmp_path / "joints.csv", b"t\n")
    assert written.stat().st_mode & 0o777 == 0o644
