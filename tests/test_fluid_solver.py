"""Fluid solver: coarse versions of the validation cases, conservation, determinism, spilling, instability
detection and configuration errors. Tolerances are the validation cases' own named constants."""

import math

import numpy as np
import pytest

from cosim.errors import InputError, count_of
from cosim.fluid.config import FluidConfig, KernelType
from cosim.fluid.runtime import cuda_available
from cosim.fluid.seeding import ParticleSet, fill_vessel, liquid_block
from cosim.fluid.solver import FluidInstabilityError, FluidSolver
from cosim.frames import Pose, rotation_y
from cosim.validation import hydrostatic, moving_vessel, slosh
from cosim.validation.common import whole_spacings
from cosim.vessel import VesselSpec

B = 0.191  # m, the width of the pouring vessel of Camporredondo et al. (2019)


def _tank_solver(dim=2, across=12, fill=0.1, kernel=KernelType.WENDLAND_C2, device="cpu", **overrides):
    tank = VesselSpec(name="tank", inner_width=B, inner_height=0.2)
    settings = dict(pressure_solver="wcsph", max_expected_speed=2 * math.sqrt(9.81 * fill), domain_min=(-0.2, -0.15, -0.1), domain_max=(0.2, 0.15, 0.35))
    settings.update(overrides)
    cfg = FluidConfig(dim=dim, spacing=B / across, kernel=kernel, **settings)
    return FluidSolver(cfg, [tank], [Pose()], fill_vessel(tank, fill, cfg), device=device), cfg


def test_hydrostatic_coarse_2d_meets_the_acceptance_tolerances():
    r = hydrostatic.run(hydrostatic.Params(spacing=B / 16, duration=1.0, solver="wcsph"))
    by_name = {m.name: m for m in r.metrics}
    assert abs(by_name["pressure (worst probe)"].error) <= hydrostatic.PRESSURE_TOLERANCE
    assert by_name["max density error"].measured <= hydrostatic.DENSITY_ERROR_LIMIT
    assert abs(by_name["vertical reaction"].error) <= hydrostatic.WEIGHT_TOLERANCE
    assert r.raw["leaked"] == 0 and r.raw["active"] == r.raw["particles"]
    assert r.passed


# The hydrostatic law p = rho0 g (H - z) puts the free surface at H = liquid volume / floor area; the
# pressure profile's zero must sit there to a tenth of a spacing. In a 3-D tank whose depth is not a
# whole number of spacings it sat 0.2 spacings higher (the seeded lattice covered only part of the floor).
SURFACE_HEIGHT_TOLERANCE = 0.1  # particle spacings


@pytest.mark.slow
def test_static_3d_tank_weighs_its_liquid_and_stands_at_its_volume_over_the_floor():
    dx = B / 10
    r = hydrostatic.run(hydrostatic.Params(spacing=dx, duration=0.5, dim=3, solver="wcsph"))
    reaction = {m.name: m for m in r.metrics}["vertical reaction"]
    assert abs(reaction.error) <= hydrostatic.WEIGHT_TOLERANCE
    assert r.raw["leaked"] == 0
    z, pressure = np.asarray(r.raw["z"]), np.asarray(r.raw["pressure"])
    intercept, slope = np.linalg.lstsq(np.vstack([np.ones_like(z), -z]).T, pressure, rcond=None)[0]
    assert abs(intercept / slope - r.raw["liquid_height"]) <= SURFACE_HEIGHT_TOLERANCE * dx


def test_validation_tanks_are_whole_spacings_wide_and_deep():
    dx = B / 16  # 0.1 m is 8.38 of these spacings
    assert hydrostatic.Params(dim=3).tank_depth(dx) == pytest.approx(8 * dx)
    assert slosh.Params(dim=3).tank_depth(B / 24) == pytest.approx(13 * B / 24)  # 12.57 rounds up
    assert hydrostatic.Params(dim=2).tank_depth(dx) == 0.1  # 2-D: an out-of-plane scale, kept
    assert whole_spacings(B, B / 40) == B  # already whole: kept to the bit (the default resolutions)
    assert whole_spacings(B, 0.006) == pytest.approx(32 * 0.006)  # 31.8 spacings


