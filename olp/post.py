"""The generic post-processor: load ``posts/<name>/``, build the template context, write files.

A post folder holds ``post.yaml`` (the manifest) and Jinja2 templates. The manifest says::

    name: kuka
    vendor: kuka                      # olp.vendors.<vendor> supplies filters and name rules
    description: ...
    line_ending: "\\r\\n"
    encoding: ascii                   # text that cannot be encoded is an error, never mangled
    files:                            # one entry per output file
      - {template: program.src.j2, name: "{name}.src"}
    options: {...}                    # free-form, passed to templates as `options`

Templates see ``program`` (name, source), ``steps`` (see :class:`PostStep`), ``station``,
``options`` and the vendor's filters (``olp.vendors.<vendor>.TEMPLATE_FILTERS``) plus ``num``.
Output never depends on the locale (Python's ``format`` is locale-independent) and every file is
written atomically (temporary file, then rename) only after all of them rendered.
"""

from __future__ import annotations

import importlib
import os
import tempfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from olp.errors import PostError, UsageError
from olp.geometry import inv
from olp.ir import MOTION_TYPES, CartesianTarget, Frame, JointMove, LinearMove, Tool
from olp.passes.resolve import CompiledProgram, Step
from olp.resources import data_path

FloatArray = NDArray[np.float64]


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


def available_posts() -> dict[str, Path]:
    """Bundled posts (``posts/<name>/post.yaml``) and those added by packages through the
    ``olp.posts`` entry-point group (an entry point names a folder path)."""
    found = {p.parent.name: p.parent for p in sorted(data_path("posts").glob("*/post.yaml"))}
    from importlib.metadata import entry_points

    for ep in entry_points(group="olp.posts"):
        folder = Path(str(ep.load()))
        if (folder / "post.yaml").is_file():
            found.setdefault(ep.name, folder)
    return dict(sorted(found.items()))


def find_post(name_or_path: str) -> PostManifest:
    """A post by name (bundled or entry point) or by folder path (``./my_posts/kuka_line3``)."""
    folder = Path(name_or_path)
    if not (folder / "post.yaml").is_file():
        posts = available_posts()
        if name_or_path not in posts:
            raise UsageError(
                f"unknown post {name_or_path!r}: not a folder with post.yaml, and not one of "
                f"{', '.join(posts) or 'none'}"
            )
        folder = posts[name_or_path]
    return load_manifest(folder)


def load_manifest(folder: Path) -> PostManifest:
    """Read and check ``folder/post.yaml``."""
    import yaml

    path = folder / "post.yaml"
    try:
        raw = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as exc:
        raise PostError(f"cannot read post manifest {path}: {exc}") from exc
    if not isinstance(raw, dict) or not isinstance(raw.get("files"), list):
        raise PostError(f"{path}: expected a mapping with a 'files' list")
    files = []
    for entry in raw["files"]:
        if not isinstance(entry, dict) or "template" not in entry or "name" not in entry:
            raise PostError(f"{path}: each file needs 'template' and 'name', got {entry!r}")
        if not (folder / entry["template"]).is_file():
            raise PostError(f"{path}: template {entry['template']!r} not found in {folder}")
        files.append((str(entry["template"]), str(entry["name"])))
    return PostManifest(
        name=str(raw.get("name", folder.name)),
        vendor=str(raw.get("vendor", "")),
        folder=folder,
        files=tuple(files),
        description=str(raw.get("description", "")),
        line_ending=str(raw.get("line_ending", "\n")),
        encoding=str(raw.get("encoding", "ascii")),
        options=dict(raw.get("options") or {}),
    )


# --------------------------------------------------------------------------------------------
# Template context


@dataclass(frozen=True, slots=True, eq=False)
class PostStep:
    """What a template sees for one instruction.

    For motions: ``joints`` (rad, controller convention), ``pose`` (TCP in the motion's frame,
    (4, 4) m), ``cartesian`` (the source gave a Cartesian target), and change flags that say
    where a vendor with modal state must emit an assignment (``new_tool``, ``new_frame``,
    ``new_linear_speed``, ``new_joint_speed``, ``new_zone``).
    """

    index: int
    kind: str
    source: str
    instruction: Any
    joints: FloatArray | None = None
    pose: FloatArray | None = None
    tool: Tool | None = None
    frame: Frame | None = None
    cartesian: bool = False
    new_tool: bool = False
    new_frame: bool = False
    new_linear_speed: bool = False
    new_joint_speed: bool = False
    new_zone: bool = False

    @property
    def speed(self) -> Any:
        return self.instruction.speed

    @property
    def zone(self) -> Any:
        return self.instruction.zone


