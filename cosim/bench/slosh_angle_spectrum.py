"""The slosh angle's spectrum in a slosh validation case: where the liquid's own motion lies in what the PID reads.

    python -m cosim.bench.slosh_angle_spectrum [--solver wcsph|dfsph] [--across N] [--hold S] [--json]

The case is ``cosim validate slosh-plant``'s (:mod:`cosim.validation.slosh_plant`) at the pour's vessel and
resolution: the default pourer (inner width 0.191 m) filled to 0.1591 m, in 2-D, ``across`` particles over the
width, the pour's fluid settings (the default ``max_expected_speed``, so WCSPH runs at the pour's c0), tilted by
0.08 rad about the floor centre (which excites the first slosh mode) and held. The slosh angle sigma = theta1 -
theta the controller reads (:class:`cosim.coupling.measure.LiquidProbe`) is recorded every 2 ms over the hold.

Reported: the first mode's frequency (the spectrum's peak), and the content above ``--above`` Hz (the band no
pour needs, five times the slosh frequency): its RMS and its share per 2.5 Hz band, both as recorded (2 ms, up to
250 Hz) and as the controller samples it (every 10 ms, so content above its 50 Hz Nyquist frequency folds back
below it). Above the shortest surface gravity wave the particle lattice resolves (wavelength two spacings, angular
frequency sqrt(g pi / spacing): 11.4 Hz at 32 across 0.191 m) the surface's motion is no gravity wave: particle-scale
motion just above that limit, and in a weakly compressible liquid its acoustic modes. The lowest acoustic mode
that tilts the surface (rigid walls and floor, free surface) is f_a = (c0 / 2) sqrt(1 / B^2 + 1 / (2 A)^2), 61 Hz
for c0 = 20 m/s. The report gives that mode and the largest band above the gravity-wave limit in each record (read
the bands too: the particle-scale content next to the limit can be as large); where the 10 ms record holds the
acoustic peak is where it reaches the controller, and that band's lower edge is the noise band's lower edge that
the PID's measurement filter (:class:`controllers.pid_spec.PidDesignSpec`, ``noise_frequency``) has to stop, its
cut-off lying between it and the slosh mode.

Both records are detrended by the least-squares damped sinusoid at the first mode before the spectrum (the
ring-down's leakage would otherwise fill the bands), with a Hann window.
"""

from __future__ import annotations

import argparse
import json
import math

import numpy as np
import scipy.optimize

from cosim.fluid.config import GRAVITY, FluidConfig, PressureSolver
from cosim.validation.scripted import run_scripted, tilt_about_axis_point
from cosim.validation.slosh_plant import SETTLE_TIME, TILT_ANGLE, TILT_DURATION, Params, SlopeRecorder, domain_for

POURER_WIDTH, POURER_FILL = 0.191, 0.1591  # m, the default scene's pourer and fill
CONTROL_PERIOD = 0.01  # s, the pour controller's sample time
BAND_WIDTH = 2.5  # Hz, of the reported bands