@pytest.mark.slow
def test_hydrostatic_at_a_spacing_that_does_not_divide_the_tank():
    r = hydrostatic.run(hydrostatic.Params(spacing=0.006, duration=1.0, solver="wcsph"))  # B = 31.8 spacings: built 32 wide
    assert r.parameters["width"] == pytest.approx(32 * 0.006)
    assert abs({m.name: m for m in r.metrics}["pressure (worst probe)"].error) <= hydrostatic.PRESSURE_TOLERANCE


@pytest.mark.slow
def test_slosh_coarse_frequency_matches_eq17():
    r = slosh.run(slosh.Params(spacing=B / 16, fill=0.108, periods=3, solver="wcsph"))
    assert r.raw["periods_used"] >= 1
    assert abs(r.metrics[0].error) <= slosh.FREQUENCY_TOLERANCE


@pytest.mark.parametrize(
    "case, dim, across, rate, solver",
    [
        ("tilt", 2, 16, 60.0, "wcsph"),
        ("shake", 2, 16, 60.0, "wcsph"),
        ("tilt", 3, 8, 60.0, "wcsph"),
        ("tilt", 2, 16, 60.0, "dfsph"),
        ("shake", 2, 16, 60.0, "dfsph"),
    ],
)
@pytest.mark.slow
def test_moving_vessel_never_leaks(case, dim, across, rate, solver):
    p = moving_vessel.Params(dim=dim, particles_across=across, rate=rate, periods=2.0, solver=solver)
    r = (moving_vessel.run_tilt if case == "tilt" else moving_vessel.run_shake)(p)
    assert r.raw["failure"] == ""
    assert r.metrics[1].measured == 0, "particles inside a wall"
    assert r.metrics[2].measured == 0, "particles through a wall"
    if case == "tilt":  # tilted to 90 degrees about the lip, most of the liquid has poured out
        assert r.raw["volume_left_in_vessel"] < 0.5 * r.raw["initial_volume"]


def test_mass_and_momentum_balance_of_a_sealed_tank():
    solver, cfg = _tank_solver()
    n0 = solver.n_particles
    for _ in range(20):
        solver.advance(0.01)
    hist = solver.history()
    assert np.all(hist["active"] == n0)
    assert np.all(hist["volume_in_vessel"][:, 0] == pytest.approx(n0 * cfg.particle_volume))
    assert np.all(np.isfinite(solver.positions()))


def test_runs_are_deterministic():
    a, _ = _tank_solver()
    b, _ = _tank_solver()
    for s in (a, b):
        s.set_vessel_poses([Pose((0.0, 0.0, 0.0), rotation_y(0.05))])
        for _ in range(5):
            s.advance(0.004)
    assert np.array_equal(a.positions(), b.positions())
    assert np.array_equal(a.vessel_wrenches(), b.vessel_wrenches())


def test_particles_leaving_the_domain_are_deactivated_and_counted_as_spilled():
    cfg = FluidConfig(dim=2, spacing=0.01, pressure_solver="wcsph", max_expected_speed=2.0, domain_min=(-0.3, -0.1, 0.0), domain_max=(0.3, 0.1, 0.5))
    blob = liquid_block((-0.03, -0.05, 0.2), (0.03, 0.05, 0.26), cfg)  # free falling, no vessel
    solver = FluidSolver(cfg, [], [], blob)
    while solver.time < 0.35:
        solver.advance(0.01)
    assert not solver.active_mask().any()
    last = solver.last_report.last
    assert last.active == 0
    assert last.spilled_volume == pytest.approx(len(blob) * cfg.particle_volume)


def test_instability_is_raised_naming_the_step_and_the_cause():
    # c0 from an expected speed 100x too small: the column compresses far past the density bound
    solver, _ = _tank_solver(fill=0.15, max_expected_speed=0.05, max_density_error=0.05)
    with pytest.raises(FluidInstabilityError) as err:
        for _ in range(100):
            solver.advance(0.01)
    assert isinstance(err.value.step, int) and err.value.time > 0.0
    assert str(err.value).startswith(f"SPH step {err.value.step} ") and "compression" in str(err.value)


