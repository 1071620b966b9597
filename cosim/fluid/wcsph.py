"""Weakly compressible SPH stages (warp kernels).

update_free_liquid: free liquid (``FluidConfig.free_liquid``): a particle outside every vessel's inner volume (or,
  by ``FluidConfig.free_liquid_rule`` 'free_surface', at the free surface, ``cosim.fluid.free_surface``) that
  has separated from the liquid (summation density below rho0) takes the memoryless, tension-free summation density
  max(sum_j m W_ij, rho0) each substep; back inside a vessel it stays free until packed (summation density >= rho0),
  then the continuity equation takes over from there. Why: the continuity density's tension (a stretched stream is
  below rest density) pulls the falling stream back toward the vessel it left, 16-22 mm short of its parabola in
  ``cosim validate free-fall``; but without tension the continuity density cannot hold caught liquid together,
  because it remembers the loose packing a drop arrived in (its offset from the summation density) and props the
  caught liquid up. Free liquid pairs use ``FluidConfig.free_liquid_alpha`` (by default the bulk's one alpha, with
  Monaghan's quadratic term beta w damping every approaching pair: impacts are inelastic wherever they happen). The same
  neighbour walk measures each particle's free-surface indicator where the 'free_surface' rule or the
  tensile-instability control needs it.
The substep's pair list (each neighbour and its kernel gradient, in loop order), where the device layout keeps pair
  tables (``cosim.fluid.device_layout.DeviceLayout.pair_tables``): recorded by the first pass that walks every
  particle (update_free_liquid under the 'free_surface' rule or the tensile-instability control, else
  compute_forces); the later passes sum over it instead of searching the cells again (the same sums in the same
  order: identical results). Under the 'outside_vessels' rule update_free_liquid walks only the liquid outside the
  vessels, and recording there would cost every particle a walk the force pass makes anyway.
compute_forces: per particle, over fluid and wall neighbours,
  - the acceleration: symmetric pressure gradient (or, by ``FluidConfig.tension_treatment`` 'tic', Sun et al.
    2018's tensile-instability control: :func:`pressure_pair_factor`), the dummy wall particles entering like liquid
    particles of mass rho0 V_w with their extrapolated pressure (Adami et al. 2012, see ``cosim.fluid.boundary``); Monaghan
    (1992) artificial viscosity and Morris et al. (1997) laminar viscosity (no-slip against the walls); gravity;
  - the reaction on each vessel: -m a_ib summed per particle, and its moment about the vessel's centre of mass,
    stored per particle so they can be reduced in a fixed order (deterministic on every device).
compute_density_rate: continuity equation (liquid and wall particles) evaluated with the kicked velocities, plus
  delta-SPH diffusion with the renormalised density gradient of Antuono et al. (2010), so a resting column keeps
  its hydrostatic density profile and loose liquid exchanges nothing. Summed over the pair list, or
  (compute_density_rate_walking, a layout without pair tables) over the same neighbours walked again in the same
  order.
integrate: symplectic Euler, i.e. leapfrog with velocities at half steps: v += dt a(rho_n); rho += dt
  Drho(v_new) (safety floor 0.8 rho0, see the kernel; free liquid keeps its summation density); x += dt v_new;
  p from the Tait equation. (Updating rho with the old velocity instead would be forward Euler for the acoustic
  waves and amplify them every step.) Then the wall guard, deactivation outside the domain, the equation of
  state and the substep's diagnostics.
"""

from __future__ import annotations

import warp as wp

from cosim.fluid.boundary import VesselGeometry, VesselMotion, on_inner_face
from cosim.fluid.diagnostics import DIAG_INTERNAL_ENERGY, DIAG_MAX_ACCEL, DIAG_MAX_COMPRESSION, DIAG_MAX_DENSITY_ERROR, DIAG_PAIR_OVERFLOW
from cosim.fluid.free_surface import FREE_AT_SURFACE, FREE_LIQUID_OFF, FREE_OUTSIDE_VESSELS, exposed_liquid, renormalisation_term, surface_indicator
from cosim.fluid.lanes import item_kernel
from cosim.fluid.neighbors import COINCIDENT_R2, SEEN_FROM_OUTSIDE, Neighborhood, neighbor_cells, next_liquid_neighbor, next_wall_neighbor, reachable_cell
from cosim.fluid.params import SPHParams
from cosim.fluid.sph_common import (
    add_wall_reaction,
    diag_slot,
    finish_particle,
    inside_any_vessel,
    kernel_gradient,
    next_free_state,
    pair_wall,
    summation_term,
    viscous_pair,
    wall_mass,
    wall_pair,
)
from cosim.fluid.sph_kernels import kernel_w

