"""PID compensator for the slosh plant Gp (Camporredondo et al. 2019, Sec. 3.1, Eq. 15; Figs. 8, 14, 15).

Loop: unity negative feedback, theta = C(s) (r - theta1), theta1 = Gp(s) theta, with Gp from
:meth:`controllers.slosh.SloshModel.plant` (sign convention there: DC gain +1).

* The paper's ideal PID C = (Kd s^2 + Kp s + Ki)/s cannot stabilise Gp: the closed-loop characteristic
  polynomial (:func:`ideal_pid_characteristic`) is
      b2 Kd s^4 + (l1 + b2 Kp) s^3 + (b2 Ki + g Kd) s^2 + g (1 + Kp) s + g Ki
  and with b2 < 0 its s^4, s^2 and s^0 coefficients can never share one sign (Hurwitz necessary condition).
* A derivative filter, C = Kp + Ki/s + Kd s/(Tf s + 1), removes the conflict. Its closed-loop polynomial
      [Tf l1 + b2 u] s^4 + [l1 + b2 v] s^3 + [Tf g + b2 w + g u] s^2 + [g + g v] s + g w,
      u = Kp Tf + Kd,  v = Kp + Ki Tf,  w = Ki,
  is linear in (Tf, u, v, w) and in a scale factor, so any four target poles are placed exactly by one linear
  solve (:func:`place_filtered_pid`). The integrator gives zero steady-state error to a step reference.
* The loop the PID really closes runs at the control period dt and through the arm: the tilt it commands reaches
  the vessel ``actuation_delay`` later (the arm's trajectory generator and servos). Pole placement on Gp alone
  ignores that lag; the paper's design placed on its printed plant, with the physical plant, has a closed-loop pole
  at +33 rad/s. :func:`design_filtered_pid` therefore places the poles for a family of bandwidths and keeps the
  design whose sampled loop with the delay (:func:`delayed_loop`) decays fastest while keeping the gain and phase
  margins the spec asks for (:class:`controllers.pid_spec.PidDesignSpec`; by default the usual robustness floor),
  verified with python-control.
* The PID reads theta1 through a low-pass (:func:`measurement_filter`) that passes the first slosh mode and stops
  the liquid's own faster motion (a weakly compressible liquid's acoustic modes, the particles' passage), which
  the derivative term would otherwise pass to the tilt. Its phase lag at omega1 is part of the loop the design
  searches (:func:`loop_chain`), so the margins hold with it.
* :class:`DiscretePid` runs that compensator at the control rate: forward-Euler integrator, backward-Euler
  derivative filter acting on the measurement (no derivative kick), output and output-rate limits, and
  back-calculation anti-windup. :meth:`PidGains.discrete_tf` is its exact z-domain transfer function.
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from controllers.checks import check_range
from controllers.errors import ControllerInputError
from controllers.motion import CriticallyDampedSmoother
from controllers.pid_spec import PidDesignSpec
from controllers.slosh import SloshModel

if TYPE_CHECKING:  # python-control (and scipy) take seconds to load: imported by the functions that use them,
    import control as ct  # so that reading a configuration stays fast

SETTLING_BAND = 0.02  # 2 % band for the settling time reported by the design (python-control's default)
# Relative tolerance between placed and computed closed-loop poles: the design has a double real pole, which
# float64 root finding resolves to about sqrt(machine eps) = 1.5e-8 relative.
POLE_MATCH_RTOL = 1e-6


def ideal_pid_characteristic(model: SloshModel, kp: float, ki: float, kd: float) -> np.ndarray:
    """Coefficients (highest power first) of s (l1 s^2 + g) + (Kd s^2 + Kp s + Ki)(b2 s^2 + g)."""
    g, l1, b2 = model.gravity, model.l1, model.b2
    return np.array([b2 * kd, l1 + b2 * kp, b2 * ki + g * kd, g * (1.0 + kp), g * ki])


def hurwitz_sign_condition(coefficients: np.ndarray) -> bool:
    """Necessary Hurwitz condition: every coefficient nonzero and all of one sign."""
    c = np.asarray(coefficients, dtype=float)
    return bool(np.all(c > 0.0) or np.all(c < 0.0))


@dataclass(frozen=True)
class PidGains:
    """C(s) = kp + ki/s + kd s/(tf s + 1); theta in rad per rad of theta1 error; ki in 1/s, kd and tf in s."""

    kp: float
    ki: float
    kd: float
    tf: float

    def __post_init__(self) -> None:
        for name in ("kp", "ki", "kd"):
            check_range(f"pid.{name}", getattr(self, name))
        check_range("pid.tf", self.tf, 0.0, 10.0, "s", lo_open=True)

    def transfer_function(self) -> ct.TransferFunction:
        """Continuous C(s)."""
        import control as ct

        s = ct.tf("s")
        return self.kp + self.ki / s + self.kd * s / (self.tf * s + 1.0)

    def discrete_tf(self, dt: float) -> ct.TransferFunction:
        """C(z) of :class:`DiscretePid` (unsaturated, derivative on the error), sample time ``dt`` (s).

        kp + ki dt / (z - 1) + kd (z - 1) / ((tf + dt) z - tf).
        """
        import control as ct

        integ = ct.tf([self.ki * dt], [1.0, -1.0], dt)
        deriv = ct.tf([self.kd, -self.kd], [self.tf + dt, -self.tf], dt)
        return ct.tf([self.kp], [1.0], dt) + integ + deriv


BANDWIDTH_RATIOS = np.round(np.arange(3.0, 0.29, -0.1), 1)  # wn / omega1 tried by design_filtered_pid, fastest first
DAMPING_RATIOS = (0.4, 0.55, 0.7)  # zeta tried by design_filtered_pid
SEARCH_PENALTY = 100.0  # 1/s of decay rate per dB (or per 10 deg) of margin short of the spec, in the design search
# The search aims this far inside the margins, so that its numpy estimate (3000 frequencies) clears python-control's
# verification, which the design must pass.
SEARCH_SLACK_DB, SEARCH_SLACK_DEG = 0.1, 1.0
SEARCH_ITERATIONS = 2000  # Nelder-Mead iterations of the design search's refinement


@dataclass(frozen=True)
class PidDesign:
    """A filtered PID for one plant, with its verified closed loop.

    closed_loop_poles: rad/s, from python-control's feedback(C Gp, 1) (continuous, no smoother, no delay).
    min_damping: smallest -Re(p)/|p| over them, and settling_time (s, 2 % band of that closed-loop step response),
    for a placed design (nan for a searched one, which is judged on its sampled loop). With a sample time ``dt``:
    delay_steps, the actuation delay in control periods; discrete_poles, the z-plane poles of :func:`delayed_loop`
    (with the smoother, the delay and the measurement filter, :func:`loop_chain`)
    in unity feedback; decay_rate (1/s), -ln(max |z|) / dt, the slowest closed-loop decay; gain_margin (dB) and
    phase_margin (deg) of that loop (python-control's stability_margins); measurement_cutoff (rad/s, nan: none) and
    measurement, the (numerator, denominator) in z of the filter through which the PID reads theta1
    (:func:`measurement_filter`).
    """

    gains: PidGains
    model: SloshModel
    target_poles: np.ndarray
    closed_loop_poles: np.ndarray
    min_damping: float
    settling_time: float
    dt: float | None
    discrete_poles: np.ndarray | None
    delay_steps: int = 0
    decay_rate: float = math.nan
    gain_margin: float = math.nan
    phase_margin: float = math.nan
    measurement_cutoff: float = math.nan
    measurement: Coefficients | None = None

    def closed_loop(self) -> ct.TransferFunction:
        """theta1 / r of the continuous loop."""
        import control as ct

        return ct.feedback(self.gains.transfer_function() * self.model.plant(), 1)


def sampled_plant(model: SloshModel, dt: float) -> ct.TransferFunction:
    """Gp as the controller sees it at sample time ``dt`` (s): the tilt command is held over each period (zero-order
    hold) and theta1 is measured just before the next command, so Gp's direct feed-through b2/l1 acts one sample
    late: Gz = (ZOH(Gp) - b2/l1) + (b2/l1) z^-1."""
    import control as ct

    zoh = ct.c2d(model.plant(), dt, "zoh")
    num, den = np.asarray(zoh.num[0][0], dtype=float), np.asarray(zoh.den[0][0], dtype=float)
    d = model.b2 / model.l1
    strictly_proper = (num - d * den)[1:]  # the z^2 coefficient of N - d D is zero: N's leading one is d D's
    return ct.tf(np.polyadd(np.polymul(strictly_proper, [1.0, 0.0]), d * den), np.polymul(den, [1.0, 0.0]), dt)


def _pole_mismatch(poles: np.ndarray, target: np.ndarray) -> float:
    """Largest distance from each target pole to its nearest unused computed pole."""
    left = list(poles)
    worst = 0.0
    for p in target:
        i = int(np.argmin([abs(q - p) for q in left]))
        worst = max(worst, abs(left.pop(i) - p))
    return worst


Coefficients = tuple[list[float], list[float]]  # (numerator, denominator) in z, highest power first


def actuator(spec: PidDesignSpec, dt: float) -> Coefficients:
    """The chain from the PID's output to the vessel's tilt at sample time ``dt`` (s): the smoother's F(z)
    (:class:`controllers.motion.CriticallyDampedSmoother`) times z^-n, n = the actuation delay in whole periods."""
    num, den = CriticallyDampedSmoother(spec.smoothing_bandwidth, dt).transfer_function_coefficients()
    return num, list(np.polymul(den, [1.0] + [0.0] * delay_steps_of(spec, dt)))


def measurement_cutoff(spec: PidDesignSpec, model: SloshModel) -> float:
    """rad/s, the measurement filter's cut-off: the geometric mean sqrt(omega1 w_n) of the first slosh mode and the
    lower edge w_n of the measurement's noise band (``spec.noise_frequency``); nan without a filter. On a log
    frequency scale it lies midway, so the filter's relative distance to the mode it must pass (which sets its phase
    lag there) equals its relative distance to the band it must stop (which sets its attenuation there)."""
    if spec.noise_frequency is None:
        return math.nan
    if not spec.noise_frequency > model.omega1:
        raise ControllerInputError(f"pid.noise_frequency: must be above the slosh frequency omega1 = {model.omega1:.4g} "
                                   f"rad/s, got {spec.noise_frequency:g} rad/s")
    return math.sqrt(model.omega1 * spec.noise_frequency)


def measurement_filter(spec: PidDesignSpec, model: SloshModel, dt: float) -> ct.TransferFunction:
    """M(z), the filter through which the PID reads theta1 at sample time ``dt`` (s): the second-order Butterworth
    low-pass M(s) = wc^2 / (s^2 + sqrt(2) wc s + wc^2) at wc = :func:`measurement_cutoff`, by the bilinear transform
    prewarped at wc (so its -3 dB point stays at wc, and its double zero at z = -1 stops the Nyquist frequency
    entirely); 1 without a filter. Unit DC gain: a steady theta1 is read as it is."""
    import control as ct

    wc = measurement_cutoff(spec, model)
    if math.isnan(wc):
        return ct.tf([1.0], [1.0], dt)
    if not wc < 0.5 * math.pi / dt:
        raise ControllerInputError(f"pid.noise_frequency: the measurement filter's cut-off {wc:.4g} rad/s must stay under "
                                   f"half the Nyquist frequency {math.pi / dt:.4g} rad/s of the control rate")
    return ct.c2d(ct.tf([wc * wc], [1.0, math.sqrt(2.0) * wc, wc * wc]), dt, "tustin", prewarp_frequency=wc)


def coefficients(tf: ct.TransferFunction) -> Coefficients:
    """(numerator, denominator) of a SISO transfer function, highest power first."""
    return list(np.asarray(tf.num[0][0], dtype=float)), list(np.asarray(tf.den[0][0], dtype=float))


def loop_chain(spec: PidDesignSpec, model: SloshModel, dt: float) -> Coefficients:
    """Everything the loop holds besides the PID and the plant, at sample time ``dt`` (s): the :func:`actuator` chain
    (smoother, delay) times the :func:`measurement_filter`. In the loop's product their order does not matter."""
    num, den = actuator(spec, dt)
    m_num, m_den = coefficients(measurement_filter(spec, model, dt))
    return list(np.polymul(num, m_num)), list(np.polymul(den, m_den))


