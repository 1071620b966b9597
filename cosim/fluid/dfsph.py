"""Divergence-free SPH stages (warp kernels): Bender & Koschier (2015, SCA; 2017, IEEE TVCG).

Incompressibility is enforced by two iterative solves per substep instead of a stiff equation of state, so the
time step follows the flow speed (CFL on particle and wall speed) rather than an artificial speed of sound.
A substep, after the neighbour search:

  compute_density_factor   the substep's pair list (liquid and wall neighbours with their kernel gradients, which
                           every later stage loops over instead of searching the cell grid again: one search per
                           substep);
                           rho_i = (sum_j m_j W_ij + sum_b rho0 V_b W_ib) / s (summation density, wall particles
                           included; s = the sum over a resting lattice / rho0, 1.005 for Wendland C2 at h = 1.5 dx
                           in 2-D, so the liquid as seeded is at rest instead of 0.5 % compressed), plus the bound
                           liquid's surface offset (the density the continuity equation carries to the rows short
                           of a full support, :func:`surface_offset`; or the seeded deficiency,
                           :func:`bound_or_free_density`), and the DFSPH
                           factor alpha_i = rho_i / (|sum_j m_j grad W_ij + sum_b rho0 V_b grad W_ib|^2
                           + sum_j m_i m_j |grad W_ij|^2) (denominator bounded below; m_j: each particle's
                           own mass, ``cosim.fluid.model``); starts the divergence solve.
  compute_wall_density_factor  the same for the wall layer that faces the liquid (below).
  divergence solve         iterate [apply_stiffness, compute_solve_error, compute_wall_solve_error,
                           check_convergence] until the average
                           compressing density rate times dt is below ``divergence_tolerance`` rho0 and no
                           particle's above MAX_PARTICLE_RESIDUAL (or the iteration cap).
  compute_nonpressure      v* = v + dt (gravity + viscosity); starts the density solve (warm start); for the
                           Gauss-Seidel solve, list_sweep_cells lists each sweep thread's cells beside it.
  density solve            on the predicted density rho_i + dt Drho_i/Dt until its average compression is below
                           ``density_tolerance`` rho0 (and no particle's above MAX_PARTICLE_RESIDUAL): by
                           Gauss-Seidel sweeps (``density_iteration`` 'gauss_seidel', the default: the warm start
                           applied by apply_stiffness, then gauss_seidel_density_sweep once per cell colour and
                           check_convergence, repeated) or by the divergence solve's Jacobi iteration ('jacobi').
  compute_wall_reaction    the liquid's force on each vessel from exactly the pair forces its wall particles
                           exerted in both solves (Newton's third law), per particle, reduced later in fixed order.
  integrate                x += dt v*, then the shared wall guard, deactivation and diagnostics.

One Gauss-Seidel step of a particle: the same increment from its error as the velocities are at that moment,
applied to it and its neighbours at once (:func:`relax_liquid_density`, :func:`relax_wall_density`).

One Jacobi iteration, for stiffness increments k_i (m^2/s^2, a pressure over density p / rho):
  k_i = omega max(e_i, 0) alpha_i / dt^2, with e_i = dt Drho_i/Dt (divergence) or rho_i - rho0 + dt Drho_i/Dt (density),
  omega = min(1, JACOBI_GAIN_LIMIT / gain) (``cosim.fluid.params``; the gain of the lattice's pressure system,
  ``cosim.fluid.sph_kernels.lattice_jacobi_gain``: 1 for the 2-D default, 0.56 in 3-D, where plain Jacobi diverges),
  Drho_i/Dt = sum_j m_j (v_i - v_j) . grad W_ij + sum_b rho0 V_b (v_i - v_b) . grad W_ib   (wall velocity v_b: the
  moving vessel enters the divergence term),
  v_i -= dt [sum_j m_j (k_i / rho_i + k_j / rho_j) grad W_ij + sum_b rho0 V_b (k_i / rho_i + k_b / rho_b) grad W_ib].
Only compression is corrected (e_i >= 0): a free surface's kernel deficiency is not a pressure. The divergence solve
removes every compressing rate, or with ``divergence_constraint`` 'past_rest_density' only the part that would carry
the particle past rest density within the step (:func:`divergence_error`).

Pressure-carrying walls (Band et al. 2018 solve boundary pressures with the liquid's; this is that idea in DFSPH's
constraint form): the layer of dummy wall particles that faces the liquid (``FluidModel.b_wetted``) is held to rest
density like liquid that does not move, each wall particle b with its own stiffness k_b (its density rate sum_j m_j
(v_b - v_j) . grad W_bj from the liquid moving against the wall, its factor from the density change its push on the
liquid causes, warm-started as the liquid's). The force on the liquid stays the transpose of the constraints'
gradient, so the solve is stable. A wall term carrying only the particle's own stiffness (as SPlisHSPlasH's Akinci
boundary; ``FluidConfig.wall_pressure`` 'mirrored', which leaves the layer's stages out and its stiffness at zero,
``cosim.fluid.dfsph_step.solved_wall_layer``) lets the constant part of the pressure push the rows next to a wall
onto it, and the column settles low (a thin wall cannot hold them off at all); mirroring the particle's pressure
onto the wall is not a constraint gradient and blows a resting column up (the measurements:
docs/physics-and-validation.md, Design notes). The deeper layers lack the layers beyond the last in their kernel
support, so they only contribute density. A wall thinner than the support lacks those layers behind its facing one
too: liquid resting against it sums it to 0.79 rho0 (one layer), so held to rho0 it is never compressed and carries
nothing; ``FluidConfig.wall_pressure`` 'solved_rest_sum' holds each of its particles to that rest sum instead (its
summation density plus ``FluidModel.b_rest_offset``, as the liquid's surface rows keep their seeded deficiency). The
stiffness each particle applied over both solves, kappa_i, is kept: it gives the reported pressure p_i = rho_i
kappa_i (the pressure whose impulse acted over dt; reported as its average over the interval), the wall reaction,
and the warm start of the next substep.

The stopping test reads one int32 flag that ``check_convergence`` writes on the device, driven by
``wp.capture_while``: captured, it becomes a conditional graph node on CUDA and a while operation of warp's
operation stream on the CPU; launched one by one, warp reads the flag each iteration (on CUDA through a copy to
the host). Captured and launched one by one, CUDA runs give the same results to the bit
(``python -m cosim.bench.device_check``; docs/benchmarks.md, On the GPU).
The average error is summed as integers (quanta of ``ERROR_QUANTUM``) so it does not depend on the order of the atomic adds: the
iteration count, and with it the trajectory, is deterministic on every device.

Diagnostics: ``max_density_error`` and ``max_compression`` are the compression max(rho - rho0, 0) / rho0 of the
density the solves hold the particle to (:func:`bound_or_free_density`) at the substep's start (the state the
previous substep left), ``max_acceleration`` is that of the non-pressure forces; the solves' final errors and
iteration counts have their own fields.
"""

from __future__ import annotations

import warp as wp

