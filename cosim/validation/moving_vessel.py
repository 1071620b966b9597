"""Moving-vessel robustness: the full pouring vessel of Camporredondo et al. (2019) tilted about its lip, or
shaken sideways at resonance.

``tilt``: the vessel filled to A is rotated about its pour lip at ``rate`` (default 60 deg/s) to ``angle``
(default 90 deg) and held; the liquid pours out and falls out of the domain. ``shake``: the vessel moves
x(t) = amplitude sin(2 pi f t) at the first sloshing frequency f (the paper's Eq. 17), default 1 cm for 4 periods.

Checked independently of the solver's own guard (``cosim.validation.scripted``), from positions and poses at
every 2 ms sample (numpy): no particle inside the wall solid (the wall region the liquid sees), and no particle
that went from the vessel's inside to its outside below the rim (through a wall) between two samples. Non-finite
values or a breached wall would stop the run with the solver's instability error, which the case reports as a
failure.

``scene``: a scene file whose pourer (``[vessels.pourer]``: a box, a cylinder or a mesh) is the vessel instead; a
mesh vessel's wall solid and inner volume are the mesh's (:mod:`cosim.validation.mesh_regions`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cosim.pour_scene import load_scene
from cosim.validation.common import CaseResult, FluidCaseParams, Metric, case_fluid_config, new_figure
from cosim.validation.scripted import FALL_HEIGHT, PoseScript, domain_around, run_scripted, shake_sideways, tilt_about_lip
from cosim.validation.slosh import eq17_frequency
from cosim.vessel import VesselSpec, seed_pouring_vessel
from declared_settings.setting import documented, setting

HOLD_AFTER_TILT = 0.5  # s the tilted vessel is held before the run ends


MOVING_VESSEL = "moving vessel"


@documented
@dataclass(frozen=True)
class Params(FluidCaseParams):
    """A vessel tilted about its lip or shaken sideways.

    scene: a scene file whose pourer is the vessel ('': the paper's vessel).
    """

    fill: float = setting(0.159, MOVING_VESSEL, "Liquid depth in the upright vessel.", "m", 0.0, "inner_height",
                          lo_open=True)
    rate: float = setting(60.0, MOVING_VESSEL, "Tilt rate.", "deg/s", 0.0, 600.0, lo_open=True)
    angle: float = setting(90.0, MOVING_VESSEL, "Tilt.", "deg", 0.0, 180.0, lo_open=True)
    amplitude: float = setting(0.01, MOVING_VESSEL, "Shake amplitude.", "m", 0.0, 0.1)
    periods: float = setting(4.0, MOVING_VESSEL, "Shake periods.", "", 0.0, 50.0, lo_open=True)
    particles_across: int = setting(24, MOVING_VESSEL, "Resolution across the vessel's inner width when spacing is not "
                                    "given.", "", 8, 400)
    scene: str = ""
    @property
    def inner_height(self) -> float:
        """m, the vessel's inner height (the fill's limit)."""
        return self.spec().inner_height

    def spec(self) -> VesselSpec:
        return load_scene(self.scene).vessels.pourer.spec("pourer", "vessels.pourer") if self.scene else seed_pouring_vessel()

    def duration_for(self, case: str) -> float:
        """Simulated time (s): the tilt plus a hold, or the shake periods."""
        if case == "tilt":
            return self.angle / self.rate + HOLD_AFTER_TILT
        return self.periods / eq17_frequency(self.spec().inner_width, self.fill)

    @property
    def resolved_spacing(self) -> float:
        return self.spacing if self.spacing is not None else self.spec().inner_width / self.particles_across


def _run(name: str, p: Params, pose_at: PoseScript) -> CaseResult:
    spec = p.spec()
    dx = p.resolved_spacing
    cfg = case_fluid_config(p.dim, dx, max(p.fill, FALL_HEIGHT), spec.section_depth, *domain_around(spec, p.amplitude), p.solver,
                            numerics=p.numerics)
    run = run_scripted(spec, p.fill, cfg, pose_at, p.duration_for(name), device=p.device)
    solver, leaks, failure = run.solver, run.leaks, run.failure
    hist = solver.history()
    volume0 = solver.n_particles * cfg.particle_volume
    metrics = [
        Metric("run completed", 0.0 if failure else 1.0, 1.0, 0.0 if not failure else 1.0, 0.0, "", absolute=True),
        Metric("particles inside a wall", float(leaks.worst_inside), 0.0, float(leaks.worst_inside), 0.0, "", absolute=True),
        Metric("particles through a wall", float(leaks.worst_through), 0.0, float(leaks.worst_through), 0.0, "", absolute=True),
    ]
    raw = {
        "failure": failure,
        "simulated_time": solver.time,
        "particles": solver.n_particles,
        "steps": solver.step_count,
        "max_density_error": float(hist["max_density_error"].max()) if hist else float("nan"),
        "guard_corrections": int(hist["wall_corrections"].sum()) if hist else 0,
        "volume_left_in_vessel": float(hist["volume_in_vessel"][-1, 0]) if hist else float("nan"),
        "initial_volume": volume0,
        "t": run.t,
        "volume_in_vessel": run.volume_in_vessel,
    }
    params = dict(fill=p.fill, spacing=dx, dim=p.dim, device=p.device, solver=p.solver.value, rate=p.rate, angle=p.angle,
                  amplitude=p.amplitude, periods=p.periods, vessel=spec.shape.value, scene=p.scene)
    return CaseResult(name, params, metrics, raw, run.wall_time)


def run_tilt(p: Params) -> CaseResult:
    return _run("tilt", p, tilt_about_lip(p.spec(), math.radians(p.rate), math.radians(p.angle)))


def run_shake(p: Params) -> CaseResult:
    omega = 2 * math.pi * eq17_frequency(p.spec().inner_width, p.fill)
    return _run("shake", p, shake_sideways(p.amplitude, omega))


def plot(result: CaseResult, path) -> None:
    fig, ax, plt = new_figure(
        f"{result.case} ({result.parameters['dim']}-D): liquid left in the vessel; "
        f"inside walls {int(result.metrics[1].measured)}, through walls {int(result.metrics[2].measured)}"
    )
    v0 = result.raw["initial_volume"]
    ax.plot(result.raw["t"], np.asarray(result.raw["volume_in_vessel"]) / v0, label="volume in vessel / initial")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("fraction")
    ax.set_ylim(0, 1.05)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