# The renormalisation matrix L^-1 (identity for a full kernel support) is used only where det L exceeds this:
# near-empty supports (spray, a lone particle) give no meaningful density gradient.
RENORMALISATION_MIN_DET = wp.constant(0.05)
MIN_DENSITY_RATIO = wp.constant(0.8)
# Tensile-instability control's free-surface region: Marrone et al. (2010)'s indicator lambda at or below 0.75, the
# region their scan test examines (a flat surface's top row 0.5, its second row 0.84, the interior 1).
TIC_SURFACE_REGION = wp.constant(0.75)
# Who walks the cells for the substep's pair list (compute_forces' ``pairs``): nobody (a layout without pair tables:
# compute_forces and compute_density_rate_walking each walk); compute_forces, which records the list as it walks;
# update_free_liquid, where it walks every particle anyway (the 'free_surface' rule, the tensile-instability
# control), so that compute_forces reads the list instead of walking a second time.
PAIRS_WALKED = wp.constant(0)
PAIRS_RECORDED_BY_FORCES = wp.constant(1)
PAIRS_RECORDED_BY_FREE_LIQUID = wp.constant(2)


@wp.func
def tait_pressure(prm: SPHParams, rho: float) -> float:
    """Tait equation of state (Camporredondo et al. 2019, Eq. 5) with the artificial sound speed, p = B ((rho/rho0)^gamma - 1), its
    tension clamped at ``max_tension`` (``FluidConfig.tension_limit``: ``max_tension`` under the 'clamp' treatment, none
    under tensile-instability control)."""
    return wp.max(prm.eos_b * (wp.pow(rho / prm.rest_density, prm.gamma) - 1.0), -prm.max_tension)


@wp.func
def tait_elastic_energy(prm: SPHParams, rho: float) -> float:
    """The unclamped Tait liquid's u = integral of p / rho^2 from rho0 to rho =
    (B / rho0) (r^(gamma - 1) / (gamma - 1) + 1 / r - gamma / (gamma - 1)), r = rho / rho0 (J/kg)."""
    r = rho / prm.rest_density
    g1 = prm.gamma - 1.0
    return (prm.eos_b / prm.rest_density) * (wp.pow(r, g1) / g1 + 1.0 / r - prm.gamma / g1)


@wp.func
def tait_internal_energy(prm: SPHParams, rho: float) -> float:
    """Elastic energy per unit mass the liquid stores at density rho (J/kg), the integral of p / rho^2 from rho0
    to rho of :func:`tait_pressure` (>= 0, zero at rest density): the Tait energy, and below the tension clamp's
    density rho_t, u(rho_t) + max_tension (1 / rho - 1 / rho_t)."""
    if rho >= prm.tension_density:
        return tait_elastic_energy(prm, rho)
    rt = prm.tension_density
    return tait_elastic_energy(prm, rt) + prm.max_tension * (1.0 / rho - 1.0 / rt)


@wp.func
def own_pressure(tic: int, p_i: float, indicator_i: float) -> float:
    """The pressure p_i of particle i as its pair terms take it (Pa): p_i, but under tensile-instability control
    (``tic`` 1) -p_i where p_i < 0 inside the liquid (indicator above :data:`TIC_SURFACE_REGION`), so that the pair
    factor's p_j + (own pressure) is Sun et al. (2018)'s p_j - p_i there (:func:`pressure_pair_factor`)."""
    if tic != 0 and p_i < 0.0 and indicator_i > TIC_SURFACE_REGION:
        return -p_i
    return p_i


@wp.func
def pressure_pair_factor(tic: int, own_i: float, rho_i: float, p_j: float, rho_j: float) -> float:
    """The factor f_ij of particle i's pressure term a_i -= m_j f_ij grad_i W_ij (Pa m^6/kg^2), for i's own
    pressure ``own_i`` (:func:`own_pressure`) and density and neighbour j's (a wall particle's: its extrapolated
    pressure and density, Adami et al. 2012):

    - ``tic`` 0: Monaghan's symmetric sum p_i / rho_i^2 + p_j / rho_j^2;
    - ``tic`` 1: Sun, Colagrossi, Marrone, Antuono & Zhang (2018), "Multi-resolution Delta-plus-SPH with tensile
      instability control: towards high Reynolds number flows", Comput. Phys. Commun. 224, Eq. (9):
      Du_i/Dt = -(1/rho_i) sum_j F_ij grad_i W_ij V_j, V_j = m_j / rho_j, so f_ij = F_ij / (rho_i rho_j), with
      F_ij = p_j + p_i where p_i >= 0 or i is in the free-surface region, and F_ij = p_j - p_i where p_i < 0
      inside the liquid. The minus form is the gradient of p - p_i: a particle in uniform tension feels no force
      from its neighbours' disorder, so tension does not clump particles (the tensile instability). It does not
      conserve momentum exactly, which Sun et al. show costs little while the particles stay regular."""
    if tic == 0:
        return own_i / (rho_i * rho_i) + p_j / (rho_j * rho_j)
    return (p_j + own_i) / (rho_i * rho_j)


