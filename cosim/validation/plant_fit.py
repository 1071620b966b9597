"""The first-mode slosh plant from the free responses to tilts about several pivots (numpy and SciPy only).

The vessel, at rest, is tilted by a small angle about a pivot at height p on its axis and then held; afterwards
the slosh angle sigma (rad, :mod:`controllers.slosh`) rings down. The pendulum (M) of :mod:`controllers.slosh` is
one plant: whatever the pivot, the liquid rings at the same omega1 with the same damping ratio zeta, and only the
drive differs, the hinge's sideways motion x_h = (H - p) theta. So the records are fitted jointly (SciPy least
squares over all runs at once) with one omega1 and one zeta and, per run i, a phasor (a_i, b_i) and an offset c_i
(the tilted lattice's surface fit need not read exactly zero at rest):

    sigma_i(t') = c_i + exp(-zeta omega1 t') (a_i cos(omega_d t') + b_i sin(omega_d t')),
    omega_d = omega1 sqrt(1 - zeta^2),

t' the time since the tilt ended. Sharing omega1 and zeta is what the model asserts, and it matters for the hinge:
a run near the hinge barely rings, and a fit of its own (its own omega and zeta) is free to lock onto whatever else
its record holds (a start-up transient, noise), which puts its phasor off the line the other runs define. At the
shared frequency its phasor is only the first mode's share of its record. Every phasor is then one common phasor
times (H - p): the signed amplitude, the phasor projected on that of the run with the largest response, is a line
in p whose zero is the hinge H, found by least squares through (p, signed amplitude).

Each run's own free fit (:func:`fit_damped_sine`) is kept as a diagnostic: where its omega departs from the shared
one, that run's record holds more than the first mode. A :class:`controllers.slosh.SloshModel` built from the
identification (l1 = g / omega1^2) stands in for the closed form where a vessel has none.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from controllers.slosh import SloshModel
from cosim.errors import InputError
from cosim.validation.common import zero_crossing_frequency

MIN_PIVOTS = 3  # a line through two points has no residual to judge it by
INITIAL_DAMPING_RATIO = 0.02  # the fits' starting zeta (SPH liquids at practical resolutions: 0.01-0.05)
MAX_DAMPING_RATIO = 0.9
OMEGA_SEARCH = (0.5, 2.0)  # the fits' omega bounds, as factors of the zero-crossing estimate


@dataclass(frozen=True)
class DampedSine:
    """One run's own fit: omega (rad/s), zeta, the phasor a, b (rad) at the tilt's end, offset c (rad), and the
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


def _phasors_at(t: np.ndarray, ys: list[np.ndarray], omega: float, zeta: float) -> np.ndarray:
    """Per record, the least-squares (a, b, c) of :func:`damped_sine` at this omega (rad/s) and zeta: rows."""
    omega_d = omega * math.sqrt(max(1.0 - zeta * zeta, 0.0))
    decay = np.exp(-zeta * omega * t)
    basis = np.stack([decay * np.cos(omega_d * t), decay * np.sin(omega_d * t), np.ones_like(t)], axis=1)
    return np.array([np.linalg.lstsq(basis, y, rcond=None)[0] for y in ys])


def _parameter_variances(result, n_residuals: int) -> np.ndarray:
    """The variances of a scipy.optimize.least_squares result's parameters: (J^T J)^-1 times the residual variance."""
    dof = n_residuals - len(result.x)
    if dof <= 0:
        return np.full(len(result.x), np.inf)
    cov = np.linalg.pinv(result.jac.T @ result.jac) * (2.0 * result.cost / dof)
    return np.where(np.isfinite(np.diag(cov)), np.diag(cov), np.inf)


def fit_damped_sine(t: np.ndarray, y: np.ndarray, omega_guess: float) -> DampedSine:
    """One record's own least-squares :func:`damped_sine` through (t, y) (s, rad), t from the tilt's end, started at
    ``omega_guess`` (rad/s) with the phasor and offset of the linear fit at that frequency."""
    import scipy.optimize

    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    a0, b0, c0 = _phasors_at(t, [y], omega_guess, INITIAL_DAMPING_RATIO)[0]
    try:
        p, cov = scipy.optimize.curve_fit(
            damped_sine, t, y, p0=[omega_guess, INITIAL_DAMPING_RATIO, a0, b0, c0],
            bounds=([OMEGA_SEARCH[0] * omega_guess, 0.0, -np.inf, -np.inf, -np.inf],
                    [OMEGA_SEARCH[1] * omega_guess, MAX_DAMPING_RATIO, np.inf, np.inf, np.inf]),
        )
    except (RuntimeError, ValueError):  # no convergence, or a record too short for five parameters
        return FAILED_FIT
    variances = np.where(np.isfinite(np.diag(cov)), np.diag(cov), np.inf)
    residual = float(np.sqrt(np.mean((y - damped_sine(t, *p)) ** 2)))
    return DampedSine(*(float(v) for v in p), float(variances[0]), float(variances[1]), residual)


@dataclass(frozen=True)
class SharedRingDown:
    """The joint fit: ``omega1`` (rad/s) and ``zeta`` shared by all records, their variances, and per record the
    phasor ``a``, ``b`` and ``offset`` (rad) and the ``rms_residual`` (rad) of its record against the fit."""

    omega1: float
    zeta: float
    omega1_variance: float
    zeta_variance: float
    a: tuple[float, ...]
    b: tuple[float, ...]
    offset: tuple[float, ...]
    rms_residual: tuple[float, ...]


