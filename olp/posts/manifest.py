"""A post's template folder: ``post.yaml`` (the manifest) beside its Jinja templates.

The manifest says::

    name: kuka
    vendor: kuka                      # the post class (olp.posts.<vendor>): filters, rules, checks
    description: ...                  # one line for `olp posts`
    line_ending: "\\r\\n"
    encoding: ascii                   # text that cannot be encoded is an error, never mangled
    files:                            # one entry per output file of a program (or of a part)
      - {template: program.src.j2, name: "{name}.src"}
    main_files:                       # a split program's main program (calls the parts)
      - {template: main.src.j2, name: "{name}.src"}
    limits:                           # per file; omitted or null: no limit
      max_motions_per_file: 2000      # positions
      max_instructions_per_file: null # instructions of any kind
      max_lines_per_file: null        # text lines, checked on the rendered files
    frames_in: world                  # or robot_base: the controller's reference for frames
    rows: true                        # the templates write a "rows" step (runs of linear moves)
                                      # with the post's row writer (default false: one step
                                      # per move, as a copied folder of an older post has it)
    accelerations: true               # the templates write the path accelerations the post
                                      # class can (default false: a folder copied before olp
                                      # wrote them; the post then warns where a program sets
                                      # one)
    flow: true                        # the templates write control flow and data (default
                                      # false: a folder copied before olp wrote them, which
                                      # would write every block's body unconditionally; a post
                                      # that checks it stops on a program with control flow)
    routines: true                    # the templates write the program's routines (default
                                      # false: a folder copied before olp wrote them gets each
                                      # routine's body written out at every call instead)
    module_data: true                 # the templates place declarations by scope (module
                                      # data in the data list, external names not declared);
                                      # default false: a folder copied before, which a post
                                      # that checks it refuses for a program with module data
    program_params: true              # the templates write the program's own parameters
                                      # (olp.ir.Program.params; default false: a folder copied
                                      # before would write the program without them, so the
                                      # post refuses a program that has them)
    program_returns: true             # the templates write a program that gives a result
                                      # (olp.ir.Program.returns: KRL DEFFCT ... ENDFCT; default
                                      # false: a folder copied before would write it as one
                                      # without, so the post refuses such a program)
    runtime_targets: true             # the templates write motions to run-time targets
                                      # (kind runtime_move; default false: a folder copied
                                      # before would leave them out, so the post refuses them)
    options: {...}                    # free-form: templates see them as `options`, and so does
                                      # the post class

A customer's copy of a bundled folder (another header, other I/O calls) needs no Python: its
manifest names the bundled post class whose rules it keeps (``vendor: kuka``).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from olp.errors import PostError
from olp.transforms.limits import LIMIT_KEYS, SplitLimits

FRAMES_IN = ("world", "robot_base")
"""What frame poses are written relative to: the station's world (the controller's world frame
must then be the station's) or the robot's controller base (``robot.base @
robot.controller_base``; a controller whose world is its robot base, as delivered)."""


@dataclass(frozen=True, slots=True)
class PostManifest:
    """A parsed ``post.yaml``."""

    name: str
    vendor: str
    folder: Path
    files: tuple[tuple[str, str], ...]
    description: str = ""
    line_ending: str = "\n"
    encoding: str = "ascii"
    options: Mapping[str, Any] = field(default_factory=dict)
    main_files: tuple[tuple[str, str], ...] = ()
    limits: SplitLimits = field(default_factory=SplitLimits)
    frames_in: str = "world"
    rows: bool = False
    accelerations: bool = False
    flow: bool = False
    routines: bool = False
    module_data: bool = False
    runtime_targets: bool = False
    program_params: bool = False
    program_returns: bool = False


def load_manifest(folder: Path) -> PostManifest:
    """Read and check ``folder/post.yaml``."""
    from olp.yamlsafe import read_yaml

    path = folder / "post.yaml"
    raw = read_yaml(path, PostError).value
    if not isinstance(raw, dict) or not isinstance(raw.get("files"), list):
        raise PostError(f"{path}: expected a mapping with a 'files' list")
    limits = _limits(raw.get("limits"), path)
    main_files = _file_entries(raw.get("main_files") or [], folder, path)
    if limits.active and not main_files:
        raise PostError(f"{path}: 'limits' need 'main_files' (the main program of the parts)")
    frames_in = str(raw.get("frames_in", "world"))
    if frames_in not in FRAMES_IN:
        raise PostError(f"{path}: frames_in must be one of {', '.join(FRAMES_IN)}")
    keys = (
        "rows",
        "accelerations",
        "flow",
        "module_data",
        "routines",
        "runtime_targets",
        "program_params",
        "program_returns",
    )
    flags = dict(zip(keys, (_flag(raw, key, path) for key in keys), strict=True))
    return PostManifest(
        name=str(raw.get("name", folder.name)),
        vendor=str(raw.get("vendor", "")),
        folder=folder,
        files=_file_entries(raw["files"], folder, path),
        description=str(raw.get("description", "")),
        line_ending=str(raw.get("line_ending", "\n")),
        encoding=str(raw.get("encoding", "ascii")),
        options=dict(raw.get("options") or {}),
        main_files=main_files,
        limits=limits,
        frames_in=frames_in,
        **flags,
    )


def _flag(raw: Mapping[str, Any], key: str, path: Path) -> bool:
    value = raw.get(key, False)
    if not isinstance(value, bool):
        raise PostError(f"{path}: {key} must be true or false, got {value!r}")
    return value


def _file_entries(entries: Any, folder: Path, path: Path) -> tuple[tuple[str, str], ...]:
    if not isinstance(entries, list):
        raise PostError(f"{path}: expected a list of files, got {entries!r}")
    files = []
    for entry in entries:
        if not isinstance(entry, dict) or "template" not in entry or "name" not in entry:
            raise PostError(f"{path}: each file needs 'template' and 'name', got {entry!r}")
        template, pattern = str(entry["template"]), str(entry["name"])
        if ".." in Path(template).parts or Path(template).is_absolute():
            raise PostError(f"{path}: template {template!r} must lie inside {folder}")
        if not (folder / template).is_file():
            raise PostError(f"{path}: template {template!r} not found in {folder}")
        if _NAME_PATTERN.fullmatch(pattern) is None:
            raise PostError(
                f"{path}: file name {pattern!r} must be a plain file name holding {{name}} "
                "once (e.g. '{name}.src')"
            )
        files.append((template, pattern))
    return tuple(files)


_NAME_PATTERN = re.compile(r"[A-Za-z0-9_.+-]*\{name\}[A-Za-z0-9_.+-]*")


def _limits(raw: Any, path: Path) -> SplitLimits:
    if raw is None:
        return SplitLimits()
    if not isinstance(raw, dict) or set(raw) - set(LIMIT_KEYS):
        raise PostError(f"{path}: 'limits' takes only {', '.join(LIMIT_KEYS)}, got {raw!r}")
    try:
        return SplitLimits(
            raw.get("max_motions_per_file"),
            raw.get("max_instructions_per_file"),
            raw.get("max_lines_per_file"),
        )
    except ValueError as exc:
        raise PostError(f"{path}: limits: {exc}") from exc
