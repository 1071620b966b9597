"""Pouring controllers: pure numpy + python-control (no warp, no MuJoCo, no cosim).

After Camporredondo et al. (2019), "A Kinematic Controller for Liquid Pouring between Vessels Modelled with
SPH": the slosh pendulum model and plant Gp (Eqs. 10-14, 17), the filtered-derivative PID compensator, the slosh
induction method (SIM) timeline, the constant-flow stage (CFS), the catcher's landing-point prediction
(Eqs. 6-7) and the pour state machine. Outputs are vessel targets (planar poses relative to home); the robot
side turns them into joint targets.

The coupling's entry point: build a :class:`PourConfig`, a :class:`PourController`, and call
``PourController.step(LiquidMeasurement) -> PourCommand`` once per ``config.dt``. Conventions (frames, the
theta1 measurement, signs) are in :mod:`controllers.measurement` and :mod:`controllers.slosh`.
"""

from controllers.config import (
    ApproachConfig,
    CatcherConfig,
    CfsConfig,
    Damping,
    Handover,
    PourConfig,
    ReturnConfig,
    SimConfig,
    SimMode,
)
from controllers.errors import ControllerInputError, MeasurementError
from controllers.geometry import PlanarPose, VesselGeometry
from controllers.measurement import LiquidMeasurement, Phase, PhaseTransition, PourCommand
from controllers.pid import PidDesignSpec
from controllers.pour import PourController
from controllers.slosh import SloshModel

__all__ = [
    "ApproachConfig",
    "CatcherConfig",
    "CfsConfig",
    "ControllerInputError",
    "Damping",
    "Handover",
    "LiquidMeasurement",
    "MeasurementError",
    "Phase",
    "PhaseTransition",
    "PidDesignSpec",
    "PlanarPose",
    "PourCommand",
    "PourConfig",
    "PourController",
    "ReturnConfig",
    "SimConfig",
    "SimMode",
    "SloshModel",
    "VesselGeometry",
]
