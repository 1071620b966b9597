"""Fluid configuration: frozen dataclasses validated on construction (SI units).

Defaults follow Camporredondo et al. (2019) (Tait EOS, rho0 = 1000 kg/m^3, gamma = 7) with the weakly compressible
form of Monaghan (1994): an artificial speed of sound c0 = ``sound_speed_factor`` x ``max_expected_speed``
(>= 10 v_max keeps the density error near (v_max / c0)^2 = 1 %) instead of the paper's 1480 m/s, delta-SPH density diffusion and a CFL
time step that includes the vessel wall speed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum

from cosim.checks import check_choice, check_int, check_positive, check_range, check_vector
from cosim.errors import InputError

GRAVITY = 9.81  # m/s^2, standard gravity magnitude used across the project
# Range of |fluid.gravity| (m/s^2): the energy guard counts the energy the numerics create in units of M g L, and the
# time step's force criterion and the expected speeds scale with g, so a liquid without gravity has no scale; the
# upper end is 10 g, beyond anything a pour meets.
MIN_GRAVITY = 0.1
MAX_GRAVITY = 10.0 * GRAVITY
MAX_CPU_THREADS = 256  # most threads a CPU substep may be split over (FluidConfig.cpu_threads, cosim pour --threads)


class KernelType(Enum):
    """SPH smoothing kernel (both with compact support 2h)."""

    CUBIC_SPLINE = "cubic_spline"  # Monaghan (1992) M4 spline, the paper's kernel
    WENDLAND_C2 = "wendland_c2"  # Wendland (1995) C2; no pairing instability at large neighbour counts


class GridReset(Enum):
    """How the neighbour grid's cell ranges are reset before each build (``cosim.fluid.neighbors``)."""

    OCCUPIED = "occupied"  # only the cells the liquid and the walls occupied: work restricted to where they are
    WHOLE = "whole"  # every cell of the domain


class PressureSolver(Enum):
    """How pressure is obtained."""

    WCSPH = "wcsph"  # weakly compressible: Tait equation of state, continuity density + delta-SPH
    DFSPH = "dfsph"  # divergence-free SPH (Bender & Koschier 2015/2017): iterative incompressibility, CFL on flow speed


class DensityIteration(Enum):
    """How DFSPH's density solve iterates (its divergence solve, about one iteration a substep, is always Jacobi)."""

    GAUSS_SEIDEL = "gauss_seidel"  # cells coloured 3 apart relaxed in turn, each cell's particles one by one
    JACOBI = "jacobi"  # every particle at once from the last iteration's velocities (Bender & Koschier's)


# The density solve's stopping tolerance when none is given, per iteration (see FluidConfig.density_tolerance).
DEFAULT_DENSITY_TOLERANCE = {DensityIteration.GAUSS_SEIDEL: 0.00015, DensityIteration.JACOBI: 0.00005}


