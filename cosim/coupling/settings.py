"""Settings of the co-simulation (frozen, validated), each declared once (:func:`declared_settings.setting.setting`):
its check, the classes' references and ``cosim scene --dump`` come from that declaration."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from declared_settings.setting import check_settings, documented, setting


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


COUPLING = "coupling"
POSE_FILTER = "pose filter"


@documented
@dataclass(frozen=True)
class CouplingSettings:
    """The MuJoCo <-> liquid coupling and the run's length."""

    coupling: Coupling = setting(Coupling.TWO_WAY, COUPLING, "Whether the arms feel the liquid: 'two_way' applies the "
                                 "liquid's wrench on each vessel in MuJoCo (xfrc_applied); 'one_way' measures it only.")
    compensation: Compensation = setting(
        Compensation.STATIC_PAYLOAD, COUPLING, "What the arms feed forward of the liquid's load (two-way coupling "
        "only): 'static_payload', the liquid's mass and centre of mass at the start, as a UR's payload setting; "
        "'updated_payload', the same re-set every control period; 'ideal_force_torque', the measured wrench itself; "
        "'none': the servos carry the whole liquid.")
    start_delay: float = setting(0.2, COUPLING, "The controller idles this long (catcher pre-positioning) before the "
                                 "pour starts.", "s", 0.0, 10.0)
    settle_time: float = setting(1.0, COUPLING, "Time simulated after the controller reports the pour done (the last "
                                 "liquid lands).", "s", 0.0, 10.0)
    stop_when_done: bool = setting(True, COUPLING, "End the run settle_time after the pour is done (false: always run "
                                   "to max_duration).")
    max_duration: float = setting(60.0, COUPLING, "The run stops here even if the pour is not done.", "s", 0.0, 600.0,
                                  lo_open=True)

    def __post_init__(self) -> None:
        check_settings(self, "coupling")


@documented
@dataclass(frozen=True)
class PoseFilterLimits:
    """Task-space limits of the vessel targets. The defaults keep the UR10e-class joints within their limits on the
    pour paths, so that the joint generators stay on the smoothed path (the measurements: docs/tuning.md)."""

    tilt_velocity: float = setting(1.5, POSE_FILTER, "Tilt rate limit.", "rad/s", 0.0, 20.0, lo_open=True)
    tilt_acceleration: float = setting(2.5, POSE_FILTER, "Tilt acceleration limit.", "rad/s^2", 0.0, 200.0, lo_open=True)
    tilt_jerk: float = setting(20.0, POSE_FILTER, "Tilt jerk limit.", "rad/s^3", 0.0, 1e4, lo_open=True)
    translation_velocity: float = setting(0.5, POSE_FILTER, "Translation speed limit.", "m/s", 0.0, 10.0, lo_open=True)
    translation_acceleration: float = setting(1.0, POSE_FILTER, "Translation acceleration limit.", "m/s^2", 0.0, 100.0,
                                              lo_open=True)
    translation_jerk: float = setting(10.0, POSE_FILTER, "Translation jerk limit.", "m/s^3", 0.0, 1e4, lo_open=True)

    def __post_init__(self) -> None:
        check_settings(self, "pose_filter")
