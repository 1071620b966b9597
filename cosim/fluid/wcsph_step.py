"""The weakly compressible SPH substep (the kernels and their physics: ``cosim.fluid.wcsph``).

    start_substep: move_vessels; place_wall_particles; find_neighbors; reorder_particles (``cosim.fluid.substep``)
    update_free_liquid      free liquid takes its summation density (``FluidConfig.free_liquid``); each particle's
                            free-surface indicator where the rule or the tensile-instability control uses it, and
                            then the substep's pair list (:func:`pair_recording`)
    extrapolate_wall_state  the wall particles' pressure, density and no-slip velocity from the liquid around them
    compute_forces          pressure, viscous and wall forces; the density gradient; the pair list where
                            update_free_liquid did not record it
    compute_density_rate    continuity with delta-SPH diffusion, over the pair list (or over the neighbours walked
                            again, where the device layout keeps no pair tables)
    integrate               symplectic Euler, the equation of state, the wall guard, diagnostics
    end_substep: reduce_wrenches; next_row (``cosim.fluid.substep``)
"""

from __future__ import annotations

import numpy as np
import warp as wp

from cosim.fluid import boundary as bd
from cosim.fluid import wcsph
from cosim.fluid.device_layout import pair_table
from cosim.fluid.config import FluidConfig, TensionTreatment
from cosim.fluid.free_surface import FREE_AT_SURFACE, free_liquid_mode
from cosim.fluid.launch import launch_now
from cosim.fluid.model import FluidModel, FluidState
from cosim.fluid.program import Recorder
from cosim.fluid.substep import PairList, SubstepScratch, end_substep, start_substep


class WCSPHScratch:
    """WCSPH's per-substep arrays: acc (N,) m/s^2; rho_grad (N,) the renormalised density gradient (kg/m^4); drho
    (N,) kg/m^3/s; pairs: the pair list (tables of one slot where the layout keeps none); b_p (Pa), b_rho (kg/m^3), b_v_noslip (m/s): (Nb,) the wall particles'
    extrapolated state; b_p_inner, b_rho_inner, b_v_noslip_inner: a sided vessel's own wall's state on its inner face
    (``cosim.fluid.boundary.extrapolate_wall_state``; (Nb,) where some wall is sided, else empty)."""

    def __init__(self, m: FluidModel, sh: SubstepScratch):
        d, n, nb, by_column = m.device, m.n_particles, m.n_boundary, sh.layout.pairs_by_column
        self.acc = wp.zeros(n, dtype=wp.vec3, device=d)
        self.rho_grad = wp.zeros(n, dtype=wp.vec3, device=d)
        self.drho = wp.zeros(n, dtype=float, device=d)
        rows, slots = (n, sh.pair_capacity) if sh.layout.pair_tables else (1, 1)
        self.pairs = PairList(
            wp.zeros(rows, dtype=wp.int32, device=d), pair_table(rows, slots, wp.int32, d, by_column), pair_table(rows, slots, wp.vec3, d, by_column),
        )
        self.b_p = wp.zeros(nb, dtype=float, device=d)
        self.b_rho = wp.zeros(nb, dtype=float, device=d)
        self.b_v_noslip = wp.zeros(nb, dtype=wp.vec3, device=d)
        inner = nb if m.one_sided_walls else 0
        self.b_p_inner = wp.zeros(inner, dtype=float, device=d)
        self.b_rho_inner = wp.zeros(inner, dtype=float, device=d)
        self.b_v_noslip_inner = wp.zeros(inner, dtype=wp.vec3, device=d)


def pair_recording(cfg: FluidConfig, sh: SubstepScratch) -> int:
    """Which pass records the substep's pair list (the kernels' int, ``cosim.fluid.wcsph.PAIRS_*``): none without pair
    tables; update_free_liquid where it walks every particle (the 'free_surface' rule or the tensile-instability
    control); else compute_forces."""
    if not sh.layout.pair_tables:
        return int(wcsph.PAIRS_WALKED)
    if tension_control(cfg) or free_liquid_mode(cfg) == FREE_AT_SURFACE:
        return int(wcsph.PAIRS_RECORDED_BY_FREE_LIQUID)
    return int(wcsph.PAIRS_RECORDED_BY_FORCES)