@item_kernel
def update_free_liquid(
    # Model
    prm: SPHParams,
    vessels: wp.array(dtype=VesselGeometry),
    b_volume: wp.array(dtype=float),
    mode: int,
    threshold: float,
    measure_surface: int,
    # State in
    motions: wp.array(dtype=VesselMotion),
    nb: Neighborhood,
    active: wp.array(dtype=wp.int32),
    mass: wp.array(dtype=float),
    row: wp.array(dtype=wp.int32),
    capacity: int,
    record_pairs: int,
    # State in/out
    free: wp.array(dtype=wp.int32),
    rho: wp.array(dtype=float),
    p: wp.array(dtype=float),
    # Out
    indicator: wp.array(dtype=float),
    pair_count: wp.array(dtype=wp.int32),
    pair_index: wp.array2d(dtype=wp.int32),
    pair_grad: wp.array2d(dtype=wp.vec3),
    diag_i: wp.array2d(dtype=wp.int32),
):
    """Free liquid: a particle where the rule ``mode`` lets liquid be free (outside every vessel's inner volume:
    the falling stream, spray, a splash above a rim; or at the free surface, its indicator below ``threshold``,
    stored in ``indicator``: ``cosim.fluid.free_surface``) is free once it has separated, and stays free until it
    is packed where the rule no longer holds (``mode`` :data:`FREE_LIQUID_OFF`: never free). Until it has separated
    (summation density below rho0) the continuity density goes on, so its pressure does not jump when it passes a rim. A free particle's density is the summation
    density sum_j m_j W_ij + sum_b rho0 V_b W_ib (normalised by a resting lattice's kernel sum), clamped below at
    rho0: memoryless (it sees the packing, whatever the particle went through in flight) and without tension
    (liquid in the air is at ambient pressure; the continuity density's tension would pull the stream back toward
    the vessel it left). It becomes bound when its summation density reaches rho0; the continuity equation then
    continues from that density, so the pressure is continuous and the caught liquid keeps no memory of the loose
    packing it arrived in. ``measure_surface`` 1 (the tensile-instability control needs it): every particle's
    indicator is computed and stored, whatever the rule.

    ``record_pairs`` 1 (a device layout with pair tables, and a rule or control that walks every particle here):
    this is the substep's one neighbour walk: it also records every particle's pair list (``pair_index[i, k]``:
    neighbour j >= 0 or wall code :func:`wall_pair`; ``pair_grad``: grad_i W), in the order of the neighbour loop,
    which compute_forces and compute_density_rate then sum over (the particles do not move until integrate); more
    than ``capacity`` neighbours count as an overflow, an instability."""
    i = wp.tid()
    if record_pairs != 0:
        pair_count[i] = 0
    if active[i] == 0:
        return
    xi = nb.x[i]
    stays_bound = mode == FREE_LIQUID_OFF  # no free liquid: every particle stays bound
    if mode == FREE_OUTSIDE_VESSELS and free[i] == 0:
        stays_bound = inside_any_vessel(prm, vessels, motions, xi)  # bound liquid inside a vessel stays bound
    if stays_bound and measure_surface == 0 and record_pairs == 0:
        return
    surface = mode == FREE_AT_SURFACE or measure_surface != 0
    count = int(0)
    density = mass[i] * kernel_w(0.0, prm.inv_h, prm.sigma, prm.kernel)
    moment = wp.mat33(0.0)
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
            mj = mass[j]
            if not stays_bound:
                density += summation_term(prm, mj, r2)
            if surface or record_pairs != 0:
                gw = kernel_gradient(prm, r, r2)
                if surface:
                    moment += renormalisation_term(mj / prm.rest_density, r, gw)
                if record_pairs != 0 and count < capacity:
                    pair_index[i, count] = j
                    pair_grad[i, count] = gw
            count += 1
            j = next_liquid_neighbor(nb.x, j + 1, liquid_end, xi, radius2, COINCIDENT_R2)
        wall_end = nb.b_cell_end[cell]
        item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, nb.b_cell_start[cell], wall_end, xi, nb.inside[i], radius2, COINCIDENT_R2)
        while item < wall_end:
            b = nb.b_order[item]
            r = xi - nb.bx[b]
            r2 = wp.dot(r, r)
            mb = wall_mass(prm, b_volume, b)
            if not stays_bound:
                density += summation_term(prm, mb, r2)
            if surface or record_pairs != 0:
                gw = kernel_gradient(prm, r, r2)
                if surface:
                    moment += renormalisation_term(mb / prm.rest_density, r, gw)
                if record_pairs != 0 and count < capacity:
                    pair_index[i, count] = wall_pair(b)
                    pair_grad[i, count] = gw
            count += 1
            item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, item + 1, wall_end, xi, nb.inside[i], radius2, COINCIDENT_R2)
    if record_pairs != 0:
        pair_count[i] = wp.min(count, capacity)
        if count > capacity:
            wp.atomic_add(diag_i, diag_slot(prm, row[0], i), DIAG_PAIR_OVERFLOW, 1)
    density = density / prm.lattice_density
    lam = float(0.0)
    if surface:
        lam = surface_indicator(prm.dim, moment)
        indicator[i] = lam
    if stays_bound:
        return
    state = next_free_state(free[i], exposed_liquid(prm, vessels, motions, mode, xi, lam, threshold), density, prm.rest_density)
    if free[i] == 0 and state == 0:
        # bound liquid leaving over a lip (or at the surface) stays bound while it is packed: its summation density
        # then still carries the particle disorder's +-2-5 %, whose Tait pressure would kick it off the lip
        return
    free[i] = state
    rhoi = wp.max(density, prm.rest_density)
    rho[i] = rhoi
    p[i] = tait_pressure(prm, rhoi)


