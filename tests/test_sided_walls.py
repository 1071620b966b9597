"""WCSPH's 'sided' walls (``fluid.wall_model = "sided"``, cosim.fluid.wall_sampling): both the covering layers and
the vessel's own wall, the first seen only by the liquid inside the vessel, the second only by the liquid outside
it (cosim.fluid.neighbors.wall_seen). So the liquid inside moves exactly as with ``kernel_layers``, and the liquid
outside as with ``real_thickness``, the crest it leaves over included, except that a wall particle with liquid on
both faces shows each face the state extrapolated from the liquid at that face (cosim.fluid.boundary)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import warp as wp

from cosim.errors import InputError
from cosim.fluid import boundary as bd
from cosim.fluid.config import FluidConfig, WallModel
from cosim.fluid.launch import launch_now
from cosim.fluid.neighbors import SEEN_ALWAYS, SEEN_FROM_INSIDE, SEEN_FROM_OUTSIDE
from cosim.fluid.seeding import ParticleSet, fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.fluid.sph_kernels import kernel_values
from cosim.fluid.wall_sampling import numerical_wall_thickness, sample_vessel_walls, wall_model_for, wall_sides
from cosim.frames import Pose
from cosim.vessel import VesselSpec, seed_pouring_vessel

POURER = seed_pouring_vessel()
TANK = VesselSpec(name="tank", inner_width=0.06, inner_depth=0.1, inner_height=0.06, wall_thickness=0.004)
DX = 0.005


def wcsph(model: WallModel, dim: int = 2, spacing: float = DX) -> FluidConfig:
    return FluidConfig(dim=dim, spacing=spacing, pressure_solver="wcsph", wall_model=model, max_expected_speed=1.0,
                       domain_min=(-0.15, -0.1, -0.05), domain_max=(0.15, 0.1, 0.15))


@pytest.mark.parametrize("dim", [2, 3])
def test_sided_walls_are_the_covering_layers_then_the_vessels_own(dim):
    cfg = wcsph(WallModel.SIDED, dim, POURER.inner_width / 20)
    points, volumes = sample_vessel_walls(POURER, cfg)
    cover = sample_vessel_walls(POURER, replace(cfg, wall_model=WallModel.KERNEL_LAYERS))
    own = sample_vessel_walls(POURER, replace(cfg, wall_model=WallModel.REAL_THICKNESS))
    assert np.array_equal(points, np.concatenate([cover[0], own[0]]))
    assert np.array_equal(volumes, np.concatenate([cover[1], own[1]]))
    sides = wall_sides(POURER, cfg)
    assert sides.tolist() == [SEEN_FROM_INSIDE] * len(cover[0]) + [SEEN_FROM_OUTSIDE] * len(own[0])
    # the guard and the controller's lip: the vessel's own wall
    assert numerical_wall_thickness(POURER, cfg) == POURER.wall_thickness


def test_other_wall_models_are_seen_by_all_liquid():
    for model in (WallModel.KERNEL_LAYERS, WallModel.REAL_THICKNESS):
        cfg = wcsph(model)
        assert (wall_sides(TANK, cfg) == SEEN_ALWAYS).all()
        assert len(wall_sides(TANK, cfg)) == len(sample_vessel_walls(TANK, cfg)[0])


def test_a_wall_too_thin_for_a_layer_of_its_own_is_seen_from_outside_at_its_one_layer():
    """A box wall thinner than dx / 2 is 'sided' too: the liquid outside sees its one layer (at one_layer_depth,
    outside the wall), the liquid inside the covering layers."""
    thin = replace(TANK, wall_thickness=0.4 * DX)
    cfg = wcsph(WallModel.SIDED)
    assert wall_model_for(thin, cfg) is WallModel.SIDED
    sides = wall_sides(thin, cfg)
    outside = sample_vessel_walls(thin, cfg)[0][sides == SEEN_FROM_OUTSIDE]
    assert len(outside) > 0 and (sides == SEEN_FROM_INSIDE).any()
    assert np.abs(outside[:, 0]).max() == pytest.approx(0.5 * thin.inner_width + numerical_wall_thickness(thin, cfg))
    assert numerical_wall_thickness(thin, cfg) > thin.wall_thickness


def test_sided_walls_are_refused_under_dfsph():
    with pytest.raises(InputError, match="fluid.wall_model: 'sided' is for pressure_solver 'wcsph'"):
        FluidConfig(pressure_solver="dfsph", wall_model="sided")


def _run(cfg: FluidConfig, particles: ParticleSet, duration: float = 0.02) -> FluidSolver:
    solver = FluidSolver(cfg, [TANK], [Pose()], particles, device="cpu")
    solver.advance(duration)
    return solver


def test_liquid_inside_moves_as_with_the_covering_layers():
    """A resting tank: every particle inside sees the covering layers only, the same particles in the same order,
    so the run is the kernel_layers run to the bit (its wall reaction too)."""
    liquid = fill_vessel(TANK, 0.04, wcsph(WallModel.KERNEL_LAYERS))
    sided, covering = (_run(wcsph(model), liquid) for model in (WallModel.SIDED, WallModel.KERNEL_LAYERS))
    assert np.array_equal(sided.positions(), covering.positions())
    assert np.array_equal(sided.velocities(), covering.velocities())
    assert np.array_equal(sided.vessel_wrenches(), covering.vessel_wrenches())


def test_liquid_outside_moves_as_with_the_vessels_own_wall():
    """Drops beside the outer face and on the rim (outside the inner volume; the covering layers would hold them
    inside their slab), too far apart to share a wall particle, see the vessel's own wall only: the real_thickness
    run to the bit, and the wall does act on them (the run differs from the drops' without a vessel)."""
    cfg = wcsph(WallModel.SIDED)
    b, t, h = 0.5 * TANK.inner_width, TANK.wall_thickness, TANK.inner_height
    drops = np.array([[b + t + 0.6 * DX, 0.0, 0.5 * h], [b + t + 0.6 * DX, 0.0, 0.5 * h + DX],
                      [-b - 0.5 * t, 0.0, h + 0.7 * DX], [-b - 0.5 * t + DX, 0.0, h + 0.7 * DX]])
    particles = ParticleSet(drops, np.zeros_like(drops), np.full(len(drops), cfg.rest_density))
    sided, own = (_run(wcsph(model), particles) for model in (WallModel.SIDED, WallModel.REAL_THICKNESS))
    alone = FluidSolver(cfg, [], [], particles, device="cpu")
    alone.advance(0.02)
    assert np.array_equal(sided.positions(), own.positions())
    assert np.array_equal(sided.vessel_wrenches(), own.vessel_wrenches())
    assert np.abs(sided.velocities() - alone.velocities()).max() > 1e-3


def test_the_vessels_own_wall_shows_each_face_the_state_of_the_liquid_there():
    """A particle of the vessel's own wall with liquid on both faces carries two extrapolated states (Adami, Hu &
    Adams 2012): the inner face's from the liquid nearer the cavity (continued past the rim) than the wall is thick,
    the liquid inside included though it never sees the particle, so that liquid over the rim and the crest meets the
    pressure of the liquid below it; the outer face's from the liquid beyond the outer faces. Against brute force
    over the solver's own arrays, and the two differ where both faces hold liquid."""
    cfg = wcsph(WallModel.SIDED)
    b, t, h = 0.5 * TANK.inner_width, TANK.wall_thickness, TANK.inner_height
    liquid = fill_vessel(TANK, h - 0.5 * DX, cfg).positions
    over = np.array([[b - 0.5 * DX, 0.0, h + 0.6 * DX], [b + 0.5 * t, 0.0, h + 0.7 * DX], [b + t + 0.6 * DX, 0.0, h + 0.9 * DX]])
    beyond = np.array([[b + t + 0.6 * DX, 0.0, z] for z in (h - 0.5 * DX, h - 1.5 * DX, h - 2.5 * DX)])
    positions = np.concatenate([liquid, over, beyond])
    velocities = np.random.default_rng(3).normal(0.0, 0.05, positions.shape) * [1.0, 0.0, 1.0]
    solver = FluidSolver(cfg, [TANK], [Pose()], ParticleSet(positions, velocities, np.full(len(positions), cfg.rest_density)), device="cpu")
    solver.advance(1e-5)
    m, st, sh = solver.model, solver.state, solver.scratch
    n_b = m.n_boundary
    out = {name: wp.zeros(n_b, dtype=wp.vec3 if name.startswith("b_v") else float, device="cpu")
           for name in ("b_p", "b_rho", "b_v_noslip", "b_p_inner", "b_rho_inner", "b_v_noslip_inner")}
    launch_now(bd.extrapolate_wall_state, n_b, "cpu", dict(
        lane=wp.vec2i(0, 1), prm=m.params, vessels=m.vessels, b_vessel=m.b_vessel, motions=sh.motions, nb=sh.neighborhood(m, st),
        bv=sh.bv, v=st.v, rho=st.rho, p=st.p, **out))
    x, v, rho, p = (a.numpy().astype(float) for a in (st.x, st.v, st.rho, st.p))
    bx, bv = sh.bx.numpy().astype(float), sh.bv.numpy().astype(float)
    gravity = np.array([0.0, 0.0, -cfg.gravity_magnitude])
    # the liquid nearer the cavity (|x| < b over the floor, continued upward) than the wall's thickness t
    beside = np.maximum(np.abs(x[:, 0]) - b, 0.0)
    inner_face = np.hypot(beside, np.maximum(-x[:, 2], 0.0)) < t

    def extrapolated(k: int, liquid: np.ndarray) -> tuple[float, np.ndarray]:
        r = bx[k] - x
        w = np.where(liquid, kernel_values(cfg.kernel, np.linalg.norm(r, axis=1), cfg.smoothing_length, 2), 0.0)
        if w.sum() == 0.0:
            return 0.0, bv[k]
        pressure = max((w @ p + gravity @ ((w * rho) @ r)) / w.sum(), 0.0)
        return pressure, 2.0 * bv[k] - (w @ v) / w.sum()

    own = np.flatnonzero(m.b_side.numpy() == SEEN_FROM_OUTSIDE)
    both = 0
    for k in own:
        for face, liquid in (("", ~inner_face), ("_inner", inner_face)):
            pressure, v_noslip = extrapolated(k, liquid)
            assert out["b_p" + face].numpy()[k] == pytest.approx(pressure, rel=1e-4, abs=1e-3)
            assert out["b_v_noslip" + face].numpy()[k] == pytest.approx(v_noslip, rel=1e-4, abs=1e-6)
        if out["b_p"].numpy()[k] > 1.0 and out["b_p_inner"].numpy()[k] > 1.0:
            both += 1
            assert abs(out["b_p"].numpy()[k] - out["b_p_inner"].numpy()[k]) > 1.0
    assert both >= 1


def test_sided_walls_give_the_same_bits_on_two_lanes():
    """The marks of which vessel holds each particle are written by every lane for its share and read across
    shares (a wall particle's extrapolated state sums any liquid around it): two lanes give one lane's bits."""
    cfg = wcsph(WallModel.SIDED)
    liquid = fill_vessel(TANK, 0.04, cfg)
    b, t, h = 0.5 * TANK.inner_width, TANK.wall_thickness, TANK.inner_height
    drops = np.array([[b + t + 0.6 * DX, 0.0, 0.5 * h], [-b - 0.5 * t, 0.0, h + 0.7 * DX]])
    positions = np.concatenate([liquid.positions, drops])
    particles = ParticleSet(positions, np.zeros_like(positions), np.full(len(positions), cfg.rest_density))
    one, two = (_run(replace(cfg, cpu_threads=threads), particles) for threads in (1, 2))
    assert two.lanes.count == 2
    assert np.array_equal(one.positions(), two.positions())
    assert np.array_equal(one.vessel_wrenches(), two.vessel_wrenches())


def test_sided_walls_refuse_more_vessels_than_a_mark_holds():
    from cosim.fluid.model import MAX_SIDED_VESSELS

    cfg = wcsph(WallModel.SIDED)
    tanks = [TANK] * (MAX_SIDED_VESSELS + 1)
    poses = [Pose((0.0, 0.0, 0.0))] * len(tanks)
    with pytest.raises(InputError, match=f"fluid.wall_model: 'sided' walls need at most {MAX_SIDED_VESSELS} vessels"):
        FluidSolver(cfg, tanks, poses, fill_vessel(TANK, 0.02, cfg), device="cpu")
