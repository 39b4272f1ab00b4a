"""``robodk.robodialogs`` for programs olp runs: no window opens (olp has no GUI).

Each dialog is a no-op noted in the build output and answers as a user who accepts the
default would: ``mbox`` returns True (or ``entry``, its default text, when one is given);
``ShowMessage`` returns None; the file dialogs return the file named by ``--set OPEN_FILE=PATH``
(``SAVE_FILE`` for a save dialog), else their ``strfile`` default, else raise (a script must
not silently read nothing). Source for names and arguments: the
RoboDK API for Python, ``robodk/robodialogs.py``.
"""

from __future__ import annotations

from typing import Any

from olp.compat import note


def mbox(
    msg: str,
    b1: Any = "OK",
    b2: Any = "Cancel",
    frame: bool = True,
    t: bool = False,
    entry: Any = None,
    *args: Any,
    **kwargs: Any,
) -> Any:
    """A message box: noted, answered with the default (``entry`` if given, else True)."""
    note("mbox", f"no dialog offline; answered with the default ({entry!r} if entry else True)")
    if entry is not None and entry is not False:
        return entry
    return True


def ShowMessage(msg: str, title: str | None = None, *args: Any, **kwargs: Any) -> None:
    """A message pop-up: noted."""
    note("ShowMessage", f"no pop-up offline; the message was {str(msg)[:80]!r}")


def _file_default(call: str, key: str, path_preference: str, strfile: str) -> str:
    from olp import dsl

    given = dsl.session().param(key, "")
    chosen = str(given) if given else strfile
    if not chosen:
        raise dsl.DslError(f"{call}: olp opens no file dialog; give the file with --set {key}=PATH")
    import os

    if not os.path.isabs(chosen) and path_preference and not given:
        chosen = os.path.join(path_preference, chosen)
    note(call, f"no file dialog offline; using {chosen!r}")
    return chosen


def getOpenFileName(path_preference: str = "", strfile: str = "", *a: Any, **k: Any) -> str:
    """The file ``--set OPEN_FILE=PATH`` names, else ``strfile`` (in ``path_preference``)."""
    return _file_default("getOpenFileName", "OPEN_FILE", path_preference, strfile)


def getSaveFileName(path_preference: str = "", strfile: str = "", *a: Any, **k: Any) -> str:
    """The file ``--set SAVE_FILE=PATH`` names, else ``strfile`` (in ``path_preference``)."""
    return _file_default("getSaveFileName", "SAVE_FILE", path_preference, strfile)


getOpenFile = getOpenFileName
getSaveFile = getSaveFileName


__all__ = sorted(
    n for n in globals() if not n.startswith("_") and n not in {"annotations", "Any", "note"}
)
