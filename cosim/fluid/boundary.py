"""Moving rigid vessels as SPH boundaries (warp side).

Per vessel: its geometry (:class:`VesselGeometry`, vessel frame) and its motion over one coupling interval
(:class:`VesselMotion`): the interval's start pose (p0, R0) and a constant linear velocity v and angular velocity
w (world frame), set from outside before each interval, so that the pose at time tau into the interval is
p(tau) = p0 + v tau, R(tau) = exp([w] tau) R0. The dummy wall particles ride on that motion with velocity
v + w x (x_b - p). Their pressure is extrapolated from the liquid each substep (Adami, Hu & Adams 2012):
p_w = (sum_f p_f W_wf + (g - a_w) . sum_f rho_f (x_w - x_f) W_wf) / sum_f W_wf, clamped at 0 so walls never
pull on the liquid, with a_w the wall's acceleration; and a no-slip velocity 2 v_wall - (sum_f v_f W_wf /
sum_f W_wf) is extrapolated for the viscous terms. A wall particle of a vessel's own wall under ``wall_model =
"sided"`` (seen by the liquid outside the vessel) has liquid on two faces: the cavity's side (the liquid inside and
the liquid over the rim on that side) and the outer faces; it carries one state per face, each extrapolated from the
liquid on that face (:func:`on_inner_face`), as a wall's particles see one side of it (Marrone et al. 2011).

The non-penetration guard (:func:`guard_vessel`) runs after every position update: a particle whose path from its
old position (in the vessel frame at the old pose) to its new one (in the frame at the new pose) enters the wall
solid is put back on the side it came from, just outside the face it crossed, and loses its velocity into that
face relative to the wall. This also catches a particle that would pass through a thin wall within one step. A
particle found inside the wall solid at the start of its step (within float32 rounding of a face it rests on, or
after a breach) leaves by the face nearest its new position.
"""

from __future__ import annotations

import warp as wp

from cosim.fluid.lanes import item_kernel
from cosim.fluid.mesh_boundary import SHAPE_MESH, mesh_guard, mesh_inside
from cosim.fluid.neighbors import SEEN_FROM_OUTSIDE, Neighborhood, neighbor_cells, next_liquid_neighbor, reachable_cell, wall_seen
from cosim.fluid.params import SPHParams
from cosim.fluid.sph_kernels import kernel_w

SHAPE_BOX = 0
SHAPE_CYLINDER = 1


@wp.struct
class VesselGeometry:
    """Vessel frame geometry (m). shape: SHAPE_BOX, SHAPE_CYLINDER (a cylinder is a box section in 2-D) or
    SHAPE_MESH (:mod:`cosim.fluid.mesh_boundary`: ``mesh`` the walls' ``wp.Mesh`` id, ``cavity_lo``/``cavity_hi`` the
    cavity's bounding box; the sizes below its box equivalent).

    half_width: b = inner_width / 2 (a cylinder's inner radius); half_depth: inner_depth / 2 (box, 3-D);
    height: inner height H; thickness: wall thickness the liquid sees (the dummy layers', if thicker than the
    vessel's own); com: centre of mass in the vessel frame (torque point); liquid_mass: the in-plane SPH mass
    (kg/m) a particle takes when it enters the vessel (2-D: its 3-D mass spread over the vessel's depth,
    :func:`cosim.fluid.model.caught_liquid_mass`), 0 where entering changes nothing (3-D).
    """

    shape: int
    half_width: float
    half_depth: float
    height: float
    thickness: float
    com: wp.vec3
    liquid_mass: float
    mesh: wp.uint64
    cavity_lo: wp.vec3
    cavity_hi: wp.vec3


@wp.struct
class VesselMotion:
    """Rigid motion over one interval (world frame): start pose, constant velocities, the acceleration estimated
    from the change of velocity since the previous interval (m/s^2, rad/s^2), and the poses at the current
    substep's start/end."""

    p0: wp.vec3
    r0: wp.mat33
    lin_vel: wp.vec3
    ang_vel: wp.vec3
    lin_acc: wp.vec3
    ang_acc: wp.vec3
    p_now: wp.vec3
    r_now: wp.mat33
    p_next: wp.vec3
    r_next: wp.mat33


