"""The divergence-free SPH substep (Bender & Koschier 2015, 2017; the kernels and their physics: ``cosim.fluid.dfsph``).

    start_substep: move_vessels; place_wall_particles; find_neighbors; reorder_particles (``cosim.fluid.substep``)
    compute_density_factor       summation density, the DFSPH factor, the pair list; the divergence solve's warm start
    compute_wall_density_factor  the same for the wall layer facing the liquid, with its warm start (a solved layer only,
                                 :func:`solved_wall_layer`)
    divergence_solve             Jacobi iterations until the density rate is small
    compute_nonpressure          v* = v + dt (g + viscosity); the density solve's warm start (and, for Gauss-Seidel,
                                 each sweep thread's cells)
    density_solve                Gauss-Seidel sweeps by cell colour, or Jacobi iterations, until the predicted
                                 compression is small
    compute_wall_reaction        the vessels' share of both solves' pair forces; the interval's average pressure
    integrate                    x += dt v*, the wall guard, diagnostics
    carry_density                ('continuity' surface density) the held density carried over the substep
    end_substep: reduce_wrenches; next_row (``cosim.fluid.substep``)

Each solve is a loop on a device flag (``wp.capture_while``) that ``check_convergence`` clears.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from cosim.fluid import dfsph, wcsph
from cosim.fluid.config import DensityIteration, DivergenceConstraint, InitialState, SurfaceDensity, WallPressure
from cosim.fluid.free_surface import free_liquid_mode
from cosim.fluid.lanes import LANE_CHUNK, Lanes, PerLane
from cosim.fluid.launch import launch_now
from cosim.fluid.model import FluidModel, FluidState
from cosim.fluid.pair_slots import flat_pair_table, pair_slots
from cosim.fluid.program import Recorder
from cosim.fluid.substep import PairList, SubstepScratch, end_substep, start_substep


def continuity_surface(m: FluidModel) -> bool:
    """Whether the surface rows' density is carried by the continuity equation (``FluidConfig.surface_density``
    'continuity', ``cosim.fluid.dfsph.surface_offset``) rather than held to a seeded offset."""
    return m.config.surface_density is SurfaceDensity.CONTINUITY


def solved_wall_layer(m: FluidModel) -> bool:
    """Whether the wall layer facing the liquid is solved with it (``FluidConfig.wall_pressure`` 'solved_layer' or
    'solved_rest_sum'). Otherwise ('mirrored') its stages do not run: its stiffness stays zero and its density rho0, so each wall pair
    of the liquid's pressure terms carries the liquid particle's own stiffness alone, sum_b rho0 V_b (k_i / rho_i)
    grad W_ib (``cosim.fluid.dfsph``, pressure-carrying walls), in the solves and in the wall reaction alike."""
    return m.config.wall_pressure is not WallPressure.MIRRORED


class DFSPHScratch:
    """DFSPH's per-substep arrays.

    Liquid (N,): alpha, the DFSPH factor (``cosim.fluid.dfsph.compute_density_factor``); increment, increment_per_rho, the
    stiffness increments a solve applies next (m^2/s^2, and over rho); v_star, the predicted velocity (m/s);
    pairs and pair_mass_grad (the pair list, and its gradients times the neighbour's mass: flat tables, each particle's
    entries at the slots of pair_slots, ``cosim.fluid.pair_slots``). Wall layer (Nb,): b_rho, b_alpha, b_increment,
    b_increment_per_rho, b_kappa_density, b_kappa_divergence and its list of liquid neighbours (b_pair_count,
    b_pair_slots, b_pair_index, b_pair_mass_grad). Solves: solve_stats (int64, a padded row per lane and
    replica), keep_going (the loop flag), substep_weight (1 / substeps of the interval). Gauss-Seidel: each sweep
    thread's cells and their colours (sweep_count, sweep_cell, sweep_color).
    """

    def __init__(self, m: FluidModel, sh: SubstepScratch, lanes: Lanes, gauss_seidel: bool):
        d, n, nb, cap, by_column, packed = m.device, m.n_particles, m.n_boundary, sh.pair_capacity, sh.layout.pairs_by_column, sh.layout.pairs_packed
        self.alpha = wp.zeros(n, dtype=float, device=d)
        self.increment = wp.zeros(n, dtype=float, device=d)
        self.increment_per_rho = wp.zeros(n, dtype=float, device=d)
        self.v_star = wp.zeros(n, dtype=wp.vec3, device=d)
        self.pairs = PairList(wp.zeros(n, dtype=wp.int32, device=d), flat_pair_table(n, cap, wp.int32, d), flat_pair_table(n, cap, wp.vec3, d))
        self.pair_slots = pair_slots(n, cap, d, by_column, packed)
        self.pair_mass_grad = flat_pair_table(n, cap, wp.vec3, d)
        self.b_rho = wp.zeros(nb, dtype=float, device=d)
        if not solved_wall_layer(m):
            self.b_rho.fill_(m.config.rest_density)  # never computed: the mirrored walls' k_b / rho_b = 0 / rho0
        self.b_alpha = wp.zeros(nb, dtype=float, device=d)
        self.b_increment = wp.zeros(nb, dtype=float, device=d)
        self.b_increment_per_rho = wp.zeros(nb, dtype=float, device=d)
        self.b_kappa_density = wp.zeros(nb, dtype=float, device=d)
        self.b_kappa_divergence = wp.zeros(nb, dtype=float, device=d)
        self.b_pair_count = wp.zeros(nb, dtype=wp.int32, device=d)
        self.b_pair_slots = pair_slots(nb, cap, d, by_column, packed)
        self.b_pair_index = flat_pair_table(nb, cap, wp.int32, d)
        self.b_pair_mass_grad = flat_pair_table(nb, cap, wp.vec3, d)
        replicas = sh.layout.atomic_replicas  # rows per lane (check_convergence sums every row)
        self.solve_stats = wp.zeros((lanes.count * replicas, dfsph.STATS_ROW_STRIDE), dtype=wp.int64, device=d)
        self.lane_stats = PerLane(self.solve_stats[k * replicas : (k + 1) * replicas].flatten() for k in range(lanes.count))
        self.keep_going = wp.zeros(1, dtype=wp.int32, device=d)
        self.substep_weight = wp.zeros(1, dtype=float, device=d)
        # threads of each Gauss-Seidel colour launch: one per item on CUDA, a chunk per lane on the CPU
        self.sweep_threads = n + nb if d.is_cuda else LANE_CHUNK * lanes.count
        if gauss_seidel:
            per_thread = -(-(n + nb) // self.sweep_threads)
            self.sweep_count = wp.zeros(self.sweep_threads, dtype=wp.int32, device=d)
            self.sweep_cell = wp.zeros((self.sweep_threads, per_thread), dtype=wp.int32, device=d)
            self.sweep_color = wp.zeros((self.sweep_threads, per_thread), dtype=wp.int32, device=d)


def compute_density_factor(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: DFSPHScratch) -> None:
    """Summation density (held to the seeded offset or free), the DFSPH factor, the substep's pair list, and the
    divergence solve's warm start and counters."""
    rec.launch(
        dfsph.compute_density_factor, m.n_particles, prm=m.params, vessels=m.vessels, b_volume=m.b_volume,
        capacity=sh.pair_capacity, free_liquid=free_liquid_mode(m.config), threshold=m.config.free_surface_threshold,
        surface_density=dfsph.SURFACE_CONTINUITY if continuity_surface(m) else dfsph.SURFACE_SEEDED_OFFSET, motions=sh.motions, nb=sh.neighborhood(m, st), active=st.active,
        mass=st.mass, row=sh.row, kappa_divergence=st.kappa_divergence, free=st.free, rest_offset=st.rest_offset,
        rho=st.rho, alpha=sc.alpha, increment=sc.increment, increment_per_rho=sc.increment_per_rho,
        pair_count=sc.pairs.count, pair_slots=sc.pair_slots, pair_index=sc.pairs.index, pair_grad=sc.pairs.grad, pair_mass_grad=sc.pair_mass_grad,
        indicator=sh.free_surface, solve_stats=sc.lane_stats, keep_going=sc.keep_going, diag_f=sh.diagnostics.lane_f, diag_i=sh.diagnostics.lane_i,
    )


