"""A mesh vessel as the liquid's boundary: the inside test and the non-penetration guard from warp's mesh queries.

The vessel's walls are a closed, outward-wound triangle mesh in the vessel frame (:mod:`cosim.mesh_vessel`), held as
a ``wp.Mesh``. Both functions take vessel-frame points, as the box and cylinder versions in
:mod:`cosim.fluid.boundary` do, which call them for a vessel of shape :data:`SHAPE_MESH`.

Inside (the vessel's cavity, :func:`mesh_inside`): walls below and on all four horizontal sides and none above (rays
along -z, +x, -x, +y, -y hit the mesh, the ray along +z does not; a point inside the walls has them above it, so it is
not inside). The same rule :mod:`cosim.mesh_vessel` applies on a voxel grid.
The rays that must hit are turned off the axes, the horizontal ones by :data:`RAY_SKEW` rad, the one down by
:data:`VERTICAL_SKEW` rad: a ray along an axis from a lattice point (or from the pour plane y = 0) meets a mesh's
faces on their shared edges (a revolved floor's centre, a quad's diagonal), where a ray can pass between two
triangles. The ray up, which must miss, stays vertical: turned, it would meet the wall from liquid resting against
it, closer to the wall than its drift over the height to the rim.

Guard (:func:`mesh_guard`): the particle's path from q_old to q_new is cast as a ray; if it enters the walls
through a face (hits the front of an outward-wound face) it is put back on that face plus ``margin`` on the side it
came from, and the face's normal is returned (the caller removes the velocity into it). This also stops a particle
that would pass a thin wall within one step. A particle that ends inside the walls without such an entry (one that
started inside after an earlier breach: the sign of its signed distance, from the mesh's winding number,
``wp.mesh_query_point_sign_winding_number``) is put onto the nearest face within ``reach`` of it. (The sign from the
closest face's pseudo-normal is cheaper but wrong where two faces are equally near, as on a symmetric vessel's
mid-plane, where the 2-D liquid lies.) A corrected position is
checked once more along the path (a path into a corner meets the second face). In 2-D the normal is taken in the
pour plane.
"""

from __future__ import annotations

import warp as wp

SHAPE_MESH = 2
RAY_SKEW = 0.0123  # rad
VERTICAL_SKEW = 1.23e-4  # rad


@wp.func
def mesh_inside(mesh: wp.uint64, cavity_lo: wp.vec3, cavity_hi: wp.vec3, q: wp.vec3) -> int:
    """1 if the vessel-frame point q (m) is in the mesh vessel's cavity, whose bounding box is [cavity_lo, cavity_hi]
    (m), else 0."""
    for a in range(3):
        if q[a] <= cavity_lo[a] or q[a] >= cavity_hi[a]:
            return 0
    reach = 2.0 * wp.length(cavity_hi - cavity_lo)
    v = VERTICAL_SKEW
    if wp.mesh_query_ray_anyhit(mesh, q, wp.vec3(0.0, 0.0, 1.0), reach):
        return 0
    if not wp.mesh_query_ray_anyhit(mesh, q, wp.vec3(-v, v, -1.0), reach):
        return 0
    c = wp.cos(RAY_SKEW)
    s = wp.sin(RAY_SKEW)
    if not wp.mesh_query_ray_anyhit(mesh, q, wp.vec3(c, s, 0.0), reach):
        return 0
    if not wp.mesh_query_ray_anyhit(mesh, q, wp.vec3(-c, -s, 0.0), reach):
        return 0
    if not wp.mesh_query_ray_anyhit(mesh, q, wp.vec3(-s, c, 0.0), reach):
        return 0
    if not wp.mesh_query_ray_anyhit(mesh, q, wp.vec3(s, -c, 0.0), reach):
        return 0
    return 1


@wp.func
def in_plane(n: wp.vec3, dim: int) -> wp.vec3:
    """The normal n, in 2-D with its y component dropped and renormalised (the liquid moves in the pour plane)."""
    if dim == 2:
        m = wp.vec3(n[0], 0.0, n[2])
        if wp.length(m) > 1.0e-6:
            return wp.normalize(m)
    return n


@wp.func
def path_entry(mesh: wp.uint64, q_old: wp.vec3, q_new: wp.vec3, margin: float, dim: int):
    """(q, normal, depth, hit) for the path q_old -> q_new: where it enters the walls through a face, q on that face
    plus ``margin`` along its outward normal, the normal, how far past the face q_new went (m), 1; else (q_new, 0, 0,
    0)."""
    d = q_new - q_old
    length = wp.length(d)
    if length > 1.0e-12:
        direction = d / length
        hit = wp.mesh_query_ray(mesh, q_old, direction, length)
        if hit.result and hit.sign > 0.0:
            n = in_plane(hit.normal, dim)
            x_hit = q_old + hit.t * direction
            return x_hit + margin * n, n, wp.max(wp.dot(x_hit - q_new, n), 0.0), 1
    return q_new, wp.vec3(0.0), 0.0, 0


@wp.func
def mesh_guard(mesh: wp.uint64, q_old: wp.vec3, q_new: wp.vec3, margin: float, reach: float, dim: int):
    """The guard of one mesh vessel (module doc): (q, normal, max_depth, hits) in the vessel frame, as
    :func:`cosim.fluid.boundary.guard_vessel` returns. ``reach``: m, how far inside the walls a particle is found."""
    q, normal, depth, hits = path_entry(mesh, q_old, q_new, margin, dim)
    if hits > 0:
        q2, n2, depth2, hit2 = path_entry(mesh, q_old, q, margin, dim)
        if hit2 > 0:
            return q2, n2, wp.max(depth, depth2), hits + hit2
        return q, normal, depth, hits
    closest = wp.mesh_query_point_sign_winding_number(mesh, q_new, reach)
    if closest.result and closest.sign < 0.0:
        c = wp.mesh_eval_position(mesh, closest.face, closest.u, closest.v)
        n = in_plane(wp.mesh_eval_face_normal(mesh, closest.face), dim)
        return c + margin * n, n, wp.length(c - q_new), 1
    return q_new, wp.vec3(0.0), 0.0, 0