from cosim.fluid.boundary import VesselGeometry, VesselMotion
from cosim.fluid.diagnostics import (
    DIAG_DENSITY_ITERATIONS,
    DIAG_DENSITY_SOLVE_ERROR,
    DIAG_DIVERGENCE_ERROR,
    DIAG_DIVERGENCE_ITERATIONS,
    DIAG_MAX_ACCEL,
    DIAG_MAX_COMPRESSION,
    DIAG_MAX_DENSITY_ERROR,
    DIAG_PAIR_OVERFLOW,
)
from cosim.fluid.free_surface import FREE_AT_SURFACE, exposed_liquid, renormalisation_term, surface_indicator
from cosim.fluid.lanes import item_kernel
from cosim.fluid.neighbors import COINCIDENT_R2, GridSpec, Neighborhood, neighbor_cells, next_liquid_neighbor, next_wall_neighbor, reachable_cell, SEES_EVERY_WALL
from cosim.fluid.pair_slots import PairSlots, close_pair_row, open_pair_row
from cosim.fluid.params import SPHParams
from cosim.fluid.sph_common import (
    add_wall_reaction,
    diag_slot,
    finish_particle,
    kernel_gradient,
    next_free_state,
    pair_wall,
    summation_term,
    viscous_pair,
    wall_mass,
    wall_pair,
)
from cosim.fluid.sph_kernels import kernel_w

# Warm starts (Bender & Koschier 2017, Sec. 4.3): each solve starts from a fraction of the stiffness it applied in
# the previous substep. Only compression is corrected, so a warm start can never be taken back within a substep:
# a large fraction ratchets the pressure up (density 0.8: a shaken tank splashes over its rim; 0.95 and 1.0: it
# blows up), a small one leaves the whole hydrostatic load to the Jacobi iterations. The divergence warm start trades
# the motion left in a resting column against the error of the shallow slosh frequency (Eq. 17 of Camporredondo et
# al. 2019): a smaller fraction calms the column and lowers the frequency. 0.5 for both, as SPlisHSPlasH (the
# fractions compared: docs/tuning.md).
WARM_START_DENSITY = wp.constant(0.5)
WARM_START_DIVERGENCE = wp.constant(0.5)
# Relative errors are summed as integers of this size (deterministic order-free sum; 1e-9 of rho0 resolves a
# 1e-5 tolerance to 1e-4 and keeps a million particles of error <= 1 within int64).
ERROR_QUANTUM = wp.constant(1.0e-9)
MAX_PARTICLE_ERROR = wp.constant(1.0)
# Besides the average (Bender & Koschier's criterion), no particle may keep more than this relative error: an
# impact compresses a few particles among many, which the average alone lets through (a jet landing in the catcher
# at 4 m/s: the solve stops after one iteration and the landing particles blow up). 1 % is the density
# error the weakly compressible solver is held to.
MAX_PARTICLE_RESIDUAL = wp.constant(0.01)
# The factor's denominator is kept above this fraction of that of a particle inside a resting lattice: with few
# neighbours (spray, a particle landing on another: the kernel gradient vanishes as r -> 0) it tends to zero, the
# linearised factor to infinity, and a tiny compression would give a kick that blows the pair apart (as the pour's
# jet landing in the catcher does). Such particles get a softer, under-relaxed push instead.
MIN_FACTOR_DENOMINATOR = wp.constant(0.25)

# The wall layer's Jacobi increments are halved: a liquid particle's constraint and its wall neighbours' measure the
# same approach, and both correcting it in full overshoots: tilted and shaken tanks create energy and the pour
# spills; halved, neither does and the validation errors stay as they are (docs/tuning.md).
WALL_RELAXATION = wp.constant(0.5)
# rest_offset of a particle whose first substep has not run yet under initial_state 'seeded' (kg/m^3; any real offset
# is >= 0)
UNSEEDED_OFFSET = wp.constant(-1.0)

# FluidConfig.surface_density as the kernels take it (an int argument)
SURFACE_SEEDED_OFFSET = wp.constant(0)
SURFACE_CONTINUITY = wp.constant(1)
# Marrone et al. (2010): a particle whose free-surface indicator is at or above 0.75 has a full kernel support (their
# scan test examines only those below); its summation density is the liquid's density there. For the square lattice
# at h = 1.5 dx: the top row 0.499, the second 0.842 (2-D; cosim.fluid.free_surface).
FULL_SUPPORT_INDICATOR = wp.constant(0.75)

SOLVE_DIVERGENCE = 0
SOLVE_DENSITY = 1
# Colours of the Gauss-Seidel density sweep by dimension (:func:`cell_color`)
CELL_COLORS = {2: 9, 3: 27}

# solve_stats (int64): error sum (quanta), active particle count, iterations of the current solve, largest error
STAT_ERROR = wp.constant(0)
STAT_COUNT = wp.constant(1)
STAT_ITERATIONS = wp.constant(2)
STAT_MAX_ERROR = wp.constant(3)
# Each lane's row of solve_stats holds those 4 fields padded to this many int64 (128 bytes: two cache lines, as the
# CPU's adjacent-line prefetch fetches them): every particle adds to its lane's row atomically, and two lanes' rows in
# one cache line would pass it back and forth between the cores on every add (false sharing; docs/tuning.md).
STATS_ROW_STRIDE = 16


@wp.func
def stat_slot(prm: SPHParams, item: int, field: int) -> int:
    """Where ``item`` adds to ``field`` in its lane's row of solve_stats: its replica's copy (replicas padded to
    :data:`STATS_ROW_STRIDE`; ``cosim.fluid.device_layout``: one replica on the CPU, the row itself). The fields
    are integers, so the sums are the same in any order and for any number of replicas."""
    return (item % prm.atomic_replicas) * STATS_ROW_STRIDE + field


@wp.func
def surface_offset(carried: float, summation: float, indicator: float) -> float:
    """``FluidConfig.surface_density`` 'continuity': the offset (kg/m^3) that holds a particle short of a full kernel
    support (free-surface ``indicator`` below FULL_SUPPORT_INDICATOR) to the density ``carried`` to it by the
    continuity equation, rho_i(t + dt) = rho_i(t) + dt Drho_i/Dt (:func:`carry_density`), and never below its
    summation density; none with a full support, where the summation density is the liquid's (kg/m^3 in, offset out).
    The surface rows' kernel deficiency is then not a memory of the seeding but the difference between the two
    densities, which follows the particle wherever the surface takes it (continuity is what keeps free-surface
    particles at rho0 in weakly compressible SPH: Colagrossi & Landrini 2003, J. Comput. Phys. 191)."""
    if indicator < FULL_SUPPORT_INDICATOR:
        return wp.max(carried - summation, 0.0)
    return 0.0


