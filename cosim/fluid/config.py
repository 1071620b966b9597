"""Fluid configuration: one frozen dataclass of the SPH liquid's settings, validated on construction (SI units).

Defaults follow Camporredondo et al. (2019) (Tait EOS, rho0 = 1000 kg/m^3, gamma = 7) with the weakly compressible
form of Monaghan (1994): an artificial speed of sound c0 = ``sound_speed_factor`` x ``max_expected_speed``
(>= 10 v_max keeps the density error near (v_max / c0)^2 = 1 %) instead of the paper's 1480 m/s, delta-SPH density
diffusion and a CFL time step that includes the vessel wall speed. Each setting is declared once, in its group
(:data:`GROUPS`): the checks, the class's reference and ``cosim scene --dump`` come from that declaration.
"""

from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass
from enum import Enum

from cosim.errors import InputError
from declared_settings.setting import check_settings, settings_reference, setting

GRAVITY = 9.81  # m/s^2, standard gravity magnitude used across the project


class KernelType(Enum):
    """SPH smoothing kernel (both with compact support 2h)."""

    CUBIC_SPLINE = "cubic_spline"  # Monaghan (1992) M4 spline, the paper's kernel
    WENDLAND_C2 = "wendland_c2"  # Wendland (1995) C2; no pairing instability at large neighbour counts


class WallModel(Enum):
    """How a vessel's walls are filled with dummy particles (``cosim.fluid.wall_sampling``)."""

    KERNEL_LAYERS = "kernel_layers"  # ceil(2h / dx) layers behind every wetted face, past a thinner wall's outer face
    REAL_THICKNESS = "real_thickness"  # layers inside the vessel's own wall, volumes compensating the missing support
    SIDED = "sided"  # the covering layers seen from inside the vessel, the real_thickness wall from outside (WCSPH)


class WallPressure(Enum):
    """How DFSPH's walls carry the liquid's pressure (``cosim.fluid.dfsph``; WCSPH extrapolates it, Adami et al. 2012)."""

    SOLVED_LAYER = "solved_layer"  # the wall layer facing the liquid solved with it, each particle's own stiffness
    SOLVED_REST_SUM = "solved_rest_sum"  # the same, each particle held to its summation density with liquid at rest
    MIRRORED = "mirrored"  # no unknown on the wall: each wall pair carries the liquid particle's own stiffness


class GridReset(Enum):
    """How the neighbour grid's cell ranges are reset before each build (``cosim.fluid.neighbors``)."""

    OCCUPIED = "occupied"  # only the cells the liquid and the walls occupied: work restricted to where they are
    WHOLE = "whole"  # every cell of the domain


class PressureSolver(Enum):
    """How pressure is obtained."""

    WCSPH = "wcsph"  # weakly compressible: Tait equation of state, continuity density + delta-SPH
    DFSPH = "dfsph"  # divergence-free SPH (Bender & Koschier 2015/2017): iterative incompressibility, CFL on flow speed


class InitialState(Enum):
    """How the seeded liquid starts (``cosim.fluid.relaxation``)."""

    SEEDED = "seeded"  # as seeded, at rest
    RELAXED = "relaxed"  # settled in its vessels held still before t = 0, then at rest


class SurfaceDensity(Enum):
    """The density DFSPH holds bound liquid short of a full kernel support to (``cosim.fluid.dfsph.surface_offset``)."""

    CONTINUITY = "continuity"  # carried by the continuity equation where Marrone's indicator is below 0.75
    SEEDED_OFFSET = "seeded_offset"  # summation + the deficiency seeded at t = 0 ('seeded'), or none ('relaxed')


class ArtificialViscosityScale(Enum):
    """The velocity scale v_sig of Monaghan's artificial viscosity Pi_ij = -alpha v_sig h (v_ij . r_ij) /
    ((r_ij^2 + eta^2) rho_ij) (``cosim.fluid.sph_common.viscous_pair``)."""

    SOUND_SPEED = "sound_speed"  # c0 (WCSPH: its equation of state's; DFSPH: sound_speed_factor x max_expected_speed)
    SIGNAL_VELOCITY = "signal_velocity"  # DFSPH: sqrt(|g| h) + 2 x each pair's approach speed (Monaghan 1997); WCSPH: c0


class ViscousTimeStep(Enum):
    """The approach speed w at which the time step's artificial-viscosity criterion evaluates the signal velocity
    v_sig = c + beta w (``cosim.fluid.time_step``)."""

    PLANNED_APPROACH = "planned_approach"  # the fastest the planned flow allows: 2 max(max_expected_speed, v_max) or that + v_wall
    MEASURED_APPROACH = "measured_approach"  # the fastest the last interval's speeds allow: max(2 v_max, v_max + v_wall)


class FreeLiquidRule(Enum):
    """Where liquid may become free liquid (``cosim.fluid.free_surface``)."""

    OUTSIDE_VESSELS = "outside_vessels"  # outside every vessel's inner volume: the stream, spray, liquid above a rim
    FREE_SURFACE = "free_surface"  # at the free surface (Marrone et al. 2010's indicator), wherever it is