def compute_wall_density_factor(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: DFSPHScratch) -> None:
    """The wall layer's summation density, factor and list of liquid neighbours."""
    rec.launch(
        dfsph.compute_wall_density_factor, m.n_boundary, prm=m.params, b_volume=m.b_volume, b_wetted=m.b_wetted, b_rest_offset=m.b_rest_offset,
        capacity=sh.pair_capacity, nb=sh.neighborhood(m, st), mass=st.mass, row=sh.row, b_rho=sc.b_rho, b_alpha=sc.b_alpha,
        b_pair_count=sc.b_pair_count, b_pair_slots=sc.b_pair_slots, b_pair_index=sc.b_pair_index, b_pair_mass_grad=sc.b_pair_mass_grad,
        solve_stats=sc.lane_stats, diag_i=sh.diagnostics.lane_i,
    )


def start_wall_solve(rec: Recorder, m: FluidModel, sc: DFSPHScratch, b_kappa: wp.array, warm_start: float, warm_start_applied: bool) -> None:
    """The wall layer's warm start of a solve (``b_kappa``: that solve's stiffness)."""
    rec.launch(
        dfsph.start_wall_solve, m.n_boundary, warm_start=float(warm_start), warm_start_applied=int(warm_start_applied), b_rho=sc.b_rho,
        b_kappa=b_kappa, b_increment=sc.b_increment, b_increment_per_rho=sc.b_increment_per_rho,
    )