def delay_steps_of(spec: PidDesignSpec, dt: float) -> int:
    """The actuation delay in whole control periods, rounded up."""
    return math.ceil(spec.actuation_delay / dt - 1e-9)


def delayed_loop(gains: PidGains, model: SloshModel, dt: float, chain: Coefficients) -> ct.TransferFunction:
    """The open loop C(z) A(z) Gz(z) the controller closes at sample time ``dt`` (s), A the ``chain``
    (:func:`loop_chain`: the actuation and the measurement filter)."""
    import control as ct

    return gains.discrete_tf(dt) * sampled_plant(model, dt) * ct.tf(chain[0], chain[1], dt)


def place_filtered_pid(model: SloshModel, target: np.ndarray) -> PidGains | None:
    """The filtered PID whose continuous closed loop with Gp has exactly the four poles ``target`` (rad/s) (module
    docstring); None when that needs a derivative filter outside (0, 10] s."""
    g, l1, b2 = model.gravity, model.l1, model.b2
    c = model.damping_coefficient
    _, c3, c2, c1, c0 = np.real(np.poly(target))
    # Unknowns (Tf, u, v, w, k): characteristic polynomial (with Gp's damping term c) = k * monic target polynomial.
    m = np.array(
        [
            [l1, b2, 0.0, 0.0, -1.0],
            [c, c, b2, 0.0, -c3],
            [g, g, c, b2, -c2],
            [0.0, 0.0, g, c, -c1],
            [0.0, 0.0, 0.0, g, -c0],
        ]
    )
    tf, u, v, w, _ = np.linalg.solve(m, np.array([0.0, -l1, -c, -g, 0.0]))
    if not 0.0 < tf <= 10.0:
        return None
    kp = v - w * tf
    return PidGains(kp=float(kp), ki=float(w), kd=float(u - kp * tf), tf=float(tf))