@wp.struct
class ForceSums:
    """What compute_forces sums over particle i's neighbours: its acceleration ``a`` (m/s^2) and, for the
    renormalised density gradient, ``moment`` = sum_j V_j (x_j - x_i) (x) grad W (dimensionless) and ``gsum`` =
    sum_j V_j (rho_j - rho_i) grad W (kg/m^4)."""

    a: wp.vec3
    moment: wp.mat33
    gsum: wp.vec3


@wp.func
def add_liquid_pair(
    prm: SPHParams, sums: ForceSums, density_gradient: bool, tic: int, own: float, free_i: int, vi: wp.vec3, rhoi: float,
    r: wp.vec3, r2: float, gw: wp.vec3, mj: float, vj: wp.vec3, rhoj: float, pj: float, free_j: int,
) -> ForceSums:
    """``sums`` with liquid neighbour j's share added (r = x_i - x_j, m; r2 = r . r; gw = grad_i W): the
    pressure term (:func:`pressure_pair_factor`), Monaghan's and the laminar viscosity (the free liquid's alpha where
    either particle is free) and, where ``density_gradient``, the renormalised density gradient's sums."""
    out = sums
    if density_gradient:
        vol = mj / rhoj
        out.moment = sums.moment + renormalisation_term(vol, r, gw)
        out.gsum = sums.gsum + (vol * (rhoj - rhoi)) * gw
    a = sums.a - mj * pressure_pair_factor(tic, own, rhoi, pj, rhoj) * gw
    alpha = wp.where(free_i != 0 or free_j != 0, prm.alpha_free, prm.alpha)
    vij = vi - vj
    out.a = a + viscous_pair(prm, alpha, mj, r, r2, gw, vij, vij, rhoi, rhoj)
    return out


@wp.func
def wall_pair_acceleration(
    prm: SPHParams, tic: int, own_wall: float, alpha_wall: float, vi: wp.vec3, rhoi: float, r: wp.vec3, r2: float, gw: wp.vec3,
    mb: float, pb: float, rhob: float, vb: wp.vec3, vb_noslip: wp.vec3,
) -> wp.vec3:
    """Particle i's acceleration (m/s^2) from wall particle b (mass ``mb``, extrapolated pressure ``pb`` and density
    ``rhob``, velocity ``vb`` and no-slip velocity ``vb_noslip``): its pressure term with i's own pressure clamped
    at 0 (``own_wall``: walls only push) and its viscous terms."""
    ab = -(mb * pressure_pair_factor(tic, own_wall, rhoi, pb, rhob)) * gw
    return ab + viscous_pair(prm, alpha_wall, mb, r, r2, gw, vi - vb, vi - vb_noslip, rhoi, rhob)


@wp.func
def wall_state_seen(
    prm: SPHParams, vessels: wp.array(dtype=VesselGeometry), motions: wp.array(dtype=VesselMotion), nb: Neighborhood,
    b_vessel: wp.array(dtype=wp.int32), b_p: wp.array(dtype=float), b_rho: wp.array(dtype=float),
    b_v_noslip: wp.array(dtype=wp.vec3), b_p_inner: wp.array(dtype=float), b_rho_inner: wp.array(dtype=float),
    b_v_noslip_inner: wp.array(dtype=wp.vec3), b: int, x: wp.vec3,
):
    """The extrapolated pressure (Pa), density (kg/m^3) and no-slip velocity (m/s) of wall particle b as the liquid at
    x sees it: a sided vessel's own wall particle shows the state of the face x is at
    (:func:`cosim.fluid.boundary.on_inner_face`), every other its one state."""
    if nb.b_side[b] == SEEN_FROM_OUTSIDE:
        vessel = b_vessel[b]
        if on_inner_face(prm, vessels[vessel], motions[vessel], x):
            return b_p_inner[b], b_rho_inner[b], b_v_noslip_inner[b]
    return b_p[b], b_rho[b], b_v_noslip[b]


