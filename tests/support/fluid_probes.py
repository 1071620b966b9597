"""Warp kernels that expose the solver's device functions to the tests."""

import warp as wp

from cosim.fluid.boundary import VesselGeometry, guard_vessel
from cosim.fluid.sph_kernels import kernel_dw, kernel_w


@wp.kernel
def evaluate_kernel(r: wp.array(dtype=float), inv_h: float, sigma: float, kind: int, w: wp.array(dtype=float), dw: wp.array(dtype=float)):
    i = wp.tid()
    w[i] = kernel_w(r[i], inv_h, sigma, kind)
    dw[i] = kernel_dw(r[i], inv_h, sigma, kind)


@wp.kernel
def apply_guard(
    geo: VesselGeometry,
    dim: int,
    margin: float,
    q_old: wp.array(dtype=wp.vec3),
    q_new: wp.array(dtype=wp.vec3),
    q_out: wp.array(dtype=wp.vec3),
    normal_out: wp.array(dtype=wp.vec3),
    depth_out: wp.array(dtype=float),
    hits_out: wp.array(dtype=int),
):
    i = wp.tid()
    q, n, depth, hits = guard_vessel(q_old[i], q_new[i], geo, dim, margin)
    q_out[i] = q
    normal_out[i] = n
    depth_out[i] = depth
    hits_out[i] = hits
