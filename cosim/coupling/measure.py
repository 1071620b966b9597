"""What the pour controller reads from the SPH liquid each control step (``controllers.LiquidMeasurement``).

Implements the measurement contract written in :class:`controllers.measurement.LiquidMeasurement` exactly
(free-surface angle theta1 from a least-squares line through the top particle of each column of width h in the
pourer's frame; h_q over the crest; v_q through the lip plane; volumes; lip and catcher-rim positions). The pour
lip used here is where the simulated liquid leaves the vessel: the outer top edge of the wall as the liquid sees
it (``FluidModel.wall_thickness``, at least the dummy-particle layers), which is also the wall thickness given to
the controller, so that its jet launch point is the simulated one.

Vectorised numpy over the particles (one pass per control step, outside the SPH step).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from controllers.geometry import height_above
from controllers.measurement import LiquidMeasurement
from cosim.frames import Pose, tilt_about_y
from cosim.vessel import VesselSpec

MIN_FIT_COLUMNS = 3  # the contract: fewer columns than this and theta1 = tilt


@dataclass(frozen=True)
class MeasurementGeometry:
    """What the measurement needs to know: the pourer (spec, wall thickness the liquid sees), the catcher's
    inner height, the smoothing length h and spacing dx (m), and the liquid's initial volume (m^3)."""

    pourer: VesselSpec
    wall_thickness: float
    catcher_height: float
    smoothing_length: float
    spacing: float
    initial_volume: float
    dim: int

    @property
    def crest_local(self) -> np.ndarray:
        return np.array([0.5 * self.pourer.inner_width, 0.0, self.pourer.inner_height])

    @property
    def lip_local(self) -> np.ndarray:
        return np.array([0.5 * self.pourer.inner_width + self.wall_thickness, 0.0, self.pourer.inner_height])


def free_surface_fit(local: np.ndarray, width: float, h: float) -> tuple[float, float, int]:
    """(c, slope, columns): least-squares line z = c + slope x through the highest particle of each column of
    width h over x in [-B/2 + h, B/2 - h] (vessel frame, particles already restricted to the inner box)."""
    lo, hi = -0.5 * width + h, 0.5 * width - h
    n_cols = int(math.floor((hi - lo) / h + 1e-9))
    if n_cols < 1 or len(local) == 0:
        return 0.0, 0.0, 0
    sel = (local[:, 0] >= lo) & (local[:, 0] < lo + n_cols * h)
    col = np.floor((local[sel, 0] - lo) / h).astype(int)
    x, z = local[sel, 0], local[sel, 2]
    top = np.full(n_cols, -np.inf)
    np.maximum.at(top, col, z)
    # the x of each column's top particle
    top_x = np.full(n_cols, np.nan)
    is_top = z == top[col]
    top_x[col[is_top]] = x[is_top]
    used = np.isfinite(top)
    if used.sum() < MIN_FIT_COLUMNS:
        return 0.0, 0.0, int(used.sum())
    slope, c = np.polyfit(top_x[used], top[used], 1)
    return float(c), float(slope), int(used.sum())


def measure(
    t: float,
    geo: MeasurementGeometry,
    pourer_pose: Pose,
    catcher_pose: Pose,
    positions: np.ndarray,
    velocities: np.ndarray,
    active: np.ndarray,
    volume_in_pourer: float,
) -> LiquidMeasurement:
    """The controller's measurement from world-frame particle positions (N, 3) m, velocities (N, 3) m/s, the
    active mask (N,) and the solver's count-based volume in the pourer (m^3)."""
    spec, dx, h = geo.pourer, geo.spacing, geo.smoothing_length
    b, d, height = 0.5 * spec.inner_width, 0.5 * spec.section_depth, spec.inner_height
    x, v = positions[active], velocities[active]
    tilt = tilt_about_y(pourer_pose.rotation)
    local = pourer_pose.inverse_transform(x)
    inner = (np.abs(local[:, 0]) <= b) & (local[:, 2] >= 0.0) & (local[:, 2] <= height)
    if geo.dim == 3:
        inner &= np.abs(local[:, 1]) <= d
    c, slope, columns = free_surface_fit(local[inner], spec.inner_width, h)
    theta1 = math.atan(slope) if columns >= MIN_FIT_COLUMNS else tilt

    crest = pourer_pose.transform(geo.crest_local[None, :])[0]
    over_crest = (np.abs(x[:, 0] - crest[0]) <= dx) & (x[:, 2] > crest[2])
    if over_crest.any():
        h_q = float(x[over_crest, 2].max() + 0.5 * dx - crest[2])
    elif columns >= MIN_FIT_COLUMNS:
        h_q = min(height_above((geo.crest_local[0], geo.crest_local[2]), c, theta1, tilt), 0.0)
    else:
        h_q = -height  # no surface to measure: far below the crest

    lip = pourer_pose.transform(geo.lip_local[None, :])[0]
    top = lip[2] + dx + max(h_q, 0.0)
    leaving = (x[:, 0] >= lip[0] - dx) & (x[:, 0] <= lip[0] + 3 * dx) & (x[:, 2] >= lip[2] - 3 * dx) & (x[:, 2] <= top) & ~inner
    if leaving.any():
        v_q, v_q_z = (float(c) for c in v[leaving][:, [0, 2]].mean(axis=0))
        jet_dx, jet_dz = (float(c) for c in x[leaving][:, [0, 2]].mean(axis=0) - lip[[0, 2]])
    else:
        v_q = v_q_z = jet_dx = jet_dz = 0.0
    rim = catcher_pose.transform(np.array([[0.0, 0.0, geo.catcher_height]]))[0]
    return LiquidMeasurement(
        t=t,
        tilt=tilt,
        theta1=theta1,
        h_q=h_q,
        v_q=v_q,
        volume_in_pourer=volume_in_pourer,
        poured_volume=max(geo.initial_volume - volume_in_pourer, 0.0),
        lip_x=float(lip[0]),
        lip_z=float(lip[2]),
        catcher_rim_z=float(rim[2]),
        v_q_z=v_q_z,
        jet_dx=jet_dx,
        jet_dz=jet_dz,
    )
