"""The pour state machine: SIM (or a plain approach), constant flow, return; the catcher throughout.

    IDLE --t >= start_time--> SIM_EXCITE -> SIM_HOLD -> SIM_DAMP -> CFS -> [CFS_FINAL] -> RETURN -> DONE
                         \\-> APPROACH ------------------------------/
    (any pouring phase -> RETURN when the target volume is reached or the pourer is empty)

A partial pour ends with CFS_FINAL: CFS holding ``cfs.final_head_fraction`` of h_q_ref, entered once the volume
still to pour before the predicted after-flow would leave within ``cfs.final_stage_time`` at the current rate. The
stop has to predict the after-flow (what still leaves while the vessel turns back,
:func:`controllers.cfs.after_flow_volume`, with the vessel's lag behind its command: ``follower_lag`` where the
configuration knows it, else fitted over the last LAG_WINDOW s). That prediction is uncertain by about a fifth of
the after-flow (docs/tuning.md); the smaller outflow at the stop makes that error a smaller share of the target.

Call :meth:`PourController.step` once per control period (``config.dt``, 10 ms by default) with a
:class:`controllers.measurement.LiquidMeasurement`; it returns a :class:`controllers.measurement.PourCommand`.
The discrete elements (PID, limiters) assume that period; the measurement's own time stamps drive the phase
timing. Pivots of the pourer's rotation (vessel frame): SIM about the inner floor centre (0, 0), the approach
about the slosh pendulum's hinge (0, l1 - b2), CFS about the pour lip (B/2 + t, L), raised in the world at large
tilts to stay above that hinge (:func:`controllers.cfs.cfs_pivot`); the return brings the pose
back to home along a straight line in (dx, dz, theta). Every pivot change keeps the pose continuous.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable

import numpy as np

from controllers.catcher import CatcherFollower, landing_x, weir_velocity
from controllers.cfs import after_flow_volume, cfs_increment, cfs_pivot, crest_lever, deepest_crest_tilt
from controllers.config import Damping, Handover, PourConfig, SimMode
from controllers.errors import ControllerInputError, MeasurementError
from controllers.geometry import PlanarPose, static_tilt_for_h_q
from controllers.measurement import LiquidMeasurement, Phase, PhaseTransition, PoseAhead, PourCommand
from controllers.motion import CriticallyDampedSmoother, JerkLimitedMove, RateLimitedTracker, fitted_delay
from controllers.pid import DiscretePid, PidDesign, design_filtered_pid
from controllers.sampled_filter import SampledFilter
from controllers.slosh_induction import excitation_duration, excitation_tilt, sim_needed

# Delay (s) of the filter on the measured outflow rate d(poured)/dt: a fifth of the paper's vessel's slosh period,
# enough to smooth SPH particle-count steps while keeping the stop prediction current. OUTFLOW_FILTER_STAGES
# first-order stages of OUTFLOW_FILTER_TIME / OUTFLOW_FILTER_STAGES each: the volume leaves in whole particles, each an
# impulse in d(poured)/dt; through one stage it is a step in the filtered rate and so in the CFS law's tilt rate
# (the level drop it feeds forward), through two a ramp.
OUTFLOW_FILTER_TIME = 0.1
OUTFLOW_FILTER_STAGES = 2
# Delay (s) of the filter (OUTFLOW_FILTER_STAGES stages) on the volume left that sets CFS's deepest tilt
# (controllers.cfs.deepest_crest_tilt): the volume changes in whole particles, and near 89 deg one particle of the
# default scene moves that tilt by 3e-4 rad, a step in a command that rides the limit. Filtered, the limit rises
# smoothly; it lags the draining, which keeps it below the instantaneous one.
DEEPEST_TILT_FILTER_TIME = 0.5
# CFS has stalled when, over the last cfs.max_tilt_hold s, less than this fraction of the initial volume left and
# the tilt rose by less than STALL_TILT: near 90 deg the crest's lever degenerates and the last wedge of liquid
# only drips, for tens of seconds, at a few mL/s.
STALL_FRACTION = 0.005
STALL_TILT = 0.01  # rad
# Tilt (rad) within which a rate-limited tilt counts as arrived (approach target, upright): 0.006 deg.
ARRIVAL_TOLERANCE = 1e-4
# The vessel's lag behind its commanded tilt, as measured: fitted as a pure delay (controllers.motion.fitted_delay)
# over the last LAG_WINDOW s of commanded and measured tilt, between 0 and MAX_FOLLOWER_LAG s in steps of half a
# control period; the bound leaves room above the coupled pour's task-space filter and arm (docs/tuning.md). The
# after-flow prediction uses it where the configuration does not know the lag (PourConfig.follower_lag): the fit
# reads a static offset of the vessel from its command (a deflection under the liquid's load) as delay.
LAG_WINDOW = 0.5  # s, about one slosh period of the vessel of Camporredondo et al. (2019)
MAX_FOLLOWER_LAG = 0.3  # s

Transition = tuple[Phase, str] | None


def _low_pass(stages: list[float], x: float, gain: float) -> float:
    """One sample ``x`` through first-order stages in series (each y += gain (input - y), updated in place); returns
    the last stage's output."""
    for k, y in enumerate(stages):
        x = stages[k] = y + gain * (x - y)
    return x


