"""Vessels from a mesh file: loading and its checks, the derived geometry against the same box given by dimensions,
the crest, the fill volume, the liquid's walls and seeding, the inside test and the guard, the MuJoCo body."""

from __future__ import annotations

import math
import runpy
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh
import warp as wp

from cosim.errors import InputError
from cosim.fluid.config import FluidConfig, WallModel
from cosim.fluid.mesh_boundary import mesh_guard
from cosim.fluid.mesh_sampling import MeshQueries, warp_mesh
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.wall_sampling import numerical_wall_thickness, sample_vessel_walls, wetted_layer
from cosim.mesh_vessel import load_vessel_mesh
from cosim.pour_scene import load_scene
from cosim.robots.vessel_mjcf import vessel_mjcf
from cosim.vessel import VesselShape, VesselSpec, mesh_vessel_spec

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
MUG = EXAMPLES / "meshes" / "mug.obj"
BEAKER = EXAMPLES / "meshes" / "beaker.obj"
# examples/meshes/make_mug.py's beaker, by its dimensions
BEAKER_BOX = VesselSpec("pourer", VesselShape.BOX, 0.08, 0.06, 0.10, 0.003, 1180.0)


def beaker() -> VesselSpec:
    return mesh_vessel_spec("pourer", load_vessel_mesh(BEAKER), 1180.0)


def test_a_box_mesh_is_the_box_of_its_dimensions():
    vessel = beaker()
    for name in ("inner_width", "inner_depth", "inner_height", "wall_thickness"):
        assert getattr(vessel, name) == pytest.approx(getattr(BEAKER_BOX, name), rel=1e-9), name
    assert vessel.mass == pytest.approx(BEAKER_BOX.mass, rel=1e-9)
    np.testing.assert_allclose(vessel.com_local, BEAKER_BOX.com_local, atol=1e-12)
    np.testing.assert_allclose(vessel.lip_local, BEAKER_BOX.lip_local, atol=1e-12)
    assert vessel.liquid_shape(3) is VesselShape.BOX and vessel.has_closed_form(2) and vessel.has_closed_form(3)


def test_fill_volume_integrates_the_cross_section():
    vessel = beaker()
    for depth in (0.01, 0.0437, 0.1):
        assert vessel.fill_volume(depth) == pytest.approx(0.08 * 0.06 * depth, rel=1e-12)
    with pytest.raises(InputError, match="fill_depth"):
        vessel.fill_volume(0.11)
    mug = mesh_vessel_spec("pourer", load_vessel_mesh(MUG))
    polygon = 0.5 * 48 * 0.04**2 * math.sin(2 * math.pi / 48)  # the 48-gon the revolved profile makes
    # the OBJ file holds 8 decimals of a metre: its vertices are within 5e-9 m of the profile's
    assert mug.fill_volume(0.07) == pytest.approx(polygon * 0.07, rel=1e-6)
    assert mug.capacity == pytest.approx(polygon * 0.1, rel=1e-6)
    assert mug.section_depth == pytest.approx(polygon / 0.08, rel=1e-6)  # the 2-D slice holds the mug's volume
    assert mug.liquid_shape(3) is VesselShape.CYLINDER and mug.has_closed_form(2)
    flared = mesh_vessel_spec("pourer", load_vessel_mesh(EXAMPLES / "meshes" / "flared_cup.obj"))
    assert not flared.has_closed_form(2) and not flared.has_closed_form(3)  # its plant is identified from the liquid
    # a cone's frustum: V(z) = pi z (r0^2 + r0 r + r^2) / 3 with r = r0 + (r1 - r0) z / H (the 48-gon's share of it)
    r = 0.030 + 0.015 * 0.05 / 0.09
    frustum = math.pi * 0.05 * (0.030**2 + 0.030 * r + r**2) / 3 * 48 * math.sin(2 * math.pi / 48) / (2 * math.pi)
    assert flared.fill_volume(0.05) == pytest.approx(frustum, rel=1e-6)


