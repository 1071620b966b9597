"""The pourer's inner box as the probe's kernels see it: its world pose and sizes, and the test of a particle
against it (:mod:`cosim.coupling.measure`, :mod:`cosim.coupling.free_surface`)."""

from __future__ import annotations

import warp as wp


@wp.struct
class PourerFrame:
    """The pourer at the measurement (world frame): origin (m) and rotation; inner half width b, half depth d and
    height (m); 3 when the y extent counts (3-D); 1 when the section across the pour plane is a circle of radius b
    (a cylinder's), else 0."""

    origin: wp.vec3
    rotation: wp.mat33
    half_width: float
    half_depth: float
    height: float
    dim: int
    round_section: int


@wp.func
def inner_local(f: PourerFrame, x: wp.vec3) -> wp.vec4:
    """(vessel x, y, z, 1 if inside the inner box else 0) of a world point."""
    q = wp.transpose(f.rotation) @ (x - f.origin)
    inside = wp.abs(q[0]) <= f.half_width and q[2] >= 0.0 and q[2] <= f.height
    if f.dim == 3 and wp.abs(q[1]) > f.half_depth:
        inside = False
    flag = float(0.0)
    if inside:
        flag = 1.0
    return wp.vec4(q[0], q[1], q[2], flag)