def tension_control(cfg: FluidConfig) -> int:
    """1 where the pressure gradient has Sun et al. (2018)'s tensile-instability control
    (``FluidConfig.tension_treatment`` 'tic'), else 0 (the kernels' int)."""
    return int(cfg.tension_treatment is TensionTreatment.TIC)


def update_free_liquid(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: WCSPHScratch) -> None:
    """Free liquid (outside every vessel or at the free surface, by ``FluidConfig.free_liquid_rule``, and separated;
    or not yet packed again) takes the tension-free summation density (``cosim.fluid.wcsph.update_free_liquid``);
    under tensile-instability control every particle's free-surface indicator is computed in the same walk. Where
    that walk covers every particle and the layout keeps pair tables, it records the substep's pair list
    (:func:`pair_recording`)."""
    tic = tension_control(m.config)
    if not m.config.free_liquid and not tic:
        return
    record_pairs = pair_recording(m.config, sh) == wcsph.PAIRS_RECORDED_BY_FREE_LIQUID
    rec.launch(
        wcsph.update_free_liquid, m.n_particles, prm=m.params, vessels=m.vessels, b_volume=m.b_volume, mode=free_liquid_mode(m.config),
        threshold=m.config.free_surface_threshold, measure_surface=tic, motions=sh.motions, nb=sh.neighborhood(m, st), active=st.active, mass=st.mass,
        row=sh.row, capacity=sh.pair_capacity, record_pairs=int(record_pairs), free=st.free, rho=st.rho, p=st.p, indicator=sh.free_surface,
        pair_count=sc.pairs.count, pair_index=sc.pairs.index, pair_grad=sc.pairs.grad, diag_i=sh.diagnostics.lane_i,
    )


def extrapolate_wall_state(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: WCSPHScratch) -> None:
    """Each wall particle's pressure, density and no-slip velocity from the liquid around it
    (``cosim.fluid.boundary.extrapolate_wall_state``)."""
    if not m.n_boundary:
        return
    rec.launch(
        bd.extrapolate_wall_state, m.n_boundary, prm=m.params, vessels=m.vessels, b_vessel=m.b_vessel, motions=sh.motions,
        nb=sh.neighborhood(m, st), bv=sh.bv, v=st.v, rho=st.rho, p=st.p, b_p=sc.b_p, b_rho=sc.b_rho, b_v_noslip=sc.b_v_noslip,
        b_p_inner=sc.b_p_inner, b_rho_inner=sc.b_rho_inner, b_v_noslip_inner=sc.b_v_noslip_inner,
    )


def compute_forces(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: WCSPHScratch) -> None:
    """Each particle's acceleration, its reaction on the vessels and its density gradient, over the pair list
    update_free_liquid recorded or the neighbours walked (recording the list where the layout keeps pair tables)."""
    rec.launch(
        wcsph.compute_forces, m.n_particles, prm=m.params, vessels=m.vessels, b_volume=m.b_volume, b_vessel=m.b_vessel,
        motions=sh.motions, nb=sh.neighborhood(m, st), v=st.v, rho=st.rho, p=st.p, active=st.active, free=st.free, mass=st.mass,
        bv=sh.bv, b_p=sc.b_p, b_rho=sc.b_rho, b_v_noslip=sc.b_v_noslip, b_p_inner=sc.b_p_inner, b_rho_inner=sc.b_rho_inner,
        b_v_noslip_inner=sc.b_v_noslip_inner, row=sh.row, capacity=sh.pair_capacity, pairs=pair_recording(m.config, sh),
        pair_count=sc.pairs.count, pair_index=sc.pairs.index, pair_grad=sc.pairs.grad, tic=tension_control(m.config), indicator=sh.free_surface,
        acc=sc.acc, rho_grad=sc.rho_grad, wall_force=sh.wall_force, wall_torque=sh.wall_torque, diag_f=sh.diagnostics.lane_f, diag_i=sh.diagnostics.lane_i,
    )