def test_the_crest_is_the_rims_lowest_point_toward_the_pour(tmp_path):
    mesh = trimesh.load_mesh(BEAKER)
    top = np.isclose(mesh.vertices[:, 2], 0.10) & (mesh.vertices[:, 0] > 0)
    vertices = mesh.vertices.copy()
    vertices[top, 2] = 0.09  # the rim slopes down toward +x
    trimesh.Trimesh(vertices, mesh.faces).export(tmp_path / "sloped.obj")
    sloped = load_vessel_mesh(tmp_path / "sloped.obj")
    assert sloped.crest_height == pytest.approx(0.09)
    assert sloped.inner_x == pytest.approx(0.04, rel=1e-3) and sloped.lip_x == pytest.approx(0.043, rel=1e-3)
    turned = load_vessel_mesh(tmp_path / "sloped.obj", pour_direction=180.0)  # pour over the high wall: the crest is
    assert turned.crest_height == pytest.approx(0.10 - 0.01 * 0.01 / 0.08)  # where the side walls' rim meets 45 deg
    across = mesh_vessel_spec("pourer", load_vessel_mesh(BEAKER, pour_direction=90.0))  # pour over a long side
    assert across.inner_width == pytest.approx(0.06) and across.inner_depth == pytest.approx(0.08)


def _write(mesh: trimesh.Trimesh, path: Path) -> Path:
    mesh.export(path)
    return path


@pytest.mark.parametrize("case, message", [
    ("missing", "no file"),
    ("suffix", "not an OBJ or STL"),
    ("millimetres", "bounding box is [0-9.]+ m across; allowed \\[0.005, 2\\] m, the file in metres \\(in millimetres"),
    ("open", "not watertight"),
    ("closed", "has no opening"),
    ("upside_down", "has no opening"),
])
def test_bad_meshes_are_refused_naming_the_field(tmp_path, case, message):
    mug = trimesh.load_mesh(BEAKER)
    path = {
        "missing": lambda: tmp_path / "absent.obj",
        "suffix": lambda: tmp_path / "mug.ply",
        "millimetres": lambda: _write(mug.copy().apply_scale(1000.0), tmp_path / "mm.obj"),
        "open": lambda: _write(trimesh.Trimesh(mug.vertices, mug.faces[:-1]), tmp_path / "open.obj"),
        "closed": lambda: _write(trimesh.creation.box((0.1, 0.1, 0.1)), tmp_path / "closed.stl"),
        "upside_down": lambda: _write(mug.copy().apply_transform(trimesh.transformations.rotation_matrix(math.pi, [1, 0, 0])), tmp_path / "down.obj"),
    }[case]()
    with pytest.raises(InputError, match=f"^vessels.pourer.mesh: .*{message}"):
        load_vessel_mesh(path, 0.0, "vessels.pourer.mesh")


def test_a_scene_with_a_bad_mesh_exits_2_with_one_line(tmp_path):
    scene = tmp_path / "bad.toml"
    scene.write_text('[vessels.pourer]\nshape = "mesh"\nmesh = "absent.obj"\n')
    run = subprocess.run([sys.executable, "-m", "cosim", "scene", "--check", str(scene)], capture_output=True, text=True)
    assert run.returncode == 2
    assert run.stderr.strip().count("\n") == 0 and "vessels.pourer.mesh: no file" in run.stderr
    with pytest.raises(InputError, match="vessels.pourer.mesh: a file for shape 'mesh'"):
        scene.write_text('[vessels.pourer]\nshape = "mesh"\n')
        load_scene(scene)


def test_the_example_scene_loads_its_mesh_relative_to_itself():
    scene = load_scene(EXAMPLES / "mug_pour.toml")
    pourer = scene.vessels.pourer.spec("pourer")
    assert pourer.is_mesh and Path(pourer.mesh.source) == MUG
    assert pourer.inner_width == pytest.approx(0.08) and pourer.inner_height == pytest.approx(0.10)
    assert pourer.lip_local == pytest.approx([0.044, 0.0, 0.10])


def test_the_committed_meshes_are_what_the_script_makes(tmp_path):
    runpy.run_path(str(EXAMPLES / "meshes" / "make_mug.py"), run_name="not_main")["main"](tmp_path)
    for name in ("mug.obj", "beaker.obj", "flared_cup.obj"):
        assert (tmp_path / name).read_bytes() == (EXAMPLES / "meshes" / name).read_bytes()


