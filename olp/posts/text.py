"""User text on its way into robot code: identifiers, comments and call arguments.

Every string that reaches a post from a user (program and file names, comments, names of called
routines and their arguments, tool and frame names, ``--set`` values that a program turned into
any of these) goes through one of three rules here, which each post parametrises:

* :class:`NameRule` - identifiers. Names olp makes up (programs, parts, points, tools, frames) are
  made legal (:meth:`NameRule.legal`); names olp does not own (a routine another program defines)
  must already be legal (:meth:`NameRule.is_legal`), or the post reports an error.
* :class:`CommentRule` - comments become one or more comment lines: a line break in the text
  starts another *comment* line, never a statement; other control characters are refused.
* :class:`ArgumentRule` - a call's arguments must each be a literal or a plain name of the target
  language; anything else (``1;MoveAbsJ ...``, an expression) is refused.

What cannot be written safely is refused with a located diagnostic (:mod:`olp.posts.base`); the
sandbox's :func:`olp.posts.sandbox.finalize` is the last guard behind these rules.
"""

from __future__ import annotations

import re
import textwrap
import unicodedata
from dataclasses import dataclass, field

from olp.posts.sandbox import unsafe_character

LINE_BREAKS = re.compile(r"\r\n|[\n\r\v\f\x1c\x1d\x1e\x85\u2028\u2029]")
"""What may end a line in a text: Python's ``str.splitlines`` set."""


@dataclass(frozen=True, slots=True)
class NameRule:
    """Identifiers of one controller language.

    ``max_length``: characters (None: no limit); ``reserved``: words a name must not be;
    ``case_sensitive``: whether ``reserved`` is compared exactly (else in upper case);
    ``upper``: names are written in upper case; ``prefix``: put in front of a name that does not
    start with a letter.
    """

    max_length: int | None = None
    reserved: frozenset[str] = frozenset()
    case_sensitive: bool = False
    upper: bool = False
    prefix: str = "P"

    def legal(self, name: str) -> str:
        """A legal identifier made from ``name``: ASCII letters, digits and ``_``, a letter
        first, cut to ``max_length``; a reserved word gets a trailing ``_``."""
        cleaned = "".join(
            ch if ch.isascii() and (ch.isalnum() or ch == "_") else "_" for ch in str(name)
        )
        if self.upper:
            cleaned = cleaned.upper()
        if not cleaned or not cleaned[0].isalpha():
            cleaned = self.prefix + cleaned
        if self.max_length is not None:
            cleaned = cleaned[: self.max_length]
        if self.is_reserved(cleaned):
            cut = cleaned if self.max_length is None else cleaned[: self.max_length - 1]
            cleaned = cut + "_"
        return cleaned

    def describe(self) -> str:
        """The rule in words, for a message."""
        length = "" if self.max_length is None else f", at most {self.max_length} characters"
        return f"ASCII letters, digits and '_', a letter first{length}, not a reserved word"

    def is_reserved(self, name: str) -> bool:
        return (name if self.case_sensitive else name.upper()) in self.reserved

    def is_legal(self, name: str) -> bool:
        """Whether ``name`` is a legal identifier as it stands (upper-case rules compare the name
        in upper case: Fanuc reads ``Grip`` as ``GRIP``)."""
        text = name.upper() if self.upper else name
        return bool(name) and self.legal(text) == text


@dataclass(frozen=True, slots=True)
class CommentRule:
    """Comments of one controller language.

    ``max_length``: characters per comment line (longer lines are wrapped at spaces; None: no
    limit); ``replace``: characters the language gives a meaning inside comments, with what is
    written instead (Fanuc ends an instruction at ``;``); ``collapse``: runs of spaces become
    one space.
    """

    max_length: int | None = None
    replace: tuple[tuple[str, str], ...] = ()
    collapse: bool = False

    def lines(self, text: str) -> list[str]:
        """The comment lines of ``text``: one per line of the text (wrapped to ``max_length``),
        tabs as spaces. Raises ValueError naming a control character that is not a line
        break or a tab."""
        out: list[str] = []
        for line in LINE_BREAKS.split(str(text)):
            line = line.replace("\t", " ")
            bad = unsafe_character(line)
            if bad is not None:
                raise ValueError(f"control character {_show(bad)}")
            for old, new in self.replace:
                line = line.replace(old, new)
            if self.collapse:
                line = " ".join(line.split())
            line = line.rstrip()
            if self.max_length is not None and len(line) > self.max_length:
                words = " ".join(line.split())
                out += textwrap.wrap(words, self.max_length, break_long_words=True) or [""]
            else:
                out.append(line)
        return out or [""]


@dataclass(frozen=True, slots=True)
class ArgumentRule:
    """What a call argument may be in one language: a full match of ``pattern`` (after
    stripping spaces). ``describe`` is the rule in words for error messages."""

    pattern: re.Pattern[str] = field(default_factory=lambda: re.compile(r"(?!)"))
    describe: str = "no arguments"

    def allows(self, argument: str) -> bool:
        return self.pattern.fullmatch(str(argument).strip()) is not None


NUMBER = r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?"
"""A decimal number literal (written so that matching is linear in its length: no two
quantifiers may share the digits of a 200,000-digit argument)."""
IDENTIFIER = r"[A-Za-z_][A-Za-z0-9_]*"
"""A plain name (a variable or constant of the program)."""


def double_quoted(forbidden: str = "") -> str:
    """A ``"..."`` string literal without control characters, ``"`` or ``forbidden``."""
    bad = re.escape('"' + forbidden)
    return rf'"[^{bad}\x00-\x1f\x7f-\x9f\u2028\u2029]*"'


def single_quoted() -> str:
    """A ``'...'`` string literal without control characters or ``'``."""
    return r"'[^'\x00-\x1f\x7f-\x9f\u2028\u2029]*'"


def one_of(*alternatives: str) -> re.Pattern[str]:
    return re.compile("|".join(f"(?:{a})" for a in alternatives))


def basename(path: str) -> str:
    """The last component of a path written with ``/`` or ``\\`` (for header comments: where a
    program came from, without the machine's folders)."""
    return str(path).replace("\\", "/").rstrip("/").rsplit("/", 1)[-1]


def encodable(text: str, encoding: str) -> str | None:
    """The first character of ``text`` that ``encoding`` cannot write, or None."""
    try:
        text.encode(encoding)
    except UnicodeEncodeError as exc:
        return text[exc.start]
    return None


def plain(text: str, encoding: str) -> str:
    """``text`` for an informational comment (a file name in a header): control characters and
    characters the encoding lacks become ``?``."""
    out = []
    for ch in str(text):
        ok = unsafe_character(ch) is None and ch != "\t" and encodable(ch, encoding) is None
        out.append(ch if ok else "?")
    return "".join(out)


def _show(ch: str) -> str:
    name = unicodedata.name(ch, "")
    return f"U+{ord(ch):04X}" + (f" ({name})" if name else "")


def show_character(ch: str) -> str:
    """A character as an error message names it: ``'é' (U+00E9)``, or ``U+0007`` for a control
    character."""
    return _show(ch) if unsafe_character(ch) is not None else f"{ch!r} (U+{ord(ch):04X})"
