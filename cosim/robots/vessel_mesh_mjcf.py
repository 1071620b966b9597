"""MuJoCo geoms of a mesh vessel (:mod:`cosim.mesh_vessel`): the mesh to see, convex parts to collide with.

MuJoCo collides a mesh geom as its convex hull, which for an open vessel would fill the cavity. The walls are
therefore cut into convex parts: the solid's surface, subdivided to half a cell, is binned into a grid of
:data:`PARTS_ACROSS` cells across its largest extent, each cell widened by the wall's thickness so that it holds both
faces of the wall passing through it; each cell's points become one mesh asset without faces, which MuJoCo replaces
by their convex hull (its own hull per part). A cell whose points are flat (a single face) adds nothing. The parts
hug the walls to within a cell's curvature; where a cell holds a wall corner (floor and side), its hull also fills
that corner of the cavity. The visible mesh does not collide; the parts are in a hidden geom group.
"""

from __future__ import annotations

import mujoco
import numpy as np

from cosim.vessel import VesselSpec

PARTS_ACROSS = 8
COLLISION_GROUP = 3  # not drawn by default (the MuJoCo viewer shows it on request)
PART_RGBA = (0.9, 0.5, 0.2, 0.3)
FLAT = 1e-3  # a cell's points are flat when their smallest spread is under this fraction of their largest


def convex_parts(vessel: VesselSpec) -> list[np.ndarray]:
    """The point sets (k, 3) m, vessel frame, whose convex hulls make the vessel's collision parts."""
    import trimesh  # imported on use, as in cosim.mesh_vessel

    mesh = vessel.mesh
    lo, hi = mesh.bounds
    cell = float(np.max(hi - lo)) / PARTS_ACROSS
    points = trimesh.remesh.subdivide_to_size(mesh.vertices, mesh.faces, max_edge=0.5 * cell)[0]
    pad = vessel.wall_thickness + 1e-6
    counts = np.maximum(np.ceil((hi - lo) / cell).astype(int), 1)
    parts = []
    for index in np.ndindex(*counts):
        c_lo = lo + cell * np.array(index) - pad
        c_hi = lo + cell * (np.array(index) + 1) + pad
        inside = points[np.all((points >= c_lo) & (points <= c_hi), axis=1)]
        if len(inside) < 4:
            continue
        spread = np.linalg.svd(inside - inside.mean(axis=0), compute_uv=False)
        if spread[-1] > FLAT * spread[0]:
            parts.append(inside)
    return parts


def add_mesh_geoms(spec: mujoco.MjSpec, body: mujoco.MjsBody, vessel: VesselSpec, group: int, rgba) -> None:
    """Add the mesh vessel's visible mesh (``group``, ``rgba``, not colliding) and its convex collision parts."""
    mesh = vessel.mesh
    name = vessel.name
    spec.add_mesh(name=f"{name}/mesh", uservert=mesh.vertices.ravel().tolist(), userface=mesh.faces.ravel().tolist())
    body.add_geom(name=f"{name}/visual", type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"{name}/mesh", group=group,
                  rgba=list(rgba), contype=0, conaffinity=0)
    for k, points in enumerate(convex_parts(vessel)):
        spec.add_mesh(name=f"{name}/part_{k:03d}", uservert=points.ravel().tolist())
        body.add_geom(name=f"{name}/part_{k:03d}", type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"{name}/part_{k:03d}",
                      group=COLLISION_GROUP, rgba=list(PART_RGBA))
