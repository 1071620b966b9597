"""PID compensator for the slosh plant Gp (seed Sec. 3.1, Eq. 15; Figs. 8, 14, 15).

Loop: unity negative feedback, theta = C(s) (r - theta1), theta1 = Gp(s) theta, with Gp from
:meth:`controllers.slosh.SloshModel.plant` (sign convention there: DC gain +1).

* The seed's ideal PID C = (Kd s^2 + Kp s + Ki)/s cannot stabilise Gp: the closed-loop characteristic
  polynomial (:func:`ideal_pid_characteristic`) is
      b2 Kd s^4 + (l1 + b2 Kp) s^3 + (b2 Ki + g Kd) s^2 + g (1 + Kp) s + g Ki
  and with b2 < 0 its s^4, s^2 and s^0 coefficients can never share one sign (Hurwitz necessary condition).
* A derivative filter, C = Kp + Ki/s + Kd s/(Tf s + 1), removes the conflict. Its closed-loop polynomial
      [Tf l1 + b2 u] s^4 + [l1 + b2 v] s^3 + [Tf g + b2 w + g u] s^2 + [g + g v] s + g w,
      u = Kp Tf + Kd,  v = Kp + Ki Tf,  w = Ki,
  is linear in (Tf, u, v, w) and in a scale factor, so any four target poles are placed exactly by one linear
  solve (:func:`design_filtered_pid`). The integrator gives zero steady-state error to a step reference.
* :class:`DiscretePid` runs that compensator at the control rate: forward-Euler integrator, backward-Euler
  derivative filter acting on the measurement (no derivative kick), output and output-rate limits, and
  back-calculation anti-windup. :meth:`PidGains.discrete_tf` is its exact z-domain transfer function.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from controllers.checks import check_range
from controllers.errors import ControllerInputError
from controllers.slosh import SloshModel

if TYPE_CHECKING:  # python-control (and scipy) take seconds to load: imported by the functions that build
    import control as ct  # transfer functions, so that reading a configuration stays fast

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


@dataclass(frozen=True)
class PidDesignSpec:
    """Closed-loop target: poles of (s^2 + 2 zeta wn s + wn^2)(s + wn)^2 with wn = bandwidth_ratio * omega1.

    damping: zeta of the complex pair, [0.3, 0.95] (1 would make a fourfold pole, which floating point cannot
      verify to better than 1e-4).
    bandwidth_ratio: wn / omega1, [0.3, 3].

    The defaults (zeta = 0.7, wn = omega1) give the seed's vessel a sensitivity peak Ms = 1.29, a 0.65 s
    settling time and a derivative filter Tf = 27 ms, which a 100 Hz loop resolves (see the report figures).
    """

    damping: float = 0.7
    bandwidth_ratio: float = 1.0

    def __post_init__(self) -> None:
        check_range("pid.damping", self.damping, 0.3, 0.95)
        check_range("pid.bandwidth_ratio", self.bandwidth_ratio, 0.3, 3.0)

    def target_poles(self, omega1: float) -> np.ndarray:
        wn = self.bandwidth_ratio * omega1
        wd = wn * math.sqrt(1.0 - self.damping**2)
        sr = -self.damping * wn
        return np.array([complex(sr, wd), complex(sr, -wd), -wn, -wn])


@dataclass(frozen=True)
class PidDesign:
    """A filtered PID for one plant, with its verified closed loop.

    closed_loop_poles: rad/s, from python-control's feedback(C Gp, 1). min_damping: smallest -Re(p)/|p| over
    them. settling_time: s, 2 % band of the closed-loop step response. discrete_poles: z-plane poles of the
    loop with :meth:`PidGains.discrete_tf` on :func:`sampled_plant`, when a sample time was given.
    """

    gains: PidGains
    model: SloshModel
    target_poles: np.ndarray
    closed_loop_poles: np.ndarray
    min_damping: float
    settling_time: float
    dt: float | None
    discrete_poles: np.ndarray | None

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


def design_filtered_pid(model: SloshModel, spec: PidDesignSpec = PidDesignSpec(), dt: float | None = None) -> PidDesign:
    """Place the closed-loop poles of C Gp exactly at ``spec``'s targets and verify the result.

    Raises :class:`ControllerInputError` if the placement needs a derivative filter outside (0, 10] s
    (:class:`PidGains`), if python-control finds a closed-loop pole off the target or in the right half-plane,
    or (with ``dt`` in s) if the sampled loop is not stable at that control period.
    """
    import control as ct

    g, l1, b2 = model.gravity, model.l1, model.b2
    target = spec.target_poles(model.omega1)
    _, c3, c2, c1, c0 = np.real(np.poly(target))
    # Unknowns (Tf, u, v, w, k): characteristic polynomial = k * monic target polynomial.
    m = np.array(
        [
            [l1, b2, 0.0, 0.0, -1.0],
            [0.0, 0.0, b2, 0.0, -c3],
            [g, g, 0.0, b2, -c2],
            [0.0, 0.0, g, 0.0, -c1],
            [0.0, 0.0, 0.0, g, -c0],
        ]
    )
    tf, u, v, w, _ = np.linalg.solve(m, np.array([0.0, -l1, 0.0, -g, 0.0]))
    ki = w
    kp = v - ki * tf
    gains = PidGains(kp=float(kp), ki=float(ki), kd=float(u - kp * tf), tf=float(tf))

    loop = ct.feedback(gains.transfer_function() * model.plant(), 1)
    poles = np.sort_complex(ct.poles(loop))
    if poles.size != 4 or _pole_mismatch(poles, target) > POLE_MATCH_RTOL * float(np.max(np.abs(target))):
        raise ControllerInputError(f"pid: closed-loop poles {poles} differ from the targets {target}")
    if np.max(poles.real) >= 0.0:
        raise ControllerInputError(f"pid: closed loop is unstable, poles {poles}")
    min_damping = float(np.min(-poles.real / np.abs(poles)))
    horizon = np.linspace(0.0, 20.0 / float(np.min(-poles.real)), 4001)
    settling = float(ct.step_info(loop, T=horizon, SettlingTimeThreshold=SETTLING_BAND)["SettlingTime"])

    dpoles = None
    if dt is not None:
        check_range("control_rate period", dt, 0.0, 0.1, "s", lo_open=True)
        dpoles = ct.poles(ct.feedback(gains.discrete_tf(dt) * sampled_plant(model, dt), 1))
        if np.max(np.abs(dpoles)) >= 1.0:
            raise ControllerInputError(
                f"control_rate: {1.0 / dt:g} Hz is too slow for the PID (Tf = {tf:.4g} s); sampled loop unstable"
            )
    return PidDesign(gains, model, target, poles, min_damping, settling, dt, dpoles)


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

    def reset(self, u0: float, y0: float, r0: float) -> None:
        """Bumpless start: the next :meth:`step` with (r0, y0) outputs exactly ``u0``."""
        self._integral = u0 - self.gains.kp * (r0 - y0)
        self._deriv = 0.0
        self._y_prev = y0
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