@item_kernel
def compute_forces(
    # Model
    prm: SPHParams,
    vessels: wp.array(dtype=VesselGeometry),
    b_volume: wp.array(dtype=float),
    b_vessel: wp.array(dtype=wp.int32),
    # State in
    motions: wp.array(dtype=VesselMotion),
    nb: Neighborhood,
    v: wp.array(dtype=wp.vec3),
    rho: wp.array(dtype=float),
    p: wp.array(dtype=float),
    active: wp.array(dtype=wp.int32),
    free: wp.array(dtype=wp.int32),
    mass: wp.array(dtype=float),
    bv: wp.array(dtype=wp.vec3),
    b_p: wp.array(dtype=float),
    b_rho: wp.array(dtype=float),
    b_v_noslip: wp.array(dtype=wp.vec3),
    b_p_inner: wp.array(dtype=float),
    b_rho_inner: wp.array(dtype=float),
    b_v_noslip_inner: wp.array(dtype=wp.vec3),
    row: wp.array(dtype=wp.int32),
    capacity: int,
    pairs: int,
    pair_count: wp.array(dtype=wp.int32),
    pair_index: wp.array2d(dtype=wp.int32),
    pair_grad: wp.array2d(dtype=wp.vec3),
    tic: int,
    indicator: wp.array(dtype=float),
    # Out
    acc: wp.array(dtype=wp.vec3),
    rho_grad: wp.array(dtype=wp.vec3),
    wall_force: wp.array2d(dtype=wp.vec3),
    wall_torque: wp.array2d(dtype=wp.vec3),
    diag_f: wp.array2d(dtype=float),
    diag_i: wp.array2d(dtype=wp.int32),
):
    """Acceleration of each particle, the reaction it exerts on each vessel (per particle, reduced later) and its
    renormalised density gradient <grad rho>^L = L^-1 sum_j V_j (rho_j - rho_i) grad W, L = sum_j V_j (x_j - x_i)
    (x) grad W (Antuono et al. 2010; liquid neighbours only; zero where L is too ill-conditioned to invert, and under
    ``FluidConfig.density_diffusion_term`` 'fourtakas', whose diffusion does not read it). ``pairs``
    :data:`PAIRS_RECORDED_BY_FREE_LIQUID`: summed over the pair list update_free_liquid recorded in this substep (the
    same neighbours in the same order as a walk finds them: the same sums); otherwise over the neighbours walked from
    the cell ranges, more than ``capacity`` of them counted as an overflow, an instability, and under
    :data:`PAIRS_RECORDED_BY_FORCES` recorded as the substep's pair list (``pair_index[i, k]``: neighbour j >= 0 or
    wall code :func:`wall_pair`; ``pair_grad``: grad_i W), in the order of the loop, for compute_density_rate.
    ``tic`` 1: the pressure terms with Sun et al. (2018)'s tensile-instability control (:func:`pressure_pair_factor`),
    ``indicator`` each particle's free-surface indicator (read only then)."""
    i = wp.tid()
    for k in range(prm.n_vessels):
        wall_force[k, i] = wp.vec3(0.0)
        wall_torque[k, i] = wp.vec3(0.0)
    record = pairs == PAIRS_RECORDED_BY_FORCES
    if record:
        pair_count[i] = 0
    if active[i] == 0:
        acc[i] = wp.vec3(0.0)
        rho_grad[i] = wp.vec3(0.0)
        return
    xi = nb.x[i]
    vi = v[i]
    rhoi = rho[i]
    lam = float(1.0)
    if tic != 0:
        lam = indicator[i]
    own = own_pressure(tic, p[i], lam)
    # walls only push: a particle's tension (p < 0) must not pull it onto a wall (it would crawl along overhanging
    # outer faces, an artificial teapot effect); the walls' own pressure is clamped at 0 when extrapolated
    own_wall = wp.max(own, 0.0)
    free_i = free[i]
    alpha_wall = wp.where(free_i != 0, prm.alpha_free, prm.alpha)
    # the renormalised density gradient is read only by Antuono et al.'s diffusion term
    density_gradient = prm.hydrostatic_diffusion == 0
    sums = ForceSums()
    sums.a = wp.vec3(0.0)
    sums.moment = wp.mat33(0.0)
    sums.gsum = wp.vec3(0.0)
    if pairs == PAIRS_RECORDED_BY_FREE_LIQUID:
        for k in range(pair_count[i]):
            code = pair_index[i, k]
            gw = pair_grad[i, k]
            if code >= 0:
                r = xi - nb.x[code]
                sums = add_liquid_pair(
                    prm, sums, density_gradient, tic, own, free_i, vi, rhoi, r, wp.dot(r, r), gw, mass[code], v[code], rho[code], p[code], free[code],
                )
            else:
                b = pair_wall(code)
                r = xi - nb.bx[b]
                pb, rhob, vb_noslip = wall_state_seen(
                    prm, vessels, motions, nb, b_vessel, b_p, b_rho, b_v_noslip, b_p_inner, b_rho_inner, b_v_noslip_inner, b, xi,
                )
                ab = wall_pair_acceleration(prm, tic, own_wall, alpha_wall, vi, rhoi, r, wp.dot(r, r), gw, wall_mass(prm, b_volume, b), pb, rhob, bv[b], vb_noslip)
                sums.a = sums.a + ab
                add_wall_reaction(prm, vessels, motions, b_vessel[b], i, nb.bx[b], ab, wall_force, wall_torque)
    else:
        count = int(0)
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
                gw = kernel_gradient(prm, r, r2)
                if record and count < capacity:
                    pair_index[i, count] = j
                    pair_grad[i, count] = gw
                sums = add_liquid_pair(prm, sums, density_gradient, tic, own, free_i, vi, rhoi, r, r2, gw, mass[j], v[j], rho[j], p[j], free[j])
                count += 1
                j = next_liquid_neighbor(nb.x, j + 1, liquid_end, xi, radius2, COINCIDENT_R2)
            wall_end = nb.b_cell_end[cell]
            item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, nb.b_cell_start[cell], wall_end, xi, nb.inside[i], radius2, COINCIDENT_R2)
            while item < wall_end:
                b = nb.b_order[item]
                r = xi - nb.bx[b]
                r2 = wp.dot(r, r)
                gw = kernel_gradient(prm, r, r2)
                if record and count < capacity:
                    pair_index[i, count] = wall_pair(b)
                    pair_grad[i, count] = gw
                pb, rhob, vb_noslip = wall_state_seen(
                    prm, vessels, motions, nb, b_vessel, b_p, b_rho, b_v_noslip, b_p_inner, b_rho_inner, b_v_noslip_inner, b, xi,
                )
                ab = wall_pair_acceleration(prm, tic, own_wall, alpha_wall, vi, rhoi, r, r2, gw, wall_mass(prm, b_volume, b), pb, rhob, bv[b], vb_noslip)
                sums.a = sums.a + ab
                add_wall_reaction(prm, vessels, motions, b_vessel[b], i, nb.bx[b], ab, wall_force, wall_torque)
                count += 1
                item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, item + 1, wall_end, xi, nb.inside[i], radius2, COINCIDENT_R2)
        if count > capacity:
            wp.atomic_add(diag_i, diag_slot(prm, row[0], i), DIAG_PAIR_OVERFLOW, 1)
        if record:
            pair_count[i] = wp.min(count, capacity)
    a = sums.a + prm.gravity
    acc[i] = a
    grad = wp.vec3(0.0)
    if density_gradient:
        moment = sums.moment
        if prm.dim == 2:
            moment[1, 1] = 1.0
        if wp.determinant(moment) > RENORMALISATION_MIN_DET:
            grad = wp.inverse(moment) @ sums.gsum
    rho_grad[i] = grad
    wp.atomic_max(diag_f, diag_slot(prm, row[0], i), DIAG_MAX_ACCEL, wp.length(a))


