"""Warp functions and kernels both pressure solvers share: what a neighbour brings into the sums (a wall particle's
mass, a neighbour's share of the summation density), the pair-list codes, the pair kernel gradient, the viscous pair terms, the
end of a particle's substep (wall guard, deactivation outside the domain, the substep's common diagnostics), the
reorder of the particle state into cell order and the fixed-order reduction of the wall wrenches."""

from __future__ import annotations

import math

import warp as wp

from cosim.fluid.boundary import VesselGeometry, VesselMotion, guard_vessel, in_vessel_frame_now, inside_vessel
from cosim.fluid.diagnostics import (
    DIAG_ACTIVE,
    DIAG_BREACHES,
    DIAG_CORRECTIONS,
    DIAG_INSIDE0,
    DIAG_KINETIC_ENERGY,
    DIAG_POTENTIAL_ENERGY,
    DIAG_REMOVED_ENERGY,
    DIAG_MAX_SPEED,
    DIAG_NONFINITE,
)
from cosim.fluid.lanes import item_kernel
from cosim.fluid.params import SPHParams
from cosim.fluid.sph_kernels import kernel_dw, kernel_w


# Pair-list room per particle, in units of the lattice neighbours a full kernel support holds (liquid and wall
# together fill one support; the rest is margin for compression and disorder)
PAIR_CAPACITY_FACTOR = 2.5


def pair_capacity(dim: int, smoothing_ratio: float) -> int:
    """Pair-list entries per particle: PAIR_CAPACITY_FACTOR x the lattice points in a support of radius 2h."""
    radius = 2.0 * smoothing_ratio  # in particle spacings
    lattice = math.pi * radius**2 if dim == 2 else 4.0 / 3.0 * math.pi * radius**3
    return math.ceil(PAIR_CAPACITY_FACTOR * lattice)


@wp.func
def inside_vessel_now(prm: SPHParams, geo: VesselGeometry, m: VesselMotion, x: wp.vec3) -> bool:
    """Whether the world point x is in the inner volume (below the rim) of the vessel ``geo`` at its pose at the
    substep's start (``m.r_now``, ``m.p_now``)."""
    return inside_vessel(in_vessel_frame_now(m, x), geo, prm.dim) != 0


@wp.func
def inside_any_vessel(prm: SPHParams, vessels: wp.array(dtype=VesselGeometry), motions: wp.array(dtype=VesselMotion), x: wp.vec3) -> bool:
    """Whether x is in some vessel's inner volume (below its rim) at the substep's start pose."""
    for k in range(prm.n_vessels):
        if inside_vessel_now(prm, vessels[k], motions[k], x):
            return True
    return False


@item_kernel
def mark_inside_vessels(
    prm: SPHParams, vessels: wp.array(dtype=VesselGeometry), motions: wp.array(dtype=VesselMotion), x: wp.array(dtype=wp.vec3),
    inside: wp.array(dtype=wp.int32),
):
    """Bit k of ``inside[i]`` set where liquid particle i lies in vessel k's inner volume (below its rim) at the
    substep's start pose: the side of a 'sided' wall it sees (:func:`cosim.fluid.neighbors.wall_seen`)."""
    i = wp.tid()
    mask = int(0)
    for k in range(prm.n_vessels):
        if inside_vessel_now(prm, vessels[k], motions[k], x[i]):
            mask = mask | (1 << k)
    inside[i] = mask


@wp.func
def next_free_state(free_now: int, exposed: bool, summation: float, rest_density: float) -> int:
    """The free-liquid rule both solvers share (``FluidConfig.free_liquid``): 1 free, 0 bound. Bound liquid becomes
    free once it is exposed (where ``FluidConfig.free_liquid_rule`` lets liquid be free: outside every vessel, or at
    the free surface; :func:`cosim.fluid.free_surface.exposed_liquid`) and has separated (summation density below
    rho0); free liquid becomes bound again when it is packed (summation density >= rho0) where it is not exposed."""
    if free_now == 0:
        return wp.where(exposed and summation < rest_density, 1, 0)
    return wp.where(not exposed and summation >= rest_density, 0, 1)


@wp.func
def wall_pair(b: int) -> int:
    """Pair-list code of wall particle b (fluid neighbours are stored as their index j >= 0)."""
    return -1 - b


@wp.func
def pair_wall(j: int) -> int:
    """The wall particle of pair-list code j < 0 (the inverse of :func:`wall_pair`)."""
    return -1 - j