def apply_stiffness(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: DFSPHScratch, v: wp.array, kappa: wp.array) -> None:
    """The pending stiffness increments (a solve's warm start, or a Jacobi iteration's) applied to ``v`` and added to
    ``kappa``."""
    rec.launch(
        dfsph.apply_stiffness, m.n_particles, increment=sc.increment, increment_per_rho=sc.increment_per_rho, active=st.active, dt=sh.dt,
        pair_count=sc.pairs.count, pair_slots=sc.pair_slots, pair_index=sc.pairs.index, pair_mass_grad=sc.pair_mass_grad, b_increment_per_rho=sc.b_increment_per_rho,
        v=v, kappa=kappa,
    )


def check_convergence(rec: Recorder, m: FluidModel, sh: SubstepScratch, sc: DFSPHScratch, mode: int) -> None:
    """The end of a solve's iteration: its error measured, the stop decided, its diagnostics written."""
    rec.launch_on_lane(
        dfsph.check_convergence, 1, prm=m.params, mode=mode, row=sh.row, solve_stats=sc.solve_stats, keep_going=sc.keep_going,
        diag_f=sh.diagnostics.lane_f[0], diag_i=sh.diagnostics.lane_i[0],
    )


def jacobi_solve(
    rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: DFSPHScratch, mode: int, v: wp.array, kappa: wp.array, b_kappa: wp.array,
) -> None:
    """A solve by Jacobi iterations (``mode``: dfsph.SOLVE_DIVERGENCE or SOLVE_DENSITY) on the velocities ``v``: each
    applies the increments the last measured (the first, the warm start), then measures the liquid's and the wall
    layer's (a solved one's) errors and their next increments."""
    with rec.loop(sc.keep_going):
        apply_stiffness(rec, m, st, sh, sc, v, kappa)
        with rec.together():
            rec.launch(
                dfsph.compute_solve_error, m.n_particles, prm=m.params, mode=mode,
                past_rest=int(m.config.divergence_constraint is DivergenceConstraint.PAST_REST_DENSITY), v=v, rho=st.rho, alpha=sc.alpha, active=st.active, dt=sh.dt,
                bv=sh.bv, pair_count=sc.pairs.count, pair_slots=sc.pair_slots, pair_index=sc.pairs.index, pair_mass_grad=sc.pair_mass_grad,
                increment=sc.increment, increment_per_rho=sc.increment_per_rho, solve_stats=sc.lane_stats,
            )
            if solved_wall_layer(m):
                rec.launch(
                    dfsph.compute_wall_solve_error, m.n_boundary, prm=m.params, mode=mode, v=v, dt=sh.dt, bv=sh.bv, b_rho=sc.b_rho,
                    b_alpha=sc.b_alpha, b_pair_count=sc.b_pair_count, b_pair_slots=sc.b_pair_slots, b_pair_index=sc.b_pair_index, b_pair_mass_grad=sc.b_pair_mass_grad,
                    b_kappa=b_kappa, b_increment=sc.b_increment, b_increment_per_rho=sc.b_increment_per_rho, solve_stats=sc.lane_stats,
                )
        check_convergence(rec, m, sh, sc, mode)


def divergence_solve(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: DFSPHScratch) -> None:
    """The velocities made divergence-free: Jacobi iterations on the density rate."""
    jacobi_solve(rec, m, st, sh, sc, dfsph.SOLVE_DIVERGENCE, st.v, st.kappa_divergence, sc.b_kappa_divergence)


def compute_nonpressure(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: DFSPHScratch) -> None:
    """v* = v + dt (g + viscosity); the density solve's warm start and counters."""
    rec.launch(
        dfsph.compute_nonpressure, m.n_particles, prm=m.params, b_volume=m.b_volume, x=st.x, v=st.v, rho=st.rho, active=st.active, dt=sh.dt,
        bx=sh.bx, bv=sh.bv, pair_count=sc.pairs.count, pair_slots=sc.pair_slots, pair_index=sc.pairs.index, pair_grad=sc.pairs.grad, row=sh.row, free=st.free, mass=st.mass,
        kappa_density=st.kappa_density, v_star=sc.v_star, increment=sc.increment, increment_per_rho=sc.increment_per_rho,
        solve_stats=sc.lane_stats, keep_going=sc.keep_going, diag_f=sh.diagnostics.lane_f,
    )


