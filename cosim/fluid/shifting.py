"""Particle shifting with the free-surface correction (``FluidConfig.particle_shifting`` 'fickian').

SPH particles follow the flow, which stretches some regions and packs others; shifting moves each particle a little
toward uniform spacing, down the gradient of the particle concentration C (Fick's law: Lind, Xu, Stansby & Rogers
2012, "Incompressible smoothed particle hydrodynamics for free-surface flows: a generalised diffusion-based algorithm
for stability and validations for impulsive flows and propagating waves", J. Comput. Phys. 231). The form is that
of the delta-plus-SPH model (Sun, Colagrossi, Marrone, Antuono & Zhang 2017, "The delta-plus-SPH model: simple
procedures for a further improvement of the SPH scheme", Comput. Methods Appl. Mech. Engrg. 315):

    grad C_i = sum_j (1 + R (W_ij / W(dx))^n) V_j grad_i W_ij          (liquid and wall neighbours, R = 0.2, n = 4)
    dr_i     = -A (2h)^2 (U dt / h) grad C_i

with V_j = m_j / rho0 (a wall particle: its own volume V_b), U = ``max_expected_speed`` and A =
``shifting_coefficient``: A = 1 is Sun et al.'s -CFL Ma (2h)^2 grad C with CFL = c0 dt / h and Ma = U / c0, the
same shift per unit time whatever the solver's step. The factor in R is Monaghan's tensile-instability term, which
pushes apart particles nearer than dx. Walls are counted in C, so the liquid a support away from a wall sees no
gradient toward or away from it.

At a free surface the support is cut and grad C points into the liquid, so the plain shift would carry the surface
particles out into the air. Marrone, Colagrossi, Le Touzé & Graziani (2010, "Fast free-surface detection and
level-set function definition in SPH solvers", J. Comput. Phys. 229) give the surface region: lambda_i, the smallest
eigenvalue of the renormalisation matrix M_i (``cosim.fluid.free_surface``), below 0.75; and its outward normal,

    n_i = -M_i^-1 sum_j V_j grad_i W_ij / |M_i^-1 sum_j V_j grad_i W_ij|.

As in Sun et al., a particle in the surface region (lambda_i < 0.75) is not shifted; one within the kernel support
of such a particle is shifted along the surface only, dr_i - (dr_i . n_i) n_i; every other one by dr_i. Here M_i
and n_i are summed over the liquid alone (not the walls, unlike the free-liquid rule's indicator): the liquid
touching a wall has half a support, like a free surface, so it is not shifted, and the next rows move along the
wall, up to the tilt of their own normal (docs/particle_shifting.md).

Stability: the shift is an explicit diffusion step of D = 4 A h U dt per substep. DFSPH's CFL step dt <= cfl h / U
(``cosim.fluid.time_step``) makes D <= 4 A cfl h^2 = A h^2 at cfl 0.25; WCSPH's acoustic step makes it about ten
times smaller.

The shift runs at the start of a substep, on the positions the substep's neighbour grid was built from. It moves
mass without momentum: velocities are not corrected to the new positions, and the potential energy changes by
m g dz without work (docs/particle_shifting.md reports it). Under WCSPH, whose density is each particle's own
(the continuity equation), the density and pressure are carried to the new position to first order,
f_i += dr_i . grad f_i, with the renormalised gradient (Lind et al. 2012's correction of the hydrodynamic
variables); DFSPH sums its density anew in every substep.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import warp as wp

from cosim.fluid.config import FluidConfig, ParticleShifting, PressureSolver
from cosim.fluid.free_surface import renormalisation_term, surface_indicator
from cosim.fluid.lanes import item_kernel
from cosim.fluid.neighbors import COINCIDENT_R2, Neighborhood, neighbor_cells, next_liquid_neighbor, next_wall_neighbor, reachable_cell
from cosim.fluid.params import SPHParams
from cosim.fluid.program import Recorder
from cosim.fluid.sph_common import kernel_gradient, wall_mass
from cosim.fluid.sph_kernels import kernel_values, kernel_w

if TYPE_CHECKING:
    from cosim.fluid.model import FluidModel, FluidState
    from cosim.fluid.substep import SubstepScratch

SURFACE_REGION = wp.constant(0.75)  # Marrone et al.'s lambda below which a particle is in the free-surface region
TENSILE_WEIGHT = wp.constant(0.2)  # R of the tensile term (Sun et al. 2017)
TENSILE_POWER = wp.constant(4.0)  # n of the tensile term


def shifting_on(cfg: FluidConfig) -> bool:
    """Whether ``cfg`` shifts its particles."""
    return cfg.particle_shifting is ParticleShifting.FICKIAN


def corrects_fields(cfg: FluidConfig) -> bool:
    """Whether a shifted particle's density and pressure are carried to its new position (WCSPH, whose continuity
    density is the particle's own; DFSPH sums its density anew every substep and averages its reported pressure
    over the interval)."""
    return cfg.pressure_solver is PressureSolver.WCSPH


def shift_per_second(cfg: FluidConfig) -> float:
    """m^2/s, the factor A (2h)^2 U / h = 4 A h U that, times dt (s) and grad C (1/m), is the shift (m)."""
    return 4.0 * cfg.shifting_coefficient * cfg.smoothing_length * cfg.max_expected_speed


@wp.func
def plane_block(dim: int, m: wp.mat33) -> wp.mat33:
    """``m`` with the out-of-plane row and column of the 2-D pour plane (y) replaced by the identity's, so that it
    inverts in the plane; 3-D: ``m`` itself."""
    if dim == 3:
        return m
    return wp.mat33(m[0, 0], 0.0, m[0, 2], 0.0, 1.0, 0.0, m[2, 0], 0.0, m[2, 2])


@wp.func
def concentration_gradient_term(prm: SPHParams, w_spacing: float, volume: float, r2: float, gw: wp.vec3) -> wp.vec3:
    """A neighbour's share of the concentration gradient with the tensile term (Sun et al. 2017),
    (1 + R (W(r) / W(dx))^n) V_j grad W (1/m): ``volume`` V_j (m^3, or m^2 in 2-D), ``r2`` its squared distance
    (m^2), ``gw`` grad_i W, ``w_spacing`` W(dx)."""
    ratio = kernel_w(wp.sqrt(r2), prm.inv_h, prm.sigma, prm.kernel) / w_spacing
    return (1.0 + TENSILE_WEIGHT * wp.pow(ratio, TENSILE_POWER)) * volume * gw


@item_kernel
def measure_concentration(
    # Model
    prm: SPHParams,
    b_volume: wp.array(dtype=float),
    w_spacing: float,
    correct_fields: int,
    # State in
    nb: Neighborhood,
    active: wp.array(dtype=wp.int32),
    mass: wp.array(dtype=float),
    rho: wp.array(dtype=float),
    p: wp.array(dtype=float),
    # Out
    indicator: wp.array(dtype=float),
    normal: wp.array(dtype=wp.vec3),
    grad_c: wp.array(dtype=wp.vec3),
    grad_rho: wp.array(dtype=wp.vec3),
    grad_p: wp.array(dtype=wp.vec3),
):
    """Each particle's concentration gradient grad C (1/m, with the tensile term), its indicator lambda and, where
    lambda is at least :data:`SURFACE_REGION` (M invertible), its outward normal n (else zero) and, with
    ``correct_fields``, its renormalised density and pressure gradients M^-1 sum_j (f_j - f_i) V_j grad_i W_ij
    (liquid neighbours); ``w_spacing`` is W(dx) (1/m^dim)."""
    i = wp.tid()
    if active[i] == 0:
        return
    xi = nb.x[i]
    moment = wp.mat33(0.0)
    kernel_sum_grad = wp.vec3(0.0)
    gradient = wp.vec3(0.0)
    rho_sum = wp.vec3(0.0)
    p_sum = wp.vec3(0.0)
    radius2 = prm.support * prm.support
    cells = neighbor_cells(nb.spec, xi)
    for k in range(cells.count):
        cell = reachable_cell(nb, cells, k, xi, radius2)
        if cell < 0:
            continue
        liquid_end = nb.cell_end[cell]
        j = next_liquid_neighbor(nb.x, nb.cell_start[cell], liquid_end, xi, radius2, COINCIDENT_R2)
        while j < liquid_end:
            r = xi - nb.x[j]
            r2 = wp.dot(r, r)
            volume = mass[j] / prm.rest_density
            gw = kernel_gradient(prm, r, r2)
            moment += renormalisation_term(volume, r, gw)
            kernel_sum_grad += volume * gw
            if correct_fields != 0:
                rho_sum += (rho[j] - rho[i]) * volume * gw
                p_sum += (p[j] - p[i]) * volume * gw
            gradient += concentration_gradient_term(prm, w_spacing, volume, r2, gw)
            j = next_liquid_neighbor(nb.x, j + 1, liquid_end, xi, radius2, COINCIDENT_R2)
        wall_end = nb.b_cell_end[cell]
        item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, nb.b_cell_start[cell], wall_end, xi, nb.inside[i], radius2, COINCIDENT_R2)
        while item < wall_end:
            b = nb.b_order[item]
            r = xi - nb.bx[b]
            r2 = wp.dot(r, r)
            volume = wall_mass(prm, b_volume, b) / prm.rest_density
            gradient += concentration_gradient_term(prm, w_spacing, volume, r2, kernel_gradient(prm, r, r2))
            item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, item + 1, wall_end, xi, nb.inside[i], radius2, COINCIDENT_R2)
    lam = surface_indicator(prm.dim, moment)
    n = wp.vec3(0.0)
    if lam >= SURFACE_REGION:
        inverse = wp.inverse(plane_block(prm.dim, moment))
        outward = -(inverse * kernel_sum_grad)
        length = wp.length(outward)
        if length > 0.0:
            n = outward / length
        if correct_fields != 0:
            grad_rho[i] = inverse * rho_sum
            grad_p[i] = inverse * p_sum
    indicator[i] = lam
    normal[i] = n
    grad_c[i] = gradient


@item_kernel
def compute_shift(
    # Model
    prm: SPHParams,
    per_second: float,
    # State in
    nb: Neighborhood,
    active: wp.array(dtype=wp.int32),
    dt: wp.array(dtype=float),
    indicator: wp.array(dtype=float),
    normal: wp.array(dtype=wp.vec3),
    grad_c: wp.array(dtype=wp.vec3),
    # Out
    shift: wp.array(dtype=wp.vec3),
):
    """Each particle's shift (m): none in the free-surface region, along the surface within the kernel support of
    a particle in it, else -``per_second`` dt grad C."""
    i = wp.tid()
    shift[i] = wp.vec3(0.0)
    if active[i] == 0 or indicator[i] < SURFACE_REGION:
        return
    near_surface = bool(False)
    xi = nb.x[i]
    radius2 = prm.support * prm.support
    cells = neighbor_cells(nb.spec, xi)
    for k in range(cells.count):
        cell = reachable_cell(nb, cells, k, xi, radius2)
        if cell < 0:
            continue
        liquid_end = nb.cell_end[cell]
        j = next_liquid_neighbor(nb.x, nb.cell_start[cell], liquid_end, xi, radius2, COINCIDENT_R2)
        while j < liquid_end:
            if indicator[j] < SURFACE_REGION:
                near_surface = True
            j = next_liquid_neighbor(nb.x, j + 1, liquid_end, xi, radius2, COINCIDENT_R2)
    dr = -per_second * dt[0] * grad_c[i]
    if near_surface:
        n = normal[i]
        dr = dr - wp.dot(dr, n) * n
    shift[i] = dr


@item_kernel
def apply_shift(
    correct_fields: int,
    active: wp.array(dtype=wp.int32),
    shift: wp.array(dtype=wp.vec3),
    grad_rho: wp.array(dtype=wp.vec3),
    grad_p: wp.array(dtype=wp.vec3),
    x: wp.array(dtype=wp.vec3),
    rho: wp.array(dtype=float),
    p: wp.array(dtype=float),
):
    """x += shift; with ``correct_fields`` the density and pressure carried to the new position to first order,
    f += shift . grad f."""
    i = wp.tid()
    if active[i] == 0:
        return
    dr = shift[i]
    x[i] = x[i] + dr
    if correct_fields != 0:
        rho[i] = rho[i] + wp.dot(dr, grad_rho[i])
        p[i] = p[i] + wp.dot(dr, grad_p[i])


class ShiftingScratch:
    """The shift's per-substep arrays (N,): indicator (lambda), normal, grad_c (1/m), shift (m), and grad_rho
    (kg/m^4), grad_p (Pa/m) where the fields are corrected (:func:`corrects_fields`)."""

    def __init__(self, m: FluidModel):
        d, n = m.device, m.grid.capacity
        cfg = m.config
        self.indicator = wp.zeros(n, dtype=float, device=d)
        self.normal = wp.zeros(n, dtype=wp.vec3, device=d)
        self.grad_c = wp.zeros(n, dtype=wp.vec3, device=d)
        self.shift = wp.zeros(n, dtype=wp.vec3, device=d)
        self.correct_fields = int(corrects_fields(cfg))
        self.grad_rho = wp.zeros(n if self.correct_fields else 1, dtype=wp.vec3, device=d)
        self.grad_p = wp.zeros(n if self.correct_fields else 1, dtype=wp.vec3, device=d)
        self.w_spacing = float(kernel_values(cfg.kernel, np.array([cfg.spacing]), cfg.smoothing_length, cfg.dim)[0])
        self.per_second = shift_per_second(cfg)


def shift_particles(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch) -> None:
    """The liquid of ``st`` (in cell order, its neighbour grid current) shifted toward uniform spacing, where
    ``FluidConfig.particle_shifting`` asks for it."""
    sc = sh.shifting
    if sc is None:
        return
    nb = sh.neighborhood(m, st)
    rec.launch(
        measure_concentration, m.n_particles, prm=m.params, b_volume=m.b_volume, w_spacing=sc.w_spacing, correct_fields=sc.correct_fields,
        nb=nb, active=st.active, mass=st.mass, rho=st.rho, p=st.p, indicator=sc.indicator, normal=sc.normal, grad_c=sc.grad_c,
        grad_rho=sc.grad_rho, grad_p=sc.grad_p,
    )
    rec.launch(
        compute_shift, m.n_particles, prm=m.params, per_second=sc.per_second, nb=nb, active=st.active, dt=sh.dt,
        indicator=sc.indicator, normal=sc.normal, grad_c=sc.grad_c, shift=sc.shift,
    )
    rec.launch(
        apply_shift, m.n_particles, correct_fields=sc.correct_fields, active=st.active, shift=sc.shift, grad_rho=sc.grad_rho, grad_p=sc.grad_p,
        x=st.x, rho=st.rho, p=st.p,
    )
