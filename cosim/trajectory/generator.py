"""Online joint trajectory generation for one arm: smooth on the target stream, ruckig (community build) to catch up.

The coupling streams inverse-kinematics joint targets at the control rate (:meth:`TrajectoryGenerator.set_target`,
every ``T`` = 10 ms) and advances the generator once per MuJoCo step (:meth:`TrajectoryGenerator.step`, 2 ms), sending
the returned state ``(q, qd, qdd)`` (rad, rad/s, rad/s^2, arrays of the arm's joints, base to tip) to the arm's servos.

How the stream is followed. The path is the uniform cubic B-spline whose control points are the targets, spaced
``T`` (de Boor, A Practical Guide to Splines, 1978). When target ``P_k`` arrives, the arm plays the segment of
``P_{k-3} .. P_k`` over the next ``T``: from the knot state ``((P_{k-3} + 4 P_{k-2} + P_{k-1}) / 6,
(P_{k-1} - P_{k-3}) / 2T, (P_{k-3} - 2 P_{k-2} + P_{k-1}) / T^2)`` to the next one. Consecutive segments join with
equal position, velocity and acceleration (the spline is C2), the acceleration is linear and the jerk
``(P_k - 3 P_{k-1} + 3 P_{k-2} - P_{k-3}) / T^3`` constant over each segment: the jerk changes sign only where the
stream's third difference does, so a smooth stream gives a smooth motion. The spline is what a robotics engineer
writes through waypoints by hand; it is also a mild low-pass of the stream (gain ``sinc^4(f T)``: 0.94 at 10 Hz,
0.66 at 25 Hz). Its price is a delay: the knot states sit at the targets of :data:`STREAM_DELAY_PERIODS` periods
before (exactly for a stream moving at constant velocity; a stream accelerating at ``a`` is cut inside by
``a T^2 / 6``, 4e-5 rad at 2.5 rad/s^2). A caller that knows its targets ahead (:mod:`cosim.trajectory.scripted`)
sends them that much early; the coupling's targets are its task-space filter's poses for one period ahead.

The re-planned ruckig profiles this replaces kept the jerk at its limit in short pulses of either sign on most
samples even on an in-limit 2 Hz sinusoid (their phases use the limit jerk or none): a chatter of the acceleration at
the control rate, not a motion.

Limits hold by construction. The segment's velocity is a quadratic B-spline with control points ``dP / T``, its
acceleration the line between the ``d^2 P / T^2``, its jerk ``d^3 P / T^3``: each within the hull of those
differences, its positions within the hull of the (clamped) targets. A segment is played only when these differences
are within ``max_velocity``, ``max_acceleration`` and ``max_jerk``, its end state is admissible (below), the arm is on
the spline (its state equals the segment's start within :data:`SPLINE_TOLERANCE`) and the target came one period after
the last. Otherwise ruckig takes the arm toward the segment's end state (extrapolated at constant acceleration beyond
it), with

* ``minimum_duration`` = the horizon ``H``, so the arm arrives when the path does instead of early, waiting;
* time synchronisation: every joint arrives together, along the joint-space path;
* ``H`` = ``T`` when that end state is reachable within the limits, and the arm is then on the spline again; when
  it has fallen behind (a stream that starts moving abruptly, a step in its acceleration), the shortest horizon at
  which ruckig can meet the extrapolated path, found by bisection on ruckig's duration (to one cycle, at most
  :data:`MAX_HORIZON`): the arm catches up time-optimally and re-plans at every target (a 0.5 rad/s ramp started
  from rest is caught in 0.35 s). :attr:`TrajectoryGenerator.late_targets` and
  :attr:`TrajectoryGenerator.max_target_error` tell when the arm was behind the path.

A stream that needs more than the limits (a joint speed or acceleration above its limit, or a velocity step that keeps
the arm behind for longer than :data:`MAX_HORIZON`) is left through extrapolations of the path that are far off it,
and the vessel cuts across by centimetres (tilt 0.3 sin(3.2 t) about the vessel bottom from rest: 45 mm; the same tilt
through a jerk-limited filter, 1.5 rad/s, 2.5 rad/s^2, 40 rad/s^3: 0.5 mm; ``tests/test_trajectory_generation.py``).
Feed it paths within the limits, smoothed in the controller's own coordinates (tilt angle, catcher position).

Admissible states. ruckig keeps velocity, acceleration and jerk within the limits between two admissible states, but
it accepts a target state from which no jerk-limited motion can continue within them: at ``v`` with acceleration
``a`` (same sign), bringing ``a`` to zero at the jerk limit ``j`` adds ``a |a| / (2 j)`` to the velocity. Arriving at
``v = max_velocity`` with ``a > 0`` (a path clipped to the limit while still accelerating), the next plan starts from
a state that must overshoot by ``a^2 / (2 j)`` (1e-4 rad/s for 0.15 rad/s^2 at 100 rad/s^3). So every ruckig target
state is made admissible, ``|a| <= sqrt(2 j (max_velocity -+ v))`` (:func:`_admissible_acceleration`), a spline
segment is played only when it ends in such a state, and the arm's state stays one from which the limits can be held.

A path the arm cannot follow within its velocity limit (the spline segment's peak speed, exactly, or a given target
velocity above ``max_velocity``) is clipped to the limit and the arm falls behind; with
:attr:`GeneratorSettings.stop_beyond_velocity_limit` (the arms' generators in a pour)
:meth:`TrajectoryGenerator.set_target` raises :class:`UntrackablePathError` at the first such target instead, naming
arm, joint, time and limit, so a run never continues on a path it cannot follow.

ruckig's community build ignores position limits, so targets outside the joint range are clamped onto it (that joint
then at rest) and counted in :attr:`clamped_targets`, and a joint whose time-optimal stop (plus one target interval of
travel) would end beyond its range is sent to rest on the boundary, so the motion itself stays in range.

Stopping is jerk-limited too: :meth:`hold` brakes to rest wherever the arm gets to (ruckig's velocity interface);
``set_target(q, zeros, zeros)`` stops at ``q`` with ruckig (a target with its velocity and acceleration given is the
path's state now, not a stream point; for ``q`` = the current position the arm comes back to it). If no new target
arrives after the last segment or target is reached while the path was moving, the generator holds by itself instead
of extrapolating the path's motion.

Timing: the generator's clock :attr:`time` starts at 0 and advances by ``cycle_time`` per :meth:`step`;
``step()`` returns the state at the new time, the end of the MuJoCo step about to be taken (what a real arm's servo
interface, e.g. UR ``servoj``, expects: the set-point to reach by the end of the cycle). :meth:`state_at` evaluates
the exact motion at any time inside the last step, for sampling at rates other than the cycle rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import ruckig

from cosim.errors import InputError, SimulationError
from cosim.trajectory.limits import ArmLimits
from declared_settings.setting import check_settings, documented, setting

# Times closer than this (s) count as equal when matching sample times to generator steps: far below any cycle time,
# far above the round-off of summing cycle times over an hour.
TIME_EPSILON = 1e-9
# s: longest look-ahead when intercepting a target path the arm has fallen behind; beyond it the extrapolation is too
# far off the path (the generator then heads for the path's state this far ahead and re-plans at the next target).
# Chosen on paths beyond the limits (a rate-limited tilt at 2 rad/s and 5 rad/s^2, the SIM excitation): of 0.1, 0.2,
# 0.3 and 1 s, 0.3 s kept the vessel closest to them; the effect is erratic, such paths need smoothing upstream.
MAX_HORIZON = 0.3
# rad: the arm is on the spline path when its position, velocity x period and acceleration x period^2 differ from the
# spline's by at most this: round-off of the knot formulas and of ruckig landing on a spline state (~1e-15 rad), far
# below a path step (a joint at 0.01 rad/s moves 1e-4 rad per period).
SPLINE_TOLERANCE = 1e-9
# Periods by which the arm follows its target stream late: a segment played from the arrival of P_k ends on the knot of
# P_{k-1} (the module docstring).
STREAM_DELAY_PERIODS = 2


GENERATOR = "trajectory generator"


@documented
@dataclass(frozen=True)
class GeneratorSettings:
    """The generator's timing and what it does with a path it cannot follow."""

    cycle_time: float = setting(0.002, GENERATOR, "The generator's step (the MuJoCo time step).", "s", 0.0, 0.1,
                                lo_open=True)
    control_period: float = setting(0.01, GENERATOR, "Expected interval between targets; used as the first target's "
                                    "minimum duration.", "s", "cycle_time", 1.0)
    stop_beyond_velocity_limit: bool = setting(
        False, GENERATOR, "Raise UntrackablePathError when a target path moves a joint faster than its max_velocity (an "
        "arm that must stay on its path); false: clip the path's velocity and catch up (a filter).")

    def __post_init__(self) -> None:
        check_settings(self, "trajectory")


