"""Static geometry: every visible geom is drawn with its MuJoCo size and colour, and the recorded transforms
(body pose on the timeline x static geom pose) put each geom where MuJoCo has it."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from cosim.frames import quat_wxyz_to_matrix
from cosim.io.recording import PourRecorder
from cosim.io.rerun_read import entity_paths, read_component

# m: Rerun stores translations and shapes as float32.
POS_TOL = 2e-6
# Rotation-matrix entries from float32 quaternions.
ROT_TOL = 2e-6

# Vertices of the mesh as written in the MJCF (body frame of "cup"): MuJoCo recentres them at compile time.
TET = np.array([[0.0, 0.0, 0.0], [0.06, 0.0, 0.0], [0.0, 0.04, 0.0], [0.0, 0.0, 0.05]])

MJCF = f"""
<mujoco>
  <asset>
    <mesh name="tet" vertex="{' '.join(f'{v:g}' for v in TET.ravel())}"/>
    <material name="blue" rgba="0 0 1 1"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 0.1"/>
    <body name="arm" pos="0.1 -0.2 0.5" quat="0.9238795 0 0 0.3826834">
      <joint name="shoulder" type="hinge" axis="0 1 0"/>
      <geom name="link" type="capsule" fromto="0 0 0 0.3 0 0.1" size="0.03" rgba="1 0 0 1"/>
      <geom name="ball" type="sphere" size="0.04" pos="0 0 0.1"/>
      <geom name="egg" type="ellipsoid" size="0.02 0.03 0.04" pos="0.1 0 0"/>
      <geom name="collision" type="box" size="0.1 0.1 0.1" group="3"/>
      <geom name="invisible" type="box" size="0.1 0.1 0.1" rgba="1 1 1 0"/>
      <body name="cup" pos="0.3 0 0.1" euler="0.3 0.2 0.1">
        <joint name="wrist" type="hinge" axis="1 0 0"/>
        <geom name="wall" type="box" size="0.05 0.004 0.06" pos="0 0.05 0.06" euler="0.1 0 0" material="blue"/>
        <geom name="stem" type="cylinder" fromto="0 0 0 0 0.1 0" size="0.01" group="2"/>
        <geom name="tet" type="mesh" mesh="tet" group="1"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

DRAWN = ("link", "ball", "egg", "wall", "stem", "tet")  # not the floor plane


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """(model, data, path): the scene posed at non-zero joint angles, recorded once."""
    model = mujoco.MjModel.from_xml_string(MJCF)
    data = mujoco.MjData(model)
    data.qpos[:] = [0.7, -1.1]
    mujoco.mj_forward(model, data)
    path = tmp_path_factory.mktemp("geometry") / "pour.rrd"
    with PourRecorder(path, model) as rec:
        rec.log_state(0.0, 0, data)
        assert rec.skipped_geoms == []
    return model, data, path


def _body_of(model, geom: str) -> str:
    return model.body(model.geom(geom).bodyid[0]).name


def _pose(path, entity: str) -> tuple[np.ndarray, np.ndarray]:
    """(translation, rotation matrix) logged at ``entity`` (first row)."""
    t = read_component(path, entity, "Transform3D:translation").values[0][0].astype(np.float64)
    xyzw = read_component(path, entity, "Transform3D:quaternion").values[0][0].astype(np.float64)
    return t, quat_wxyz_to_matrix(xyzw[[3, 0, 1, 2]])


def test_only_visible_geoms_are_drawn(recorded):
    model, _, path = recorded
    geoms = {p for p in entity_paths(path) if p.count("/") == 4}
    assert geoms == {f"/world/robot/{_body_of(model, g)}/{g}" for g in DRAWN}


@pytest.mark.parametrize("geom", DRAWN)
def test_body_pose_times_geom_pose_is_where_mujoco_has_the_geom(recorded, geom):
    model, data, path = recorded
    body = _body_of(model, geom)
    p_body, r_body = _pose(path, f"world/robot/{body}")
    p_geom, r_geom = _pose(path, f"world/robot/{body}/{geom}")
    g = model.geom(geom).id
    np.testing.assert_allclose(p_body + r_body @ p_geom, data.geom_xpos[g], rtol=0, atol=POS_TOL)
    np.testing.assert_allclose(r_body @ r_geom, data.geom_xmat[g].reshape(3, 3), rtol=0, atol=ROT_TOL)