def delayed_loop_figures(gains: PidGains, model: SloshModel, dt: float, chain: Coefficients) -> tuple[float, float, float]:
    """(decay rate 1/s, gain margin dB, phase margin deg) of :func:`delayed_loop` in unity feedback: -ln(max |z|)/dt
    over the closed-loop poles (-inf if unstable); the margins from python-control's crossings as distances from
    the critical point: the gain margin closest to 0 dB (up or down) over every phase crossover, the phase margin
    closest to 0 over every gain crossover (inf where the loop has none)."""
    import control as ct

    loop = delayed_loop(gains, model, dt, chain)
    radius = float(np.max(np.abs(ct.poles(ct.feedback(loop, 1)))))
    if radius >= 1.0:
        return -math.inf, -math.inf, -math.inf
    with warnings.catch_warnings():
        # With the slosh-angle filter the loop's order makes python-control fall back from its polynomial crossings to
        # the frequency response, and say so: that fallback is what 'best' means, not a fault for the user to see.
        warnings.filterwarnings("ignore", message="stability_margins: Falling back", category=UserWarning)
        gms, pms, *_ = ct.stability_margins(loop, returnall=True)
    gm_db = min((abs(20.0 * math.log10(g)) for g in np.atleast_1d(gms) if g > 0.0 and math.isfinite(g)), default=math.inf)
    pm = min((abs(float(p)) for p in np.atleast_1d(pms) if math.isfinite(p)), default=math.inf)
    return -math.log(radius) / dt, gm_db, pm