class UntrackablePathError(SimulationError):
    """A target path needs a joint faster than its velocity limit; the message is one line naming arm, joint, time and
    limit."""


def _admissible_acceleration(v: float, a: float, vmax: float, jmax: float) -> float:
    """The acceleration (rad/s^2) of a state at velocity ``v`` (rad/s, within +-``vmax``), reduced so that bringing it
    to zero at the jerk limit ``jmax`` (rad/s^3), which changes the velocity by ``a |a| / (2 jmax)``, ends within
    +-``vmax``: ``a`` unchanged when it does, else ``+-sqrt(2 jmax (vmax -+ v))``."""
    if a > 0.0 and v + a * a / (2.0 * jmax) > vmax:
        return math.sqrt(2.0 * jmax * (vmax - v))
    if a < 0.0 and v - a * a / (2.0 * jmax) < -vmax:
        return -math.sqrt(2.0 * jmax * (vmax + v))
    return a


def _quadratic_derivatives(times: list[float], points: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """First and second derivative at the last time of the interpolating polynomial through up to three points."""
    zero = np.zeros_like(points[-1])
    if len(points) == 1:
        return zero, zero
    if len(points) == 2:
        return (points[1] - points[0]) / (times[1] - times[0]), zero
    (t0, t1, t2), (q0, q1, q2) = times, points
    h1, h2 = t1 - t0, t2 - t1
    qd = q0 * (h2 / (h1 * (h1 + h2))) - q1 * ((h1 + h2) / (h1 * h2)) + q2 * ((h1 + 2.0 * h2) / (h2 * (h1 + h2)))
    qdd = 2.0 * (q0 / (h1 * (h1 + h2)) - q1 / (h1 * h2) + q2 / (h2 * (h1 + h2)))
    return qd, qdd


def _spline_weights(us: list[float]) -> tuple[np.ndarray, ...]:
    """The weights of :func:`_spline_states` at each ``u`` of ``us`` in [0, 1], as columns (len(us), 1), computed per
    ``u`` in floats: the position's basis ``(1-u)^3, 3u^3 - 6u^2 + 4, -3u^3 + 3u^2 + 3u + 1, u^3``, the velocity's
    ``(1-u)^2, 1 + 2u - 2u^2, u^2`` and the acceleration's ``1-u, u``."""
    def column(values) -> np.ndarray:
        return np.array(values)[:, None]

    ws = [1.0 - u for u in us]
    return (column([w * w * w for w in ws]), column([3.0 * u**3 - 6.0 * u * u + 4.0 for u in us]),
            column([1.0 + 3.0 * u + 3.0 * u * u - 3.0 * u**3 for u in us]), column([u**3 for u in us]),
            column([w * w for w in ws]), column([1.0 + 2.0 * u - 2.0 * u * u for u in us]), column([u * u for u in us]),
            column(ws), column(us))


def _spline_states(points: np.ndarray, weights: tuple[np.ndarray, ...], period: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, qd, qdd)``, each (rows, n), at the parameters ``u`` whose :func:`_spline_weights` are ``weights`` of the
    uniform cubic B-spline segment with control points ``points`` (4, n) spaced ``period`` s (de Boor, A Practical
    Guide to Splines, 1978): ``q(u) = sum_i B_i(u) P_i`` with the basis ``B = ((1-u)^3, 3u^3 - 6u^2 + 4, -3u^3 + 3u^2
    + 3u + 1, u^3) / 6``; the velocity, the quadratic B-spline of the differences ``D_i = P_{i+1} - P_i``, ``((1-u)^2
    D_0 + (1 + 2u - 2u^2) D_1 + u^2 D_2) / (2 period)``; the acceleration, the line between the second differences,
    ``((1-u) E_0 + u E_1) / period^2``. Written out term by term (no BLAS, whose kernels round differently) and in
    differences, which keeps the velocity and acceleration within the hull of theirs up to one rounding. The weights
    apply to all rows at once: each entry is the same sequence of roundings as for one ``u``."""
    b0, b1, b2, b3, v0, v1, v2, a0, a1 = weights
    p0, p1, p2, p3 = points
    d0, d1, d2 = p1 - p0, p2 - p1, p3 - p2
    position = (b0 * p0 + b1 * p1 + b2 * p2 + b3 * p3) / 6.0
    velocity = (v0 * d0 + v1 * d1 + v2 * d2) / (2.0 * period)
    acceleration = (a0 * (d1 - d0) + a1 * (d2 - d1)) / (period * period)
    return position, velocity, acceleration


def _spline_state(points: np.ndarray, u: float, period: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, qd, qdd)`` (n,) at ``u`` in [0, 1] of the B-spline segment with control points ``points`` (4, n)
    (:func:`_spline_states`)."""
    return tuple(a[0] for a in _spline_states(points, _spline_weights([u]), period))  # type: ignore[return-value]


def _peak_speed(points: np.ndarray, period: float) -> np.ndarray:
    """(n,) rad/s: the largest speed over the B-spline segment with control points ``points`` (4, n) spaced
    ``period`` s, exactly: its velocity ``(c0 + c1 u + c2 u^2) / (2 period)`` (:func:`_spline_state`) peaks at an end
    or at its vertex ``u = -c1 / (2 c2)`` inside the segment."""
    d0, d1, d2 = np.diff(points, axis=0)
    c0, c1, c2 = d0 + d1, 2.0 * (d1 - d0), d0 - 2.0 * d1 + d2
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = np.where(c2 != 0.0, -c1 / (2.0 * c2), 0.0)
    vertex = np.clip(vertex, 0.0, 1.0)
    speeds = [np.abs(c0 + c1 * u + c2 * u * u) for u in (0.0, 1.0, vertex)]
    return np.max(speeds, axis=0) / (2.0 * period)


def _control_points(q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, period: float) -> list[np.ndarray]:
    """Three control points (spaced ``period`` s) whose B-spline is at ``(q, qd, qdd)`` at the knot after the middle
    one: ``P1 = q - qdd period^2 / 6``, ``P0, P2 = P1 -+ qd period + qdd period^2 / 2`` (inverting
    ``q = (P0 + 4 P1 + P2) / 6``, ``qd = (P2 - P0) / (2 period)``, ``qdd = (P0 - 2 P1 + P2) / period^2``)."""
    middle = q - qdd * period * period / 6.0
    half = 0.5 * qdd * period * period
    return [middle - qd * period + half, middle, middle + qd * period + half]


def _clip(x: float, lo: float, hi: float) -> float:
    """``min(max(x, lo), hi)`` with numpy ``clip``'s tie-breaking (the second argument when neither is larger),
    so a signed zero comes out as numpy's does."""
    x = x if x > lo else lo
    return x if x < hi else hi


def _vector(name: str, value: object, n: int) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name}: must be {n} finite numbers, got {type(value).__name__}") from None
    if array.shape != (n,):
        raise InputError(f"{name}: must be {n} finite numbers, got shape {array.shape}")
    if not np.isfinite(array).all():
        raise InputError(f"{name}: must be {n} finite numbers, got {array.tolist()}")
    return array


