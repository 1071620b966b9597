"""The stages every substep runs around its pressure solver's, and the scratch they share.

A substep of either solver (``cosim.fluid.wcsph_step``, ``cosim.fluid.dfsph_step``) reads

    start_substep
      move_vessels          each vessel's pose at the substep's start and end (constant velocity over the interval)
      place_wall_particles  the dummy wall particles at the start pose, with the wall's velocity
      find_neighbors        the cell lists of the wall particles (by indirection) and of the liquid (sorted)
      reorder_particles     the liquid's state gathered into cell order, into the other buffer
      mark_inside           which vessels hold each particle, where a wall is seen from one side only
      shift_particles       particle shifting, where configured (``cosim.fluid.shifting``)
    ...                     the pressure solver's stages, ending in its integrate (wall guard, diagnostics)
    end_substep
      reduce_wrenches       the particles' forces and torques on each vessel summed in a fixed order
      next_row              the next substep's diagnostics row

Each stage is a function of (recorder, model, state or scratch) that launches its kernels by argument name through
the recorder (``cosim.fluid.program``).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
import warp as wp

from cosim.fluid import boundary as bd
from cosim.fluid.device_layout import DeviceLayout, ReductionLevel, reduction_levels
from cosim.fluid.diagnostics import DiagnosticBuffers
from cosim.fluid.lanes import Lanes
from cosim.fluid.model import FluidModel, FluidState
from cosim.fluid.neighbors import Neighborhood, neighborhood
from cosim.fluid.program import Recorder
from cosim.fluid.shifting import ShiftingScratch, shift_particles, shifting_on
from cosim.fluid.sph_common import accumulate_wall_wrench, gather_particles, mark_inside_vessels, next_substep, pair_capacity, sum_wall_wrench_chunks
from cosim.frames import Pose

GUARD_MARGIN = 0.01  # the guard puts a particle this many dx outside the wall face it crossed


class SubstepScratch:
    """What the substeps of an interval share, whichever the pressure solver.

    motions: (V,) :class:`cosim.fluid.boundary.VesselMotion`, the vessels' motion over the interval; dt: (1,) s, the
    substep's; row: (1,) int32, the substep's index in the interval (its diagnostics row); bx, bv: (Nb,) the wall
    particles' world positions (m) and velocities (m/s); b_active: (Nb,) all ones (the wall grid sorts every wall
    particle); wall_force, wall_torque: (V, N) each particle's force (N) and torque (N m) on each vessel this substep;
    force_sum, torque_sum: (V,) their sums over the interval (reduced in a fixed order through ``partial_wrench``);
    pair_capacity: entries of each particle's pair list; free_surface: (N,) each particle's free-surface indicator
    at its last substep's start, in that substep's particle order (written under ``FluidConfig.free_liquid_rule``
    'free_surface' only; ``cosim.fluid.free_surface``); inside: (N,) int32, the vessels whose inner volume holds each
    particle (bit k for vessel k, in the substep's particle order; written only where the model has walls seen from
    one side, zero otherwise); shifting: the particle shift's arrays, None where
    ``FluidConfig.particle_shifting`` is 'off' (``cosim.fluid.shifting``); diagnostics: the substeps' rows, per lane.
    """

    def __init__(self, model: FluidModel, lanes: Lanes, layout: DeviceLayout):
        d, n, nb, nv = model.device, model.grid.capacity, model.n_boundary, model.n_vessels
        v_count = max(nv, 1)
        self.layout = layout
        self.pair_capacity = pair_capacity(model.config.dim, model.densest_smoothing_ratio)
        self.motions = wp.zeros(nv, dtype=bd.VesselMotion, device=d)
        # the motions are written on the host through a structured numpy view (the CPU device's array itself, else a
        # pinned staging copy): no per-field warp struct assignment in the step loop
        self._motions_host = self.motions if not d.is_cuda else wp.zeros(nv, dtype=bd.VesselMotion, device="cpu", pinned=True)
        self._motions_view = self._motions_host.numpy()
        self.dt = wp.zeros(1, dtype=float, device=d)
        self._dt_written: float | None = None
        self.row = wp.zeros(1, dtype=wp.int32, device=d)
        self.bx = wp.zeros(nb, dtype=wp.vec3, device=d)
        self.bv = wp.zeros(nb, dtype=wp.vec3, device=d)
        self.b_active = wp.ones(nb, dtype=wp.int32, device=d)
        self.wall_force = wp.zeros((v_count, n), dtype=wp.vec3, device=d)
        self.wall_torque = wp.zeros((v_count, n), dtype=wp.vec3, device=d)
        self.wrench_levels: list[ReductionLevel] = reduction_levels(n, layout.interleaved_reduction)
        self.partial_wrench = [
            (wp.zeros((v_count, level.chunks), dtype=wp.vec3, device=d), wp.zeros((v_count, level.chunks), dtype=wp.vec3, device=d))
            for level in self.wrench_levels
        ]
        self.force_sum = wp.zeros(v_count, dtype=wp.vec3, device=d)
        self.torque_sum = wp.zeros(v_count, dtype=wp.vec3, device=d)
        self._wrench_views = (self.force_sum.numpy(), self.torque_sum.numpy()) if d.is_cpu else None  # shared memory
        self._counter_views = (self.row.numpy(), *self._wrench_views) if d.is_cpu else None  # cleared every interval
        self.free_surface = wp.zeros(n, dtype=float, device=d)
        self.inside = wp.zeros(n, dtype=wp.int32, device=d)
        self.shifting = ShiftingScratch(model) if shifting_on(model.config) else None
        self.diagnostics = DiagnosticBuffers(lanes.count, layout.atomic_replicas, nv, d)

    def set_motions(self, poses: list[Pose], lin_vel: np.ndarray, ang_vel: np.ndarray, lin_acc: np.ndarray, ang_acc: np.ndarray) -> None:
        """The vessels' motion over the next interval (world frame; (V, 3) m/s, rad/s, m/s^2, rad/s^2), from their
        current ``poses``; the substeps' own poses start there."""
        if not poses:
            return
        mo = self._motions_view
        mo["p0"] = mo["p_now"] = mo["p_next"] = np.array([pose.position for pose in poses])  # converted once for the three
        mo["r0"] = mo["r_now"] = mo["r_next"] = np.array([pose.rotation for pose in poses])
        mo["lin_vel"], mo["ang_vel"], mo["lin_acc"], mo["ang_acc"] = lin_vel, ang_vel, lin_acc, ang_acc
        if self._motions_host is not self.motions:  # copied into the existing array: the recorded launches hold it
            wp.copy(self.motions, self._motions_host)

    def begin_interval(self, dt: float) -> None:
        """Substeps of ``dt`` s from row 0, with the diagnostics and the wrench sums cleared."""
        if dt != self._dt_written:  # the substeps read it on the device; most intervals keep the last one
            self.dt.fill_(dt)
            self._dt_written = dt
        self.diagnostics.zero()
        if self._counter_views is not None:  # the CPU's arrays through their numpy views: no warp call per interval
            for view in self._counter_views:
                view.fill(0)
            return
        self.row.zero_()
        self.force_sum.zero_()
        self.torque_sum.zero_()

    def mean_wrench(self, n_vessels: int, substeps: int) -> np.ndarray:
        """(V, 6): each vessel's force (N) and torque (N m) summed over the interval, over ``substeps``."""
        wrench = np.concatenate(self._wrench_views or (self.force_sum.numpy(), self.torque_sum.numpy()), axis=1)[:n_vessels]
        return wrench.astype(np.float64) * (1.0 / substeps)

    def neighborhood(self, model: FluidModel, st: FluidState) -> Neighborhood:
        """The liquid of ``st`` and the wall particles in the model's cell grids, as the neighbour loops read them
        (``cosim.fluid.neighbors``)."""
        return neighborhood(model.grid, st.x, model.b_grid, self.bx, model.b_side, model.b_vessel, self.inside)

    def guard_args(self, model: FluidModel) -> dict:
        """The arguments both solvers' integrate kernels take for the shared end of a particle's substep
        (``cosim.fluid.sph_common.finish_particle``: wall guard, deactivation outside the domain, diagnostics)."""
        cfg = model.config
        return dict(
            prm=model.params, vessels=model.vessels, domain_min=wp.vec3(*cfg.domain_min), domain_max=wp.vec3(*cfg.domain_max),
            guard_margin=GUARD_MARGIN * cfg.spacing, max_penetration=cfg.max_wall_penetration * cfg.spacing,
            motions=self.motions, dt=self.dt, row=self.row,
        )


