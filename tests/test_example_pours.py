"""The example scenes that pour at a coarse resolution in CI. The mesh mug held by a user's arm
(examples/mug_small_arm.toml and its 3-D variant: examples/meshes/mug.obj on examples/arms/small_arm.xml): the mount
plate rests on the mug's handle, the payload check weighs the mesh, both scenes pass the checks `cosim pour` runs. A
short coarse pour of each, and of the 3-D cylinder cup (examples/cylinder_cup.toml), runs."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from cosim.cli.main import main
from cosim.pour_checks import check_pour
from cosim.pour_scene import load_scene
from cosim.robots import assets
from cosim.robots.payload import LIQUID_DENSITY
from cosim.robots.scene_builder import held_side_reach
from cosim.robots.scene_config import ArmRole, MountSide, MountSpec
from tests.support.cli_refusal import refusal

EXAMPLES = assets.models_dir().parent / "examples"
MUG_ARM = EXAMPLES / "mug_small_arm.toml"


def _absolute(text: str) -> str:
    """The example's text with its mesh and arm files by their absolute paths (for a copy written elsewhere)."""
    for relative in ("meshes/mug.obj", "arms/small_arm.xml"):
        text = text.replace(f'"{relative}"', json.dumps(str(EXAMPLES / relative)))
    return text


def test_the_mount_plate_rests_on_the_mugs_handle_not_through_it():
    plan = check_pour(load_scene(MUG_ARM))
    robots = plan.robots
    model, data = robots.model, robots.data
    pour = robots.arms[ArmRole.POUR]
    mesh = pour.vessel.mesh
    plate = model.geom("pour_arm/mount_plate").id
    # The plate's far face (its +z face, toward the vessel) in the vessel frame.
    plate_rot = data.geom_xmat[plate].reshape(3, 3)
    face = data.geom_xpos[plate] + plate_rot[:, 2] * model.geom_size[plate][2]
    vessel_rot = data.xmat[pour.vessel_body].reshape(3, 3)
    face_in_vessel = vessel_rot.T @ (face - data.xpos[pour.vessel_body])
    handle_back = mesh.bounds[0, 0]  # the handle's outermost point on -x
    assert handle_back < -(0.5 * pour.vessel.inner_width + pour.vessel.wall_thickness) - 0.02  # the handle sticks out
    assert face_in_vessel[0] == pytest.approx(handle_back, abs=1e-9)
    assert np.all(mesh.vertices[:, 0] >= face_in_vessel[0] - 1e-9)  # nothing of the mug behind the plate
    catch = robots.arms[ArmRole.CATCH].vessel  # a box: its wall's outer face, as before
    assert held_side_reach(catch, MountSide.FRONT) == 0.5 * catch.inner_width + catch.wall_thickness


def test_the_payload_check_weighs_the_mesh_mug(tmp_path, capsys, monkeypatch):
    scene = load_scene(MUG_ARM)
    plan = check_pour(scene)
    mug = plan.robots.arms[ArmRole.POUR].vessel
    assert mug.mass == pytest.approx(2400.0 * mug.mesh.volume)
    mount = MountSpec()
    load = (mug.mass + LIQUID_DENSITY * mug.inner_width * mug.section_depth * scene.liquid.fill_depth
            + mount.density * (2.0 * mount.half_width) ** 2 * mount.thickness)
    monkeypatch.chdir(tmp_path)
    text = _absolute(MUG_ARM.read_text())
    for rated, refused in ((load - 0.005, True), (load + 0.005, False)):  # the load the check weighs, to 5 g
        (tmp_path / "scene.toml").write_text(text.replace("rated_payload = 5.0  # kg", f"rated_payload = {rated:.4f}"))
        if refused:
            assert refusal(capsys, ["scene", "--check", "scene.toml"], "scene") == (
                f"vessels.pourer: {load:.1f} kg with its liquid and mount, more than the arm's rated payload of "
                f"{rated:.4f} kg (a smaller or lighter vessel, or a smaller liquid.fill_depth)")
        else:
            assert main(["scene", "--check", "scene.toml"]) == 0

@pytest.mark.parametrize("name, dim", [("mug_small_arm", 2), ("mug_small_arm_3d", 3)])
def test_the_mug_on_the_small_arm_passes_the_pours_checks(name, dim):
    scene = load_scene(EXAMPLES / f"{name}.toml")
    plan = check_pour(scene)  # the cell, the payload, the reach over the whole pour, the memory and the estimate
    assert scene.fluid.dim == dim and plan.particles > 0
    for role in ArmRole:
        assert plan.limits[role].arm_model == "small_arm"
    assert plan.robots.arms[ArmRole.POUR].vessel.is_mesh


@pytest.mark.parametrize("name, arm_model", [("mug_small_arm", "small_arm"), ("mug_small_arm_3d", "small_arm"),
                                             ("cylinder_cup", "UR10e")])
def test_a_short_coarse_example_pour_runs(name, arm_model, tmp_path):
    scene = tmp_path / "short.toml"
    text = _absolute((EXAMPLES / f"{name}.toml").read_text())
    scene.write_text(re.sub(r"(?m)^particles_across = .*$", "particles_across = 8", text))
    assert main(["pour", str(scene), "--out", str(tmp_path / "run"), "--duration", "0.3", "--no-log", "--quiet"]) == 0
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    exported = json.loads((tmp_path / "run" / "trajectory.json").read_text())["arms"]
    assert exported["pour_arm"]["arm_model"] == exported["catch_arm"]["arm_model"] == arm_model
    assert summary["dim"] == load_scene(EXAMPLES / f"{name}.toml").fluid.dim
    spacing = load_scene(scene).vessels.pourer.spec("pourer").inner_width / 8
    assert summary["particle_spacing"] == pytest.approx(spacing) and summary["sim_time"] == pytest.approx(0.3, abs=0.01)
    assert summary["volume_left_in_pourer"] == pytest.approx(summary["initial_volume"])  # still upright: all inside
