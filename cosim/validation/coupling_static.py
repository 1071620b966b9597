"""Static coupling: the pour arm holds its full vessel still; the liquid's weight must reach the arm.

Two-way coupled run at the home posture: the SPH liquid fills the pourer to ``fill``; the arms hold their home
joint targets with the measured liquid wrench fed forward (ideal force-torque compensation: the arm holds still). After ``duration`` the liquid's vertical force on the
pourer (averaged over the last ``AVERAGE_WINDOW``) is compared with the liquid's weight, and the pour arm's
actuator torques (servo + gravity compensation, ``qfrc_actuator``, averaged likewise) with those of the same
scene holding an equal rigid payload (a block of water of the liquid's mass filling the vessel to the liquid's
actual height, ``cosim.robots.payload``). The torque error is taken relative to the payload's own share of the
torques (rigid-payload torques minus empty-scene torques), the part the liquid has to supply.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import mujoco
import numpy as np

from controllers.config import PourConfig
from cosim.coupling.exchange import ROLES
from cosim.coupling.liquid import scene_liquid
from cosim.coupling.loop import coupled_step
from cosim.coupling.settings import Compensation, CouplingSettings
from cosim.fluid.config import GRAVITY, FluidConfig
from cosim.robots.payload import add_liquid_payload
from cosim.robots.scene import RobotScene
from cosim.robots.scene_builder import build_scene_spec
from cosim.robots.scene_config import ArmRole
from cosim.validation.common import CaseResult, FluidCaseParams, Metric, new_figure
from declared_settings.setting import documented, setting

# Acceptance: the reaction equals the liquid's weight within 1 %; the joint torques match the rigid-payload model
# within 2 %.
WEIGHT_TOLERANCE = 0.01
TORQUE_TOLERANCE = 0.02
AVERAGE_WINDOW = 0.1  # s at the end of the run over which forces and torques are averaged
PARTICLES_ACROSS = 24


COUPLING_STATIC = "coupling static"


@documented
@dataclass(frozen=True)
class Params(FluidCaseParams):
    """The pourer held still by its arm with the liquid at rest in it."""

    fill: float = setting(PourConfig.fill_depth, COUPLING_STATIC, "Liquid depth in the pourer.", "m", 0.0, 2.0,
                          lo_open=True)
    duration: float = setting(0.5, COUPLING_STATIC, "Time held.", "s", 0.0, 30.0, lo_open=True)

def _hold(scene: RobotScene, steps: int, window: int, step_fn) -> np.ndarray:
    """Run ``steps`` MuJoCo steps holding home; return the pour arm's mean qfrc_actuator over the last ``window``."""
    arm = scene.arms[ArmRole.POUR]
    samples = []
    for k in range(steps):
        step_fn()
        if k >= steps - window:
            samples.append(scene.data.qfrc_actuator[arm.dof_adr].copy())
    return np.mean(samples, axis=0)


def _rigid_torques(fill: float, steps: int, window: int) -> tuple[np.ndarray, np.ndarray]:
    """Pour-arm actuator torques holding home: with a rigid water block filled to ``fill`` (m), and empty."""
    out = []
    for depth in (fill, 0.0):
        spec = build_scene_spec(None)
        if depth > 0.0:
            pourer = RobotScene(spec.compile(), "probe", spec).arms[ArmRole.POUR].vessel
            spec = build_scene_spec(None)
            add_liquid_payload(spec, pourer, depth)
        scene = RobotScene(spec.compile(), "rigid payload", spec)

        def step(scene=scene) -> None:
            for role in ROLES:
                scene.set_joint_targets(role, scene.arms[role].home_q)
            mujoco.mj_step(scene.model, scene.data)

        out.append(_hold(scene, steps, window, step))
    return out[0], out[1]


def run(p: Params) -> CaseResult:
    scene = RobotScene.load()
    pourer = scene.arms[ArmRole.POUR].vessel
    spacing = p.spacing if p.spacing is not None else pourer.inner_width / PARTICLES_ACROSS
    fluid = scene_liquid(scene, FluidConfig(dim=p.dim, spacing=spacing, pressure_solver=p.solver, **dict(p.numerics)), p.fill, p.device)
    cfg = fluid.config
    settings = CouplingSettings(compensation=Compensation.IDEAL_FORCE_TORQUE)
    dt = float(scene.model.opt.timestep)
    steps = int(round(p.duration / dt))
    window = max(1, int(round(AVERAGE_WINDOW / dt)))
    state = {"wrench": np.zeros((2, 6)), "frames": None}
    forces = []
    targets = {role: (scene.arms[role].home_q, None) for role in ROLES}

    def step() -> None:
        state["wrench"], state["frames"] = coupled_step(scene, fluid, state["wrench"], targets, settings, frames=state["frames"])
        forces.append(state["wrench"][0, 2])

    start = time.perf_counter()
    tau_coupled = _hold(scene, steps, window, step)
    wall = time.perf_counter() - start
    volume = fluid.n_particles * cfg.particle_volume
    weight = volume * cfg.rest_density * GRAVITY
    reaction = -float(np.mean(forces[-window:]))
    actual_fill = volume / (pourer.inner_width * pourer.section_depth)
    tau_rigid, tau_empty = _rigid_torques(actual_fill, steps, window)
    load = tau_rigid - tau_empty
    torque_error = float(np.max(np.abs(tau_coupled - tau_rigid)) / np.max(np.abs(load)))
    joints = [j.split("/")[-1] for j in scene.arms[ArmRole.POUR].joints]
    metrics = [
        Metric("vertical reaction", reaction, weight, (reaction - weight) / weight, WEIGHT_TOLERANCE, "N"),
        Metric("joint torques vs rigid payload", float(np.max(np.abs(tau_coupled - tau_rigid))), float(np.max(np.abs(load))),
               torque_error, TORQUE_TOLERANCE, "N m"),
    ]
    raw = {
        "reaction_force_z": reaction,
        "fluid_weight": weight,
        "liquid_mass": volume * cfg.rest_density,
        "joints": joints,
        "joint_torques": tau_coupled.tolist(),
        "rigid_payload_joint_torques": tau_rigid.tolist(),
        "empty_joint_torques": tau_empty.tolist(),
        "force_z_series": forces,
        "particles": fluid.n_particles,
    }
    params = dict(fill=p.fill, spacing=spacing, dim=p.dim, device=p.device, solver=p.solver.value, duration=p.duration)
    return CaseResult("coupling-static", params, metrics, raw, wall)


def plot(result: CaseResult, path) -> None:
    fig, ax, plt = new_figure("Static coupling: pour-arm joint torques, SPH liquid vs rigid payload")
    joints = result.raw["joints"]
    x = np.arange(len(joints))
    ax.bar(x - 0.2, np.abs(result.raw["joint_torques"]), 0.4, label="coupled SPH liquid")
    ax.bar(x + 0.2, np.abs(result.raw["rigid_payload_joint_torques"]), 0.4, label="rigid payload")
    ax.set_xticks(x, joints, rotation=20)
    ax.set_ylabel("|actuator torque| (N m)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
