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

import importlib

# Each public name -> the module defining it, imported when the name is first used (PEP 562): reading a
# configuration (``controllers.config``) loads no NumPy, ruckig or python-control.
_MODULES = {
    "ApproachConfig": "controllers.config",
    "CatcherConfig": "controllers.config",
    "CfsConfig": "controllers.config",
    "Damping": "controllers.config",
    "Handover": "controllers.config",
    "PourConfig": "controllers.config",
    "ReturnConfig": "controllers.config",
    "SimConfig": "controllers.config",
    "SimMode": "controllers.config",
    "ControllerInputError": "controllers.errors",
    "MeasurementError": "controllers.errors",
    "PlanarPose": "controllers.geometry",
    "VesselGeometry": "controllers.geometry",
    "LiquidMeasurement": "controllers.measurement",
    "Phase": "controllers.measurement",
    "PhaseTransition": "controllers.measurement",
    "PourCommand": "controllers.measurement",
    "PidDesignSpec": "controllers.pid_spec",
    "PourController": "controllers.pour",
    "SloshModel": "controllers.slosh",
}
__all__ = sorted(_MODULES)


def __getattr__(name: str) -> object:
    if name not in _MODULES:
        raise AttributeError(f"module 'controllers' has no attribute {name!r}")
    return getattr(importlib.import_module(_MODULES[name]), name)
