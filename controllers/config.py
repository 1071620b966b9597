"""Configuration of the pour controller: frozen dataclasses validated on construction, closed choices as enums.

Each maps 1:1 onto a TOML table (field names are the keys, enum values the strings). Every error is one
:class:`controllers.errors.ControllerInputError` line naming the field and its allowed range. SI units, rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum

from controllers.checks import check_choice, check_range
from controllers.errors import ControllerInputError
from controllers.geometry import VesselGeometry
from controllers.pid_spec import PidDesignSpec
from controllers.slosh import GRAVITY, SloshModel, potential_flow_model


class Handover(Enum):
    """When SIM's damping phase t2 hands over to the constant-flow stage."""

    DAMPED = "damped"  # once the slosh is damped (|sigma| small for a dwell) or after the timeout
    CREST = "crest"  # the paper's rule: as soon as liquid runs over the crest (h_q > 0), else as DAMPED


class Damping(Enum):
    """What SIM's damping phase t2 does with the slosh the excitation left."""

    PID = "pid"  # the filtered PID on theta1 (controllers.pid), the paper's t2
    HOLD = "hold"  # no feedback: the tilt moves to the same reference through the same smoother and holds it, so
    # the slosh decays at the liquid's own damping (the comparison case for the PID)


class SimMode(Enum):
    """When the slosh induction method runs."""

    AUTO = "auto"  # when the fill condition holds (controllers.slosh_induction.sim_needed)
    ALWAYS = "always"
    NEVER = "never"  # plain approach tilt, then CFS (the comparison case without slosh induction)


def _check_type(name: str, value: object, kind: type) -> None:
    if not isinstance(value, kind):
        raise ControllerInputError(f"{name}: must be a {kind.__name__}, got {type(value).__name__}")


@dataclass(frozen=True)
class SimConfig:
    """Slosh induction (Camporredondo et al. 2019, Fig. 7).

    mode: :class:`SimMode`.
    trigger_angle: rad, the fill condition's tilt (the paper's: 20 deg). (0, 1.0]
    amplitude_fraction: phi as a fraction of the tilt at which the resting liquid reaches the crest. (0, 1]
      The default 0.9 leaves the static level just under the crest, so that the induced wave, not the tilt,
      starts the outflow (the point of SIM).
    frequency_ratio: alpha / omega1 of the excitation theta = phi sin(alpha t). (0, 0.5]; the paper keeps alpha
      well below the slosh resonance (its Fig. 6, left); 0.25 puts the paper's vessel at alpha = 3.2 rad/s.
    hold_timeout_periods: longest t1 hold, in slosh periods. [0.5, 10]
    damp_timeout_periods: longest t2 damping, in slosh periods. [1, 50]
    settle_tolerance: rad, |sigma| below which the slosh counts as damped. (0, 0.2]
    settle_dwell: s, how long |sigma| must stay below the tolerance before t3. [0, 5]
    max_tilt_rate: rad/s, rate limit of the PID's output. (0, 10]
    handover: :class:`Handover`. ``damped`` (the default) holds the level damp_head below the crest until the slosh
      is damped, then CFS starts the outflow from a calm liquid. ``crest`` is the paper's t3: CFS starts as the
      induced wave runs over the crest, and t2 damps toward the tilt that pours at cfs.h_q_ref; on the coupled pour
      the PID then acts for under a slosh period (docs/controller.md).
    damp_head: m, height over the crest at which t2 holds the resting liquid (negative: below the crest). The PID
      acts on the pendulum plant only while the slosh stays inside the vessel: once liquid runs over the crest, the
      crest clamps the surface and theta1 no longer follows Gp. Holding the level below the crest by the wall rise
      (B/2) tan(sigma) of the induced wave keeps it in: 5 mm is that rise for sigma = 3 deg in the paper's vessel.
      t2 then ends once the slosh is damped, and CFS starts the outflow from a calm liquid. [-0.05, 0.05]
    damping: :class:`Damping`. ``pid`` (the default) damps theta1 with the PID; ``hold`` moves to the same tilt
      reference open loop and lets the liquid's own damping act (the comparison case, docs/controller.md).
    pid: :class:`controllers.pid.PidDesignSpec`.
    """

    mode: SimMode = SimMode.AUTO
    trigger_angle: float = math.radians(20.0)
    amplitude_fraction: float = 0.9
    frequency_ratio: float = 0.25
    hold_timeout_periods: float = 1.5
    damp_timeout_periods: float = 8.0
    settle_tolerance: float = 0.01
    settle_dwell: float = 0.25
    max_tilt_rate: float = 2.0
    handover: Handover = Handover.DAMPED
    damp_head: float = -0.005
    damping: Damping = Damping.PID
    pid: PidDesignSpec = field(default_factory=PidDesignSpec)

    def __post_init__(self) -> None:
        object.__setattr__(self, "mode", check_choice("sim.mode", self.mode, SimMode))
        check_range("sim.trigger_angle", self.trigger_angle, 0.0, 1.0, "rad", lo_open=True)
        check_range("sim.amplitude_fraction", self.amplitude_fraction, 0.0, 1.0, lo_open=True)
        check_range("sim.frequency_ratio", self.frequency_ratio, 0.0, 0.5, lo_open=True)
        check_range("sim.hold_timeout_periods", self.hold_timeout_periods, 0.5, 10.0)
        check_range("sim.damp_timeout_periods", self.damp_timeout_periods, 1.0, 50.0)
        check_range("sim.settle_tolerance", self.settle_tolerance, 0.0, 0.2, "rad", lo_open=True)
        check_range("sim.settle_dwell", self.settle_dwell, 0.0, 5.0, "s")
        check_range("sim.max_tilt_rate", self.max_tilt_rate, 0.0, 10.0, "rad/s", lo_open=True)
        object.__setattr__(self, "handover", check_choice("sim.handover", self.handover, Handover))
        check_range("sim.damp_head", self.damp_head, -0.05, 0.05, "m")
        object.__setattr__(self, "damping", check_choice("sim.damping", self.damping, Damping))
        _check_type("sim.pid", self.pid, PidDesignSpec)