@wp.func
def hydrostatic_density_difference(prm: SPHParams, r: wp.vec3) -> float:
    """rho^H_i - rho^H_j (kg/m^3) of a liquid at rest under gravity g between particle i and particle j = i - r:
    the Tait equation p = B ((rho / rho0)^gamma - 1) solved for the density at the hydrostatic pressure difference
    rho0 g . r (Pa; positive where i lies deeper), rho0 ((1 + rho0 g . r / B)^(1/gamma) - 1)."""
    return prm.rest_density * (wp.pow(1.0 + prm.rest_density * wp.dot(prm.gravity, r) / prm.eos_b, 1.0 / prm.gamma) - 1.0)


@wp.func
def add_liquid_density_rate(
    prm: SPHParams, dr: float, diffusion: float, rhoi: float, grad_i: wp.vec3, vi: wp.vec3, r: wp.vec3, r2: float, gw: wp.vec3,
    vj: wp.vec3, rhoj: float, grad_j: wp.vec3, mj: float,
) -> float:
    """The density rate sum ``dr`` (kg/m^3/s) with a liquid neighbour j's share added: continuity
    m_j v_ij . grad W, then delta-SPH diffusion ``diffusion`` (m_j / rho_j) psi_ij (``diffusion`` = delta h c0,
    m^2/s), at the kicked velocities vi, vj (m/s); r = x_i - x_j (m), r2 = r . r, gw = grad_i W. psi_ij:

    - Antuono et al. (2010): 2 (rho_i - rho_j) r . grad W / (r^2 + eta^2) - (<grad rho>_i + <grad rho>_j) . grad W,
      the renormalised gradients ``grad_i``, ``grad_j`` removing a linear density field's share;
    - ``prm.hydrostatic_diffusion`` (Fourtakas, Dominguez, Vacondio & Rogers 2019, "Local uniform stencil (LUST)
      boundary condition for arbitrary 3-D boundaries in parallel smoothed particle hydrodynamics (SPH) models",
      Comput. Fluids 190): 2 (rho~_i - rho~_j - rho^H_ij) r . grad W / (r^2 + eta^2), where
      rho^H_ij = rho0 ((1 + rho0 g . r / B)^(1/gamma) - 1) is the density difference the Tait equation gives a
      resting liquid between the pair's heights (:func:`hydrostatic_density_difference`): only the dynamic density
      diffuses, and no gradient is estimated: a resting column's hydrostatic profile is not diffused whatever the
      support, also where a wall or the free surface cuts it and the renormalised gradient is only approximate.
      rho~ = max(rho, rho_t), rho_t the density at which the tension clamp binds (``prm.tension_density``; rho0
      without tension, 0 under tensile-instability control): the density the pressure sees. Below rho_t a particle
      is a void the pressure ignores; diffusing its deficit into the liquid around it would take pressure from
      liquid that is not expanded, and without tension nothing gives it back: a caught pool's floor loses its
      hydrostatic pressure and the liquid sinks into the wall (a departure from Fourtakas et al., who keep
      tension; docs/density_diffusion.md)."""
    dr += mj * wp.dot(vi - vj, gw)
    psi = float(0.0)
    if prm.hydrostatic_diffusion != 0:
        dynamic = wp.max(rhoi, prm.tension_density) - wp.max(rhoj, prm.tension_density) - hydrostatic_density_difference(prm, r)
        psi = 2.0 * dynamic * wp.dot(r, gw) / (r2 + prm.eta2)
    else:
        psi = 2.0 * (rhoi - rhoj) * wp.dot(r, gw) / (r2 + prm.eta2) - wp.dot(grad_i + grad_j, gw)
    return dr + diffusion * (mj / rhoj) * psi


