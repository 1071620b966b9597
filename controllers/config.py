"""Configuration of the pour controller: frozen dataclasses validated on construction, closed choices as enums.

Each maps 1:1 onto a TOML table (field names are the keys, enum values the strings). Each setting is declared once
(:func:`declared_settings.setting.setting`: default, unit, allowed values, meaning): its check, the class's
reference below and ``cosim scene --dump`` come from that declaration. Every error is one
:class:`controllers.errors.ControllerInputError` line naming the field and its allowed range. SI units, rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum

from controllers.errors import ControllerInputError
from controllers.geometry import VesselGeometry
from controllers.pid_spec import PidDesignSpec
from controllers.slosh import SloshModel, potential_flow_model
from declared_settings.setting import REQUIRED, check_settings, documented, like, setting


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


SIM = "slosh induction"
APPROACH = "approach"
CFS = "constant-flow stage"
RETURN = "return"
CATCHER = "catcher"
POUR = "pour"


@documented
@dataclass(frozen=True)
class SimConfig:
    """Slosh induction (Camporredondo et al. 2019, Fig. 7).

    pid: the PID design of the damping phase t2, :class:`controllers.pid_spec.PidDesignSpec`.
    """

    mode: SimMode = setting(SimMode.AUTO, SIM, "When the slosh induction method runs: 'auto' when the fill condition "
                            "holds (controllers.slosh_induction.sim_needed), 'always', or 'never' (plain approach tilt, "
                            "then CFS: the comparison case without slosh induction).")
    trigger_angle: float = setting(math.radians(20.0), SIM, "The fill condition's tilt (the paper's: 20 deg).", "rad",
                                   0.0, 1.0, lo_open=True)
    amplitude_fraction: float = setting(
        0.9, SIM, "phi as a fraction of the tilt at which the resting liquid reaches the crest. 0.9 leaves the static "
        "level just under the crest, so that the induced wave, not the tilt, starts the outflow (the point of SIM).",
        "", 0.0, 1.0, lo_open=True)
    frequency_ratio: float = setting(
        0.25, SIM, "alpha / omega1 of the excitation theta = phi sin(alpha t). The paper keeps alpha well below the "
        "slosh resonance (its Fig. 6, left); 0.25 puts the paper's vessel at alpha = 3.2 rad/s.", "", 0.0, 0.5,
        lo_open=True)
    hold_timeout_periods: float = setting(1.5, SIM, "Longest t1 hold, in slosh periods.", "", 0.5, 10.0)
    damp_timeout_periods: float = setting(8.0, SIM, "Longest t2 damping, in slosh periods.", "", 1.0, 50.0)
    settle_tolerance: float = setting(0.01, SIM, "|sigma| below which the slosh counts as damped.", "rad", 0.0, 0.2,
                                      lo_open=True)
    settle_dwell: float = setting(0.25, SIM, "How long |sigma| must stay below the tolerance before t3.", "s", 0.0, 5.0)
    max_tilt_rate: float = setting(2.0, SIM, "Rate limit of the PID's output.", "rad/s", 0.0, 10.0, lo_open=True)
    handover: Handover = setting(
        Handover.DAMPED, SIM, "When t2 hands over to CFS: 'damped' holds the level damp_head below the crest until the "
        "slosh is damped, then CFS starts the outflow from a calm liquid; 'crest' is the paper's t3: CFS starts as the "
        "induced wave runs over the crest, and t2 damps toward the tilt that pours at cfs.h_q_ref; on the coupled pour "
        "the PID then acts for under a slosh period (docs/controller.md).")
    damp_head: float = setting(
        -0.005, SIM, "Height over the crest at which t2 holds the resting liquid (negative: below the crest). The PID "
        "acts on the pendulum plant only while the slosh stays inside the vessel: once liquid runs over the crest, the "
        "crest clamps the surface and theta1 no longer follows Gp. Holding the level below the crest by the wall rise "
        "(B/2) tan(sigma) of the induced wave keeps it in: 5 mm is that rise for sigma = 3 deg in the paper's vessel.",
        "m", -0.05, 0.05)
    damping: Damping = setting(
        Damping.PID, SIM, "What t2 does with the slosh: 'pid' damps theta1 with the PID; 'hold' moves to the same tilt "
        "reference open loop and lets the liquid's own damping act (the comparison case, docs/controller.md).")
    pid: PidDesignSpec = field(default_factory=PidDesignSpec)

    def __post_init__(self) -> None:
        check_settings(self, "sim")
        _check_type("sim.pid", self.pid, PidDesignSpec)


@documented
@dataclass(frozen=True)
class ApproachConfig:
    """Tilt toward the crest without SIM, about the pendulum's hinge (no slosh excitation to first order)."""

    max_rate: float = setting(0.15, APPROACH, "Tilt rate limit.", "rad/s", 0.0, 2.0, lo_open=True)
    max_accel: float = setting(0.5, APPROACH, "Tilt acceleration limit.", "rad/s^2", 0.0, 20.0, lo_open=True)

    def __post_init__(self) -> None:
        check_settings(self, "approach")


