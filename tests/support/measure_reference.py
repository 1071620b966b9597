"""A plain numpy transcription of the measurement contract (controllers.measurement.LiquidMeasurement) and of the
rim-plane crossing, written over particle arrays: the independent reference the device probe
(cosim.coupling.measure.LiquidProbe) is checked against on real SPH states."""

from __future__ import annotations

import math

import numpy as np

from controllers.geometry import height_above
from cosim.coupling.landing import BAND_SPACINGS, MIN_FALL_SPEED_FRACTION
from cosim.coupling.free_surface import MIN_FIT_COLUMNS
from cosim.coupling.measure import MeasurementGeometry
from cosim.frames import Pose, tilt_about_y
from cosim.vessel import VesselShape


def reference_measure(geo: MeasurementGeometry, pourer: Pose, catcher: Pose, x: np.ndarray, v: np.ndarray) -> dict:
    """theta1, h_q, v_q, v_q_z, jet_dx, jet_dz, lip_x, lip_z, catcher_rim_z of the active particles x, v (N, 3)."""
    spec, dx = geo.pourer, geo.spacing
    b, d, height = 0.5 * spec.inner_width, 0.5 * spec.section_depth, spec.inner_height
    tilt = tilt_about_y(pourer.rotation)
    local = pourer.inverse_transform(x)
    inner = (np.abs(local[:, 0]) <= b) & (local[:, 2] >= 0.0) & (local[:, 2] <= height)
    if geo.dim == 3:
        inner &= np.abs(local[:, 1]) <= d
    q = local[inner]
    across = np.ones(len(q))
    if geo.dim == 3:
        across = 2.0 * (np.sqrt(np.maximum(b * b - q[:, 0] ** 2, 0.0)) if spec.shape is VesselShape.CYLINDER else np.full(len(q), d))
        q, across = q[across > 0.0], across[across > 0.0]
    w = 2.0 * dx  # the columns' B-spline width and spacing
    n_cols = geo.columns
    xs = (np.arange(n_cols) - n_cols // 2) * w
    weights = [_bspline((q[:, 0] - xk) / w) / across ** (geo.dim - 2) * dx**geo.dim / w for xk in xs]
    levels = [max(weight.sum() - 3.0 * dx, 2.0 * dx) for weight in weights]  # z_k: three spacings under M_k
    volumes = np.array([(weight * _bspline_integral((q[:, 2] - z) / dx)).sum() for weight, z in zip(weights, levels)])
    used = volumes > 0.0
    heights = np.array([z + dx * _level_for_volume(m / dx) if m > 0.0 else np.nan for z, m in zip(levels, volumes)])
    if used.sum() >= MIN_FIT_COLUMNS:
        slope, c = np.polyfit(xs[used], heights[used], 1)
        theta1 = math.atan(slope)
    else:
        c, theta1 = 0.0, tilt
    crest = pourer.transform(geo.crest_local[None, :])[0]
    w = 2.0 * dx  # the window's width, its centre one width upstream of the crest
    d = x - np.array([crest[0] - w, crest[1], crest[2]])
    weight = _bspline(d[:, 0] / w) * _bspline_integral(d[:, 2] / dx) * (_bspline(d[:, 1] / w) if geo.dim == 3 else 1.0)
    if weight.sum() > 0.0:
        h_q = dx * _level_for_volume(float(weight.sum()) * (dx / w) ** (geo.dim - 1))
    elif used.sum() >= MIN_FIT_COLUMNS:
        h_q = min(height_above((geo.crest_local[0], geo.crest_local[2]), c, theta1, tilt), 0.0)
    else:
        h_q = -height
    lip = pourer.transform(geo.lip_local[None, :])[0]
    top_z = lip[2] + dx + max(h_q, 0.0)
    leaving = (x[:, 0] >= lip[0] + dx) & (x[:, 0] <= lip[0] + 4 * dx) & (x[:, 2] >= lip[2] - 6 * dx) & (x[:, 2] <= top_z) & ~inner
    if leaving.any():
        v_q, v_q_z = v[leaving][:, [0, 2]].mean(axis=0)
        jet_dx, jet_dz = x[leaving][:, [0, 2]].mean(axis=0) - lip[[0, 2]]
    else:
        v_q = v_q_z = jet_dx = jet_dz = 0.0
    rim = catcher.transform(np.array([[0.0, 0.0, geo.catcher_height]]))[0]
    return dict(theta1=theta1, h_q=h_q, v_q=v_q, v_q_z=v_q_z, jet_dx=jet_dx, jet_dz=jet_dz, lip_x=lip[0], lip_z=lip[2],
                catcher_rim_z=rim[2], leaving=int(leaving.sum()))


def _bspline(s: np.ndarray) -> np.ndarray:
    """Cubic B-spline of unit spacing (support [-2, 2], unit integral)."""
    a = np.abs(s)
    return np.where(a < 1.0, 2.0 / 3.0 - a**2 + 0.5 * a**3, np.where(a < 2.0, (2.0 - np.minimum(a, 2.0)) ** 3 / 6.0, 0.0))


def _bspline_integral(s: np.ndarray) -> np.ndarray:
    """Integral of the cubic B-spline from -inf to s, by Simpson's rule on its pieces (exact for cubics)."""
    s = np.clip(np.asarray(s, dtype=float), -2.0, 2.0)
    total = np.zeros_like(s)
    for k in np.arange(-2.0, 2.0):  # each piece [k, k + 1] is one cubic
        b = np.clip(s, k, k + 1.0)
        total += (b - k) / 6.0 * (_bspline(np.full_like(b, k)) + 4.0 * _bspline(0.5 * (k + b)) + _bspline(b))
    return total


def _level_for_volume(volume: float) -> float:
    """v (spacings) whose resting level has this volume over the crest: bisection of G(v) = integral of the
    B-spline's integral from -inf to v (trapezoid on a fine grid), G(v) = v from v = 2 on."""
    if volume >= 2.0:
        return volume
    grid = np.linspace(-2.0, 2.0, 40001)
    share = _bspline_integral(grid)
    second = np.concatenate([[0.0], np.cumsum(0.5 * (share[1:] + share[:-1]) * np.diff(grid))])
    return float(np.interp(volume, second, grid))


def reference_crossing_x(x: np.ndarray, v: np.ndarray, rim_z: float, lip_z: float, spacing: float, gravity: float) -> float:
    """Median x of the active particles falling through the rim plane (cosim.coupling.landing's definition)."""
    min_speed = MIN_FALL_SPEED_FRACTION * math.sqrt(2.0 * gravity * max(lip_z - rim_z, 0.0))
    falling = (np.abs(x[:, 2] - rim_z) <= BAND_SPACINGS * spacing) & (v[:, 2] < -min_speed)
    return float(np.median(x[falling, 0])) if falling.any() else math.nan
