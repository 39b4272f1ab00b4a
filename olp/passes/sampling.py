"""Sampling of Cartesian paths: many straight TCP segments interpolated at once.

A chain of linear moves is M segments, each from the previous TCP pose to the next target.
Each segment gets ``n_k = max(ceil(length / step_m), ceil(angle / step_rad), 1)`` samples at
fractions ``1/n_k, 2/n_k, ..., 1`` (the segment's start is the previous segment's end), linear in
position and constant-axis in orientation, all in one vectorised pass.

The count is bounded before anything is allocated: a call never makes more than
:data:`MAX_SAMPLES` samples (a target 1e40 m away would need 2e42 of them; its count is a float
the caller compares first, see :func:`segment_counts`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from olp.geometry import pose_distance, pose_from, rotation_exp, rotation_log

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

MAX_SAMPLES = 1 << 16
"""Most samples of one :func:`sample_segments` call: ~65,000, i.e. a 330 m TCP line at 5 mm
or 360 turns at 2° (no reachable move of a bundled arm with a tool under 100 m comes near),
at ~1 kB of temporaries per sample downstream (IK of 8 branches, unwrapping)."""


class TooManySamples(ValueError):
    """Segments that need more than :data:`MAX_SAMPLES` samples (callers check
    :func:`segment_counts` first; this guards memory if one does not)."""


@dataclass(frozen=True, slots=True, eq=False)
class SegmentSamples:
    """Samples of M chained segments.

    ``poses``: (S, 4, 4) sampled poses; ``segment``: (S,) segment index of each sample;
    ``ends``: (M,) index of each segment's last sample (its target); ``fractions``: (S,)
    position of each sample within its segment, in (0, 1]; ``lengths`` (M,) metres and
    ``angles`` (M,) radians of the segments.
    """

    poses: FloatArray
    segment: IntArray
    ends: IntArray
    fractions: FloatArray
    lengths: FloatArray
    angles: FloatArray


def segment_counts(
    start: FloatArray, targets: FloatArray, step_m: float, step_rad: float
) -> FloatArray:
    """Samples (M,) each segment ``start -> targets[0] -> ...`` needs, as floats:
    ``max(ceil(length / step_m), ceil(angle / step_rad), 1)``; huge (or inf) for absurd
    lengths, so compare before converting to integers. ``start`` (4, 4), ``targets``
    (M, 4, 4)."""
    previous = np.concatenate([start[None], targets[:-1]], axis=0)
    with np.errstate(over="ignore", invalid="ignore"):
        return _counts(*pose_distance(previous, targets), step_m, step_rad)


def _counts(lengths: FloatArray, angles: FloatArray, step_m: float, step_rad: float) -> FloatArray:
    with np.errstate(over="ignore", invalid="ignore"):
        counts: FloatArray = np.maximum(
            np.maximum(np.ceil(lengths / step_m), np.ceil(angles / step_rad)), 1.0
        )
    return counts


def sample_segments(
    start: FloatArray, targets: FloatArray, step_m: float, step_rad: float
) -> SegmentSamples:
    """Sample the straight segments ``start -> targets[0] -> targets[1] -> ...``.

    Parameters
    ----------
    start : (4, 4) pose where the chain starts.
    targets : (M, 4, 4) segment end poses.
    step_m, step_rad : largest travel (m) and rotation (rad) between samples.

    Raises :class:`TooManySamples` if they need more than :data:`MAX_SAMPLES` samples.
    """
    previous = np.concatenate([start[None], targets[:-1]], axis=0)
    with np.errstate(over="ignore", invalid="ignore"):
        lengths, angles = pose_distance(previous, targets)
    wanted = _counts(lengths, angles, step_m, step_rad)
    if not float(np.sum(wanted)) <= MAX_SAMPLES:
        raise TooManySamples(f"{float(np.sum(wanted)):.4g} samples (at most {MAX_SAMPLES})")
    counts = wanted.astype(np.int64)
    segment = np.repeat(np.arange(targets.shape[0], dtype=np.int64), counts)
    ends = np.cumsum(counts) - 1
    within = np.arange(segment.size, dtype=np.int64) - np.repeat(ends - counts + 1, counts) + 1
    fractions = within / np.repeat(counts, counts)
    prev_r, prev_p = previous[:, :3, :3], previous[:, :3, 3]
    delta = rotation_log(np.swapaxes(prev_r, -1, -2) @ targets[:, :3, :3])
    rot = prev_r[segment] @ rotation_exp(fractions[:, None] * delta[segment])
    pos = prev_p[segment] + fractions[:, None] * (targets[:, :3, 3] - prev_p)[segment]
    return SegmentSamples(pose_from(rot, pos), segment, ends, fractions, lengths, angles)