class TrajectoryGenerator:
    """Online ruckig trajectory generation for one arm (see the module docstring).

    limits: the arm's :class:`ArmLimits`. q0: (n,) rad, the starting joint positions (at rest); they must lie in the
    joint range. settings: :class:`GeneratorSettings`.
    """

    def __init__(self, limits: ArmLimits, q0: np.ndarray, settings: GeneratorSettings = GeneratorSettings()) -> None:
        self.limits = limits
        self.settings = settings
        n = len(limits.joints)
        self._lo, self._hi = limits.array("min_position"), limits.array("max_position")
        self._vmax, self._amax = limits.array("max_velocity"), limits.array("max_acceleration")
        self._lo_floats, self._hi_floats, self._vmax_floats = self._lo.tolist(), self._hi.tolist(), self._vmax.tolist()
        self._jmax = limits.array("max_jerk")
        self._jmax_floats = self._jmax.tolist()
        period = settings.control_period
        # a spline segment's first, second and third differences of control points within the limits
        # (:meth:`_spline_within_limits`)
        self._step_limits = (self._vmax * period, self._amax * period**2, self._jmax * period**3)
        # first differences within which the segment's speed is below max_velocity (the hull bound, less a margin far
        # beyond the round-off of the exact peak, :func:`_peak_speed`)
        self._trackable_step = self._vmax * period * (1.0 - 1e-9)
        # the spline weights at a segment's start, its end and after each step it may be played for (its parameter u
        # as :meth:`_segment_u` gives it, while below 1): the same for every segment
        played = [1]
        while played[-1] * settings.cycle_time / period < 1.0 - TIME_EPSILON:
            played.append(played[-1] + 1)
        self._segment_weights = _spline_weights([0.0, 1.0] + [k * settings.cycle_time / period for k in played])
        q0 = _vector(f"{limits.arm}: start position", q0, n)
        outside = np.flatnonzero((q0 < self._lo) | (q0 > self._hi))
        if outside.size:
            j = limits.joints[outside[0]]
            raise InputError(
                f"{j.name}: start position {q0[outside[0]]:g} rad is outside [{j.min_position:g}, {j.max_position:g}] rad"
            )
        self._otg = ruckig.Ruckig(n, settings.cycle_time)
        self._input = ruckig.InputParameter(n)
        self._output = ruckig.OutputParameter(n)
        self._probe = ruckig.Ruckig(n)  # time-optimal durations for the interception search
        self._probe_input = ruckig.InputParameter(n)
        self._probe_trajectory = ruckig.Trajectory(n)
        self._brake_input = ruckig.InputParameter(n)  # time-optimal stop of each joint on its own
        for inp in (self._input, self._probe_input, self._brake_input):
            inp.max_velocity = list(self._vmax)
            inp.max_acceleration = list(self._amax)
            inp.max_jerk = list(limits.array("max_jerk"))
            inp.synchronization = ruckig.Synchronization.Time
        self._brake_input.control_interface = ruckig.ControlInterface.Velocity
        self._brake_input.synchronization = ruckig.Synchronization.No
        self._brake_input.target_velocity = [0.0] * n
        self._brake_input.target_acceleration = [0.0] * n
        inp = self._input
        inp.current_position = list(q0)
        inp.current_velocity = [0.0] * n
        inp.current_acceleration = [0.0] * n
        inp.target_position = list(q0)
        inp.target_velocity = [0.0] * n
        inp.target_acceleration = [0.0] * n
        self._steps = 0
        self._state = (q0.copy(), np.zeros(n), np.zeros(n))
        self._path = self._state  # the latest target path state (q, qd, qdd) at its time
        self._path_floats = tuple(a.tolist() for a in self._path)  # the same as lists of floats, for _predict
        self._path_lead = 0.0  # s, how far ahead of now _path lies (a spline segment's end: one period)
        self._points: list[np.ndarray] = []  # the spline path's last control points (at most four)
        self._segment: tuple[np.ndarray, int] | None = None  # (control points (4, n), start step) of a spline segment
        # the segment's (q, qd, qdd), each (rows, n): at its start, its end, then after each of its steps
        self._segment_states: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._unsent_state: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None  # the arm's state not yet in ruckig's input
        self._on_segment = False  # the last step followed the spline segment
        self._history_steps: list[int] = []  # step index of each recent target (at most three)
        self._history_q: list[np.ndarray] = []
        self._new_target = False
        self._finished = True
        self._clamped = np.zeros(n, dtype=int)
        self._late_targets = 0
        self._max_target_error = 0.0

    # ---- inputs ----------------------------------------------------------------------------------------------------
    def set_target(self, q: np.ndarray, qd: np.ndarray | None = None, qdd: np.ndarray | None = None) -> None:
        """Track the joint target ``q`` (n,) rad. Without ``qd`` and ``qdd``: the next point of the target stream,
        followed on the B-spline through the stream (the module docstring). With them (rad/s, rad/s^2, either may be
        ``None`` for the estimate from the recent targets): the path's state now, reached by ruckig (a stop:
        ``set_target(q, zeros, zeros)``). Components outside the joint range are clamped onto it (counted in
        :attr:`clamped_targets`). Takes effect at the next :meth:`step`."""
        n = len(self.limits.joints)
        explicit = qd is not None or qdd is not None
        q = _vector(f"{self.limits.arm}: target position", q, n)
        if self._history_steps and self._history_steps[-1] == self._steps:  # a second target in the same cycle
            self._history_steps.pop()
            self._history_q.pop()
            if self._points:
                self._points.pop()
        if self._history_steps:
            interval = (self._steps - self._history_steps[-1]) * self.settings.cycle_time
        else:
            interval = self.settings.control_period
        clamped = (q < self._lo) | (q > self._hi)
        self._clamped += clamped
        q = q.clip(self._lo, self._hi)  # the array's own clip (np.clip's, without its dispatch)
        self._history_steps = (self._history_steps + [self._steps])[-3:]
        self._history_q = (self._history_q + [q])[-3:]
        if explicit:
            times = [s * self.settings.cycle_time for s in self._history_steps]
            est_qd, est_qdd = _quadratic_derivatives(times, self._history_q)
            qd = est_qd if qd is None else _vector(f"{self.limits.arm}: target velocity", qd, n)
            qdd = est_qdd if qdd is None else _vector(f"{self.limits.arm}: target acceleration", qdd, n)
            if self.settings.stop_beyond_velocity_limit:
                self._check_trackable(qd, clamped)
            self._points, self._segment = [], None
            self._sync_input()
            error = float(np.abs(np.array(self._input.current_position) - q).max())
            self._follow_with_ruckig(q, qd, qdd, clamped, interval, 0.0, error)
            return
        period = self.settings.control_period
        if len(self._points) < 3:  # a new stream: the spline starts from the arm's state
            self._points = _control_points(*self._state, period)
        self._points = self._points[-3:] + [q]
        points = np.array(self._points)
        differences = points[1:] - points[:-1]  # np.diff's own subtraction, without its dispatch
        sizes = np.abs(differences)
        # the segment's speed stays within the hull of the differences / T (:meth:`_spline_within_limits`): within the bound
        # no joint can be above its limit and the exact peak need not be computed
        if self.settings.stop_beyond_velocity_limit and not (sizes <= self._trackable_step).all():
            self._check_trackable(_peak_speed(points, period), clamped)
        states = _spline_states(points, self._segment_weights, period)
        start, end = (tuple(a[i] for a in states) for i in (0, 1))
        error = float(np.abs(self._state[0] - start[0]).max())
        offset = max(error, float(np.abs(self._state[1] - start[1]).max()) * period,
                     float(np.abs(self._state[2] - start[2]).max()) * period * period)
        if offset <= SPLINE_TOLERANCE and abs(interval - period) <= TIME_EPSILON and self._spline_within_limits(points, differences, sizes, end):
            self._max_target_error = max(self._max_target_error, error)
            self._segment = (points, self._steps)
            self._segment_states = states
            inp = self._input
            inp.target_position, inp.target_velocity, inp.target_acceleration = (a.tolist() for a in end)
            self._new_target = True
            return
        self._segment = None
        self._follow_with_ruckig(end[0], end[1], end[2], clamped, interval, period, error)

    def _spline_within_limits(
        self, points: np.ndarray, differences: np.ndarray, sizes: np.ndarray, end: tuple[np.ndarray, np.ndarray, np.ndarray]
    ) -> bool:
        """Whether the B-spline segment with control points ``points`` (4, n) keeps every limit, exactly: its
        velocity is a quadratic B-spline with control points ``dP / T``, its acceleration the line between the
        ``d^2 P / T^2``, its jerk ``d^3 P / T^3`` (``T`` the control period), so each lies within the hull of those
        differences; its positions lie within the hull of the control points, which must lie in the joint range (the
        targets are clamped onto it, the points made from the arm's state may not be). And its end state is
        admissible (:func:`_admissible_acceleration`), so that ruckig can take over from it within the limits.
        ``differences`` (3, n): the points' first differences, ``sizes`` their magnitudes."""
        if ((points < self._lo) | (points > self._hi)).any():  # a state's virtual control points may lie beyond
            return False
        if (sizes > self._step_limits[0]).any():
            return False
        second = differences[1:] - differences[:-1]
        if (np.abs(second) > self._step_limits[1]).any():
            return False
        if (np.abs(second[1:] - second[:-1]) > self._step_limits[2]).any():
            return False
        _, v, a = end
        return all(
            _admissible_acceleration(vj, aj, vmax, jmax) == aj
            for vj, aj, vmax, jmax in zip(v.tolist(), a.tolist(), self._vmax_floats, self._jmax_floats)
        )

    def _follow_with_ruckig(
        self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, clamped: np.ndarray, interval: float, lead: float, error: float
    ) -> None:
        """Plan ruckig toward the path state ``(q, qd, qdd)`` (n,) at ``lead`` s from now (0: a target now; one
        period: a spline segment's end), clamped joints at rest, made admissible, met at the shortest horizon
        (:meth:`_intercept_horizon`); ``error`` (rad) is the arm's distance to the path now."""
        self._sync_input()
        self._max_target_error = max(self._max_target_error, error)
        qd = np.where(clamped, 0.0, qd.clip(-self._vmax, self._vmax))
        qdd = np.where(clamped, 0.0, qdd.clip(-self._amax, self._amax))
        self._path = self._stop_at_range(q, qd, qdd, interval)
        self._path_floats = tuple(a.tolist() for a in self._path)
        self._path_lead = lead
        horizon = self._intercept_horizon(interval)
        self._late_targets += horizon > interval + TIME_EPSILON
        inp = self._input
        inp.control_interface = ruckig.ControlInterface.Position
        inp.minimum_duration = horizon
        inp.target_position, inp.target_velocity, inp.target_acceleration = self._predict(horizon)
        self._new_target = True

    def _check_trackable(self, qd: np.ndarray, clamped: np.ndarray) -> None:
        """Raise :class:`UntrackablePathError` for the first joint (not clamped onto its range) whose path speed
        ``qd`` (n,) rad/s (a target's velocity, or the peak over the spline segment a stream point starts) is above
        its ``max_velocity``."""
        beyond = np.flatnonzero(~clamped & (np.abs(qd) > self._vmax))
        if beyond.size:
            j = int(beyond[0])
            joint = self.limits.joints[j].name.partition("/")[2]
            raise UntrackablePathError(
                f"untrackable path: arm {self.limits.arm}, joint {joint}, t={self.time:.4f} s: the target path moves at "
                f"{abs(qd[j]):.6g} rad/s, above max_velocity {self._vmax[j]:.6g} rad/s"
            )

    def _stop_at_range(
        self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, interval: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The path state, with joints that must start braking now to stay in range set to rest on the boundary.

        A joint must brake when its time-optimal stop from the current state (ruckig, velocity interface, per joint)
        plus one target interval of travel at the current speed would end beyond its range."""
        brake, src = self._brake_input, self._input
        brake.current_position, brake.current_velocity = src.current_position, src.current_velocity
        brake.current_acceleration = src.current_acceleration
        self._probe.calculate(brake, self._probe_trajectory)
        stop = np.array(self._probe_trajectory.at_time(self._probe_trajectory.duration)[0])
        v = np.array(src.current_velocity)
        reach = stop + v * interval
        upper, lower = (v > 0.0) & (reach > self._hi), (v < 0.0) & (reach < self._lo)
        if not (upper.any() or lower.any()):
            return q, qd, qdd
        braking = upper | lower
        target = np.where(upper, self._hi, np.where(lower, self._lo, q))
        return target, np.where(braking, 0.0, qd), np.where(braking, 0.0, qdd)

    def _predict(self, tau: float) -> tuple[list[float], list[float], list[float]]:
        """The target path's state ``tau`` s ahead (``tau`` minus the path state's own lead beyond its time),
        extrapolated at constant acceleration, made admissible: velocity
        and acceleration clamped to the limits, the acceleration then to what the velocity limit leaves
        (:func:`_admissible_acceleration`), positions clamped to the joint range (those joints then at rest).

        Plain Python floats, one joint at a time (the interception search calls this up to a dozen times per target,
        and on six numbers numpy's per-call overhead would outweigh the arithmetic), with the operations, their order
        and the clamps' tie-breaking of numpy's ``clip`` (``_clip``): the same bits as the array expressions."""
        pos, vel, acc = [], [], []
        limits = zip(self._lo_floats, self._hi_floats, self._vmax_floats, self._jmax_floats)
        tau = tau - self._path_lead
        for q, qd, qdd, (lo, hi, vmax, jmax) in zip(*self._path_floats, limits):
            p = q + qd * tau + 0.5 * qdd * tau * tau
            if p < lo or p > hi:
                pos.append(_clip(p, lo, hi))
                vel.append(0.0)
                acc.append(0.0)
            else:
                v = _clip(qd + qdd * tau, -vmax, vmax)
                pos.append(p)
                vel.append(v)
                acc.append(_admissible_acceleration(v, qdd, vmax, jmax))
        return pos, vel, acc

    def _reachable(self, tau: float) -> bool:
        """Whether the arm can be on the predicted path state ``tau`` s from now: ruckig, asked for a motion of at
        least ``tau`` s, finds one of exactly ``tau`` (a numerical failure counts as not reachable)."""
        probe, src = self._probe_input, self._input
        probe.current_position, probe.current_velocity = src.current_position, src.current_velocity
        probe.current_acceleration = src.current_acceleration
        probe.target_position, probe.target_velocity, probe.target_acceleration = self._predict(tau)
        probe.minimum_duration = tau
        try:
            result = self._probe.calculate(probe, self._probe_trajectory)
        except ruckig.RuckigError:
            return False
        return result in (ruckig.Result.Working, ruckig.Result.Finished) and self._probe_trajectory.duration <= tau + TIME_EPSILON

    def _intercept_horizon(self, interval: float) -> float:
        """Shortest horizon (s, at least ``interval``, to within one cycle) at which the arm can meet the extrapolated
        target path; :data:`MAX_HORIZON` if it cannot within that."""
        if self._reachable(interval):
            return interval
        lo, hi = interval, 2.0 * interval
        while not self._reachable(hi):
            if hi >= MAX_HORIZON:
                return MAX_HORIZON
            lo, hi = hi, min(2.0 * hi, MAX_HORIZON)
        while hi - lo > self.settings.cycle_time:
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if self._reachable(mid) else (mid, hi)
        return hi

    def reset(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> None:
        """Put the generator at the state ``(q, qd, qdd)`` (n,) (rad, rad/s, rad/s^2), at rest on it as a target, for a
        caller that moved the path itself for a while (the task-space filter's pass-through); velocity and
        acceleration are clipped to the limits, positions to the joint range. The next :meth:`set_target` starts a
        new target stream from that state."""
        n = len(self.limits.joints)
        q = np.clip(_vector(f"{self.limits.arm}: reset position", q, n), self._lo, self._hi)
        qd = np.clip(_vector(f"{self.limits.arm}: reset velocity", qd, n), -self._vmax, self._vmax)
        qdd = np.clip(_vector(f"{self.limits.arm}: reset acceleration", qdd, n), -self._amax, self._amax)
        inp = self._input
        inp.control_interface = ruckig.ControlInterface.Position
        inp.minimum_duration = None
        inp.current_position, inp.current_velocity, inp.current_acceleration = q.tolist(), qd.tolist(), qdd.tolist()
        self._unsent_state = None
        inp.target_position, inp.target_velocity, inp.target_acceleration = q.tolist(), [0.0] * n, [0.0] * n
        self._state = (q.copy(), qd.copy(), qdd.copy())
        self._path = self._state
        self._path_floats = tuple(a.tolist() for a in self._path)
        self._path_lead = 0.0
        self._history_steps, self._history_q = [], []
        self._points, self._segment = [], None
        self._new_target = True

    def hold(self) -> None:
        """Brake to rest, jerk-limited, wherever the arm gets to (ruckig's velocity interface, time-optimal); the next
        :meth:`set_target` starts a new target stream."""
        n = len(self.limits.joints)
        inp = self._input
        inp.control_interface = ruckig.ControlInterface.Velocity
        inp.minimum_duration = None
        inp.target_velocity = [0.0] * n
        inp.target_acceleration = [0.0] * n
        self._history_steps, self._history_q = [], []
        self._points, self._segment = [], None
        self._new_target = True

    # ---- stepping --------------------------------------------------------------------------------------------------
    def step(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Advance one cycle; returns ``(q, qd, qdd)`` (n,) at the new :attr:`time` (rad, rad/s, rad/s^2)."""
        inp = self._input
        if self._segment is not None and not self._new_target and self._segment_u(self._steps) >= 1.0 - TIME_EPSILON:
            self._segment = None  # the segment is played to its end and no next target came
        if self._finished and not self._new_target and self._target_moving():
            self.hold()  # the last target was reached and no new one came: do not extrapolate its motion
        if self._segment is not None:
            row = 1 + self._steps + 1 - self._segment[1]  # after the start's and the end's rows
            q, qd, qdd = self._segment_states
            state = (q[row], qd[row], qdd[row])
            self._unsent_state = state
            self._on_segment = True
            self._finished = self._segment_u(self._steps + 1) >= 1.0 - TIME_EPSILON
        else:
            self._sync_input()
            try:
                result = self._otg.update(inp, self._output)
            except ruckig.RuckigError as exc:
                raise SimulationError(f"{self.limits.arm}: ruckig refused the input at t={self.time:.4f} s: {exc}") from None
            if result not in (ruckig.Result.Working, ruckig.Result.Finished):
                raise SimulationError(f"{self.limits.arm}: ruckig failed at t={self.time:.4f} s: {result}")
            out = self._output
            out.pass_to_input(inp)
            self._on_segment = False
            self._finished = result == ruckig.Result.Finished
            state = (self._in_range(out.new_position), np.array(out.new_velocity), np.array(out.new_acceleration))
        self._steps += 1
        self._new_target = False
        self._state = state
        return self.state

    def _sync_input(self) -> None:
        """Give ruckig's input the arm's state played on a spline segment (held back while the segment plays: only
        ruckig reads it)."""
        if self._unsent_state is not None:
            inp = self._input
            inp.current_position, inp.current_velocity, inp.current_acceleration = (a.tolist() for a in self._unsent_state)
            self._unsent_state = None

    def _segment_u(self, step: int) -> float:
        """The spline segment's parameter in [0, 1] at generator step ``step``."""
        assert self._segment is not None
        return (step - self._segment[1]) * self.settings.cycle_time / self.settings.control_period

    def state_at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q, qd, qdd)`` (n,) at time ``t`` s inside the last step, ``[time - cycle_time, time]`` (the exact motion
        the generator produced over that step)."""
        if self._steps == 0 or abs(t - self.time) <= TIME_EPSILON:
            return self.state
        if not self.time - self.settings.cycle_time - TIME_EPSILON <= t <= self.time:
            raise ValueError(f"t={t!r} s is outside the last step [{self.time - self.settings.cycle_time!r}, {self.time!r}] s")
        if self._on_segment:
            assert self._segment is not None
            points, start = self._segment
            u = (t - start * self.settings.cycle_time) / self.settings.control_period
            return _spline_state(points, min(max(u, 0.0), 1.0), self.settings.control_period)
        out = self._output
        q, qd, qdd = out.trajectory.at_time(max(out.time - (self.time - t), 0.0))
        return self._in_range(q), np.array(qd), np.array(qdd)

    def _in_range(self, q: list[float]) -> np.ndarray:
        """ruckig's positions (rad) clipped onto the joint range: its braking onto a boundary lands on it up to
        round-off (of order 1e-12 rad beyond it), which the range check must not see."""
        return np.array(q).clip(self._lo, self._hi)

    # ---- state -----------------------------------------------------------------------------------------------------
    @property
    def time(self) -> float:
        """s, the generator's clock: steps taken times the cycle time."""
        return self._steps * self.settings.cycle_time

    @property
    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q, qd, qdd)`` (n,) at :attr:`time` (copies; the tuple written out: a generator expression costs a call
        per element, and the step loop reads this state twice a MuJoCo step per arm)."""
        q, qd, qdd = self._state
        return q.copy(), qd.copy(), qdd.copy()

    @property
    def at_rest(self) -> bool:
        """True when the last target (or hold) is reached and it was a state at rest (zero velocity and acceleration)."""
        return self._finished and not self._new_target and not self._target_moving()

    def _target_moving(self) -> bool:
        inp = self._input
        return any(inp.target_velocity) or any(inp.target_acceleration)

    @property
    def late_targets(self) -> int:
        """How many targets the arm could not meet within one target interval (it was off the path and caught up
        over a longer horizon): 0 on a path within the limits that starts at rest."""
        return self._late_targets

    @property
    def max_target_error(self) -> float:
        """rad, the largest joint distance between the arm and a target when it arrived (the arm should be there:
        about 1e-9 rad on a path within the limits; more means it fell behind or cut across)."""
        return self._max_target_error

    @property
    def clamped_targets(self) -> dict[str, int]:
        """Per joint (full name): how many targets were clamped onto the joint range."""
        return {name: int(c) for name, c in zip(self.limits.joint_names, self._clamped)}