@wp.func
def wall_density_rate(prm: SPHParams, volume: float, vi: wp.vec3, vb: wp.vec3, gw: wp.vec3) -> float:
    """A wall particle's share of particle i's density rate (kg/m^3/s): rho0 V_b (v_i - v_b) . grad W, the wall
    moving at vb (m/s)."""
    return prm.rest_density * volume * wp.dot(vi - vb, gw)


@item_kernel
def compute_density_rate(
    # Model
    prm: SPHParams,
    b_volume: wp.array(dtype=float),
    # State in
    x: wp.array(dtype=wp.vec3),
    v: wp.array(dtype=wp.vec3),
    acc: wp.array(dtype=wp.vec3),
    rho: wp.array(dtype=float),
    rho_grad: wp.array(dtype=wp.vec3),
    active: wp.array(dtype=wp.int32),
    mass: wp.array(dtype=float),
    dt: wp.array(dtype=float),
    bv: wp.array(dtype=wp.vec3),
    pair_count: wp.array(dtype=wp.int32),
    pair_index: wp.array2d(dtype=wp.int32),
    pair_grad: wp.array2d(dtype=wp.vec3),
    # Out
    drho: wp.array(dtype=float),
):
    """Density rate from the continuity equation with the KICKED velocities v + dt a (symplectic: the density
    sees the velocity it is integrated with), plus delta-SPH diffusion (Antuono et al. 2010):
    delta h c0 sum_j V_j [2 (rho_i - rho_j) r_ij . grad W / (r^2 + eta^2) - (<grad rho>_i + <grad rho>_j) . grad W],
    which vanishes for any linear density field (a resting column) and conserves mass between pairs. Sums over
    the substep's pair list, in its order (the neighbours have not moved since)."""
    i = wp.tid()
    if active[i] == 0:
        drho[i] = 0.0
        return
    h = dt[0]
    xi = x[i]
    vi = v[i] + h * acc[i]
    rhoi = rho[i]
    grad_i = rho_grad[i]
    diffusion = prm.delta * prm.h * prm.sound_speed
    dr = float(0.0)
    for k in range(pair_count[i]):
        j = pair_index[i, k]
        gw = pair_grad[i, k]
        if j >= 0:
            r = xi - x[j]
            dr = add_liquid_density_rate(prm, dr, diffusion, rhoi, grad_i, vi, r, wp.dot(r, r), gw, v[j] + h * acc[j], rho[j], rho_grad[j], mass[j])
        else:
            b = pair_wall(j)
            dr += wall_density_rate(prm, b_volume[b], vi, bv[b], gw)
    drho[i] = dr


