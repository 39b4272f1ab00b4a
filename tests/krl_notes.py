"""Notes of the KRL frontend that a test about something else leaves aside."""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

START_FRAMES = re.compile(r"before any \$(TOOL|BASE):")
"""The note on a module's first motion before it sets its tool (base): olp checks and writes
the flange (world), where the source ran with the controller's (tests/frontends/
test_krl_start_frames.py)."""


def own_notes(notes: Sequence[Any]) -> list[Any]:
    """``notes`` without the :data:`START_FRAMES` ones."""
    return [n for n in notes if not START_FRAMES.search(n.message)]