@wp.func
def bound_or_free_density(
    prm: SPHParams,
    vessels: wp.array(dtype=VesselGeometry),
    motions: wp.array(dtype=VesselMotion),
    free_liquid: int,
    i: int,
    xi: wp.vec3,
    summation: float,
    indicator: float,
    threshold: float,
    free: wp.array(dtype=wp.int32),
    rest_offset: wp.array(dtype=float),
) -> float:
    """The density the solves hold particle i to (kg/m^3), from its summation density ``summation`` (over a resting
    lattice's). With ``surface_density`` 'continuity' the offset is :func:`surface_offset`'s, written this substep.
    With 'seeded_offset' and ``initial_state`` 'seeded', a particle's first substep stores the kernel deficiency it was
    seeded with, max(rho0 - summation, 0), as its ``rest_offset``: the seeded liquid is at rest, so its surface rows,
    short of neighbours above, are held at the spacing they were seeded with instead of sinking until their sums
    reach rho0 (without it a resting column's top rows merge below their spacing). With 'relaxed' every offset is 0
    from the start (``cosim.fluid.dfsph_step.DFSPHStep.initialise``): standard DFSPH, the surface rows settle before
    t = 0 (``cosim.fluid.relaxation``). Bound liquid is held to summation + offset; free liquid
    (WCSPH's rules, ``cosim.fluid.wcsph.update_free_liquid``; ``free_liquid`` the rule's mode,
    ``cosim.fluid.free_surface``, 0: all liquid stays bound) to its plain summation density: a bound particle where
    the rule lets liquid be free (outside every vessel, or at the free surface: its ``indicator`` below
    ``threshold``) becomes free once separated (summation below rho0), a free one bound again, with no offset, when
    packed (summation >= rho0) where the rule no longer holds. (Only
    compression is corrected, so neither has tension.) Updates ``free[i]`` and ``rest_offset[i]``."""
    offset = rest_offset[i]
    if offset == UNSEEDED_OFFSET:
        offset = wp.max(prm.rest_density - summation, 0.0)
        rest_offset[i] = offset
    if free_liquid != 0:
        state = next_free_state(free[i], exposed_liquid(prm, vessels, motions, free_liquid, xi, indicator, threshold), summation, prm.rest_density)
        if free[i] != 0 and state == 0:
            offset = 0.0
            rest_offset[i] = 0.0
        free[i] = state
    if free[i] != 0:
        return summation
    return summation + offset


@item_kernel
def compute_density_factor(
    # Model
    prm: SPHParams,
    vessels: wp.array(dtype=VesselGeometry),
    b_volume: wp.array(dtype=float),
    capacity: int,
    free_liquid: int,
    threshold: float,
    surface_density: int,
    # State in
    motions: wp.array(dtype=VesselMotion),
    nb: Neighborhood,
    active: wp.array(dtype=wp.int32),
    mass: wp.array(dtype=float),
    row: wp.array(dtype=wp.int32),
    # State in/out
    kappa_divergence: wp.array(dtype=float),
    free: wp.array(dtype=wp.int32),
    rest_offset: wp.array(dtype=float),
    # Out
    rho: wp.array(dtype=float),
    alpha: wp.array(dtype=float),
    increment: wp.array(dtype=float),
    increment_per_rho: wp.array(dtype=float),
    pair_count: wp.array(dtype=wp.int32),
    pair_slots: PairSlots,
    pair_index: wp.array(dtype=wp.int32),
    pair_grad: wp.array(dtype=wp.vec3),
    pair_mass_grad: wp.array(dtype=wp.vec3),
    indicator: wp.array(dtype=float),
    solve_stats: wp.array(dtype=wp.int64),
    keep_going: wp.array(dtype=wp.int32),
    diag_f: wp.array2d(dtype=float),
    diag_i: wp.array2d(dtype=wp.int32),
):
    """Summation density, DFSPH factor (for particles of different masses, alpha_i = rho_i / (|sum_j m_j grad W_ij|^2
    + sum_j m_i m_j |grad W_ij|^2): neighbour j moves by m_i (k_i / rho_i) grad W_ij under i's stiffness) and the
    substep's pair list (entry k at slot s of particle i's ``pair_slots``, ``cosim.fluid.pair_slots``; ``pair_index[s]``:
    neighbour j >= 0 or wall code :func:`wall_pair`; ``pair_grad[s]``: grad_i W, 1/m^(dim+1); ``pair_mass_grad[s]``: the same times the
    pair's mass, m_j or rho0 V_b, as the solves use it), which the later stages loop over instead of the cell grid;
    the divergence solve's warm start (increment = a fraction of the last substep's stiffness, applied by the first
    iteration; ``increment_per_rho`` = increment / rho, as the neighbours read it) and its counters. More than
    ``capacity`` neighbours (impossible below ~2x compression) count as an overflow, an instability. Under the
    'free_surface' rule (``free_liquid`` = FREE_AT_SURFACE) also each particle's free-surface indicator, from the same
    walk (``indicator``, ``cosim.fluid.free_surface``). Under ``surface_density`` SURFACE_CONTINUITY also the
    indicator, and ``rho`` holds on entry the density carried to the particle (:func:`surface_offset`)."""
    i = wp.tid()
    if i == 0:
        solve_stats[STAT_ITERATIONS] = wp.int64(0)
        keep_going[0] = 1
    warm = WARM_START_DIVERGENCE * kappa_divergence[i]
    kappa_divergence[i] = 0.0
    pair_count[i] = 0
    first = open_pair_row(pair_slots, i)
    if active[i] == 0:
        rho[i] = prm.rest_density
        alpha[i] = 0.0
        increment[i] = 0.0
        increment_per_rho[i] = 0.0
        return
    wp.atomic_add(solve_stats, stat_slot(prm, i, STAT_COUNT), wp.int64(1))
    xi = nb.x[i]
    mi = mass[i]
    density = mi * kernel_w(0.0, prm.inv_h, prm.sigma, prm.kernel)
    grad_sum = wp.vec3(0.0)
    grad_sq = float(0.0)
    moment = wp.mat33(0.0)
    count = int(0)
    radius2 = prm.support * prm.support
    with_indicator = free_liquid == FREE_AT_SURFACE or surface_density == SURFACE_CONTINUITY
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
            mj = mass[j]
            density += summation_term(prm, mj, r2)
            gw = kernel_gradient(prm, r, r2)
            gm = mj * gw
            if with_indicator:
                moment += renormalisation_term(mj / prm.rest_density, r, gw)
            grad_sum += gm
            grad_sq += wp.dot(gm, gm) * (mi / mj)  # m_i m_j |grad W|^2: j's push from i's stiffness
            if count < capacity:
                slot = first + count * pair_slots.step
                pair_index[slot] = j
                pair_grad[slot] = gw
                pair_mass_grad[slot] = gm
            count += 1
            j = next_liquid_neighbor(nb.x, j + 1, liquid_end, xi, radius2, COINCIDENT_R2)
        wall_end = nb.b_cell_end[cell]
        item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, nb.b_cell_start[cell], wall_end, xi, SEES_EVERY_WALL, radius2, COINCIDENT_R2)
        while item < wall_end:
            b = nb.b_order[item]
            r = xi - nb.bx[b]
            r2 = wp.dot(r, r)
            mb = wall_mass(prm, b_volume, b)
            density += summation_term(prm, mb, r2)
            gw = kernel_gradient(prm, r, r2)
            gm = mb * gw
            if with_indicator:
                moment += renormalisation_term(mb / prm.rest_density, r, gw)
            grad_sum += gm
            if count < capacity:
                slot = first + count * pair_slots.step
                pair_index[slot] = wall_pair(b)
                pair_grad[slot] = gw
                pair_mass_grad[slot] = gm
            count += 1
            item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, item + 1, wall_end, xi, SEES_EVERY_WALL, radius2, COINCIDENT_R2)
    if count > capacity:
        wp.atomic_add(diag_i, diag_slot(prm, row[0], i), DIAG_PAIR_OVERFLOW, 1)
    pair_count[i] = wp.min(count, capacity)
    close_pair_row(pair_slots, i, first, pair_count[i])
    lam = float(0.0)
    if with_indicator:
        lam = surface_indicator(prm.dim, moment)
        indicator[i] = lam
    summation = density / prm.lattice_density
    if surface_density == SURFACE_CONTINUITY:
        rest_offset[i] = surface_offset(rho[i], summation, lam)
    density = bound_or_free_density(prm, vessels, motions, free_liquid, i, xi, summation, lam, threshold, free, rest_offset)
    denominator = wp.max(wp.dot(grad_sum, grad_sum) + grad_sq, MIN_FACTOR_DENOMINATOR * prm.lattice_factor_denominator)
    rho[i] = density
    alpha[i] = density / denominator
    increment[i] = warm
    increment_per_rho[i] = warm / density
    compression = wp.max(density - prm.rest_density, 0.0) / prm.rest_density
    wp.atomic_max(diag_f, diag_slot(prm, row[0], i), DIAG_MAX_DENSITY_ERROR, compression)
    wp.atomic_max(diag_f, diag_slot(prm, row[0], i), DIAG_MAX_COMPRESSION, compression)


