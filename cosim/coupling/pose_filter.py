"""Smoothing of the controller's vessel targets in task space, before inverse kinematics: jerk-limited, then linear.

The controller's planar targets can change faster than a jerk-limited arm can follow (the paper's SIM excitation
theta = phi sin(alpha t) starts with a velocity step); fed straight to IK, the joint trajectory then cuts across
the intended vessel path by centimetres. The targets (dx, dz, theta of the pourer; dx of the catcher) go through a
ruckig generator in those coordinates first (the same :class:`TrajectoryGenerator`, one "joint" per coordinate),
stepped at the control rate; the joint generators then follow IK of the smoothed path within their limits. Each
target is approached as a state at rest, so a moving target is followed with a small lag (a 0.35 rad/s ramp: 0.055
rad, a jerk-limited stop's distance plus the re-planning) and a chattering one never sets the filter swinging. In
CFS, whose targets move on every period, the path is moved by a linear tracking filter wherever its jerk is
admissible (:class:`cosim.coupling.tracking_filter.TrackingFilter`): a ramp is then followed at a constant lag with
no jerk at all.

The jerk-limited filter's own motion is bang-bang in jerk (ruckig's phases use the limit jerk or none), re-planned
every period toward a target that the controller moves every period: its path carries a ripple at the control rate
that the joints would follow. :class:`PoseSmoother` removes it: :data:`SMOOTHING_STAGES` first-order low-passes at
:data:`SMOOTHING_BANDWIDTH` in series (:class:`controllers.motion.CriticallyDampedSmoother`) on each coordinate of the
limited pose (a path whose timing the controller designs, such as a passed-through command, is not delayed:
:class:`PoseSmoother`). Their impulse response is positive with unit sum, so the smoothed path's sampled velocity,
acceleration and jerk stay within those of the limited path (within its limits), and it delays a ramp by
:data:`SMOOTHING_DELAY` (36 ms), which the pour's feedback sees (the partial pour's stop fits the vessel's lag behind
its command).
"""

from __future__ import annotations

import math

import numpy as np

from controllers.motion import CriticallyDampedSmoother
from cosim.coupling.settings import PoseFilterLimits
from cosim.coupling.tracking_filter import TrackingFilter
from cosim.robots.planar import PlanarPose
from cosim.trajectory.generator import GeneratorSettings, TrajectoryGenerator
from cosim.trajectory.limits import ArmLimits, JointLimits

POSE_RANGE = 10.0  # m / rad: the filter's own position bounds (the arms' ranges are checked downstream)
# m / rad: how close the filtered pose must be to a pass-through command before the filter hands over to it; a
# step of this size in a 10 ms target is 0.1 m/s or rad/s, well inside the arms' limits.
PASS_THROUGH_JOIN = 1e-3
# rad/s and count: the linear smoothing after the jerk-limited filter. The bandwidth is the controller's own command
# smoothing's (controllers.config PidDesignSpec.smoothing_bandwidth); three stages roll the ripple at the control rate
# off as f^-3 where two leave more of it; the delay is about half the jerk-limited filter's own lag on a CFS path.
SMOOTHING_BANDWIDTH = 60.0
SMOOTHING_STAGES = 3
# s: how long the difference between the smoothed path and a passed-through command is blended out after a hand-over;
# the blend of a difference d peaks at 1.9 d / HANDOVER_TIME in rate and 5.8 d / HANDOVER_TIME^2 in acceleration
# (d = 36 ms x 0.1 rad/s = 3.6 mrad, a slosh damping's rate: 0.03 rad/s, 0.5 rad/s^2).
HANDOVER_TIME = 0.2
# rad/s: the closed-loop bandwidth of the tracking filter that follows a moving target (in CFS). On recorded CFS
# targets (cosim.bench.pose_filter_replay), 35 rad/s follows the tilt command with less lag and less acceleration
# content above 10 Hz than a filter that re-plans to rest every period (the figures: docs/tuning.md).
TRACKING_BANDWIDTH = 35.0
# How far beyond the jerk limit the tracking filter's linear law may ask (clipped to the limits) before the
# jerk-limited generator moves the path instead: a linear law clipped far beyond its limits winds up (0.02-1 rad steps
# overshoot by 13 % to several times the step, see cosim.coupling.tracking_filter).
TRACKING_SATURATION = 1.5


