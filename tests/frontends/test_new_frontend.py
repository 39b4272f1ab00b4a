"""A new input language is one frontend and one registry line (issue 11).

The frontend below reads "one joint target per line" text files (``.jnt``: six joint values in
degrees, ``#`` comments) with one option, the joint speed in percent (``--joint-speed``). It is
defined here, in the test, and registered in :data:`olp.frontends.REGISTRY` or through an entry
point: ``olp.parse`` and ``olp build`` then read such files and take the option with no other
edit.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.cli import main
from olp.errors import ParseError, UsageError
from olp.frontends import REGISTRY, ParsedProgram, frontend_for, frontends
from olp.frontends.bundled import CsvOptions
from olp.frontends.options import cli, number
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
OFFSETS_DEG = ((0, 0, 0, 0, 0, 0), (10, 5, -5, 0, 10, 20), (-15, 0, 5, 10, -10, 0))


@dataclass(frozen=True, slots=True, kw_only=True)
class JointListOptions:
    """``speed``: percent of each axis' maximum speed, for every move."""

    speed: float = field(
        default=100.0,
        metadata=cli("--joint-speed", "joint speed in %% (default 100)", parse=number),
    )

    def __post_init__(self) -> None:
        if not 0 < self.speed <= 100:
            raise UsageError(f"--joint-speed must be in (0, 100] %, got {self.speed}")


class JointListFrontend:
    """One joint target per line: six values in degrees."""

    NAME = "joints"
    TITLE = "joint lists"
    SUFFIXES = (".jnt",)
    Options = JointListOptions

    def load(self, path: Path, options: JointListOptions, station: Station | None) -> ParsedProgram:
        speed = ir.Speed(joint=options.speed / 100.0)
        moves = []
        for number_, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            text = line.split("#")[0].strip()
            if not text:
                continue
            span = ir.SourceSpan(str(path), number_, 1, number_, len(line) + 1)
            try:
                degrees = [float(v) for v in text.split()]
            except ValueError:
                raise ParseError("expected six joint values in degrees", span) from None
            target = ir.JointTarget(joints=np.radians(degrees))
            moves.append(ir.JointMove(target=target, speed=speed, span=span))
        return ParsedProgram(
            ir.Program(name=path.stem, instructions=tuple(moves), source=str(path))
        )


@pytest.fixture(scope="module")
def station() -> Station:
    return olp.load_station(CELL)


@pytest.fixture
def program(tmp_path: Path, station: Station) -> Path:
    """Three joint targets around the robot's home position."""
    home = np.degrees(station.robot.home)
    rows = [" ".join(f"{v:.3f}" for v in home + np.array(o)) for o in OFFSETS_DEG]
    path = tmp_path / "Joints.jnt"
    path.write_text("# a joint list\n" + "\n".join(rows) + "\n", encoding="utf-8")
    return path