def test_instability_messages_count_in_words():
    # an instability message names its counts in words: "1 particle inside a vessel wall", not "1 particles"
    assert count_of(1, "particle") == "1 particle"
    assert count_of(0, "particle") == "0 particles" and count_of(40, "particle") == "40 particles"


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"spacing": -0.01}, "fluid.spacing"),
        ({"dim": 4}, "fluid.dim"),
        ({"sound_speed_factor": 5.0}, "fluid.sound_speed_factor"),
        ({"kernel": "quintic"}, "fluid.kernel"),
        ({"pressure_solver": "pcisph"}, "fluid.pressure_solver"),
        ({"density_tolerance": 0.0}, "fluid.density_tolerance"),
        ({"density_iteration": "sor"}, "fluid.density_iteration"),
        ({"gravity": (0.0, 0.0, 0.0)}, "fluid.gravity"),
        ({"max_solver_iterations": 1}, "fluid.max_solver_iterations"),
        ({"cfl": float("nan")}, "fluid.cfl"),
        ({"domain_min": (0.0, 0.0, 0.0), "domain_max": (0.01, 1.0, 1.0)}, "fluid.domain_max[0]"),
    ],
)
def test_bad_configuration_is_one_line_naming_the_field(kwargs, field):
    with pytest.raises(InputError) as err:
        FluidConfig(**kwargs)
    message = str(err.value)
    assert message.startswith(field) and "\n" not in message


def test_fill_above_the_rim_is_refused():
    tank = VesselSpec(name="tank", inner_height=0.1)
    with pytest.raises(InputError, match="fill_depth"):
        fill_vessel(tank, 0.12, FluidConfig())


@pytest.mark.cuda
@pytest.mark.skipif(not cuda_available(), reason="no CUDA device")
def test_cpu_and_cuda_agree():
    results = []
    for device in ("cpu", "cuda:0"):
        solver, _ = _tank_solver(device=device)
        solver.set_vessel_poses([Pose((0.01, 0.0, 0.0), rotation_y(0.1))])
        for _ in range(10):
            solver.advance(0.004)
        results.append((solver.positions(), solver.vessel_wrenches()))
    np.testing.assert_allclose(results[0][0], results[1][0], atol=1e-5)
    np.testing.assert_allclose(results[0][1], results[1][1], rtol=1e-3, atol=1e-4)


@pytest.mark.parametrize(
    ("solver_name", "numerics"),
    [("wcsph", {}), ("wcsph", {"free_liquid_rule": "outside_vessels"}), ("dfsph", {})],
    # WCSPH's pair list is recorded by its first walk under the free-surface rule, by its force pass under
    # 'outside_vessels' (cosim.fluid.wcsph_step.pair_recording): either must count the overflow
    ids=["wcsph", "wcsph-outside-vessels", "dfsph"],
)
def test_more_neighbours_than_the_pair_list_holds_is_an_instability(solver_name, numerics):
    # Liquid at a third of its spacing holds 9 x the neighbours of a resting lattice, more than the pair list's
    # room (cosim.fluid.sph_common.PAIR_CAPACITY_FACTOR = 2.5 x): the solver must stop with its clear error instead of
    # summing a truncated neighbourhood.
    # (a wide, tall tank: the packed liquid bursts apart in its first substep and must not reach a wall within it)
    tank = VesselSpec(name="tank", inner_width=0.6, inner_height=0.6)
    cfg = FluidConfig(dim=2, spacing=0.1 / 16, pressure_solver=solver_name, domain_min=(-0.5, -0.15, -0.1), domain_max=(0.5, 0.15, 0.8),
                      **numerics)
    side = np.arange(12) * cfg.spacing / 3.0
    xs, zs = np.meshgrid(side - side.mean(), side + 0.3)
    n = xs.size
    packed = ParticleSet(np.stack([xs.ravel(), np.zeros(n), zs.ravel()], axis=1), np.zeros((n, 3)), np.full(n, cfg.rest_density))
    fluid = FluidSolver(cfg, [tank], [Pose()], packed)
    with pytest.raises(FluidInstabilityError, match="more neighbours than the pair list holds"):
        fluid.advance(0.002)
