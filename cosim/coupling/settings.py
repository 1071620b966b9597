"""Settings of the co-simulation (frozen, validated)."""

from __future__ import annotations

from dataclasses import dataclass

from cosim.checks import check_choice, check_positive, check_range
from enum import Enum


class Coupling(Enum):
    """Whether the arms feel the liquid."""

    TWO_WAY = "two_way"  # the liquid's wrench on each vessel goes into MuJoCo (xfrc_applied)
    ONE_WAY = "one_way"  # arms drive the vessels, the liquid's wrench is measured but not applied


class Compensation(Enum):
    """What each arm's controller knows of the liquid it holds and feeds forward (two-way coupling only); the rest of
    the liquid's wrench acts on the servos (:mod:`cosim.coupling.compensation`)."""

    STATIC_PAYLOAD = "static_payload"  # the liquid's mass and centre of mass at the start, as a UR's payload setting
    UPDATED_PAYLOAD = "updated_payload"  # the same, re-set to the liquid left every control period (UR set_payload)
    IDEAL_FORCE_TORQUE = "ideal_force_torque"  # the measured wrench itself: a perfect wrist force-torque sensor
    NONE = "none"  # nothing: the servos carry the whole liquid


@dataclass(frozen=True)
class CouplingSettings:
    """coupling: :class:`Coupling`.
    compensation: :class:`Compensation`, what the arms feed forward of the liquid's load (two-way coupling only).
    start_delay: s, the controller idles this long (catcher pre-positioning) before the pour starts. [0, 10]
    settle_time: s simulated after the controller reports the pour done (the last liquid lands). [0, 10]
    stop_when_done: end the run settle_time after the pour is done (False: always run to max_duration).
    max_duration: s, the run stops here even if the pour is not done. (0, 600]
    """

    coupling: Coupling = Coupling.TWO_WAY
    compensation: Compensation = Compensation.STATIC_PAYLOAD
    start_delay: float = 0.2
    settle_time: float = 1.0
    stop_when_done: bool = True
    max_duration: float = 120.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "coupling", check_choice("coupling.coupling", self.coupling, Coupling))
        object.__setattr__(self, "compensation", check_choice("coupling.compensation", self.compensation, Compensation))
        check_range("coupling.start_delay", self.start_delay, 0.0, 10.0, "s")
        check_range("coupling.settle_time", self.settle_time, 0.0, 10.0, "s")
        check_positive("coupling.max_duration", self.max_duration, "s", 600.0)


@dataclass(frozen=True)
class PoseFilterLimits:
    """Task-space limits of the vessel targets.

    tilt_velocity: rad/s. (0, 20]
    tilt_acceleration: rad/s^2. (0, 200]
    tilt_jerk: rad/s^3. (0, 1e4]
    translation_velocity: m/s. (0, 10]
    translation_acceleration: m/s^2. (0, 100]
    translation_jerk: m/s^3. (0, 1e4]
    Defaults keep the UR10e-class joints within their limits on the pour paths, so that the joint generators stay
    on the smoothed path: with jerk limits of 40 rad/s^3 and 20 m/s^3 a CFS path (the coupled pour's own targets,
    ``tests/test_coupling_target_tracking.py``) left the generator behind and its catch-up overshot the tilt by
    0.08 rad; with 20 and 10 it follows within 5 mrad (trajectory tests: 0.5 mm from the path for the paper's SIM
    excitation through 40 rad/s^3).
    """

    tilt_velocity: float = 1.5
    tilt_acceleration: float = 2.5
    tilt_jerk: float = 20.0
    translation_velocity: float = 0.5
    translation_acceleration: float = 1.0
    translation_jerk: float = 10.0

    def __post_init__(self) -> None:
        check_positive("pose_filter.tilt_velocity", self.tilt_velocity, "rad/s", 20.0)
        check_positive("pose_filter.tilt_acceleration", self.tilt_acceleration, "rad/s^2", 200.0)
        check_positive("pose_filter.tilt_jerk", self.tilt_jerk, "rad/s^3", 1e4)
        check_positive("pose_filter.translation_velocity", self.translation_velocity, "m/s", 10.0)
        check_positive("pose_filter.translation_acceleration", self.translation_acceleration, "m/s^2", 100.0)
        check_positive("pose_filter.translation_jerk", self.translation_jerk, "m/s^3", 1e4)
