"""``robodk.robofileio`` for programs olp runs: RoboDK's file helpers (same names and returns).

Source: the RoboDK API for Python, ``robodk/robofileio.py``: ``getFileName`` is the name
without folder and extension, ``getBaseName`` with the extension, ``getFileDir`` the folder;
``LoadList`` reads a CSV into a list of rows, each value a float where it parses as one, else
the text. FTP transfers need a live controller: they raise, naming the call.
"""

from __future__ import annotations

import csv
import os
from typing import Any

from olp.compat.robodk.robomath import Mat


def getFileDir(filepath: str) -> str:
    """The folder of a file path."""
    return os.path.dirname(filepath)


def getBaseName(filepath: str) -> str:
    """The file name with its extension."""
    return os.path.basename(filepath)


def getFileName(filepath: str) -> str:
    """The file name without folder and extension."""
    return os.path.splitext(os.path.basename(filepath))[0]


def FileExists(file: str) -> bool:
    return os.path.exists(file)


def DirExists(folder: str) -> bool:
    return os.path.isdir(folder)


def _number(text: str) -> float | str:
    try:
        return float(text)
    except ValueError:
        return text


def LoadList(strfile: str, separator: str = ",", codec: str = "utf-8") -> list[list[Any]]:
    """The rows of a CSV/TXT file: each value a float where it parses as one, else its text."""
    with open(strfile, encoding=codec, newline="") as file:
        return [[_number(v) for v in row] for row in csv.reader(file, delimiter=separator)]


def SaveList(list_variable: Any, strfile: str, separator: str = ",") -> None:
    """Write a list of rows (or a list of numbers, one per line) as CSV."""
    rows = [r if isinstance(r, list | tuple) else [r] for r in list_variable]
    with open(strfile, "w", encoding="utf-8", newline="") as file:
        csv.writer(file, delimiter=separator).writerows(rows)


def LoadMat(strfile: str, separator: str = ",") -> Mat:
    """The CSV's numbers as a :class:`~olp.compat.robodk.robomath.Mat` (one row per line)."""
    return Mat(LoadList(strfile, separator))


def _offline(call: str) -> Any:
    from olp.dsl import DslError

    raise DslError(f"{call}: olp runs offline and transfers nothing to a controller")


def UploadFTP(*args: Any, **kwargs: Any) -> Any:
    return _offline("UploadFTP")


def UploadFileFTP(*args: Any, **kwargs: Any) -> Any:
    return _offline("UploadFileFTP")


def UploadDirFTP(*args: Any, **kwargs: Any) -> Any:
    return _offline("UploadDirFTP")


__all__ = sorted(
    n
    for n in globals()
    if not n.startswith("_") and n not in {"annotations", "csv", "os", "Any", "Mat"}
)
