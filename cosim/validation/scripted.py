"""A liquid-filled vessel moved along a scripted path, with a leak check independent of the solver's own guard.

Shared by the moving-vessel validation cases (``tilt``, ``shake``) and the stability matrix (``cosim stress``):
the scripted poses (tilt about the pour lip or a point on the axis, sideways shaking), the fluid domain around the moving vessel, the
sampled run loop, and :class:`LeakMonitor`, which classifies particles from positions and poses alone (numpy):
inside the wall solid the liquid sees, through a wall (inner volume -> outside below the rim between two
samples), and, where the motion cannot spill, out of the vessel at all.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable, Protocol

import numpy as np

from cosim.fluid.config import FluidConfig
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidInstabilityError, FluidSolver
from cosim.frames import Pose, rotation_y
from cosim.validation.mesh_regions import MeshWallRegions
from cosim.vessel import VesselSpec

SAMPLE_INTERVAL = 0.002  # s, pose update and leak-check interval
FALL_HEIGHT = 0.3  # m of domain below the vessel for the poured liquid (then it leaves the domain)

PoseScript = Callable[[float], Pose]  # time (s) -> world pose of the vessel frame


def tilt_about_lip(spec: VesselSpec, rate: float, angle: float) -> PoseScript:
    """Rotation about the pour lip at ``rate`` (rad/s) up to ``angle`` (rad), then held."""
    lip = spec.lip_local

    def pose_at(t: float) -> Pose:
        rot = rotation_y(min(rate * t, angle))
        return Pose(lip - rot @ lip, rot)

    return pose_at


def tilt_about_axis_point(pivot_height: float, angle: float, duration: float) -> PoseScript:
    """Rotation about the vessel-frame point (0, 0, ``pivot_height``) (m above the inner floor, on the axis) from
    upright to ``angle`` (rad) along theta(t) = angle (1 - cos(pi t / duration)) / 2 (zero rate at both ends) over
    ``duration`` (s), then held."""
    pivot = np.array([0.0, 0.0, pivot_height])

    def pose_at(t: float) -> Pose:
        rot = rotation_y(0.5 * angle * (1.0 - math.cos(math.pi * min(t, duration) / duration)))
        return Pose(pivot - rot @ pivot, rot)

    return pose_at


def shake_sideways(amplitude: float, omega: float) -> PoseScript:
    """x(t) = amplitude sin(omega t) (m, rad/s) along the pour direction, upright."""
    return lambda t: Pose((amplitude * math.sin(omega * t), 0.0, 0.0))


def domain_around(spec: VesselSpec, excursion: float) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """(domain_min, domain_max) in m: room for the vessel tilted about its lip in any direction, moved up to
    ``excursion`` (m) along x, and :data:`FALL_HEIGHT` below it."""
    reach = spec.inner_height + 0.5 * spec.inner_width + 0.1
    return (-reach - excursion, -reach, -FALL_HEIGHT), (reach + excursion, reach, reach)


@dataclass(frozen=True)
class WallRegions:
    """The vessel's regions as the liquid sees them (vessel frame): b, d = inner half width and half depth, h =
    inner height, t = wall thickness the solver uses (m); ``dim`` 2 ignores y."""

    b: float
    d: float
    h: float
    t: float
    dim: int

    @classmethod
    def of(cls, spec: VesselSpec, solver: FluidSolver) -> "WallRegions | MeshWallRegions":
        if spec.is_mesh:
            return MeshWallRegions(spec)
        return cls(0.5 * spec.inner_width, 0.5 * spec.section_depth, spec.inner_height, float(solver.model.wall_thickness[0]), solver.config.dim)

    def classify(self, local: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(inside the wall solid, in the inner volume, above the opening) for vessel-frame points (N, 3)."""
        b, d, h, t = self.b, self.d, self.h, self.t
        ax, ay, z = np.abs(local[:, 0]), np.abs(local[:, 1]), local[:, 2]
        y_in = np.ones(len(local), bool) if self.dim == 2 else ay < d
        y_outer = np.ones(len(local), bool) if self.dim == 2 else ay < d + t
        inner = (ax < b) & y_in & (z > 0.0) & (z < h)
        above = (ax < b) & y_in & (z >= h)
        envelope = (ax < b + t) & y_outer & (z > -t) & (z < h)
        return envelope & ~inner & ~above, inner, above