def ring_down_residual(t: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """sigma (rad) less its least-squares fit a + exp(-d t) (b cos(w t) + c sin(w t)), t in s."""

    def model(p: np.ndarray) -> np.ndarray:
        a, d, w, b, c = p
        return a + np.exp(-d * t) * (b * np.cos(w * t) + c * np.sin(w * t))

    w0 = 2.0 * math.pi * peak_frequency(t, sigma)
    fit = scipy.optimize.least_squares(lambda p: model(p) - sigma, [float(np.mean(sigma)), 0.1, w0, float(sigma[0]), 0.0])
    return sigma - model(fit.x)


def peak_frequency(t: np.ndarray, sigma: np.ndarray) -> float:
    """Hz, the largest bin of sigma's spectrum (its mean removed)."""
    freq = np.fft.rfftfreq(t.size, float(t[1] - t[0]))
    power = np.abs(np.fft.rfft(sigma - np.mean(sigma))) ** 2
    return float(freq[1 + int(np.argmax(power[1:]))])


def band_powers(x: np.ndarray, dt: float, above: float) -> tuple[float, list[tuple[float, float]]]:
    """(RMS of x above ``above`` Hz, [(band's lower edge Hz, share of that power)]) with a Hann window, bands
    BAND_WIDTH Hz wide from ``above``; the RMS by Parseval over the windowed record (window power normalised)."""
    window = np.hanning(x.size)
    spectrum = np.abs(np.fft.rfft((x - np.mean(x)) * window)) ** 2
    freq = np.fft.rfftfreq(x.size, dt)
    scale = 2.0 / (x.size * np.sum(window**2))
    above_mask = freq > above
    total = float(np.sum(spectrum[above_mask]))
    bands = []
    for lo in np.arange(above, freq[-1], BAND_WIDTH):
        mask = (freq > lo) & (freq <= lo + BAND_WIDTH)
        bands.append((float(lo), float(np.sum(spectrum[mask])) / total if total > 0.0 else 0.0))
    return math.sqrt(scale * total), bands


def gravity_wave_limit(spacing: float) -> float:
    """Hz, the deep-water frequency sqrt(g k) / (2 pi) of the shortest wave a lattice of ``spacing`` (m) resolves,
    k = 2 pi / (2 spacing)."""
    return math.sqrt(GRAVITY * math.pi / spacing) / (2.0 * math.pi)


def acoustic_mode(sound_speed: float, width: float, depth: float) -> float:
    """Hz, the lowest acoustic mode of a liquid of ``depth`` (m) in a box of ``width`` (m) that tilts its surface:
    pressure cos(pi x / B) sin(pi z / 2A) (rigid walls and floor, free surface at z = A), sound speed c0 (m/s),
    f_a = (c0 / 2) sqrt(1 / B^2 + 1 / (2 A)^2)."""
    return 0.5 * sound_speed * math.hypot(1.0 / width, 0.5 / depth)


def largest_band(bands: list[tuple[float, float]], above: float) -> tuple[float, float]:
    """(lower edge Hz, share) of the largest band starting at or above ``above`` Hz."""
    return max(((lo, share) for lo, share in bands if lo >= above), key=lambda b: b[1])


def measure(solver: PressureSolver, across: int, hold: float, above: float) -> dict:
    p = Params(width=POURER_WIDTH, fill=POURER_FILL, hold=hold, particles_across=across, solver=solver)
    spec, dx = p.tank(), p.resolved_spacing
    pose = tilt_about_axis_point(0.0, TILT_ANGLE, TILT_DURATION)(TILT_DURATION)
    lo, hi = domain_for(spec, [pose], 0.05 * spec.inner_width + 10 * dx)
    cfg = FluidConfig(dim=2, pressure_solver=solver, spacing=dx, depth_2d=spec.section_depth, domain_min=tuple(lo),
                      domain_max=tuple(hi))
    recorder = SlopeRecorder(spec, cfg)
    run = run_scripted(spec, POURER_FILL, cfg, tilt_about_axis_point(0.0, TILT_ANGLE, TILT_DURATION), TILT_DURATION + hold,
                       can_spill=False, observer=recorder, settle=SETTLE_TIME)
    t, sigma = np.asarray(recorder.t), np.asarray(recorder.sigma)
    t, sigma = t[t > TILT_DURATION + 1e-9] - TILT_DURATION, sigma[t > TILT_DURATION + 1e-9]
    record_dt = float(t[1] - t[0])
    residual = ring_down_residual(t, sigma)
    step = round(CONTROL_PERIOD / record_dt)
    rms, bands = band_powers(residual, record_dt, above)
    rms_c, bands_c = band_powers(residual[::step], CONTROL_PERIOD, above)
    limit = gravity_wave_limit(dx)
    return {
        "solver": solver.value, "across": across, "c0": cfg.sound_speed,
        "slosh_frequency": peak_frequency(t, sigma), "record_interval": record_dt,
        "rms_above": rms, "bands": bands, "rms_above_control_rate": rms_c, "bands_control_rate": bands_c,
        "gravity_wave_limit": limit, "acoustic_mode": acoustic_mode(cfg.sound_speed, spec.inner_width, POURER_FILL),
        "largest_band": largest_band(bands, limit), "largest_band_control_rate": largest_band(bands_c, limit),
        "failure": run.failure,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--solver", default="wcsph", choices=[s.value for s in PressureSolver])
    ap.add_argument("--across", type=int, default=32)
    ap.add_argument("--hold", type=float, default=2.0, help="s recorded after the tilt")
    ap.add_argument("--above", type=float, default=10.0, help="Hz, the band's lower end")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    r = measure(PressureSolver(a.solver), a.across, a.hold, a.above)
    if a.json:
        print(json.dumps(r))
        return 0
    print(f"{r['solver']}, {r['across']} across: slosh peak {r['slosh_frequency']:.2f} Hz; sigma above {a.above:g} Hz: "
          f"{r['rms_above']:.3g} rad RMS (2 ms), {r['rms_above_control_rate']:.3g} rad RMS (10 ms)")
    for name in ("bands", "bands_control_rate"):
        print(name + ": " + ", ".join(f"{lo:g}-{lo + BAND_WIDTH:g} Hz {100 * s:.1f} %" for lo, s in r[name] if s >= 0.005))
    print(f"shortest resolved gravity wave {r['gravity_wave_limit']:.1f} Hz; lowest surface-tilting acoustic mode "
          f"(c0 = {r['c0']:g} m/s) {r['acoustic_mode']:.1f} Hz; largest band above the gravity waves: "
          f"{r['largest_band'][0]:g} Hz ({100 * r['largest_band'][1]:.1f} %) recorded, "
          f"{r['largest_band_control_rate'][0]:g} Hz ({100 * r['largest_band_control_rate'][1]:.1f} %) at the control rate")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
