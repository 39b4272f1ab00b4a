"""Read YAML that a user wrote (station files, robot library entries, post manifests) safely.

PyYAML's ``safe_load`` still turns a careless or hostile file into a traceback or a hang: an
alias bomb expands without limit, a recursive alias or deep nesting overflows the stack, a
400-digit number or a date reaches the caller as a Python object it does not expect, a second
``robot:`` silently replaces the first, and ``0100`` means 64 (YAML 1.1 octal). :func:`read_yaml`
reads one document under these rules instead; every breach is the caller's
:class:`~olp.errors.OlpError` subclass located at file:line:column and quoting the user's text:

- the file is a regular file of at most :data:`MAX_BYTES`, UTF-8 (a leading BOM is dropped),
  without control characters;
- values are text, whole numbers, floating-point numbers, ``true``/``false``, null, lists and
  mappings (the YAML 1.2 core schema): ``1e3`` is a number, ``yes``/``on``/``2024-01-01`` are
  text, and a whole number with a leading zero (``0100``) is an error, since YAML 1.1 reads it
  as octal and YAML 1.2 as decimal;
- explicit tags other than the core ones (``!!str !!int !!float !!bool !!null !!seq !!map``)
  are errors (``!!python/name:...``, ``!foo``, ``!!timestamp``, ``!!binary`` ...), and so is a
  core tag on text it does not fit (``!!int "abc"``);
- keys are plain text (not lists or mappings), unique within their mapping at every level;
  merge keys (``<<``) are not supported;
- aliases are allowed, but the document may hold at most :data:`MAX_VALUES` values once they
  are expanded, at most :data:`MAX_DEPTH` levels deep, and an alias may not contain itself;
- a whole number has at most :data:`MAX_DIGITS` digits.

The result, a :class:`YamlDocument`, keeps for every key path (``("robot", "base", "xyz", 0)``)
where it was written and the text written there, so a reader can report its own mistakes
(a wrong type, a value out of range) the same way.
"""

from __future__ import annotations

import math
import os
import re
import stat
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from olp.errors import OlpError
from olp.span import SourceSpan

KeyPath = tuple[str | int, ...]
"""Where a value sits in a document: mapping keys and list indices from the top."""

MAX_BYTES = 2**20
"""Largest YAML file read (1 MiB; pure-Python parsing takes up to ~2.5 s for that);
hand-written stations and manifests are a few kB."""
MAX_VALUES = 50_000
"""Most values (scalars, lists, mappings) a document may hold, aliases expanded."""
MAX_DEPTH = 64
"""Deepest nesting of lists and mappings, aliases expanded."""
MAX_DIGITS = 100
"""Most digits of a whole number; longer ones mean nothing to olp and are slow to convert."""

_CORE = "tag:yaml.org,2002:"
_STR, _INT, _FLOAT, _BOOL, _NULL = (_CORE + t for t in ("str", "int", "float", "bool", "null"))
_SEQ, _MAP = _CORE + "seq", _CORE + "map"
_LEADING_ZERO = "tag:olp,2026:leading-zero-int"
_DIGITS = "0123456789"

_RESOLVERS: tuple[tuple[str, str, str | list[str]], ...] = (
    (_BOOL, r"(?:true|True|TRUE|false|False|FALSE)\Z", "tTfF"),
    (_NULL, r"(?:~|null|Null|NULL|)\Z", ["~", "n", "N", ""]),
    (_LEADING_ZERO, r"[-+]?0[0-9_]+\Z", "-+0"),
    (_INT, r"[-+]?(?:0|[1-9][0-9_]*)\Z", "-+" + _DIGITS),
    (_INT, r"[-+]?0x[0-9a-fA-F_]+\Z", "-+0"),
    (_INT, r"[-+]?0o[0-7_]+\Z", "-+0"),
    (
        _FLOAT,
        r"[-+]?(?:[0-9][0-9_]*\.[0-9_]*(?:[eE][-+]?[0-9]+)?"
        r"|\.[0-9][0-9_]*(?:[eE][-+]?[0-9]+)?"
        r"|[0-9][0-9_]*[eE][-+]?[0-9]+)\Z",
        "-+." + _DIGITS,
    ),
    (_FLOAT, r"(?:[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))\Z", "-+."),
)