@dataclass(frozen=True)
class FluidConfig:
    """Numerical and physical parameters of the SPH liquid.

    dim: 2 (liquid in the pour plane, world x-z at y = 0, per unit depth times ``depth_2d``) or 3.
    spacing: m, initial particle spacing dx. (0, 0.05]
    smoothing_ratio: h / dx. [1.0, 2.5]
    kernel: :class:`KernelType`.
    pressure_solver: :class:`PressureSolver`.
    rest_density: kg/m^3, rho0. [500, 2000]
    gamma: Tait exponent. [1, 10]
    max_expected_speed: m/s, the largest liquid speed the scene is expected to reach (sets c0). (0, 50]
    sound_speed_factor: c0 / max_expected_speed. [10, 100] (>= 10 keeps |rho - rho0|/rho0 ~ 1 %). DFSPH has no
        equation of state: it uses c0 only as the velocity scale of the artificial viscosity, as WCSPH does.
    kinematic_viscosity: m^2/s, laminar viscosity (water 1.0e-6 at 20 C). [0, 0.01]
    artificial_viscosity: Monaghan alpha (dimensionless), also applied against walls. [0, 1]
    free_liquid: WCSPH: True treats liquid outside every vessel (the falling stream, spray, a splash above a rim) as
        free liquid once it has separated (summation density below rho0): memoryless summation density clamped at
        rho0, so no tension pulls the stream back toward the vessel it left, back to the continuity density once
        packed inside a vessel again (:func:`cosim.fluid.wcsph.update_free_liquid`). False: the continuity density
        everywhere (its tension holds the stream together and lands it short of its free-fall parabola, ``cosim
        validate free-fall``). DFSPH: the same rules decide which liquid is free; free liquid is held to its plain
        summation density (no seeded surface offset) and its pairs use ``free_artificial_viscosity``
        (:func:`cosim.fluid.dfsph.bound_or_free_density`).
    free_artificial_viscosity: Monaghan alpha of every pair with a free particle (and of a free particle against
        walls): free liquid has no tension to hold it together, so this is what makes its impacts inelastic
        (the first stream hitting an empty vessel, a drop on a wall); alpha acts only on approaching pairs, so
        the separating particles of a falling stream fly free. [0, 1]
    max_tension: Pa, the most tension (negative pressure) WCSPH's bound liquid carries: p = max(Tait, -max_tension).
        Tension holds the continuity-density liquid together (its surface row carries a few hundred Pa), but a film
        or a last wedge stretched at a rim reaches tens of kPa (7 % under rest density), enough to fling its
        particles at metres per second; 1 kPa (the hydrostatic pressure of 10 cm of water) keeps them calm. [0, 1e6]
    density_diffusion: delta of delta-SPH (Antuono et al. 2010, renormalised density gradient). [0, 1]
    cfl: Courant number: dt <= cfl h / (c0 + v_max + v_wall) (WCSPH) or cfl h / (v_max + v_wall) (DFSPH, no sound
        speed). (0, 0.6]
    grid_reset: :class:`GridReset`: 'occupied' resets only the neighbour-grid cells the last build occupied (the
        grid's work restricted to the region holding liquid and walls, O(particles)); 'whole' resets every cell of
        the domain (O(cells)). Identical neighbours either way.
    adaptive_time_step: True: every interval plans its step from the previous interval's largest speed and
        acceleration and the walls' speed (the CFL above plus the force criterion). False: one fixed step for the
        whole run from the expected speed alone, cfl h / (c0 + max_expected_speed) (WCSPH) or
        cfl h / max_expected_speed (DFSPH), no force criterion: nothing is measured to plan it, and nothing
        shortens it when the flow or the walls outrun the expectation.
    density_iteration: DFSPH: :class:`DensityIteration`, how the density solve iterates. 'gauss_seidel' relaxes
        each particle's constraint from the velocities its neighbours have now, so a correction reaches the whole
        liquid within one sweep: on the default pour's first 3 s 2.74 density iterations per substep at its default
        tolerance against Jacobi's 7.02, 0.78 x the substeps' time, with the hydrostatic validation's worst probe
        +1.07 % against +1.04 % and the slosh frequencies within 0.2 points of Jacobi's (README, Validation and
        Speed). Its cells are coloured so that cells
        of one colour share no neighbour (9 colours in 2-D, 27 in 3-D) and run in parallel, each cell's particles
        one after the other: the results are the same for any number of threads and on any device, but a colour
        gives a GPU only a ninth (a 27th) of the occupied cells to run at once, so 'jacobi' (every particle at once,
        Bender & Koschier's) is the choice for large scenes on a GPU.
    density_tolerance: DFSPH: the density solve stops when the average compression (rho* - rho0) / rho0 its last
        iteration measured is below this; None: the iteration's own default (``DEFAULT_DENSITY_TOLERANCE``). The
        two measure differently (a Gauss-Seidel sweep measures each particle before relaxing it, after the
        particles before it), so their tolerances are set by the validations, not to one number. Gauss-Seidel
        0.015 %: the resting tank's density error 0.16 % (Jacobi's 0.03 %), the pour's 0.27 % (0.39 %); at 0.02 %
        2.1 iterations per pour substep, but the worst probe +1.55 % (density error 0.20 %); at 0.01 % 4.0; at
        0.005 % as many as Jacobi's. Jacobi 0.005 %: the worst probe stays within -0.79 to +1.04 %
        from 1 to 3 s, its density error within 0.035 %; at SPlisHSPlasH's 0.01 % the probe wanders between +2.0
        and +3.0 %; at 0.003 % it stays within +0.95 to +1.28 % (density error 0.016 %) for 1.16 to 1.30 x the
        default pour's time, at 0.001 % within +0.85 to +0.99 % for about 2 x; 0.1 % leaves a pressure noise of
        tens of % between substeps that kicks particles over rims. The iterations converge slowly near these
        levels, so the tolerance sets most of a DFSPH substep's cost: docs/benchmarks.md has every case at 0.001,
        0.003 and 0.01 % besides. (0, 0.05]
    divergence_tolerance: DFSPH: the divergence solve stops when the average density rate times dt, over rho0, is
        below this (the paper's 0.1 % per step). (0, 0.05]
    max_solver_iterations: DFSPH: iteration cap of each of the two solves (a solve that hits it is not an error;
        the remaining error shows in the diagnostics). [2, 1000]
    cpu_threads: threads a CPU substep is split over (``cosim.fluid.lanes``; each takes every n-th chunk of 16 particles
        in cell order, and the results are the same to the bit for any number); 0: one per core this process may run
        on, at most one per 200 particles. Ignored on CUDA. [0, 256]
    depth_2d: m, liquid thickness perpendicular to the pour plane in 2-D as seeded (the pouring vessel's depth): a
        particle stands for the 3-D volume dx^2 depth_2d; in a vessel of another depth it enters, that volume
        spreads over the vessel's depth (``cosim.fluid.model``). Volumes and wrenches reported to the outside are
        3-D. (0, 2]
    boundary_spacing_ratio: wall sample spacing / dx. [0.3, 1.0]
    domain_min, domain_max: m, world box of the simulation; its bottom face is the floor. Particles that leave it
        are deactivated and counted as spilled.
    max_density_error: compression (rho - rho0) / rho0 above which the run is declared unstable. (0, 1]. An impact
        compresses the liquid by about v / c0 (the acoustic rho c v pressure), i.e. 10 % at c0 = 10 v_max, so the
        default 0.3 flags only what is no longer a pressure (DualSPHysics treats +-30 % as out of range).
    max_wall_penetration: penetration into a wall (in units of dx) above which the run is declared unstable;
        shallower contacts are corrected by the non-penetration guard and counted. (0, 10]
    min_time_step: s, a CFL step below this is an instability. (0, 1e-3]
    max_energy_creation: energy the numerics may create, in units of M g L (liquid mass M, L the tallest vessel's
        inner height), before the run is declared unstable (``cosim.fluid.energy``): a quarter of the work of
        lifting the whole liquid by the vessel's height. (0, 10]. Not zero: the symplectic step is not
        energy-exact under impulsive wall loads (a tilt starting from rest at 5 rad/s within one 2 ms interval
        creates 0.1-0.24 on coarse grids whose other measures stay clean, docs/stability.md).
    gravity: m/s^2, world-frame gravity vector; its magnitude in [0.1, 98.1].
    """

    dim: int = 2
    spacing: float = 0.191 / 40
    smoothing_ratio: float = 1.5
    kernel: KernelType = KernelType.WENDLAND_C2
    pressure_solver: PressureSolver = PressureSolver.WCSPH
    rest_density: float = 1000.0
    gamma: float = 7.0
    max_expected_speed: float = 2.0
    sound_speed_factor: float = 10.0
    kinematic_viscosity: float = 1.0e-6
    artificial_viscosity: float = 0.01
    free_liquid: bool = True
    free_artificial_viscosity: float = 0.25
    max_tension: float = 1000.0
    density_diffusion: float = 0.1
    cfl: float = 0.25
    adaptive_time_step: bool = True
    grid_reset: GridReset = GridReset.OCCUPIED
    density_iteration: DensityIteration = DensityIteration.GAUSS_SEIDEL
    density_tolerance: float | None = None
    divergence_tolerance: float = 0.001
    max_solver_iterations: int = 100
    cpu_threads: int = 0
    depth_2d: float = 0.1
    boundary_spacing_ratio: float = 0.75
    domain_min: tuple[float, float, float] = (-1.0, -0.5, 0.0)
    domain_max: tuple[float, float, float] = (1.0, 0.5, 1.5)
    max_density_error: float = 0.3
    max_wall_penetration: float = 0.5
    min_time_step: float = 1.0e-7
    max_energy_creation: float = 0.25
    gravity: tuple[float, float, float] = field(default=(0.0, 0.0, -GRAVITY))

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "dim", check_int("fluid.dim", self.dim, 2, 3))
        s(self, "spacing", check_positive("fluid.spacing", self.spacing, "m", 0.05))
        s(self, "smoothing_ratio", check_range("fluid.smoothing_ratio", self.smoothing_ratio, 1.0, 2.5))
        s(self, "kernel", check_choice("fluid.kernel", self.kernel, KernelType))
        s(self, "pressure_solver", check_choice("fluid.pressure_solver", self.pressure_solver, PressureSolver))
        s(self, "rest_density", check_range("fluid.rest_density", self.rest_density, 500.0, 2000.0, "kg/m^3"))
        s(self, "gamma", check_range("fluid.gamma", self.gamma, 1.0, 10.0))
        s(self, "max_expected_speed", check_positive("fluid.max_expected_speed", self.max_expected_speed, "m/s", 50.0))
        s(self, "sound_speed_factor", check_range("fluid.sound_speed_factor", self.sound_speed_factor, 10.0, 100.0))
        s(self, "kinematic_viscosity", check_range("fluid.kinematic_viscosity", self.kinematic_viscosity, 0.0, 0.01, "m^2/s"))
        s(self, "artificial_viscosity", check_range("fluid.artificial_viscosity", self.artificial_viscosity, 0.0, 1.0))
        if not isinstance(self.free_liquid, bool):
            raise InputError(f"fluid.free_liquid: must be true or false, got {self.free_liquid!r}")
        s(self, "free_artificial_viscosity", check_range("fluid.free_artificial_viscosity", self.free_artificial_viscosity, 0.0, 1.0))
        s(self, "max_tension", check_range("fluid.max_tension", self.max_tension, 0.0, 1.0e6, "Pa"))
        s(self, "density_diffusion", check_range("fluid.density_diffusion", self.density_diffusion, 0.0, 1.0))
        s(self, "cfl", check_range("fluid.cfl", self.cfl, 0.0, 0.6, lo_open=True))
        s(self, "grid_reset", check_choice("fluid.grid_reset", self.grid_reset, GridReset))
        if not isinstance(self.adaptive_time_step, bool):
            raise InputError(f"fluid.adaptive_time_step: must be true or false, got {self.adaptive_time_step!r}")
        s(self, "density_iteration", check_choice("fluid.density_iteration", self.density_iteration, DensityIteration))
        if self.density_tolerance is None:
            s(self, "density_tolerance", DEFAULT_DENSITY_TOLERANCE[self.density_iteration])
        s(self, "density_tolerance", check_range("fluid.density_tolerance", self.density_tolerance, 0.0, 0.05, lo_open=True))
        s(self, "divergence_tolerance", check_range("fluid.divergence_tolerance", self.divergence_tolerance, 0.0, 0.05, lo_open=True))
        s(self, "max_solver_iterations", check_int("fluid.max_solver_iterations", self.max_solver_iterations, 2, 1000))
        s(self, "cpu_threads", check_int("fluid.cpu_threads", self.cpu_threads, 0, MAX_CPU_THREADS))
        s(self, "depth_2d", check_positive("fluid.depth_2d", self.depth_2d, "m", 2.0))
        s(self, "boundary_spacing_ratio", check_range("fluid.boundary_spacing_ratio", self.boundary_spacing_ratio, 0.3, 1.0))
        lo = check_vector("fluid.domain_min", self.domain_min, 3)
        hi = check_vector("fluid.domain_max", self.domain_max, 3)
        for axis in range(3):
            if hi[axis] - lo[axis] < 4.0 * self.support_radius:
                raise InputError(
                    f"fluid.domain_max[{axis}]: must exceed domain_min[{axis}] by at least 4 smoothing supports "
                    f"({4.0 * self.support_radius:g} m), got {lo[axis]:g} .. {hi[axis]:g}"
                )
        s(self, "domain_min", lo)
        s(self, "domain_max", hi)
        s(self, "max_density_error", check_range("fluid.max_density_error", self.max_density_error, 0.0, 1.0, lo_open=True))
        s(self, "max_wall_penetration", check_range("fluid.max_wall_penetration", self.max_wall_penetration, 0.0, 10.0, lo_open=True))
        s(self, "min_time_step", check_range("fluid.min_time_step", self.min_time_step, 0.0, 1.0e-3, "s", lo_open=True))
        s(self, "max_energy_creation", check_range("fluid.max_energy_creation", self.max_energy_creation, 0.0, 10.0, lo_open=True))
        s(self, "gravity", check_vector("fluid.gravity", self.gravity, 3))
        if not MIN_GRAVITY <= self.gravity_magnitude <= MAX_GRAVITY:
            raise InputError(f"fluid.gravity: magnitude must be in [{MIN_GRAVITY:g}, {MAX_GRAVITY:g}] m/s^2, got {self.gravity_magnitude:g}")

    # ---- derived quantities ------------------------------------------------------------------------------------
    @property
    def smoothing_length(self) -> float:
        """h (m)."""
        return self.smoothing_ratio * self.spacing

    @property
    def support_radius(self) -> float:
        """Kernel support 2h (m)."""
        return 2.0 * self.smoothing_ratio * self.spacing

    @property
    def sound_speed(self) -> float:
        """Artificial speed of sound c0 (m/s)."""
        return self.sound_speed_factor * self.max_expected_speed

    @property
    def fixed_time_step(self) -> float:
        """s, the time step with ``adaptive_time_step`` off: the CFL condition on the sound speed plus the expected
        speed (WCSPH) or on the expected speed alone (DFSPH), dt = cfl h / (c0 + v_max) (the solver's viscous
        criterion, h^2 / nu scaled, can shorten it further: never for water at these resolutions)."""
        sound = self.sound_speed if self.pressure_solver is PressureSolver.WCSPH else 0.0
        return self.cfl * self.smoothing_length / (sound + self.max_expected_speed)

    @property
    def particle_mass(self) -> float:
        """SPH mass of one particle: kg (3-D) or kg per metre of depth (2-D)."""
        return self.rest_density * self.spacing**self.dim

    @property
    def out_of_plane_scale(self) -> float:
        """Factor that turns the solver's per-unit-depth quantities into 3-D ones (depth_2d in 2-D, 1 in 3-D)."""
        return self.depth_2d if self.dim == 2 else 1.0

    @property
    def particle_volume(self) -> float:
        """m^3 of liquid one particle stands for at rest."""
        return self.spacing**self.dim * self.out_of_plane_scale

    @property
    def gravity_magnitude(self) -> float:
        return math.sqrt(sum(g * g for g in self.gravity))
