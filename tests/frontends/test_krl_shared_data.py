"""Names declared in other modules' data lists (issue 15): a program that uses a point declared
GLOBAL in a shared ``PUBLIC`` data list (``Positions.dat``) reads it with ``--data-list`` or
``--data-lists-from``; KRL's visibility rules (only GLOBAL names of a PUBLIC list; the module's
own names hide global ones; a global name declared twice is an error naming both places)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.cli import main
from olp.errors import ParseError, UsageError
from olp.frontends.bundled import KrlOptions
from olp.frontends.krl import load_data_list, load_krl, parse_dat

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "tests" / "corpus" / "krc" / "R1"
CONFIG = CELL / "System" / "$config.dat"
SHARED = CELL / "Program" / "Shared"
PROGRAM = SHARED / "load_cell.src"
POSITIONS = SHARED / "Positions.dat"
STATION = REPO / "stations" / "kr6_milling_cell.yaml"

POUNCE_MM = [20.337, -110.5, 300.0]


def _points(result: object) -> list[ir.Motion]:
    return list(result.program.motions())  # type: ignore[attr-defined]


def test_a_shared_point_is_not_declared_without_its_data_list() -> None:
    with pytest.raises(ParseError, match="XSAFE is not declared") as info:
        load_krl(PROGRAM, CONFIG)
    assert "--data-list" in (info.value.hint or "")


@pytest.mark.parametrize("how", ["list", "folder"])
def test_a_program_reads_global_points_of_a_public_data_list(how: str) -> None:
    given = {"data_lists": [POSITIONS]} if how == "list" else {"data_lists_from": CELL}
    result = load_krl(PROGRAM, CONFIG, **given)  # type: ignore[arg-type]
    safe, pounce, _p1, back = _points(result)
    np.testing.assert_allclose(np.degrees(safe.target.joints), [0, -90, 90, 0, 30, 0])
    assert pounce.target.name == "XPOUNCE" and back.target.name == "XPOUNCE"
    np.testing.assert_allclose(pounce.target.pose[:3, 3] * 1000, POUNCE_MM, atol=1e-9)
    assert str(POSITIONS) in result.data_sources or how == "folder"
    assert any(Path(s).name == "Positions.dat" for s in result.data_sources)


def test_names_not_global_or_of_a_list_not_public_stay_hidden(tmp_path: Path) -> None:
    src = tmp_path / "uses_scratch.src"
    src.write_text("DEF uses_scratch( )\nPTP XSCRATCH\nEND\n")
    # every file where the controller would find a name is given: the module's own .dat too
    (tmp_path / "uses_scratch.dat").write_text("DEFDAT uses_scratch\nENDDAT\n")
    with pytest.raises(ParseError, match="XSCRATCH is not declared"):
        load_krl(src, CONFIG, data_lists=[POSITIONS])  # in Positions.dat, but not GLOBAL
    private = tmp_path / "Private.dat"
    private.write_text("DEFDAT Private\nDECL GLOBAL E6AXIS XHIDDEN={A1 0,A2 -90,A3 90}\nENDDAT\n")
    with pytest.raises(ParseError, match="DEFDAT Private is not PUBLIC") as info:
        load_krl(src, data_lists=[private])
    assert info.value.span.file == str(private) and info.value.span.line == 1
    src.write_text("DEF uses_scratch( )\nPTP XHIDDEN\nEND\n")
    with pytest.raises(ParseError, match="XHIDDEN is not declared"):
        load_krl(
            src, CONFIG, data_lists_from=tmp_path
        )  # a folder's lists that are not PUBLIC: skipped


def test_the_modules_own_names_hide_global_ones(tmp_path: Path) -> None:
    src = tmp_path / "local.src"
    src.write_text("DEF local( )\nPTP XSAFE\nEND\n")
    (tmp_path / "local.dat").write_text(
        "DEFDAT local\nDECL E6AXIS XSAFE={A1 10,A2 -90,A3 90,A4 0,A5 30,A6 0}\nENDDAT\n"
    )
    (move,) = load_krl(src, data_lists=[POSITIONS]).program
    assert np.degrees(move.target.joints)[0] == pytest.approx(10.0)  # type: ignore[union-attr]


def test_a_global_name_declared_twice_names_both_places(tmp_path: Path) -> None:
    other = tmp_path / "Other.dat"
    other.write_text(
        "DEFDAT Other PUBLIC\nDECL INT N=1\n"
        "DECL GLOBAL E6AXIS XSAFE={A1 5,A2 -90,A3 90,A4 0,A5 30,A6 0}\nENDDAT\n"
    )
    src = tmp_path / "p.src"
    src.write_text("DEF p( )\nPTP XSAFE\nEND\n")
    with pytest.raises(ParseError, match="XSAFE is declared GLOBAL twice") as info:
        load_krl(src, data_lists=[POSITIONS, other])
    assert info.value.span.file == str(other) and info.value.span.line == 3
    assert f"{POSITIONS}:6" in info.value.message
    clash = tmp_path / "Clash.dat"  # and against the controller's $config.dat
    clash.write_text("DEFDAT Clash PUBLIC\nDECL GLOBAL E6AXIS XHOME={A1 1}\nENDDAT\n")
    with pytest.raises(ParseError, match="XHOME is declared GLOBAL twice"):
        load_krl(src, CONFIG, data_lists=[clash])


def test_the_modules_own_dat_is_read_once(tmp_path: Path) -> None:
    """A folder (or a --data-list) holding the module's own PUBLIC .dat does not make its GLOBAL
    names clash with themselves."""
    src = tmp_path / "own.src"
    src.write_text("DEF own( )\nPTP XOWN\nEND\n")
    own = tmp_path / "own.dat"
    own.write_text(
        "DEFDAT own PUBLIC\nDECL GLOBAL E6AXIS XOWN={A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}\nENDDAT\n"
    )
    for given in ({"data_lists_from": tmp_path}, {"data_lists": [own]}):
        assert len(load_krl(src, **given).program) == 1  # type: ignore[arg-type]


def test_bad_data_lists_are_located_errors(tmp_path: Path) -> None:
    bad = tmp_path / "Bad.dat"
    bad.write_text("DEFDAT Bad PUBLIC\nDECL GLOBAL E6POS XP={X 1,\nENDDAT\n")
    src = tmp_path / "p.src"
    src.write_text("DEF p( )\nEND\n")
    with pytest.raises(ParseError) as info:
        load_krl(src, data_lists_from=tmp_path)
    assert info.value.span.file == str(bad) and info.value.span.line == 2
    with pytest.raises(UsageError, match="cannot read data list"):
        load_krl(src, data_lists=[tmp_path / "missing.dat"])
    with pytest.raises(UsageError, match="not a folder"):
        load_krl(src, data_lists_from=tmp_path / "nowhere")
    assert not parse_dat("DEFDAT Bad\nENDDAT\n").public
    with pytest.raises(ParseError, match=r"give the controller's \$config.dat"):
        load_data_list(CONFIG)


def test_a_krl_to_krl_build_references_shared_names_as_config_names_are() -> None:
    """The KUKA post writes a shared point as it writes one of $config.dat (XHOME): its value,
    in place (``points: inline``); a shared variable (PICK_COUNT) stays a reference, not
    redeclared in the written module (which would hide the shared one)."""
    station = olp.load_station(STATION)
    options = KrlOptions(config_dat=CONFIG, data_lists=(POSITIONS,))
    result = olp.build(station, PROGRAM, post="kuka", program_options=options, collisions=None)
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    src, dat = result.files["load_cell.src"], result.files["load_cell.dat"]
    assert "PICK_COUNT = PICK_COUNT + 1" in src
    assert "PICK_COUNT" not in dat and "DECL" not in src.split("PICK_COUNT")[0].split("INI)")[-1]
    assert src.count("PTP {X 20.337,Y -110.500,Z 300.000,A -90.0000,B 0.0000,C 180.0000") == 1


def test_the_command_line_takes_data_lists(capsys: pytest.CaptureFixture[str]) -> None:
    args = ["check", str(STATION), str(PROGRAM), "--config-dat", str(CONFIG), "--no-collisions"]
    assert main(args) == 2
    assert "XSAFE is not declared" in capsys.readouterr().err
    assert main([*args, "--data-list", str(POSITIONS)]) == 0
    assert main([*args, "--data-list", str(POSITIONS), "--data-list", str(POSITIONS)]) == 0
    assert main([*args, "--data-lists-from", str(CELL)]) == 0


def test_a_global_signal_of_a_public_list_is_an_input(tmp_path: Path) -> None:
    (tmp_path / "Io.dat").write_text("DEFDAT Io PUBLIC\nGLOBAL SIGNAL DOOR_OK $IN[7]\nENDDAT\n")
    src = tmp_path / "p.src"
    src.write_text("DEF p( )\nWAIT FOR DOOR_OK\nEND\n")
    (wait,) = load_krl(src, data_lists_from=tmp_path).program
    assert isinstance(wait, ir.WaitInput) and wait.index == 7
