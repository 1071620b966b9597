"""Static Rerun geometry of a MuJoCo model: one shape per visible geom, in its body's frame.

Each geom becomes the entity ``world/robot/<body>/<geom>`` holding a static Transform3D (geom frame -> body frame:
``model.geom_pos`` m, ``model.geom_quat``) and the geom's shape in its own frame, coloured like MuJoCo colours it
(``geom_rgba``, or the material's ``mat_rgba`` when the geom keeps the default rgba). The body entity itself moves:
:class:`cosim.io.recording.PourRecorder` logs its pose on the timelines. The world body's geoms go under
``world/scene``.

Names: a body's MJCF name is its path under ``world/robot`` (``pour_arm/wrist_1_link``); a geom is named by its MJCF
name less the namespace it shares with its body (``pourer/floor`` on body ``pourer`` is ``floor``), an unnamed geom
by its mesh's name or its type (``cylinder``), numbered when a body has several of the same name (``cylinder_1``,
``cylinder_2``). A body whose path would hold another body's entity gets ``_body`` appended, since Rerun composes
the transforms of nested entities.

Planes are not drawn: MuJoCo's ground plane is usually kilometres of texture that would only enlarge the 3-D view's
bounds; the view's grid stands for the ground (:mod:`cosim.io.rerun_blueprint`).

MuJoCo size conventions (``model.geom_size``, m): box = half sizes; sphere = radius; ellipsoid = semi-axes;
capsule and cylinder = (radius, half length along the geom's z); plane = half sizes in x and y, 0 meaning infinite.
Mesh vertices (``model.mesh_vert``) are already in the geom frame (the compiler moves mesh frames into geom_pos/quat).
Height fields and SDF geoms are not drawn (:func:`geom_visuals` reports them as skipped).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
import rerun as rr

from cosim.io import rerun_paths

# MuJoCo's viewer shows geom groups 0, 1 and 2 and hides 3-5 by default (mjvOption.geomgroup); models put
# collision-only geoms in group 3, so the recording draws what MuJoCo's viewer draws.
VISIBLE_GEOM_GROUPS = frozenset({0, 1, 2})
# geom_rgba MuJoCo gives a geom without an rgba attribute; with a material, the material colour shows instead.
_DEFAULT_GEOM_RGBA = np.array([0.5, 0.5, 0.5, 1.0], dtype=np.float32)

_SOLID = rr.components.FillMode.Solid


@dataclass(frozen=True)
class GeomVisual:
    """One drawable geom.

    body_id, geom_id: MuJoCo indices. path: its entity. translation: (3,) m, geom origin in the body frame.
    quat_xyzw: (4,) geom -> body rotation in Rerun's [x, y, z, w] order. shape: the Rerun archetype in the geom frame.
    """

    body_id: int
    geom_id: int
    path: str
    translation: np.ndarray
    quat_xyzw: np.ndarray
    shape: rr.AsComponents


def xyzw_from_wxyz(q: np.ndarray) -> np.ndarray:
    """Reorder quaternions (..., 4) from MuJoCo's [w, x, y, z] to Rerun's [x, y, z, w]."""
    return np.asarray(q)[..., [1, 2, 3, 0]]


def body_name(model: mujoco.MjModel, body_id: int) -> str:
    """The body's MJCF name, or ``body_<id>`` for an unnamed body."""
    return model.body(body_id).name or f"body_{body_id}"


def body_paths(model: mujoco.MjModel, body_ids) -> dict[int, str]:
    """Entity of each body in ``body_ids``: ``world/scene`` for the world body, else its name under ``world/robot``,
    with ``_body`` appended where another body's entity would lie below it."""
    paths = {b: rerun_paths.SCENE if b == 0 else rerun_paths.under(rerun_paths.ROBOT, body_name(model, b)) for b in body_ids}
    taken = set(paths.values())
    for b, path in paths.items():
        if b != 0 and any(other.startswith(path + "/") for other in taken):
            paths[b] = path + "_body"
    return paths


def _own_geom_name(model: mujoco.MjModel, geom_id: int) -> str:
    """A geom's name before numbering: its MJCF name less the leading parts it shares with its body's name, else its
    mesh's name or its type."""
    name = model.geom(geom_id).name
    if name:
        parts = rerun_paths.name_parts(name)
        body = rerun_paths.name_parts(body_name(model, int(model.geom_bodyid[geom_id])))
        shared = 0
        while shared < min(len(parts) - 1, len(body)) and parts[shared] == body[shared]:
            shared += 1
        return "_".join(parts[shared:])
    t = int(model.geom_type[geom_id])
    if t == mujoco.mjtGeom.mjGEOM_MESH:
        mesh = model.mesh(int(model.geom_dataid[geom_id])).name
        if mesh:
            return "_".join(rerun_paths.name_parts(mesh))
    return mujoco.mjtGeom(t).name.removeprefix("mjGEOM_").lower()


def geom_names(model: mujoco.MjModel, geom_ids) -> dict[int, str]:
    """Name of each geom in ``geom_ids`` within its body (see the module docstring), unique per body."""
    own = {g: _own_geom_name(model, g) for g in geom_ids}
    count: dict[tuple[int, str], int] = {}
    for g, name in own.items():
        key = (int(model.geom_bodyid[g]), name)
        count[key] = count.get(key, 0) + 1
    seen: dict[tuple[int, str], int] = {}
    out = {}
    for g, name in own.items():
        key = (int(model.geom_bodyid[g]), name)
        if count[key] > 1:
            seen[key] = seen.get(key, 0) + 1
            name = f"{name}_{seen[key]}"
        out[g] = name
    return out