class TensionTreatment(Enum):
    """How WCSPH's pressure gradient treats negative pressure (``cosim.fluid.wcsph.pressure_pair_factor``)."""

    SYMMETRIC = "symmetric"  # Monaghan's symmetric sum p_i / rho_i^2 + p_j / rho_j^2 everywhere, the Tait tension unclamped
    CLAMP = "clamp"  # the same sum, tension clamped at max_tension
    TIC = "tic"  # Sun et al. (2018)'s tensile-instability control (p_j - p_i where p_i < 0 away from the surface), no clamp


class DensityDiffusionTerm(Enum):
    """The form of WCSPH's delta-SPH density diffusion (``cosim.fluid.wcsph.add_liquid_density_rate``)."""

    ANTUONO = "antuono"  # 2 (rho_j - rho_i) less the renormalised gradients' linear part (Antuono et al. 2010)
    FOURTAKAS = "fourtakas"  # 2 (rho_j - rho_i) less the pair's hydrostatic density difference (Fourtakas et al. 2019)


class ParticleShifting(Enum):
    """Whether particles are shifted toward uniform spacing each substep (``cosim.fluid.shifting``)."""

    OFF = "off"  # particles move with the flow alone
    FICKIAN = "fickian"  # down the particle-concentration gradient, tangential at the free surface (Sun et al. 2017)


class DensityIteration(Enum):
    """How DFSPH's density solve iterates (its divergence solve, about one iteration a substep, is always Jacobi)."""

    GAUSS_SEIDEL = "gauss_seidel"  # cells coloured 3 apart relaxed in turn, each cell's particles one by one
    JACOBI = "jacobi"  # every particle at once from the last iteration's velocities (Bender & Koschier's)


class DivergenceConstraint(Enum):
    """Which density rates DFSPH's divergence solve removes (``cosim.fluid.dfsph.divergence_error``)."""

    PAST_REST_DENSITY = "past_rest_density"  # only the rate that would compress the particle past rho0 within the step
    EVERY_COMPRESSION = "every_compression"  # every compressing rate (Bender & Koschier 2017)


# The density solve's stopping tolerance when none is given, per iteration (see FluidConfig.density_tolerance): the
# two measure differently (a Gauss-Seidel sweep measures each particle before relaxing it, after the particles
# before it), so each has its own, chosen by the validations (docs/benchmarks.md, docs/performance.md).
DEFAULT_DENSITY_TOLERANCE = {DensityIteration.GAUSS_SEIDEL: 0.00015, DensityIteration.JACOBI: 0.00005}

# beta of the signal velocity v_sig = c + beta max(0, -v_ij . r_ij / |r_ij|) (FluidConfig.viscosity_speed): Monaghan
# (1997)'s form c_i + c_j + 4 max(0, -w_ij) per unit of one particle's c (docs/artificial_viscosity.md).
APPROACH_WEIGHT = 2.0

# Monaghan's alpha when none is given (FluidConfig.artificial_viscosity), per velocity scale in effect: the same
# alpha is a viscosity about c0 / sqrt(g h) (~100) times as large on c0, so each scale has its own, chosen by the
# validations (docs/artificial_viscosity.md).
DEFAULT_ARTIFICIAL_VISCOSITY = {ArtificialViscosityScale.SOUND_SPEED: 0.01, ArtificialViscosityScale.SIGNAL_VELOCITY: 1.0}
# The free-liquid rule when none is given (FluidConfig.free_liquid_rule), under either pressure solver: every
# validation that passes with the vessels' inner volumes passes with the local free-surface indicator, which needs no
# knowledge of the scene (WCSPH's free fall failed under it while WCSPH's liquid carried tension, which pulled the
# stream's bound interior back; docs/free_surface.md).
DEFAULT_FREE_LIQUID_RULE = FreeLiquidRule.FREE_SURFACE
# The wall model when none is given (FluidConfig.wall_model), per pressure solver: DFSPH with the vessel's own walls
# ('real_thickness', with wall_pressure 'solved_rest_sum') passes every validation case the covering layers pass, in
# 2-D and 3-D, and puts the lip where the vessel has it; WCSPH's resting cases stop with them (its continuity density
# does not see the liquid piling into the corners of a one-layer wall); WCSPH's 'sided' (the vessel's own walls for
# the liquid outside it, each face's wall state from the liquid at that face, the covering layers for the liquid
# inside) passes every 2-D case and puts the 3-D launch point within 1 mm of the real lip (docs/walls.md).
# A mesh vessel's wall (not validated confined) gets 'kernel_layers' under either solver; a box's or cylinder's wall
# thinner than dx / 2 holds its one layer outside it, where one layer gives the liquid's first row the covering walls'
# kernel sum and gradient (cosim.fluid.wall_sampling.wall_model_for, one_layer_wall_depth).
DEFAULT_WALL_MODEL = {PressureSolver.DFSPH: WallModel.REAL_THICKNESS, PressureSolver.WCSPH: WallModel.SIDED}
# Monaghan's alpha of pairs with free liquid under DFSPH's 'sound_speed' scale when none is given
# (FluidConfig.free_artificial_viscosity): c0 does not grow with an impact, so without an approach term the free
# liquid's impacts need their own, larger alpha (a value set on the pour, docs/artificial_viscosity.md). The signal
# velocity's approach term, and WCSPH's quadratic term (WCSPH_ARTIFICIAL_VISCOSITY_BETA), damp impacts wherever they
# happen, so under them one alpha serves all liquid.
SOUND_SPEED_FREE_ARTIFICIAL_VISCOSITY = 0.25
# Monaghan's quadratic coefficient beta under WCSPH when none is given (FluidConfig.artificial_viscosity_beta), with
# one alpha for all liquid: Monaghan (1992)'s standard beta = 2 (his alpha = 1; WCSPH's alpha stays 0.01, which the
# slosh bounds), as DFSPH's signal velocity's approach term 2 alpha w at its alpha 1. Not fitted: it replaces a
# free-liquid alpha that was set on the pour; what it passes and fails: docs/wcsph_knobs.md.
WCSPH_ARTIFICIAL_VISCOSITY_BETA = 2.0