@wp.func
def error_quanta(relative: float) -> wp.int64:
    """A constraint's relative error (capped at MAX_PARTICLE_ERROR) in ERROR_QUANTUM units, as the solves sum it."""
    return wp.int64(wp.min(relative, MAX_PARTICLE_ERROR) / ERROR_QUANTUM + 0.5)


@wp.func
def divergence_error(prm: SPHParams, past_rest: int, rate_error: float, rho: float) -> float:
    """The density-rate error the divergence solve removes from particle i (kg/m^3), from ``rate_error`` = dt
    Drho_i/Dt and the density ``rho`` the solves hold it to. Bender & Koschier (2017) remove every compressing rate,
    max(rate_error, 0): the velocities are made divergence-free wherever they compress. Where rho < rho0 the density
    constraint rho <= rho0 (the density solve's, compression only) is not active, and holding the rate at zero
    there keeps the particle at the density it has: a loose packing never closes. With ``past_rest`` (FluidConfig
    divergence_constraint 'past_rest_density') only the rate past that slack is removed,
    max(rate_error - max(rho0 - rho, 0), 0): a particle at or above rest density is treated as before, a rarefied one
    may close by its shortfall within the step (SPlisHSPlasH skips the divergence solve outright for a particle short
    of neighbours, fewer than 7 in 2-D and 20 in 3-D; here the density itself measures the deficiency)."""
    if past_rest != 0:
        return wp.max(rate_error - wp.max(prm.rest_density - rho, 0.0), 0.0)
    return wp.max(rate_error, 0.0)


@wp.func
def liquid_density_rate(
    i: int,
    v: wp.array(dtype=wp.vec3),
    bv: wp.array(dtype=wp.vec3),
    pair_count: wp.array(dtype=wp.int32),
    pair_slots: PairSlots,
    pair_index: wp.array(dtype=wp.int32),
    pair_mass_grad: wp.array(dtype=wp.vec3),
) -> float:
    """Drho_i/Dt = sum_j m_j (v_i - v_j) . grad W_ij + sum_b rho0 V_b (v_i - v_b) . grad W_ib over liquid particle i's
    pair list, from the velocities as they are (kg/m^3/s)."""
    vi = v[i]
    rate = float(0.0)
    first = pair_slots.start[i]
    for k in range(pair_count[i]):
        s = first + k * pair_slots.step
        j = pair_index[s]
        vj = wp.vec3(0.0)
        if j >= 0:
            vj = v[j]
        else:
            vj = bv[pair_wall(j)]
        rate += wp.dot(vi - vj, pair_mass_grad[s])
    return rate


@wp.func
def wall_density_rate(
    b: int,
    v: wp.array(dtype=wp.vec3),
    bv: wp.array(dtype=wp.vec3),
    b_pair_count: wp.array(dtype=wp.int32),
    b_pair_slots: PairSlots,
    b_pair_index: wp.array(dtype=wp.int32),
    b_pair_mass_grad: wp.array(dtype=wp.vec3),
) -> float:
    """Drho_b/Dt = sum_j m_j (v_b - v_j) . grad W_bj over wall-layer particle b's liquid neighbours (kg/m^3/s)."""
    vb = bv[b]
    rate = float(0.0)
    first = b_pair_slots.start[b]
    for k in range(b_pair_count[b]):
        s = first + k * b_pair_slots.step
        rate += wp.dot(vb - v[b_pair_index[s]], b_pair_mass_grad[s])
    return rate


@item_kernel
def apply_stiffness(
    # State in
    increment: wp.array(dtype=float),
    increment_per_rho: wp.array(dtype=float),
    active: wp.array(dtype=wp.int32),
    dt: wp.array(dtype=float),
    pair_count: wp.array(dtype=wp.int32),
    pair_slots: PairSlots,
    pair_index: wp.array(dtype=wp.int32),
    pair_mass_grad: wp.array(dtype=wp.vec3),
    b_increment_per_rho: wp.array(dtype=float),
    # State in/out
    v: wp.array(dtype=wp.vec3),
    kappa: wp.array(dtype=float),
):
    """v_i -= dt [sum_j m_j (k_i/rho_i + k_j/rho_j) grad W_ij + sum_b rho0 V_b (k_i/rho_i + k_b/rho_b) grad W_ib]
    (k_b: the wall layer's increment, zero for the deeper wall particles; k / rho read from ``increment_per_rho``,
    which the stage that set the increments wrote); kappa_i += k_i. The first iteration of a solve applies its warm
    start; once a solve has converged, the increments its last iteration measured are not applied (the loop ends
    before this stage)."""
    i = wp.tid()
    if active[i] == 0:
        return
    ki = increment_per_rho[i]
    dv = wp.vec3(0.0)
    first = pair_slots.start[i]
    for k in range(pair_count[i]):
        s = first + k * pair_slots.step
        j = pair_index[s]
        kj = float(0.0)
        if j >= 0:
            kj = increment_per_rho[j]
        else:
            kj = b_increment_per_rho[pair_wall(j)]
        dv += (ki + kj) * pair_mass_grad[s]
    v[i] = v[i] - dt[0] * dv
    kappa[i] = kappa[i] + increment[i]


@item_kernel
def compute_solve_error(
    # Model
    prm: SPHParams,
    mode: int,
    past_rest: int,
    # State in
    v: wp.array(dtype=wp.vec3),
    rho: wp.array(dtype=float),
    alpha: wp.array(dtype=float),
    active: wp.array(dtype=wp.int32),
    dt: wp.array(dtype=float),
    bv: wp.array(dtype=wp.vec3),
    pair_count: wp.array(dtype=wp.int32),
    pair_slots: PairSlots,
    pair_index: wp.array(dtype=wp.int32),
    pair_mass_grad: wp.array(dtype=wp.vec3),
    # Out
    increment: wp.array(dtype=float),
    increment_per_rho: wp.array(dtype=float),
    solve_stats: wp.array(dtype=wp.int64),
):
    """Each particle's remaining error e_i (``mode`` SOLVE_DIVERGENCE: dt Drho/Dt, its compressing part or with
    ``past_rest`` the part past rest density, :func:`divergence_error`; SOLVE_DENSITY: rho_i - rho0 + dt Drho/Dt,
    only compression: e_i >= 0), its next stiffness increment omega e_i alpha_i / dt^2 (omega:
    ``prm.jacobi_relaxation``, 1 unless the support holds so many neighbours that plain Jacobi would diverge) and the
    error sum."""
    i = wp.tid()
    if active[i] == 0:
        increment[i] = 0.0
        increment_per_rho[i] = 0.0
        return
    h = dt[0]
    e = h * liquid_density_rate(i, v, bv, pair_count, pair_slots, pair_index, pair_mass_grad)
    if mode == SOLVE_DENSITY:
        e += rho[i] - prm.rest_density
        e = wp.max(e, 0.0)
    else:
        e = divergence_error(prm, past_rest, e, rho[i])
    k_i = prm.jacobi_relaxation * e * alpha[i] / (h * h)
    increment[i] = k_i
    increment_per_rho[i] = k_i / rho[i]
    quanta = error_quanta(e / prm.rest_density)
    wp.atomic_add(solve_stats, stat_slot(prm, i, STAT_ERROR), quanta)
    wp.atomic_max(solve_stats, stat_slot(prm, i, STAT_MAX_ERROR), quanta)


