"""The solver's static parameters as one warp struct (built once from :class:`FluidConfig`)."""

from __future__ import annotations

import warp as wp

from cosim.fluid.config import DensityDiffusionTerm, FluidConfig
from cosim.fluid.sph_kernels import KERNEL_IDS, kernel_sigma, lattice_gradient_square_sum, lattice_jacobi_gain, lattice_kernel_sum

# DFSPH's Jacobi solves diverge once one step's gain (cosim.fluid.sph_kernels.lattice_jacobi_gain) exceeds about 4
# (a hydrostatic tank is stable at gain 3.74 and blows up at 4.17; docs/tuning.md). Only compression is
# corrected, which halves the gain of an oscillating mode: hence 4, not the 2 of a linear Jacobi iteration. The
# increments are scaled down so that the scaled gain stays at this limit (a margin below 4); at or below it they are
# not scaled, so the 2-D default (gain 3.34) is unchanged.
JACOBI_GAIN_LIMIT = 3.5


@wp.struct
class SPHParams:
    """Static SPH parameters (SI). ``mass`` is the SPH mass a particle is seeded with (kg, or kg/m of depth in 2-D;
    each particle's own is ``FluidState.mass``); ``mass_out`` the 3-D mass one particle stands for (kg, the same for
    every particle); ``eos_b`` = rho0 c0^2 / gamma (Pa); ``alpha_free`` the artificial
    viscosity of pairs with free liquid (:attr:`FluidConfig.free_liquid_alpha`); ``viscosity_speed`` (m/s) and
    ``viscosity_approach_weight`` the c and beta of the artificial viscosity's velocity scale
    (``FluidConfig.viscosity_speed``); ``max_tension`` (Pa) the clamp of WCSPH's negative pressure (``FluidConfig.tension_limit``),
    reached at ``tension_density`` (kg/m^3); ``hydrostatic_diffusion`` 1 where WCSPH's density diffusion subtracts the
    pair's hydrostatic density difference (``FluidConfig.density_diffusion_term`` 'fourtakas'); ``eta2`` = 0.01 h^2 (m^2); then DFSPH's stopping rule (relative
    tolerances and the iteration cap of each solve) and ``lattice_density``, the summation density of a resting
    lattice over rho0 (DFSPH and WCSPH's free liquid divide their summation density by it, so the liquid as seeded
    is at rest density) and ``lattice_factor_denominator``, sum_j |m grad W|^2 of a particle inside that lattice
    (kg^2/m^(2 dim + 2)), the scale below which DFSPH does not let a factor's denominator fall; ``jacobi_relaxation``
    the factor (<= 1) DFSPH's Jacobi increments are scaled by (:data:`JACOBI_GAIN_LIMIT`); ``atomic_replicas`` the copies
    of each diagnostics row the particles spread their atomics over (``cosim.fluid.device_layout``)."""

    dim: int
    kernel: int
    h: float
    inv_h: float
    support: float
    sigma: float
    mass: float
    mass_out: float
    rest_density: float
    sound_speed: float
    eos_b: float
    gamma: float
    nu: float
    alpha: float
    alpha_free: float
    viscosity_speed: float
    viscosity_approach_weight: float
    max_tension: float
    tension_density: float
    delta: float
    hydrostatic_diffusion: int
    eta2: float
    gravity: wp.vec3
    n_vessels: int
    density_tolerance: float
    divergence_tolerance: float
    max_iterations: int
    lattice_density: float
    lattice_factor_denominator: float
    jacobi_relaxation: float
    atomic_replicas: int


def make_params(cfg: FluidConfig, n_vessels: int, atomic_replicas: int = 1, densest_smoothing_ratio: float | None = None) -> SPHParams:
    """The struct for ``cfg``. ``densest_smoothing_ratio``: h over the spacing of the densest liquid the particles
    can pack to (``cosim.fluid.model.densest_smoothing_ratio``; None: the configured ratio): the Jacobi relaxation
    is set for that lattice's gain, the largest any part of the liquid has."""
    p = SPHParams()
    h = cfg.smoothing_length
    p.dim = cfg.dim
    p.kernel = KERNEL_IDS[cfg.kernel]
    p.h = h
    p.inv_h = 1.0 / h
    p.support = 2.0 * h
    p.sigma = kernel_sigma(cfg.kernel, h, cfg.dim)
    p.mass = cfg.particle_mass
    p.mass_out = cfg.particle_mass * cfg.out_of_plane_scale
    p.rest_density = cfg.rest_density
    p.sound_speed = cfg.sound_speed
    p.eos_b = cfg.rest_density * cfg.sound_speed**2 / cfg.gamma
    # the density below which the Tait pressure is clamped at -max_tension (0: the clamp is never reached)
    p.tension_density = cfg.rest_density * (1.0 - cfg.tension_limit / p.eos_b) ** (1.0 / cfg.gamma) if cfg.tension_limit < p.eos_b else 0.0
    p.gamma = cfg.gamma
    p.nu = cfg.kinematic_viscosity
    p.alpha = cfg.alpha
    p.alpha_free = cfg.free_liquid_alpha
    p.viscosity_speed = cfg.viscosity_speed
    p.viscosity_approach_weight = cfg.viscosity_approach_weight
    p.max_tension = cfg.tension_limit
    p.delta = cfg.density_diffusion
    p.hydrostatic_diffusion = int(cfg.density_diffusion_term is DensityDiffusionTerm.FOURTAKAS)
    p.eta2 = 0.01 * h * h
    p.gravity = wp.vec3(*cfg.gravity)
    p.n_vessels = n_vessels
    p.density_tolerance = cfg.density_solve_tolerance
    p.divergence_tolerance = cfg.divergence_tolerance
    p.max_iterations = cfg.max_solver_iterations
    p.lattice_density = lattice_kernel_sum(cfg.kernel, cfg.smoothing_ratio, cfg.dim)
    p.lattice_factor_denominator = lattice_gradient_square_sum(cfg.kernel, cfg.smoothing_ratio, cfg.dim) * (cfg.particle_mass / cfg.spacing ** (cfg.dim + 1)) ** 2
    densest = cfg.smoothing_ratio if densest_smoothing_ratio is None else densest_smoothing_ratio
    p.jacobi_relaxation = min(1.0, JACOBI_GAIN_LIMIT / lattice_jacobi_gain(cfg.kernel, densest, cfg.dim))
    p.atomic_replicas = atomic_replicas
    return p