class PoseFilter:
    """Smooths one vessel's planar targets; ``coordinates`` is "dx,dz,theta" (pourer) or "dx" (catcher)."""

    def __init__(self, name: str, coordinates: tuple[str, ...], limits: PoseFilterLimits, control_period: float):
        def joint(c: str) -> JointLimits:
            if c == "theta":
                return JointLimits(f"{name}/theta", limits.tilt_velocity, limits.tilt_acceleration, limits.tilt_jerk, -math.pi, math.pi)
            return JointLimits(f"{name}/{c}", limits.translation_velocity, limits.translation_acceleration, limits.translation_jerk, -POSE_RANGE, POSE_RANGE)

        self.coordinates = coordinates
        arm = ArmLimits(name, "task space", tuple(joint(c) for c in coordinates))
        settings = GeneratorSettings(cycle_time=control_period, control_period=control_period)
        self._generator = TrajectoryGenerator(arm, np.zeros(len(coordinates)), settings)
        self._tracking = False  # the last call tracked its target
        self._tracker = TrackingFilter(
            np.array([j.max_velocity for j in arm.joints]), np.array([j.max_acceleration for j in arm.joints]),
            np.array([j.max_jerk for j in arm.joints]), TRACKING_BANDWIDTH, control_period,
        )
        self._period = control_period
        self._passed: list[np.ndarray] = []  # the last pass-through targets (at most three), for their rates
        self.passing = False  # the last call passed its target through

    def __call__(self, target: PlanarPose, pass_through: bool = False, track: bool = False) -> PlanarPose:
        """The smoothed pose one control period after the previous call, heading for ``target``; with ``track``
        a target that moves on every period (the CFS law's), followed by the :class:`TrackingFilter` from the
        path's current state, which follows a ramp at a constant lag with no jerk instead of re-planning a stop at
        every target (where its linear law would ask more than :data:`TRACKING_SATURATION` times the jerk limit,
        the jerk-limited generator takes the step toward the law's steady motion: the target less the law's lag
        times its estimate of the target's rate, at that rate); with
        ``pass_through`` the target itself (a command the controller has already smoothed, whose timing matters:
        the slosh damping's feedback), the filter's own state following it (its rates from the last three
        targets) so that filtering resumes from where the path is. Pass-through starts only once the filtered
        pose is within :data:`PASS_THROUGH_JOIN` of the command (until then it is filtered), so the path never
        jumps to a command the arm has not caught up with."""
        values = np.array([getattr(target, c) for c in self.coordinates])
        if pass_through and not self._passed:  # join the command only where the filtered path has reached it
            position = self._generator.state[0]
            pass_through = bool(np.all(np.abs(values - position) <= PASS_THROUGH_JOIN))
        self.passing = pass_through
        if pass_through:
            self._passed = (self._passed + [values])[-3:]
            rates = np.diff(self._passed, axis=0) / self._period
            velocity = rates[-1] if len(rates) else np.zeros_like(values)
            acceleration = (rates[-1] - rates[-2]) / self._period if len(rates) > 1 else np.zeros_like(values)
            self._generator.reset(values, velocity, acceleration)
            return target
        self._passed = []
        if track:
            state = self._generator.state
            linear = self._tracker.limited_step(values, *state)
            if linear is None and self._tracker.saturation(values, *state) <= TRACKING_SATURATION:
                linear = self._tracker.clipped_step(values, *state)
            reference = self._tracker.follow(values, state if linear is not None or not self._tracking else None)
            self._tracking = True
            if linear is not None:
                self._generator.reset(*linear)
                return self._pose(linear[0])
            # onto the law's steady motion: the target's estimated rate, the law's lag behind the target
            rate = reference[1]
            self._generator.set_target(values - self._tracker.lag * rate, rate, np.zeros_like(rate))
            q, _, _ = self._generator.step()
            return self._pose(q)
        self._tracking = False
        # Each target is one to come to rest at. Estimating a path velocity from the targets (what the joint
        # generators do with the already smooth output of this filter) reads the controller's step-to-step
        # corrections of either sign as velocity and drove a +-0.1 rad limit cycle of the tilt in the coupled pour.
        zero = np.zeros(len(self.coordinates))
        self._generator.set_target(values, zero, zero)
        q, _, _ = self._generator.step()
        return self._pose(q)

    def _pose(self, q: np.ndarray) -> PlanarPose:
        values = dict(zip(self.coordinates, map(float, q)))
        return PlanarPose(values.get("dx", 0.0), values.get("dz", 0.0), values.get("theta", 0.0))


