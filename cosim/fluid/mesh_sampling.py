"""A mesh vessel's particles (numpy out, warp's mesh queries on the CPU, done once per run): its dummy wall particles
on the liquid-facing surfaces and the liquid that fills it.

Walls (:func:`sample_mesh_walls`): a lattice of spacing dx, anchored at the inner rim on the pour side and the
inner floor (cell centres half a spacing off them, as the box's layers are), over the cavity's bounding box widened
by the numerical wall thickness t (:func:`cosim.fluid.wall_sampling.numerical_wall_thickness`). A lattice point is
a wall particle when it is outside the cavity, no higher than the rim's highest point, less than t from the
liquid-facing faces, and behind them (on the side their outward normal points away from, or inside the walls): the
layers that cover the kernel support behind every wetted face (Adami, Hu & Adams 2012); where the wall is thinner
than t they reach beyond its outer face, as the box's do; ``confined`` (the ``real_thickness`` wall model) keeps only
those inside the wall solid. Each particle's volume is dx^dim; in 2-D only y = 0.

Liquid (:func:`fill_mesh_vessel`): the lattice of :func:`cosim.fluid.seeding.liquid_block` over the cavity's
bounding box, kept where it is in the cavity and at least dx/2 from the liquid-facing faces, as the box's lattice
lies dx/2 inside its walls. In 2-D the distance is taken in the pour plane, to the faces' section by it (the walls
the 2-D liquid sees): the distance in space to a face inclined to the plane is shorter, and would leave out lattice
points the 2-D walls leave room for (the outermost column in a revolved vessel whose polygon has a corner in the
plane), a gap the liquid fills as it settles, leaving a disordered surface with a partial top layer.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from cosim.fluid.mesh_boundary import mesh_inside
from cosim.vessel import VesselSpec

HOST = "cpu"


@wp.kernel
def classify_points(
    mesh: wp.uint64,
    wet: wp.uint64,
    cavity_lo: wp.vec3,
    cavity_hi: wp.vec3,
    reach: float,
    points: wp.array(dtype=wp.vec3),
    inside: wp.array(dtype=wp.int32),
    distance: wp.array(dtype=float),
    behind: wp.array(dtype=wp.int32),
    solid: wp.array(dtype=wp.int32),
):
    """Per point: in the cavity (1/0); distance (m) to the liquid-facing faces ``wet`` (``reach`` if farther); behind
    them (1: inside the walls, or on the far side of the nearest liquid-facing face); inside the walls (1/0, found
    within ``reach`` of their surface)."""
    i = wp.tid()
    p = points[i]
    inside[i] = mesh_inside(mesh, cavity_lo, cavity_hi, p)
    distance[i] = reach
    behind[i] = 0
    solid[i] = 0
    near = wp.mesh_query_point_no_sign(wet, p, reach)
    if near.result:
        c = wp.mesh_eval_position(wet, near.face, near.u, near.v)
        distance[i] = wp.length(p - c)
        if wp.dot(p - c, wp.mesh_eval_face_normal(wet, near.face)) < 0.0:
            behind[i] = 1
    walls = wp.mesh_query_point_sign_winding_number(mesh, p, reach)
    if walls.result and walls.sign < 0.0:
        behind[i] = 1
        solid[i] = 1


def warp_mesh(vertices: np.ndarray, faces: np.ndarray, device) -> wp.Mesh:
    """The triangle mesh as a ``wp.Mesh`` on ``device`` (float32 vertices, as the solver's positions), with the
    winding number's data (:mod:`cosim.fluid.mesh_boundary`)."""
    return wp.Mesh(points=wp.array(vertices.astype(np.float32), dtype=wp.vec3, device=device),
                   indices=wp.array(faces.astype(np.int32).ravel(), dtype=wp.int32, device=device), support_winding_number=True)


def cavity_bounds(spec: VesselSpec) -> np.ndarray:
    """(2, 3) m: the bounding box of the mesh vessel's liquid-facing faces (the cavity's), vessel frame."""
    mesh = spec.mesh
    wet = mesh.vertices[np.unique(mesh.faces[mesh.liquid_facing])]
    return np.stack([wet.min(axis=0), wet.max(axis=0)])


class MeshQueries:
    """A mesh vessel's walls and liquid-facing faces as ``wp.Mesh`` on the CPU, for classifying many point sets."""

    def __init__(self, spec: VesselSpec):
        mesh = spec.mesh
        self.solid = warp_mesh(mesh.vertices, mesh.faces, HOST)
        self.wet = warp_mesh(mesh.vertices, mesh.faces[mesh.liquid_facing], HOST)
        self.cavity = cavity_bounds(spec)

    def classify(self, points: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(inside, distance m, behind, solid), each (n,), of vessel-frame ``points`` (:func:`classify_points`)."""
        n = len(points)
        out = [wp.zeros(n, dtype=wp.int32, device=HOST), wp.zeros(n, dtype=float, device=HOST),
               wp.zeros(n, dtype=wp.int32, device=HOST), wp.zeros(n, dtype=wp.int32, device=HOST)]
        lo, hi = self.cavity
        wp.launch(classify_points, dim=n, device=HOST, outputs=out,
                  inputs=[self.solid.id, self.wet.id, wp.vec3(*lo), wp.vec3(*hi), reach, wp.array(points.astype(np.float32), dtype=wp.vec3, device=HOST)])
        inside, distance, behind, solid = (a.numpy() for a in out)
        return inside.astype(bool), distance.astype(float), behind.astype(bool), solid.astype(bool)


def classify(spec: VesselSpec, points: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(inside, distance m, behind, solid) of vessel-frame ``points`` (:meth:`MeshQueries.classify`)."""
    return MeshQueries(spec).classify(points, reach)


def _lattice(lo: np.ndarray, hi: np.ndarray, anchor: np.ndarray, dx: float, dim: int) -> np.ndarray:
    """Points anchor + (k + 1/2) dx per axis (integer k) within [lo, hi]; only y = 0 in 2-D."""
    axes = []
    for a in range(3):
        if dim == 2 and a == 1:
            axes.append(np.zeros(1))
            continue
        k = np.arange(np.floor((lo[a] - anchor[a]) / dx - 0.5), np.ceil((hi[a] - anchor[a]) / dx) + 1)
        values = anchor[a] + (k + 0.5) * dx
        axes.append(values[(values >= lo[a]) & (values <= hi[a])])
    grid = np.meshgrid(*axes, indexing="ij")
    return np.stack([g.ravel() for g in grid], axis=1)


def sample_mesh_walls(spec: VesselSpec, spacing: float, thickness: float, dim: int, confined: bool) -> tuple[np.ndarray, np.ndarray]:
    """Dummy wall particles (n, 3) in the vessel frame and their volumes (n,) (m^dim) of a mesh vessel whose walls
    the liquid sees ``thickness`` (m) thick (module doc); ``confined``: only those inside the wall solid (the vessel's
    own walls, :class:`cosim.fluid.config.WallModel`)."""
    lo, hi = cavity_bounds(spec)
    anchor = np.array([-0.5 * spec.inner_width, lo[1], 0.0])
    points = _lattice(lo - thickness, hi + np.array([thickness, thickness, 0.0]), anchor, spacing, dim)
    inside, distance, behind, solid = classify(spec, points, 2.0 * thickness)
    keep = ~inside & behind & (distance < thickness) & (solid | (not confined))
    walls = points[keep]
    return walls, np.full(len(walls), spacing**dim)


def mesh_wetted_layer(spec: VesselSpec, points: np.ndarray, spacing: float) -> np.ndarray:
    """(n,) bool: the wall particles ``points`` less than one ``spacing`` from the liquid-facing faces."""
    return classify(spec, points, 2.0 * spacing)[1] < spacing


def pour_plane_distance(segments: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(n,) m: the distance in the pour plane (x, z) from each of ``points`` (n, 3) to the nearest of the section's
    ``segments`` (k, 2, 3) (:meth:`cosim.mesh_vessel.VesselMesh.section_segments`)."""
    p = points[:, None, [0, 2]]
    a, b = segments[None, :, 0, [0, 2]], segments[None, :, 1, [0, 2]]
    ab = b - a
    f = np.clip(np.sum((p - a) * ab, axis=2) / np.maximum(np.sum(ab * ab, axis=2), 1e-300), 0.0, 1.0)
    return np.linalg.norm(p - (a + f[:, :, None] * ab), axis=2).min(axis=1)


def fill_mesh_vessel(spec: VesselSpec, local: np.ndarray, spacing: float, dim: int) -> np.ndarray:
    """(n,) bool: which lattice points ``local`` (vessel frame) the liquid filling the mesh vessel keeps: those in its
    cavity at least half a ``spacing`` from its liquid-facing faces, in 2-D from their section by the pour plane
    (module doc; a thousandth of a spacing spared for the queries' float32 rounding)."""
    inside, distance, _, _ = classify(spec, local, spacing)
    if dim == 2:
        distance = pour_plane_distance(spec.mesh.section_segments(), local)
    return inside & (distance >= (0.5 - 1e-3) * spacing)