@wp.func
def rotation_exp(w: wp.vec3, tau: float) -> wp.mat33:
    """exp([w] tau): rotation by angle |w| tau about w (Rodrigues)."""
    angle = wp.length(w) * tau
    if angle < 1.0e-12:
        return wp.identity(n=3, dtype=float)
    k = wp.normalize(w)
    kx = wp.skew(k)
    return wp.identity(n=3, dtype=float) + wp.sin(angle) * kx + (1.0 - wp.cos(angle)) * (kx @ kx)


@wp.kernel
def advance_vessel_poses(
    # State in
    substep: wp.array(dtype=wp.int32),
    dt: wp.array(dtype=float),
    # State in/out
    motions: wp.array(dtype=VesselMotion),
):
    """Poses at the start (tau = s dt) and end (tau = (s + 1) dt) of substep s of the interval."""
    k = wp.tid()
    m = motions[k]
    tau = float(substep[0]) * dt[0]
    m.p_now = m.p0 + m.lin_vel * tau
    m.r_now = rotation_exp(m.ang_vel, tau) @ m.r0
    m.p_next = m.p0 + m.lin_vel * (tau + dt[0])
    m.r_next = rotation_exp(m.ang_vel, tau + dt[0]) @ m.r0
    motions[k] = m


@item_kernel
def place_wall_particles(
    # Model
    local_pos: wp.array(dtype=wp.vec3),
    vessel_of: wp.array(dtype=wp.int32),
    # State in
    motions: wp.array(dtype=VesselMotion),
    # Out
    x: wp.array(dtype=wp.vec3),
    v: wp.array(dtype=wp.vec3),
):
    """World position and velocity of each wall sample at the current substep's start pose."""
    b = wp.tid()
    m = motions[vessel_of[b]]
    arm = m.r_now @ local_pos[b]
    x[b] = m.p_now + arm
    v[b] = m.lin_vel + wp.cross(m.ang_vel, arm)


@wp.struct
class WallStateSums:
    """The sums of one wall particle's extrapolation over the liquid around it (Adami, Hu & Adams 2012): sum_f W_wf,
    sum_f p_f W_wf (Pa), sum_f rho_f (x_w - x_f) W_wf (kg/m^2), sum_f v_f W_wf (m/s)."""

    w: float
    pw: float
    rho_r: wp.vec3
    v: wp.vec3


@wp.func
def empty_wall_state() -> WallStateSums:
    """The sums over no liquid: all zero."""
    sums = WallStateSums()
    sums.w = 0.0
    sums.pw = 0.0
    sums.rho_r = wp.vec3(0.0)
    sums.v = wp.vec3(0.0)
    return sums


@wp.func
def add_to_wall_state(sums: WallStateSums, w: float, p: float, rho: float, r: wp.vec3, v: wp.vec3) -> WallStateSums:
    """``sums`` with liquid particle f added: its kernel weight w, pressure p, density rho, x_w - x_f = r, velocity v."""
    out = WallStateSums()
    out.w = sums.w + w
    out.pw = sums.pw + p * w
    out.rho_r = sums.rho_r + (rho * w) * r
    out.v = sums.v + w * v
    return out


@wp.func
def write_wall_state(
    prm: SPHParams, sums: WallStateSums, g_rel: wp.vec3, v_wall: wp.vec3, b: int,
    b_p: wp.array(dtype=float), b_rho: wp.array(dtype=float), b_v_noslip: wp.array(dtype=wp.vec3),
):
    """Wall particle b's pressure (Pa, clamped at 0), density (kg/m^3, the equation of state's) and no-slip velocity
    (m/s) from its sums; ``g_rel`` the gravity less the wall's acceleration, ``v_wall`` the wall's velocity there.
    With no liquid around it: pressure 0, the wall's velocity."""
    pw = float(0.0)
    v_noslip = v_wall
    if sums.w > 0.0:
        pw = wp.max((sums.pw + wp.dot(g_rel, sums.rho_r)) / sums.w, 0.0)
        v_noslip = 2.0 * v_wall - sums.v / sums.w
    b_p[b] = pw
    b_rho[b] = prm.rest_density * wp.pow(1.0 + pw / prm.eos_b, 1.0 / prm.gamma)
    b_v_noslip[b] = v_noslip


