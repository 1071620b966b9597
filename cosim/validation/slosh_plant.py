"""The slosh plant identified from the SPH liquid, against linear potential flow (:mod:`controllers.slosh`).

A box (inner width B) or cylindrical cup (inner diameter D, 3-D only) filled to A stands still (the seeded liquid
first relaxes to rest, :data:`SETTLE_TIME`); in each run it is
tilted by :data:`TILT_ANGLE` over :data:`TILT_DURATION` (theta = angle (1 - cos(pi t / T)) / 2) about a pivot on
its axis, then held for ``hold`` seconds. The pivots sit at :data:`PIVOT_FRACTIONS` of the potential-flow hinge H
above the inner floor, on both sides of it. The slosh angle sigma = theta1 - theta is what the pour controller
reads (:class:`cosim.coupling.measure.LiquidProbe`: the free-surface line through the liquid's column heights),
sampled every 2 ms. :mod:`cosim.validation.plant_fit` fits the ring-downs jointly (one omega1 and damping ratio,
one phasor per run) and identifies the hinge (the zero of the residual amplitude, a line in the pivot height); the potential-flow model is
evaluated for the liquid's actual depth (its volume over the floor area: the lattice holds whole layers).

:func:`identify` runs the tilts and the fit for any vessel and pivots, so that a vessel with no closed form takes
its plant (:meth:`PlantFit.slosh_model`) from the liquid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from controllers.config import PourConfig
from controllers.errors import ControllerInputError
from controllers.slosh import SloshModel, VesselShape as SloshShape, potential_flow_model
from cosim.errors import InputError
from cosim.fluid.config import FluidConfig
from cosim.fluid.solver import FluidSolver
from cosim.coupling.measure import LiquidProbe, MeasurementGeometry
from cosim.frames import Pose
from cosim.validation.common import CaseResult, FluidCaseParams, Metric, case_fluid_config, new_figure, require_particles_across, whole_spacings
from cosim.validation.plant_fit import PlantFit, identify_plant
from cosim.validation.scripted import run_scripted, tilt_about_axis_point
from cosim.vessel import VesselShape, VesselSpec
from declared_settings.setting import documented, setting

# Acceptance: the identified hinge within 5 mm and omega1 within 2 % of the potential-flow model.
HINGE_TOLERANCE = 0.005  # m
OMEGA_TOLERANCE = 0.02
TILT_ANGLE = 0.08  # rad: small, so the slosh stays linear (surface slope ~0.1)
TILT_DURATION = 0.16  # s: about a third of the first period at the default fills, so the tilt excites the mode
PIVOT_FRACTIONS = (0.0, 0.5, 1.0, 1.2)  # pivot heights as fractions of the potential-flow hinge H
MIN_PARTICLES_ACROSS = 8
MIN_HOLD_PERIODS = 2.0  # the ring-down recorded after each tilt, in first-mode periods at least
# s the seeded liquid relaxes upright, its velocity dropped after every sample, before each tilt
# (cosim.fluid.solver.FluidSolver.relax): a 3-D cylinder's rings start a few per cent off rest density in places,
# and released at once that error becomes a lasting agitation.
SETTLE_TIME = 0.1


SLOSH_PLANT = "slosh plant"


@documented
@dataclass(frozen=True)
class Params(FluidCaseParams):
    """A box or a cup tilted about pivots at several heights, its slosh identified as a pendulum."""

    width: float = setting(VesselSpec.inner_width, SLOSH_PLANT, "Box inner width B or cylinder inner diameter.", "m",
                           0.0, 2.0, lo_open=True)
    fill: float = setting(PourConfig.fill_depth, SLOSH_PLANT, "Fill depth A.", "m", 0.0, 2.0, lo_open=True)
    shape: VesselShape = setting(VesselShape.BOX, SLOSH_PLANT, "'box' or 'cylinder' (3-D only: in 2-D a cylinder's "
                                 "section is a box).")
    hold: float = setting(1.5, SLOSH_PLANT, "Time recorded after each tilt, at least two first-mode periods.", "s",
                          0.0, 60.0, lo_open=True)
    particles_across: int = setting(40, SLOSH_PLANT, "The resolution across width when spacing is not "
                                    "given.", "", MIN_PARTICLES_ACROSS, 200)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.shape is VesselShape.CYLINDER and self.dim == 2:
            raise InputError("shape: a cylinder needs dim 3 (its 2-D section is a box); use shape box or dim 3")
        require_particles_across("spacing", self.width, self.resolved_spacing, MIN_PARTICLES_ACROSS)
        period = self.model_at(self.fill).period
        if self.hold < MIN_HOLD_PERIODS * period:
            raise InputError(f"hold: {self.hold:g} s is under {MIN_HOLD_PERIODS:g} first-mode periods ({period:.3f} s each); "
                             f"needs >= {MIN_HOLD_PERIODS * period:.3f} s")

    @property
    def resolved_spacing(self) -> float:
        return self.spacing if self.spacing is not None else self.width / self.particles_across

    def model_at(self, liquid_depth: float) -> SloshModel:
        """The potential-flow pendulum of this vessel filled to ``liquid_depth`` (m)."""
        return potential_flow_model(self.width, liquid_depth, shape=SloshShape(self.shape.value))

    def tank(self) -> VesselSpec:
        """The vessel the liquid sees: a box of whole spacings across (and deep, in 3-D), or the cup; its rim
        half a width above the fill, clear of the tilted, sloshing surface."""
        dx = self.resolved_spacing
        is_box = self.shape is VesselShape.BOX
        width = whole_spacings(self.width, dx) if is_box else self.width
        depth = self.tank_depth(dx) if is_box else width
        return VesselSpec(name="tank", shape=self.shape, inner_width=width, inner_depth=depth,
                          inner_height=self.fill + 0.5 * width + 4 * dx)


def domain_for(spec: VesselSpec, poses: list[Pose], margin: float) -> tuple[np.ndarray, np.ndarray]:
    """(domain_min, domain_max) in m: the vessel's outer box at each of ``poses``, widened by ``margin`` (m)."""
    r, d, t = 0.5 * spec.inner_width, 0.5 * spec.section_depth, spec.wall_thickness
    corners = np.array([[sx * (r + t), sy * (d + t), z] for sx in (-1, 1) for sy in (-1, 1) for z in (-t, spec.inner_height)])
    points = np.concatenate([pose.transform(corners) for pose in poses])
    return points.min(axis=0) - margin, points.max(axis=0) + margin


