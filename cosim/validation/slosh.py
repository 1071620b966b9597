"""First sloshing mode of a rectangular tank against linear potential-flow theory.

omega^2 = (g pi / B) tanh(pi A / B), f = omega / (2 pi)  (Camporredondo et al. 2019, Eq. 17).

The tank (inner width B, fill A) starts at rest; a smooth lateral displacement pulse of a few millimetres (half a
cosine over a quarter of the expected period) excites the first mode, then the tank stands still. The horizontal
position of the liquid's centre of mass relative to the tank oscillates at the sloshing frequency; the frequency
is the mean period between its upward zero crossings over the measurement window. The damping ratio (from the
decay of successive peaks) is reported too, for information.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from cosim.fluid.config import GRAVITY
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose
from cosim.validation.common import (
    CaseResult,
    FluidCaseParams,
    Metric,
    case_fluid_config,
    new_figure,
    require_particles_across,
    whole_spacings,
    zero_crossing_frequency,
)
from cosim.vessel import VesselSpec
from declared_settings.setting import documented, setting

# Acceptance: first-mode frequency within 3 % of Eq. 17.
FREQUENCY_TOLERANCE = 0.03
SEED_FILLS = (0.054, 0.108, 0.162)  # m, fills within the paper's tests (its Sec. 4: 54..162 mm)
MIN_PARTICLES_ACROSS = 40
PULSE_AMPLITUDE = 0.004  # m, lateral displacement of the excitation pulse (small: linear regime)
SAMPLE_INTERVAL = 0.002  # s, sampling of the centre-of-mass signal (and the pose update interval)


def eq17_frequency(width: float, fill: float, g: float = GRAVITY) -> float:
    """Eq. 17: first-mode sloshing frequency (Hz) of a rectangular tank of inner width B, fill depth A."""
    return math.sqrt(g * math.pi / width * math.tanh(math.pi * fill / width)) / (2.0 * math.pi)


SLOSH = "slosh"


@documented
@dataclass(frozen=True)
class Params(FluidCaseParams):
    """A tank's first slosh mode, excited by a pulse."""

    width: float = setting(VesselSpec.inner_width, SLOSH, "Tank inner width B.", "m", 0.0, 2.0, lo_open=True)
    fill: float = setting(0.108, SLOSH, "Fill depth A.", "m", 0.0, 2.0, lo_open=True)
    periods: float = setting(5.0, SLOSH, "Oscillation periods measured after the pulse.", "", 0.0, 50.0, lo_open=True)

    def __post_init__(self) -> None:
        super().__post_init__()
        require_particles_across("spacing", self.width, self.resolved_spacing, 8)  # refused before any case runs

    @property
    def resolved_spacing(self) -> float:
        return self.spacing if self.spacing is not None else self.width / MIN_PARTICLES_ACROSS


def run(p: Params) -> CaseResult:
    dx = p.resolved_spacing
    width, depth = whole_spacings(p.width, dx), p.tank_depth(dx)
    f_ref = eq17_frequency(width, p.fill)
    period = 1.0 / f_ref
    pulse = 0.25 * period
    tank = VesselSpec(name="tank", inner_width=width, inner_depth=depth, inner_height=p.fill + 0.5 * width + 4 * dx)
    margin = 0.05 * width + 10 * dx
    half = 0.5 * width + margin
    cfg = case_fluid_config(
        p.dim, dx, p.fill, depth, (-half, -0.5 * depth - margin, -margin), (half + PULSE_AMPLITUDE, 0.5 * depth + margin, tank.inner_height + margin), p.solver,
        numerics=p.numerics,
    )
    solver = FluidSolver(cfg, [tank], [Pose()], fill_vessel(tank, p.fill, cfg), device=p.device)
    t_end = pulse + p.periods * period
    n = int(math.ceil(t_end / SAMPLE_INTERVAL))
    times, com = np.empty(n), np.empty(n)
    start = time.perf_counter()
    for k in range(n):
        t = (k + 1) * SAMPLE_INTERVAL
        shift = PULSE_AMPLITUDE * 0.5 * (1.0 - math.cos(math.pi * min(t, pulse) / pulse))
        solver.set_vessel_poses([Pose((shift, 0.0, 0.0))])
        solver.advance(SAMPLE_INTERVAL)
        x = solver.positions()
        times[k], com[k] = t, x[:, 0].mean() - shift
    wall = time.perf_counter() - start

    window = times > pulse + 0.25 * period
    f_meas, used = zero_crossing_frequency(times[window], com[window])
    y = com[window] - com[window].mean()
    peaks = [y[i] for i in range(1, len(y) - 1) if y[i] > y[i - 1] and y[i] >= y[i + 1] and y[i] > 0.2 * y.max()]
    damping = float("nan")
    if len(peaks) >= 2 and peaks[-1] > 0:
        log_dec = math.log(peaks[0] / peaks[-1]) / (len(peaks) - 1)
        damping = log_dec / math.sqrt(4 * math.pi**2 + log_dec**2)
    metrics = [Metric("first-mode frequency", f_meas, f_ref, (f_meas - f_ref) / f_ref, FREQUENCY_TOLERANCE, "Hz")]
    raw = {
        "frequency_hz": f_meas,
        "reference_hz": f_ref,
        "periods_used": used,
        "damping_ratio": damping,
        "t": times.tolist(),
        "com_x": com.tolist(),
        "particles": solver.n_particles,
        "steps": solver.step_count,
    }
    params = dict(width=width, fill=p.fill, spacing=dx, dim=p.dim, device=p.device, solver=p.solver.value, periods=p.periods, depth=depth)
    return CaseResult("slosh", params, metrics, raw, wall)


def plot(result: CaseResult, path) -> None:
    par = result.parameters
    fig, ax, plt = new_figure(
        f"Slosh B={par['width']:.3f} m A={par['fill']:.3f} m: {result.raw['frequency_hz']:.3f} Hz "
        f"(Eq. 17: {result.raw['reference_hz']:.3f} Hz)"
    )
    t, c = np.asarray(result.raw["t"]), np.asarray(result.raw["com_x"])
    ax.plot(t, 1e3 * (c - c[-len(c) // 2 :].mean()), lw=1.2, label="SPH liquid centre of mass (tank frame)")
    ref = result.raw["reference_hz"]
    amp = 1e3 * np.abs(c - c.mean()).max()
    ax.plot(t, amp * np.cos(2 * np.pi * ref * (t - t[np.argmax(c)])), "k:", lw=0.8, label="Eq. 17 frequency (phase-matched)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("x_com (mm)")
    ax.legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