# What the YAML spec (and PyYAML's reader) refuses: C0/C1 controls other than tab and line
# breaks, surrogates, and the two non-characters U+FFFE/U+FFFF.
_NOT_PRINTABLE = re.compile(
    "[^\x09\x0a\x0d\x20-\x7e\x85\xa0-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]"
)


class _Refused(Exception):
    """A rule above was broken at ``mark``; becomes the caller's error type."""

    def __init__(self, message: str, mark: Any) -> None:
        super().__init__(message)
        self.message = message
        self.mark = mark


class AliasNode(yaml.Node):
    """An alias as written (``*name``): where it stands, and the node it names."""

    id = "alias"

    def __init__(self, target: yaml.Node, anchor: str, start_mark: Any, end_mark: Any) -> None:
        super().__init__("alias", target, start_mark, end_mark)
        self.anchor = anchor


class SafeYamlLoader(yaml.SafeLoader):
    """PyYAML's safe loader with the core-schema resolvers above, bounded node count and
    nesting, and aliases kept as :class:`AliasNode` (so expansion can be counted and recursion
    found). Only composing is used: :func:`read_yaml` builds the Python values itself."""

    # A fresh table, filled below (PyYAML's class-level registry; ClassVar would clash with
    # the stubs' instance annotation).
    yaml_implicit_resolvers: dict[Any, list[tuple[str, re.Pattern[str]]]] = {}  # noqa: RUF012

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0
        self._nodes = 0

    def compose_node(self, parent: Any, index: Any) -> Any:
        if self.check_event(yaml.AliasEvent):
            event = self.get_event()
            if event.anchor not in self.anchors:
                raise _Refused(f"alias *{event.anchor} names no anchor", event.start_mark)
            target = self.anchors[event.anchor]
            return AliasNode(target, event.anchor, event.start_mark, event.end_mark)
        start = self.peek_event().start_mark
        self._nodes += 1
        if self._nodes > MAX_VALUES:
            raise _Refused(f"more than {MAX_VALUES} values in one file", start)
        self._depth += 1
        if self._depth > MAX_DEPTH:
            raise _Refused(f"lists and mappings nested more than {MAX_DEPTH} deep", start)
        try:
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


for _tag, _pattern, _first in _RESOLVERS:
    SafeYamlLoader.add_implicit_resolver(_tag, re.compile(_pattern), list(_first))


@dataclass(frozen=True, slots=True)
class YamlDocument:
    """One YAML document as plain Python values, with where each value was written.

    ``value``: dicts (str keys, in file order), lists, str, int, float, bool, None.
    ``locations``: (line, column), 1-based, per key path: a mapping entry's key, else the value.
    ``extents``: (start, end) character offsets into ``text`` of the value at each key path.
    ``error_type``: the :class:`OlpError` subclass :meth:`error` raises (StationError ...).
    """

    value: Any
    file: str
    text: str
    locations: Mapping[KeyPath, tuple[int, int]]
    extents: Mapping[KeyPath, tuple[int, int]]
    error_type: type[OlpError]

    @property
    def folder(self) -> Path:
        """The folder the file lies in: files it names are relative to it."""
        return Path(self.file).parent

    def span(self, path: KeyPath) -> SourceSpan:
        line, column = self.locations.get(path, (1, 1))
        return SourceSpan(self.file, line, column)

    def source(self, path: KeyPath, limit: int = 60) -> str:
        """The text written for the value at ``path``, on one line, shortened to ``limit``."""
        start, end = self.extents.get(path, (0, 0))
        return shorten(" ".join(self.text[start:end].split()), limit)

    def shown(self, path: KeyPath) -> str:
        """The value at ``path`` as an error message quotes it: ``'text'`` (or ``"text"`` as
        written, when the user quoted it), or ``nothing``."""
        text = self.source(path)
        if len(text) >= 2 and text[0] in "'\"" and text[-1] == text[0]:
            return text
        return f"'{text}'" if text else "nothing"

    def error(self, path: KeyPath, message: str) -> OlpError:
        """An error at ``path``, its message prefixed with the key path (``robot.base: ...``)."""
        where = ".".join(str(p) for p in path) or "<top level>"
        span = self.span(path)
        return self.error_type(f"{where}: {message}", span, _line(self.text, span.line))