@wp.func
def wall_mass(prm: SPHParams, b_volume: wp.array(dtype=float), b: int) -> float:
    """The mass wall particle b brings into the SPH sums (kg, or kg/m in 2-D): rho0 V_b, the liquid it stands for
    (a liquid neighbour j brings its own m_j)."""
    return prm.rest_density * b_volume[b]


@wp.func
def summation_term(prm: SPHParams, m_pair: float, r2: float) -> float:
    """A neighbour's share m W(|r|) of the summation density (kg/m^3) at squared distance ``r2`` (m^2), ``m_pair``
    its mass (kg, or kg/m in 2-D)."""
    return m_pair * kernel_w(wp.sqrt(r2), prm.inv_h, prm.sigma, prm.kernel)


@wp.func
def kernel_gradient(prm: SPHParams, r: wp.vec3, r2: float) -> wp.vec3:
    """grad_i W(x_i - x_j) for r = x_i - x_j, |r|^2 = r2 > 0 (1/m^(dim+1))."""
    rl = wp.sqrt(r2)
    return r * (kernel_dw(rl, prm.inv_h, prm.sigma, prm.kernel) / rl)


@wp.func
def viscous_pair(
    prm: SPHParams, alpha: float, mass_j: float, r: wp.vec3, r2: float, gw: wp.vec3, v_rel: wp.vec3, v_rel_laminar: wp.vec3, rho_i: float,
    rho_j: float,
) -> wp.vec3:
    """Acceleration (m/s^2) of particle i from neighbour j of mass ``mass_j`` (kg, or kg/m in 2-D): Monaghan (1992)
    artificial viscosity with coefficient ``alpha`` on the approaching relative velocity ``v_rel`` = v_i - v_j,
    -m_j Pi_ij grad W with Pi_ij = -alpha v_sig mu_ij / rho_ij, mu_ij = h min(v_rel . r, 0) / (r^2 + eta^2), its velocity
    scale v_sig = c + b max(0, -v_rel . r / |r|) (Monaghan 1997, "SPH and Riemann solvers"; c =
    ``prm.viscosity_speed``, b = ``prm.viscosity_approach_weight``: c0 and 0, or sqrt(|g| h) and 2, or with
    ``artificial_viscosity_beta`` set Monaghan's quadratic coefficient over alpha, ``FluidConfig.viscosity_speed``),
    plus Morris et al. (1997) laminar viscosity on ``v_rel_laminar`` (v_i minus the neighbour's, or a wall's no-slip,
    velocity)."""
    # min(vr, 0) instead of a branch on the approach: about half the pairs approach, so the branch is mispredicted
    # about half the time (docs/tuning.md); a receding pair adds exactly zero, as the branch would skip it
    approach = wp.min(wp.dot(v_rel, r), 0.0)
    mu = prm.h * approach / (r2 + prm.eta2)
    speed = prm.viscosity_speed + prm.viscosity_approach_weight * (-approach / wp.sqrt(r2))
    a = (mass_j * alpha * speed * mu / (0.5 * (rho_i + rho_j))) * gw
    a += (mass_j * prm.nu * (1.0 / rho_i + 1.0 / rho_j) * wp.dot(r, gw) / (r2 + prm.eta2)) * v_rel_laminar
    return a


@wp.func
def add_wall_reaction(
    prm: SPHParams,
    vessels: wp.array(dtype=VesselGeometry),
    motions: wp.array(dtype=VesselMotion),
    kv: int,
    i: int,
    xb: wp.vec3,
    a_wall: wp.vec3,
    wall_force: wp.array2d(dtype=wp.vec3),
    wall_torque: wp.array2d(dtype=wp.vec3),
):
    """Add to particle i's reaction on vessel kv the opposite of the acceleration ``a_wall`` (m/s^2) one of that
    vessel's wall particles, at ``xb``, gave it: the force -m a_wall (N, the 3-D mass the particle stands for) and
    its moment about the vessel's centre of mass at the substep's start (N m)."""
    m = motions[kv]
    com = m.p_now + m.r_now @ vessels[kv].com
    f_vessel = -prm.mass_out * a_wall
    wall_force[kv, i] = wall_force[kv, i] + f_vessel
    wall_torque[kv, i] = wall_torque[kv, i] + wp.cross(xb - com, f_vessel)


