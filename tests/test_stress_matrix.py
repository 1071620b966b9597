"""The stress matrix: generated from its axes, stable ids, filters; the classifier flags crafted garbage; the
independent leak monitor counts crafted leaks (so neither check can pass vacuously)."""

import dataclasses
import math

import numpy as np
import pytest

from cosim.errors import InputError
from cosim.fluid.config import FluidConfig, PressureSolver
from cosim.stress.classify import DENSITY_ERROR_BOUND, ENERGY_EXCESS_BOUND, Outcome, classify
from cosim.stress.filters import select
from cosim.stress.matrix import Motion, StressConfig, build_matrix
from cosim.validation.scripted import LeakMonitor, WallRegions
from tests.support.stress import CLEAN

def test_matrix_covers_the_required_ranges():
    configs = build_matrix()
    assert len(configs) >= 200
    assert len({c.id for c in configs}) == len(configs)
    assert max(c.level for c in configs if c.motion is Motion.TILT) == pytest.approx(5.0)  # rad/s
    assert max(c.level for c in configs if c.motion is Motion.CARRY) == pytest.approx(1.0)  # m/s
    assert any(c.motion is Motion.SHAKE for c in configs)
    assert {c.fill for c in configs} >= {0.10, 0.95}
    assert max(c.cfl_factor for c in configs) == pytest.approx(2.0)
    assert {c.dim for c in configs} == {2, 3}
    assert {c.solver for c in configs} == {s.value for s in PressureSolver}
    assert len({c.across for c in configs if c.dim == 2}) == 4 and len({c.across for c in configs if c.dim == 3}) == 2
    assert any(c.fill == 0.10 and c.layers >= 3 for c in configs)  # the lowest fill is simulated, not only refused


def test_config_id_is_stable_and_fluid_config_follows_the_axes():
    c = StressConfig(Motion.TILT, 5.0, 0.5, 12, 2.0, 2, "wcsph")
    assert c.id == "bdd0ac7cc31f"  # a hash of the canonical field text: the same in every process and version
    cfg = c.fluid_config()
    assert cfg.cfl == pytest.approx(2.0 * FluidConfig().cfl)
    assert cfg.spacing == pytest.approx(0.191 / 12)
    assert cfg.pressure_solver is PressureSolver.WCSPH
    # the settings left unset resolve for the configuration's own solver, not for the default solver's
    for solver in PressureSolver:
        own = FluidConfig(pressure_solver=solver)
        cfg = StressConfig(Motion.TILT, 5.0, 0.5, 12, 1.0, 2, solver.value).fluid_config()
        assert (cfg.alpha, cfg.free_liquid_alpha) == (own.alpha, own.free_liquid_alpha)


def test_shake_runs_at_the_first_sloshing_mode():
    c = StressConfig(Motion.SHAKE, 0.02, 0.5, 12, 1.0, 2, "wcsph")
    b, a = 0.191, 0.5 * 0.191
    omega = math.sqrt(9.81 * math.pi / b * math.tanh(math.pi * a / b))  # Eq. 17, the linear first sloshing mode
    assert c.shake_omega == pytest.approx(omega)
    assert c.pose_script()(math.pi / (2 * omega)).position[0] == pytest.approx(0.02)


def test_carry_peak_speed_and_spill_bound():
    c = StressConfig(Motion.CARRY, 1.0, 0.1, 12, 1.0, 2, "wcsph")
    p = c.pose_script()
    speed = (p(0.2 + 1e-4).position[0] - p(0.2 - 1e-4).position[0]) / 2e-4
    assert speed == pytest.approx(1.0, rel=1e-3)
    gentle = dataclasses.replace(c, level=0.25)  # a_max = 1.96 m/s^2: rise <= 5 x 0.0955 x 0.2 = 0.096 m
    assert not gentle.can_spill and dataclasses.replace(gentle, fill=0.95).can_spill and c.can_spill


def test_filter():
    configs = build_matrix()
    tilt3 = select(configs, ["motion=tilt", "dim=3", "level=5.0"])
    assert tilt3 and all(c.motion is Motion.TILT and c.dim == 3 and c.level == 5.0 for c in tilt3)
    assert select(configs, [f"id={configs[7].id}"]) == [configs[7]]
    with pytest.raises(InputError, match="FIELD"):
        select(configs, ["speed=1"])