@wp.kernel
def check_convergence(
    # Model
    prm: SPHParams,
    mode: int,
    # State in
    row: wp.array(dtype=wp.int32),
    # State in/out
    solve_stats: wp.array2d(dtype=wp.int64),
    keep_going: wp.array(dtype=wp.int32),
    diag_f: wp.array2d(dtype=float),
    diag_i: wp.array2d(dtype=wp.int32),
):
    """One thread: average error of the iteration just measured (the lanes' sums added, their maxima compared:
    integers, so the same for any number of lanes), the stop decision, the solve's diagnostics. The iteration count
    is kept in lane 0's row."""
    count = wp.int64(0)
    error_sum = wp.int64(0)
    worst_quanta = wp.int64(0)
    for lane in range(solve_stats.shape[0]):
        count += solve_stats[lane, STAT_COUNT]
        error_sum += solve_stats[lane, STAT_ERROR]
        worst_quanta = wp.max(worst_quanta, solve_stats[lane, STAT_MAX_ERROR])
        solve_stats[lane, STAT_ERROR] = wp.int64(0)
        solve_stats[lane, STAT_MAX_ERROR] = wp.int64(0)
    error = float(error_sum) * ERROR_QUANTUM / float(wp.max(count, wp.int64(1)))
    worst = float(worst_quanta) * ERROR_QUANTUM
    iterations = solve_stats[0, STAT_ITERATIONS] + wp.int64(1)
    solve_stats[0, STAT_ITERATIONS] = iterations
    tolerance = prm.divergence_tolerance
    err_col = DIAG_DIVERGENCE_ERROR
    it_col = DIAG_DIVERGENCE_ITERATIONS
    if mode == SOLVE_DENSITY:
        tolerance = prm.density_tolerance
        err_col = DIAG_DENSITY_SOLVE_ERROR
        it_col = DIAG_DENSITY_ITERATIONS
    unconverged = error > tolerance or worst > MAX_PARTICLE_RESIDUAL
    keep_going[0] = wp.where(unconverged and iterations < wp.int64(prm.max_iterations), 1, 0)
    s = row[0] * prm.atomic_replicas  # replica 0 of the substep's row
    diag_f[s, err_col] = error
    diag_i[s, it_col] = int(iterations)


@item_kernel
def compute_wall_density_factor(
    # Model
    prm: SPHParams,
    b_volume: wp.array(dtype=float),
    b_wetted: wp.array(dtype=wp.int32),
    b_rest_offset: wp.array(dtype=float),
    capacity: int,
    # State in
    nb: Neighborhood,
    mass: wp.array(dtype=float),
    row: wp.array(dtype=wp.int32),
    # Out
    b_rho: wp.array(dtype=float),
    b_alpha: wp.array(dtype=float),
    b_pair_count: wp.array(dtype=wp.int32),
    b_pair_slots: PairSlots,
    b_pair_index: wp.array(dtype=wp.int32),
    b_pair_mass_grad: wp.array(dtype=wp.vec3),
    solve_stats: wp.array(dtype=wp.int64),
    diag_i: wp.array2d(dtype=wp.int32),
):
    """The pressure-carrying wall layer (``b_wetted``): each of its particles b is held to rest density like a
    liquid particle that does not move. Its summation density rho_b = (rho0 V_b W(0) + sum_j m_j W_bj + sum_b'
    rho0 V_b' W_bb') / s + o_b (o_b, ``b_rest_offset``: the shortfall of a thin wall's sum with liquid at rest,
    :func:`cosim.fluid.wall_sampling.wall_rest_offsets`, or zero), its factor alpha_b = rho_b / sum_j m_j rho0 V_b |grad W_bj|^2 (the density change its
    stiffness causes by pushing its liquid neighbours away; bounded below as the liquid's) and its list of liquid
    neighbours with m grad_b W. Other wall particles carry no stiffness (rho_b = rho0, no pairs)."""
    b = wp.tid()
    b_pair_count[b] = 0
    first = open_pair_row(b_pair_slots, b)
    b_rho[b] = prm.rest_density
    b_alpha[b] = 0.0
    if b_wetted[b] == 0:
        return
    mb = prm.rest_density * b_volume[b]
    density = mb * kernel_w(0.0, prm.inv_h, prm.sigma, prm.kernel)
    grad_sq = float(0.0)
    count = int(0)
    xb = nb.bx[b]
    radius2 = prm.support * prm.support
    cells = neighbor_cells(nb.spec, xb)
    for k in range(cells.count):
        cell = reachable_cell(nb, cells, k, xb, radius2)
        if cell < 0:
            continue
        liquid_end = nb.cell_end[cell]
        j = next_liquid_neighbor(nb.x, nb.cell_start[cell], liquid_end, xb, radius2, COINCIDENT_R2)
        while j < liquid_end:
            r = xb - nb.x[j]
            r2 = wp.dot(r, r)
            mj = mass[j]
            density += summation_term(prm, mj, r2)
            gw = kernel_gradient(prm, r, r2)
            grad_sq += mj * mb * wp.dot(gw, gw)
            if count < capacity:
                b_pair_index[first + count * b_pair_slots.step] = j
                b_pair_mass_grad[first + count * b_pair_slots.step] = mj * gw
            count += 1
            j = next_liquid_neighbor(nb.x, j + 1, liquid_end, xb, radius2, COINCIDENT_R2)
        wall_end = nb.b_cell_end[cell]
        item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, nb.b_cell_start[cell], wall_end, xb, SEES_EVERY_WALL, radius2, COINCIDENT_R2)
        while item < wall_end:
            other = nb.b_order[item]
            r = xb - nb.bx[other]
            r2 = wp.dot(r, r)
            density += summation_term(prm, wall_mass(prm, b_volume, other), r2)
            item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, item + 1, wall_end, xb, SEES_EVERY_WALL, radius2, COINCIDENT_R2)
    if count == 0:
        return
    if count > capacity:
        wp.atomic_add(diag_i, diag_slot(prm, row[0], b), DIAG_PAIR_OVERFLOW, 1)
    b_pair_count[b] = wp.min(count, capacity)
    close_pair_row(b_pair_slots, b, first, b_pair_count[b])
    density = density / prm.lattice_density + b_rest_offset[b]
    b_rho[b] = density
    b_alpha[b] = density / wp.max(grad_sq, MIN_FACTOR_DENOMINATOR * prm.lattice_factor_denominator)
    wp.atomic_add(solve_stats, stat_slot(prm, b, STAT_COUNT), wp.int64(1))