@dataclass(frozen=True)
class ApproachConfig:
    """Tilt toward the crest without SIM, about the pendulum's hinge (no slosh excitation to first order).

    max_rate: rad/s. (0, 2]   max_accel: rad/s^2. (0, 20]
    """

    max_rate: float = 0.15
    max_accel: float = 0.5

    def __post_init__(self) -> None:
        check_range("approach.max_rate", self.max_rate, 0.0, 2.0, "rad/s", lo_open=True)
        check_range("approach.max_accel", self.max_accel, 0.0, 20.0, "rad/s^2", lo_open=True)


CFS_MAX_HEAD = 0.05  # m, the largest liquid height over the crest CFS accepts as its reference


@dataclass(frozen=True)
class CfsConfig:
    """Constant-flow stage (Camporredondo et al. 2019, Sec. 3.2).

    h_q_ref: m, liquid height over the crest to hold (Camporredondo et al. 2019: 5 mm, about one SPH smoothing radius). [0.001, 0.05]
    time_constant: s, the error h_ref - h_q is corrected at the rate dt / time_constant per step. [0.01, 10]
    max_tilt_rate: rad/s. (0, 2]
    max_tilt: rad, largest tilt. (0, 2.5]
    empty_fraction: the pour ends as empty when the pourer holds at most this fraction of its initial volume.
      [0, 0.5]
    max_tilt_hold: s, holding max_tilt this long also ends the pour (what is left cannot be poured). [0, 60]
    pivot_margin: m, least world height of the CFS pivot above the slosh pendulum's hinge (the pivot is the lip
      while the lip is that high; see controllers.cfs). [0, 0.2] The CFS integral law damps the slosh at the rate
      m / (2 l1 time_constant): 0.1 m gives 2.7 /s in the paper's vessel, which brings the slosh SIM leaves to
      within 0.25 mm of the head reference 3 s into CFS on the pendulum plant (tests/test_controllers_pour.py).
    final_head_fraction: a partial pour holds this fraction of h_q_ref in its final stage, so that the outflow
      (and with it the after-flow the stop has to predict) is smaller when it stops; 1 disables the stage. (0, 1]
    final_stage_time: s, the final stage starts when the volume still to pour before the predicted after-flow
      would leave in this time at the current outflow rate. [0, 10]
    head_filter_fraction: the law reads the measured h_q through a first-order low-pass whose time constant is
      this fraction of time_constant (0: unfiltered). [0, 1] The SPH head carries the particles' passage over the
      crest as noise, and the law would turn each sample's noise into a tilt increment. Linearised, the integral
      law with a lag tau in its loop is tau T s^2 + T s + 1 (T = time_constant), damped at zeta = sqrt(T / tau) /
      2; the loop's lag is this filter's plus the arm's (its task-space filter and servos: 0.08-0.1 s in the
      coupled pour). zeta >= 0.7 needs their sum <= T / 2 = 0.15 s, which leaves at most 0.05 s for the filter; the
      default, 0.1 T = 0.03 s, keeps a margin for the slosh mode the law also acts on. (At 0.25 T a partial pour
      with an arm 90 ms late on the pendulum plant stopped 12 % short.)
    """

    h_q_ref: float = 0.005
    time_constant: float = 0.3
    max_tilt_rate: float = 0.35
    max_tilt: float = 1.75
    empty_fraction: float = 0.02
    max_tilt_hold: float = 3.0
    pivot_margin: float = 0.1
    final_head_fraction: float = 0.5
    final_stage_time: float = 0.8
    head_filter_fraction: float = 0.1

    def __post_init__(self) -> None:
        check_range("cfs.h_q_ref", self.h_q_ref, 0.001, CFS_MAX_HEAD, "m")
        check_range("cfs.time_constant", self.time_constant, 0.01, 10.0, "s")
        check_range("cfs.max_tilt_rate", self.max_tilt_rate, 0.0, 2.0, "rad/s", lo_open=True)
        check_range("cfs.max_tilt", self.max_tilt, 0.0, 2.5, "rad", lo_open=True)
        check_range("cfs.empty_fraction", self.empty_fraction, 0.0, 0.5)
        check_range("cfs.max_tilt_hold", self.max_tilt_hold, 0.0, 60.0, "s")
        check_range("cfs.pivot_margin", self.pivot_margin, 0.0, 0.2, "m")
        check_range("cfs.final_head_fraction", self.final_head_fraction, 0.0, 1.0, lo_open=True)
        check_range("cfs.final_stage_time", self.final_stage_time, 0.0, 10.0, "s")
        check_range("cfs.head_filter_fraction", self.head_filter_fraction, 0.0, 1.0)