@wp.kernel
def _guard(mesh: wp.uint64, q_old: wp.array(dtype=wp.vec3), q_new: wp.array(dtype=wp.vec3), q: wp.array(dtype=wp.vec3),
           normal: wp.array(dtype=wp.vec3), hits: wp.array(dtype=wp.int32)):
    i = wp.tid()
    qi, ni, _, hi = mesh_guard(mesh, q_old[i], q_new[i], 1.0e-4, 0.01, 3)
    q[i] = qi
    normal[i] = ni
    hits[i] = hi


def test_the_inside_test_and_the_guard_follow_the_mug():
    mug = mesh_vessel_spec("pourer", load_vessel_mesh(MUG))
    points = np.array([[0.0, 0.0, 0.05], [0.039, 0.0, 0.005], [0.04 - 2e-6, 0.0, 0.002], [0.042, 0.0, 0.05], [-0.06, 0.0, 0.05],
                       [0.0, 0.0, 0.11], [0.0, 0.0, -0.003], [0.06, 0.0, 0.05]])
    inside, _, _, solid = MeshQueries(mug).classify(points, 0.2)
    # cavity (the axis, near the wall, resting against it); wall; handle's eye; above; floor; out
    assert inside.tolist() == [True, True, True, False, False, False, False, False]
    assert solid.tolist() == [False, False, False, True, False, False, True, False]
    mesh = warp_mesh(mug.mesh.vertices, mug.mesh.faces, "cpu")
    q_old = wp.array(np.array([[0.035, 0.0, 0.05], [0.0, 0.0, 0.004], [0.0, 0.0, 0.05]], np.float32), dtype=wp.vec3, device="cpu")
    q_new = wp.array(np.array([[0.05, 0.0, 0.05], [0.0, 0.0, -0.01], [0.01, 0.0, 0.05]], np.float32), dtype=wp.vec3, device="cpu")
    q, normal, hits = (wp.zeros(3, dtype=t, device="cpu") for t in (wp.vec3, wp.vec3, wp.int32))
    wp.launch(_guard, dim=3, inputs=[mesh.id, q_old, q_new], outputs=[q, normal, hits], device="cpu")
    assert hits.numpy().tolist() == [1, 1, 0]  # through the thin side wall within one step; through the floor; free
    np.testing.assert_allclose(q.numpy()[0], [0.04 - 1e-4, 0.0, 0.05], atol=2e-4)  # back inside, the 48-gon's face
    np.testing.assert_allclose(normal.numpy()[1], [0.0, 0.0, 1.0], atol=1e-6)
    np.testing.assert_allclose(q.numpy()[1], [0.0, 0.0, 1e-4], atol=1e-6)


def test_the_box_mesh_gives_the_box_liquid_and_walls():
    cfg = FluidConfig(dim=2, spacing=0.08 / 24)
    mesh_liquid, box_liquid = fill_vessel(beaker(), 0.07, cfg), fill_vessel(BEAKER_BOX, 0.07, cfg)
    np.testing.assert_array_equal(mesh_liquid.positions, box_liquid.positions)
    for dim in (2, 3):
        cfg_dim = FluidConfig(dim=dim, spacing=cfg.spacing, wall_model=WallModel.KERNEL_LAYERS)
        walls, volumes = sample_vessel_walls(beaker(), cfg_dim)
        box_walls, _ = sample_vessel_walls(BEAKER_BOX, cfg_dim)
        assert np.all(volumes == cfg.spacing**dim)
        assert wetted_layer(beaker(), walls, cfg.spacing, dim).sum() == wetted_layer(BEAKER_BOX, box_walls, cfg.spacing, dim).sum()
        # the same layers but for the outer corners more than the layers' thickness from the cavity
        assert 0.9 * len(box_walls) < len(walls) <= len(box_walls)


