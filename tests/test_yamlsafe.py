"""The safe YAML reader: the core schema (no dates, no octal surprises, no Python objects),
bounded aliases and nesting, unique keys, only regular files, and the caller's error type."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from olp.errors import PostError, StationError
from olp.yamlsafe import parse_yaml, read_yaml


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("1e3", 1000.0),  # YAML 1.1 (PyYAML) reads text: no dot
        ("-2.5E-1", -0.25),
        (".5", 0.5),
        ("1_000", 1000),
        ("0x1F", 31),
        ("0o17", 15),
        ("0", 0),
        ("true", True),
        ("FALSE", False),
        ("yes", "yes"),  # YAML 1.1: True
        ("off", "off"),  # YAML 1.1: False
        ("2024-01-01", "2024-01-01"),  # YAML 1.1: a date
        ("1:30", "1:30"),  # YAML 1.1: 90
        ("=", "="),  # YAML 1.1: a 'value' tag PyYAML cannot build
        ("~", None),
        ("", None),
        ("!!str 5", "5"),
        ("!!float '1'", 1.0),
        ('"0100"', "0100"),
    ],
)
def test_core_schema_values(text: str, value: object) -> None:
    got = parse_yaml(f"a: {text}\n", "f.yaml", StationError).value["a"]
    assert got == value and type(got) is type(value)


def test_errors_are_the_callers_type_and_located() -> None:
    with pytest.raises(PostError) as info:
        parse_yaml("name: x\nfiles:\n  a: 1\n  a: 2\n", "post.yaml", PostError)
    error = info.value
    assert error.span is not None and (error.span.line, error.span.column) == (4, 3)
    assert "duplicate key 'a' (first given at line 3)" in error.message
    assert error.source_line == "  a: 2"


def test_where_each_value_was_written() -> None:
    doc = parse_yaml("\ufeffa:\r\n  b: [1, 2024-01-01]\r\n  c: {x: 1}\r\n", "f", StationError)
    assert doc.value == {"a": {"b": [1, "2024-01-01"], "c": {"x": 1}}}
    assert doc.locations[("a", "b")] == (2, 3)  # a mapping entry: its key
    assert doc.locations[("a", "b", 1)] == (2, 10)
    assert doc.shown(("a", "b", 1)) == "'2024-01-01'"
    assert doc.shown(("a", "c")) == "'{x: 1}'"
    assert parse_yaml('a: "x y"', "f", StationError).shown(("a",)) == '"x y"'  # as written
    error = doc.error(("a", "c", "x"), "wrong")
    assert error.message == "a.c.x: wrong" and error.source_line == "  c: {x: 1}"


def test_a_long_value_is_quoted_shortened() -> None:
    doc = parse_yaml("a: " + "x" * 1000 + "\n", "f", StationError)
    shown = doc.shown(("a",))
    assert len(shown) == 62 and "..." in shown


def test_aliases_expand_within_bounds() -> None:
    doc = parse_yaml("a: &p [1, 2]\nb: *p\n", "f", StationError)
    assert doc.value == {"a": [1, 2], "b": [1, 2]}
    levels = ["a: &a [x, x, x, x, x, x, x, x]\n"] + [
        f"{c}: &{c} [{', '.join([f'*{p}'] * 8)}]\n" for p, c in zip("abcde", "bcdef", strict=True)
    ]
    with pytest.raises(StationError, match="alias \\*e expands to more than 50000 values"):
        parse_yaml("".join(levels), "f", StationError)


@pytest.mark.parametrize(
    ("make", "needle"),
    [
        (lambda p: os.mkfifo(p), "not a regular file"),
        (lambda p: p.mkdir(), "a folder, not a file"),
        (lambda p: p.symlink_to(os.devnull), "olp never reads /proc, /sys or /dev"),
        (lambda p: p.write_text("a: " + "x" * 2**20), "larger than 1 MiB"),
        (lambda p: None, "no such file"),
    ],
)
def test_only_regular_files_of_sane_size_are_read(
    tmp_path: Path, make: object, needle: str
) -> None:
    path = tmp_path / "cell.yaml"
    make(path)  # type: ignore[operator]
    with pytest.raises(StationError) as info:
        read_yaml(path, StationError)
    assert needle in info.value.message
    assert info.value.span is not None and info.value.span.file == str(path)