class SlopeRecorder:
    """A :class:`cosim.validation.scripted.RunObserver` that records the slosh angle sigma = theta1 - theta (rad)
    the controller would read (:class:`LiquidProbe`) after every sample, with its time (s)."""

    def __init__(self, spec: VesselSpec, cfg: FluidConfig):
        self.spec, self.cfg = spec, cfg
        self.t: list[float] = []
        self.sigma: list[float] = []

    def start(self, solver: FluidSolver) -> None:
        geo = MeasurementGeometry(self.spec, float(solver.model.wall_thickness[0]), self.spec.inner_height, self.cfg.smoothing_length,
                                  self.cfg.spacing, solver.n_particles * self.cfg.particle_volume, self.cfg.dim)
        self.probe = LiquidProbe(geo, solver.n_particles, solver.device)

    def sample(self, solver: FluidSolver, before: Pose, after: Pose, x: np.ndarray, active: np.ndarray) -> None:
        state = solver.state
        m = self.probe.measure(solver.time, after, after, state.x, state.v, state.active, 0.0)
        self.t.append(solver.time)
        self.sigma.append(m.theta1 - m.tilt)


@dataclass
class Identification:
    """What :func:`identify` produced: the plant fit (None if a run failed), the record's times (s from the tilt's
    end) and per pivot sigma (rad; a failed run's is shorter), the runs' failures ('' each if none), the liquid's
    depth (m, volume over floor area), particles, wall time (s)."""

    fit: PlantFit | None
    t: np.ndarray
    sigmas: list[np.ndarray]
    failures: list[str]
    liquid_depth: float
    particles: int
    wall_time: float