@wp.func
def in_vessel_frame_now(m: VesselMotion, x: wp.vec3) -> wp.vec3:
    """The world point x (m) in the vessel's frame at its pose at the substep's start."""
    return wp.transpose(m.r_now) @ (x - m.p_now)


@wp.func
def cavity_distance(q: wp.vec3, geo: VesselGeometry, dim: int) -> float:
    """m, the distance of the vessel-frame point q from the vessel's cavity continued upward past its rim (its inner
    section, over the floor, at any height): 0 inside it, the depth into the walls or the distance past their outer
    faces outside. A box or cylinder (in 2-D a cylinder is a box section)."""
    below = wp.max(-q[2], 0.0)
    across = float(0.0)
    if geo.shape == SHAPE_CYLINDER and dim == 3:
        across = wp.max(wp.sqrt(q[0] * q[0] + q[1] * q[1]) - geo.half_width, 0.0)
    else:
        across = wp.max(wp.abs(q[0]) - geo.half_width, 0.0)
        if dim == 3:
            beside = wp.max(wp.abs(q[1]) - geo.half_depth, 0.0)
            across = wp.sqrt(across * across + beside * beside)
    return wp.sqrt(across * across + below * below)


@wp.func
def on_inner_face(prm: SPHParams, geo: VesselGeometry, m: VesselMotion, x: wp.vec3) -> bool:
    """Whether the world point x is on the cavity's side of the vessel's own wall: nearer the cavity continued past
    the rim (:func:`cavity_distance`) than the wall is thick, as the liquid inside and the liquid
    over the rim and the crest are; otherwise it is beyond the wall's outer faces. The vessel at its pose at the
    substep's start."""
    return cavity_distance(in_vessel_frame_now(m, x), geo, prm.dim) < geo.thickness


@item_kernel
def extrapolate_wall_state(
    # Model
    prm: SPHParams,
    vessels: wp.array(dtype=VesselGeometry),
    b_vessel: wp.array(dtype=wp.int32),
    # State in
    motions: wp.array(dtype=VesselMotion),
    nb: Neighborhood,
    bv: wp.array(dtype=wp.vec3),
    v: wp.array(dtype=wp.vec3),
    rho: wp.array(dtype=float),
    p: wp.array(dtype=float),
    # Out
    b_p: wp.array(dtype=float),
    b_rho: wp.array(dtype=float),
    b_v_noslip: wp.array(dtype=wp.vec3),
    b_p_inner: wp.array(dtype=float),
    b_rho_inner: wp.array(dtype=float),
    b_v_noslip_inner: wp.array(dtype=wp.vec3),
):
    """Pressure, density and no-slip velocity of each dummy wall particle from the liquid around it that sees it
    (:func:`cosim.fluid.neighbors.wall_seen`). A particle of a sided vessel's own wall (seen from outside) gets
    two: ``b_p`` ... from the liquid beyond the wall's outer faces, ``b_p_inner`` ... from the liquid on the cavity's
    side (:func:`on_inner_face`: the liquid inside, which does not see it, and the liquid over the rim that does)."""
    b = wp.tid()
    xb = nb.bx[b]
    vessel = b_vessel[b]
    side = nb.b_side[b]
    two_faces = side == SEEN_FROM_OUTSIDE
    m = motions[vessel]
    geo = vessels[vessel]
    arm = xb - m.p_now
    a_wall = m.lin_acc + wp.cross(m.ang_acc, arm) + wp.cross(m.ang_vel, wp.cross(m.ang_vel, arm))
    outer = empty_wall_state()
    inner = empty_wall_state()
    radius2 = prm.support * prm.support
    cells = neighbor_cells(nb.spec, xb)
    for k in range(cells.count):
        cell = reachable_cell(nb, cells, k, xb, radius2)
        if cell < 0:
            continue
        liquid_end = nb.cell_end[cell]  # the liquid only, however near
        f = next_liquid_neighbor(nb.x, nb.cell_start[cell], liquid_end, xb, radius2, 0.0)
        while f < liquid_end:
            xf = nb.x[f]
            if two_faces:
                r = xb - xf
                w = kernel_w(wp.sqrt(wp.dot(r, r)), prm.inv_h, prm.sigma, prm.kernel)
                if on_inner_face(prm, geo, m, xf):
                    inner = add_to_wall_state(inner, w, p[f], rho[f], r, v[f])
                else:
                    outer = add_to_wall_state(outer, w, p[f], rho[f], r, v[f])
            elif wall_seen(side, vessel, nb.inside[f]):  # only the liquid that sees this particle
                r = xb - xf
                w = kernel_w(wp.sqrt(wp.dot(r, r)), prm.inv_h, prm.sigma, prm.kernel)
                outer = add_to_wall_state(outer, w, p[f], rho[f], r, v[f])
            f = next_liquid_neighbor(nb.x, f + 1, liquid_end, xb, radius2, 0.0)
    g_rel = prm.gravity - a_wall
    write_wall_state(prm, outer, g_rel, bv[b], b, b_p, b_rho, b_v_noslip)
    if two_faces:
        write_wall_state(prm, inner, g_rel, bv[b], b, b_p_inner, b_rho_inner, b_v_noslip_inner)