@wp.func
def finish_particle(
    prm: SPHParams,
    vessels: wp.array(dtype=VesselGeometry),
    motions: wp.array(dtype=VesselMotion),
    domain_min: wp.vec3,
    domain_max: wp.vec3,
    guard_margin: float,
    max_penetration: float,
    s: int,
    i: int,
    x_old: wp.vec3,
    x_new: wp.vec3,
    v_new: wp.vec3,
    rho_new: float,
    dt: float,
    x: wp.array(dtype=wp.vec3),
    v: wp.array(dtype=wp.vec3),
    active: wp.array(dtype=wp.int32),
    mass: wp.array(dtype=float),
    free: wp.array(dtype=wp.int32),
    wall_force: wp.array2d(dtype=wp.vec3),
    wall_torque: wp.array2d(dtype=wp.vec3),
    diag_f: wp.array2d(dtype=float),
    diag_i: wp.array2d(dtype=wp.int32),
) -> int:
    """Store the particle's new position and velocity after the non-penetration guard of every vessel; deactivate
    it if non-finite or outside the domain. The velocity a guard removes is a wall impulse: its reaction
    -m dv / dt is added to the particle's force and torque on that vessel (``wall_force``/``wall_torque``, N and
    N m about the vessel's centre of mass), so the reaction wrench balances every boundary force. Records wall
    corrections/breaches, per-vessel contents, speed, kinetic and potential energy (and the energy of a particle
    leaving the domain), and the active count in row ``s``. Returns 1 if the particle is still active (the caller
    then stores its density and pressure), else 0.

    A particle that enters a vessel (outside its inner volume at the substep's start, inside at its end) takes the
    vessel's in-plane mass (``VesselGeometry.liquid_mass``, 2-D: its own 3-D mass spread over the vessel's depth)
    where that differs from its own, and becomes free liquid: its density is then re-measured by summation with the
    new mass until it is packed inside the vessel (:func:`next_free_state`), under both solvers, instead of carrying
    a continuity density or a seeded offset that describe its old packing. One switch at the inlet: the stream
    between the vessels keeps the depth of the vessel it left."""
    xi = x_new
    vi = v_new
    if prm.dim == 2:
        vi[1] = 0.0
        xi[1] = 0.0
    for k in range(prm.n_vessels):
        m = motions[k]
        geo = vessels[k]
        q_old = in_vessel_frame_now(m, x_old)
        q_new = wp.transpose(m.r_next) @ (xi - m.p_next)
        q, normal, depth, hits = guard_vessel(q_old, q_new, geo, prm.dim, guard_margin)
        if hits > 0:
            xi = m.p_next + m.r_next @ q
            n_world = m.r_next @ normal
            v_wall = m.lin_vel + wp.cross(m.ang_vel, xi - m.p_next)
            vn = wp.dot(vi - v_wall, n_world)
            if vn < 0.0:
                vi = vi - vn * n_world
                f_vessel = (prm.mass_out * vn / dt) * n_world  # -m dv / dt with dv = -vn n
                com = m.p_now + m.r_now @ geo.com
                wall_force[k, i] = wall_force[k, i] + f_vessel
                wall_torque[k, i] = wall_torque[k, i] + wp.cross(xi - com, f_vessel)
            wp.atomic_add(diag_i, s, DIAG_CORRECTIONS, 1)
            if depth > max_penetration:
                wp.atomic_add(diag_i, s, DIAG_BREACHES, 1)
        if inside_vessel(q, geo, prm.dim) != 0:
            wp.atomic_add(diag_i, s, DIAG_INSIDE0 + k, 1)
            if geo.liquid_mass > 0.0 and mass[i] != geo.liquid_mass and inside_vessel(q_old, geo, prm.dim) == 0:
                mass[i] = geo.liquid_mass
                free[i] = 1
    if not (wp.isfinite(xi) and wp.isfinite(vi) and wp.isfinite(rho_new)):
        wp.atomic_add(diag_i, s, DIAG_NONFINITE, 1)
        active[i] = 0
        return 0
    outside = False
    for a in range(3):
        if xi[a] < domain_min[a] or xi[a] > domain_max[a]:
            outside = True
    if outside:
        active[i] = 0
        wp.atomic_add(diag_f, s, DIAG_REMOVED_ENERGY, prm.mass_out * (0.5 * wp.dot(vi, vi) - wp.dot(prm.gravity, xi)))
        x[i] = xi
        v[i] = wp.vec3(0.0)
        return 0
    x[i] = xi
    v[i] = vi
    speed = wp.length(vi)
    wp.atomic_add(diag_i, s, DIAG_ACTIVE, 1)
    wp.atomic_max(diag_f, s, DIAG_MAX_SPEED, speed)
    wp.atomic_add(diag_f, s, DIAG_KINETIC_ENERGY, 0.5 * prm.mass_out * speed * speed)
    wp.atomic_add(diag_f, s, DIAG_POTENTIAL_ENERGY, -prm.mass_out * wp.dot(prm.gravity, xi))
    return 1