def identify(spec: VesselSpec, fill: float, cfg: FluidConfig, pivots: list[float], hold: float, device: str = "cpu") -> Identification:
    """Tilt ``spec`` filled to ``fill`` (m) about each of ``pivots`` (m above the inner floor, on the axis) by
    TILT_ANGLE over TILT_DURATION, record sigma for ``hold`` (s) after, and fit the plant. ``cfg``'s domain must hold
    the vessel at every pose (:func:`domain_for`)."""
    times, sigmas, failures, wall = [], [], [], 0.0
    for pivot in pivots:
        recorder = SlopeRecorder(spec, cfg)
        run = run_scripted(spec, fill, cfg, tilt_about_axis_point(pivot, TILT_ANGLE, TILT_DURATION), TILT_DURATION + hold,
                           device=device, can_spill=False, observer=recorder, settle=SETTLE_TIME)
        t, sigma = np.asarray(recorder.t), np.asarray(recorder.sigma)
        after = t > TILT_DURATION + 1e-9
        times.append(t[after] - TILT_DURATION)
        sigmas.append(sigma[after])
        failures.append(run.failure)
        wall += run.wall_time
    t = max(times, key=len)
    fit = identify_plant(pivots, t, sigmas) if not any(failures) else None
    particles = run.solver.n_particles
    return Identification(fit, t, sigmas, failures, particles * cfg.particle_volume / spec.inner_floor_area, particles, wall)


def pivot_heights(hinge: float) -> list[float]:
    """m above the inner floor: :data:`PIVOT_FRACTIONS` of the model's hinge ``hinge`` (m)."""
    return [f * hinge for f in PIVOT_FRACTIONS]


def identified_model(fit: PlantFit | None, gravity: float) -> dict[str, float] | None:
    """The identified pendulum's l1 (m), hinge_height (m), damping_ratio, omega1 (rad/s); None where the fit gave
    none (a failed run, NaN, or values no pendulum has)."""
    if fit is None:
        return None
    try:
        model = fit.slosh_model(gravity)
    except ControllerInputError:
        return None
    return {"l1": model.l1, "hinge_height": model.hinge_height, "damping_ratio": model.damping_ratio, "omega1": model.omega1}


def shared_fit_summary(fit: PlantFit | None) -> dict[str, float] | None:
    """The joint fit's omega1 (rad/s) and damping ratio with their standard errors; None where there is none."""
    if fit is None or fit.shared is None:
        return None
    s = fit.shared
    return {"omega1": s.omega1, "omega1_std": math.sqrt(s.omega1_variance), "damping_ratio": s.zeta, "damping_ratio_std": math.sqrt(s.zeta_variance)}


