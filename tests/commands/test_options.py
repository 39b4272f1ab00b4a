"""The program options on the command line come from the frontends' ``Options`` types (issue 11):
every flag keeps its spelling and meaning, and goes to the frontend of the program's suffix."""

from __future__ import annotations

import argparse

import pytest

from olp.commands.options import add_program, add_program_options, program_options
from olp.errors import UsageError
from olp.frontends.bundled import CsvOptions, DslOptions, KrlOptions


def options(*argv: str) -> object:
    parser = argparse.ArgumentParser()
    add_program(parser)
    add_program_options(parser)
    return program_options(parser.parse_args(argv))


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["p.csv"], CsvOptions()),
        (
            ["p.CSV", "--tool", "spindle", "--frame", "table"],
            CsvOptions(tool="spindle", frame="table"),
        ),
        (["p.csv", "--orientation=-180,0,90"], CsvOptions(orientation=(-180.0, 0.0, 90.0))),
        (["p.csv", "--orientation", "180;0;0"], CsvOptions(orientation=(180.0, 0.0, 0.0))),
        (["p.csv", "--orientation", "home"], CsvOptions(orientation=None)),
        (["p.csv", "--euler", "abc"], CsvOptions(euler="ZYX")),
        (["p.csv", "--speed", "40", "--zone", "2.5"], CsvOptions(speed=40.0, zone=2.5)),
        (["p.csv", "--delimiter", "tab"], CsvOptions(delimiter="\t")),
        (["p.csv", "--delimiter", ";", "--decimal", ","], CsvOptions(delimiter=";", decimal=",")),
        (["p.csv", "--header", "2"], CsvOptions(header=2)),
        (
            ["p.csv", "--units", "in", "--angle-units", "rad"],
            CsvOptions(units="in", angle_units="rad"),
        ),
        (["p.src"], KrlOptions()),
        (["p.src", "--config-dat", "c.dat"], KrlOptions(config_dat="c.dat")),
        (["p.py"], DslOptions(timeout=60.0)),
        (["p.py", "--set", "A=1", "--set", "B= x"], DslOptions(params={"A": "1", "B": " x"})),
        (["p.py", "--timeout", "5"], DslOptions(timeout=5.0)),
        (["p.py", "--timeout", "inf"], DslOptions(timeout=None)),
    ],
)
def test_every_flag_reaches_its_frontends_options(argv: list[str], expected: object) -> None:
    assert options(*argv) == expected


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["p.src", "--tool", "spindle"], "--tool is for CSV toolpaths (.csv), not .src"),
        (["p.py", "--delimiter", ","], "--delimiter is for CSV toolpaths (.csv), not .py"),
        (["p.csv", "--config-dat", "c.dat"], "--config-dat is for KRL programs (.src), not .csv"),
        (["p.csv", "--set", "A=1"], "--set is for Python programs (.py), not .csv"),
        (["p.src", "--timeout", "5"], "--timeout is for Python programs (.py), not .src"),
        (["p.src", "--set", "A"], "--set 'A': expected NAME=VALUE"),
        (["p.csv", "--header", "two"], "--header 'two': expected a whole number"),
        (["p.csv", "--speed", "nan"], "--speed 'nan': expected a finite number"),
        (["p.csv", "--zone", "-1"], "toolpath zone must be >= 0 mm, got -1.0"),
        (["p.csv", "--euler", "xxy"], "Euler sequence 'xxy'"),
        (["p.py", "--timeout", "0"], "--timeout must be a positive number of seconds"),
        (["p.txt"], "unknown program type '.txt' (supported: .src, .csv, .py)"),
    ],
)
def test_flags_that_do_not_fit_are_usage_errors(argv: list[str], message: str) -> None:
    with pytest.raises(UsageError) as info:
        options(*argv)
    assert message in info.value.message


def test_choices_are_checked_by_argparse() -> None:
    with pytest.raises(SystemExit):
        options("p.csv", "--units", "km")