@pytest.fixture
def registered(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(REGISTRY, "joints", JointListFrontend)  # the one registry line


def test_olp_parse_reads_the_new_language_with_its_options(
    registered: None, program: Path, station: Station
) -> None:
    parsed = olp.parse(program, station=station, options=JointListOptions(speed=40.0))
    moves = list(parsed.program.motions())
    assert [m.span.line for m in moves] == [2, 3, 4]
    assert all(m.speed.joint == pytest.approx(0.4) for m in moves)
    expected = np.radians(np.degrees(station.robot.home) + np.array(OFFSETS_DEG[1]))
    assert np.allclose(moves[1].target.joints, expected, atol=1e-9)  # type: ignore[union-attr]
    default = olp.parse(program, station=station)
    assert next(default.program.motions()).speed.joint == 1.0


def test_another_frontends_options_are_refused_naming_both(registered: None, program: Path) -> None:
    with pytest.raises(UsageError) as info:
        olp.parse(program, options=CsvOptions(frame="table"))
    message = info.value.message
    assert "joint lists (.jnt) take JointListOptions, not CsvOptions" in message
    assert "the options of CSV toolpaths" in message


def test_olp_build_takes_the_new_language_and_its_flag(
    registered: None, program: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    args = ["build", str(CELL), str(program), "-o", str(out), "--joint-speed", "25", "-q"]
    assert main(args) == 0, capsys.readouterr().err
    src = (out / "Joints.src").read_text(encoding="ascii")
    assert src.count("PTP {A1") == len(OFFSETS_DEG)
    assert "$VEL_AXIS[1] = 25\n" in src


def test_the_help_shows_the_new_flag_in_its_group(
    registered: None, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit):
        main(["check", "--help"])
    help_text = capsys.readouterr().out
    assert "joint lists (.jnt):\n  --joint-speed JOINT_SPEED" in help_text


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--joint-speed", "fast"], "--joint-speed 'fast': expected a number"),
        (["--joint-speed", "0"], "--joint-speed must be in (0, 100] %"),
        (["--config-dat", "x.dat"], "--config-dat is for KRL programs (.src), not .jnt"),
        (["--zone", "1"], "--zone is for CSV toolpaths (.csv), not .jnt"),
    ],
)
def test_flags_that_do_not_fit_are_usage_errors(
    registered: None,
    program: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    flags: list[str],
    message: str,
) -> None:
    out = tmp_path / "out"
    assert main(["build", str(CELL), str(program), "-o", str(out), *flags]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_the_joint_speed_flag_is_not_for_krl(
    registered: None, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["check", str(CELL), str(REPO / "examples" / "milling.src"), "--joint-speed", "5"]
    assert main(args) == 2
    assert "--joint-speed is for joint lists (.jnt), not .src" in capsys.readouterr().err


def test_an_installed_package_adds_a_frontend_through_its_entry_point(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, program: Path, station: Station
) -> None:
    """No registry edit: a distribution on sys.path declares ``olp.frontends = joints``."""
    entry = f"{JointListFrontend.__module__}:{JointListFrontend.__qualname__}"
    _install(tmp_path / "site", "joints", entry)
    assert "joints" not in frontends()
    monkeypatch.syspath_prepend(str(tmp_path / "site"))
    assert isinstance(frontends()["joints"], JointListFrontend)
    parsed = olp.parse(program, station=station, options=JointListOptions(speed=50.0))
    assert len(parsed.program) == len(OFFSETS_DEG)


def test_a_suffix_keeps_the_frontend_registered_first(monkeypatch: pytest.MonkeyPatch) -> None:
    """A frontend registered later (or installed) that also claims .src does not take it over."""

    class Impostor(JointListFrontend):
        NAME = "impostor"
        SUFFIXES = (".src",)

    monkeypatch.setitem(REGISTRY, "impostor", Impostor)
    assert frontend_for("Pick.SRC").NAME == "krl"


def _install(site: Path, name: str, entry: str) -> None:
    """A distribution in ``site`` whose entry point ``olp.frontends`` ``name`` is ``entry``."""
    info = site / f"olp_{name}-1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: olp-{name}\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text(f"[olp.frontends]\n{name} = {entry}\n")


def test_an_installed_frontend_that_fails_to_load_is_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    _install(tmp_path / "site", "broken", "olp_no_such_module:Frontend")
    monkeypatch.syspath_prepend(str(tmp_path / "site"))
    assert main(["build", str(CELL), str(REPO / "examples" / "milling.src")]) == 2
    err = capsys.readouterr().err
    assert "installed frontend 'broken' (olp_no_such_module:Frontend) failed to load" in err


def test_a_frontend_flag_that_clashes_with_a_command_option_is_a_usage_error(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    @dataclass(frozen=True, slots=True, kw_only=True)
    class PostOptions:
        post: str = field(default="", metadata=cli("--post", "a clash"))

    class Clashing(JointListFrontend):
        Options = PostOptions

    monkeypatch.setitem(REGISTRY, "joints", Clashing)
    assert main(["build", str(CELL), str(REPO / "examples" / "milling.src")]) == 2
    assert "joint lists (.jnt) declare --post: conflicting option" in capsys.readouterr().err


def test_a_registration_that_is_no_frontend_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    class NoSuffixes:
        NAME, TITLE, Options = "bad", "bad files", JointListOptions

        def load(self, path: Path, options: object, station: object) -> None: ...

    monkeypatch.setitem(REGISTRY, "bad", NoSuffixes)
    with pytest.raises(UsageError, match=r"frontend 'bad' is registered as .*lacks"):
        olp.parse(REPO / "examples" / "milling.src")
