"""Every model file loads without warnings; generated files match their generator; the home scene is at rest."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest

from cosim.robots import assets
from cosim.tools.generate_models import generated_files
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.robots.vessel_mjcf import vessel_inertia, vessel_mjcf
from cosim.vessel import VesselSpec, default_catching_vessel, seed_pouring_vessel

# MjSpec.to_xml writes 6 significant digits: a written value is within 5e-6 (relative) of the value in memory;
# two files written from the same values agree exactly, but allow for that rounding.
MJCF_WRITE_RTOL = 5e-6
# Holding still at home under the servos with gravity compensation for 1 s: joint drift, rad (round-off level).
HOME_DRIFT_TOL = 1e-9
COMPARED_FIELDS = (
    "body_pos", "body_quat", "body_mass", "body_ipos", "body_inertia", "body_gravcomp", "geom_type", "geom_size",
    "geom_pos", "geom_quat", "site_pos", "jnt_range", "dof_armature", "actuator_gainprm", "actuator_biasprm",
    "key_qpos", "key_ctrl", "numeric_data", "exclude_signature",
)
# The home keyframe is written to 6 significant digits: joint angles to ~5e-6 rad, which moves a vessel frame by
# ~1e-6 m and turns it by ~5e-6 rad from the pose the builder solved for (m and rad).
HOME_ROUNDING_TOL = 1e-5

MODEL_FILES = sorted(p.relative_to(assets.models_dir()).as_posix() for p in assets.models_dir().rglob("*.xml"))


def test_models_directory_holds_the_expected_files():
    assert {assets.DEFAULT_SCENE, assets.UR10E_ARM, "vessels/pourer.xml", "vessels/catcher.xml"} <= set(MODEL_FILES)


@pytest.mark.parametrize("relative", MODEL_FILES)
def test_model_file_loads_and_steps_without_warnings(relative, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # MuJoCo writes warnings to MUJOCO_LOG.TXT in the working directory
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = mujoco.MjModel.from_xml_path(str(assets.models_dir() / relative))
        data = mujoco.MjData(model)
        if model.nkey:
            mujoco.mj_resetDataKeyframe(model, data, 0)
        for _ in range(50):
            mujoco.mj_step(model, data)
    assert all(w.number == 0 for w in data.warning)
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


@pytest.mark.parametrize("relative", sorted(generated_files()))
def test_committed_file_equals_generator_output(relative):
    generated = mujoco.MjModel.from_xml_string(generated_files()[relative])
    committed = mujoco.MjModel.from_xml_path(str(assets.models_dir() / relative))
    hint = "run python -m cosim.tools.generate_models"
    assert bytes(generated.names) == bytes(committed.names), f"{relative}: names differ; {hint}"
    assert bytes(generated.text_data) == bytes(committed.text_data), f"{relative}: custom text differs; {hint}"
    for name in COMPARED_FIELDS:
        a, b = getattr(generated, name), getattr(committed, name)
        assert a.shape == b.shape, f"{relative}: {name} shape differs; {hint}"
        np.testing.assert_allclose(a, b, rtol=MJCF_WRITE_RTOL, atol=1e-12, err_msg=f"{relative}: {name}")


def test_home_scene_has_no_contacts_and_holds_still(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    scene = RobotScene.load()
    assert scene.data.ncon == 0
    q0 = scene.data.qpos.copy()
    for _ in range(500):
        mujoco.mj_step(scene.model, scene.data)
    assert scene.data.ncon == 0
    assert np.max(np.abs(scene.data.qpos - q0)) < HOME_DRIFT_TOL


def test_home_vessel_poses_follow_the_conventions():
    scene = RobotScene.load()
    pourer, catcher = scene.vessel_state(ArmRole.POUR), scene.vessel_state(ArmRole.CATCH)
    for state in (pourer, catcher):
        assert abs(state.pos[1]) < HOME_ROUNDING_TOL  # in the pour plane y = 0
        np.testing.assert_allclose(np.abs(state.quat), [1.0, 0.0, 0.0, 0.0], atol=HOME_ROUNDING_TOL)  # world axes
    lip = scene.lip_position(ArmRole.POUR)
    catcher_rim = catcher.pos[2] + scene.arms[ArmRole.CATCH].vessel.inner_height
    assert catcher.pos[0] > lip[0] - scene.arms[ArmRole.CATCH].vessel.inner_width / 2  # catcher at +x, under the lip
    assert catcher_rim < pourer.pos[2]  # and below the pourer's floor


@pytest.mark.parametrize("vessel", [seed_pouring_vessel(), default_catching_vessel()])
def test_box_vessel_inertia_equals_mujoco_geom_inertia(vessel):
    """The explicit inertial (analytic sum of wall boxes) equals what MuJoCo derives from the wall geoms."""
    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body(name="v")
    body.add_freejoint()
    for wall in vessel.wall_boxes():
        body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=list(wall.half_size), pos=list(wall.center),
                      density=vessel.wall_density)
    model = spec.compile()
    explicit = mujoco.MjModel.from_xml_string(vessel_mjcf(vessel))
    assert explicit.body_mass[1] == pytest.approx(model.body_mass[1], rel=MJCF_WRITE_RTOL)
    np.testing.assert_allclose(explicit.body_ipos[1], model.body_ipos[1], rtol=MJCF_WRITE_RTOL, atol=1e-12)
    np.testing.assert_allclose(np.sort(vessel_inertia(vessel)), np.sort(model.body_inertia[1]), rtol=1e-9)


def test_cylinder_vessel_mass_and_symmetry():
    cup = VesselSpec(name="cup", shape="cylinder", inner_width=0.08, inner_height=0.1)
    model = mujoco.MjModel.from_xml_string(vessel_mjcf(cup))
    assert model.body_mass[1] == pytest.approx(cup.mass, rel=MJCF_WRITE_RTOL)
    np.testing.assert_allclose(model.body_ipos[1], cup.com_local, atol=1e-7)
    inertia = vessel_inertia(cup)
    assert inertia[0] == pytest.approx(inertia[1]) and np.all(inertia > 0.0)


def test_scene_written_to_xml_equals_the_compiled_spec():
    """The builder's spec (used directly for user arms) and its MJCF text (models/scene.xml) give the same model."""
    from cosim.robots.scene_builder import build_scene_spec

    spec = build_scene_spec()
    direct, reread = spec.compile(), mujoco.MjModel.from_xml_string(spec.to_xml())
    compared = 0
    for name in dir(direct):
        a, b = getattr(direct, name, None), getattr(reread, name, None)
        if isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and a.dtype.kind in "fiub" and a.shape == b.shape:
            np.testing.assert_allclose(a, b, rtol=MJCF_WRITE_RTOL, atol=1e-12, err_msg=name)
            compared += 1
    assert compared > 100