def geom_rgba8(model: mujoco.MjModel, geom_id: int) -> np.ndarray:
    """(4,) uint8 colour MuJoCo renders the geom with."""
    rgba = model.geom_rgba[geom_id]
    mat = int(model.geom_matid[geom_id])
    if mat >= 0 and np.array_equal(rgba, _DEFAULT_GEOM_RGBA):
        rgba = model.mat_rgba[mat]
    return np.round(np.clip(rgba, 0.0, 1.0) * 255.0).astype(np.uint8)


def _mesh(model: mujoco.MjModel, mesh_id: int, color: np.ndarray) -> rr.Mesh3D:
    v0, nv = int(model.mesh_vertadr[mesh_id]), int(model.mesh_vertnum[mesh_id])
    f0, nf = int(model.mesh_faceadr[mesh_id]), int(model.mesh_facenum[mesh_id])
    vertices = np.asarray(model.mesh_vert[v0 : v0 + nv], dtype=np.float32)
    faces = np.asarray(model.mesh_face[f0 : f0 + nf], dtype=np.uint32)
    return rr.Mesh3D(
        vertex_positions=vertices,
        triangle_indices=faces,
        vertex_normals=vertex_normals(vertices, faces),
        albedo_factor=color,
    )


def vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(V, 3) unit vertex normals: the area-weighted sum of the adjacent faces' normals (for shading)."""
    tri = vertices[faces]
    face_n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])  # length = 2 x area
    normals = np.zeros_like(vertices)
    for k in range(3):
        np.add.at(normals, faces[:, k], face_n)
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    return normals / np.where(length > 0.0, length, 1.0)


def geom_shape(model: mujoco.MjModel, geom_id: int) -> rr.AsComponents | None:
    """The Rerun archetype of a geom in its own frame, or None for a type this module does not draw."""
    t = mujoco.mjtGeom(int(model.geom_type[geom_id]))
    size = np.asarray(model.geom_size[geom_id], dtype=np.float32)
    color = geom_rgba8(model, geom_id)
    G = mujoco.mjtGeom
    if t == G.mjGEOM_BOX:
        return rr.Boxes3D(half_sizes=[size], colors=[color], fill_mode=_SOLID)
    if t == G.mjGEOM_SPHERE:
        return rr.Ellipsoids3D(half_sizes=[[size[0]] * 3], colors=[color], fill_mode=_SOLID)
    if t == G.mjGEOM_ELLIPSOID:
        return rr.Ellipsoids3D(half_sizes=[size], colors=[color], fill_mode=_SOLID)
    if t == G.mjGEOM_CYLINDER:  # Rerun's cylinder is centred on its origin, axis z
        return rr.Cylinders3D(lengths=[2 * size[1]], radii=[size[0]], colors=[color], fill_mode=_SOLID)
    if t == G.mjGEOM_CAPSULE:  # Rerun's capsule runs from its origin to +length along z: centre it
        return rr.Capsules3D(
            lengths=[2 * size[1]], radii=[size[0]], translations=[[0.0, 0.0, -size[1]]], colors=[color], fill_mode=_SOLID
        )
    if t == G.mjGEOM_MESH:
        return _mesh(model, int(model.geom_dataid[geom_id]), color)
    return None


def geom_visuals(model: mujoco.MjModel) -> tuple[list[GeomVisual], list[int]]:
    """The drawable visible geoms (group in :data:`VISIBLE_GEOM_GROUPS`, alpha > 0, not a plane), and the ids of
    visible geoms skipped because their type is not drawn (height field, SDF)."""
    shown = [
        g for g in range(model.ngeom)
        if int(model.geom_group[g]) in VISIBLE_GEOM_GROUPS and geom_rgba8(model, g)[3] > 0
        and int(model.geom_type[g]) != mujoco.mjtGeom.mjGEOM_PLANE
    ]
    shapes = {g: geom_shape(model, g) for g in shown}
    skipped = [g for g in shown if shapes[g] is None]
    drawn = [g for g in shown if shapes[g] is not None]
    bodies = body_paths(model, {int(model.geom_bodyid[g]) for g in drawn})
    names = geom_names(model, drawn)
    visuals = [
        GeomVisual(
            body_id=int(model.geom_bodyid[g]),
            geom_id=g,
            path=f"{bodies[int(model.geom_bodyid[g])]}/{names[g]}",
            translation=np.asarray(model.geom_pos[g], dtype=np.float64).copy(),
            quat_xyzw=xyzw_from_wxyz(model.geom_quat[g]).astype(np.float64),
            shape=shapes[g],
        )
        for g in drawn
    ]
    return visuals, skipped


def log_static_geometry(rec: rr.RecordingStream, visuals: list[GeomVisual]) -> None:
    """Log every geom once, static: its geom -> body transform and its shape, plus the world's z-up axes."""
    rec.log(rerun_paths.WORLD, rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    for v in visuals:
        rec.log(v.path, rr.Transform3D(translation=v.translation, quaternion=rr.Quaternion(xyzw=v.quat_xyzw)), v.shape, static=True)