@wp.func
def slab_entry(q_old: wp.vec3, q_new: wp.vec3, lo: wp.vec3, hi: wp.vec3, dim: int, margin: float):
    """Guard against one wall slab [lo, hi] (vessel frame; the y axis is ignored in 2-D).

    Returns (q, normal, depth, hit): if the path q_old -> q_new enters the slab, q is q_new moved back onto the
    entry face plus ``margin`` on the side it came from, normal the outward normal of that face and depth how far
    past the face q_new went (m); otherwise (q_new, 0, 0, 0).
    """
    no_hit = wp.vec3(0.0)
    inside_old = True
    for a in range(3):
        if dim == 2 and a == 1:
            continue
        if q_old[a] <= lo[a] or q_old[a] >= hi[a]:
            inside_old = False
    axis = int(-1)
    side = float(0.0)
    if inside_old:
        # Started inside (only possible if a previous step was breached): leave by the face nearest q_new.
        best = float(1.0e30)
        for a in range(3):
            if dim == 2 and a == 1:
                continue
            if q_new[a] - lo[a] < best:
                best = q_new[a] - lo[a]
                axis = a
                side = -1.0
            if hi[a] - q_new[a] < best:
                best = hi[a] - q_new[a]
                axis = a
                side = 1.0
        if best <= 0.0:
            return q_new, no_hit, 0.0, 0
    else:
        t_enter = float(-1.0e30)
        t_exit = float(1.0e30)
        for a in range(3):
            if dim == 2 and a == 1:
                continue
            d = q_new[a] - q_old[a]
            if wp.abs(d) < 1.0e-15:
                if q_old[a] <= lo[a] or q_old[a] >= hi[a]:
                    return q_new, no_hit, 0.0, 0
            else:
                t1 = (lo[a] - q_old[a]) / d
                t2 = (hi[a] - q_old[a]) / d
                tn = wp.min(t1, t2)
                if tn > t_enter:
                    t_enter = tn
                    axis = a
                    side = wp.where(d > 0.0, -1.0, 1.0)
                t_exit = wp.min(t_exit, wp.max(t1, t2))
        # The path meets the closed slab on [t_enter, t_exit]; it enters the open slab only if that span has length
        # and reaches past t = 0: a path leaving a face it starts on (t_exit = 0), as liquid resting on a wall does
        # in float32 now and then, or grazing an edge (t_enter = t_exit) does not enter.
        if axis < 0 or t_enter >= t_exit or t_enter > 1.0 or t_exit <= 0.0:
            return q_new, no_hit, 0.0, 0
    q = q_new
    normal = wp.vec3(0.0)
    normal[axis] = side
    depth = float(0.0)
    if side > 0.0:
        depth = hi[axis] - q_new[axis]
        q[axis] = hi[axis] + margin
    else:
        depth = q_new[axis] - lo[axis]
        q[axis] = lo[axis] - margin
    return q, normal, wp.max(depth, 0.0), 1


