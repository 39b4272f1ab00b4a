"""Vendor conventions, one module per brand. Frontends and posts both use them.

``KNOWN`` lists the brands; :func:`flange_in_tool0` gives each brand's flange frame in the
kinematic model's tool0 frame (Z out of the flange, the ROS-Industrial convention).
"""

from __future__ import annotations

import importlib

import numpy as np
from numpy.typing import NDArray

KNOWN = ("kuka", "abb", "fanuc", "ur")


def flange_in_tool0(vendor: str) -> NDArray[np.float64]:
    """The vendor's flange frame in the model's tool0 frame; identity unless the module says."""
    if vendor not in KNOWN:
        raise KeyError(f"unknown vendor {vendor!r}")
    try:
        module = importlib.import_module(f"olp.vendors.{vendor}")
    except ModuleNotFoundError:
        return np.eye(4)
    return np.array(getattr(module, "FLANGE_IN_TOOL0", np.eye(4)), dtype=np.float64)
