"""The liquid's height over the pourer's crest as a smooth function of the particle positions.

The height of the top particle over the crest jumps by a large part of a particle spacing whenever another particle
becomes the highest one there, and the constant-flow law turns every jump into a tilt increment. Instead the head is
read from the liquid's volume over the crest level, through a cubic B-spline colour field of the particles: particle
i (spacing dx, volume dx^dim) stands for the liquid fraction

    phi_i(x, y, z) = (dx / w)^(dim - 1) B((x - x_i) / w) [B((y - y_i) / w)] B((z - z_i) / dx),

B the cubic B-spline (support [-2, 2], unit integral), w = WINDOW_WIDTH dx its width across (dim = 2: the pour
plane x-z; dim = 3 adds y). The volume over the crest level z_c per unit width and depth, at the window's centre
(x_w, y_w), is the integral of sum_i phi_i over z > z_c:

    m = dx (dx / w)^(dim - 1) sum_i B((x_i - x_w) / w) [B((y_i - y_w) / w)] C((z_i - z_c) / dx),

C the B-spline's integral (the particle's share above z_c, from 0 at 2 dx below it to 1 at 2 dx above). m is twice
continuously differentiable in every particle position: a particle entering, leaving or overtaking another changes
it gradually. Liquid flows over the crest at about sqrt(g h_q) (0.4 m/s at 15 mm), across a spacing every 12 ms,
and that passage is noise in the head at tens of Hz. A window two spacings wide (support +-4 dx) averages over
twice the particles of one a spacing wide and passes less of their passage (the B-spline's spectrum falls as sinc^4
of its width). Its centre lies WINDOW_OFFSET widths upstream of the crest, x_w = x_c - w, where the liquid still
stands at the level that drives the flow over the crest (weir heads are read upstream of the crest); the liquid
falling past the crest lies below the crest level and does not count.

Calibration: a continuous liquid at rest whose level stands u (m) over the crest gives m = dx G(u / dx), G the
second integral of B (G(v) = 0 for v <= -2, G(v) = v for v >= 2, G'' = B). So h_q = dx G^-1(m / dx) reads the
level itself: negative while it is below the crest, positive once liquid stands over it. A particle lattice (dx
apart, top layer u - dx/2 over the crest, any phase in x) gives m = u exactly from u = 1.5 dx on, because the
B-spline translated by its knot spacing sums to one (B(s / 2) / 2 by half its width too); from u = 2 dx on h_q = u,
the top particle plus half a spacing, as the top-particle reading of a lattice (from 1.5 to 2 dx h_q lies below u by
at most 3e-4 dx).
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

REACH = wp.constant(2.0)  # spacings: the B-spline's half support, how far below the crest level a particle counts
WINDOW_WIDTH = 2.0  # spacings: the horizontal B-spline's width w (its support is +-2 w)
WINDOW_OFFSET = 1.0  # widths: the window's centre lies this far upstream of the crest (toward -x in the world)
NEWTON_ITERATIONS = 30  # G is convex and increasing: Newton from above converges monotonically
NEWTON_TOLERANCE = 1e-12  # spacings
LOWEST_PIECE = 1.0 / 120.0  # G(-1): below it G(v) = (v + 2)^5 / 120, inverted in closed form


@wp.func
def bspline(s: float) -> float:
    """Cubic B-spline B(s) (unit spacing, unit integral, support [-2, 2])."""
    a = wp.abs(s)
    if a >= 2.0:
        return 0.0
    if a >= 1.0:
        return (2.0 - a) * (2.0 - a) * (2.0 - a) / 6.0
    return 2.0 / 3.0 - a * a + 0.5 * a * a * a


@wp.func
def bspline_share_above(s: float) -> float:
    """C(s) = integral of B from -inf to s: the share of a particle s spacings above a level that lies above it."""
    if s <= -2.0:
        return 0.0
    if s >= 2.0:
        return 1.0
    if s <= -1.0:
        return (2.0 + s) * (2.0 + s) * (2.0 + s) * (2.0 + s) / 24.0
    if s >= 1.0:
        return 1.0 - (2.0 - s) * (2.0 - s) * (2.0 - s) * (2.0 - s) / 24.0
    a = wp.abs(s)
    half = 2.0 * a / 3.0 - a * a * a / 3.0 + a * a * a * a / 8.0  # integral of B from 0 to |s|
    if s < 0.0:
        return 0.5 - half
    return 0.5 + half


@wp.kernel
def sum_crest_head(
    # Model
    windows: wp.array(dtype=wp.vec3),
    dx: float,
    width: float,
    dim: int,
    n: int,
    chunk: int,
    # State in
    x: wp.array(dtype=wp.vec3),
    active: wp.array(dtype=wp.int32),
    # Out
    sums: wp.array(dtype=float),
):
    """Per chunk of ``chunk`` consecutive particles, in order: sum of B(sx) [B(sy)] C(sz) (module docstring; window
    = world (x_w, y_w, z_c) = ``windows[0]``, an array of one, written before each measurement, so that a captured
    graph of the launch reads the current one; its width w = ``width``; m = dx (dx / w)^(dim - 1) times the total)."""
    k = wp.tid()
    window = windows[0]
    total = float(0.0)
    for i in range(k * chunk, wp.min((k + 1) * chunk, n)):
        if active[i] == 0:
            continue
        d = x[i] - window
        sx = d[0] / width
        sz = d[2] / dx
        if sz <= -REACH or wp.abs(sx) >= REACH:
            continue
        w = bspline(sx) * bspline_share_above(sz)
        if dim == 3:
            w *= bspline(d[1] / width)
        total += w
    sums[k] = total


def head_window(crest: np.ndarray, spacing: float) -> np.ndarray:
    """World point (m) of the window's centre: :data:`WINDOW_OFFSET` windows upstream of the crest in x, the crest's
    y and z."""
    return np.array([crest[0] - WINDOW_OFFSET * WINDOW_WIDTH * spacing, crest[1], crest[2]])


def volume_over_crest(chunk_sums: np.ndarray, spacing: float, dim: int) -> float:
    """m (m): the liquid's volume over the crest per unit width and depth, from :func:`sum_crest_head`'s chunk sums
    (added in their order)."""
    return spacing * WINDOW_WIDTH ** (1 - dim) * float(np.asarray(chunk_sums, dtype=np.float64).sum())


def level_share(v: float) -> float:
    """G(v): the volume (in spacings) over the crest of a resting liquid standing v spacings over it (module
    docstring): the B-spline's second integral, written with truncated powers."""
    return sum((-1) ** k * math.comb(4, k) * max(v + 2.0 - k, 0.0) ** 5 for k in range(5)) / 120.0 if v < REACH else v


def level_share_slope(v: float) -> float:
    """G'(v) = C(v), the B-spline's integral (truncated powers)."""
    return sum((-1) ** k * math.comb(4, k) * max(v + 2.0 - k, 0.0) ** 4 for k in range(5)) / 24.0 if v < REACH else 1.0


def head_from_volume(volume: float, spacing: float) -> float:
    """h_q (m) of the liquid volume ``volume`` (m, per unit width and depth) over the crest: dx G^-1(volume / dx);
    needs volume > 0. On G's lowest piece in closed form; above it G(v) >= v and G' >= 1/24, so Newton's method
    starts at v = volume / dx, on or above the root."""
    target = volume / spacing
    if target <= LOWEST_PIECE:
        return ((120.0 * target) ** 0.2 - 2.0) * spacing
    v = target
    for _ in range(NEWTON_ITERATIONS):
        step = (level_share(v) - target) / level_share_slope(v)
        v -= step
        if step <= NEWTON_TOLERANCE:
            break
    return v * spacing