@wp.func
def box_slab(index: int, geo: VesselGeometry):
    """(lo, hi) of a box vessel's wall slab in the vessel frame: 0 floor, 1 +x, 2 -x, 3 +y, 4 -y.

    The walls are the outer box [-b-t, b+t] x [-d-t, d+t] x [-t, h] less the cavity [-b, b] x [-d, d] x [0, h]; each
    slab spans the outer box on every axis but its own, so the slabs overlap at the corners and every point strictly
    inside the walls is strictly inside some slab. Slabs that merely abut would share faces inside the walls, which
    both take for outside: a path lying in such a face's plane (along the floor's plane under a side wall) would
    pass into the wall unseen.
    """
    b = geo.half_width
    d = geo.half_depth
    t = geo.thickness
    h = geo.height
    if index == 0:
        return wp.vec3(-b - t, -d - t, -t), wp.vec3(b + t, d + t, 0.0)
    if index == 1:
        return wp.vec3(b, -d - t, -t), wp.vec3(b + t, d + t, h)
    if index == 2:
        return wp.vec3(-b - t, -d - t, -t), wp.vec3(-b, d + t, h)
    if index == 3:
        return wp.vec3(-b - t, d, -t), wp.vec3(b + t, d + t, h)
    return wp.vec3(-b - t, -d - t, -t), wp.vec3(b + t, -d, h)


@wp.func
def cylinder_exit(q: wp.vec3, r_in: float, t: float, h: float, margin: float):
    """The nearest way out of a cylindrical cup's walls for a point q inside them (floor disc z in (-t, 0),
    r < R + t, or side wall r in (R, R + t), z in [0, h)): onto the inner floor (z = 0, where r <= R), the inner
    side wall (r = R, where z >= 0), the inner corner (r = R, z = 0) from under the side wall, the underside
    (z = -t), the outer side (r = R + t) or the rim (z = h), plus ``margin`` beyond it. Returns (q moved out,
    the outward normal there, the distance moved without the margin (m))."""
    r = wp.sqrt(q[0] * q[0] + q[1] * q[1])
    radial = wp.vec3(1.0, 0.0, 0.0)
    if r > 1.0e-12:
        radial = wp.vec3(q[0] / r, q[1] / r, 0.0)
    up = wp.vec3(0.0, 0.0, 1.0)
    # the underside
    out = wp.vec3(q[0], q[1], -t - margin)
    normal = -up
    best = q[2] + t
    # the outer side
    if r_in + t - r < best:
        best = r_in + t - r
        out = wp.vec3(radial[0] * (r_in + t + margin), radial[1] * (r_in + t + margin), q[2])
        normal = radial
    # the rim's top
    if r > r_in and h - q[2] < best:
        best = h - q[2]
        out = wp.vec3(q[0], q[1], h + margin)
        normal = up
    # the cavity: through the inner floor, the inner side wall, or from under the side wall the corner between them
    inner = float(0.0)
    inner_out = wp.vec3(q[0], q[1], margin)
    inner_normal = up
    if r <= r_in:
        inner = -q[2]
    elif q[2] >= 0.0:
        inner = r - r_in
        inner_out = wp.vec3(radial[0] * (r_in - margin), radial[1] * (r_in - margin), q[2])
        inner_normal = -radial
    else:
        inner = wp.sqrt((r - r_in) * (r - r_in) + q[2] * q[2])
        inner_out = wp.vec3(radial[0] * (r_in - margin), radial[1] * (r_in - margin), margin)
        inner_normal = wp.normalize((r_in - r) * radial - q[2] * up)
    if inner <= best:
        best = inner
        out = inner_out
        normal = inner_normal
    return out, normal, best


