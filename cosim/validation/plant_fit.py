"""The first-mode slosh plant from the free responses to tilts about several pivots (numpy and SciPy only).

The vessel, at rest, is tilted by a small angle about a pivot at height p on its axis and then held; afterwards
the slosh angle sigma (rad, :mod:`controllers.slosh`) rings down. Each run's record after the tilt is fitted with
a damped sinusoid plus an offset (the tilted lattice's surface fit need not read exactly zero at rest):

    sigma(t') = c + exp(-zeta omega t') (a cos(omega_d t') + b sin(omega_d t')),  omega_d = omega sqrt(1 - zeta^2),

t' the time since the tilt ended. The pendulum (M) of :mod:`controllers.slosh` is driven by the hinge's sideways
motion x_h = (H - p) theta, so every run rings with the same omega1 and zeta, and its phasor (a, b) is one common
phasor times (H - p): the signed amplitude, the phasor projected on that of the run with the largest response, is
a line in p whose zero is the hinge H. omega1 and zeta are the fits' inverse-variance weighted means (a run near
the hinge barely rings and says little about either); the hinge is the zero of the least-squares line through
(p, signed amplitude). A :class:`controllers.slosh.SloshModel` built from these (l1 = g / omega1^2) stands in for
the closed form where a vessel has none.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from controllers.slosh import SloshModel
from cosim.errors import InputError
from cosim.validation.common import zero_crossing_frequency

MIN_PIVOTS = 3  # a line through two points has no residual to judge it by
INITIAL_DAMPING_RATIO = 0.02  # the fit's starting zeta (SPH liquids at practical resolutions: 0.01-0.05)


@dataclass(frozen=True)
class DampedSine:
    """One run's fit: omega (rad/s), zeta, the phasor a, b (rad) at the tilt's end, offset c (rad), and the
    variances of omega and zeta from the fit's covariance (inf where the fit failed)."""

    omega: float
    zeta: float
    a: float
    b: float
    offset: float
    omega_variance: float
    zeta_variance: float
    rms_residual: float

    @property
    def amplitude(self) -> float:
        """|(a, b)| (rad), the ring-down's amplitude at the tilt's end."""
        return math.hypot(self.a, self.b)

    def __call__(self, t: np.ndarray) -> np.ndarray:
        return damped_sine(np.asarray(t, dtype=float), self.omega, self.zeta, self.a, self.b, self.offset)


FAILED_FIT = DampedSine(math.nan, math.nan, math.nan, math.nan, math.nan, math.inf, math.inf, math.nan)


def damped_sine(t: np.ndarray, omega: float, zeta: float, a: float, b: float, offset: float) -> np.ndarray:
    """offset + exp(-zeta omega t) (a cos(omega_d t) + b sin(omega_d t)), omega_d = omega sqrt(1 - zeta^2)."""
    omega_d = omega * math.sqrt(max(1.0 - zeta * zeta, 0.0))
    return offset + np.exp(-zeta * omega * t) * (a * np.cos(omega_d * t) + b * np.sin(omega_d * t))


def fit_damped_sine(t: np.ndarray, y: np.ndarray, omega_guess: float) -> DampedSine:
    """Least-squares :func:`damped_sine` through (t, y) (s, rad), t from the tilt's end, started at
    ``omega_guess`` (rad/s) with the phasor and offset of the linear fit at that frequency."""
    import scipy.optimize

    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    decay = np.exp(-INITIAL_DAMPING_RATIO * omega_guess * t)
    basis = np.stack([decay * np.cos(omega_guess * t), decay * np.sin(omega_guess * t), np.ones_like(t)], axis=1)
    a0, b0, c0 = np.linalg.lstsq(basis, y, rcond=None)[0]
    try:
        p, cov = scipy.optimize.curve_fit(
            damped_sine, t, y, p0=[omega_guess, INITIAL_DAMPING_RATIO, a0, b0, c0],
            bounds=([0.5 * omega_guess, 0.0, -np.inf, -np.inf, -np.inf], [2.0 * omega_guess, 0.9, np.inf, np.inf, np.inf]),
        )
    except (RuntimeError, ValueError):  # no convergence, or a record too short for five parameters
        return FAILED_FIT
    variances = np.where(np.isfinite(np.diag(cov)), np.diag(cov), np.inf)
    residual = float(np.sqrt(np.mean((y - damped_sine(t, *p)) ** 2)))
    return DampedSine(*(float(v) for v in p), float(variances[0]), float(variances[1]), residual)


