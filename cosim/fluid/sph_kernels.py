"""SPH smoothing kernels (warp functions), both with compact support 2h, for 2-D and 3-D.

Cubic spline: Monaghan (1992), the kernel of Camporredondo et al. (2019); sigma = 10/(7 pi h^2) (2-D), 1/(pi h^3) (3-D).
Wendland C2: Wendland (1995), W = sigma (1 - q/2)^4 (2q + 1); sigma = 7/(4 pi h^2) (2-D), 21/(16 pi h^3) (3-D).
q = r / h. ``kind`` is :class:`cosim.fluid.config.KernelType` as an int (see ``KERNEL_IDS``).
"""

from __future__ import annotations

import functools
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


def _lattice_points(smoothing_ratio: float, dim: int) -> np.ndarray:
    """(k, dim) points of a square (cubic) lattice of unit spacing within the support 2h, the centre included."""
    reach = math.ceil(2.0 * smoothing_ratio)
    axis = np.arange(-reach, reach + 1, dtype=float)
    grid = np.stack(np.meshgrid(*([axis] * dim), indexing="ij"), axis=-1).reshape(-1, dim)
    return grid[np.linalg.norm(grid, axis=1) < 2.0 * smoothing_ratio]


def _lattice_q(smoothing_ratio: float, dim: int) -> np.ndarray:
    """q = r / h of the lattice points within the support, the centre included."""
    return np.linalg.norm(_lattice_points(smoothing_ratio, dim), axis=1) / smoothing_ratio


def _kernel_slope(kernel: KernelType, q: np.ndarray, h: float) -> np.ndarray:
    """dW/dr / sigma at q = r / h (h in the same unit as r)."""
    if kernel is KernelType.CUBIC_SPLINE:
        return np.where(q < 1.0, -3.0 * q + 2.25 * q**2, -0.75 * (2.0 - q) ** 2) / h
    return -5.0 * q * (1.0 - 0.5 * q) ** 3 / h


def kernel_values(kernel: KernelType, r: np.ndarray, h: float, dim: int) -> np.ndarray:
    """W (1/m^dim) at distances ``r`` (m) for smoothing length ``h`` (m); 0 beyond the support 2h."""
    return kernel_sigma(kernel, h, dim) * _kernel_shape(kernel, np.asarray(r, dtype=float) / h)


def kernel_derivatives(kernel: KernelType, r: np.ndarray, h: float, dim: int) -> np.ndarray:
    """dW/dr (1/m^(dim+1)) at distances ``r`` (m) for smoothing length ``h`` (m); 0 beyond the support 2h. The
    gradient of W(x - x_b) with respect to x is dW/dr (x - x_b) / r."""
    r = np.asarray(r, dtype=float)
    return np.where(r < 2.0 * h, kernel_sigma(kernel, h, dim) * _kernel_slope(kernel, r / h, h), 0.0)


def _kernel_shape(kernel: KernelType, q: np.ndarray) -> np.ndarray:
    """W / sigma at q = r / h; 0 beyond q = 2."""
    if kernel is KernelType.CUBIC_SPLINE:
        w = np.where(q < 1.0, 1.0 - 1.5 * q**2 + 0.75 * q**3, 0.25 * (2.0 - q) ** 3)
    else:
        w = (1.0 - 0.5 * q) ** 4 * (2.0 * q + 1.0)
    return np.where(q < 2.0, w, 0.0)


def lattice_kernel_sum(kernel: KernelType, smoothing_ratio: float, dim: int) -> float:
    """sum_j W(x_i - x_j) dx^dim over a full square (cubic) lattice of spacing dx around x_i (itself included):
    the summation density of a resting lattice in units of rho0 (1.005 for Wendland C2 at h = 1.5 dx in 2-D)."""
    h = smoothing_ratio  # in units of dx
    return float(kernel_sigma(kernel, h, dim) * _kernel_shape(kernel, _lattice_q(h, dim)).sum())


def lattice_gradient_square_sum(kernel: KernelType, smoothing_ratio: float, dim: int) -> float:
    """sum_j |grad W(x_i - x_j)|^2 dx^(2 dim + 2) over the same lattice (dimensionless): the DFSPH factor's
    denominator of a particle inside a resting liquid, in units of (rho0 dx^dim / dx^(dim+1))^2."""
    h = smoothing_ratio
    q = _lattice_q(h, dim)
    q = q[q > 0.0]
    return float((kernel_sigma(kernel, h, dim) * _kernel_slope(kernel, q, h)) ** 2 @ np.ones_like(q))


# Wave numbers per axis over [0, pi] (the lattice is symmetric, so the non-negative ones suffice) at which
# lattice_jacobi_gain looks for its maximum
JACOBI_GAIN_SAMPLES = {2: 41, 3: 17}


@functools.cache
def lattice_jacobi_gain(kernel: KernelType, smoothing_ratio: float, dim: int) -> float:
    """Largest eigenvalue of D^-1 A for DFSPH's pressure system on a resting lattice: how far one Jacobi step (the
    DFSPH factor is the diagonal D) overshoots its most amplified mode. A stiffness field kappa_j = exp(i k . x_j)
    changes the density rate of particle i by (m^2 / rho) |sum_j exp(-i k . r_ij) grad W_ij|^2 times that field,
    and the factor's diagonal is (m^2 / rho) sum_j |grad W_ij|^2 (the lattice's sum_j grad W_ij is zero), so the gain
    is the largest ratio of the two over the wave vectors k of the Brillouin zone (sampled, JACOBI_GAIN_SAMPLES).
    Dimensionless; it grows with the neighbours a support holds: 3.34 for Wendland C2 at h = 1.5 dx in 2-D, 6.25 in
    3-D."""
    points = _lattice_points(smoothing_ratio, dim)
    r = np.linalg.norm(points, axis=1)
    points, r = points[r > 0.0], r[r > 0.0]
    grad = (_kernel_slope(kernel, r / smoothing_ratio, smoothing_ratio) / r)[:, None] * points
    axis = np.linspace(0.0, math.pi, JACOBI_GAIN_SAMPLES[dim])
    waves = np.stack(np.meshgrid(*([axis] * dim), indexing="ij"), axis=-1).reshape(-1, dim)
    response = np.exp(-1j * waves @ points.T) @ grad
    return float((np.abs(response) ** 2).sum(axis=1).max() / (grad**2).sum())


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