class PourController:
    """Closed-loop pour controller for one pour. Pure: its output depends only on the config and measurements."""

    def __init__(self, config: PourConfig) -> None:
        if not isinstance(config, PourConfig):
            raise ControllerInputError(f"pour: must be a PourConfig, got {type(config).__name__}")
        self.config = config
        self.dt = config.dt
        geom = config.vessel
        self.model = config.slosh_model()
        sim = config.sim
        if sim.mode is SimMode.AUTO:
            self.use_sim, self.entry_reason = sim_needed(
                geom.inner_width, geom.inner_height, config.fill_depth, sim.trigger_angle
            )
        else:
            self.use_sim = sim.mode is SimMode.ALWAYS
            self.entry_reason = f"sim.mode = {sim.mode.value}"
        self.pid_design: PidDesign | None = None
        self._pid: DiscretePid | None = None
        self._smoother: CriticallyDampedSmoother | None = None  # between the PID and the arm (SIM_DAMP)
        self._theta1_filter: SampledFilter | None = None  # through which the PID reads theta1, from the first step
        if self.use_sim:
            self.pid_design = design_filtered_pid(self.model, sim.pid, self.dt)
            self._pid = DiscretePid(self.pid_design.gains, self.dt, 0.0, config.cfs.max_tilt, sim.max_tilt_rate)
            self._smoother = CriticallyDampedSmoother(sim.pid.smoothing_bandwidth, self.dt)
            self._theta1_filter = SampledFilter(*self.pid_design.measurement)
        self.sim_frequency = sim.frequency_ratio * self.model.omega1  # alpha, rad/s
        self.sim_amplitude = math.nan  # phi, rad; set from the first measurement's volume
        self._approach = RateLimitedTracker(config.approach.max_rate, config.approach.max_accel, self.dt)
        c = config.catcher
        self._catcher = CatcherFollower(
            c.home_x, (c.travel_min, c.travel_max), c.max_speed, c.max_accel, self.dt, c.filter_time
        )

        self.pose = PlanarPose()
        self.phase = Phase.IDLE
        self.reason = "waiting for start_time"
        self._transitions: list[PhaseTransition] = []
        self._phase_start = 0.0
        self._last_t: float | None = None
        self._first_t = math.nan
        self._initial_volume = math.nan
        self._outflow_stages = [0.0] * OUTFLOW_FILTER_STAGES  # the outflow rate's filter
        self._outflow_rate = 0.0  # m^3/s, filtered
        # m, the head over the crest as the weir law sees it (max(h_q, 0): a negative head pours nothing), filtered like
        # the outflow rate, for the after-flow prediction, which scales that rate by (head / this)^(3/2)
        self._head_stages = [math.nan] * OUTFLOW_FILTER_STAGES
        self._h_q = math.nan
        self._volume_stages = [math.nan] * OUTFLOW_FILTER_STAGES  # m^3, the volume left for the deepest tilt
        self._tilt_rate = 0.0  # rad/s, of the commanded tilt over the last step
        self._cfs_head = 0.0  # m, the measured h_q through CFS's head filter (cfs.head_filter_fraction)
        self._theta1_rate = 0.0  # rad/s, of the free-surface angle the PID reads (filtered) over the last step
        self._last_theta1 = 0.0
        self._theta1 = 0.0  # rad, theta1 as the PID reads it: through its measurement filter
        self._last_poured = 0.0
        self._sigma_prev = 0.0
        self._vessel_held = False  # SIM_HOLD: the vessel itself has stopped at phi, not only its command
        self._since = math.nan  # start of the current settle (SIM_DAMP) or max-tilt (CFS) interval, s
        self._cfs_history: deque[tuple[float, float, float]] = deque()  # (t, poured, tilt) over the last hold
        self._tilt_history: deque[tuple[float, float, float]] = deque()  # (t, commanded, measured tilt), LAG_WINDOW
        self._reference = 0.0  # rad, tilt reference of SIM_DAMP / target of APPROACH
        self._held_tilt = 0.0  # rad, SIM_DAMP's open-loop tilt command (sim.damping = hold)
        self._return_from = PlanarPose()
        self._return: JerkLimitedMove | None = None

        self._check: dict[Phase, Callable[[LiquidMeasurement], Transition]] = {
            Phase.IDLE: self._check_idle,
            Phase.SIM_EXCITE: self._check_excite,
            Phase.SIM_HOLD: self._check_hold,
            Phase.SIM_DAMP: self._check_damp,
            Phase.APPROACH: self._check_approach,
            Phase.CFS: self._check_cfs,
            Phase.CFS_FINAL: self._check_cfs,
            Phase.RETURN: self._check_return,
            Phase.DONE: lambda m: None,
        }
        self._act: dict[Phase, Callable[[LiquidMeasurement], PlanarPose]] = {
            Phase.IDLE: lambda m: self.pose,
            Phase.SIM_EXCITE: self._act_excite,
            Phase.SIM_HOLD: lambda m: self.pose,
            Phase.SIM_DAMP: self._act_damp,
            Phase.APPROACH: self._act_approach,
            Phase.CFS: self._act_cfs,
            Phase.CFS_FINAL: self._act_cfs,
            Phase.RETURN: self._act_return,
            Phase.DONE: lambda m: PlanarPose(),
        }

    # ---- public -----------------------------------------------------------------------------------------------
    @property
    def transitions(self) -> tuple[PhaseTransition, ...]:
        return tuple(self._transitions)

    def phase_intervals(self, t_end: float) -> list[tuple[str, float, float]]:
        """(phase name, start s, end s) of every phase entered so far, IDLE from the first step, the current
        phase ending at ``t_end``. Empty before the first step."""
        if self._last_t is None:
            return []
        starts = [(Phase.IDLE, self._first_t)] + [(tr.target, tr.t) for tr in self._transitions]
        ends = [t for _, t in starts[1:]] + [t_end]
        return [(phase.value, t0, t1) for (phase, t0), t1 in zip(starts, ends)]

    def step(self, m: LiquidMeasurement) -> PourCommand:
        """One control step: the pourer's and vessel B's target poses for this measurement."""
        if not isinstance(m, LiquidMeasurement):
            raise MeasurementError(f"measurement: must be a LiquidMeasurement, got {type(m).__name__}")
        if self._last_t is None:
            self._begin(m)
        elif not m.t > self._last_t:
            raise MeasurementError(f"measurement.t: must increase, got {m.t:g} s after {self._last_t:g} s")
        else:
            rate = (m.poured_volume - self._last_poured) / (m.t - self._last_t)
            gain = min(OUTFLOW_FILTER_STAGES * (m.t - self._last_t) / OUTFLOW_FILTER_TIME, 1.0)
            self._outflow_rate = _low_pass(self._outflow_stages, rate, gain)
            self._h_q = _low_pass(self._head_stages, max(m.h_q, 0.0), gain)
            gain = min(OUTFLOW_FILTER_STAGES * (m.t - self._last_t) / DEEPEST_TILT_FILTER_TIME, 1.0)
            _low_pass(self._volume_stages, m.volume_in_pourer, gain)
        self._theta1 = self._theta1_filter.step(m.theta1) if self._theta1_filter is not None else m.theta1
        if self._last_t is not None:
            self._theta1_rate = (self._theta1 - self._last_theta1) / (m.t - self._last_t)
        self._last_theta1 = self._theta1
        self._last_t, self._last_poured = m.t, m.poured_volume

        for _ in Phase:  # a step may pass several phases; each at most once
            nxt = self._check[self.phase](m)
            if nxt is None:
                break
            self._enter(nxt[0], nxt[1], m)
        theta_before = self.pose.theta
        self.pose = self._act[self.phase](m)
        self._tilt_rate = (self.pose.theta - theta_before) / self.dt
        self._tilt_history.append((m.t, self.pose.theta, m.tilt))
        while m.t - self._tilt_history[0][0] > LAG_WINDOW:
            self._tilt_history.popleft()
        landing = self._landing(m)
        return PourCommand(
            t=m.t,
            pourer=self.pose,
            catcher=PlanarPose(self._catcher.step(landing), 0.0, 0.0),
            phase=self.phase,
            reason=self.reason,
            landing_x=self._catcher.target_dx + self.config.catcher.home_x if landing is None else landing,
            slosh_angle=m.slosh_angle,
            feedback=self.phase is Phase.SIM_DAMP,
            pourer_ahead=self._excitation_ahead(m) if self.phase in (Phase.SIM_EXCITE, Phase.SIM_HOLD) else None,
        )

    # ---- bookkeeping ------------------------------------------------------------------------------------------
    def _begin(self, m: LiquidMeasurement) -> None:
        self._first_t = m.t
        self._h_q = max(m.h_q, 0.0)
        self._head_stages = [self._h_q] * OUTFLOW_FILTER_STAGES
        self._volume_stages = [m.volume_in_pourer] * OUTFLOW_FILTER_STAGES
        self._initial_volume = m.volume_in_pourer + m.poured_volume
        if self._theta1_filter is not None:
            self._theta1_filter.reset(m.theta1)
        if not self._initial_volume > 0.0:
            raise MeasurementError("measurement.volume_in_pourer: the pourer is empty at the first step")
        contact = static_tilt_for_h_q(self.config.vessel, 0.0, self._area(m))
        self.sim_amplitude = self.config.sim.amplitude_fraction * contact

    def _area(self, m: LiquidMeasurement) -> float:
        return self.config.vessel.area(m.volume_in_pourer)

    def _enter(self, phase: Phase, reason: str, m: LiquidMeasurement) -> None:
        self._transitions.append(PhaseTransition(m.t, self.phase, phase, reason))
        self.phase, self.reason, self._phase_start = phase, reason, m.t
        self._since = math.nan
        self._cfs_history.clear()
        self._cfs_head = m.h_q  # the head filter starts on the measurement (no step into CFS)
        if phase is Phase.SIM_HOLD:
            self._sigma_prev = m.slosh_angle
            self._vessel_held = False
        elif phase is Phase.SIM_DAMP:
            assert self._pid is not None and self._smoother is not None
            # The damping starts from the vessel's measured tilt: a command that ran ahead of the arm (the task-space
            # filter lags a large excitation) would otherwise be a step in the path it passes to the arm.
            self.pose = self.pose.rotated_about((0.0, 0.0), m.tilt)
            self._reference = self._damp_reference(m)
            # Bumpless in rate too: the PID's first outputs continue the command's motion (at rest in the hold) with
            # the measured surface moving at its current rate; a PID started at rest with the surface moving steps
            # its output's rate, which the arm can only follow at its jerk limit.
            self._pid.reset(u0=self.pose.theta, y0=self._theta1, r0=self._reference, y_rate=self._theta1_rate,
                            u_rate=self._tilt_rate)
            self._smoother.reset(self.pose.theta, self._tilt_rate)
            self._held_tilt = self.pose.theta
        elif phase is Phase.APPROACH:
            self._reference = static_tilt_for_h_q(self.config.vessel, 0.0, self._area(m))
            self._approach.reset(self.pose.theta)
        elif phase is Phase.CFS and self._transitions[-1].source is Phase.SIM_DAMP and m.tilt < self.pose.theta:
            # The PID's command runs ahead of the arm (task-space filter lag); CFS starts from the measured tilt, so
            # the stream does not begin with the command's lead as an overshoot of h_q.
            self.pose = self.pose.rotated_about((0.0, 0.0), m.tilt)
        elif phase is Phase.RETURN:
            self._return_from = self.pose
            ret = self.config.returning
            # from the pour's tilt rate (its mean over the last LAG_WINDOW s: the last step's CFS increment jitters)
            rate = min(max(self._mean_tilt_rate(), -ret.max_rate), ret.max_rate)
            self._return = JerkLimitedMove(self.pose.theta, rate, 0.0, ret.max_rate, ret.max_accel, ret.max_jerk,
                                           ret.stop_accel)

    def _mean_tilt_rate(self) -> float:
        """rad/s, of the commanded tilt over the last LAG_WINDOW s of steps (0 before two steps)."""
        if len(self._tilt_history) < 2:
            return 0.0
        (t0, theta0, _), (t1, theta1, _) = self._tilt_history[0], self._tilt_history[-1]
        return (theta1 - theta0) / (t1 - t0)

    def _lag(self) -> float:
        """Time (s) the vessel runs behind its commanded tilt, fitted as a pure delay over the last LAG_WINDOW s of
        steps (a static offset of the vessel from its command counts in it as offset / tilt rate)."""
        if len(self._tilt_history) < 2:
            return 0.0
        t, commanded, measured = (np.array(c) for c in zip(*self._tilt_history))
        return fitted_delay(t, commanded, measured, MAX_FOLLOWER_LAG, 0.5 * self.dt)

    def _elapsed(self, m: LiquidMeasurement) -> float:
        return m.t - self._phase_start

    def _damp_reference(self, m: LiquidMeasurement) -> float:
        """Tilt (rad) at which the current liquid, at rest, would stand sim.damp_head over the crest (h_q_ref with
        the paper's crest hand-over, which damps toward the pouring tilt)."""
        cfs, sim = self.config.cfs, self.config.sim
        head = cfs.h_q_ref if sim.handover is Handover.CREST else sim.damp_head
        return min(static_tilt_for_h_q(self.config.vessel, head, self._area(m)), cfs.max_tilt)

    def _head_reference(self, phase: Phase) -> float:
        """h_q (m) that CFS holds in ``phase``: h_q_ref, or its final_head_fraction in a partial pour's final stage."""
        cfs = self.config.cfs
        return cfs.h_q_ref * (cfs.final_head_fraction if phase is Phase.CFS_FINAL else 1.0)

    # ---- transitions ------------------------------------------------------------------------------------------
    def _check_idle(self, m: LiquidMeasurement) -> Transition:
        if m.t < self.config.start_time:
            return None
        return (Phase.SIM_EXCITE if self.use_sim else Phase.APPROACH), self.entry_reason

    def _check_stop(self, m: LiquidMeasurement) -> Transition:
        """Partial pour reached (with the predicted after-flow) or pourer empty: go back upright."""
        target = self.config.target_volume
        if target is not None:
            lever = crest_lever(self.config.vessel, self.pose.theta, self._area(m))
            ret = self.config.returning
            known = self.config.follower_lag
            lag = self._lag() if known is None else known
            # Nothing over the crest now: the return only lowers the head, nothing more leaves. (The filtered rate and
            # head both decay after an earlier spill, and their ratio rate / head^(3/2), which the prediction scales
            # by, grows without bound as they do.)
            head = self._h_q if m.h_q > 0.0 else 0.0
            # The return's jerk limit ramps its acceleration up over max_accel / max_jerk s, which after the ramp
            # leaves it where the acceleration-limited turn would be max_accel / (2 max_jerk) s earlier: that delay
            # counts as lag (the positions differ by max_accel^3 / (24 max_jerk^2), 1.4 mrad with the defaults).
            ramp = ret.max_accel / (2.0 * ret.max_jerk)
            after = after_flow_volume(self._outflow_rate, head, lever, ret.max_rate, ret.max_accel,
                                      self._mean_tilt_rate(), lag + ramp)
            after = min(after, m.volume_in_pourer)  # what is there is the most that can still leave
            to_go = target - m.poured_volume - after
            if to_go <= 0.0:
                fitted = lag if known is None else self._lag()
                measured = f"vessel {1e3 * fitted:.0f} ms behind its command"
                lags = measured if known is None else f"follower lag {1e3 * known:.0f} ms, {measured} by the fit"
                return Phase.RETURN, (
                    f"poured {1e6 * m.poured_volume:.1f} mL + {1e6 * after:.1f} mL predicted after-flow "
                    f"({lags}) >= target {1e6 * target:.1f} mL"
                )
            cfs = self.config.cfs
            if (
                self.phase is Phase.CFS
                and cfs.final_head_fraction < 1.0
                and to_go <= self._outflow_rate * cfs.final_stage_time
            ):
                return Phase.CFS_FINAL, (
                    f"{1e6 * to_go:.1f} mL to go before the predicted after-flow <= {cfs.final_stage_time:g} s at "
                    f"{1e6 * self._outflow_rate:.0f} mL/s: h_q reference {1e3 * self._head_reference(Phase.CFS_FINAL):.2f} mm"
                )
        left = self.config.cfs.empty_fraction * self._initial_volume
        if m.volume_in_pourer <= left:
            return Phase.RETURN, f"empty: {1e6 * m.volume_in_pourer:.1f} mL left <= {1e6 * left:.1f} mL"
        return None

    def _check_excite(self, m: LiquidMeasurement) -> Transition:
        stop = self._check_stop(m)
        if stop or self._elapsed(m) < excitation_duration(self.sim_frequency):
            return stop
        return Phase.SIM_HOLD, f"t0 done: theta reached phi = {math.degrees(self.sim_amplitude):.2f} deg"

    def _check_hold(self, m: LiquidMeasurement) -> Transition:
        stop = self._check_stop(m)
        if stop:
            return stop
        sigma, prev = m.slosh_angle, self._sigma_prev
        self._sigma_prev = sigma
        # The paper's t1: theta1 returns to zero "while theta remains at phi". The command reaches phi at t0's end;
        # the vessel follows it late (the arm's filter and servos) and the surface answers its motion until it
        # stops, so a crossing counts once the vessel's own tilt (m.tilt) has stopped rising (not above the last).
        self._vessel_held = self._vessel_held or (bool(self._tilt_history) and m.tilt <= self._tilt_history[-1][2])
        if self._vessel_held and prev < 0.0 <= sigma:
            return Phase.SIM_DAMP, f"t1 done: slosh angle crossed zero toward the lip ({prev:+.4f} -> {sigma:+.4f} rad)"
        limit = self.config.sim.hold_timeout_periods * self.model.period
        if self._elapsed(m) >= limit:
            return Phase.SIM_DAMP, f"t1 timeout: no zero crossing of the slosh angle within {limit:.2f} s"
        return None

    def _check_damp(self, m: LiquidMeasurement) -> Transition:
        stop = self._check_stop(m)
        if stop:
            return stop
        sim = self.config.sim
        if sim.handover is Handover.CREST and m.h_q > 0.0:
            return Phase.CFS, f"t3: the slosh found free exit over the crest (h_q = {1e3 * m.h_q:.2f} mm)"
        if abs(m.slosh_angle) > sim.settle_tolerance:
            self._since = math.nan
        elif math.isnan(self._since):
            self._since = m.t
        if not math.isnan(self._since) and m.t - self._since >= sim.settle_dwell:
            return Phase.CFS, (
                f"t2 done: slosh damped, |sigma| <= {sim.settle_tolerance:g} rad for {sim.settle_dwell:g} s"
            )
        limit = sim.damp_timeout_periods * self.model.period
        if self._elapsed(m) >= limit:
            return Phase.CFS, f"t2 timeout after {limit:.2f} s, |sigma| = {abs(m.slosh_angle):.4f} rad"
        return None

    def _check_approach(self, m: LiquidMeasurement) -> Transition:
        stop = self._check_stop(m)
        if stop:
            return stop
        if m.h_q > 0.0:
            return Phase.CFS, f"liquid over the crest: h_q = {1e3 * m.h_q:.2f} mm"
        if self._approach.at(self._reference, ARRIVAL_TOLERANCE):
            return Phase.CFS, f"reached the static crest tilt {math.degrees(self._reference):.2f} deg"
        return None

    def _check_cfs(self, m: LiquidMeasurement) -> Transition:
        stop = self._check_stop(m)
        if stop:
            return stop
        cfs = self.config.cfs
        if self.pose.theta < cfs.max_tilt:
            self._since = math.nan
        elif math.isnan(self._since):
            self._since = m.t
        if not math.isnan(self._since) and m.t - self._since >= cfs.max_tilt_hold:
            return Phase.RETURN, f"held max_tilt {math.degrees(cfs.max_tilt):.1f} deg for {cfs.max_tilt_hold:g} s"
        return self._check_stall(m)

    def _check_stall(self, m: LiquidMeasurement) -> Transition:
        """CFS stalled: over the last max_tilt_hold s almost nothing left and the tilt hardly rose."""
        hold, history = self.config.cfs.max_tilt_hold, self._cfs_history
        history.append((m.t, m.poured_volume, self.pose.theta))
        while len(history) > 1 and m.t - history[1][0] >= hold:
            history.popleft()
        t0, poured0, tilt0 = history[0]
        if m.t - t0 < hold:
            return None
        poured, rose = m.poured_volume - poured0, self.pose.theta - tilt0
        if poured < STALL_FRACTION * self._initial_volume and rose < STALL_TILT:
            return Phase.RETURN, (
                f"outflow stalled: {1e6 * poured:.1f} mL in {hold:g} s at {math.degrees(self.pose.theta):.1f} deg, "
                f"{1e6 * m.volume_in_pourer:.1f} mL left"
            )
        return None

    def _check_return(self, m: LiquidMeasurement) -> Transition:
        """Done once the command is upright at rest and the vessel has stopped following it (it moved less than
        ARRIVAL_TOLERANCE over the last step): the pour is over when the vessel is, not its command."""
        assert self._return is not None
        if self._elapsed(m) + self.dt < self._return.duration or len(self._tilt_history) < 2:
            return None
        if abs(m.tilt - self._tilt_history[-1][2]) <= ARRIVAL_TOLERANCE:
            return Phase.DONE, "upright at home, the vessel at rest"
        return None

    # ---- actions ----------------------------------------------------------------------------------------------
    def _act_excite(self, m: LiquidMeasurement) -> PlanarPose:
        theta = excitation_tilt(self._elapsed(m), self.sim_amplitude, self.sim_frequency)
        return self.pose.rotated_about((0.0, 0.0), theta)

    def _excitation_ahead(self, m: LiquidMeasurement) -> PoseAhead:
        """The excitation's command ``tau`` s after this step (its hold at phi after the quarter period); in the
        hold, the held pose."""
        pose = self.pose
        if self.phase is Phase.SIM_HOLD:
            return lambda tau: pose
        elapsed, phi, alpha = self._elapsed(m), self.sim_amplitude, self.sim_frequency
        return lambda tau: pose.rotated_about((0.0, 0.0), excitation_tilt(elapsed + tau, phi, alpha))

    def _act_damp(self, m: LiquidMeasurement) -> PlanarPose:
        assert self._pid is not None and self._smoother is not None
        self._reference = self._damp_reference(m)
        sim = self.config.sim
        if sim.damping is Damping.PID:
            command = self._pid.step(self._reference, self._theta1)
        else:  # the same reference at the PID's rate limit, without feedback
            step = sim.max_tilt_rate * self.dt
            command = self._held_tilt = min(max(self._reference, self._held_tilt - step), self._held_tilt + step)
        return self.pose.rotated_about((0.0, 0.0), self._smoother.step(command))

    def _act_approach(self, m: LiquidMeasurement) -> PlanarPose:
        theta = self._approach.step(self._reference)
        return self.pose.rotated_about((0.0, self.model.hinge_height), theta)

    def _act_cfs(self, m: LiquidMeasurement) -> PlanarPose:
        cfs, geom, theta = self.config.cfs, self.config.vessel, self.pose.theta
        tau = cfs.head_filter_fraction * cfs.time_constant
        self._cfs_head += (1.0 - math.exp(-self.dt / tau) if tau > 0.0 else 1.0) * (m.h_q - self._cfs_head)
        step = cfs_increment(
            geom,
            theta,
            self._area(m),
            self._cfs_head,
            self._head_reference(self.phase),
            self.dt / cfs.time_constant,
            self._outflow_rate * self.dt,
            cfs.max_tilt_rate * self.dt,
        )
        pivot = cfs_pivot(geom, self.model, theta, cfs.pivot_margin)
        # no further than the crest's deepest tilt (controllers.cfs.deepest_crest_tilt) for the filtered volume left,
        # approached or, should it sink below the tilt, returned to at the rate limit
        deepest = deepest_crest_tilt(geom, geom.area(self._volume_stages[-1]))
        limit = min(cfs.max_tilt, max(deepest, theta - cfs.max_tilt_rate * self.dt))
        return self.pose.rotated_about(pivot, min(max(theta + step, 0.0), limit))

    def _act_return(self, m: LiquidMeasurement) -> PlanarPose:
        assert self._return is not None
        start = self._return_from
        theta = self._return.at(self._elapsed(m) + self.dt)
        f = min(max(theta / start.theta, 0.0), 1.0) if start.theta > 0.0 else 0.0
        return PlanarPose(start.dx * f, start.dz * f, theta)

    def _landing(self, m: LiquidMeasurement) -> float | None:
        """Predicted landing x (m, world): the measured jet (launched where v_q is measured) while liquid flows, else
        the weir estimate at h_q_ref launched at the lip;
        None (hold vessel B) once the pour is over and nothing flows."""
        flowing = m.h_q > 0.0 and m.v_q > 0.0
        if not flowing and self.phase in (Phase.RETURN, Phase.DONE):
            return None
        cfg = self.config
        if flowing:
            return landing_x(m.lip_x + m.jet_dx, m.lip_z + m.jet_dz, m.catcher_rim_z, m.v_q, m.v_q_z, cfg.gravity)
        v_weir = weir_velocity(cfg.cfs.h_q_ref, cfg.catcher.discharge_coefficient, cfg.gravity)
        return landing_x(m.lip_x, m.lip_z, m.catcher_rim_z, v_weir, 0.0, cfg.gravity)