CFS_MAX_HEAD = 0.05  # m, the largest liquid height over the crest CFS accepts as its reference


@documented
@dataclass(frozen=True)
class CfsConfig:
    """Constant-flow stage (Camporredondo et al. 2019, Sec. 3.2)."""

    h_q_ref: float = setting(0.005, CFS, "Liquid height over the crest to hold (Camporredondo et al. 2019: 5 mm, about "
                             "one SPH smoothing radius).", "m", 0.001, CFS_MAX_HEAD)
    time_constant: float = setting(0.3, CFS, "The error h_ref - h_q is corrected at the rate dt / time_constant per "
                                   "step.", "s", 0.01, 10.0)
    max_tilt_rate: float = setting(0.35, CFS, "Tilt rate limit.", "rad/s", 0.0, 2.0, lo_open=True)
    max_tilt: float = setting(1.75, CFS, "Largest tilt.", "rad", 0.0, 2.5, lo_open=True)
    empty_fraction: float = setting(0.02, CFS, "The pour ends as empty when the pourer holds at most this fraction of "
                                    "its initial volume.", "", 0.0, 0.5)
    max_tilt_hold: float = setting(3.0, CFS, "Holding max_tilt this long also ends the pour (what is left cannot be "
                                   "poured).", "s", 0.0, 60.0)
    pivot_margin: float = setting(
        0.1, CFS, "Least world height of the CFS pivot above the slosh pendulum's hinge (the pivot is the lip while the "
        "lip is that high; see controllers.cfs). The CFS integral law damps the slosh at the rate m / (2 l1 "
        "time_constant): 0.1 m gives 2.7 /s in the paper's vessel.", "m", 0.0, 0.2)
    final_head_fraction: float = setting(
        0.5, CFS, "A partial pour holds this fraction of h_q_ref in its final stage, so that the outflow (and with it "
        "the after-flow the stop has to predict) is smaller when it stops; 1 disables the stage.", "", 0.0, 1.0,
        lo_open=True)
    final_stage_time: float = setting(
        0.8, CFS, "The final stage starts when the volume still to pour before the predicted after-flow would leave in "
        "this time at the current outflow rate.", "s", 0.0, 10.0)
    head_filter_fraction: float = setting(
        0.1, CFS, "The law reads the measured h_q through a first-order low-pass whose time constant is this fraction "
        "of time_constant (0: unfiltered). The SPH head carries the particles' passage over the crest as noise, and "
        "the law would turn each sample's noise into a tilt increment. Linearised, the integral law with a lag tau in "
        "its loop is tau T s^2 + T s + 1 (T = time_constant), damped at zeta = sqrt(T / tau) / 2; the loop's lag is "
        "this filter's plus the arm's (its task-space filter and servos). zeta >= 0.7 needs their sum <= T / 2 (0.15 s "
        "at the default T), so the filter gets what the arm's lag leaves of it; 0.1 T keeps a margin for the slosh "
        "mode the law also acts on (the measured lags: docs/tuning.md).", "", 0.0, 1.0)

    def __post_init__(self) -> None:
        check_settings(self, "cfs")


@documented
@dataclass(frozen=True)
class ReturnConfig:
    """Back upright after the pour, rate-, acceleration- and jerk-limited (no back-slosh over the rim).

    The stop is gentler than the turn so that a follower that lags the return stops with it well within its own
    limits. The arms get the path through a task-space filter that approaches each target as one to stop at, with
    limits that keep the arms' joints within theirs for a tilt alone (A = 2.5 rad/s^2, 20 rad/s^3): at rate v it
    lags by about its stopping distance L(v) = v^2 / (2 A). While the return slows at a, that lag shrinks at
    a v / A, so the follower moves at v (1 + a / A) and slows at a (1 + a / A). The return's straight line in
    (dx, dz, theta) adds a translation to the tilt, which the joints carry too, so that is held to half the tilt's
    limit: a (1 + a / A) <= A / 2, i.e. stop_accel <= (sqrt(3) - 1) / 2 A = 0.9 rad/s^2. The turn back starts from
    the pour's slow tilt rate, where the follower's lag is small, and is brisk, which the partial pour's stop
    prediction relies on (the after-flow while the crest rises over the head). The jerk: half the follower's, its
    lag adding to the jerk it needs as to the acceleration.
    """

    max_rate: float = setting(1.0, RETURN, "Tilt rate limit.", "rad/s", 0.0, 3.0, lo_open=True)
    max_accel: float = setting(2.5, RETURN, "Acceleration turning back.", "rad/s^2", 0.0, 20.0, lo_open=True)
    max_jerk: float = setting(10.0, RETURN, "Jerk limit.", "rad/s^3", 0.0, 1000.0, lo_open=True)
    stop_accel: float = setting(0.9, RETURN, "Deceleration into upright.", "rad/s^2", 0.0, "max_accel", lo_open=True)

    def __post_init__(self) -> None:
        check_settings(self, "returning")


