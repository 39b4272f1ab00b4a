"""Post-processors: one class per controller language over one base, one template folder each.

* :mod:`olp.posts.base` - :class:`~olp.posts.base.Post`: shared checks, escaping, numbers,
  filters; :mod:`olp.posts.kuka`, :mod:`~olp.posts.abb`, :mod:`~olp.posts.ur`,
  :mod:`~olp.posts.fanuc` state what differs.
* :mod:`olp.posts.manifest` (``post.yaml``), :mod:`olp.posts.view` (what templates see),
  :mod:`olp.posts.render`, :mod:`olp.posts.sandbox`, :mod:`olp.posts.text`,
  :mod:`olp.posts.numbers`.

The registry: :data:`REGISTRY` maps a post name to its class (``"module:Class"``, imported on
first use); a class's templates are the bundled folder ``posts/<name>/`` unless it sets
``FOLDER``. Installed packages add posts through the entry-point group ``olp.posts``: an entry
point loads either a :class:`~olp.posts.base.Post` subclass (with ``FOLDER``) or a template
folder whose ``post.yaml`` names the class it uses (``vendor: kuka``).

A new brand is one module here, one template folder and one line in :data:`REGISTRY`.
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import TYPE_CHECKING, Any

from olp.errors import PostError, UsageError
from olp.resources import data_path

if TYPE_CHECKING:
    from olp.posts.base import Post

REGISTRY: dict[str, Any] = {
    "kuka": "olp.posts.kuka:KukaPost",
    "abb": "olp.posts.abb:AbbPost",
    "ur": "olp.posts.ur:UrPost",
    "fanuc": "olp.posts.fanuc:FanucPost",
}
"""Post name -> its class, or ``"module:Class"`` for one imported on first use."""


def post_class(name: str) -> type[Post]:
    """The class registered as ``name`` (``""``: the base :class:`~olp.posts.base.Post`)."""
    from olp.posts.base import Post

    if not name:
        return Post
    entry = REGISTRY.get(name)
    if entry is None:
        entry = _entry_point_classes().get(name)
    if entry is None:
        raise PostError(f"no post class {name!r} (known: {', '.join(sorted(REGISTRY))})")
    if isinstance(entry, str):
        module, _, attr = entry.partition(":")
        entry = getattr(importlib.import_module(module), attr)
    if not (isinstance(entry, type) and issubclass(entry, Post)):
        raise PostError(f"post {name!r} is registered as {entry!r}, not a Post class")
    return entry


def available_posts() -> dict[str, Path]:
    """Every post by name with its template folder: the registry's, then installed ones."""
    found: dict[str, Path] = {}
    for name, entry in REGISTRY.items():
        folder = getattr(entry, "FOLDER", None) if not isinstance(entry, str) else None
        found[name] = Path(folder) if folder is not None else data_path("posts", name)
    for name, value in _entry_points().items():
        folder = getattr(value, "FOLDER", value)
        if folder is not None and (Path(str(folder)) / "post.yaml").is_file():
            found.setdefault(name, Path(str(folder)))
    return dict(sorted(found.items()))


def find_post(name_or_path: str, options: dict[str, Any] | None = None) -> Post:
    """A post by name (bundled or installed) or by folder path (``./my_posts/kuka_line3``),
    ready to check and render; ``options`` override the manifest's.

    A bare name (no path separator, not starting with ``.`` or ``~``) is only ever a registered
    post: a folder of that name in the working directory never replaces it, so a cloned project
    cannot slip its own templates in for ``--post kuka``. A folder post is used only when named
    as a path.
    """
    if is_post_path(name_or_path):
        folder = Path(name_or_path).expanduser()
        if not (folder / "post.yaml").is_file():
            raise UsageError(f"post folder {name_or_path!r} has no post.yaml")
        return load_post(folder, options)
    posts = available_posts()
    if name_or_path not in posts:
        hint = None
        if (Path(name_or_path) / "post.yaml").is_file():
            hint = f"to use the folder {name_or_path!r}, name it as a path: ./{name_or_path}"
        raise UsageError(
            f"unknown post {name_or_path!r}: the posts are {', '.join(posts) or 'none'}",
            hint=hint,
        )
    return load_post(posts[name_or_path], options)


def load_post(folder: Path, options: dict[str, Any] | None = None) -> Post:
    """The post of a template folder: its manifest, and the class its ``vendor`` names."""
    import dataclasses

    from olp.posts.manifest import load_manifest

    manifest = load_manifest(folder)
    if options:
        manifest = dataclasses.replace(manifest, options={**manifest.options, **options})
    return post_class(manifest.vendor)(manifest)


def is_post_path(name_or_path: str) -> bool:
    """Whether ``--post`` names a folder (a path) rather than a registered post."""
    text = str(name_or_path)
    return "/" in text or "\\" in text or text.startswith((".", "~")) or Path(text).is_absolute()


def _entry_points() -> dict[str, Any]:
    from importlib.metadata import entry_points

    found: dict[str, Any] = {}
    for ep in entry_points(group="olp.posts"):
        try:
            found.setdefault(ep.name, ep.load())
        except Exception as exc:  # an installed package's import error: name it, do not crash
            msg = f"installed post {ep.name!r} ({ep.value}) failed to load: {exc}"
            raise PostError(msg) from exc
    return found


def _entry_point_classes() -> dict[str, Any]:
    from olp.posts.base import Post

    return {
        name: value
        for name, value in _entry_points().items()
        if isinstance(value, type) and issubclass(value, Post)
    }