def _fast_loop_figures(gains: PidGains, plant: tuple[np.ndarray, np.ndarray], dt: float, chain: Coefficients,
                       frequencies: np.ndarray) -> tuple[float, float, float]:
    """:func:`delayed_loop_figures` in numpy, for the design search: closed-loop roots of den + num, and the margins
    from the loop's response at ``frequencies`` (rad/sample) as python-control defines them (the gain margin closest
    to 0 dB, up or down, over every phase crossover; the smallest phase margin over every gain crossover)."""
    k, t = gains, dt
    c_num = np.polyadd(np.polyadd(np.polymul([k.kp], np.polymul([1.0, -1.0], [k.tf + t, -k.tf])),
                                  np.polymul([k.ki * t], [k.tf + t, -k.tf])), np.polymul([k.kd, -k.kd], [1.0, -1.0]))
    c_den = np.polymul([1.0, -1.0], [k.tf + t, -k.tf])
    num = np.polymul(np.polymul(c_num, plant[0]), chain[0])
    den = np.polymul(np.polymul(c_den, plant[1]), chain[1])
    radius = float(np.max(np.abs(np.roots(np.polyadd(den, num)))))
    if not radius < 1.0:
        return -math.inf, -math.inf, -math.inf
    z = np.exp(1j * frequencies)
    response = np.polyval(num, z) / np.polyval(den, z)
    magnitude = np.abs(response)
    from_half_turn = np.mod(np.angle(response), 2.0 * math.pi) - math.pi  # phase + pi, wrapped into [-pi, pi)
    gm = min((abs(20.0 * math.log10(magnitude[i])) for i in _crossings(from_half_turn)), default=math.inf)
    pm = min((abs(math.degrees(from_half_turn[i])) for i in _crossings(magnitude - 1.0)), default=math.inf)
    return -math.log(radius) / dt, gm, pm