def list_sweep_cells(rec: Recorder, m: FluidModel, sc: DFSPHScratch) -> None:
    """Each Gauss-Seidel sweep thread's cells of the substep, with their colours."""
    n, nb = m.n_particles, m.n_boundary
    rec.launch(
        dfsph.list_sweep_cells, sc.sweep_threads, g=m.grid.spec, n=n, items=n + nb, threads=sc.sweep_threads, keys=m.grid.keys,
        cell_start=m.grid.cell_start, cell_end=m.grid.cell_end, b_keys=m.b_grid.keys,
        sweep_count=sc.sweep_count, sweep_cell=sc.sweep_cell, sweep_color=sc.sweep_color,
    )


def gauss_seidel_density_solve(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: DFSPHScratch) -> None:
    """The density solve by Gauss-Seidel sweeps: the warm start applied at once, then sweeps of one stage per cell
    colour, each sweep followed by the convergence test, until it passes."""
    apply_stiffness(rec, m, st, sh, sc, sc.v_star, st.kappa_density)
    with rec.loop(sc.keep_going):
        for color in range(dfsph.CELL_COLORS[m.config.dim]):
            rec.launch(
                dfsph.gauss_seidel_density_sweep, sc.sweep_threads, prm=m.params, color=color, b_volume=m.b_volume,
                sweep_count=sc.sweep_count, sweep_cell=sc.sweep_cell, sweep_color=sc.sweep_color, cell_start=m.grid.cell_start,
                cell_end=m.grid.cell_end, b_order=m.b_grid.order, b_cell_start=m.b_grid.cell_start, b_cell_end=m.b_grid.cell_end,
                rho=st.rho, alpha=sc.alpha, dt=sh.dt, bv=sh.bv, pair_count=sc.pairs.count, pair_slots=sc.pair_slots, pair_index=sc.pairs.index, pair_mass_grad=sc.pair_mass_grad,
                b_rho=sc.b_rho, b_alpha=sc.b_alpha, b_pair_count=sc.b_pair_count, b_pair_slots=sc.b_pair_slots, b_pair_index=sc.b_pair_index, b_pair_mass_grad=sc.b_pair_mass_grad,
                mass=st.mass, v=sc.v_star, kappa=st.kappa_density, b_kappa=sc.b_kappa_density, solve_stats=sc.lane_stats,
            )
        check_convergence(rec, m, sh, sc, dfsph.SOLVE_DENSITY)


def density_solve(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: DFSPHScratch, gauss_seidel: bool) -> None:
    """The predicted velocities v* corrected until the predicted compression is small: by Gauss-Seidel sweeps or by
    Jacobi iterations (``FluidConfig.density_iteration``)."""
    if gauss_seidel:
        gauss_seidel_density_solve(rec, m, st, sh, sc)
    else:
        jacobi_solve(rec, m, st, sh, sc, dfsph.SOLVE_DENSITY, sc.v_star, st.kappa_density, sc.b_kappa_density)


def compute_wall_reaction(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: DFSPHScratch) -> None:
    """Each particle's force on each vessel from both solves' pair forces; its share of the reported pressure."""
    rec.launch(
        dfsph.compute_wall_reaction, m.n_particles, prm=m.params, vessels=m.vessels, b_volume=m.b_volume, b_vessel=m.b_vessel, motions=sh.motions,
        x=st.x, v=st.v, rho=st.rho, kappa_density=st.kappa_density, kappa_divergence=st.kappa_divergence, active=st.active, bx=sh.bx, bv=sh.bv,
        pair_count=sc.pairs.count, pair_slots=sc.pair_slots, pair_index=sc.pairs.index, pair_grad=sc.pairs.grad, b_rho=sc.b_rho, b_kappa_density=sc.b_kappa_density,
        b_kappa_divergence=sc.b_kappa_divergence, substep_weight=sc.substep_weight, free=st.free,
        wall_force=sh.wall_force, wall_torque=sh.wall_torque, p=st.p,
    )


def integrate(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: DFSPHScratch) -> None:
    """x += dt v*, then the wall guard, deactivation and diagnostics."""
    rec.launch(
        dfsph.integrate, m.n_particles, **sh.guard_args(m), v_star=sc.v_star, rho=st.rho, x=st.x, v=st.v, active=st.active, mass=st.mass,
        free=st.free, wall_force=sh.wall_force, wall_torque=sh.wall_torque, diag_f=sh.diagnostics.lane_f, diag_i=sh.diagnostics.lane_i,
    )