@dataclass
class LeakMonitor:
    """Particles that a sealed vessel must never show, from positions and poses at each sample.

    ``inside``: in the wall solid. ``through``: went from the inner volume to outside below the rim (a dx under
    it) between two samples without being in the wall solid (crossed it within one sample). ``escaped`` (only
    when ``can_spill`` is False): anywhere outside the inner volume and the column above the opening.
    ``worst_*`` are the largest per-sample counts; ``leaked`` marks every particle ever counted by any check.
    """

    regions: WallRegions
    spacing: float
    can_spill: bool
    prev_inner: np.ndarray
    leaked: np.ndarray
    worst_inside: int = 0
    worst_through: int = 0
    worst_escaped: int = 0

    @classmethod
    def start(cls, regions: WallRegions, spacing: float, local0: np.ndarray, can_spill: bool = True) -> "LeakMonitor":
        inner = regions.classify(local0)[1]
        return cls(regions, spacing, can_spill, inner, np.zeros(len(local0), bool))

    def update(self, local: np.ndarray, active: np.ndarray) -> None:
        """One sample: vessel-frame positions (N, 3) m and the active mask (N,)."""
        in_wall, inner, above = self.regions.classify(local)
        below_rim = local[:, 2] < self.regions.h - self.spacing
        inside = in_wall & active
        through = self.prev_inner & ~inner & ~in_wall & below_rim & active
        escaped = ~inner & ~above & ~in_wall & active if not self.can_spill else np.zeros_like(inner)
        self.worst_inside = max(self.worst_inside, int(inside.sum()))
        self.worst_through = max(self.worst_through, int(through.sum()))
        self.worst_escaped = max(self.worst_escaped, int(escaped.sum()))
        self.leaked |= inside | through | escaped
        self.prev_inner = inner & active

    @property
    def leaked_count(self) -> int:
        return int(self.leaked.sum())


@dataclass
class ScriptedRun:
    """What :func:`run_scripted` produced: the solver (its history and final state), the leak monitor, the
    instability message ('' if none), the sampled times (s) and volumes in the vessel (m^3), wall time (s)."""

    solver: FluidSolver
    leaks: LeakMonitor
    failure: str
    wall_time: float
    t: list[float] = field(default_factory=list)
    volume_in_vessel: list[float] = field(default_factory=list)


class RunObserver(Protocol):
    """Sees the run: ``start`` once the solver holds the initial liquid, ``sample`` after each interval with the
    vessel poses at the interval's start and end, world positions (N, 3) m and the active mask (N,)."""

    def start(self, solver: FluidSolver) -> None: ...

    def sample(self, solver: FluidSolver, before: Pose, after: Pose, x: np.ndarray, active: np.ndarray) -> None: ...


def run_scripted(
    spec: VesselSpec,
    fill: float,
    cfg: FluidConfig,
    pose_at: PoseScript,
    duration: float,
    device: str = "cpu",
    can_spill: bool = True,
    observer: RunObserver | None = None,
    settle: float = 0.0,
) -> ScriptedRun:
    """Fill ``spec`` to ``fill`` (m), move it along ``pose_at`` for ``duration`` (s) in intervals of
    :data:`SAMPLE_INTERVAL`, checking leaks after each; a :class:`FluidInstabilityError` ends the run and is
    returned as ``failure``. ``can_spill`` False counts any particle out of the vessel as a leak. ``settle`` > 0
    (s): the seeded liquid first relaxes at the first pose (:meth:`FluidSolver.relax`), and the script starts from
    the relaxed liquid at rest."""
    pose0 = pose_at(0.0)
    solver = FluidSolver(cfg, [spec], [pose0], fill_vessel(spec, fill, cfg, pose0), device=device)
    failure = ""
    if settle > 0.0:
        try:
            solver.relax(settle, SAMPLE_INTERVAL)
        except FluidInstabilityError as exc:
            failure = str(exc)
    regions = WallRegions.of(spec, solver)
    leaks = LeakMonitor.start(regions, cfg.spacing, pose0.inverse_transform(solver.positions()), can_spill)
    run = ScriptedRun(solver, leaks, failure, 0.0)
    if observer is not None:
        observer.start(solver)
    start = time.perf_counter()
    try:
        while not run.failure and solver.time < duration - 1e-9:
            before = solver.vessel_poses()[0]
            solver.set_vessel_poses([pose_at(solver.time + SAMPLE_INTERVAL)])
            solver.advance(SAMPLE_INTERVAL)
            after = solver.vessel_poses()[0]
            x, active = solver.positions(), solver.active_mask()
            leaks.update(after.inverse_transform(x), active)
            run.t.append(solver.time)
            run.volume_in_vessel.append(solver.last_report.last.volume_in_vessel[0])
            if observer is not None:
                observer.sample(solver, before, after, x, active)
    except FluidInstabilityError as exc:
        run.failure = str(exc)
    run.wall_time = time.perf_counter() - start
    return run