@dataclass(frozen=True)
class ReturnConfig:
    """Back upright after the pour, rate-, acceleration- and jerk-limited (no back-slosh over the rim).

    max_rate: rad/s. (0, 3]   max_accel: rad/s^2, turning back. (0, 20]   max_jerk: rad/s^3. (0, 1000]
    stop_accel: rad/s^2, slowing down into upright. (0, max_accel]
    The stop is gentler than the turn so that a follower that lags the return stops with it well within its own
    limits. The arms get the path through a task-space filter that approaches each target as one to stop at, with
    limits that keep the arms' joints within theirs for a tilt alone (A = 2.5 rad/s^2, 20 rad/s^3): at rate v it
    lags by about its stopping distance L(v) = v^2 / (2 A). While the return slows at a, that lag shrinks at
    a v / A, so the follower moves at v (1 + a / A) and slows at a (1 + a / A). The return's straight line in
    (dx, dz, theta) adds a translation to the tilt, which the joints carry too, so that is held to half the tilt's
    limit: a (1 + a / A) <= A / 2, i.e. stop_accel <= (sqrt(3) - 1) / 2 A = 0.9 rad/s^2. (With the stop at 2.5 or
    1.5 rad/s^2 the follower stopped at its limits after the return had ended, and the joints, asked for more than
    their acceleration limit, followed in a catch-up.) The turn back starts from the pour's slow tilt rate, where
    the follower's lag is small; it stays as brisk as before, which the partial pour's stop prediction relies on
    (the after-flow while the crest rises over the head). The jerk: half the follower's, its lag adding to the jerk
    it needs as to the acceleration.
    """

    max_rate: float = 1.0
    max_accel: float = 2.5
    max_jerk: float = 10.0
    stop_accel: float = 0.9

    def __post_init__(self) -> None:
        check_range("returning.max_rate", self.max_rate, 0.0, 3.0, "rad/s", lo_open=True)
        check_range("returning.max_accel", self.max_accel, 0.0, 20.0, "rad/s^2", lo_open=True)
        check_range("returning.max_jerk", self.max_jerk, 0.0, 1000.0, "rad/s^3", lo_open=True)
        check_range("returning.stop_accel", self.stop_accel, 0.0, self.max_accel, "rad/s^2", lo_open=True)