def compute_density_rate(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: WCSPHScratch) -> None:
    """The continuity equation's density rate with delta-SPH diffusion, over the pair list (or the neighbours
    walked again, where the layout keeps no pair tables)."""
    if not sh.layout.pair_tables:
        rec.launch(
            wcsph.compute_density_rate_walking, m.n_particles, prm=m.params, b_volume=m.b_volume, nb=sh.neighborhood(m, st), v=st.v, acc=sc.acc, rho=st.rho,
            rho_grad=sc.rho_grad, active=st.active, mass=st.mass, dt=sh.dt, bv=sh.bv, drho=sc.drho,
        )
        return
    rec.launch(
        wcsph.compute_density_rate, m.n_particles, prm=m.params, b_volume=m.b_volume, x=st.x, v=st.v, acc=sc.acc, rho=st.rho, rho_grad=sc.rho_grad,
        active=st.active, mass=st.mass, dt=sh.dt, bv=sh.bv, pair_count=sc.pairs.count, pair_index=sc.pairs.index, pair_grad=sc.pairs.grad, drho=sc.drho,
    )


def integrate(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: WCSPHScratch) -> None:
    """Symplectic Euler of velocity, position and density, the equation of state, the wall guard and diagnostics."""
    rec.launch(
        wcsph.integrate, m.n_particles, **sh.guard_args(m), drho=sc.drho, acc=sc.acc, free=st.free, mass=st.mass,
        x=st.x, v=st.v, rho=st.rho, p=st.p, active=st.active, wall_force=sh.wall_force, wall_torque=sh.wall_torque,
        diag_f=sh.diagnostics.lane_f, diag_i=sh.diagnostics.lane_i,
    )


class WCSPHStep:
    """Weakly compressible SPH (Monaghan's Tait equation of state, delta-SPH; ``cosim.fluid.wcsph``): owns its
    scratch; :meth:`substep` is the substep, stage by stage."""

    def __init__(self, model: FluidModel, shared: SubstepScratch):
        self.model = model
        self.shared = shared
        self.scratch = WCSPHScratch(model, shared)

    def initialise(self, st: FluidState) -> None:
        """The seeded liquid's pressure from its density (the equation of state)."""
        launch_now(wcsph.equation_of_state, self.model.n_particles, self.model.device, dict(prm=self.model.params, rho=st.rho, p=st.p))

    def internal_energy(self, st: FluidState) -> float:
        """Elastic energy the Tait liquid stores (J): sum m u(rho)."""
        energy = wp.zeros(self.model.n_particles, dtype=float, device=self.model.device)
        launch_now(wcsph.measure_internal_energy, self.model.n_particles, self.model.device, dict(prm=self.model.params, rho=st.rho, energy=energy))
        return float(energy.numpy().astype(np.float64).sum())

    def begin_interval(self, st: FluidState, substeps: int) -> None:
        """Nothing to prepare: the pressure is the last substep's."""

    def substep(self, rec: Recorder, src: FluidState, st: FluidState) -> None:
        """One substep: the liquid ``src`` reordered into ``st`` and advanced there."""
        m, sh, sc = self.model, self.shared, self.scratch
        start_substep(rec, m, src, st, sh)
        update_free_liquid(rec, m, st, sh, sc)
        extrapolate_wall_state(rec, m, st, sh, sc)
        compute_forces(rec, m, st, sh, sc)
        compute_density_rate(rec, m, st, sh, sc)
        integrate(rec, m, st, sh, sc)
        end_substep(rec, m, sh)