# The concerns the settings are grouped by, in the order references list them.
DISCRETISATION = "discretisation"
MATERIAL = "material"
PRESSURE = "pressure (both solvers)"
WCSPH = "WCSPH"
DFSPH = "DFSPH"
TIME_STEPPING = "time stepping"
GUARDS = "guards"
RUNTIME = "runtime"
GROUPS = (DISCRETISATION, MATERIAL, PRESSURE, WCSPH, DFSPH, TIME_STEPPING, GUARDS, RUNTIME)


@dataclass(frozen=True)
class FluidConfig:
    """Numerical and physical parameters of the SPH liquid (SI units); each field is declared once with its group,
    unit, default and allowed values (:func:`declared_settings.setting.setting`), the reference below is generated from them."""

    # ---- discretisation
    dim: int = setting(2, DISCRETISATION, "2: the liquid in the pour plane (world x-z at y = 0), per unit depth times "
                       "depth_2d; 3: the liquid in 3-D.", lo=2, hi=3)
    spacing: float = setting(0.191 / 40, DISCRETISATION, "Initial particle spacing dx.", "m", 0.0, 0.05, lo_open=True)
    smoothing_ratio: float = setting(1.5, DISCRETISATION, "Smoothing length over spacing, h / dx.", "", 1.0, 2.5)
    kernel: KernelType = setting(KernelType.WENDLAND_C2, DISCRETISATION, "SPH smoothing kernel, compact support 2h: "
                                 "Wendland (1995) C2 (no pairing instability at large neighbour counts) or Monaghan "
                                 "(1992)'s cubic spline.")
    wall_model: WallModel | None = setting(
        None, DISCRETISATION, "How the walls are filled with dummy particles: 'kernel_layers' (ceil(2h / dx) layers "
        "behind every wetted face, so a wall thinner than that reaches past its outer face and the pour lip with it) "
        "or 'real_thickness' (layers confined to the vessel's own wall, their volumes fitted to make up the kernel "
        "support missing behind a thin wall; the lip is the real one) or 'sided' (WCSPH only: liquid inside the vessel "
        "sees the covering layers, liquid outside it, over the rim included, the 'real_thickness' wall; docs/walls.md).", kind="choice",
        choices=WallModel, none_means="'real_thickness' under DFSPH, 'sided' under WCSPH; 'kernel_layers' for "
        "a mesh vessel's (chosen on the validation cases)")
    depth_2d: float = setting(0.1, DISCRETISATION, "2-D: the liquid's thickness across the pour plane as seeded (the "
                              "pourer's depth); a particle stands for the 3-D volume dx^2 depth_2d, spread over the depth "
                              "of any other vessel it enters (cosim.fluid.model). Volumes and wrenches reported outside "
                              "are 3-D.", "m", 0.0, 2.0, lo_open=True)
    domain_min: tuple[float, float, float] = setting((-1.0, -0.5, 0.0), DISCRETISATION, "Lower corner of the "
                                                     "simulated world box, its floor; particles that leave the box are "
                                                     "deactivated and counted as spilled.", "m")
    domain_max: tuple[float, float, float] = setting((1.0, 0.5, 1.5), DISCRETISATION, "Upper corner of the simulated "
                                                     "box; at least 4 kernel supports (8h) above domain_min on every "
                                                     "axis.", "m")
    # ---- material
    rest_density: float = setting(1000.0, MATERIAL, "Rest density rho0.", "kg/m^3", 500.0, 2000.0)
    kinematic_viscosity: float = setting(1.0e-6, MATERIAL, "Laminar kinematic viscosity nu (water: 1e-6 at 20 C).",
                                         "m^2/s", 0.0, 0.01)
    gravity: tuple[float, float, float] = setting((0.0, 0.0, -GRAVITY), MATERIAL, "World-frame gravity vector. The "
                                                  "energy guard counts in units of M g L and the time step's force "
                                                  "criterion and the expected speeds scale with g, so a liquid without "
                                                  "gravity has no scale; up to 10 g.", "m/s^2",
                                                  0.1, 10.0 * GRAVITY)
    # ---- pressure and viscosity, both solvers
    pressure_solver: PressureSolver = setting(PressureSolver.DFSPH, PRESSURE, "How pressure is obtained: 'wcsph' "
                                              "(weakly compressible, Tait equation of state, Monaghan 1994) or 'dfsph' "
                                              "(divergence-free SPH, Bender & Koschier 2015/2017: iterative "
                                              "incompressibility, time step set by the flow speed).")
    max_expected_speed: float = setting(2.0, PRESSURE, "The largest liquid speed the scene is expected to reach; "
                                        "sets c0 and the fixed time step.", "m/s", 0.0, 50.0, lo_open=True)
    sound_speed_factor: float = setting(10.0, PRESSURE, "c0 / max_expected_speed: the artificial speed of sound c0 of "
                                        "Monaghan (1994) instead of water's; >= 10 keeps the density error near "
                                        "(v_max / c0)^2 = 1 %. DFSPH has no equation of state and uses c0 only as "
                                        "the artificial viscosity's velocity scale (artificial_viscosity_scale "
                                        "'sound_speed').", "", 10.0, 100.0)
    artificial_viscosity: float | None = setting(None, PRESSURE, "Monaghan's alpha (dimensionless), also against "
                                                 "walls.", "", 0.0, 1.0, kind="float", none_means="the velocity scale's "
                                                 "own, " + ", ".join(f"{a:g} for {s.value!r}" for s, a in
                                                                     DEFAULT_ARTIFICIAL_VISCOSITY.items())
                                                 + " (WCSPH, whose scale is c0 either way: the first)")
    artificial_viscosity_scale: ArtificialViscosityScale = setting(
        ArtificialViscosityScale.SIGNAL_VELOCITY, PRESSURE, "The artificial viscosity's velocity scale v_sig (its "
        "kinematic viscosity is about alpha h v_sig / (2 (dim + 2)), Monaghan 2005): 'sound_speed', c0 (WCSPH: the "
        "equation of state's signal speed; DFSPH, which has no equation of state: the same c0 from "
        "max_expected_speed, a scene estimate) or 'signal_velocity': WCSPH keeps its c0, DFSPH takes Monaghan "
        "(1997)'s signal velocity of each pair, v_sig = sqrt(|g| h) + 2 max(0, -v_ij . r_ij / |r_ij|), with the "
        "speed of gravity waves at the kernel scale, sqrt(|g| h), for the sound speed the incompressible liquid does "
        "not have: the same for every scene, larger where particles collide (docs/artificial_viscosity.md).")
    free_liquid: bool = setting(True, PRESSURE, "Treat exposed liquid (the stream, spray: where free_liquid_rule lets "
                                "liquid be free) as free once it has separated (summation density below rho0): WCSPH "
                                "gives it a memoryless summation density clamped at rho0, so no tension pulls the "
                                "stream back to the vessel it left "
                                "(cosim.fluid.wcsph.update_free_liquid; false: the continuity density everywhere, which "
                                "under a tension clamp lands the stream short of its free-fall parabola, `cosim "
                                "validate free-fall`, and without tension keeps the voids a splash leaves); "
                                "DFSPH holds it to its plain summation density (cosim.fluid.dfsph.bound_or_free_density). "
                                "Either way its pairs use free_artificial_viscosity. Where liquid may become free: "
                                "free_liquid_rule.")
    free_liquid_rule: FreeLiquidRule | None = setting(
        None, PRESSURE, "Where liquid may become free (with free_liquid): 'outside_vessels', outside every vessel's "
        "inner volume (so the liquid over a weir's or a tilted pourer's crest is free as well as the stream), or "
        "'free_surface', at the free surface wherever it is: Marrone et al. (2010)'s indicator, the smallest "
        "eigenvalue of the renormalisation matrix, below free_surface_threshold (cosim.fluid.free_surface; "
        "docs/free_surface.md). Either way the liquid must also have separated (summation density below rho0) and is "
        "bound again once packed (summation density >= rho0) where the rule no longer holds.", kind="choice",
        choices=FreeLiquidRule, none_means=f"{DEFAULT_FREE_LIQUID_RULE.value!r} under either pressure solver (chosen on the "
        "validation cases)")
    free_surface_threshold: float = setting(0.4, PRESSURE, "free_liquid_rule 'free_surface': liquid whose indicator "
                                            "lambda is below this is at the free surface (about 1 inside the liquid, "
                                            "0.5 at a flat surface's top row, 0 for a lone particle; Marrone et al. "
                                            "2010: <= 0.2 certainly at the surface, <= 0.75 near it). 0.4, chosen on "
                                            "the validation cases: below a resting surface's 0.5, which DFSPH's "
                                            "hydrostatic column needs bound (docs/free_surface.md).", "", 0.0, 1.0)
    free_artificial_viscosity: float | None = setting(None, PRESSURE, "Monaghan's alpha of every pair with a free "
                                                      "particle (and of a free particle against walls): free liquid "
                                                      "has no tension, so this makes its impacts inelastic; alpha acts "
                                                      "only on approaching pairs, so a separating stream flies free.",
                                                      "", 0.0, 1.0, kind="float", none_means="artificial_viscosity, "
                                                      "one alpha for all liquid, with the signal velocity or under "
                                                      "WCSPH (their approach terms damp impacts); "
                                                      f"{SOUND_SPEED_FREE_ARTIFICIAL_VISCOSITY:g} with DFSPH's "
                                                      "'sound_speed'")
    artificial_viscosity_beta: float | None = setting(None, PRESSURE, "Monaghan's quadratic coefficient beta of the "
                                                      "artificial viscosity (Monaghan & Gingold 1983; Monaghan 1992: "
                                                      "Pi_ij = (-alpha c mu_ij + beta mu_ij^2) / rho_ij), in the signal-"
                                                      "velocity form Pi_ij = -(alpha c + beta w) mu_ij / rho_ij with w = "
                                                      "max(0, -v_ij . r_ij / |r_ij|) the pair's approach speed (Monaghan "
                                                      "1997; about beta mu_ij^2 at |r_ij| = h): it damps each pair by "
                                                      "its own approach speed, an impact wherever it happens, on top of "
                                                      "the linear term alpha c. Needs alpha > 0 and one alpha for all "
                                                      "liquid (free_artificial_viscosity equal to the bulk's, or "
                                                      "free_liquid off): the kernel scales the approach term with each "
                                                      "pair's alpha (docs/wcsph_knobs.md).", "", 0.0, 10.0, kind="float",
                                                      none_means=f"{WCSPH_ARTIFICIAL_VISCOSITY_BETA:g} under WCSPH "
                                                      "with one alpha above 0 for all liquid (0 with a free-liquid "
                                                      "alpha of its own); 0 with DFSPH's 'sound_speed'; "
                                                      f"{APPROACH_WEIGHT:g} alpha with the signal velocity")
    particle_shifting: ParticleShifting = setting(ParticleShifting.OFF, PRESSURE, "Particle shifting at the start of "
                                                  "every substep, both solvers: 'fickian' moves each particle down the "
                                                  "gradient of the particle concentration (walls counted), "
                                                  "dr = -shifting_coefficient (2h)^2 (max_expected_speed dt / h) grad C "
                                                  "(Lind et al. 2012; Sun et al. 2017's delta-plus-SPH form), with its "
                                                  "component normal to the free surface (or a wall) removed near it and "
                                                  "no shift at it (Marrone et al. 2010's indicator, over the liquid). It "
                                                  "moves mass without momentum; WCSPH's density and pressure follow the "
                                                  "shifted particle to first order (cosim.fluid.shifting; "
                                                  "docs/particle_shifting.md).")
    shifting_coefficient: float = setting(0.1, PRESSURE, "particle_shifting 'fickian': the shift's coefficient A in "
                                          "dr = -A (2h)^2 (max_expected_speed dt / h) grad C (1 is Sun et al. "
                                          "2017's CFL Ma (2h)^2 with Ma = max_expected_speed / c0). 0.1, chosen on "
                                          "the validation cases: the largest at which DFSPH's hydrostatic column "
                                          "passes (docs/particle_shifting.md).", "", 0.0, 1.0)
    initial_state: InitialState = setting(InitialState.SEEDED, PRESSURE, "How the liquid starts: 'seeded' (from "
                                          "its seeded lattice, at rest) or 'relaxed' (settled first with its vessels "
                                          "held still and its velocities zeroed, until it stops moving, and started "
                                          "from there at rest). Under surface_density 'seeded_offset' DFSPH holds "
                                          "each bound particle of a 'seeded' start to the kernel deficiency it was "
                                          "seeded with, and a 'relaxed' one to none (compression only: Bender & "
                                          "Koschier 2017). docs/relaxed_start.md.")
    surface_density: SurfaceDensity = setting(SurfaceDensity.CONTINUITY, PRESSURE, "DFSPH: the density of "
                                              "bound liquid short of a full kernel support (the surface rows). "
                                              "'continuity': carried by the continuity equation wherever Marrone et "
                                              "al. 2010's indicator is below 0.75 (the summation density inside), "
                                              "so the offset follows the liquid instead of the seeding. "
                                              "'seeded_offset': its summation density plus the deficiency it was "
                                              "seeded with (initial_state 'seeded'), or none ('relaxed'). "
                                              "docs/surface_density.md.")
    # ---- WCSPH
    gamma: float = setting(7.0, WCSPH, "Tait exponent of the equation of state p = rho0 c0^2 / gamma ((rho / rho0)^gamma "
                           "- 1) (Camporredondo et al. 2019).", "", 1.0, 10.0)
    max_tension: float = setting(0.0, WCSPH, "tension_treatment 'clamp': the most tension (negative pressure) "
                                 "the bound liquid carries, p = max(Tait, -max_tension). 0: none, the liquid only "
                                 "pushes (as DFSPH's, and SPlisHSPlasH's WCSPH, whose density is floored at rho0): "
                                 "tension pulls a stream's particles back as pairs part, which made WCSPH's stream "
                                 "twice as noisy as DFSPH's (docs/landing.md). Without tension the density "
                                 "diffusion must leave the hydrostatic profile alone (density_diffusion_term "
                                 "'fourtakas', docs/density_diffusion.md). Used by 'clamp' only.", "Pa", 0.0, 1.0e6)
    tension_treatment: TensionTreatment = setting(TensionTreatment.CLAMP, WCSPH, "How the pressure gradient treats "
                                                  "negative pressure: 'symmetric' (Monaghan's symmetric sum m_j (p_i "
                                                  "/ rho_i^2 + p_j / rho_j^2) grad W for every pair, the Tait tension "
                                                  "as it is), 'clamp' (the same, the tension clamped at max_tension) "
                                                  "or 'tic' (Sun et al. 2018's tensile-"
                                                  "instability control, no clamp: (m_j / (rho_i rho_j)) F_ij grad W "
                                                  "with F_ij = p_j + p_i where p_i >= 0 or particle i is in the "
                                                  "free-surface region, Marrone et al. 2010's indicator at or below "
                                                  "0.75, and p_j - p_i where p_i < 0 inside the liquid, so tension "
                                                  "does not clump particles). docs/tensile_control.md.")
    density_diffusion: float = setting(0.1, WCSPH, "delta of delta-SPH density diffusion, D = delta h c0 "
                                       "sum_j V_j psi_ij (its pair term psi_ij: density_diffusion_term).", "", 0.0, 1.0)
    density_diffusion_term: DensityDiffusionTerm = setting(DensityDiffusionTerm.FOURTAKAS, WCSPH, "The density "
                                                          "diffusion's pair term: 'antuono' (Antuono et al. 2010: "
                                                          "2 (rho_j - rho_i) less the linear part the renormalised "
                                                          "density gradients give) or 'fourtakas' (Fourtakas et al. "
                                                          "2019: 2 (rho_j - rho_i) less the pair's hydrostatic density "
                                                          "difference from the Tait equation, no gradient estimated, "
                                                          "each density read no lower than where the tension clamp "
                                                          "binds). docs/density_diffusion.md.")
    # ---- DFSPH
    density_iteration: DensityIteration = setting(DensityIteration.GAUSS_SEIDEL, DFSPH, "How the density solve "
                                                  "iterates (the divergence solve is Jacobi): 'gauss_seidel' relaxes "
                                                  "each particle from its neighbours' current velocities, cells "
                                                  "coloured 3 apart in turn (9 colours in 2-D, 27 in 3-D), so a "
                                                  "correction crosses the liquid in one sweep and the results are the "
                                                  "same on any number of threads and any device; 'jacobi' (Bender & "
                                                  "Koschier's) moves every particle at once, the choice for large "
                                                  "scenes on a GPU, where a colour holds too few cells.")
    density_tolerance: float | None = setting(None, DFSPH, "The density solve stops when its last iteration's average "
                                              "compression (rho* - rho0) / rho0 is below this; it sets most of a "
                                              "DFSPH substep's cost (docs/benchmarks.md).", "", 0.0, 0.05,
                                              lo_open=True, kind="float", none_means="the density iteration's own, "
                                              + ", ".join(f"{t:g} for {it.value!r}" for it, t in
                                                          DEFAULT_DENSITY_TOLERANCE.items()))
    divergence_constraint: DivergenceConstraint = setting(
        DivergenceConstraint.PAST_REST_DENSITY, DFSPH, "Which density rates the divergence solve removes: "
        "'every_compression' (every compressing rate, dt Drho/Dt > 0, Bender & Koschier 2017: liquid below rest "
        "density is held at the density it has, so a loose packing, such as liquid that landed in a splash, is never "
        "closed and stands taller than its volume) or 'past_rest_density' (only the rate that would compress the "
        "particle past rest density within the step, dt Drho/Dt > rho0 - rho_i: liquid below rest density closes "
        "under its weight, as the density solve, which corrects compression only, lets it; "
        "docs/divergence_constraint.md).")
    divergence_tolerance: float = setting(0.001, DFSPH, "The divergence solve stops when the average density rate "
                                          "times dt, over rho0, is below this (Bender & Koschier's 0.1 % per step).",
                                          "", 0.0, 0.05, lo_open=True)
    wall_pressure: WallPressure = setting(WallPressure.SOLVED_REST_SUM, DFSPH, "How the walls carry pressure: "
                                         "'solved_layer' (the wall layer facing the liquid is held to rest density "
                                         "with a stiffness of its own, solved with the liquid's; a wall thinner than "
                                         "the kernel support, whose particles sum short of rho0 with liquid resting "
                                         "against them, carries none), 'solved_rest_sum' (the same, each particle of "
                                         "a thin wall held to the summation density it has with liquid resting "
                                         "against it; walls covering the support as 'solved_layer') or 'mirrored' "
                                         "(no unknown on the wall: each wall pair carries the liquid particle's own "
                                         "stiffness, Akinci et al. 2012); docs/walls.md.")
    max_solver_iterations: int = setting(100, DFSPH, "Iteration cap of each of the two solves; a solve that hits it "
                                         "is not an error, its remaining error shows in the diagnostics.", "", 2, 1000)
    # ---- time stepping
    cfl: float = setting(0.25, TIME_STEPPING, "Courant number: dt <= cfl h / (c0 + v_max + v_wall) (WCSPH) or "
                         "cfl h / (v_max + v_wall) (DFSPH, no sound speed), v_wall the vessel walls' speed.", "",
                         0.0, 0.6, lo_open=True)
    viscous_time_step: ViscousTimeStep = setting(
        ViscousTimeStep.MEASURED_APPROACH, TIME_STEPPING, "The approach speed w at which the artificial viscosity's "
        "time-step criterion dt <= 0.125 h^2 / (nu + alpha h v_sig / (2 (dim + 2))) takes the velocity scale v_sig = "
        "c + b w (b = 0, so that w has no effect, under DFSPH's 'sound_speed' without artificial_viscosity_beta): "
        "'planned_approach', the fastest approach the planned flow allows, two particles head on at the CFL condition's flow speed (at least "
        "max_expected_speed) or one against the walls; 'measured_approach', the fastest the last interval's largest "
        "particle speed v_max allows, max(2 v_max, v_max + v_wall), with no floor: the criterion follows the "
        "approaches the liquid has, as Monaghan (1997)'s dt <= C h / max v_sig,ij does, the default "
        "(docs/artificial_viscosity.md).")
    adaptive_time_step: bool = setting(True, TIME_STEPPING, "True: every interval plans its step from the previous "
                                       "interval's largest speed and acceleration and the walls' speed (the CFL "
                                       "condition plus the force criterion). False: one fixed step for the whole run "
                                       "from max_expected_speed alone (fixed_time_step): nothing is measured to plan "
                                       "it, nothing shortens it when the flow or the walls outrun the expectation.")
    # ---- guards: what declares a run unstable
    max_density_error: float = setting(0.3, GUARDS, "Compression (rho - rho0) / rho0 above which the run is unstable. "
                                       "An impact compresses the liquid by about v / c0 (the acoustic pressure "
                                       "rho c0 v), 10 % at c0 = 10 v_max, so 0.3 flags only what is no longer a "
                                       "pressure (DualSPHysics's +-30 % range).", "", 0.0, 1.0, lo_open=True)
    max_wall_penetration: float = setting(0.5, GUARDS, "Penetration into a wall, in spacings dx, above which the run "
                                          "is unstable; shallower contacts are corrected by the non-penetration guard "
                                          "and counted.", "", 0.0, 10.0, lo_open=True)
    min_time_step: float = setting(1.0e-7, GUARDS, "A planned time step below this is an instability.", "s",
                                   0.0, 1.0e-3, lo_open=True)
    max_energy_creation: float = setting(0.25, GUARDS, "Energy the numerics may create, in units of M g L (liquid "
                                         "mass M, L the tallest vessel's inner height), before the run is unstable "
                                         "(cosim.fluid.energy): a quarter of lifting the whole liquid by the vessel's "
                                         "height. Not zero: the symplectic step is not energy-exact under impulsive "
                                         "wall loads (docs/stability.md).", "", 0.0, 10.0, lo_open=True)
    # ---- runtime: how the work is done, not what is computed
    cpu_threads: int = setting(0, RUNTIME, "Threads a CPU substep is split over (cosim.fluid.lanes: each takes every "
                               "n-th chunk of 16 particles in cell order, the same results to the bit for any number); "
                               "0: one per core this process may run on, at most one per 200 particles. Ignored on "
                               "CUDA.", "", 0, 256)
    grid_reset: GridReset = setting(GridReset.OCCUPIED, RUNTIME, "Which neighbour-grid cells are reset before each "
                                    "build: 'occupied', the cells the liquid and walls occupied (O(particles)), or "
                                    "'whole', every cell of the domain (O(cells)); the same neighbours either way.")

    def __post_init__(self) -> None:
        check_settings(self, "fluid")
        if self.artificial_viscosity_beta is not None:
            if self.alpha <= 0.0:
                raise InputError(
                    "fluid.artificial_viscosity_beta: needs Monaghan's alpha above 0 (the kernel's approach term is "
                    f"alpha times beta / alpha), got artificial_viscosity {self.alpha:g}"
                )
            if not self.one_alpha_for_all_liquid:
                raise InputError(
                    "fluid.artificial_viscosity_beta: needs one alpha for all liquid (the kernel's approach term is "
                    "each pair's alpha times beta / alpha, so a free-liquid alpha would scale beta with it): set "
                    f"fluid.free_artificial_viscosity to the bulk's {self.alpha:g} (it is {self.free_liquid_alpha:g}) or "
                    "free_liquid = false"
                )
        if self.wall_model is WallModel.SIDED and self.pressure_solver is not PressureSolver.WCSPH:
            raise InputError("fluid.wall_model: 'sided' is for pressure_solver 'wcsph' (DFSPH's wall constraint sums each "
                             f"wall particle's whole support), got pressure_solver '{self.pressure_solver.value}'")
        for axis in range(3):
            if self.domain_max[axis] - self.domain_min[axis] < 4.0 * self.support_radius:
                raise InputError(
                    f"fluid.domain_max[{axis}]: must exceed domain_min[{axis}] by at least 4 smoothing supports "
                    f"({4.0 * self.support_radius:g} m), got {self.domain_min[axis]:g} .. {self.domain_max[axis]:g}"
                )

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
    def tension_limit(self) -> float:
        """Pa, the most tension WCSPH's equation of state gives: ``max_tension`` under the 'clamp' treatment; none
        (infinite) under the plain symmetric sum, and under tensile-instability control, whose pressure gradient
        keeps tension from clumping particles."""
        return self.max_tension if self.tension_treatment is TensionTreatment.CLAMP else math.inf

    # The settings left unset (None) stay unset in the fields and resolve here, for the solver and iteration in
    # effect, so that dataclasses.replace with another solver or iteration resolves them for that one.
    @property
    def alpha(self) -> float:
        """Monaghan's alpha of the bound liquid: ``artificial_viscosity``, or where unset the velocity scale's own
        (:data:`DEFAULT_ARTIFICIAL_VISCOSITY`; WCSPH's scale is c0 either way)."""
        if self.artificial_viscosity is not None:
            return self.artificial_viscosity
        scale = ArtificialViscosityScale.SIGNAL_VELOCITY if self.signal_velocity_viscosity else ArtificialViscosityScale.SOUND_SPEED
        return DEFAULT_ARTIFICIAL_VISCOSITY[scale]

    @property
    def free_liquid_rule_in_effect(self) -> FreeLiquidRule:
        """Where liquid may become free: ``free_liquid_rule``, or where unset :data:`DEFAULT_FREE_LIQUID_RULE`."""
        return DEFAULT_FREE_LIQUID_RULE if self.free_liquid_rule is None else self.free_liquid_rule

    @property
    def density_solve_tolerance(self) -> float:
        """The density solve's stopping tolerance (fraction of rho0): ``density_tolerance``, or where unset the
        iteration's own (:data:`DEFAULT_DENSITY_TOLERANCE`)."""
        return DEFAULT_DENSITY_TOLERANCE[self.density_iteration] if self.density_tolerance is None else self.density_tolerance

    @property
    def free_liquid_alpha(self) -> float:
        """Monaghan's alpha of pairs with free liquid: ``free_artificial_viscosity``; where unset, the one alpha under
        the signal velocity and under WCSPH, :data:`SOUND_SPEED_FREE_ARTIFICIAL_VISCOSITY` under DFSPH's c0."""
        if self.free_artificial_viscosity is not None:
            return self.free_artificial_viscosity
        one_alpha = self.signal_velocity_viscosity or self.pressure_solver is PressureSolver.WCSPH
        return self.alpha if one_alpha else SOUND_SPEED_FREE_ARTIFICIAL_VISCOSITY

    @property
    def quadratic_viscosity(self) -> float | None:
        """Monaghan's quadratic coefficient beta in effect: ``artificial_viscosity_beta`` where set; where unset,
        :data:`WCSPH_ARTIFICIAL_VISCOSITY_BETA` under WCSPH with one alpha above 0 for all liquid (the kernel scales
        the approach term with each pair's alpha), otherwise none."""
        if self.artificial_viscosity_beta is not None:
            return self.artificial_viscosity_beta
        if self.pressure_solver is PressureSolver.WCSPH and self.alpha > 0.0 and self.one_alpha_for_all_liquid:
            return WCSPH_ARTIFICIAL_VISCOSITY_BETA
        return None

    @property
    def one_alpha_for_all_liquid(self) -> bool:
        """Whether every pair takes the bulk's alpha: no free liquid, or free liquid at the bulk's alpha (what a
        quadratic term beta needs, since the kernel scales its approach term with each pair's alpha)."""
        return not self.free_liquid or self.free_liquid_alpha == self.alpha

    @property
    def signal_velocity_viscosity(self) -> bool:
        """Whether the artificial viscosity's velocity scale is Monaghan (1997)'s signal velocity of an
        incompressible liquid under gravity (DFSPH with ``artificial_viscosity_scale`` 'signal_velocity') rather
        than c0 (WCSPH's equation of state has the physical signal speed c0, which it keeps)."""
        return self.artificial_viscosity_scale is ArtificialViscosityScale.SIGNAL_VELOCITY and self.pressure_solver is PressureSolver.DFSPH

    @property
    def viscosity_speed(self) -> float:
        """m/s, the part c of the artificial viscosity's velocity scale v_sig = c + beta max(0, -v_ij . r_ij / |r_ij|)
        every pair has: c0, or for the signal velocity sqrt(|g| h), the speed of gravity waves of wavenumber 1/h."""
        return math.sqrt(self.gravity_magnitude * self.smoothing_length) if self.signal_velocity_viscosity else self.sound_speed

    @property
    def viscosity_approach_weight(self) -> float:
        """b of the velocity scale c + b w (:attr:`viscosity_speed`), which the kernel multiplies by alpha: Monaghan's
        quadratic coefficient over alpha, :attr:`quadratic_viscosity` / alpha where there is one; otherwise 0 with c0
        and :data:`APPROACH_WEIGHT` with the signal velocity (there alpha b = 2 alpha is the quadratic coefficient)."""
        beta = self.quadratic_viscosity
        if beta is not None:
            return beta / self.alpha
        return APPROACH_WEIGHT if self.signal_velocity_viscosity else 0.0

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


FluidConfig.__doc__ += "\n\n" + textwrap.indent(settings_reference(FluidConfig, GROUPS), "    ")