def shorten(text: str, limit: int = 60) -> str:
    """``text`` cut to ``limit`` characters, the middle replaced by ``...`` when cut."""
    if len(text) <= limit:
        return text
    half = (limit - 3) // 2
    return f"{text[:half]}...{text[len(text) - (limit - 3 - half) :]}"


def read_yaml(
    path: str | Path, error_type: type[OlpError], *, max_bytes: int = MAX_BYTES
) -> YamlDocument:
    """Read one YAML document a user wrote, under the rules of this module.

    Parameters
    ----------
    path:
        The file; it must be a regular file (not a folder, device or FIFO) of at most
        ``max_bytes`` bytes, in UTF-8.
    error_type:
        What to raise: ``StationError`` for stations and robot files, ``PostError`` for post
        manifests. Every mistake is raised as ``error_type(message, span, source_line)``.

    Returns
    -------
    YamlDocument
        The values (an empty file is ``{}``), their locations and the text.
    """
    file = str(path)
    try:
        data = read_regular_file(Path(path), max_bytes)
    except UnreadableFile as exc:
        raise error_type(f"cannot read {file}: {exc}", SourceSpan(file, 1)) from exc
    return parse_yaml(data, file, error_type)


def parse_yaml(data: bytes | str, file: str, error_type: type[OlpError]) -> YamlDocument:
    """Like :func:`read_yaml` for text already read; ``file`` is the name errors give."""
    text = _decode(data, file, error_type) if isinstance(data, bytes) else data
    text = text.removeprefix("\ufeff")
    bad = _NOT_PRINTABLE.search(text)
    if bad:
        line, column = _position(text, bad.start())
        raise error_type(
            f"character U+{ord(bad.group()):04X} (a control character) is not allowed in YAML",
            SourceSpan(file, line, column),
            _printable(_line(text, line) or ""),
        )
    loader = SafeYamlLoader(text)
    builder = _Builder()
    try:
        node = loader.get_single_node()
        value = {} if node is None else builder.build(node, (), 0)
    except _Refused as exc:
        raise _located(error_type, exc.message, exc.mark, file, text) from None
    except yaml.MarkedYAMLError as exc:
        problem = ", ".join(p for p in (exc.context, exc.problem) if p) or "not valid YAML"
        mark = exc.problem_mark or exc.context_mark
        raise _located(error_type, f"invalid YAML: {problem}", mark, file, text) from None
    except yaml.YAMLError as exc:
        raise error_type(f"invalid YAML: {exc}", SourceSpan(file, 1)) from None
    finally:
        loader.dispose()
    return YamlDocument(value, file, text, builder.locations, builder.extents, error_type)


# --------------------------------------------------------------------------------------------
# Files


class UnreadableFile(Exception):
    """Why a file named by a user is not read (its text is the reason, for a message)."""


_SYSTEM_ROOTS = (Path("/proc"), Path("/sys"), Path("/dev"))


def read_regular_file(path: Path, max_bytes: int) -> bytes:
    """The bytes of ``path`` if it is a regular file of at most ``max_bytes`` bytes.

    Never opens a folder, device, FIFO or socket, nor anything under /proc, /sys or /dev (their
    "files" are endless, change while read, or reveal the process); the type is checked before
    opening and again on the opened descriptor, so a swap in between is caught. Raises
    :class:`UnreadableFile` with the reason.
    """
    real = path.resolve()
    if any(real.is_relative_to(root) for root in _SYSTEM_ROOTS):
        raise UnreadableFile(f"{real} is a system file; olp never reads /proc, /sys or /dev")
    try:
        _check_kind(os.stat(path), max_bytes)
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    except FileNotFoundError:
        raise UnreadableFile("no such file") from None
    except OSError as exc:
        raise UnreadableFile(exc.strerror or str(exc)) from None
    try:
        _check_kind(os.fstat(fd), max_bytes)
        with os.fdopen(fd, "rb", closefd=False) as stream:
            data = stream.read(max_bytes + 1)
    except OSError as exc:
        raise UnreadableFile(exc.strerror or str(exc)) from None
    finally:
        os.close(fd)
    if len(data) > max_bytes:
        raise UnreadableFile(_too_big(max_bytes))
    return data


