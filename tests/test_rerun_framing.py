"""The 3-D view's starting camera: framed on points so that, seen through Rerun's perspective view, they are inside
the view and fill the set share of its width or height; on the pour, between the vessels, from the side opposite
the pour arm, for the default cell and for another placement (seen through :mod:`tests.support.view_projection`)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from cosim.io.rerun_framing import VIEW_FILL, frame_points, geom_box_corners
from cosim.pour_checks import robot_scene
from cosim.pour_recording import pour_camera, vessel_geoms
from cosim.pour_scene import PlacementSettings, PourScene
from cosim.robots.scene_config import ArmRole
from tests.support.view_projection import image_coordinates

TOL = 1e-9


def box_corners(lo, hi) -> np.ndarray:
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


@pytest.mark.parametrize("toward_eye", [(0.0, 1.0, 0.35), (0.0, -1.0, 0.35), (0.3, -1.0, 0.8)])
@pytest.mark.parametrize("size, binding", [((0.8, 0.1, 0.2), 0), ((0.2, 0.1, 0.7), 1)])
def test_a_box_is_inside_the_view_and_fills_it_where_it_binds(toward_eye, size, binding):
    lo = np.array([0.3, -0.2, 0.9])
    hi = lo + size
    camera = frame_points(box_corners(lo, hi), np.array(toward_eye))
    np.testing.assert_allclose(camera.target, 0.5 * (lo + hi), atol=TOL)
    direction = np.subtract(camera.eye, camera.target)
    np.testing.assert_allclose(direction / np.linalg.norm(direction), np.array(toward_eye) / np.linalg.norm(toward_eye), atol=TOL)
    extent = np.abs(image_coordinates(camera.eye, camera.target, box_corners(lo, hi))).max(axis=0)
    assert np.all(extent <= VIEW_FILL + TOL)
    assert extent[binding] == pytest.approx(VIEW_FILL, abs=1e-9)  # as near as the box allows
    assert extent[1 - binding] < VIEW_FILL


def test_scattered_points_are_inside_and_the_outermost_reaches_the_fill():
    points = np.random.default_rng(3).normal([0.1, 0.0, 1.2], [0.2, 0.05, 0.15], size=(200, 3))
    camera = frame_points(points, np.array([0.0, 1.0, 0.4]), aspect=0.85)
    np.testing.assert_allclose(camera.target, 0.5 * (points.min(axis=0) + points.max(axis=0)), atol=TOL)
    extent = np.abs(image_coordinates(camera.eye, camera.target, points, aspect=0.85)).max(axis=0)
    assert extent.max() == pytest.approx(VIEW_FILL, abs=1e-9) and np.all(extent <= VIEW_FILL + TOL)


def test_a_wider_view_leaves_a_wide_box_more_room():
    corners = box_corners(np.zeros(3), np.array([0.8, 0.1, 0.2]))
    near = frame_points(corners, np.array([0.0, 1.0, 0.3]), aspect=1.0)
    far = frame_points(corners, np.array([0.0, 1.0, 0.3]), aspect=2.0)
    assert np.linalg.norm(np.subtract(far.eye, far.target)) < np.linalg.norm(np.subtract(near.eye, near.target))


@pytest.mark.parametrize("points, toward", [([[0, 0, 0], [1, 1, np.nan]], (0, 1, 0)), (np.zeros((0, 3)), (0, 1, 0)),
                                            ([[0, 0, 0], [1, 1, 1]], (0, 0, 2))])
def test_no_points_a_bad_point_or_a_vertical_view_is_refused(points, toward):
    with pytest.raises(ValueError):
        frame_points(np.array(points, dtype=float), np.array(toward, dtype=float))


def test_box_corners_of_a_turned_geom():
    model = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body pos='1 2 3' euler='0 0 90'><geom type='box' size='.1 .2 .3'/></body></worldbody></mujoco>"
    )
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    corners = geom_box_corners(model, data, np.array([0]))
    assert corners.shape == (8, 3)
    np.testing.assert_allclose(corners.min(axis=0), [0.8, 1.9, 2.7], atol=1e-12)  # turned 90 deg: x and y swap
    np.testing.assert_allclose(corners.max(axis=0), [1.2, 2.1, 3.3], atol=1e-12)


# The default cell's vessels are about as wide as high seen from the side, and fill the view both ways; a catcher far
# and low makes them wider than high: they fill the view's width, and its height as far as their shape allows.
@pytest.mark.parametrize("placement, both_ways", [(PlacementSettings(), True),
                                                  (PlacementSettings(catcher_home_x=0.35, pour_height=0.25), False)],
                         ids=["default", "far-low-catcher"])
def test_the_pour_camera_looks_between_the_vessels_and_the_vessels_fill_the_view(placement, both_ways):
    scene = robot_scene(PourScene(placement=placement))
    mujoco.mj_forward(scene.model, scene.data)
    corners = geom_box_corners(scene.model, scene.data, vessel_geoms(scene))
    camera = pour_camera(scene, corners)
    pourer, catcher = (scene.data.site_xpos[scene.arms[r].frame_site] for r in (ArmRole.POUR, ArmRole.CATCH))
    assert catcher[0] - pourer[0] == pytest.approx(placement.catcher_home_x, abs=1e-6)
    eye, target = np.array(camera.eye), np.array(camera.target)
    assert pourer[0] < eye[0] < catcher[0] and pourer[0] < target[0] < catcher[0]
    assert catcher[2] < target[2] < pourer[2] + scene.arms[ArmRole.POUR].vessel.inner_height
    shoulder = scene.data.xpos[scene.model.jnt_bodyid[scene.model.joint(scene.arms[ArmRole.POUR].joints[0]).id]]
    assert np.sign(eye[1] - target[1]) == -np.sign(shoulder[1] - target[1])  # the arm's links do not hide the pour
    seen = image_coordinates(eye, target, corners)
    extent = np.abs(seen).max(axis=0)
    assert extent.max() == pytest.approx(VIEW_FILL, abs=1e-9) and np.all(extent <= VIEW_FILL + TOL)
    spread = (seen.max(axis=0) - seen.min(axis=0)) / 2  # shares of the view's width and height
    assert (spread.min() if both_ways else spread.max()) > 0.8, spread