def build_steps(compiled: CompiledProgram) -> list[PostStep]:
    """The template view of every compiled instruction, with modal-state change flags."""
    robot = compiled.station.robot
    out: list[PostStep] = []
    last: dict[str, Any] = {}
    for step in compiled.steps:
        ins = step.instruction
        source = ins.span.location
        if not isinstance(ins, MOTION_TYPES):
            out.append(PostStep(step.index, ins.kind, source, ins))
            continue
        if step.skipped:
            continue
        assert step.joints is not None and step.tool is not None and step.frame is not None
        pose = _pose_in_frame(step, robot.flange_poses(step.joints))
        flags = {
            "new_tool": _changed(last, "tool", step.tool),
            "new_frame": _changed(last, "frame", step.frame),
            "new_zone": _changed(last, "zone", ins.zone),
        }
        if isinstance(ins, JointMove):
            flags["new_joint_speed"] = _changed(
                last, "joint_speed", (ins.speed.joint, ins.speed.joint_acceleration)
            )
        else:
            flags["new_linear_speed"] = _changed(
                last, "linear_speed", (ins.speed.linear, ins.speed.angular)
            )
        cartesian = isinstance(ins.target, CartesianTarget)
        out.append(
            PostStep(
                step.index,
                ins.kind,
                source,
                ins,
                step.joints,
                pose,
                step.tool,
                step.frame,
                cartesian,
                **flags,
            )
        )
    return out


def _changed(last: dict[str, Any], key: str, value: Any) -> bool:
    same = key in last and _same(last[key], value)
    last[key] = value
    return not same


def _same(a: Any, b: Any) -> bool:
    if hasattr(a, "pose") and hasattr(b, "pose"):
        return bool(a.name == b.name and np.array_equal(a.pose, b.pose))
    return bool(a == b)


def _pose_in_frame(step: Step, flange: FloatArray) -> FloatArray:
    ins = step.instruction
    if isinstance(ins, JointMove | LinearMove) and isinstance(ins.target, CartesianTarget):
        return np.array(ins.target.pose)
    assert step.tool is not None and step.frame is not None
    assert step.tool.pose is not None and step.frame.pose is not None
    result: FloatArray = inv(step.frame.pose) @ flange @ step.tool.pose
    return result


# --------------------------------------------------------------------------------------------
# Rendering and writing


def num(value: float, decimals: int = 3) -> str:
    """A fixed-point number, locale-independent, never ``-0.000``."""
    text = f"{float(value):.{decimals}f}"
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]
    return text


def render(
    compiled: CompiledProgram, manifest: PostManifest, name: str | None = None
) -> dict[str, str]:
    """Render every file of the post: ``{file name: text}``. Raises PostError, writes nothing."""
    import jinja2

    vendor = _vendor_module(manifest)
    legal = getattr(vendor, "legal_name", lambda s: s)
    program_name = legal(name or compiled.program.name)
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(manifest.folder)),
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        autoescape=False,
    )
    filters: Mapping[str, Callable[..., Any]] = getattr(vendor, "TEMPLATE_FILTERS", {})
    env.filters.update({"num": num, **filters})
    context = {
        "program": {"name": program_name, "source": compiled.program.source},
        "steps": build_steps(compiled),
        "station": compiled.station,
        "options": manifest.options,
        "post": {"name": manifest.name, "vendor": manifest.vendor},
    }
    files: dict[str, str] = {}
    for template, pattern in manifest.files:
        try:
            text = env.get_template(template).render(**context)
        except jinja2.TemplateError as exc:
            where = f"{manifest.folder / template}:{getattr(exc, 'lineno', '?')}"
            raise PostError(f"{where}: template error: {exc}") from exc
        files[pattern.format(name=program_name)] = _line_endings(text, manifest.line_ending)
    return files


def _vendor_module(manifest: PostManifest) -> Any:
    if not manifest.vendor:
        return None
    try:
        return importlib.import_module(f"olp.vendors.{manifest.vendor}")
    except ModuleNotFoundError as exc:
        raise PostError(f"post {manifest.name!r} names unknown vendor {manifest.vendor!r}") from exc


def _line_endings(text: str, ending: str) -> str:
    lines = text.replace("\r\n", "\n").split("\n")
    return ending.join(line.rstrip() for line in lines)


def write_files(files: Mapping[str, str], out_dir: Path, encoding: str = "ascii") -> list[Path]:
    """Write every file atomically (temp file in ``out_dir``, then rename). All texts are encoded
    before the first file is written, so an encoding problem leaves nothing behind."""
    encoded = {}
    for fname, text in files.items():
        try:
            encoded[fname] = text.encode(encoding)
        except UnicodeEncodeError as exc:
            bad = text[exc.start : exc.end]
            raise PostError(f"{fname}: character {bad!r} cannot be written in {encoding}") from exc
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for fname, data in encoded.items():
        target = out_dir / fname
        fd, tmp = tempfile.mkstemp(prefix=f".{fname}.", dir=out_dir)
        try:
            with os.fdopen(fd, "wb") as handle:
                handle.write(data)
            os.replace(tmp, target)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        written.append(target)
    return written