def _crossings(values: np.ndarray) -> np.ndarray:
    """Indices i where ``values`` changes sign between i and i + 1 (the jumps of a wrapped phase excluded)."""
    change = np.sign(values[:-1]) != np.sign(values[1:])
    return np.flatnonzero(change & (np.abs(values[1:] - values[:-1]) < math.pi))


def _search(model: SloshModel, spec: PidDesignSpec, dt: float, chain: Coefficients) -> tuple[PidGains, np.ndarray]:
    """The gains whose delayed sampled loop decays fastest within the spec's margins: the best pole placement over
    the damping and bandwidth grid, refined by Nelder-Mead on (kp, ki, kd, ln tf) with the margins as penalties.
    Returns the gains and the placement's target poles it started from."""
    import scipy.optimize

    zoh = sampled_plant(model, dt)
    plant = (np.asarray(zoh.num[0][0], dtype=float), np.asarray(zoh.den[0][0], dtype=float))
    frequencies = np.linspace(1e-4, math.pi, 3000)

    def score(gains: PidGains) -> float:
        decay, gm, pm = _fast_loop_figures(gains, plant, dt, chain, frequencies)
        shortfall = (max(spec.min_gain_margin + SEARCH_SLACK_DB - gm, 0.0)
                     + max(spec.min_phase_margin + SEARCH_SLACK_DEG - pm, 0.0) / 10.0)
        return -decay + SEARCH_PENALTY * shortfall if math.isfinite(decay) else math.inf

    start = None
    for zeta in DAMPING_RATIOS if spec.damping is None else (spec.damping,):
        for r in BANDWIDTH_RATIOS if spec.bandwidth_ratio is None else (spec.bandwidth_ratio,):
            target = spec.target_poles(model.omega1, zeta, float(r))
            gains = place_filtered_pid(model, target)
            if gains is not None and (start is None or score(gains) < start[0]):
                start = (score(gains), gains, target)
    if start is None or not math.isfinite(start[0]):
        raise ControllerInputError(
            f"pid: no stable design with an actuation delay of {spec.actuation_delay:g} s at {1.0 / dt:g} Hz"
        )

    def objective(x: np.ndarray) -> float:
        tf = math.exp(x[3])
        return score(PidGains(float(x[0]), float(x[1]), float(x[2]), tf)) if 0.0 < tf <= 10.0 else math.inf

    g0 = start[1]
    result = scipy.optimize.minimize(objective, np.array([g0.kp, g0.ki, g0.kd, math.log(g0.tf)]), method="Nelder-Mead",
                                     options={"xatol": 1e-6, "fatol": 1e-6, "maxiter": SEARCH_ITERATIONS})
    x = result.x if result.fun < start[0] else np.array([g0.kp, g0.ki, g0.kd, math.log(g0.tf)])
    return PidGains(float(x[0]), float(x[1]), float(x[2]), math.exp(x[3])), start[2]