def test_classifier():
    assert classify(CLEAN) == (Outcome.CLEAN, "")
    assert classify(dataclasses.replace(CLEAN, failure="SPH step 9: compression")) == (Outcome.INSTABILITY, "SPH step 9: compression")
    garbage = {
        "non-finite": dict(nonfinite=3),
        "leaked": dict(leaked=2, worst_through=2),
        "density error": dict(max_density_error=DENSITY_ERROR_BOUND * 1.5),
        "energy created": dict(energy_excess=ENERGY_EXCESS_BOUND * 2),
    }
    for word, change in garbage.items():
        outcome, message = classify(dataclasses.replace(CLEAN, **change))
        assert outcome is Outcome.SILENT and word in message
    assert classify(dataclasses.replace(CLEAN, max_density_error=math.nan))[0] is Outcome.SILENT


def test_leak_monitor_counts_crafted_leaks():
    regions = WallRegions(b=0.1, d=0.05, h=0.2, t=0.01, dim=2)
    start = np.array([[0.0, 0, 0.05], [0.05, 0, 0.05], [-0.05, 0, 0.05]])
    sealed = LeakMonitor.start(regions, 0.01, start, can_spill=False)
    sealed.update(np.array([[0.0, 0, 0.06], [0.105, 0, 0.05], [-0.15, 0, 0.05]]), np.ones(3, bool))
    assert (sealed.worst_inside, sealed.worst_through, sealed.worst_escaped, sealed.leaked_count) == (1, 1, 1, 2)
    spilling = LeakMonitor.start(regions, 0.01, start, can_spill=True)
    spilling.update(np.array([[0.0, 0, 0.25], [0.15, 0, 0.25], [-0.05, 0, 0.05]]), np.ones(3, bool))  # over the rim
    assert spilling.leaked_count == 0


class _CraftedSolver:
    """Stand-in for FluidSolver: two particles at rest, then whatever the test sets (energy account inputs only)."""

    def __init__(self):
        self.config = FluidConfig(dim=3, spacing=0.01)
        self.n_particles = 2
        self.x = np.array([[0.0, 0.0, 0.05], [0.01, 0.0, 0.05]])
        self.v = np.zeros((2, 3))
        self.wrench = np.zeros((1, 6))

    def positions(self):
        return self.x.copy()

    def velocities(self):
        return self.v.copy()

    def vessel_wrenches(self):
        return self.wrench.copy()

    def plan_time_step(self, duration, wall_speed):
        return 1, duration


def test_energy_account_flags_energy_no_wall_supplied_and_balances_wall_work():
    from cosim.frames import Pose
    from cosim.stress.runner import EnergyAccount
    from cosim.validation.scripted import SAMPLE_INTERVAL

    mass = 1000.0 * 0.01**3
    length = 0.2
    scale = 2 * mass * 9.81 * length
    # a particle kicked to 1 m/s by a still vessel: all of its kinetic energy is created
    s = _CraftedSolver()
    acc = EnergyAccount(np.zeros(3), length)
    acc.start(s)
    s.v[0] = (1.0, 0.0, 0.0)
    acc.sample(s, Pose(), Pose(), s.x, np.ones(2, bool))
    assert acc.excess / acc.scale == pytest.approx(0.5 * mass / scale)
    # the same kick by a vessel moving at 1 m/s that pushed with the reaction force -m dv/dt: balanced by its work
    s = _CraftedSolver()
    acc = EnergyAccount(np.zeros(3), length)
    acc.start(s)
    s.v[0] = (1.0, 0.0, 0.0)
    s.wrench[0, 0] = -0.5 * mass * 1.0**2 / (1.0 * SAMPLE_INTERVAL)  # work F v dt = kinetic energy gained
    acc.sample(s, Pose(), Pose((SAMPLE_INTERVAL * 1.0, 0.0, 0.0)), s.x, np.ones(2, bool))
    assert acc.work == pytest.approx(0.5 * mass) and acc.excess == pytest.approx(0.0, abs=1e-12)
