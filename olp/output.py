"""Writing what olp produces: every path checked before anything is written, an output folder
replaced as a whole, single files replaced atomically, modes from the user's umask.

Robot code is a *set* of files (a module and its data list, a main program and its parts). A
controller must never receive half of a new set beside half of an old one, so
:func:`write_folder` builds the whole set in a staging folder beside the output folder and then
swaps the two:

1. the new files are written (and flushed to disk) into ``.<out>.olp-<pid>-<random>`` in the
   output folder's parent; files already in the output folder that olp did not write (listed in
   no earlier manifest) are carried over as hard links (copies where links are impossible);
   (a file of the same name as a new one is replaced, as any build replaces its files);
2. a manifest, ``.olp-manifest.json``, records which files olp wrote;
3. the staging folder and the output folder are exchanged with one ``renameat2(RENAME_EXCHANGE)``
   call (Linux; atomic), or elsewhere with two renames (a window of microseconds in which the
   output folder is absent, never mixed);
4. the old folder is removed: parts of an earlier, larger build disappear with it.

A kill before step 3 leaves the old output untouched and a staging folder, which the next run
removes once its process is gone. Files are created with mode ``0o666`` and folders with
``0o777``, less the umask, as any other program's files (not ``0o600`` as temporary files are);
a replaced folder keeps its permission bits.

Because the output folder is replaced, it can be neither the working directory nor one of its
parents (:func:`check_output_folder`). Every path is checked before a build starts, so a bad
``--report`` path can no longer fail after the robot code was written.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import json
import os
import secrets
import shutil
import stat
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import BinaryIO

from olp.errors import UsageError

MANIFEST = ".olp-manifest.json"
"""The file in an output folder that lists the files olp wrote there."""

_STAGING = ".olp-"
"""Infix of staging names: ``.<name>.olp-<pid>-<hex>``."""


# --------------------------------------------------------------------------------------------
# Checks before anything is written


def check_output_folder(path: str | Path, option: str = "-o") -> Path:
    """Raise a UsageError unless ``path`` can become olp's output folder; returns it.

    It may exist (a folder, not a file) or not (its nearest existing ancestor must be a writable
    folder); it must not be the working directory or one of its parents, nor the file system
    root, since olp replaces it as a whole.
    """
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise UsageError(f"{option} {path}: is a file, not a folder")
    here = Path.cwd().resolve()
    target = folder.resolve()
    if target == here or target in here.parents or target == Path(target.anchor):
        raise UsageError(
            f"{option} {path}: olp replaces its output folder as a whole, so it cannot be the "
            "current folder or one of its parents",
            hint="name a folder of its own, e.g. -o out/",
        )
    _check_writable(target.parent, f"{option} {path}")
    return folder


def check_output_file(path: str | Path, option: str) -> Path:
    """Raise a UsageError unless ``path`` can be written as a file; returns it."""
    file = Path(path)
    if file.is_dir():
        raise UsageError(f"{option} {path}: is a folder; name a file")
    if file.exists() and not file.is_file():
        raise UsageError(f"{option} {path}: is not a regular file")
    _check_writable(file.parent, f"{option} {path}")
    return file


def check_distinct(paths: Iterable[tuple[str, Path | None]]) -> None:
    """Raise a UsageError when two output options name the same path."""
    seen: dict[Path, str] = {}
    for option, path in paths:
        if path is None:
            continue
        key = path.resolve()
        if key in seen:
            raise UsageError(f"{option} and {seen[key]} name the same path {path}")
        seen[key] = option


def _check_writable(folder: Path, what: str) -> None:
    existing = folder
    while not existing.exists():
        if existing.parent == existing:
            break
        existing = existing.parent
    if not existing.is_dir():
        raise UsageError(f"{what}: {existing} is not a folder")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise UsageError(f"{what}: no permission to write in {existing}")


# --------------------------------------------------------------------------------------------
# A folder of files, as one set


def write_folder(files: Mapping[str, bytes], folder: str | Path) -> list[Path]:
    """Replace olp's files in ``folder`` by ``files`` (name -> bytes) as one set; see the
    module docstring. Returns the written paths, in the order of ``files``."""
    for name in files:
        _check_name(name)
    staged = StagedFolder(folder)
    try:
        for name, data in files.items():
            staged.add(name, data)
        return staged.commit()
    finally:
        staged.discard()


def _check_name(name: str) -> None:
    if name in ("", ".", "..", MANIFEST) or "/" in name or "\\" in name:
        raise UsageError(f"output file name {name!r} is not a plain file name")


class StagedFolder:
    """A new set of output files built file by file (and each file piece by piece) in a
    staging folder beside ``folder``, then swapped in as :func:`write_folder` does.

    For output too big to hold in memory (a streamed build): :meth:`create` opens a new file
    for writing in pieces, :meth:`scratch` a hidden working file that is never part of the set;
    :meth:`commit` carries the user's own files over, writes the manifest and swaps the folders;
    :meth:`discard` (always safe to call; a no-op after :meth:`commit`) removes the staging
    folder, so that an error leaves the old output untouched and no half-written file.
    """

    def __init__(self, folder: str | Path) -> None:
        target = Path(folder)
        if target.is_symlink():
            target = target.resolve()
        self.target = target
        parent = target.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise UsageError(f"cannot create {parent}: {exc.strerror}") from exc
        _remove_stale_staging(parent, target.name)
        self.staging: Path | None = _make_staging(parent, target.name)
        self.names: list[str] = []
        self._scratch = 0

    def create(self, name: str) -> BinaryIO:
        """A new file ``name`` of the set, open for writing (flushed to disk by
        :meth:`commit`)."""
        self._claim(name)
        return self._open(name)

    def _claim(self, name: str) -> None:
        _check_name(name)
        if name in self.names:
            raise UsageError(f"output file name {name!r} is written twice")
        self.names.append(name)

    def add(self, name: str, data: bytes) -> None:
        """A new file ``name`` of the set holding ``data``, written and flushed at once."""
        self._claim(name)
        try:
            _write_new(self._folder() / name, data)
        except OSError as exc:
            raise UsageError(f"cannot write {self.target}: {exc.strerror or exc}") from exc

    def scratch(self) -> Path:
        """A fresh hidden working file in the staging folder (not part of the set); the
        caller removes it when done, or :meth:`discard` does."""
        self._scratch += 1
        path = self._folder() / f".scratch-{self._scratch}"
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        os.close(fd)
        return path

    def _folder(self) -> Path:
        if self.staging is None:
            raise UsageError(f"{self.target}: the staged output was already committed")
        return self.staging

    def _open(self, name: str) -> BinaryIO:
        try:
            fd = os.open(self._folder() / name, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except OSError as exc:
            raise UsageError(f"cannot write {self.target / name}: {exc.strerror}") from exc
        return os.fdopen(fd, "wb")

    def commit(self) -> list[Path]:
        """Swap the new set in; returns its paths in the order they were created."""
        staging, target = self._folder(), self.target
        try:
            for entry in os.listdir(staging):
                if entry.startswith(".scratch-"):
                    os.unlink(staging / entry)
            _fill(staging, target, self.names)
            _swap_in(staging, target)
        except OSError as exc:
            raise UsageError(f"cannot write {target}: {exc.strerror or exc}") from exc
        self.staging = None
        return [target / name for name in self.names]

    def discard(self) -> None:
        """Remove the staging folder and everything in it (nothing after :meth:`commit`)."""
        if self.staging is not None:
            shutil.rmtree(self.staging, ignore_errors=True)
            self.staging = None


def _fill(staging: Path, target: Path, names: Sequence[str]) -> None:
    """Complete a staging folder holding the new files ``names``: each flushed to disk, the
    user's own files of ``target`` carried over, the manifest written."""
    ours = _previous_manifest(target)
    if target.is_dir():
        os.chmod(staging, stat.S_IMODE(target.stat().st_mode))
        for entry in sorted(os.listdir(target)):
            if entry != MANIFEST and entry not in ours and entry not in names:
                _carry_over(target / entry, staging / entry)
    for name in names:
        _fsync_file(staging / name)  # pieces written by StagedFolder.create
    manifest = json.dumps({"files": sorted(names)}, indent=1) + "\n"
    _write_new(staging / MANIFEST, manifest.encode("utf-8"))
    _fsync_dir(staging)


