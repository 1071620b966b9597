"""Imported by pytest before any test module: pins numpy's OpenBLAS kernels and keeps it on one thread before numpy
is loaded (cosim.reproducibility, cosim.blas_threads), as the cosim command does."""

import math

import pytest

from cosim.blas_threads import limit_openblas_threads
from cosim.reproducibility import pin_openblas_core

pin_openblas_core()
limit_openblas_threads()

from cosim.robots.scene import RobotScene  # noqa: E402  (after the OpenBLAS settings)
from cosim.trajectory.pour_motion import Pivot, PourMotionSpec  # noqa: E402
from cosim.trajectory.scripted import ScriptedRun, generate_scripted, pour_poses  # noqa: E402


@pytest.fixture(scope="module")
def scene() -> RobotScene:
    """The bundled two-arm robot scene, loaded once per test module (tests may change its data)."""
    return RobotScene.load()


@pytest.fixture(scope="session")
def scripted_pour_spec() -> PourMotionSpec:
    """The trajectory tests' scripted pour: 10 s, tilt 0 -> 100 deg about the lip and back, catcher 0.15 m along x."""
    return PourMotionSpec(duration=10.0, max_tilt=math.radians(100.0), pivot=Pivot.LIP, catcher_dx=0.15)


@pytest.fixture(scope="module")
def scripted_pour(scene, scripted_pour_spec) -> ScriptedRun:
    """That pour generated through the arms' trajectory generators (no liquid)."""
    return generate_scripted(scene, pour_poses(scene, scripted_pour_spec))