@dataclass
class PairList:
    """Each particle's neighbours of the substep, found once and looped over by the later stages: ``count`` (N,),
    ``index`` (N, capacity; a liquid neighbour j >= 0 or a wall code ``cosim.fluid.sph_common.wall_pair``) and
    ``grad`` (N, capacity; grad_i W, 1/m^(dim+1)), laid out as the device wants (``cosim.fluid.device_layout``)."""

    count: wp.array
    index: wp.array
    grad: wp.array


def move_vessels(rec: Recorder, m: FluidModel, sh: SubstepScratch) -> None:
    """Each vessel's pose at the start and end of the substep (``cosim.fluid.boundary.advance_vessel_poses``)."""
    if m.n_vessels:
        rec.launch_on_lane(bd.advance_vessel_poses, m.n_vessels, substep=sh.row, dt=sh.dt, motions=sh.motions)


def place_wall_particles(rec: Recorder, m: FluidModel, sh: SubstepScratch) -> None:
    """The dummy wall particles at their vessel's start pose, moving with it."""
    if m.n_vessels:
        rec.launch(bd.place_wall_particles, m.n_boundary, local_pos=m.b_local, vessel_of=m.b_vessel, motions=sh.motions, x=sh.bx, v=sh.bv)


def find_neighbors(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch) -> None:
    """The cell lists: the wall particles' by indirection (on the first lane), the liquid's (sorted into cell order,
    on the last)."""
    with rec.together():
        rec.call(0, *m.b_grid.build_commands(sh.bx, sh.b_active, m.n_boundary))
        rec.call(-1, *m.grid.build_commands(st.x, st.active, m.n_particles))


