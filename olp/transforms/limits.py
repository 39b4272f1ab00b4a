"""Per-file limits of a controller (a post's ``limits``), without the splitting machinery: the
manifest reader needs them and must stay light (no numpy for ``olp posts``)."""

from __future__ import annotations

from dataclasses import dataclass

LIMIT_KEYS = ("max_motions_per_file", "max_instructions_per_file", "max_lines_per_file")
"""The manifest keys of ``limits`` (``max_lines_per_file`` is checked by the post after
rendering, see :func:`olp.posts.render.render`)."""


@dataclass(frozen=True, slots=True)
class SplitLimits:
    """Per-file limits; None means no limit.

    ``max_motions``: motion instructions (positions) per part. ``max_instructions``: written
    instructions of any kind per part. ``max_lines``: text lines per written file (checked on
    the rendered text by :func:`olp.posts.render.render`, which splits finer until it holds).
    """

    max_motions: int | None = None
    max_instructions: int | None = None
    max_lines: int | None = None

    def __post_init__(self) -> None:
        for name in ("max_motions", "max_instructions", "max_lines"):
            value = getattr(self, name)
            if value is not None and (isinstance(value, bool) or not isinstance(value, int)):
                raise ValueError(f"SplitLimits.{name} must be an integer, got {value!r}")
            if value is not None and value < 1:
                raise ValueError(f"SplitLimits.{name} must be >= 1, got {value}")

    @property
    def active(self) -> bool:
        """Any limit set."""
        return any(v is not None for v in (self.max_motions, self.max_instructions, self.max_lines))