@wp.func
def diag_slot(prm: SPHParams, row: int, i: int) -> int:
    """The diagnostics row particle ``i`` writes for substep ``row``: its replica of that row
    (``cosim.fluid.device_layout``; one replica on the CPU: the row itself)."""
    return row * prm.atomic_replicas + i % prm.atomic_replicas


@item_kernel
def gather_particles(
    order: wp.array(dtype=wp.int32),
    x: wp.array(dtype=wp.vec3),
    v: wp.array(dtype=wp.vec3),
    rho: wp.array(dtype=float),
    p: wp.array(dtype=float),
    active: wp.array(dtype=wp.int32),
    pid: wp.array(dtype=wp.int32),
    kappa_density: wp.array(dtype=float),
    kappa_divergence: wp.array(dtype=float),
    free: wp.array(dtype=wp.int32),
    rest_offset: wp.array(dtype=float),
    mass: wp.array(dtype=float),
    x_out: wp.array(dtype=wp.vec3),
    v_out: wp.array(dtype=wp.vec3),
    rho_out: wp.array(dtype=float),
    p_out: wp.array(dtype=float),
    active_out: wp.array(dtype=wp.int32),
    pid_out: wp.array(dtype=wp.int32),
    kappa_density_out: wp.array(dtype=float),
    kappa_divergence_out: wp.array(dtype=float),
    free_out: wp.array(dtype=wp.int32),
    rest_offset_out: wp.array(dtype=float),
    mass_out: wp.array(dtype=float),
):
    """Reorder the particle state into cell order (``order`` from the neighbour grid)."""
    i = wp.tid()
    src = order[i]
    x_out[i] = x[src]
    v_out[i] = v[src]
    rho_out[i] = rho[src]
    p_out[i] = p[src]
    active_out[i] = active[src]
    pid_out[i] = pid[src]
    kappa_density_out[i] = kappa_density[src]
    kappa_divergence_out[i] = kappa_divergence[src]
    free_out[i] = free[src]
    rest_offset_out[i] = rest_offset[src]
    mass_out[i] = mass[src]


@wp.kernel
def sum_wall_wrench_chunks(
    n: int,
    first_stride: int,
    item_stride: int,
    items: int,
    wall_force: wp.array2d(dtype=wp.vec3),
    wall_torque: wp.array2d(dtype=wp.vec3),
    partial_force: wp.array2d(dtype=wp.vec3),
    partial_torque: wp.array2d(dtype=wp.vec3),
):
    """One level of the fixed-order reduction of ``n`` items per vessel: chunk c of vessel k sums the items
    c * first_stride + j * item_stride, j = 0, 1, ... below ``items`` and ``n``, in order
    (``cosim.fluid.device_layout.ReductionLevel``)."""
    k, c = wp.tid()
    f = wp.vec3(0.0)
    t = wp.vec3(0.0)
    for j in range(items):
        i = c * first_stride + j * item_stride
        if i >= n:
            break
        f += wall_force[k, i]
        t += wall_torque[k, i]
    partial_force[k, c] = f
    partial_torque[k, c] = t


@wp.kernel
def accumulate_wall_wrench(
    n_chunks: int,
    partial_force: wp.array2d(dtype=wp.vec3),
    partial_torque: wp.array2d(dtype=wp.vec3),
    force_sum: wp.array(dtype=wp.vec3),
    torque_sum: wp.array(dtype=wp.vec3),
):
    """Second level: the chunks of vessel k in order, added to the interval's running sum."""
    k = wp.tid()
    f = wp.vec3(0.0)
    t = wp.vec3(0.0)
    for c in range(n_chunks):
        f += partial_force[k, c]
        t += partial_torque[k, c]
    force_sum[k] = force_sum[k] + f
    torque_sum[k] = torque_sum[k] + t


@wp.kernel
def next_substep(row: wp.array(dtype=wp.int32)):
    row[0] = row[0] + 1