@item_kernel
def start_wall_solve(
    warm_start: float,
    warm_start_applied: int,
    # State in
    b_rho: wp.array(dtype=float),
    # State in/out
    b_kappa: wp.array(dtype=float),
    # Out
    b_increment: wp.array(dtype=float),
    b_increment_per_rho: wp.array(dtype=float),
):
    """A solve's warm start for the wall layer: a fraction of the stiffness it applied in the last substep (and
    that over the wall particle's density, as the liquid reads it). The Jacobi iteration counts the warm start into
    the stiffness when its first iteration has applied it (:func:`compute_wall_solve_error`); with
    ``warm_start_applied`` (the Gauss-Seidel density solve, whose warm start is applied before its sweeps) it
    counts from here."""
    b = wp.tid()
    warm = warm_start * b_kappa[b]
    b_increment[b] = warm
    b_increment_per_rho[b] = warm / b_rho[b]
    b_kappa[b] = wp.where(warm_start_applied != 0, warm, 0.0)


@item_kernel
def compute_wall_solve_error(
    # Model
    prm: SPHParams,
    mode: int,
    # State in
    v: wp.array(dtype=wp.vec3),
    dt: wp.array(dtype=float),
    bv: wp.array(dtype=wp.vec3),
    b_rho: wp.array(dtype=float),
    b_alpha: wp.array(dtype=float),
    b_pair_count: wp.array(dtype=wp.int32),
    b_pair_slots: PairSlots,
    b_pair_index: wp.array(dtype=wp.int32),
    b_pair_mass_grad: wp.array(dtype=wp.vec3),
    # State in/out
    b_kappa: wp.array(dtype=float),
    b_increment: wp.array(dtype=float),
    b_increment_per_rho: wp.array(dtype=float),
    solve_stats: wp.array(dtype=wp.int64),
):
    """The wall layer's side of one iteration: adds the increment the liquid just received from it to its
    stiffness, then its remaining error e_b (dt Drho_b/Dt, plus rho_b - rho0 in the density solve; compression
    only), with Drho_b/Dt = sum_j m_j (v_b - v_j) . grad W_bj, and its next increment omega e_b alpha_b / dt^2."""
    b = wp.tid()
    b_kappa[b] = b_kappa[b] + b_increment[b]
    n = b_pair_count[b]
    if n == 0:
        b_increment[b] = 0.0
        b_increment_per_rho[b] = 0.0
        return
    h = dt[0]
    e = h * wall_density_rate(b, v, bv, b_pair_count, b_pair_slots, b_pair_index, b_pair_mass_grad)
    if mode == SOLVE_DENSITY:
        e += b_rho[b] - prm.rest_density
    e = wp.max(e, 0.0)
    k_b = WALL_RELAXATION * prm.jacobi_relaxation * e * b_alpha[b] / (h * h)
    b_increment[b] = k_b
    b_increment_per_rho[b] = k_b / b_rho[b]
    quanta = error_quanta(e / prm.rest_density)
    wp.atomic_add(solve_stats, stat_slot(prm, b, STAT_ERROR), quanta)
    wp.atomic_max(solve_stats, stat_slot(prm, b, STAT_MAX_ERROR), quanta)