def run(p: Params) -> CaseResult:
    dx = p.resolved_spacing
    spec = p.tank()
    pivots = pivot_heights(p.model_at(p.fill).hinge_height)
    poses = [Pose()] + [tilt_about_axis_point(q, TILT_ANGLE, TILT_DURATION)(TILT_DURATION) for q in pivots]
    lo, hi = domain_for(spec, poses, 0.05 * spec.inner_width + 10 * dx)
    cfg = case_fluid_config(p.dim, dx, p.fill, spec.section_depth, lo, hi, p.solver, numerics=p.numerics)
    ident = identify(spec, p.fill, cfg, pivots, p.hold, p.device)
    model = p.model_at(ident.liquid_depth)
    fit = ident.fit
    omega_sph = fit.omega1 if fit else math.nan
    hinge_sph = fit.hinge_height if fit else math.nan
    completed = sum(1 for f in ident.failures if not f)
    metrics = [
        Metric("pivot runs completed", float(completed), float(len(pivots)), float(completed - len(pivots)), 0.0, "", absolute=True),
        Metric("first-mode omega1", omega_sph, model.omega1, (omega_sph - model.omega1) / model.omega1, OMEGA_TOLERANCE, "rad/s"),
        Metric("hinge height", hinge_sph, model.hinge_height, hinge_sph - model.hinge_height, HINGE_TOLERANCE, "m", absolute=True),
    ]
    raw = {
        "omega1_sph": omega_sph,
        "omega1_model": model.omega1,
        "hinge_height_sph": hinge_sph,
        "hinge_height_model": model.hinge_height,
        "damping_ratio_sph": fit.damping_ratio if fit else math.nan,
        "liquid_depth": ident.liquid_depth,
        "pivots": pivots,
        "signed_amplitudes": list(fit.signed_amplitudes) if fit else [],
        "amplitude_line": list(fit.line) if fit else [],
        "amplitude_line_rms": fit.line_rms if fit else math.nan,
        "shared_fit": shared_fit_summary(fit),
        "fits": [{"a": a, "b": b, "offset": c, "rms_residual": r, "own_omega": f.omega, "own_damping_ratio": f.zeta, "own_rms_residual": f.rms_residual}
                 for a, b, c, r, f in zip(fit.shared.a, fit.shared.b, fit.shared.offset, fit.shared.rms_residual, fit.free_fits)]
        if fit and fit.shared else [],
        "identified_model": identified_model(fit, cfg.gravity_magnitude),
        "failures": ident.failures,
        "t": ident.t,
        "sigma": ident.sigmas,
        "particles": ident.particles,
    }
    params = dict(width=spec.inner_width, fill=p.fill, shape=p.shape.value, spacing=dx, dim=p.dim, device=p.device, solver=p.solver.value,
                  hold=p.hold, tilt_angle=TILT_ANGLE, tilt_duration=TILT_DURATION,
                  depth=spec.section_depth if p.shape is VesselShape.BOX else None)
    return CaseResult("slosh-plant", params, metrics, raw, ident.wall_time)


def plot(result: CaseResult, path) -> None:
    from mpl_toolkits.axes_grid1 import make_axes_locatable

    raw, par = result.raw, result.parameters
    fig, ax, plt = new_figure(
        f"Slosh plant, {par['shape']} {par['width']:.3f} m filled to {raw['liquid_depth']:.4f} m ({par['dim']}-D)\n"
        f"omega1 {raw['omega1_sph']:.3f} rad/s (model {raw['omega1_model']:.3f}), "
        f"hinge {1e3 * raw['hinge_height_sph']:.1f} mm (model {1e3 * raw['hinge_height_model']:.1f}), zeta {raw['damping_ratio_sph']:.3f}"
    )
    fig.set_size_inches(10, 4.5)
    ax.title.set_fontsize(9)
    t = np.asarray(raw["t"])
    for pivot, sigma in zip(raw["pivots"], raw["sigma"]):
        ax.plot(t[: len(sigma)], 1e3 * np.asarray(sigma), lw=1.0, label=f"pivot {1e3 * pivot:.1f} mm")
    ax.set_xlabel("t after the tilt (s)")
    ax.set_ylabel("slosh angle sigma (mrad)")
    ax.legend(loc="lower right", fontsize=7)
    side = make_axes_locatable(ax).append_axes("right", size="40%", pad=0.7)
    side.grid(True, alpha=0.3)
    if raw["signed_amplitudes"]:
        pivots = np.asarray(raw["pivots"])
        side.plot(1e3 * pivots, 1e3 * np.asarray(raw["signed_amplitudes"]), "o", label="SPH runs")
        slope, intercept = raw["amplitude_line"]
        side.plot(1e3 * pivots, 1e3 * (slope * pivots + intercept), "k-", lw=0.8, label="least-squares line")
    side.axvline(1e3 * raw["hinge_height_model"], color="r", ls=":", lw=0.8, label="model hinge")
    side.axhline(0.0, color="gray", lw=0.5)
    side.set_xlabel("pivot above the floor (mm)")
    side.set_ylabel("signed amplitude (mrad)")
    side.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
