"""The arm's lag behind the controller's tilt command (cosim.coupling.follower_lag), against its parts and against the
arm itself driven along a ramp without liquid through the coupling's own chain (pose filter -> smoothing -> IK ->
joint generator -> servos in MuJoCo)."""

import math

import mujoco
import numpy as np
import pytest

from controllers.motion import fitted_delay
from cosim.coupling.exchange import ROLES
from cosim.coupling.follower_lag import follower_lag
from cosim.coupling.loop import TARGET_IK
from cosim.coupling.pose_filter import PoseFilter, PoseFilterLimits, PoseSmoother
from cosim.robots.ik import ArmIK
from cosim.robots.planar import PlanarPose
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.robots.vessel_mjcf import frame_site
from cosim.trajectory.generator import GeneratorSettings, TrajectoryGenerator
from cosim.trajectory.limits import scene_limits

PERIOD = 0.01  # s, the coupled pour's control period
RAMP_PERIODS = 100  # 1 s of ramp: the chain's start (its slowest pole, 35 rad/s) has died away by its last 0.5 s
WINDOW = 0.5  # s, the stop's fitting window (controllers.pour.LAG_WINDOW)
RESOLUTION = 0.001  # s, the delay grid of the fit here
# s: the no-liquid arm against the chain's lag; the fit's grid step plus what the IK's and servos' small errors
# leave (the servos follow a ramp with no steady error, the module under test).
ARM_TOLERANCE = 0.002


def _ramp_response(rate: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t, commanded tilt, measured tilt) per control period, the command a tilt ramp at ``rate`` (rad/s) from home,
    measured before each command as the coupled pour measures the liquid's vessel."""
    scene = RobotScene.load()
    dt = float(scene.model.opt.timestep)
    limits = scene_limits(scene)
    settings = GeneratorSettings(cycle_time=dt, control_period=PERIOD, stop_beyond_velocity_limit=True)
    generators = {r: TrajectoryGenerator(limits[r], scene.joint_positions(r), settings) for r in ROLES}
    arm = scene.arms[ArmRole.POUR]
    ik = ArmIK(scene.model, arm.joints, frame_site(arm.vessel), arm.home_q, TARGET_IK)
    pose_filter = PoseFilter("pourer_pose", ("dx", "dz", "theta"), PoseFilterLimits(), PERIOD)
    smoother = PoseSmoother(("dx", "dz", "theta"), PERIOD)
    q = arm.home_q
    t, commanded, measured = [], [], []
    for k in range(RAMP_PERIODS):
        w, x, y, z = scene.vessel_state(ArmRole.POUR).quat
        t.append(k * PERIOD)
        commanded.append(rate * k * PERIOD)
        measured.append(math.atan2(2 * (x * z + y * w), 1 - 2 * (x * x + y * y)))  # the tilt about world y
        pose = smoother(pose_filter(PlanarPose(0.0, 0.0, commanded[-1]), track=True), source="limited")
        q = ik.solve_or_raise(*scene.vessel_target(ArmRole.POUR, pose), q, "ramp")
        generators[ArmRole.POUR].set_target(q)
        for _ in range(round(PERIOD / dt)):
            for role in ROLES:
                scene.set_joint_targets(role, *generators[role].step()[:2])
            mujoco.mj_step(scene.model, scene.data)
    return np.array(t), np.array(commanded), np.array(measured)


def test_the_task_space_chain_follows_a_ramp_at_the_lag_less_the_spline_period() -> None:
    """The pose filter's tracking law and the smoothing stages alone: their pose at call k is for one period on, so
    it trails the ramp by the lag less the joint spline's period."""
    rate = 0.05  # rad/s
    pose_filter = PoseFilter("pourer_pose", ("dx", "dz", "theta"), PoseFilterLimits(), PERIOD)
    smoother = PoseSmoother(("dx", "dz", "theta"), PERIOD)
    for k in range(RAMP_PERIODS):
        pose = smoother(pose_filter(PlanarPose(0.0, 0.0, rate * k * PERIOD), track=True), source="limited")
    lag = (rate * RAMP_PERIODS * PERIOD - pose.theta) / rate  # behind the ramp one period after the last call
    assert lag == pytest.approx(follower_lag(PERIOD) - PERIOD, abs=1e-6)


@pytest.mark.parametrize("rate", [0.05, 0.35])  # rad/s: a partial pour's final stage; CFS's tilt rate limit
def test_the_arm_without_liquid_follows_a_ramp_at_the_lag(rate: float) -> None:
    t, commanded, measured = _ramp_response(rate)
    window = t > t[-1] - WINDOW
    fitted = fitted_delay(t[window], commanded[window], measured[window], 0.3, RESOLUTION)
    assert fitted == pytest.approx(follower_lag(PERIOD), abs=ARM_TOLERANCE)
    # the same from the mean error: the vessel is where the command was the lag ago, with no offset
    lag = np.mean(commanded[window] - measured[window]) / rate
    assert lag == pytest.approx(follower_lag(PERIOD), abs=ARM_TOLERANCE)