@item_kernel
def compute_density_rate_walking(
    # Model
    prm: SPHParams,
    b_volume: wp.array(dtype=float),
    # State in
    nb: Neighborhood,
    v: wp.array(dtype=wp.vec3),
    acc: wp.array(dtype=wp.vec3),
    rho: wp.array(dtype=float),
    rho_grad: wp.array(dtype=wp.vec3),
    active: wp.array(dtype=wp.int32),
    mass: wp.array(dtype=float),
    dt: wp.array(dtype=float),
    bv: wp.array(dtype=wp.vec3),
    # Out
    drho: wp.array(dtype=float),
):
    """compute_density_rate's sum over the neighbours walked again from the cell ranges (the neighbours
    compute_forces walked, in its order; nothing read from pair tables): a layout without pair tables trades their
    writes and reads for more walks and the kernel gradients computed again."""
    i = wp.tid()
    if active[i] == 0:
        drho[i] = 0.0
        return
    h = dt[0]
    xi = nb.x[i]
    vi = v[i] + h * acc[i]
    rhoi = rho[i]
    grad_i = rho_grad[i]
    diffusion = prm.delta * prm.h * prm.sound_speed
    dr = float(0.0)
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
            gw = kernel_gradient(prm, r, r2)
            dr = add_liquid_density_rate(prm, dr, diffusion, rhoi, grad_i, vi, r, r2, gw, v[j] + h * acc[j], rho[j], rho_grad[j], mass[j])
            j = next_liquid_neighbor(nb.x, j + 1, liquid_end, xi, radius2, COINCIDENT_R2)
        wall_end = nb.b_cell_end[cell]
        item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, nb.b_cell_start[cell], wall_end, xi, nb.inside[i], radius2, COINCIDENT_R2)
        while item < wall_end:
            b = nb.b_order[item]
            r = xi - nb.bx[b]
            r2 = wp.dot(r, r)
            dr += wall_density_rate(prm, b_volume[b], vi, bv[b], kernel_gradient(prm, r, r2))
            item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, item + 1, wall_end, xi, nb.inside[i], radius2, COINCIDENT_R2)
    drho[i] = dr


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
    drho: wp.array(dtype=float),
    acc: wp.array(dtype=wp.vec3),
    # State in/out
    free: wp.array(dtype=wp.int32),
    mass: wp.array(dtype=float),
    x: wp.array(dtype=wp.vec3),
    v: wp.array(dtype=wp.vec3),
    rho: wp.array(dtype=float),
    p: wp.array(dtype=float),
    active: wp.array(dtype=wp.int32),
    wall_force: wp.array2d(dtype=wp.vec3),
    wall_torque: wp.array2d(dtype=wp.vec3),
    # Out
    diag_f: wp.array2d(dtype=float),
    diag_i: wp.array2d(dtype=wp.int32),
):
    i = wp.tid()
    if active[i] == 0:
        return
    s = diag_slot(prm, row[0], i)
    h = dt[0]
    x_old = x[i]
    vi = v[i] + h * acc[i]
    xi = x_old + h * vi
    # The density is not floored at rho0 (only the pressure, by max_tension): a floor would ratchet, in an agitated
    # bed every expansion clipped and every collision compressing from there, so that the density climbs and props
    # the liquid up as a "gas". The safety floor below only stops the rare runaway expansion of a fragment whose
    # support emptied (its density would otherwise fall without bound, even below zero).
    rhoi = wp.max(rho[i] + h * drho[i], MIN_DENSITY_RATIO * prm.rest_density)
    if free[i] != 0:
        rhoi = rho[i]  # free liquid: the summation density, recomputed at the next substep's start
    kept = finish_particle(
        prm, vessels, motions, domain_min, domain_max, guard_margin, max_penetration, s, i, x_old, xi, vi, rhoi, h,
        x, v, active, mass, free, wall_force, wall_torque, diag_f, diag_i,
    )
    if kept == 0:
        return
    rho[i] = rhoi
    p[i] = tait_pressure(prm, rhoi)
    wp.atomic_add(diag_f, s, DIAG_INTERNAL_ENERGY, prm.mass_out * tait_internal_energy(prm, rhoi))
    wp.atomic_max(diag_f, s, DIAG_MAX_DENSITY_ERROR, wp.abs(rhoi - prm.rest_density) / prm.rest_density)
    wp.atomic_max(diag_f, s, DIAG_MAX_COMPRESSION, (rhoi - prm.rest_density) / prm.rest_density)


@wp.kernel
def measure_internal_energy(prm: SPHParams, rho: wp.array(dtype=float), energy: wp.array(dtype=float)):
    """Each particle's elastic energy (J, 3-D equivalent) at its density (the energy account's start)."""
    i = wp.tid()
    energy[i] = prm.mass_out * tait_internal_energy(prm, rho[i])


@wp.kernel
def equation_of_state(prm: SPHParams, rho: wp.array(dtype=float), p: wp.array(dtype=float)):
    """p from rho for every particle (used once at start-up; integrate() keeps p current afterwards)."""
    i = wp.tid()
    p[i] = tait_pressure(prm, rho[i])
