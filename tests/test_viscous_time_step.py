"""The artificial viscosity's time-step criterion at the planned or the measured approach speed
(``fluid.viscous_time_step``), each criterion's step (``TimeStepPlanner.limits``) and the bench's approach speed."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cosim.bench import time_step_criteria
from cosim.bench.time_step_criteria import max_approach_speed
from cosim.fluid.config import GRAVITY, FluidConfig
from cosim.fluid.time_step import VISCOUS_CFL, TimeStepPlanner, split_interval

SPACING = 0.191 / 32  # m, the default pour's
EXPECTED_SPEED = 3.3  # m/s, about the default pour's max_expected_speed


def _planner(choice: str, **kw) -> TimeStepPlanner:
    return TimeStepPlanner(FluidConfig(dim=2, spacing=SPACING, max_expected_speed=EXPECTED_SPEED, viscous_time_step=choice, **kw))


def _viscous_step(cfg: FluidConfig, approach: float) -> float:
    """0.125 h^2 / (nu + alpha h (sqrt(g h) + 2 approach) / 8), 2-D, alpha 1."""
    h = cfg.smoothing_length
    return VISCOUS_CFL * h * h / (cfg.kinematic_viscosity + h * (math.sqrt(GRAVITY * h) + 2.0 * approach) / 8.0)


def test_planned_approach_takes_two_particles_head_on_at_the_expected_speed_even_in_slow_flow():
    planner = _planner("planned_approach")
    limits = planner.limits(0.0, 0.1, GRAVITY)
    cfg = FluidConfig(dim=2, spacing=SPACING, max_expected_speed=EXPECTED_SPEED)
    assert limits.viscous == pytest.approx(_viscous_step(cfg, 2.0 * EXPECTED_SPEED), rel=1e-12)
    # just shorter than the CFL condition's 0.25 h / v: it sets the step, and a 2 ms interval takes 4 substeps, not 3
    assert limits.binding == "viscous" and 0.97 < limits.viscous / limits.advection < 1.0
    assert split_interval(0.002, limits.step)[0] == 4
    assert split_interval(0.002, min(limits.advection, limits.force))[0] == 3


def test_measured_approach_takes_the_approach_the_last_intervals_speeds_allow():
    cfg = FluidConfig(dim=2, spacing=SPACING, max_expected_speed=EXPECTED_SPEED)
    measured = _planner("measured_approach")
    slow = measured.limits(0.0, 0.1, GRAVITY)
    assert slow.viscous == pytest.approx(_viscous_step(cfg, 0.2), rel=1e-12)
    assert slow.binding == "advection"
    # a wall faster than the liquid: one particle at v_max against it
    assert measured.limits(0.5, 0.1, GRAVITY).viscous == pytest.approx(_viscous_step(cfg, 0.6), rel=1e-12)
    # the advection and force criteria are the planned setting's
    planned = _planner("planned_approach").limits(0.0, 0.1, GRAVITY)
    assert (slow.advection, slow.force) == (planned.advection, planned.force)


def test_both_settings_agree_once_the_flow_outruns_the_expected_speed():
    fast = 1.5 * EXPECTED_SPEED
    for wall in (0.0, 2.0 * fast):
        assert _planner("measured_approach").limits(wall, fast, GRAVITY) == _planner("planned_approach").limits(wall, fast, GRAVITY)


@pytest.mark.parametrize("kw", [dict(artificial_viscosity_scale="sound_speed"), dict(pressure_solver="wcsph", artificial_viscosity_beta=0.0),
                                dict(adaptive_time_step=False)])
def test_the_setting_changes_nothing_where_the_approach_speed_plays_no_part(kw):
    # c0 without an approach term (DFSPH's 'sound_speed'; WCSPH with beta = 0); the fixed step measures nothing
    for wall, speed in ((0.0, 0.1), (0.3, 1.0)):
        assert _planner("measured_approach", **kw).limits(wall, speed, GRAVITY) == _planner("planned_approach", **kw).limits(wall, speed, GRAVITY)


def test_the_step_is_the_shortest_criterion_and_the_force_criterion_can_set_it():
    limits = _planner("measured_approach").limits(0.0, 0.1, 1.0e5)
    assert limits.binding == "force"
    assert limits.step == limits.force < min(limits.advection, limits.viscous)


def test_the_pairwise_approach_speed_counts_approaching_pairs_within_the_support():
    x = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.5, 0.0, 0.0]])
    head_on = np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [-9.0, 0.0, 0.0]])  # the third is outside the support
    assert max_approach_speed(x, head_on, 0.02) == pytest.approx(2.0)
    assert max_approach_speed(x, -head_on, 0.02) == 0.0  # receding
    sideways = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 0.0, 0.0]])  # shearing past: no approach
    assert max_approach_speed(x, sideways, 0.02) == 0.0


@pytest.mark.parametrize("argv, field", [(["--approach-every", "0"], "--approach-every"), (["--duration", "-1"], "--duration"),
                                         (["--threads", "-1"], "--threads")])
def test_the_bench_refuses_bad_input_in_one_line(argv, field, capsys):
    assert time_step_criteria.main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and field in err


def test_scenes_and_the_validation_cases_take_the_setting():
    from cosim.fluid.config import ViscousTimeStep
    from cosim.pour_scene import FluidSettings
    from cosim.validation.common import NUMERICS_FIELDS

    assert FluidSettings().fluid_config(0.191).viscous_time_step is ViscousTimeStep.MEASURED_APPROACH
    planned = FluidSettings(viscous_time_step=ViscousTimeStep.PLANNED_APPROACH)
    assert planned.fluid_config(0.191).viscous_time_step is ViscousTimeStep.PLANNED_APPROACH
    assert "viscous_time_step" in NUMERICS_FIELDS


def test_dfsph_cfl_takes_the_fastest_approach_to_a_wall_or_the_expected_speed_whichever_is_larger():
    cfg = FluidConfig(dim=2, spacing=SPACING, max_expected_speed=EXPECTED_SPEED)
    planner = _planner("measured_approach")
    step = lambda signal: cfg.cfl * cfg.smoothing_length / signal  # noqa: E731
    # slow liquid in a moving vessel: the jet's expected speed is the floor, the wall's speed is not added to it
    assert planner.limits(0.3, 0.5, GRAVITY).advection == pytest.approx(step(EXPECTED_SPEED), rel=1e-12)
    # a particle at the liquid's largest speed against the fastest wall, once that outruns the floor
    assert planner.limits(1.0, 3.0, GRAVITY).advection == pytest.approx(step(4.0), rel=1e-12)
    assert planner.limits(0.0, 4.0, GRAVITY).advection == pytest.approx(step(4.0), rel=1e-12)
    # WCSPH's acoustic signal still adds the flow's and the wall's speed to c0
    wcsph = FluidConfig(dim=2, spacing=SPACING, max_expected_speed=EXPECTED_SPEED, pressure_solver="wcsph")
    acoustic = TimeStepPlanner(wcsph).limits(0.3, 0.5, GRAVITY).advection
    assert acoustic == pytest.approx(wcsph.cfl * wcsph.smoothing_length / (wcsph.sound_speed + 0.8), rel=1e-12)