@dataclass(frozen=True)
class CatcherConfig:
    """Vessel B, moved along world x under the predicted landing point.

    home_x: m, world x of vessel B's centre (its vessel-frame origin) at home. Required.
    travel_min, travel_max: m, allowed offsets from home (travel_min < 0 < travel_max is not required, but
      travel_min < travel_max is).
    max_speed: m/s. (0, 2]   max_accel: m/s^2. (0, 20]
    discharge_coefficient: C_d of the weir estimate v_q = (2/3) C_d sqrt(2 g h_q) used to place vessel B before
      the outflow starts (Camporredondo et al. 2019, Sec. 2.2: about 0.6). (0, 1]
    filter_time: s, time constant of the low-pass on vessel B's target (the predicted landing point). [0, 5]
    """

    home_x: float
    travel_min: float = -0.3
    travel_max: float = 0.3
    max_speed: float = 0.4
    max_accel: float = 1.0
    discharge_coefficient: float = 0.6
    filter_time: float = 0.2

    def __post_init__(self) -> None:
        check_range("catcher.filter_time", self.filter_time, 0.0, 5.0, "s")
        check_range("catcher.home_x", self.home_x, -10.0, 10.0, "m")
        check_range("catcher.travel_min", self.travel_min, -2.0, 2.0, "m")
        check_range("catcher.travel_max", self.travel_max, self.travel_min, 2.0, "m", lo_open=True)
        check_range("catcher.max_speed", self.max_speed, 0.0, 2.0, "m/s", lo_open=True)
        check_range("catcher.max_accel", self.max_accel, 0.0, 20.0, "m/s^2", lo_open=True)
        check_range("catcher.discharge_coefficient", self.discharge_coefficient, 0.0, 1.0, lo_open=True)


@dataclass(frozen=True)
class PourConfig:
    """The whole pour.

    catcher: :class:`CatcherConfig` (required: vessel B's home x depends on the scene).
    vessel: the pourer's :class:`controllers.geometry.VesselGeometry`.
    fill_depth: m, A, the initial liquid depth in the upright pourer. (0, vessel.inner_height)
    target_volume: m^3 to pour (partial pour), or None to pour until empty. (0, initial volume]
    control_rate: Hz, rate of :meth:`PourController.step`. [20, 500]. Default 100 Hz: five 2 ms MuJoCo steps,
      50 samples per slosh period (0.50 s for the paper's vessel), the derivative filter Tf = 27 ms spans 2.7
      samples, and the sampled SIM loop (theta1 measured one period before it acts) keeps a 52 deg phase
      margin, 13.8 dB gain margin and Ms = 1.47 (50 Hz: 43 deg, 11.6 dB, Ms = 1.70).
    start_time: s, the controller idles (vessel at home, catcher pre-positioned) until this time. [0, 60]
    gravity: m/s^2. (0, 100]
    slosh: the pourer's first-mode slosh model the controller is designed on; None: potential flow for the vessel's
      shape and fill (:func:`controllers.slosh.potential_flow_model`). Set it for a vessel with no closed form, from
      the SPH identification (``cosim validate slosh-plant``).
    """

    catcher: CatcherConfig
    vessel: VesselGeometry = field(default_factory=VesselGeometry)
    fill_depth: float = 0.1591
    target_volume: float | None = None
    control_rate: float = 100.0
    start_time: float = 0.0
    gravity: float = GRAVITY
    slosh: SloshModel | None = None
    sim: SimConfig = field(default_factory=SimConfig)
    approach: ApproachConfig = field(default_factory=ApproachConfig)
    cfs: CfsConfig = field(default_factory=CfsConfig)
    returning: ReturnConfig = field(default_factory=ReturnConfig)

    def __post_init__(self) -> None:
        for name, kind in (
            ("catcher", CatcherConfig),
            ("vessel", VesselGeometry),
            ("sim", SimConfig),
            ("approach", ApproachConfig),
            ("cfs", CfsConfig),
            ("returning", ReturnConfig),
        ):
            _check_type(f"pour.{name}", getattr(self, name), kind)
        check_range("pour.fill_depth", self.fill_depth, 0.0, self.vessel.inner_height, "m", lo_open=True, hi_open=True)
        if self.target_volume is not None:
            check_range("pour.target_volume", self.target_volume, 0.0, self.initial_volume, "m^3", lo_open=True)
        check_range("pour.control_rate", self.control_rate, 20.0, 500.0, "Hz")
        check_range("pour.start_time", self.start_time, 0.0, 60.0, "s")
        check_range("pour.gravity", self.gravity, 0.0, 100.0, "m/s^2", lo_open=True)
        if self.slosh is not None:
            _check_type("pour.slosh", self.slosh, SloshModel)

    def slosh_model(self) -> SloshModel:
        """The slosh model the controller is designed on: ``slosh`` if set, else potential flow for the vessel."""
        if self.slosh is not None:
            return self.slosh
        return potential_flow_model(self.vessel.inner_width, self.fill_depth, self.gravity, self.vessel.shape)

    @property
    def initial_volume(self) -> float:
        """m^3 of liquid in the upright pourer filled to fill_depth."""
        v = self.vessel
        return v.inner_width * v.inner_depth * self.fill_depth

    @property
    def dt(self) -> float:
        """Control period (s)."""
        return 1.0 / self.control_rate