@documented
@dataclass(frozen=True)
class CatcherConfig:
    """Vessel B, moved along world x under the predicted landing point."""

    home_x: float = setting(REQUIRED, CATCHER, "World x of vessel B's centre (its vessel-frame origin) at home.", "m",
                            -10.0, 10.0)
    travel_min: float = setting(-0.3, CATCHER, "Least allowed offset from home (it need not be negative).", "m",
                                -2.0, 2.0)
    travel_max: float = setting(0.3, CATCHER, "Largest allowed offset from home.", "m", "travel_min", 2.0, lo_open=True)
    max_speed: float = setting(0.4, CATCHER, "Speed limit.", "m/s", 0.0, 2.0, lo_open=True)
    max_accel: float = setting(1.0, CATCHER, "Acceleration limit.", "m/s^2", 0.0, 20.0, lo_open=True)
    discharge_coefficient: float = setting(
        0.6, CATCHER, "C_d of the weir estimate v_q = (2/3) C_d sqrt(2 g h_q) used to place vessel B before the outflow "
        "starts (Camporredondo et al. 2019, Sec. 2.2: about 0.6).", "", 0.0, 1.0, lo_open=True)
    filter_time: float = setting(0.2, CATCHER, "Time constant of the low-pass on vessel B's target (the predicted "
                                 "landing point).", "s", 0.0, 5.0)

    def __post_init__(self) -> None:
        check_settings(self, "catcher")


@documented
@dataclass(frozen=True)
class PourConfig:
    """The whole pour.

    catcher: :class:`CatcherConfig` (required: vessel B's home x depends on the scene).
    vessel: the pourer's :class:`controllers.geometry.VesselGeometry`.
    slosh: the pourer's first-mode slosh model the controller is designed on; None: potential flow for the vessel's
      shape and fill (:func:`controllers.slosh.potential_flow_model`). Set it for a vessel with no closed form, from
      the SPH identification (``cosim validate slosh-plant``).
    """

    catcher: CatcherConfig
    vessel: VesselGeometry = field(default_factory=VesselGeometry)
    fill_depth: float = setting(0.1591, POUR, "A, the initial liquid depth in the upright pourer (the paper's).", "m",
                                0.0, "vessel.inner_height", lo_open=True, hi_open=True)
    target_volume: float | None = setting(None, POUR, "Volume to pour (a partial pour).", "m^3", 0.0,
                                          "initial_volume", lo_open=True, none_means="pour until empty")
    control_rate: float = setting(
        100.0, POUR, "Rate of PourController.step. 100 Hz is five 2 ms MuJoCo steps and 50 samples per slosh period "
        "of the paper's vessel (0.50 s). The PID is designed for the loop sampled at this rate, theta1 measured one "
        "period before it acts, so a slower rate delays the feedback and leaves the design less margin (the designs' "
        "margins: docs/controller.md).", "Hz", 20.0, 500.0)
    start_time: float = setting(0.0, POUR, "The controller idles (vessel at home, catcher pre-positioned) until this "
                                "time.", "s", 0.0, 60.0)
    gravity: float = like(SloshModel, "gravity")
    follower_lag: float | None = setting(
        None, POUR, "How late the vessel's tilt follows a ramp of its command: the lag that the partial pour's stop "
        "counts in the after-flow it predicts (controllers.cfs.after_flow_volume), known from the arm's chain (the "
        "coupled pour sets its task-space filter's, trajectory's and servos'). A delay fitted to the measured tilt "
        "reads a deflection of the vessel under the liquid's load, a static offset, as delay (offset / tilt rate); the "
        "fit is reported beside it.", "s", 0.0, 1.0,
        none_means="the delay fitted to the last 0.5 s of commanded and measured tilt (a plant without deflection)")
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
        check_settings(self, "pour")
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