@functools.lru_cache(maxsize=64)
def design_filtered_pid(model: SloshModel, spec: PidDesignSpec = PidDesignSpec(), dt: float | None = None) -> PidDesign:
    """A filtered PID for ``model``, verified with python-control.

    With ``spec.damping`` and ``spec.bandwidth_ratio`` both set (or no sample time ``dt``): the closed-loop poles of
    C Gp placed exactly at the spec's targets. Otherwise, with ``dt`` (s): the design whose sampled loop with the
    actuation delay (:func:`delayed_loop`) decays fastest within the spec's margins (:func:`_search`). Raises
    :class:`ControllerInputError` if the placement needs a derivative filter outside (0, 10] s, if python-control
    finds a placed pole off its target or any in the right half-plane, or if the sampled loop with the delay is
    unstable or (searched) short of the margins.
    """
    import control as ct

    searched = dt is not None and (spec.damping is None or spec.bandwidth_ratio is None)
    if dt is not None:
        check_range("control_rate period", dt, 0.0, 0.1, "s", lo_open=True)
    delay_steps = delay_steps_of(spec, dt) if dt is not None else 0
    chain = loop_chain(spec, model, dt) if dt is not None else None
    if searched:
        gains, target = _search(model, spec, dt, chain)
    else:
        target = spec.target_poles(model.omega1, spec.damping or 0.7, spec.bandwidth_ratio or 1.0)
        gains = place_filtered_pid(model, target)
        if gains is None:
            raise ControllerInputError(f"pid: the poles {target} need a derivative filter outside (0, 10] s")

    loop = ct.feedback(gains.transfer_function() * model.plant(), 1)
    poles = np.sort_complex(ct.poles(loop))
    min_damping = settling = math.nan
    if not searched:  # the placed continuous loop is the design; a searched one is judged on its sampled loop below
        if poles.size != 4 or _pole_mismatch(poles, target) > POLE_MATCH_RTOL * float(np.max(np.abs(target))):
            raise ControllerInputError(f"pid: closed-loop poles {poles} differ from the targets {target}")
        if np.max(poles.real) >= 0.0:
            raise ControllerInputError(f"pid: closed loop is unstable, poles {poles}")
        min_damping = float(np.min(-poles.real / np.abs(poles)))
        horizon = np.linspace(0.0, 20.0 / float(np.min(-poles.real)), 4001)
        settling = float(ct.step_info(loop, T=horizon, SettlingTimeThreshold=SETTLING_BAND)["SettlingTime"])
    if dt is None:
        return PidDesign(gains, model, target, poles, min_damping, settling, dt, None)

    dpoles = ct.poles(ct.feedback(delayed_loop(gains, model, dt, chain), 1))
    decay, gm_db, pm = delayed_loop_figures(gains, model, dt, chain)
    if np.max(np.abs(dpoles)) >= 1.0:
        raise ControllerInputError(
            f"control_rate: {1.0 / dt:g} Hz with an actuation delay of {spec.actuation_delay:g} s is too slow for the "
            f"PID (Tf = {gains.tf:.4g} s); sampled loop unstable"
        )
    if searched and (gm_db < spec.min_gain_margin or pm < spec.min_phase_margin):
        raise ControllerInputError(
            f"pid: no design reaches {spec.min_gain_margin:g} dB and {spec.min_phase_margin:g} deg of margin with an "
            f"actuation delay of {spec.actuation_delay:g} s at {1.0 / dt:g} Hz (best: {gm_db:.2f} dB, {pm:.1f} deg)"
        )
    return PidDesign(gains, model, target, poles, min_damping, settling, dt, dpoles, delay_steps, decay, gm_db, pm,
                     measurement_cutoff(spec, model), coefficients(measurement_filter(spec, model, dt)))


