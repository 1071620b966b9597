"""The liquid of a coupled scene, ready to step: the fluid solver holding the scene's two vessels at their poses in
the live MuJoCo data, the pourer filled to a depth, in the domain the pour needs (:func:`pour_fluid_config`)."""

from __future__ import annotations

from cosim.coupling.exchange import ROLES, vessel_poses
from cosim.coupling.loop import pour_fluid_config
from cosim.fluid.config import FluidConfig
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.robots.scene import RobotScene


def scene_liquid(scene: RobotScene, base: FluidConfig, fill_depth: float, device: str = "cpu") -> FluidSolver:
    """The fluid solver of ``scene`` (vessels in ``ROLES`` order at their current poses) with the pourer filled at
    rest to ``fill_depth`` m; its configuration (``.config``) is ``base`` with the scene's domain and expected
    speed."""
    config = pour_fluid_config(scene, base, fill_depth)
    vessels = [scene.arms[role].vessel for role in ROLES]
    poses = vessel_poses(scene)
    return FluidSolver(config, vessels, poses, fill_vessel(vessels[0], fill_depth, config, poses[0]), device=device)
