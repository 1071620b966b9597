"""Static Rerun geometry of a MuJoCo model: one shape per visible geom, in its body's frame.

Each geom becomes the entity ``world/robot/<body>/<geom>`` holding a static Transform3D (geom frame -> body frame:
``model.geom_pos`` m, ``model.geom_quat``) and the geom's shape in its own frame, coloured like MuJoCo colours it
(``geom_rgba``, or the material's ``mat_rgba`` when the geom keeps the default rgba). The body entity itself moves:
:class:`cosim.io.recording.PourRecorder` logs its pose on the timelines.

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
# m: drawn half extent of a plane whose MuJoCo size is 0 (infinite).
INFINITE_PLANE_HALF_SIZE = 1.5
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


def geom_name(model: mujoco.MjModel, geom_id: int) -> str:
    """The geom's MJCF name, or ``geom_<id>`` for an unnamed geom."""
    return model.geom(geom_id).name or f"geom_{geom_id}"


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
    if t == G.mjGEOM_PLANE:
        hx, hy = (float(s) if s > 0 else INFINITE_PLANE_HALF_SIZE for s in size[:2])
        return rr.Boxes3D(half_sizes=[[hx, hy, 0.0]], colors=[color], fill_mode=_SOLID)
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
    """The drawable visible geoms (group in :data:`VISIBLE_GEOM_GROUPS`, alpha > 0), and the ids of visible geoms
    skipped because their type is not drawn (height field, SDF)."""
    visuals: list[GeomVisual] = []
    skipped: list[int] = []
    for g in range(model.ngeom):
        if int(model.geom_group[g]) not in VISIBLE_GEOM_GROUPS or geom_rgba8(model, g)[3] == 0:
            continue
        shape = geom_shape(model, g)
        if shape is None:
            skipped.append(g)
            continue
        b = int(model.geom_bodyid[g])
        visuals.append(
            GeomVisual(
                body_id=b,
                geom_id=g,
                path=rerun_paths.geom_path(body_name(model, b), geom_name(model, g)),
                translation=np.asarray(model.geom_pos[g], dtype=np.float64).copy(),
                quat_xyzw=xyzw_from_wxyz(model.geom_quat[g]).astype(np.float64),
                shape=shape,
            )
        )
    return visuals, skipped


def log_static_geometry(rec: rr.RecordingStream, visuals: list[GeomVisual]) -> None:
    """Log every geom once, static: its geom -> body transform and its shape, plus the world's z-up axes."""
    rec.log(rerun_paths.WORLD, rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    for v in visuals:
        rec.log(v.path, rr.Transform3D(translation=v.translation, quaternion=rr.Quaternion(xyzw=v.quat_xyzw)), static=True)
        rec.log(v.path, v.shape, static=True)
