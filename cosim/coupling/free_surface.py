"""The free surface of the liquid in the pourer as a smooth function of the particle positions: the line whose
angle is the slosh measurement theta1 (:class:`controllers.measurement.LiquidMeasurement`).

A line through the top particle of each surface column jumps by a large part of a spacing whenever another particle
becomes a column's highest one, and the slosh damping's PID, which differentiates theta1, turns every jump into a
tilt step. Instead each column's surface is read through the same cubic B-spline colour field as the head over the
crest (:mod:`cosim.coupling.crest_head`). In the pourer's vessel frame, particle i (spacing dx, volume dx^dim) is
spread across x as B((x - x_i) / w) / w, B the cubic B-spline (support [-2, 2], unit integral), w = WINDOW_WIDTH
dx, and over z as B((z - z_i) / dx) / dx, C its integral. Column k at x_k:

1. Its liquid's height from the volume it holds,

       M_k = (dx^dim / w) sum_i B((x_i - x_k) / w) / D(x_i)^(dim - 2),

   summed over the liquid inside the inner box; D(x) is the section's extent across the pour plane at x in 3-D (a
   box's depth, a cylinder's chord 2 sqrt(R^2 - x^2)), so that M_k is a height averaged over the depth.
2. Its surface from the volume over a level z_k = max(M_k - LAYER_SPACINGS dx, REACH dx) just under it,

       m_k = (dx^dim / w) sum_i B((x_i - x_k) / w) C((z_i - z_k) / dx) / D(x_i)^(dim - 2),
       S_k = z_k + dx G^-1(m_k / dx),

   G^-1 the crest head's map from such a volume to the level of a liquid at rest over z_k
   (:func:`cosim.coupling.crest_head.head_from_volume`). M_k alone counts the whole column's liquid at its rest
   volume: a weakly compressible liquid's acoustic modes (the first across the vessel near c0 / 2B, tens of Hz)
   carry its mass to and fro across the vessel while the surface stays, and M_k tilts with them. The pressure
   vanishes at the free surface and so does the density's departure from rest there: S_k counts only the layer
   over z_k, a few spacings deep, and follows the surface.

A plane surface z = c + m x over a liquid filling the windows gives S_k = c + m x_k exactly: B is symmetric with
unit integral, so it reproduces linear functions across x, and the level over z_k is exact by G's calibration
(z_k lies at least REACH dx over the floor, so the liquid below it fills C's ramp). A particle lattice does too
where it is level, since the B-spline of width 2 dx translated by dx sums to 2 (B(s / 2) / 2 is a partition of
unity); its Fourier transform sinc^4(f w) vanishes at the lattice's frequency 1 / dx and its harmonics. S_k is
twice continuously differentiable in every particle position: no particle overtaking another moves it by a step.

Columns: x_k = k w for k = -K..K, K = floor((B/2 - 2 w) / w), so every column's window lies within the walls (B the
inner width); nearer the walls it would miss the liquid beyond them. A column holds liquid where m_k > 0; the line
z = c + m x is fitted through those by least squares, theta1 = atan(m). Fewer than MIN_FIT_COLUMNS such columns:
nothing to fit. Where the surface bares the floor (a deep tilt), the columns at its edge read the edge smoothed
across 4 w, and the fitted line lies off the surface there.

The sums run per chunk of consecutive particles and the chunks are added in their order on the device, so the
result does not depend on the particles' order or the device, and the host reads back one number per column.
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from cosim.coupling.crest_head import REACH, WINDOW_WIDTH, bspline, bspline_share_above, head_from_volume
from cosim.coupling.pourer_frame import PourerFrame, inner_local

MIN_FIT_COLUMNS = 3  # the contract: fewer columns holding liquid than this and theta1 = tilt
# spacings: the level z_k under the surface from M_k. G is calibrated down to REACH spacings under the surface, and
# M_k departs from the surface by the liquid's mean compression times its depth: at most 1 % (a weakly compressible
# liquid's density error at c0 = 10 v_max) of a column up to the vessel's height L, half a spacing for L = 50 dx. One
# spacing more than REACH holds that with margin, and the layer counted stays thin against the column.
LAYER_SPACINGS = 3.0


def column_count(inner_width: float, spacing: float) -> int:
    """2 K + 1 columns of width w = WINDOW_WIDTH dx whose windows (+-2 w) lie within the inner width B (m); 0 where
    not even the middle one fits."""
    w = WINDOW_WIDTH * spacing
    reach = 0.5 * inner_width - float(REACH) * w
    return 2 * int(math.floor(reach / w + 1e-9)) + 1 if reach >= 0.0 else 0


def column_positions(columns: int, spacing: float) -> np.ndarray:
    """Vessel x (m) of the columns' centres: k w for k = -K..K (``columns`` = 2 K + 1)."""
    return (np.arange(columns) - (columns - 1) // 2) * WINDOW_WIDTH * spacing


@wp.func
def section_extent(f: PourerFrame, qx: float) -> float:
    """The inner section's extent (m) across the pour plane at vessel x ``qx``: a cylinder's chord, a box's depth."""
    if f.round_section == 1:
        return 2.0 * wp.sqrt(wp.max(f.half_width * f.half_width - qx * qx, 0.0))
    return 2.0 * f.half_depth


@wp.kernel
def sum_columns(
    # Model
    frames: wp.array(dtype=PourerFrame),
    width: float,
    dx: float,
    columns: int,
    n: int,
    chunk: int,
    # State in
    x: wp.array(dtype=wp.vec3),
    active: wp.array(dtype=wp.int32),
    levels: wp.array(dtype=float),
    layer: int,
    # Out
    sums: wp.array2d(dtype=float),
):
    """Per chunk of ``chunk`` consecutive particles, in order, and per column: sum over the chunk's liquid in the
    inner box of B((x_i - x_k) / w) / D(x_i)^(dim - 2) (``layer`` 0: M_k), times C((z_i - z_k) / dx) with z_k =
    ``levels[k]`` (``layer`` 1: m_k) (module docstring; w = ``width``). The pourer's frame is ``frames[0]`` (an
    array of one, written before each measurement, so that a captured graph of the launches reads the current one)."""
    k = wp.tid()
    f = frames[0]
    half = (columns - 1) // 2
    for c in range(columns):
        sums[k, c] = 0.0
    for i in range(k * chunk, wp.min((k + 1) * chunk, n)):
        if active[i] == 0:
            continue
        q = inner_local(f, x[i])
        if q[3] == 0.0:
            continue
        across = float(1.0)
        if f.dim == 3:
            across = section_extent(f, q[0])
            if across <= 0.0:
                continue
        s = q[0] / width
        first = wp.max(int(wp.ceil(s - REACH)), -half)
        last = wp.min(int(wp.floor(s + REACH)), half)
        for j in range(first, last + 1):
            share = float(1.0)
            if layer == 1:
                share = bspline_share_above((q[2] - levels[j + half]) / dx)
            sums[k, j + half] = sums[k, j + half] + bspline(s - float(j)) * share / across


@wp.kernel
def add_column_chunks(
    # State in
    sums: wp.array2d(dtype=float),
    chunks: int,
    scale: float,
    # Out
    totals: wp.array(dtype=float),
):
    """Per column: its chunk sums added in the chunks' order, times ``scale`` (dx^dim / w: M_k or m_k in m)."""
    c = wp.tid()
    total = float(0.0)
    for k in range(chunks):
        total += sums[k, c]
    totals[c] = scale * total


@wp.kernel
def layer_levels(
    # State in
    heights: wp.array(dtype=float),
    layer: float,
    lowest: float,
    # Out
    levels: wp.array(dtype=float),
):
    """z_k = max(M_k - ``layer``, ``lowest``) (m) per column."""
    c = wp.tid()
    levels[c] = wp.max(heights[c] - layer, lowest)


def column_scale(spacing: float, dim: int) -> float:
    """dx^dim / w (m^(dim - 1)): a particle's volume per window width, which turns the sums into heights."""
    return spacing**dim / (WINDOW_WIDTH * spacing)


def surface_heights(levels: np.ndarray, volumes: np.ndarray, spacing: float) -> np.ndarray:
    """S_k (m) from the levels z_k and the volumes over them m_k (m); NaN where m_k = 0 (no liquid there)."""
    return np.array([z + head_from_volume(m, spacing) if m > 0.0 else math.nan for z, m in zip(levels, volumes)])


def surface_line(heights: np.ndarray, spacing: float) -> tuple[float, float, int]:
    """(c, m, columns): the least-squares line z = c + m x (vessel frame, m) through the columns holding liquid
    (finite S_k), and their count; (0, 0, count) with fewer than MIN_FIT_COLUMNS."""
    xs = column_positions(len(heights), spacing)
    wet = np.isfinite(heights)
    columns = int(wet.sum())
    if columns < MIN_FIT_COLUMNS:
        return 0.0, 0.0, columns
    slope, c = np.polyfit(xs[wet], heights[wet], 1)
    return float(c), float(slope), columns