class DiscretePid:
    """The filtered PID at a fixed sample time, with output limits, a rate limit and anti-windup.

    u_k = kp e_k + I_k + D_k, e_k = r_k - y_k;
    D_k = tf/(tf+dt) D_{k-1} - kd/(tf+dt) (y_k - y_{k-1})      (derivative of -y, filtered);
    u_k is clipped to [u_min, u_max] and to u_{k-1} +- rate_max dt;
    I_{k+1} = I_k + dt (ki e_k + (u_k - u_unclipped) / t_track)  (back-calculation, t_track = sqrt(kd/ki)).
    Units: r, y in rad (theta1), u in rad (tilt), dt in s, rate_max in rad/s.
    """

    def __init__(self, gains: PidGains, dt: float, u_min: float, u_max: float, rate_max: float) -> None:
        check_range("pid dt", dt, 0.0, 0.1, "s", lo_open=True)
        if not u_min < u_max:
            raise ControllerInputError(f"pid output limits: need u_min < u_max, got [{u_min:g}, {u_max:g}]")
        check_range("pid rate_max", rate_max, 0.0, None, "rad/s", lo_open=True)
        if not gains.ki > 0.0:
            raise ControllerInputError(f"pid.ki: must be > 0 for anti-windup tracking, got {gains.ki:g}")
        self.gains, self.dt = gains, dt
        self.u_min, self.u_max, self.rate_max = u_min, u_max, rate_max
        self.t_track = max(math.sqrt(max(gains.kd, 0.0) / gains.ki), dt)
        self.reset(u0=0.0, y0=0.0, r0=0.0)

    def reset(self, u0: float, y0: float, r0: float, y_rate: float = 0.0, u_rate: float = 0.0) -> None:
        """Bumpless start in value and rate: the next :meth:`step` with (r0, y0) outputs exactly ``u0``, and the one
        after it, with the reference unchanged and the measurement moved on at ``y_rate`` (rad/s), ``u0 + u_rate dt``
        (within the limits). The integral I and the derivative's filter state D are solved for those two outputs:
        with a = tf / (tf + dt), b = kd / (tf + dt), e = r0 - y0 and the measurement's last value y0 - y_rate dt,
        D1 = a D - b y_rate dt and u0 = kp e + I + D1; the second output's change kp (-y_rate dt) + dt ki e + (a - 1) D1
        - b y_rate dt = u_rate dt gives D1 = -(tf + dt) (u_rate + (kp + b) y_rate - ki e).
        Only the controller's initial state is chosen: its dynamics, and so the loop's design, are unchanged; D's
        departure from its steady value decays with the derivative filter's time constant tf."""
        k, dt = self.gains, self.dt
        e, b = r0 - y0, k.kd / (k.tf + dt)
        d1 = -(k.tf + dt) * (u_rate + (k.kp + b) * y_rate - k.ki * e)
        self._deriv = (d1 + b * y_rate * dt) * (k.tf + dt) / k.tf
        self._integral = u0 - k.kp * e - d1
        self._y_prev = y0 - y_rate * dt
        self._u_prev = u0

    def step(self, r: float, y: float) -> float:
        """One sample: reference ``r``, measurement ``y``; returns the limited output."""
        k, dt = self.gains, self.dt
        e = r - y
        self._deriv = (k.tf * self._deriv - k.kd * (y - self._y_prev)) / (k.tf + dt)
        u_raw = k.kp * e + self._integral + self._deriv
        lo = max(self.u_min, self._u_prev - self.rate_max * dt)
        hi = min(self.u_max, self._u_prev + self.rate_max * dt)
        u = min(max(u_raw, lo), hi)
        self._integral += dt * (k.ki * e + (u - u_raw) / self.t_track)
        self._y_prev, self._u_prev = y, u
        return u