def carry_density(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch, sc: DFSPHScratch) -> None:
    """'continuity' surface density: the held density carried over the substep (``cosim.fluid.dfsph.carry_density``)."""
    rec.launch(
        dfsph.carry_density, m.n_particles, active=st.active, dt=sh.dt, v_star=sc.v_star, bv=sh.bv, pair_count=sc.pairs.count,
        pair_slots=sc.pair_slots, pair_index=sc.pairs.index, pair_mass_grad=sc.pair_mass_grad, rho=st.rho,
    )


def reset_solve_stats(rec: Recorder, sc: DFSPHScratch) -> None:
    """The solves' counters cleared for the next substep."""
    rec.call(0, sc.solve_stats.zero_)


class DFSPHStep:
    """Divergence-free SPH: owns its scratch; :meth:`substep` is the substep, stage by stage."""

    def __init__(self, model: FluidModel, shared: SubstepScratch, lanes: Lanes):
        self.model = model
        self.shared = shared
        self.gauss_seidel = model.config.density_iteration is DensityIteration.GAUSS_SEIDEL
        self.scratch = DFSPHScratch(model, shared, lanes, self.gauss_seidel)
        self._weight_written: int | None = None

    def initialise(self, st: FluidState) -> None:
        """The seeded pressure (hydrostatic for a filled vessel) as the stiffness the liquid was already under: the
        first density solve warm-starts from it as from any previous substep's. With ``surface_density`` 'continuity'
        the liquid starts at rho0, which the continuity equation carries on where a particle's support is not full
        (``cosim.fluid.dfsph.surface_offset``). With 'seeded_offset' and ``initial_state`` 'seeded', the seeded
        kernel deficiency is taken in the first substep and kept as each particle's rest offset
        (``cosim.fluid.dfsph.bound_or_free_density``); with 'relaxed', no particle has one: the liquid is held to its
        summation density, compression only (Bender & Koschier 2017), and settles before t = 0
        (``cosim.fluid.relaxation``)."""
        launch_now(wcsph.equation_of_state, self.model.n_particles, self.model.device, dict(prm=self.model.params, rho=st.rho, p=st.p))
        st.kappa_density.assign((st.p.numpy() / st.rho.numpy()).astype(np.float32))
        if continuity_surface(self.model):
            st.rest_offset.zero_()
            st.rho.fill_(self.model.config.rest_density)  # at rest, at rest density: what the surface rows carry on
            return
        seeded = self.model.config.initial_state is InitialState.SEEDED
        st.rest_offset.fill_(float(dfsph.UNSEEDED_OFFSET) if seeded else 0.0)

    def internal_energy(self, st: FluidState) -> float:
        """The incompressible liquid stores no elastic energy (J)."""
        return 0.0

    def begin_interval(self, st: FluidState, substeps: int) -> None:
        """The reported pressure restarts: it is averaged over the interval's ``substeps``."""
        if substeps != self._weight_written:
            self.scratch.substep_weight.fill_(1.0 / substeps)
            self._weight_written = substeps
        st.p.zero_()

    def substep(self, rec: Recorder, src: FluidState, st: FluidState) -> None:
        """One substep: the liquid ``src`` reordered into ``st`` and advanced there."""
        m, sh, sc = self.model, self.shared, self.scratch
        start_substep(rec, m, src, st, sh)
        solved_walls = solved_wall_layer(m)
        compute_density_factor(rec, m, st, sh, sc)
        if solved_walls:
            with rec.together():
                compute_wall_density_factor(rec, m, st, sh, sc)
                start_wall_solve(rec, m, sc, sc.b_kappa_divergence, dfsph.WARM_START_DIVERGENCE, warm_start_applied=False)
        divergence_solve(rec, m, st, sh, sc)
        with rec.together():
            compute_nonpressure(rec, m, st, sh, sc)
            if solved_walls:
                start_wall_solve(rec, m, sc, sc.b_kappa_density, dfsph.WARM_START_DENSITY, warm_start_applied=self.gauss_seidel)
            if self.gauss_seidel:
                list_sweep_cells(rec, m, sc)
        density_solve(rec, m, st, sh, sc, self.gauss_seidel)
        compute_wall_reaction(rec, m, st, sh, sc)
        integrate(rec, m, st, sh, sc)
        if continuity_surface(m):
            carry_density(rec, m, st, sh, sc)
        reset_solve_stats(rec, sc)
        end_substep(rec, m, sh)
