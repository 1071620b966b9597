"""Collision check of planned motions: the pour workspace is free; a colliding motion is caught and described."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cosim.errors import InputError
from cosim.robots.collision import MotionChecker, PartKind
from cosim.robots.planar import PlanarPose, tilt_about_pivot
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole

TILTS = np.radians(np.linspace(0.0, 120.0, 41))


@pytest.fixture(scope="module")
def scene() -> RobotScene:
    return RobotScene.load()


def _tilt_path(scene: RobotScene, pivot: np.ndarray) -> np.ndarray:
    arm = scene.arms[ArmRole.POUR]
    qs, seed = [], arm.home_q
    for theta in TILTS:
        seed = scene.solve_vessel_target(ArmRole.POUR, tilt_about_pivot(arm.home_quat, pivot, theta), seed)
        qs.append(seed)
    return np.array(qs)


@pytest.mark.parametrize("pivot_name", ["bottom", "lip"])
@pytest.mark.parametrize("catcher_dx", [-0.15, 0.0, 0.15])
def test_pour_workspace_is_collision_free(scene, pivot_name, catcher_dx):
    pivot = np.zeros(3) if pivot_name == "bottom" else scene.arms[ArmRole.POUR].vessel.lip_local
    q_catch = scene.solve_vessel_target(ArmRole.CATCH, PlanarPose(dx=catcher_dx), scene.arms[ArmRole.CATCH].home_q)
    motion = {ArmRole.POUR: _tilt_path(scene, pivot), ArmRole.CATCH: np.repeat(q_catch[None], TILTS.size, axis=0)}
    hit = MotionChecker(scene).check_motion(TILTS, motion)
    assert hit is None, hit.describe()


def test_raised_catcher_collides_with_tilted_pourer(scene):
    q_catch = scene.solve_vessel_target(ArmRole.CATCH, PlanarPose(dz=0.1), scene.arms[ArmRole.CATCH].home_q)
    times = np.linspace(0.0, 4.0, TILTS.size)
    motion = {ArmRole.POUR: _tilt_path(scene, np.zeros(3)), ArmRole.CATCH: np.repeat(q_catch[None], TILTS.size, axis=0)}
    hit = MotionChecker(scene).check_motion(times, motion)
    assert hit is not None
    assert hit.kind1 is PartKind.VESSEL and hit.kind2 is PartKind.VESSEL and hit.pair == "vessel-vessel"
    assert 0.0 < hit.time < 4.0 and hit.distance < 0.0
    assert "vessel-vessel collision at t=" in hit.describe()


def test_clearance_turns_near_misses_into_collisions(scene):
    """At home nothing is within 20 mm; within 100 mm there are pairs (the wrist housings are 26 mm apart)."""
    home = {role: arm.home_q[None] for role, arm in scene.arms.items()}
    assert MotionChecker(scene).check_motion(np.zeros(1), home) is None
    assert MotionChecker(scene, clearance=0.02).check_motion(np.zeros(1), home) is None
    near = MotionChecker(scene, clearance=0.1).check_motion(np.zeros(1), home)
    assert near is not None and 0.02 <= near.distance < 0.1


def test_bad_motion_input(scene):
    with pytest.raises(InputError, match="strictly increasing"):
        MotionChecker(scene).check_motion(np.array([0.0, 0.0]), {})
    with pytest.raises(InputError, match="motion\\[pour_arm\\]"):
        MotionChecker(scene).check_motion(np.array([0.0, 1.0]), {ArmRole.POUR: np.zeros((2, 5))})
    assert math.isfinite(MotionChecker(scene).clearance)