def test_mesh_vertices_land_on_the_authored_vertices(recorded):
    model, data, path = recorded
    p_body, r_body = _pose(path, "world/robot/cup")
    p_geom, r_geom = _pose(path, "world/robot/cup/tet")
    local = read_component(path, "world/robot/cup/tet", "Mesh3D:vertex_positions").values[0].astype(np.float64)
    world = (local @ r_geom.T + p_geom) @ r_body.T + p_body
    cup = model.body("cup").id
    authored = TET @ data.xmat[cup].reshape(3, 3).T + data.xpos[cup]
    assert len(world) == len(authored)
    for v in authored:  # same set of points (MuJoCo may reorder vertices)
        assert np.min(np.linalg.norm(world - v, axis=1)) < POS_TOL
    faces = read_component(path, "world/robot/cup/tet", "Mesh3D:triangle_indices").values[0]
    assert faces.shape == (4, 3) and set(faces.ravel()) == {0, 1, 2, 3}


def test_shapes_have_mujoco_sizes_and_colours(recorded):
    _, _, path = recorded

    def first(entity, component):
        return read_component(path, entity, component).values[0]

    np.testing.assert_allclose(first("world/robot/cup/wall", "Boxes3D:half_sizes"), [[0.05, 0.004, 0.06]], rtol=1e-6)
    np.testing.assert_allclose(first("world/robot/arm/ball", "Ellipsoids3D:half_sizes"), [[0.04] * 3], rtol=1e-6)
    np.testing.assert_allclose(first("world/robot/arm/egg", "Ellipsoids3D:half_sizes"), [[0.02, 0.03, 0.04]], rtol=1e-6)
    # cylinder and capsule: MuJoCo size = (radius, half length); Rerun wants the full length
    np.testing.assert_allclose(first("world/robot/cup/stem", "Cylinders3D:lengths"), [0.1], rtol=1e-6)
    np.testing.assert_allclose(first("world/robot/cup/stem", "Cylinders3D:radii"), [0.01], rtol=1e-6)
    link_length = np.hypot(0.3, 0.1)
    np.testing.assert_allclose(first("world/robot/arm/link", "Capsules3D:lengths"), [link_length], rtol=1e-6)
    np.testing.assert_allclose(first("world/robot/arm/link", "Capsules3D:translations"), [[0, 0, -link_length / 2]], atol=1e-7)
    # colours are packed 0xRRGGBBAA: the material colour shows when the geom keeps MuJoCo's default rgba
    assert first("world/robot/cup/wall", "Boxes3D:colors").tolist() == [0x0000FFFF]
    assert first("world/robot/arm/link", "Capsules3D:colors").tolist() == [0xFF0000FF]
    assert first("world/robot/arm/ball", "Ellipsoids3D:colors").tolist() == [0x808080FF]


NAMESPACED = """
<mujoco>
  <asset><mesh name="ns/shell" vertex="0 0 0 0.1 0 0 0 0.1 0 0 0 0.1"/></asset>
  <worldbody>
    <geom name="ground" type="plane" size="4 4 0.1"/>
    <geom name="table" type="box" size="0.5 0.5 0.02"/>
    <body name="ns/link">
      <joint type="hinge"/>
      <geom name="ns/link_visual" type="box" size="0.1 0.1 0.1"/>
      <geom type="cylinder" size="0.01 0.02"/>
      <geom type="cylinder" size="0.01 0.03"/>
      <geom type="mesh" mesh="ns/shell"/>
      <body name="ns/link/tip">
        <joint type="hinge"/>
        <geom type="sphere" size="0.01"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_entities_are_named_after_bodies_and_geoms_without_escapes(tmp_path):
    """A body's name is its path; a geom drops the namespace it shares with its body; unnamed geoms take their mesh's
    name or their type, numbered within the body; a body holding another body's path gets ``_body``; the world body's
    geoms are the scene; the ground plane is not drawn."""
    model = mujoco.MjModel.from_xml_string(NAMESPACED)
    path = tmp_path / "pour.rrd"
    with PourRecorder(path, model) as rec:
        rec.log_state(0.0, 0, mujoco.MjData(model))
    drawn = {p for p in entity_paths(path) if p.startswith(("/world/robot/", "/world/scene/"))}
    assert drawn == {
        "/world/scene/table",
        "/world/robot/ns/link_body", "/world/robot/ns/link_body/link_visual", "/world/robot/ns/link_body/cylinder_1",
        "/world/robot/ns/link_body/cylinder_2", "/world/robot/ns/link_body/ns_shell",
        "/world/robot/ns/link/tip", "/world/robot/ns/link/tip/sphere",
    }