@wp.func
def cell_color(g: GridSpec, cell: int) -> int:
    """The colour of a grid cell for the Gauss-Seidel sweep: cells whose indices differ by a multiple of 3 on every
    axis share one (9 colours in 2-D, 27 in 3-D). Cells are one support wide, so a particle's pairs reach only the
    adjacent cells, and two cells of one colour, 3 apart, have no particle within reach of both."""
    cx = cell % g.nx
    cy = (cell // g.nx) % g.ny
    cz = cell // (g.nx * g.ny)
    return cx % 3 + 3 * (cz % 3) + 9 * (cy % 3)


@wp.func
def relax_liquid_density(
    prm: SPHParams,
    i: int,
    h: float,
    rho: wp.array(dtype=float),
    alpha: wp.array(dtype=float),
    bv: wp.array(dtype=wp.vec3),
    pair_count: wp.array(dtype=wp.int32),
    pair_slots: PairSlots,
    pair_index: wp.array(dtype=wp.int32),
    pair_mass_grad: wp.array(dtype=wp.vec3),
    mass: wp.array(dtype=float),
    v: wp.array(dtype=wp.vec3),
    kappa: wp.array(dtype=float),
) -> float:
    """One Gauss-Seidel step of liquid particle i's density constraint: its predicted compression e_i = rho_i - rho0
    + dt sum_j m_j (v_i - v_j) . grad W_ij from the velocities as they are now (compression only), the stiffness
    increment k_i = e_i alpha_i / dt^2 that removes it, added to kappa_i, and applied at once to i and to its liquid
    neighbours (v_i -= dt (k_i / rho_i) sum_j m_j grad W_ij, v_j += dt (k_i / rho_i) m_i grad W_ij: the k_i part of
    the Jacobi step's pair force, so the momentum exchanged is the same). Returns e_i / rho0."""
    e = wp.max(h * liquid_density_rate(i, v, bv, pair_count, pair_slots, pair_index, pair_mass_grad) + rho[i] - prm.rest_density, 0.0)
    if e == 0.0:
        return 0.0
    k_i = e * alpha[i] / (h * h)
    kappa[i] = kappa[i] + k_i
    push = h * k_i / rho[i]
    mi = mass[i]
    dv = wp.vec3(0.0)
    first = pair_slots.start[i]
    for k in range(pair_count[i]):
        s = first + k * pair_slots.step
        j = pair_index[s]
        gm = pair_mass_grad[s]
        dv += gm
        if j >= 0:
            v[j] = v[j] + (push * (mi / mass[j])) * gm  # gm carries m_j
    v[i] = v[i] - push * dv
    return e / prm.rest_density


@wp.func
def relax_wall_density(
    prm: SPHParams,
    b: int,
    h: float,
    b_volume: wp.array(dtype=float),
    bv: wp.array(dtype=wp.vec3),
    b_rho: wp.array(dtype=float),
    b_alpha: wp.array(dtype=float),
    b_pair_count: wp.array(dtype=wp.int32),
    b_pair_slots: PairSlots,
    b_pair_index: wp.array(dtype=wp.int32),
    b_pair_mass_grad: wp.array(dtype=wp.vec3),
    mass: wp.array(dtype=float),
    v: wp.array(dtype=wp.vec3),
    b_kappa: wp.array(dtype=float),
) -> float:
    """The same step for wall-layer particle b (compression e_b = rho_b - rho0 + dt sum_j m_j (v_b - v_j) . grad W_bj),
    pushing its liquid neighbours only (v_j += dt (k_b / rho_b) rho0 V_b grad_b W_bj, the wall term of the pair
    force). Not relaxed: the Jacobi step halves the wall's increment because the liquid's constraints correct the
    same approach in the same iteration (``WALL_RELAXATION``); here the wall measures what the liquid left. Returns
    e_b / rho0."""
    n = b_pair_count[b]
    if n == 0:
        return 0.0
    e = wp.max(h * wall_density_rate(b, v, bv, b_pair_count, b_pair_slots, b_pair_index, b_pair_mass_grad) + b_rho[b] - prm.rest_density, 0.0)
    if e == 0.0:
        return 0.0
    k_b = e * b_alpha[b] / (h * h)
    b_kappa[b] = b_kappa[b] + k_b
    push = h * k_b / b_rho[b] * prm.rest_density * b_volume[b]
    first = b_pair_slots.start[b]
    for k in range(n):
        s = first + k * b_pair_slots.step
        j = b_pair_index[s]
        v[j] = v[j] + (push / mass[j]) * b_pair_mass_grad[s]  # b_pair_mass_grad carries the liquid's m_j
    return e / prm.rest_density


@wp.func
def task_cell(g: GridSpec, n: int, t: int, keys: wp.array(dtype=wp.int32), b_keys: wp.array(dtype=wp.int32), cell_start: wp.array(dtype=wp.int32), cell_end: wp.array(dtype=wp.int32)) -> int:
    """The cell item t starts in a sweep, or -1. Items: the n liquid particles in cell order (``keys``: their sorted
    cell indices), then the wall particles in cell order (``b_keys``); the first item of each occupied cell starts
    it, a wall item only where the cell holds no liquid."""
    n_cells = g.nx * g.ny * g.nz
    if t < n:
        cell = keys[t]
        if cell >= n_cells or (t > 0 and keys[t - 1] == cell):
            return -1
        return cell
    s = t - n
    cell = b_keys[s]
    if cell >= n_cells or (s > 0 and b_keys[s - 1] == cell) or cell_end[cell] > cell_start[cell]:
        return -1
    return cell


@item_kernel
def list_sweep_cells(
    # Model
    g: GridSpec,
    n: int,
    items: int,
    threads: int,
    # State in
    keys: wp.array(dtype=wp.int32),
    cell_start: wp.array(dtype=wp.int32),
    cell_end: wp.array(dtype=wp.int32),
    b_keys: wp.array(dtype=wp.int32),
    # Out
    sweep_count: wp.array(dtype=wp.int32),
    sweep_cell: wp.array2d(dtype=wp.int32),
    sweep_color: wp.array2d(dtype=wp.int32),
):
    """The cells each of the ``threads`` threads of :func:`gauss_seidel_density_sweep` relaxes in this substep, with
    their colours (:func:`cell_color`): the thread takes every threads-th of the ``items`` items and the cells they
    start (:func:`task_cell`). Listed once per substep, so that each colour's launch visits its own cells instead of
    testing every item (for a colour with few cells, the test would be most of its launch)."""
    thread = wp.tid()
    count = int(0)
    for t in range(thread, items, threads):
        cell = task_cell(g, n, t, keys, b_keys, cell_start, cell_end)
        if cell >= 0:
            sweep_cell[thread, count] = cell
            sweep_color[thread, count] = cell_color(g, cell)
            count += 1
    sweep_count[thread] = count


@item_kernel
def gauss_seidel_density_sweep(
    # Model
    prm: SPHParams,
    color: int,
    b_volume: wp.array(dtype=float),
    # State in
    sweep_count: wp.array(dtype=wp.int32),
    sweep_cell: wp.array2d(dtype=wp.int32),
    sweep_color: wp.array2d(dtype=wp.int32),
    cell_start: wp.array(dtype=wp.int32),
    cell_end: wp.array(dtype=wp.int32),
    b_order: wp.array(dtype=wp.int32),
    b_cell_start: wp.array(dtype=wp.int32),
    b_cell_end: wp.array(dtype=wp.int32),
    rho: wp.array(dtype=float),
    alpha: wp.array(dtype=float),
    dt: wp.array(dtype=float),
    bv: wp.array(dtype=wp.vec3),
    pair_count: wp.array(dtype=wp.int32),
    pair_slots: PairSlots,
    pair_index: wp.array(dtype=wp.int32),
    pair_mass_grad: wp.array(dtype=wp.vec3),
    b_rho: wp.array(dtype=float),
    b_alpha: wp.array(dtype=float),
    b_pair_count: wp.array(dtype=wp.int32),
    b_pair_slots: PairSlots,
    b_pair_index: wp.array(dtype=wp.int32),
    b_pair_mass_grad: wp.array(dtype=wp.vec3),
    mass: wp.array(dtype=float),
    # State in/out
    v: wp.array(dtype=wp.vec3),
    kappa: wp.array(dtype=float),
    b_kappa: wp.array(dtype=float),
    solve_stats: wp.array(dtype=wp.int64),
):
    """One colour's part of a Gauss-Seidel sweep of the density solve: each cell of colour ``color`` relaxes its
    liquid particles, then its wall-layer particles, one after the other (:func:`relax_liquid_density`,
    :func:`relax_wall_density`), the cells in parallel (their particles share no neighbour, :func:`cell_color`).
    Each thread relaxes the cells of the colour in its list (:func:`list_sweep_cells`): few threads on the CPU,
    where a thread's start-up (its copy of these arguments, about 35 ns) would cost more than a cell's turn. The
    result depends on neither the order of the cells nor the number of threads or lanes."""
    h = dt[0]
    total = wp.int64(0)
    worst = wp.int64(0)
    thread = wp.tid()
    for k in range(sweep_count[thread]):
        if sweep_color[thread, k] != color:
            continue
        cell = sweep_cell[thread, k]
        for i in range(cell_start[cell], cell_end[cell]):
            q = error_quanta(relax_liquid_density(prm, i, h, rho, alpha, bv, pair_count, pair_slots, pair_index, pair_mass_grad, mass, v, kappa))
            total += q
            worst = wp.max(worst, q)
        for kk in range(b_cell_start[cell], b_cell_end[cell]):
            q = error_quanta(relax_wall_density(prm, b_order[kk], h, b_volume, bv, b_rho, b_alpha, b_pair_count, b_pair_slots, b_pair_index, b_pair_mass_grad, mass, v, b_kappa))
            total += q
            worst = wp.max(worst, q)
    if total > wp.int64(0):
        wp.atomic_add(solve_stats, stat_slot(prm, thread, STAT_ERROR), total)
        wp.atomic_max(solve_stats, stat_slot(prm, thread, STAT_MAX_ERROR), worst)


@wp.func
def wall_pair_viscosity(prm: SPHParams, alpha: float, volume: float, r: wp.vec3, r2: float, gw: wp.vec3, v_rel: wp.vec3, rho_i: float) -> wp.vec3:
    """Viscous acceleration of a particle from one wall particle (of rest density, ``volume``, kernel gradient
    ``gw``, relative velocity ``v_rel`` against the wall's own): the same call in compute_nonpressure and
    compute_wall_reaction, so the vessel receives exactly the opposite force."""
    return viscous_pair(prm, alpha, prm.rest_density * volume, r, r2, gw, v_rel, v_rel, rho_i, prm.rest_density)


@item_kernel
def compute_nonpressure(
    # Model
    prm: SPHParams,
    b_volume: wp.array(dtype=float),
    # State in
    x: wp.array(dtype=wp.vec3),
    v: wp.array(dtype=wp.vec3),
    rho: wp.array(dtype=float),
    active: wp.array(dtype=wp.int32),
    dt: wp.array(dtype=float),
    bx: wp.array(dtype=wp.vec3),
    bv: wp.array(dtype=wp.vec3),
    pair_count: wp.array(dtype=wp.int32),
    pair_slots: PairSlots,
    pair_index: wp.array(dtype=wp.int32),
    pair_grad: wp.array(dtype=wp.vec3),
    row: wp.array(dtype=wp.int32),
    free: wp.array(dtype=wp.int32),
    mass: wp.array(dtype=float),
    # State in/out
    kappa_density: wp.array(dtype=float),
    # Out
    v_star: wp.array(dtype=wp.vec3),
    increment: wp.array(dtype=float),
    increment_per_rho: wp.array(dtype=float),
    solve_stats: wp.array(dtype=wp.int64),
    keep_going: wp.array(dtype=wp.int32),
    diag_f: wp.array2d(dtype=float),
):
    """v* = v + dt (g + viscosity) over the substep's pair list (walls: their own velocity, rest density;
    :func:`wall_pair_viscosity`); the density solve's warm start (and it over rho) and counters."""
    i = wp.tid()
    if i == 0:
        solve_stats[STAT_ITERATIONS] = wp.int64(0)
        keep_going[0] = 1
    warm = WARM_START_DENSITY * kappa_density[i]
    kappa_density[i] = 0.0
    if active[i] == 0:
        v_star[i] = v[i]
        increment[i] = 0.0
        increment_per_rho[i] = 0.0
        return
    xi = x[i]
    vi = v[i]
    rhoi = rho[i]
    a = wp.vec3(0.0)
    free_i = free[i]
    first = pair_slots.start[i]
    for k in range(pair_count[i]):
        s = first + k * pair_slots.step
        j = pair_index[s]
        if j >= 0:
            r = xi - x[j]
            vij = vi - v[j]
            alpha = wp.where(free_i != 0 or free[j] != 0, prm.alpha_free, prm.alpha)
            a += viscous_pair(prm, alpha, mass[j], r, wp.dot(r, r), pair_grad[s], vij, vij, rhoi, rho[j])
        else:
            b = pair_wall(j)
            r = xi - bx[b]
            a += wall_pair_viscosity(prm, wp.where(free_i != 0, prm.alpha_free, prm.alpha), b_volume[b], r, wp.dot(r, r), pair_grad[s], vi - bv[b], rhoi)
    a += prm.gravity
    v_star[i] = vi + dt[0] * a
    increment[i] = warm
    increment_per_rho[i] = warm / rhoi
    wp.atomic_max(diag_f, diag_slot(prm, row[0], i), DIAG_MAX_ACCEL, wp.length(a))


@item_kernel
def compute_wall_reaction(
    # Model
    prm: SPHParams,
    vessels: wp.array(dtype=VesselGeometry),
    b_volume: wp.array(dtype=float),
    b_vessel: wp.array(dtype=wp.int32),
    # State in
    motions: wp.array(dtype=VesselMotion),
    x: wp.array(dtype=wp.vec3),
    v: wp.array(dtype=wp.vec3),
    rho: wp.array(dtype=float),
    kappa_density: wp.array(dtype=float),
    kappa_divergence: wp.array(dtype=float),
    active: wp.array(dtype=wp.int32),
    bx: wp.array(dtype=wp.vec3),
    bv: wp.array(dtype=wp.vec3),
    pair_count: wp.array(dtype=wp.int32),
    pair_slots: PairSlots,
    pair_index: wp.array(dtype=wp.int32),
    pair_grad: wp.array(dtype=wp.vec3),
    b_rho: wp.array(dtype=float),
    b_kappa_density: wp.array(dtype=float),
    b_kappa_divergence: wp.array(dtype=float),
    substep_weight: wp.array(dtype=float),
    free: wp.array(dtype=wp.int32),
    # Out
    wall_force: wp.array2d(dtype=wp.vec3),
    wall_torque: wp.array2d(dtype=wp.vec3),
    # State in/out
    p: wp.array(dtype=float),
):
    """The force each particle exerted on each vessel this substep, the opposite of what its wall neighbours (the
    wall entries of the pair list) gave it: per wall particle the pressure m (kappa_i / rho_i) rho0 V_b grad W_ib
    over both solves (kappa_i enters linearly, so the sum over the iterations is exact) and the viscous term with
    the velocity the non-pressure stage saw (``v``, before the density solve), and its moment about the vessel's
    centre of mass. Also adds this substep's share (``substep_weight`` = 1 / substeps of the interval) of the
    reported pressure p_i = rho_i kappa_i (Pa): the pressure is the interval's average, as the wrenches are (one
    substep's stiffness is the multiplier of that substep's residual, noisy from substep to substep)."""
    i = wp.tid()
    for k in range(prm.n_vessels):
        wall_force[k, i] = wp.vec3(0.0)
        wall_torque[k, i] = wp.vec3(0.0)
    if active[i] == 0:
        return
    kappa = kappa_density[i] + kappa_divergence[i]
    rhoi = rho[i]
    p[i] = p[i] + substep_weight[0] * rhoi * kappa
    xi = x[i]
    vi = v[i]
    ki = kappa / rhoi
    first = pair_slots.start[i]
    for k in range(pair_count[i]):
        s = first + k * pair_slots.step
        j = pair_index[s]
        if j >= 0:
            continue
        b = pair_wall(j)
        xb = bx[b]
        r = xi - xb
        gw = pair_grad[s]
        ab = wall_pair_viscosity(prm, wp.where(free[i] != 0, prm.alpha_free, prm.alpha), b_volume[b], r, wp.dot(r, r), gw, vi - bv[b], rhoi)
        kb = (b_kappa_density[b] + b_kappa_divergence[b]) / b_rho[b]
        ab -= (prm.rest_density * b_volume[b] * (ki + kb)) * gw
        add_wall_reaction(prm, vessels, motions, b_vessel[b], i, xb, ab, wall_force, wall_torque)


@item_kernel
def carry_density(
    # State in
    active: wp.array(dtype=wp.int32),
    dt: wp.array(dtype=float),
    v_star: wp.array(dtype=wp.vec3),
    bv: wp.array(dtype=wp.vec3),
    pair_count: wp.array(dtype=wp.int32),
    pair_slots: PairSlots,
    pair_index: wp.array(dtype=wp.int32),
    pair_mass_grad: wp.array(dtype=wp.vec3),
    # State in/out
    rho: wp.array(dtype=float),
):
    """``FluidConfig.surface_density`` 'continuity': the density the solves held particle i to carried over the
    substep by the continuity equation, rho_i += dt Drho_i/Dt with the velocities x moved by (v*, and the walls')
    over the substep's pairs (kg/m^3): the next substep's :func:`surface_offset` reads it."""
    i = wp.tid()
    if active[i] == 0:
        return
    rho[i] = rho[i] + dt[0] * liquid_density_rate(i, v_star, bv, pair_count, pair_slots, pair_index, pair_mass_grad)


@item_kernel
def integrate(
    # Model
    prm: SPHParams,
    vessels: wp.array(dtype=VesselGeometry),
    domain_min: wp.vec3,
    domain_max: wp.vec3,
    guard_margin: float,
    max_penetration: float,
    # State in
    motions: wp.array(dtype=VesselMotion),
    dt: wp.array(dtype=float),
    row: wp.array(dtype=wp.int32),
    v_star: wp.array(dtype=wp.vec3),
    rho: wp.array(dtype=float),
    # State in/out
    x: wp.array(dtype=wp.vec3),
    v: wp.array(dtype=wp.vec3),
    active: wp.array(dtype=wp.int32),
    mass: wp.array(dtype=float),
    free: wp.array(dtype=wp.int32),
    wall_force: wp.array2d(dtype=wp.vec3),
    wall_torque: wp.array2d(dtype=wp.vec3),
    # Out
    diag_f: wp.array2d(dtype=float),
    diag_i: wp.array2d(dtype=wp.int32),
):
    """x += dt v* (the velocity both solves corrected), then the shared guard, deactivation and diagnostics."""
    i = wp.tid()
    if active[i] == 0:
        return
    x_old = x[i]
    vi = v_star[i]
    finish_particle(
        prm, vessels, motions, domain_min, domain_max, guard_margin, max_penetration, diag_slot(prm, row[0], i), i, x_old, x_old + dt[0] * vi, vi, rho[i], dt[0],
        x, v, active, mass, free, wall_force, wall_torque, diag_f, diag_i,
    )
