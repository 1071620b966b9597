"""SPH smoothing kernels (warp functions), both with compact support 2h, for 2-D and 3-D.

Cubic spline: Monaghan (1992), the seed's kernel; sigma = 10/(7 pi h^2) (2-D), 1/(pi h^3) (3-D).
Wendland C2: Wendland (1995), W = sigma (1 - q/2)^4 (2q + 1); sigma = 7/(4 pi h^2) (2-D), 21/(16 pi h^3) (3-D).
q = r / h. ``kind`` is :class:`cosim.fluid.config.KernelType` as an int (see ``KERNEL_IDS``).
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from cosim.fluid.config import KernelType

KERNEL_IDS = {KernelType.CUBIC_SPLINE: 0, KernelType.WENDLAND_C2: 1}


def kernel_sigma(kernel: KernelType, h: float, dim: int) -> float:
    """Normalisation constant sigma (1/m^dim) so that the kernel integrates to one."""
    if kernel is KernelType.CUBIC_SPLINE:
        return 10.0 / (7.0 * math.pi * h * h) if dim == 2 else 1.0 / (math.pi * h**3)
    return 7.0 / (4.0 * math.pi * h * h) if dim == 2 else 21.0 / (16.0 * math.pi * h**3)


def _lattice_q(smoothing_ratio: float, dim: int) -> np.ndarray:
    """q = r / h of the points of a square (cubic) lattice of unit spacing within the support, the centre included."""
    reach = math.ceil(2.0 * smoothing_ratio)
    axis = np.arange(-reach, reach + 1, dtype=float)
    grid = np.stack(np.meshgrid(*([axis] * dim), indexing="ij"), axis=-1).reshape(-1, dim)
    q = np.linalg.norm(grid, axis=1) / smoothing_ratio
    return q[q < 2.0]


def lattice_kernel_sum(kernel: KernelType, smoothing_ratio: float, dim: int) -> float:
    """sum_j W(x_i - x_j) dx^dim over a full square (cubic) lattice of spacing dx around x_i (itself included):
    the summation density of a resting lattice in units of rho0 (1.005 for Wendland C2 at h = 1.5 dx in 2-D)."""
    h = smoothing_ratio  # in units of dx
    q = _lattice_q(h, dim)
    if kernel is KernelType.CUBIC_SPLINE:
        w = np.where(q < 1.0, 1.0 - 1.5 * q**2 + 0.75 * q**3, 0.25 * (2.0 - q) ** 3)
    else:
        w = (1.0 - 0.5 * q) ** 4 * (2.0 * q + 1.0)
    return float(kernel_sigma(kernel, h, dim) * w.sum())


def lattice_gradient_square_sum(kernel: KernelType, smoothing_ratio: float, dim: int) -> float:
    """sum_j |grad W(x_i - x_j)|^2 dx^(2 dim + 2) over the same lattice (dimensionless): the DFSPH factor's
    denominator of a particle inside a resting liquid, in units of (rho0 dx^dim / dx^(dim+1))^2."""
    h = smoothing_ratio
    q = _lattice_q(h, dim)
    q = q[q > 0.0]
    if kernel is KernelType.CUBIC_SPLINE:
        dw = np.where(q < 1.0, -3.0 * q + 2.25 * q**2, -0.75 * (2.0 - q) ** 2) / h
    else:
        dw = -5.0 * q * (1.0 - 0.5 * q) ** 3 / h
    return float((kernel_sigma(kernel, h, dim) * dw) ** 2 @ np.ones_like(q))


@wp.func
def kernel_w(r: float, inv_h: float, sigma: float, kind: int) -> float:
    """W(r) (1/m^dim)."""
    q = r * inv_h
    if q >= 2.0:
        return 0.0
    if kind == 0:
        if q < 1.0:
            return sigma * (1.0 - 1.5 * q * q + 0.75 * q * q * q)
        t = 2.0 - q
        return sigma * 0.25 * t * t * t
    t = 1.0 - 0.5 * q
    t2 = t * t
    return sigma * t2 * t2 * (2.0 * q + 1.0)


@wp.func
def kernel_dw(r: float, inv_h: float, sigma: float, kind: int) -> float:
    """dW/dr (1/m^(dim+1)); the gradient is dW/dr * r_vec / r."""
    q = r * inv_h
    if q >= 2.0:
        return 0.0
    if kind == 0:
        if q < 1.0:
            return sigma * inv_h * (-3.0 * q + 2.25 * q * q)
        t = 2.0 - q
        return -0.75 * sigma * inv_h * t * t
    t = 1.0 - 0.5 * q
    return -5.0 * sigma * inv_h * q * t * t * t
