"""The Jinja environment every post renders in: sandboxed, and no expression may start a line.

A post's templates are data. Bundled ones ship with olp, but a customer's template folder (passed
by an explicit path, ``--post ./my_posts/kuka_line3``) may come from anywhere, so no template can
run code: :class:`PostSandbox` is Jinja's immutable sandbox with a stricter rule for calls. A
template may call its own macros, Jinja's loop helpers and globals, the non-mutating methods of
plain Python data (``dict.values``, ``str.upper``), and :class:`olp.posts.view.Modal` - nothing
else. The sandbox's default allows calling any method of any object it is handed, and a template
sees numpy arrays (``ndarray.tofile`` writes files) and the station; those methods are refused
here. Filters are the post's own Python and are not affected.

Every ``{{ expression }}`` goes through :func:`finalize`, the last guard of "user text is never
code": a plain string that holds a line break or another control character, and any bare float
(a number written without the post's number format), is refused. Text a post builds from several
lines on purpose (Fanuc's numbered /MN body) is a :class:`SafeText`, made only by post filters.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from jinja2 import FileSystemLoader, StrictUndefined, TemplateRuntimeError
from jinja2.runtime import BlockReference, LoopContext, Macro
from jinja2.sandbox import ImmutableSandboxedEnvironment, SecurityError
from jinja2.utils import Cycler, Joiner, Namespace

from olp.posts.view import Modal


class SafeText(str):
    """Text a post filter assembled from already-checked pieces (it may span several lines)."""

    __slots__ = ()


class UnsafeOutput(TemplateRuntimeError):
    """A template expression produced text that could start a new line, or a bare float."""


_PLAIN_DATA = (str, bytes, dict, list, tuple, int, float, bool, frozenset, range)
_HELPERS = (Modal, LoopContext, Cycler, Joiner, Namespace, BlockReference)

_CONTROL = frozenset(chr(c) for c in (*range(0x00, 0x20), 0x7F, *range(0x80, 0xA0))) | {
    "\u2028",
    "\u2029",
}
"""Characters no template expression may produce: C0 and C1 controls (line feed, carriage
return, vertical tab, form feed, NEL among them), DEL, and the Unicode line and paragraph
separators. Tabs are refused too: posts write spaces."""


def unsafe_character(text: str) -> str | None:
    """The first character of ``text`` that may start a new line or is a control character, or
    None. Used by :func:`finalize` and by the posts' escaping."""
    for ch in text:
        if ch in _CONTROL:
            return ch
    return None


def finalize(value: Any) -> Any:
    """Check the value of every ``{{ expression }}`` before it becomes text."""
    if isinstance(value, SafeText) or value is None:
        return value
    if isinstance(value, float):
        raise UnsafeOutput(
            f"a template wrote the bare number {value!r}: numbers go through the post's "
            "number filters, which check range and resolution"
        )
    if isinstance(value, str):
        bad = unsafe_character(value)
        if bad is not None:
            raise UnsafeOutput(
                f"a template expression produced the control character {bad!r} in "
                f"{_excerpt(value)!r}: user text must go through the post's escaping"
            )
    return value


def _excerpt(text: str, limit: int = 60) -> str:
    return text if len(text) <= limit else text[: limit - 3] + "..."


class PostSandbox(ImmutableSandboxedEnvironment):
    """Jinja's immutable sandbox, calling only macros, Jinja helpers and plain-data methods."""

    def is_safe_callable(self, obj: Any) -> bool:
        if not super().is_safe_callable(obj):
            return False
        if isinstance(obj, Macro) or any(obj is g for g in self.globals.values()):
            return True
        owner = getattr(obj, "__self__", None)
        if inspect.ismethod(obj) and isinstance(owner, _HELPERS):
            return True
        if inspect.isbuiltin(obj) and isinstance(owner, _PLAIN_DATA):
            return True
        wrapped = getattr(obj, "__wrapped__", None)  # the sandbox's safe str.format
        return inspect.isbuiltin(wrapped) and isinstance(getattr(wrapped, "__self__", None), str)

    def call(__self, __context: Any, __obj: Any, *args: Any, **kwargs: Any) -> Any:
        """A macro's output is template text whose expressions were each finalized already: it
        may span lines (it is a :class:`SafeText`)."""
        if not __self.is_safe_callable(__obj):
            raise SecurityError(f"a template may not call {_callable_name(__obj)}")
        result = super().call(__context, __obj, *args, **kwargs)
        if isinstance(__obj, Macro) and isinstance(result, str):
            return SafeText(result)
        return result


def _callable_name(obj: Any) -> str:
    owner = getattr(obj, "__self__", None)
    name = getattr(obj, "__name__", type(obj).__name__)
    return f"{type(owner).__name__}.{name}" if owner is not None else str(name)


def make_environment(folder: Path, filters: Mapping[str, Callable[..., Any]]) -> PostSandbox:
    """The environment for one post's template ``folder``, with the post's ``filters``."""
    env = PostSandbox(
        loader=FileSystemLoader(str(folder)),
        undefined=StrictUndefined,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        autoescape=False,
        finalize=finalize,
    )
    env.filters.update(filters)
    return env