def reorder_particles(rec: Recorder, m: FluidModel, src: FluidState, dst: FluidState) -> None:
    """The liquid's state ``src`` gathered into cell order into ``dst`` (neighbours contiguous in memory)."""
    names = [f.name for f in fields(FluidState)]
    rec.launch(
        gather_particles, m.n_particles, order=m.grid.order,
        **{name: getattr(src, name) for name in names}, **{f"{name}_out": getattr(dst, name) for name in names},
    )


def mark_inside(rec: Recorder, m: FluidModel, st: FluidState, sh: SubstepScratch) -> None:
    """Which vessels hold each liquid particle of ``st`` (in cell order), where a wall is seen from one side only."""
    if m.one_sided_walls:
        rec.launch(mark_inside_vessels, m.n_particles, prm=m.params, vessels=m.vessels, motions=sh.motions, x=st.x, inside=sh.inside)


def reduce_wrenches(rec: Recorder, m: FluidModel, sh: SubstepScratch) -> None:
    """Each vessel's force and torque from its particles summed in a fixed order (the same on every device and
    for any lane count, ``cosim.fluid.device_layout``) and added to the interval's sums."""
    if not m.n_vessels:
        return
    force, torque, length = sh.wall_force, sh.wall_torque, m.n_particles
    for level, (partial_force, partial_torque) in zip(sh.wrench_levels, sh.partial_wrench):
        rec.launch_on_lane(
            sum_wall_wrench_chunks, (m.n_vessels, level.chunks), n=level.length, first_stride=level.first_stride, item_stride=level.item_stride,
            items=level.items, wall_force=force, wall_torque=torque, partial_force=partial_force, partial_torque=partial_torque,
        )
        force, torque, length = partial_force, partial_torque, level.chunks
    rec.launch_on_lane(
        accumulate_wall_wrench, m.n_vessels, n_chunks=length, partial_force=force, partial_torque=torque, force_sum=sh.force_sum, torque_sum=sh.torque_sum,
    )


def next_row(rec: Recorder, sh: SubstepScratch) -> None:
    """The next substep's diagnostics row (and its index in the interval)."""
    rec.launch_on_lane(next_substep, 1, row=sh.row)


def start_substep(rec: Recorder, m: FluidModel, src: FluidState, dst: FluidState, sh: SubstepScratch) -> None:
    """The stages before the pressure solver's: the walls moved, the neighbours found, ``src`` reordered into
    ``dst``."""
    move_vessels(rec, m, sh)
    place_wall_particles(rec, m, sh)
    find_neighbors(rec, m, src, sh)
    reorder_particles(rec, m, src, dst)
    mark_inside(rec, m, dst, sh)
    shift_particles(rec, m, dst, sh)


def end_substep(rec: Recorder, m: FluidModel, sh: SubstepScratch) -> None:
    """The stages after the pressure solver's, on one lane between the same barriers."""
    with rec.together():
        reduce_wrenches(rec, m, sh)
        next_row(rec, sh)