def _check_kind(info: os.stat_result, max_bytes: int) -> None:
    if stat.S_ISDIR(info.st_mode):
        raise UnreadableFile("it is a folder, not a file")
    if not stat.S_ISREG(info.st_mode):
        raise UnreadableFile("not a regular file (a device, FIFO or socket); olp reads only files")
    if info.st_size > max_bytes:
        raise UnreadableFile(_too_big(max_bytes))


def _too_big(max_bytes: int) -> str:
    return f"the file is larger than {max_bytes / 2**20:g} MiB, the most olp reads"


# --------------------------------------------------------------------------------------------
# Nodes to values


class _Builder:
    """Python values from composed nodes, counting values and depth with aliases expanded."""

    def __init__(self) -> None:
        self.locations: dict[KeyPath, tuple[int, int]] = {}
        self.extents: dict[KeyPath, tuple[int, int]] = {}
        self.count = 0
        self.open: set[int] = set()  # ids of the lists and mappings being built (recursion)
        self.aliases: list[AliasNode] = []  # the aliases being expanded, outermost first

    def _too_much(self, node: yaml.Node, depth: int) -> _Refused:
        """Too many values or too deep: blamed on the outermost alias being expanded, if any
        (that is where a bomb is set off), else on the node itself."""
        what = (
            f"more than {MAX_VALUES} values"
            if self.count > MAX_VALUES
            else f"lists and mappings nested more than {MAX_DEPTH} deep"
        )
        if not self.aliases:
            return _Refused(what, node.start_mark)
        alias = self.aliases[0]
        return _Refused(
            f"alias *{alias.anchor} expands to {what}; olp bounds how far aliases expand "
            f"(at most {MAX_VALUES} values, {MAX_DEPTH} levels deep)",
            alias.start_mark,
        )

    def build(self, node: yaml.Node, path: KeyPath, depth: int) -> Any:
        self.count += 1
        if self.count > MAX_VALUES or depth > MAX_DEPTH:
            raise self._too_much(node, depth)
        self.locations.setdefault(path, _mark(node.start_mark))
        self.extents[path] = (node.start_mark.index, node.end_mark.index)
        if isinstance(node, AliasNode):
            if id(node.value) in self.open:
                raise _Refused(f"alias *{node.anchor} contains itself", node.start_mark)
            self.aliases.append(node)
            try:
                return self.build(node.value, path, depth)
            finally:
                self.aliases.pop()
        if isinstance(node, yaml.ScalarNode):
            return _scalar(node)
        _check_tag(node, _SEQ if isinstance(node, yaml.SequenceNode) else _MAP)
        self.open.add(id(node))
        try:
            if isinstance(node, yaml.SequenceNode):
                return [self.build(n, (*path, i), depth + 1) for i, n in enumerate(node.value)]
            return self._mapping(node, path, depth)
        finally:
            self.open.discard(id(node))

    def _mapping(self, node: yaml.Node, path: KeyPath, depth: int) -> dict[str, Any]:
        out: dict[str, Any] = {}
        first: dict[str, tuple[int, int]] = {}
        for key_node, value_node in node.value:
            key = _key(key_node)
            if key in first:
                raise _Refused(
                    f"duplicate key '{shorten(key)}' (first given at line {first[key][0]}); "
                    "YAML would silently keep only the last one",
                    key_node.start_mark,
                )
            first[key] = _mark(key_node.start_mark)
            self.locations[(*path, key)] = first[key]
            out[key] = self.build(value_node, (*path, key), depth + 1)
        return out


def _key(node: yaml.Node) -> str:
    if not isinstance(node, yaml.ScalarNode):
        text = _text_of(node)
        raise _Refused(f"a key must be plain text, not '{text}'", node.start_mark)
    if node.value == "<<" and node.style is None:
        raise _Refused("merge keys ('<<') are not supported; write the keys out", node.start_mark)
    _scalar(node)  # the same tag rules as for values
    return str(node.value)


