"""``robodk`` for programs olp runs (see :mod:`olp.compat`).

``from robodk import *`` is the old single-module toolbox (matrices, poses, file and dialog
helpers): this package re-exports :mod:`~olp.compat.robodk.robomath`,
:mod:`~olp.compat.robodk.robofileio` and :mod:`~olp.compat.robodk.robodialogs`; the newer
``robodk.robolink`` / ``robodk.robomath`` paths are its submodules.
"""

from __future__ import annotations

from olp.compat.robodk.robodialogs import *  # noqa: F403
from olp.compat.robodk.robofileio import *  # noqa: F403
from olp.compat.robodk.robomath import *  # noqa: F403