@pytest.mark.parametrize("across", [24, 40])
def test_the_2d_mug_holds_the_liquid_and_floor_of_the_box_of_its_section(across):
    """In the pour plane the mug is an 80 mm box (the 48-gon has a corner there): the 2-D liquid fills its section as
    the box's fills the box (a column short, it settles with a partial top layer), and the floor's wall samples hold
    the box floor's volume, 2 b t per unit depth."""
    mug = mesh_vessel_spec("pourer", load_vessel_mesh(MUG))
    box = VesselSpec("pourer", VesselShape.BOX, 0.08, mug.section_depth, 0.10, 0.004, 1000.0)
    cfg = FluidConfig(dim=2, spacing=0.08 / across)
    np.testing.assert_array_equal(fill_vessel(mug, 0.07, cfg).positions, fill_vessel(box, 0.07, cfg).positions)
    walls, volumes = sample_vessel_walls(mug, cfg)
    floor = (walls[:, 2] < 0.0) & (np.abs(walls[:, 0]) < 0.04)
    thickness = numerical_wall_thickness(mug, cfg)
    assert volumes[floor].sum() == pytest.approx(0.08 * thickness, rel=1e-12)


def test_the_mujoco_body_weighs_the_mesh_and_collides_by_convex_parts():
    mug = mesh_vessel_spec("pourer", load_vessel_mesh(MUG), 2400.0)
    model = mujoco.MjModel.from_xml_string(vessel_mjcf(mug))
    assert model.body_mass[1] == pytest.approx(mug.mass, rel=1e-5)  # MJCF text holds 6 digits
    visual = model.geom("pourer/visual")
    assert model.geom_contype[visual.id] == 0 and model.geom_conaffinity[visual.id] == 0
    parts = [g for g in range(model.ngeom) if model.geom(g).name.startswith("pourer/part_")]
    assert len(parts) > 10 and all(model.geom_contype[g] == 1 for g in parts)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    geomid = np.zeros(1, np.int32)
    parts_only = np.array([0, 0, 0, 1, 0, 0], np.uint8)
    down = mujoco.mj_ray(model, data, np.array([0.01, 0.003, 0.2]), np.array([0.0, 0.0, -1.0]), parts_only, 1, -1, geomid)
    assert down == pytest.approx(0.2, abs=1e-6)  # a ray down the mug's middle meets the floor, not a hull over the cavity


@pytest.mark.slow
def test_the_mug_scene_builds_its_cell_and_reads_the_mesh_back():
    from cosim.pour_checks import robot_scene
    from cosim.robots.scene_config import ArmRole

    scene = load_scene(EXAMPLES / "mug_pour.toml")
    robots = robot_scene(scene)
    pourer = robots.arms[ArmRole.POUR].vessel  # parsed back from the scene's vessel record
    assert pourer.is_mesh and pourer == scene.vessels.pourer.spec("pourer")
    assert pourer.mesh.source == str(MUG) and pourer.mass == pytest.approx(scene.vessels.pourer.spec("pourer").mass)
    np.testing.assert_allclose(robots.lip_position(ArmRole.POUR) - robots.arms[ArmRole.POUR].home_pos, pourer.lip_local, atol=1e-6)


@pytest.mark.slow
def test_a_pourer_without_closed_form_takes_the_identified_plant(tmp_path):
    from dataclasses import replace

    from controllers.slosh import SloshModel
    from cosim.pour_run import prepare

    scene = load_scene(EXAMPLES / "mug_pour.toml")
    flared = replace(scene.vessels.pourer, mesh=str(EXAMPLES / "meshes" / "flared_cup.obj"))
    scene = replace(scene, vessels=replace(scene.vessels, pourer=flared))
    identified = SloshModel(0.03, 0.02, 0.05, source="SPH identification")
    calls = []

    def identify(pourer, fill, cfg):
        calls.append((pourer.mesh.source, fill, cfg.dim))
        return identified

    pour = prepare(scene, identify_plant=identify)
    assert calls == [(flared.mesh, 0.07, 2)]
    assert pour.controller.config.slosh_model() is identified
    mug = prepare(load_scene(EXAMPLES / "mug_pour.toml"), identify_plant=identify)  # a closed form: not called
    assert len(calls) == 1 and mug.controller.config.slosh is None