def _scalar(node: yaml.ScalarNode) -> Any:
    text, tag = node.value, node.tag
    if tag == _STR:
        return text
    if tag == _LEADING_ZERO:
        raise _Refused(
            f"'{shorten(text)}' is ambiguous: YAML 1.1 reads a leading 0 as octal, YAML 1.2 "
            "as decimal; write it without the leading 0 (or quote it if it is text)",
            node.start_mark,
        )
    readers = {_NULL: _to_null, _BOOL: _to_bool, _INT: _to_int, _FLOAT: _to_float}
    if tag not in readers:
        raise _Refused(
            f"unsupported tag {_short(tag)}: olp reads plain YAML (text, numbers, true/false, "
            "null, lists and mappings)",
            node.start_mark,
        )
    value = readers[tag](text)
    if value is _INVALID:
        kind = {_NULL: "null", _BOOL: "true or false", _INT: "a whole number"}
        raise _Refused(
            f"'{shorten(text)}' is not {kind.get(tag, 'a number')} ({_short(tag)})",
            node.start_mark,
        )
    if value is _TOO_LONG:
        raise _Refused(
            f"the number '{shorten(text)}' has more than {MAX_DIGITS} digits; "
            "too large to mean anything",
            node.start_mark,
        )
    return value


_INVALID = object()
_TOO_LONG = object()


def _to_null(text: str) -> Any:
    return None if text in ("", "~", "null", "Null", "NULL") else _INVALID


def _to_bool(text: str) -> Any:
    return {"true": True, "false": False}.get(text.lower(), _INVALID)


def _to_int(text: str) -> Any:
    body = text.replace("_", "")
    if sum(c.isalnum() for c in body) > MAX_DIGITS:
        return _TOO_LONG
    try:
        return int(body, 0)
    except ValueError:
        return _INVALID


def _to_float(text: str) -> Any:
    body = text.replace("_", "")
    special = {".inf": math.inf, "+.inf": math.inf, "-.inf": -math.inf, ".nan": math.nan}
    if body.lower() in special:
        return special[body.lower()]
    try:
        return float(body)
    except ValueError:
        return _INVALID


def _check_tag(node: yaml.Node, expected: str) -> None:
    if node.tag != expected:
        raise _Refused(f"unsupported tag {_short(node.tag)} on a list or mapping", node.start_mark)


def _short(tag: str) -> str:
    return "!!" + tag[len(_CORE) :] if tag.startswith(_CORE) else shorten(tag, 40)


def _text_of(node: yaml.Node) -> str:
    buffer = node.start_mark.buffer or ""
    return shorten(" ".join(buffer[node.start_mark.index : node.end_mark.index].split()))


# --------------------------------------------------------------------------------------------
# Positions


def _mark(mark: Any) -> tuple[int, int]:
    return mark.line + 1, mark.column + 1


def _located(error_type: type[OlpError], message: str, mark: Any, file: str, text: str) -> OlpError:
    line, column = _mark(mark) if mark is not None else (1, 1)
    return error_type(message, SourceSpan(file, line, column), _line(text, line))


def _line(text: str, line: int) -> str | None:
    """The 1-based ``line`` of ``text`` (YAML's line breaks), or None if out of range."""
    lines = re.split(r"\r\n|[\r\n\x85\u2028\u2029]", text)
    return lines[line - 1] if 1 <= line <= len(lines) else None


def _position(text: str, index: int) -> tuple[int, int]:
    """1-based (line, column) of character ``index``, counting YAML's line breaks."""
    before = re.split(r"\r\n|[\r\n\x85\u2028\u2029]", text[:index])
    return len(before), len(before[-1]) + 1


def _printable(line: str) -> str:
    return _NOT_PRINTABLE.sub("?", line)


def _decode(data: bytes, file: str, error_type: type[OlpError]) -> str:
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        line_start = data.rfind(b"\n", 0, exc.start) + 1
        column = len(data[line_start : exc.start].decode("utf-8", "replace")) + 1
        line_end = data.find(b"\n", exc.start)
        shown = data[line_start : line_end if line_end >= 0 else len(data)]
        raise error_type(
            f"not UTF-8 text: byte 0x{data[exc.start]:02X} cannot start or continue a character "
            "(save the file as UTF-8)",
            SourceSpan(file, line, column),
            _printable(shown.decode("utf-8", "replace")),
        ) from None