@wp.func
def cylinder_guard(q_old: wp.vec3, q_new: wp.vec3, geo: VesselGeometry, margin: float):
    """Guard against a cylindrical cup (3-D): floor disc z in [-t, 0], r <= R + t, then the side wall r in
    [R, R + t], z in [0, H]. Same returns as :func:`guard_vessel`. Relies on the CFL step moving a particle less
    than the wall thickness per step; a path from inside to outside (or back) below the rim counts as crossing
    the side wall.

    A particle that starts inside the walls crossed no face this step, so the paths above do not see it. A particle
    resting on a face starts inside now and then: the vessel frame is recomputed in float32 from the moving pose
    at every substep, and a particle within rounding of the inner floor (about 1e-7 m a metre from the origin) is
    found just below it at the next step. Such a particle, and whatever else ends inside the walls, leaves by the
    nearest face (:func:`cylinder_exit`), as a box's slabs do (:func:`slab_entry`); left in the floor, it would sink
    among the floor's wall particles, below the inner floor.
    """
    r_in = geo.half_width
    t = geo.thickness
    h = geo.height
    q = q_new
    normal = wp.vec3(0.0)
    depth = float(0.0)
    hits = int(0)
    ro = wp.sqrt(q_old[0] * q_old[0] + q_old[1] * q_old[1])
    rq = wp.sqrt(q[0] * q[0] + q[1] * q[1])
    if ro < r_in + t and rq < r_in + t and q[2] < 0.0 and (q[2] > -t or q_old[2] >= 0.0):
        if q_old[2] >= 0.0:
            depth = -q[2]
            q[2] = margin
            normal = wp.vec3(0.0, 0.0, 1.0)
            hits += 1
        elif q_old[2] <= -t:
            depth = q[2] + t
            q[2] = -t - margin
            normal = wp.vec3(0.0, 0.0, -1.0)
            hits += 1
    if q[2] < h and q[2] > -t and q_old[2] < h:
        radial = wp.vec3(1.0, 0.0, 0.0)
        if rq > 1.0e-12:
            radial = wp.vec3(q[0] / rq, q[1] / rq, 0.0)
        if ro <= r_in and rq > r_in:
            depth = wp.max(depth, rq - r_in)
            q = wp.vec3(radial[0] * (r_in - margin), radial[1] * (r_in - margin), q[2])
            normal = -radial
            hits += 1
        elif ro >= r_in + t and rq < r_in + t:
            depth = wp.max(depth, r_in + t - rq)
            q = wp.vec3(radial[0] * (r_in + t + margin), radial[1] * (r_in + t + margin), q[2])
            normal = radial
            hits += 1
    elif q[2] < h and q_old[2] >= h and rq > r_in and rq < r_in + t:
        depth = wp.max(depth, h - q[2])
        q[2] = h + margin
        normal = wp.vec3(0.0, 0.0, 1.0)
        hits += 1
    r_end = wp.sqrt(q[0] * q[0] + q[1] * q[1])
    if r_end < r_in + t and q[2] > -t and q[2] < h and (r_end > r_in or q[2] < 0.0):
        q_out, n_out, d_out = cylinder_exit(q, r_in, t, h, margin)
        q = q_out
        normal = n_out
        depth = wp.max(depth, d_out)
        hits += 1
    return q, normal, depth, hits


@wp.func
def guard_vessel(q_old: wp.vec3, q_new: wp.vec3, geo: VesselGeometry, dim: int, margin: float):
    """Apply the guard of one vessel. Returns (q, normal, max_depth, hits) in the vessel frame; ``normal`` is that
    of the last face hit (its component of the relative velocity into the wall is removed by the caller)."""
    q = q_new
    normal = wp.vec3(0.0)
    max_depth = float(0.0)
    hits = int(0)
    if geo.shape == SHAPE_MESH:
        q, normal, max_depth, hits = mesh_guard(geo.mesh, q_old, q_new, margin, geo.thickness, dim)
    elif geo.shape == 1 and dim == 3:
        q, normal, max_depth, hits = cylinder_guard(q_old, q_new, geo, margin)
    else:
        n_slabs = wp.where(dim == 2, 3, 5)
        for s in range(n_slabs):
            lo, hi = box_slab(s, geo)
            q_s, n_s, depth_s, hit_s = slab_entry(q_old, q, lo, hi, dim, margin)
            if hit_s != 0:
                q = q_s
                normal = n_s
                max_depth = wp.max(max_depth, depth_s)
                hits += 1
    return q, normal, max_depth, hits


@wp.func
def inside_vessel(q: wp.vec3, geo: VesselGeometry, dim: int) -> int:
    """1 if the vessel-frame point q is in the vessel's inner volume (below the rim), else 0."""
    if geo.shape == SHAPE_MESH:
        return mesh_inside(geo.mesh, geo.cavity_lo, geo.cavity_hi, q)
    if q[2] <= 0.0 or q[2] >= geo.height:
        return 0
    if geo.shape == 1 and dim == 3:
        return wp.where(q[0] * q[0] + q[1] * q[1] < geo.half_width * geo.half_width, 1, 0)
    if wp.abs(q[0]) >= geo.half_width:
        return 0
    if dim == 3 and wp.abs(q[1]) >= geo.half_depth:
        return 0
    return 1