def _fsync_file(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _previous_manifest(target: Path) -> set[str]:
    try:
        raw = json.loads((target / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return set()
    names = raw.get("files") if isinstance(raw, dict) else None
    return {n for n in names if isinstance(n, str)} if isinstance(names, list) else set()


def _carry_over(source: Path, destination: Path) -> None:
    """A file or folder of the user's, linked (or copied) into the new set unchanged."""
    if source.is_symlink():
        os.symlink(os.readlink(source), destination)
    elif source.is_dir():
        shutil.copytree(source, destination, symlinks=True, copy_function=_link_or_copy)
    else:
        _link_or_copy(str(source), str(destination))


def _link_or_copy(source: str, destination: str) -> str:
    try:
        os.link(source, destination)
    except OSError:
        shutil.copy2(source, destination)
    return destination


def _write_new(path: Path, data: bytes) -> None:
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
    with os.fdopen(fd, "wb") as handle:
        handle.write(data)
        handle.flush()
        os.fsync(handle.fileno())


def _make_staging(parent: Path, name: str) -> Path:
    for _ in range(100):
        staging = parent / f".{name}{_STAGING}{os.getpid()}-{secrets.token_hex(4)}"
        try:
            os.mkdir(staging, 0o777)
        except FileExistsError:
            continue
        except OSError as exc:
            raise UsageError(f"cannot write in {parent}: {exc.strerror}") from exc
        return staging
    raise UsageError(f"cannot create a staging folder in {parent}")


def _swap_in(staging: Path, target: Path) -> None:
    if not target.exists():
        os.rename(staging, target)
    elif _exchange(staging, target):
        shutil.rmtree(staging, ignore_errors=True)
    else:
        old = staging.with_name(staging.name + "-old")
        os.rename(target, old)
        os.rename(staging, target)
        shutil.rmtree(old, ignore_errors=True)
    _fsync_dir(target.parent)


_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically with Linux's ``renameat2(RENAME_EXCHANGE)``; False where it is
    not available (another OS, an old kernel or C library, a file system without it)."""
    libc_name = ctypes.util.find_library("c")
    if libc_name is None:
        return False
    libc = ctypes.CDLL(libc_name, use_errno=True)
    renameat2 = getattr(libc, "renameat2", None)
    if renameat2 is None:
        return False
    result = renameat2(
        _AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), ctypes.c_uint(_RENAME_EXCHANGE)
    )
    return bool(result == 0)


def _remove_stale_staging(parent: Path, name: str) -> None:
    """Remove staging folders (and files) of ``name`` left by olp processes that are gone."""
    prefix = f".{name}{_STAGING}"
    with contextlib.suppress(OSError):
        for entry in os.listdir(parent):
            if not entry.startswith(prefix):
                continue
            pid = entry[len(prefix) :].split("-", 1)[0]
            if pid.isdigit() and not _alive(int(pid)):
                path = parent / entry
                if path.is_dir() and not path.is_symlink():
                    shutil.rmtree(path, ignore_errors=True)
                else:
                    path.unlink(missing_ok=True)


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


def _fsync_dir(folder: Path) -> None:
    with contextlib.suppress(OSError):
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


# --------------------------------------------------------------------------------------------
# Single files


def write_file(path: str | Path, data: bytes) -> Path:
    """Replace the file ``path`` by ``data`` atomically (temporary file beside it, flushed, then
    renamed); mode ``0o666`` less the umask. Returns the path."""
    file = Path(path)
    parent = file.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UsageError(f"cannot create {parent}: {exc.strerror}") from exc
    _remove_stale_staging(parent, file.name)
    temp = parent / f".{file.name}{_STAGING}{os.getpid()}-{secrets.token_hex(4)}"
    try:
        _write_new(temp, data)
        os.replace(temp, file)
    except OSError as exc:
        temp.unlink(missing_ok=True)
        raise UsageError(f"cannot write {file}: {exc.strerror or exc}") from exc
    _fsync_dir(parent)
    return file
