"""Sampling of straight TCP segments: counts before allocation, the cap, the samples."""

from __future__ import annotations

import numpy as np
import pytest

from olp.geometry import rotz, transl
from olp.passes.sampling import MAX_SAMPLES, TooManySamples, sample_segments, segment_counts


def test_counts_follow_length_and_angle() -> None:
    start = np.eye(4)
    targets = np.stack(
        [
            transl(0.012, 0, 0),
            transl(0.012, 0, 0) @ rotz(np.radians(7)),
            transl(0.012, 0, 0) @ rotz(np.radians(7)),
        ]
    )
    counts = segment_counts(start, targets, 0.005, np.radians(2))
    assert counts.tolist() == [3.0, 4.0, 1.0]
    samples = sample_segments(start, targets, 0.005, np.radians(2))
    assert samples.ends.tolist() == [2, 6, 7]
    assert np.allclose(samples.poses[2], targets[0]) and np.allclose(samples.poses[6], targets[1])


@pytest.mark.parametrize("metres", [1e5, 1e40, 1e300, 1e308])
def test_a_far_target_is_counted_not_sampled(metres: float) -> None:
    """1e40 m made a negative int64 count ("negative dimensions"), 1e5 m 2e7 samples (7 GB)."""
    targets = transl(metres, 0, 0)[None]
    count = float(segment_counts(np.eye(4), targets, 0.005, np.radians(2))[0])
    assert count > MAX_SAMPLES
    with pytest.raises(TooManySamples):
        sample_segments(np.eye(4), targets, 0.005, np.radians(2))


def test_the_cap_is_inclusive() -> None:
    targets = transl(0.005 * MAX_SAMPLES - 1e-9, 0, 0)[None]
    assert sample_segments(np.eye(4), targets, 0.005, np.radians(2)).poses.shape[0] == MAX_SAMPLES