def fit_shared_ring_down(t: np.ndarray, ys: list[np.ndarray], omega_guess: float) -> SharedRingDown | None:
    """Least squares of :func:`damped_sine` through every record ``ys[i]`` (rad, at times ``t`` in s from the tilt's
    end) at once, with one omega and zeta for all and a phasor and offset per record, started at ``omega_guess``
    (rad/s) with each record's linear fit at that frequency. None if the fit does not converge."""
    import scipy.optimize

    t = np.asarray(t, dtype=float)
    ys = [np.asarray(y, dtype=float) for y in ys]
    n = len(ys)

    def residuals(x: np.ndarray) -> np.ndarray:
        return np.concatenate([damped_sine(t, x[0], x[1], *x[2 + 3 * i: 5 + 3 * i]) - y for i, y in enumerate(ys)])

    x0 = np.concatenate([[omega_guess, INITIAL_DAMPING_RATIO], _phasors_at(t, ys, omega_guess, INITIAL_DAMPING_RATIO).ravel()])
    lower = np.concatenate([[OMEGA_SEARCH[0] * omega_guess, 0.0], np.full(3 * n, -np.inf)])
    upper = np.concatenate([[OMEGA_SEARCH[1] * omega_guess, MAX_DAMPING_RATIO], np.full(3 * n, np.inf)])
    result = scipy.optimize.least_squares(residuals, x0, bounds=(lower, upper), x_scale="jac")
    if not result.success:
        return None
    variances = _parameter_variances(result, n * len(t))
    phasors = result.x[2:].reshape(n, 3)
    rms = np.sqrt(np.mean(result.fun.reshape(n, len(t)) ** 2, axis=1))
    return SharedRingDown(float(result.x[0]), float(result.x[1]), float(variances[0]), float(variances[1]),
                          tuple(float(v) for v in phasors[:, 0]), tuple(float(v) for v in phasors[:, 1]),
                          tuple(float(v) for v in phasors[:, 2]), tuple(float(v) for v in rms))


@dataclass(frozen=True)
class PlantFit:
    """The identified plant: ``omega1`` (rad/s), ``damping_ratio``, ``hinge_height`` (m above the inner floor), the
    joint fit behind them (``shared``), and per run the ``pivots`` (m), ``signed_amplitudes`` (rad) and own fits
    (``free_fits``, diagnostics); ``line`` = (slope 1/m, intercept) of the amplitude against the pivot height,
    ``line_rms`` (rad) its residual."""

    omega1: float
    damping_ratio: float
    hinge_height: float
    pivots: tuple[float, ...]
    shared: SharedRingDown | None
    free_fits: tuple[DampedSine, ...]
    signed_amplitudes: tuple[float, ...]
    line: tuple[float, float]
    line_rms: float

    def slosh_model(self, gravity: float, source: str = "SPH identification") -> SloshModel:
        """The pendulum (M) with l1 = g / omega1^2, this hinge and damping ratio (``gravity`` in m/s^2)."""
        return SloshModel(gravity / self.omega1**2, self.hinge_height, self.damping_ratio, gravity, source)


def signed_amplitudes(a: list[float], b: list[float]) -> list[float]:
    """Each phasor (a_i, b_i) (rad) projected on the unit phasor of the largest one: the amplitudes with the sign
    of their phase (rad)."""
    phasors = np.column_stack([a, b])
    reference = phasors[int(np.argmax(np.hypot(phasors[:, 0], phasors[:, 1])))]
    return [float(v) for v in phasors @ (reference / np.hypot(*reference))]


def identify_plant(pivots: list[float], t: np.ndarray, sigmas: list[np.ndarray]) -> PlantFit:
    """Fit the slosh angles ``sigmas[i]`` (rad, at times ``t`` in s from the tilt's end) after tilts about the
    pivots ``pivots[i]`` (m above the inner floor) jointly and identify the plant (module docstring). What the
    records cannot give (no full period, a fit that does not converge) is NaN, so that a comparison with it fails."""
    if len(pivots) != len(sigmas) or len(set(pivots)) < MIN_PIVOTS:
        raise InputError(f"pivots: need one record per pivot and >= {MIN_PIVOTS} distinct pivots, got {list(pivots)}")
    t = np.asarray(t, dtype=float)
    sigmas = [np.asarray(s, dtype=float) for s in sigmas]
    loudest = max(range(len(sigmas)), key=lambda i: float(np.ptp(sigmas[i])))
    frequency, _ = zero_crossing_frequency(t, sigmas[loudest])
    if not math.isfinite(frequency):
        nan = math.nan
        return PlantFit(nan, nan, nan, tuple(float(p) for p in pivots), None, (FAILED_FIT,) * len(sigmas),
                        (nan,) * len(sigmas), (nan, nan), nan)
    omega_guess = 2.0 * math.pi * frequency
    free_fits = tuple(fit_damped_sine(t, s, omega_guess) for s in sigmas)
    shared = fit_shared_ring_down(t, sigmas, omega_guess)
    if shared is None:
        amplitudes, slope, intercept, line_rms = [math.nan] * len(sigmas), math.nan, math.nan, math.nan
    else:
        amplitudes = signed_amplitudes(list(shared.a), list(shared.b))
        slope, intercept = (float(c) for c in np.polyfit(pivots, amplitudes, 1))
        line_rms = float(np.sqrt(np.mean((np.polyval([slope, intercept], pivots) - amplitudes) ** 2)))
    return PlantFit(
        omega1=shared.omega1 if shared else math.nan,
        damping_ratio=shared.zeta if shared else math.nan,
        hinge_height=-intercept / slope if slope != 0.0 else math.nan,
        pivots=tuple(float(p) for p in pivots),
        shared=shared,
        free_fits=free_fits,
        signed_amplitudes=tuple(amplitudes),
        line=(slope, intercept),
        line_rms=line_rms,
    )
