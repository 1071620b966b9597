"""The stress matrix: generated from its axes, stable ids, filters; the classifier flags crafted garbage; the
independent leak monitor counts crafted leaks (so neither check can pass vacuously)."""

import dataclasses
import math

import numpy as np
import pytest

from cosim.errors import InputError
from cosim.fluid.config import FluidConfig, PressureSolver
from cosim.stress.classify import DENSITY_ERROR_BOUND, ENERGY_EXCESS_BOUND, Outcome, classify
from cosim.stress.matrix import Motion, StressConfig, build_matrix, select, solver_field
from cosim.stress.runner import Measurement
from cosim.validation.scripted import LeakMonitor, WallRegions

CLEAN = Measurement(particles=100, simulated_time=0.8, steps=4000, failure="", nonfinite=0, leaked=0, worst_inside=0,
                    worst_through=0, worst_escaped=0, max_density_error=0.02, energy_excess=0.01, energy_change=0.1,
                    work_in=0.12, dt_ratio_min=0.9, guard_corrections=0, spilled_fraction=0.0, wall_time=1.0)


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
    assert len({c.across for c in configs if c.dim == 2}) == 3 and len({c.across for c in configs if c.dim == 3}) == 2


def test_config_id_is_stable_and_fluid_config_follows_the_axes():
    c = StressConfig(Motion.TILT, 5.0, 0.5, 12, 2.0, 2, "wcsph")
    assert c.id == "bdd0ac7cc31f"  # a hash of the canonical field text: the same in every process and version
    cfg = c.fluid_config()
    assert cfg.cfl == pytest.approx(2.0 * FluidConfig().cfl)
    assert cfg.spacing == pytest.approx(0.191 / 12)
    assert getattr(cfg, solver_field()) is PressureSolver.WCSPH


def test_shake_runs_at_the_first_sloshing_mode():
    c = StressConfig(Motion.SHAKE, 0.02, 0.5, 12, 1.0, 2, "wcsph")
    b, a = 0.191, 0.5 * 0.191
    omega = math.sqrt(9.81 * math.pi / b * math.tanh(math.pi * a / b))  # seed Eq. 17
    assert c.shake_omega == pytest.approx(omega)
    assert c.pose_script()(math.pi / (2 * omega)).position[0] == pytest.approx(0.02)


def test_carry_peak_speed_and_spill_bound():
    c = StressConfig(Motion.CARRY, 1.0, 0.1, 12, 1.0, 2, "wcsph")
    p = c.pose_script()
    speed = (p(0.2 + 1e-4).position[0] - p(0.2 - 1e-4).position[0]) / 2e-4
    assert speed == pytest.approx(1.0, rel=1e-3)
    assert not c.can_spill and dataclasses.replace(c, fill=0.95).can_spill


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