SMOOTHING_DELAY = CriticallyDampedSmoother(SMOOTHING_BANDWIDTH, 0.01, SMOOTHING_STAGES).delay  # s, at a 10 ms period


def _blend_out(s: float) -> float:
    """1 at ``s <= 0`` down to 0 at ``s >= 1`` with zero first and second derivatives at both ends (the quintic
    ``1 - (10 s^3 - 15 s^4 + 6 s^5)``)."""
    s = min(max(s, 0.0), 1.0)
    return 1.0 - s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)


class PoseSmoother:
    """Linear smoothing of one vessel's planar pose, per coordinate (see the module docstring); ``coordinates`` as
    :class:`PoseFilter`'s, starting at rest at the home pose (all zero).

    A path that must not be delayed (a command the pose filter passes through, the slosh damping's feedback, whose
    delay the controller's design includes with its own smoothing; the coupling also passes the damping's path
    before the filter joins it) is not delayed. The output is always a path plus a residual: the smoothed limited
    pose, or the undelayed path itself, plus what is left of the difference at the last hand-over, blended
    out over :data:`HANDOVER_TIME` with zero rate and acceleration at both ends (:func:`_blend_out`). At a hand-over to
    pass-through the residual is where the output would be at its last rate less the command (the pose filter joins
    a command up to a millimetre or milliradian away from its own path, :data:`PASS_THROUGH_JOIN`); back to filtering, the smoothing stages restart
    as on a ramp at the command's last rate into its last value, and the residual is the output's lead over theirs.
    So neither hand-over puts a step in the path, its rate or its acceleration."""

    def __init__(self, coordinates: tuple[str, ...], control_period: float):
        self.coordinates = coordinates
        self._period = control_period
        self._smoothers = {c: CriticallyDampedSmoother(SMOOTHING_BANDWIDTH, control_period, SMOOTHING_STAGES) for c in coordinates}
        self._passing = False
        self._source = ""
        self._residual = {c: 0.0 for c in coordinates}  # the difference at the last hand-over
        self._since = 0  # control periods since the last hand-over
        self._last_command = {c: 0.0 for c in coordinates}
        self._last_output = {c: 0.0 for c in coordinates}
        self._previous_output = {c: 0.0 for c in coordinates}

    def __call__(self, pose: PlanarPose, passing: bool = False, source: str = "") -> PlanarPose:
        """The smoothed pose for the next control period's ``pose``; ``passing``: ``pose`` is a path not to delay
        (e.g. a command the pose filter passed through, :attr:`PoseFilter.passing`); ``source``: what ``pose`` is
        (the limited path or the command): a change is a hand-over too (the pose filter joins a command off its own
        path), blended out like one."""
        handover = passing != self._passing or (passing and source != self._source)
        self._source = source
        self._since = 0 if handover else self._since + 1
        values = {}
        for c, smoother in self._smoothers.items():
            x = getattr(pose, c)
            if handover and passing:  # the output as continued at its last rate, less the command
                self._residual[c] = 2.0 * self._last_output[c] - self._previous_output[c] - x
            elif handover:
                rate = (x - self._last_command[c]) / self._period
                restart = self._last_command[c] - rate * smoother.delay  # the ramp's smoothed value there
                smoother.reset(restart, rate)
                self._residual[c] = self._last_output[c] - restart
            path = x if passing else smoother.step(x)
            values[c] = path + self._residual[c] * _blend_out((self._since + 1) * self._period / HANDOVER_TIME)
            self._last_command[c], self._previous_output[c], self._last_output[c] = x, self._last_output[c], values[c]
        self._passing = passing
        return PlanarPose(values.get("dx", 0.0), values.get("dz", 0.0), values.get("theta", 0.0))
