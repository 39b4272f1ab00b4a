"""The geometry of a chain of path moves: the resolved samples joined, blends cut into the
corners, and the joint path q(s) as a cubic spline (see the package docstring)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from olp.passes.timing.tcp import tcp_positions
from olp.station.model import Robot

if TYPE_CHECKING:
    from scipy.interpolate import PPoly


FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class ChainGeometry:
    """The joint path of a chain of path moves, corners rounded.

    ``s`` (S,): the path parameter at the samples, joint-space chord length in rad;
    ``q`` (S, dof): joint samples; ``boundaries`` (M+1,): ``s`` at the chain's start, at each
    instruction boundary (blend midpoints) and at its end; ``lengths`` (M,): TCP travel per
    instruction, m.
    """

    s: FloatArray
    q: FloatArray
    boundaries: FloatArray
    lengths: FloatArray


@dataclass(frozen=True, slots=True, eq=False)
class _Samples:
    """The samples of M moves end to end: ``q`` (S, dof) rad; ``arc`` (S,) m of TCP travel
    from each move's first sample; ``first`` and ``sizes`` (M,): each move's first row and
    sample count; ``move`` (S,): each row's move."""

    q: FloatArray
    arc: FloatArray
    first: NDArray[np.int64]
    sizes: NDArray[np.int64]
    move: NDArray[np.int64]

    @classmethod
    def of(
        cls, q: FloatArray, sizes: NDArray[np.int64], robot: Robot, tool: FloatArray
    ) -> _Samples:
        first = np.cumsum(sizes) - sizes
        move = np.repeat(np.arange(sizes.size), sizes)
        steps = np.linalg.norm(np.diff(tcp_positions(robot, q, tool), axis=0), axis=-1)
        steps[first[1:] - 1] = 0.0  # from one move's last sample to the next one's first
        travel = np.concatenate([[0.0], np.cumsum(steps)])
        return cls(q, travel - travel[first][move], first, sizes, move)

    @property
    def lengths(self) -> FloatArray:
        """TCP travel (M,) m along each move's samples."""
        return self.arc[self.first + self.sizes - 1]

    def cut(self, which: NDArray[np.int64], at: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Joints (n, dof) at TCP travel ``at`` (n,) m along moves ``which`` (n,) (linear
        between samples), and the tangents dq/d(travel) (n, dof) rad/m there."""
        below = _count_at_most(self.move, self.arc, which, at) - self.first[which]
        lo = self.first[which]
        i = np.clip(lo + below - 1, lo, lo + self.sizes[which] - 2)
        width = np.maximum(self.arc[i + 1] - self.arc[i], 1e-15)  # repeated samples
        delta = self.q[i + 1] - self.q[i]
        return self.q[i] + ((at - self.arc[i]) / width)[:, None] * delta, delta / width[:, None]

    def spacing(self) -> FloatArray:
        """Median TCP travel (M,) m between consecutive samples of each move."""
        count = self.sizes - 1
        keep = np.ones(self.arc.size - 1, dtype=bool)
        keep[self.first[1:] - 1] = False
        values = np.diff(self.arc)[keep]
        ordered = values[np.lexsort((values, np.repeat(np.arange(count.size), count)))]
        start = np.cumsum(count) - count
        return 0.5 * (ordered[start + (count - 1) // 2] + ordered[start + count // 2])


def _count_at_most(
    groups: NDArray[np.int64], values: FloatArray, which: NDArray[np.int64], at: FloatArray
) -> NDArray[np.int64]:
    """For each query (``which[k]``, ``at[k]``), the number of entries before it: those of
    lower groups and those of group ``which[k]`` whose value is at most ``at[k]`` (``groups``
    (S,) nondecreasing, ``values`` (S,) nondecreasing within a group). A searchsorted per
    group, done by one sort of entries and queries together (entries first on ties)."""
    size = groups.size
    order = np.lexsort(
        (
            np.concatenate([np.zeros(size), np.ones(at.size)]),
            np.concatenate([values, at]),
            np.concatenate([groups, which]),
        )
    )
    is_query = order >= size
    position = np.flatnonzero(is_query)
    counts = np.empty(at.size, dtype=np.int64)
    counts[order[position] - size] = position - np.arange(position.size)
    return counts


def chain_geometry(
    paths: Sequence[FloatArray],
    robot: Robot,
    tool: FloatArray,
    blends: Sequence[float],
    blend_samples: int = 5,
) -> ChainGeometry:
    """Join the sampled joint paths (S_k, dof) of M moves, cutting each inner corner at
    ``blends[k]`` m of TCP travel on both sides and joining the cuts by a blend curve.
    Vectorised over the moves (two forward kinematics calls for the whole chain)."""
    sizes = np.array([len(path) for path in paths], dtype=np.int64)
    return joined_geometry(np.concatenate(paths), sizes, robot, tool, blends, blend_samples)


def joined_geometry(
    q: FloatArray,
    sizes: NDArray[np.int64],
    robot: Robot,
    tool: FloatArray,
    blends: Sequence[float] | FloatArray,
    blend_samples: int = 5,
) -> ChainGeometry:
    """:func:`chain_geometry` of M moves given end to end: joints ``q`` (S, dof) rad, each
    move's samples (its start included) in turn, ``sizes`` (M,) samples per move."""
    samples = _Samples.of(q, sizes, robot, tool)
    moves = np.arange(sizes.size)
    d = np.asarray(blends, dtype=np.float64)
    enter = np.concatenate([[0.0], d])
    leave = samples.lengths - np.concatenate([d, [0.0]])
    entries, exits = samples.cut(moves, enter), samples.cut(moves, leave)
    start = (exits[0][:-1], exits[1][:-1])
    end = (entries[0][1:], entries[1][1:])
    counts = _blend_counts(start[1], end[1], d, samples.spacing(), blend_samples)
    curves = _blend_curves(start, end, d, counts)
    inner = _inner(samples, enter, np.concatenate([d, [0.0]]))
    # An end without a blend is the move's own end sample, whatever its TCP travel: a move
    # that only turns the tool has none, and a cut by travel would pick a sample at random.
    last = samples.first + samples.sizes - 1
    no_entry, no_exit = enter <= 0.0, np.concatenate([d, [0.0]]) <= 0.0
    entries[0][no_entry] = samples.q[samples.first[no_entry]]
    exits[0][no_exit] = samples.q[last[no_exit]]
    q, marks = _assemble(samples, inner, entries[0], exits[0], curves, counts - 2)
    return _geometry(q, marks, robot, tool)


def _inner(samples: _Samples, enter: FloatArray, leave_blend: FloatArray) -> NDArray[np.bool_]:
    """The samples (S,) kept between each move's ends: beyond its entry blend and before its
    exit blend by TCP travel where it has those blends, else all but its first and last (a
    move without TCP travel, a pure turn of the tool, keeps its samples)."""
    own = samples.move
    index = np.arange(own.size)
    first = samples.first[own]
    last = first + samples.sizes[own] - 1
    leave = samples.lengths[own] - leave_blend[own]
    after_entry = (samples.arc > enter[own] + 1e-9) | (enter[own] <= 0.0)
    before_exit = (samples.arc < leave - 1e-9) | (leave_blend[own] <= 0.0)
    inner: NDArray[np.bool_] = (index > first) & (index < last) & after_entry & before_exit
    return inner


_BLEND_TURN_PER_SAMPLE = float(np.radians(4.0))


def _blend_counts(
    t0: FloatArray, t3: FloatArray, d: FloatArray, spacing: FloatArray, least: int
) -> NDArray[np.int64]:
    """Samples (M-1,) on each blend, odd (the midpoint is one): at least ``least``; one per 4°
    between the joint-space tangents ``t0``, ``t3`` (M-1, dof) plus 3 (the gridpoints then
    subdivide to 1°; a cubic spline through these samples follows the cubic blend curve
    closely); and no sparser than the two moves' own samples (``spacing`` (M,) m)."""
    cos = np.sum(t0 * t3, axis=-1) / np.maximum(
        np.linalg.norm(t0, axis=-1) * np.linalg.norm(t3, axis=-1), 1e-300
    )
    turn = np.ceil(np.arccos(np.clip(cos, -1.0, 1.0)) / _BLEND_TURN_PER_SAMPLE).astype(np.int64)
    space = np.minimum(spacing[:-1], spacing[1:])
    dense = np.ceil(2 * d / np.maximum(space, 1e-9)).astype(np.int64) + 1
    count = np.maximum.reduce([np.full(d.size, least, dtype=np.int64), turn + 3, dense])
    return count + 1 - count % 2


def _blend_curves(
    start: tuple[FloatArray, FloatArray],
    end: tuple[FloatArray, FloatArray],
    d: FloatArray,
    counts: NDArray[np.int64],
) -> FloatArray:
    """Inner samples (sum(counts - 2), dof) of the joint-space cubic Beziers from the cuts
    ``start`` to the cuts ``end`` (each joints and tangents (M-1, dof)): control points 2/3 of
    ``d`` along the tangents, i.e. the cubic form of the parabola whose middle control point is
    the corner."""
    (p0, t0), (p3, t3) = start, end
    p1 = p0 + ((2.0 / 3.0) * d)[:, None] * t0
    p2 = p3 - ((2.0 / 3.0) * d)[:, None] * t3
    inner = counts - 2
    owner = np.repeat(np.arange(inner.size), inner)
    j = np.arange(int(inner.sum())) - np.repeat(np.cumsum(inner) - inner, inner) + 1
    u = (j * (1.0 / (counts - 1))[owner])[:, None]  # as np.linspace(0, 1, count)[1:-1]
    v = 1.0 - u
    curve: FloatArray = (
        v**3 * p0[owner] + 3 * v**2 * u * p1[owner] + 3 * v * u**2 * p2[owner] + u**3 * p3[owner]
    )
    return curve


def _assemble(
    samples: _Samples,
    inner: NDArray[np.bool_],
    entries: FloatArray,
    exits: FloatArray,
    curves: FloatArray,
    curve_sizes: NDArray[np.int64],
) -> tuple[FloatArray, NDArray[np.int64]]:
    """The chain's rows in order — per move its entry cut, its ``inner`` samples and its exit
    cut, then the blend curve to the next move — and the marks (M+1,): the first row, each
    blend curve's middle row and the last row."""
    kept = np.bincount(samples.move[inner], minlength=samples.sizes.size)
    blocks = np.zeros(2 * samples.sizes.size - 1, dtype=np.int64)
    blocks[0::2], blocks[1::2] = kept + 2, curve_sizes
    offsets = np.cumsum(blocks) - blocks
    section, curve = offsets[0::2], offsets[1::2]
    q = np.empty((int(blocks.sum()), samples.q.shape[1]))
    q[section], q[section + kept + 1] = entries, exits
    rank = np.cumsum(inner) - 1
    move = samples.move[inner]
    q[section[move] + 1 + rank[inner] - (np.cumsum(kept) - kept)[move]] = samples.q[inner]
    owner = np.repeat(np.arange(curve_sizes.size), curve_sizes)
    within = np.arange(owner.size) - np.repeat(np.cumsum(curve_sizes) - curve_sizes, curve_sizes)
    q[curve[owner] + within] = curves
    marks = np.concatenate([[0], curve + curve_sizes // 2, [len(q) - 1]])
    return q, marks.astype(np.int64)


def _geometry(
    q: FloatArray, marks: NDArray[np.int64], robot: Robot, tool: FloatArray
) -> ChainGeometry:
    """Drop repeated samples, parameterise by joint chord length, measure TCP travel."""
    steps = np.linalg.norm(np.diff(q, axis=0), axis=-1)
    keep = np.concatenate([[True], steps > 1e-12])
    rows = np.cumsum(keep) - 1  # each old row's index among the kept ones
    q = q[keep]
    s = np.concatenate([[0.0], np.cumsum(steps[keep[1:]])])
    arc = _arc(tcp_positions(robot, q, tool))
    at = rows[marks]
    return ChainGeometry(s=s, q=q, boundaries=s[at], lengths=np.diff(arc[at]))


def _arc(positions: FloatArray) -> FloatArray:
    """Cumulative polyline length (S,) m through positions (S, 3)."""
    steps = np.linalg.norm(np.diff(positions, axis=0), axis=-1)
    return np.concatenate([[0.0], np.cumsum(steps)])


@dataclass(frozen=True, slots=True, eq=False)
class JointSpline:
    """A joint path ``q(s)``: piecewise cubic polynomials for the path and its first two
    derivatives. ``path(s, order)`` (N, dof); ``dof`` and ``path_interval`` as toppra's
    geometric paths have them (the toppra reference solver takes this path)."""

    pieces: tuple[PPoly | Pieces, PPoly | Pieces, PPoly | Pieces]

    def __call__(self, s: FloatArray, order: int = 0) -> FloatArray:
        out: FloatArray = self.pieces[order](s)
        return out

    @property
    def dof(self) -> int:
        return int(self.pieces[0].c.shape[-1])

    @property
    def path_interval(self) -> FloatArray:
        return np.asarray(self.pieces[0].x[[0, -1]], dtype=np.float64)


def joint_path(geometry: ChainGeometry) -> JointSpline:
    """The cubic spline q(s) (not-a-knot) through a chain's samples: scipy's, except through
    three samples, where it is the parabola, built here (scipy solves that case with a dense
    solver that cost up to 5 ms a call on a busy 2-core machine, ~0.1 ms for other counts)."""
    s, q = geometry.s, geometry.q
    if s.size == 3:  # without scipy, whose import costs a short program ~0.5 s
        parabola = _parabola(s, q)
        slope = parabola.derivative()
        return JointSpline((parabola, slope, slope.derivative()))
    from scipy.interpolate import CubicSpline  # scipy loads only where a chain needs it

    spline = CubicSpline(s, q)
    first = spline.derivative()
    return JointSpline((spline, first, first.derivative()))


class Pieces:
    """Piecewise polynomials as scipy's ``PPoly`` holds them (coefficients ``c`` (k, m, dof),
    highest power first, breakpoints ``x`` (m + 1,)) and evaluated in its order (powers of
    ``s - x[i]`` summed from the lowest, the end pieces extended), for the paths that need no
    spline solve."""

    def __init__(self, c: FloatArray, x: FloatArray) -> None:
        self.c, self.x = c, x

    def __call__(self, s: FloatArray) -> FloatArray:
        at = np.asarray(s, dtype=np.float64)
        i = np.clip(np.searchsorted(self.x, at, side="right") - 1, 0, self.x.size - 2)
        dx = (at - self.x[i])[..., None]
        out = np.zeros(at.shape + self.c.shape[2:])
        power = np.ones_like(dx)
        order = self.c.shape[0]
        for kp in range(order):
            out = out + self.c[order - 1 - kp][i] * power
            power = power * dx
        return out

    def derivative(self) -> Pieces:
        order = self.c.shape[0]
        factor = np.arange(order - 1, 0, -1, dtype=np.float64)[:, None, None]
        return Pieces(self.c[:-1] * factor, self.x)


def _parabola(s: FloatArray, q: FloatArray) -> Pieces:
    """The parabola through three samples (s (3,), q (3, dof)) as a piecewise cubic."""
    h = np.diff(s)
    slope = np.diff(q, axis=0) / h[:, None]
    curve = 2.0 * (slope[1] - slope[0]) / (h[0] + h[1])  # q''
    start = slope[0] - 0.5 * curve * h[0]  # q'(s0)
    rates = np.stack([start, start + curve * h[0]])
    zeros = np.zeros_like(rates)
    coefficients = np.stack([zeros, np.broadcast_to(0.5 * curve, rates.shape), rates, q[:2]])
    return Pieces(coefficients, s)
