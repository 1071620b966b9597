"""The scene file's robot cell: ``[vessels]`` and ``[placement]`` build the MuJoCo bodies, the liquid's vessels and the
controller's geometry the pour uses; their defaults are the project's scene file, unchanged."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from controllers.config import CatcherConfig, PourConfig
from controllers.geometry import VesselGeometry
from controllers.slosh import VesselShape as SloshShape, first_mode_frequency
from cosim.errors import InputError
from cosim.pour_checks import check_pour, robot_scene
from cosim.pour_scene import PlacementSettings, PourScene, VesselSettings, VesselsSettings, load_scene
from cosim.robots import assets
from cosim.robots.scene_builder import scene_mjcf
from cosim.robots.scene_config import ArmRole, default_scene_config, pour_cell_config
from cosim.vessel import VesselShape, VesselSpec, default_catching_vessel, seed_pouring_vessel

SMALL_BEAKER = assets.models_dir().parent / "examples" / "small_beaker.toml"


def test_the_default_cell_is_the_project_scene_file():
    assert PourScene().cell_config() is None  # the pour loads models/scene.xml as before
    same = PourScene(vessels=VesselsSettings(VesselSettings.of(seed_pouring_vessel()), VesselSettings.of(default_catching_vessel())),
                     placement=PlacementSettings(0.75, 0.5, 0.2, 0.401))
    assert same.cell_config() is None
    config = pour_cell_config(seed_pouring_vessel(), default_catching_vessel())
    assert config == default_scene_config()
    assert scene_mjcf(config) == assets.model_path(assets.DEFAULT_SCENE).read_text()


def test_the_vessels_and_placement_of_a_scene_file_build_the_robot_cell():
    scene = load_scene(SMALL_BEAKER)
    robots = robot_scene(scene)
    pourer, catcher = robots.arms[ArmRole.POUR], robots.arms[ArmRole.CATCH]
    assert pourer.vessel == scene.vessels.pourer.spec("pourer")
    assert catcher.vessel == scene.vessels.catcher.spec("catcher")
    p = scene.placement
    assert pourer.home_pos[2] == pytest.approx(p.table_height + p.pourer_height, abs=1e-6)
    assert catcher.home_pos[0] - pourer.home_pos[0] == pytest.approx(p.catcher_home_x, abs=1e-6)
    lip_z = pourer.home_pos[2] + pourer.vessel.inner_height
    rim_z = catcher.home_pos[2] + catcher.vessel.inner_height
    assert lip_z - rim_z == pytest.approx(p.pour_height, abs=1e-6)
    model = robots.model
    for arm in (pourer, catcher):  # the MuJoCo body is the vessel: its mass and its lip site
        assert model.body_mass[arm.vessel_body] == pytest.approx(arm.vessel.mass)
        np.testing.assert_allclose(model.site_pos[arm.lip_site], arm.vessel.lip_local)
    table = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "table")
    assert model.geom_pos[table][2] + model.geom_size[table][2] == pytest.approx(p.table_height)
    plan = check_pour(scene)
    assert plan.fluid.spacing == pytest.approx(scene.vessels.pourer.inner_width / scene.fluid.particles_across)
    assert plan.fluid.depth_2d == pytest.approx(scene.vessels.pourer.inner_depth)


def test_a_cylinder_vessel_setting_is_a_cup_of_its_diameter():
    cup = VesselSettings(shape=VesselShape.CYLINDER, inner_width=0.08, inner_depth=0.3, inner_height=0.1,
                         wall_thickness=0.003, wall_density=2400.0).spec("pourer")
    assert cup.shape is VesselShape.CYLINDER and cup.section_depth == cup.inner_depth == 0.08
    assert cup.capacity == pytest.approx(math.pi * 0.04**2 * 0.1)


def test_the_liquid_section_follows_the_vessel_and_the_dimension():
    box, cup = seed_pouring_vessel(), VesselSpec("cup", VesselShape.CYLINDER, 0.08, 0.08, 0.1)
    assert box.liquid_depth(3) == box.liquid_depth(2) == box.inner_depth
    assert cup.liquid_depth(2) == 0.08  # the pour-plane slice times the diameter
    assert cup.inner_width * cup.liquid_depth(3) == pytest.approx(cup.inner_floor_area)  # the same volume at every fill
    assert [box.liquid_shape(d) for d in (2, 3)] == [VesselShape.BOX, VesselShape.BOX]
    assert [cup.liquid_shape(d) for d in (2, 3)] == [VesselShape.BOX, VesselShape.CYLINDER]


def test_the_controller_designs_on_the_slosh_mode_of_the_liquids_shape():
    catcher = CatcherConfig(home_x=0.2)
    periods = {}
    for shape in SloshShape:
        config = PourConfig(catcher=catcher, vessel=VesselGeometry(0.08, 0.1, 0.003, 0.08, shape.value), fill_depth=0.07)
        model = config.slosh_model()
        assert model.source == f"potential flow ({shape.value})"
        periods[shape] = model.period
        assert model.omega1 / (2.0 * math.pi) == pytest.approx(first_mode_frequency(0.08, 0.07, shape=shape))
    assert periods[SloshShape.CYLINDER] < periods[SloshShape.BOX]  # xi / R = 3.68 / D > pi / D: a faster mode


def test_the_dump_lists_the_vessels_and_the_placement_with_their_ranges():
    from cosim.pour_scene import dump_scene

    from cosim.pour_scene import PlacementSettings, VesselSettings
    from declared_settings.setting import declared

    text = dump_scene(PourScene())
    wall, height = declared(VesselSettings, "wall_thickness"), declared(PlacementSettings, "pour_height")
    for line in ("[vessels.pourer]", "[vessels.catcher]", "[placement]",
                 f"wall_thickness = {VesselSettings().wall_thickness} # {wall.meaning} Allowed: [0.001, 0.05] m.",
                 f"pour_height = {PlacementSettings().pour_height} # {height.meaning} Allowed: [0.05, 1] m."):
        assert line in text


@pytest.mark.parametrize("name", ["small_beaker", "cylinder_cup"])
def test_the_example_cells_pass_the_checks(name):
    scene = load_scene(SMALL_BEAKER.with_name(f"{name}.toml"))
    plan = check_pour(scene)
    pourer = plan.robots.arms[ArmRole.POUR].vessel
    assert pourer == scene.vessels.pourer.spec("pourer") and plan.particles > 0