def _weighted_mean(values: list[float], variances: list[float]) -> float:
    """Inverse-variance weighted mean of the finite values with a positive finite variance; NaN if none."""
    pairs = [(v, 1.0 / s) for v, s in zip(values, variances) if math.isfinite(v) and 0.0 < s < math.inf]
    if not pairs:
        return math.nan
    return sum(v * w for v, w in pairs) / sum(w for _, w in pairs)


@dataclass(frozen=True)
class PlantFit:
    """The identified plant: ``omega1`` (rad/s), ``damping_ratio``, ``hinge_height`` (m above the inner floor), and
    per run the ``pivots`` (m), ``fits`` and ``signed_amplitudes`` (rad); ``line`` = (slope 1/m, intercept) of the
    amplitude against the pivot height, ``line_rms`` (rad) its residual."""

    omega1: float
    damping_ratio: float
    hinge_height: float
    pivots: tuple[float, ...]
    fits: tuple[DampedSine, ...]
    signed_amplitudes: tuple[float, ...]
    line: tuple[float, float]
    line_rms: float

    def slosh_model(self, gravity: float, source: str = "SPH identification") -> SloshModel:
        """The pendulum (M) with l1 = g / omega1^2, this hinge and damping ratio (``gravity`` in m/s^2)."""
        return SloshModel(gravity / self.omega1**2, self.hinge_height, self.damping_ratio, gravity, source)


def identify_plant(pivots: list[float], t: np.ndarray, sigmas: list[np.ndarray]) -> PlantFit:
    """Fit each run's slosh angle ``sigmas[i]`` (rad, at times ``t`` in s from the tilt's end) after a tilt about
    the pivot ``pivots[i]`` (m above the inner floor) and identify the plant (module docstring). What the records
    cannot give (no full period, failed fits) is NaN, so that a comparison with it fails."""
    if len(pivots) != len(sigmas) or len(set(pivots)) < MIN_PIVOTS:
        raise InputError(f"pivots: need one record per pivot and >= {MIN_PIVOTS} distinct pivots, got {list(pivots)}")
    t = np.asarray(t, dtype=float)
    loudest = max(range(len(sigmas)), key=lambda i: float(np.ptp(sigmas[i])))
    frequency, _ = zero_crossing_frequency(t, np.asarray(sigmas[loudest], dtype=float))
    fits = [fit_damped_sine(t, s, 2.0 * math.pi * frequency) if math.isfinite(frequency) else FAILED_FIT for s in sigmas]
    reference = max(fits, key=lambda f: f.amplitude if math.isfinite(f.amplitude) else -1.0)
    unit = np.array([reference.a, reference.b]) / reference.amplitude
    amplitudes = [float(np.dot([f.a, f.b], unit)) for f in fits]
    slope = intercept = line_rms = math.nan
    if all(math.isfinite(a) for a in amplitudes):
        slope, intercept = (float(c) for c in np.polyfit(pivots, amplitudes, 1))
        line_rms = float(np.sqrt(np.mean((np.polyval([slope, intercept], pivots) - amplitudes) ** 2)))
    return PlantFit(
        omega1=_weighted_mean([f.omega for f in fits], [f.omega_variance for f in fits]),
        damping_ratio=_weighted_mean([f.zeta for f in fits], [f.zeta_variance for f in fits]),
        hinge_height=-intercept / slope if slope != 0.0 else math.nan,
        pivots=tuple(float(p) for p in pivots),
        fits=tuple(fits),
        signed_amplitudes=tuple(amplitudes),
        line=(slope, intercept),
        line_rms=line_rms,
    )
