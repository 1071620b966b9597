"""Free-surface detection (warp functions) and the free-liquid rule built on it.

Marrone, Colagrossi, Le Touzé & Graziani (2010), "Fast free-surface detection and level-set function definition in
SPH solvers", J. Comput. Phys. 229: the renormalisation matrix of particle i,

    M_i = -sum_j (x_i - x_j) (x) grad_i W_ij V_j        (liquid and wall neighbours, V_j their volumes),

is the identity inside a full kernel support (the first-order consistency of the gradient) and loses the directions
in which the support is empty. Its smallest eigenvalue lambda_i is the free-surface indicator: about 1 inside the
liquid, about 0.5 at a flat free surface, 0 for an isolated particle; Marrone et al. take lambda <= 0.2 as certainly
at the surface and lambda <= 0.75 as the region their scan test examines. For a square (cubic) lattice of spacing
dx and Wendland C2 at h = 1.5 dx: interior 0.997 (2-D), 1.001 (3-D); top row of a flat surface 0.499 (2-D), 0.500
(3-D); second row 0.842 (2-D), 0.859 (3-D). For radial kernels grad_i W_ij is parallel to x_i - x_j, so M_i is
symmetric and its eigenvalues are real: closed form in 2-D (the x-z block), the trigonometric formula for a
symmetric 3x3 matrix in 3-D (Smith 1961, "Eigenvalues of a symmetric 3 x 3 matrix", Commun. ACM 4; warp has no
eigen-solver).

The volumes are V_j = m_j / rho0 (wall particles: their own volume V_b): each particle's own mass, at rest density,
so the indicator reads the particles' packing and does not depend on a density the same pass is still writing.

The free-liquid rule (``FluidConfig.free_liquid_rule``) decides where a particle may become free: outside every
vessel's inner volume ('outside_vessels'), or at the free surface, lambda below ``free_surface_threshold``
('free_surface'), wherever the particle is: the decision needs nothing of the scene. Either way the particle must
also have separated (summation density below rho0) and becomes bound again when packed
(``cosim.fluid.sph_common.next_free_state``).
"""

from __future__ import annotations

import math

import warp as wp

from cosim.fluid.boundary import VesselGeometry, VesselMotion
from cosim.fluid.config import FluidConfig, FreeLiquidRule
from cosim.fluid.params import SPHParams
from cosim.fluid.sph_common import inside_any_vessel

# The rule as the kernels take it (an int argument)
FREE_LIQUID_OFF = wp.constant(0)  # every particle stays bound
FREE_OUTSIDE_VESSELS = wp.constant(1)
FREE_AT_SURFACE = wp.constant(2)

TWO_THIRDS_PI = wp.constant(2.0 * math.pi / 3.0)


def free_liquid_mode(cfg: FluidConfig) -> int:
    """The rule of ``cfg`` as the kernels' int: off, outside every vessel, or at the free surface."""
    if not cfg.free_liquid:
        return int(FREE_LIQUID_OFF)
    if cfg.free_liquid_rule_in_effect is FreeLiquidRule.FREE_SURFACE:
        return int(FREE_AT_SURFACE)
    return int(FREE_OUTSIDE_VESSELS)


@wp.func
def renormalisation_term(volume: float, r: wp.vec3, gw: wp.vec3) -> wp.mat33:
    """One neighbour's share -(x_i - x_j) (x) grad_i W_ij V_j of the renormalisation matrix, for r = x_i - x_j (m),
    gw = grad_i W_ij (1/m^(dim+1)) and the neighbour's volume (m^dim): dimensionless."""
    return volume * wp.outer(-r, gw)


@wp.func
def smallest_eigenvalue_2d(a: float, b: float, c: float) -> float:
    """Smallest eigenvalue of the symmetric matrix [[a, b], [b, c]]: (a + c) / 2 - sqrt(((a - c) / 2)^2 + b^2)."""
    half_gap = 0.5 * (a - c)
    return 0.5 * (a + c) - wp.sqrt(half_gap * half_gap + b * b)


@wp.func
def smallest_eigenvalue_3d(m: wp.mat33) -> float:
    """Smallest eigenvalue of the symmetric 3x3 matrix m (Smith 1961): with q = tr(m) / 3, p = sqrt(tr((m - q I)^2)
    / 6) and B = (m - q I) / p, the eigenvalues are q + 2 p cos(phi + 2 pi k / 3), phi = acos(det(B) / 2) / 3; the
    smallest is k = 1. A diagonal matrix: its smallest diagonal entry."""
    off = m[0, 1] * m[0, 1] + m[0, 2] * m[0, 2] + m[1, 2] * m[1, 2]
    if off == 0.0:
        return wp.min(m[0, 0], wp.min(m[1, 1], m[2, 2]))
    q = (m[0, 0] + m[1, 1] + m[2, 2]) / 3.0
    d0 = m[0, 0] - q
    d1 = m[1, 1] - q
    d2 = m[2, 2] - q
    p = wp.sqrt((d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * off) / 6.0)
    b = (m - q * wp.identity(n=3, dtype=float)) / p
    phi = wp.acos(wp.clamp(0.5 * wp.determinant(b), -1.0, 1.0)) / 3.0
    return q + 2.0 * p * wp.cos(phi + TWO_THIRDS_PI)


@wp.func
def surface_indicator(dim: int, m: wp.mat33) -> float:
    """Marrone et al.'s lambda: the smallest eigenvalue of the renormalisation matrix m (in 2-D of its x-z block,
    the pour plane)."""
    if dim == 2:
        return smallest_eigenvalue_2d(m[0, 0], m[0, 2], m[2, 2])
    return smallest_eigenvalue_3d(m)


@wp.func
def exposed_liquid(
    prm: SPHParams,
    vessels: wp.array(dtype=VesselGeometry),
    motions: wp.array(dtype=VesselMotion),
    mode: int,
    x: wp.vec3,
    indicator: float,
    threshold: float,
) -> bool:
    """Whether the particle at ``x`` is where the rule ``mode`` lets liquid be free: outside every vessel's inner
    volume (:data:`FREE_OUTSIDE_VESSELS`) or at the free surface, its indicator below ``threshold``
    (:data:`FREE_AT_SURFACE`)."""
    if mode == FREE_AT_SURFACE:
        return indicator < threshold
    return not inside_any_vessel(prm, vessels, motions, x)
