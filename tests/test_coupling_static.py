"""Static coupling (coarse): the held full vessel's liquid weight reaches the arm (two-way), or not (one-way)."""

import numpy as np
import pytest

from cosim.coupling.exchange import ROLES
from cosim.coupling.liquid import scene_liquid
from cosim.coupling.loop import coupled_step
from cosim.coupling.settings import Coupling, CouplingSettings
from cosim.fluid.config import FluidConfig
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.validation import coupling_static


def test_two_way_static_coupling_meets_the_acceptance_tolerances():
    r = coupling_static.run(coupling_static.Params(spacing=0.191 / 14, duration=0.3, solver="wcsph"))
    reaction, torques = r.metrics
    assert abs(reaction.error) <= coupling_static.WEIGHT_TOLERANCE
    assert abs(torques.error) <= coupling_static.TORQUE_TOLERANCE
    assert r.raw["fluid_weight"] == pytest.approx(r.raw["liquid_mass"] * 9.81)


def test_one_way_coupling_keeps_the_liquid_off_the_arm():
    scene = RobotScene.load()
    pourer = scene.arms[ArmRole.POUR].vessel
    fluid = scene_liquid(scene, FluidConfig(dim=2, spacing=pourer.inner_width / 12, pressure_solver="wcsph"), 0.15)
    cfg = fluid.config
    settings = CouplingSettings(coupling=Coupling.ONE_WAY)
    targets = {r: (scene.arms[r].home_q, None) for r in ROLES}
    wrench, frames = np.zeros((2, 6)), None
    for _ in range(50):
        wrench, frames = coupled_step(scene, fluid, wrench, targets, settings, frames=frames)
    weight = fluid.n_particles * cfg.particle_volume * 1000.0 * 9.81
    assert -wrench[0, 2] == pytest.approx(weight, rel=0.05)  # measured on the vessel ...
    body = scene.arms[ArmRole.POUR].vessel_body
    assert np.all(scene.data.xfrc_applied[body] == 0.0)  # ... but never applied to MuJoCo
