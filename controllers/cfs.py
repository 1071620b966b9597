"""Constant-flow stage: hold the liquid height over the crest at h_ref (Camporredondo et al. 2019, Sec. 3.2,
Fig. 9, Eq. 16).

Each control step the crest has to come down, relative to the liquid, by a height dh; the paper's vector step
(:func:`controllers.geometry.vector_step`) turns dh into a tilt increment. The paper's b is "how far the level
over the lip dropped this step"; here dh has two parts, which make it a feedback law that a sloshing liquid
tolerates:

* the level drop of this step, from the measured outflow: outflow rate * dt / (inner depth * free-surface chord)
  (feed-forward: the draining vessel needs a steadily growing tilt; without it the integral law below lags
  a ramp with a constant error);
* a correction of the fraction dt / time_constant of the error h_ref - h_q (time_constant = dt would be the
  paper's one-step correction). Linearised, this is the integral law theta' = (theta1_ref - theta1) /
  time_constant on the slosh plant, because at the crest h_q depends, to first order, only on the free
  surface's angle theta1 in the vessel frame.

The centre of rotation of the vector step is the midpoint of the free surface: a level surface spanning the
vessel turns about that point when the vessel tilts with its volume unchanged, so lowering the crest by dh about
it raises the static h_q by exactly dh (tested).

The pose turns about the pour lip (the jet's launch point stays put for the catcher) as long as the lip is at
least ``pivot_margin`` above the slosh pendulum's hinge in the world; beyond that (large tilts, where the lip
sinks below the hinge) about the point that far above the hinge straight over the lip, which moves the lip
only sideways. Why: rotating about a pivot at effective height p (:meth:`controllers.slosh.SloshModel.plant`)
makes the loop polynomial of the integral law l1 s^3 + k (b2 + p) s^2 + g s + k g (k = 1/time_constant),
Hurwitz iff b2 + p > l1, i.e. iff the pivot is above the hinge; a margin m above it damps the slosh mode at
the rate k m / (2 l1). The floor centre (the SIM pivot) is below the hinge and would pump the slosh.
"""

from __future__ import annotations

import math

import numpy as np

from controllers.geometry import MAX_STATIC_TILT, VesselGeometry, rotate, surface_chord, vector_step
from controllers.slosh import SloshModel

AFTER_FLOW_SAMPLES = 257  # quadrature points for the after-flow integral (trapezoid; smooth integrand)
DEEPEST_TILT_HALVINGS = 40  # bisection of [0, 90 deg) for deepest_crest_tilt: 1.4e-12 rad


def _static_chord(geom: VesselGeometry, theta: float, area: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """Vessel-frame chord of the level free surface at tilt ``theta`` (slope clipped below 90 deg)."""
    slope_angle = min(max(theta, -MAX_STATIC_TILT), MAX_STATIC_TILT)
    return surface_chord(geom.inner_width, math.tan(slope_angle), area)


def crest_lever(geom: VesselGeometry, theta: float, area: float) -> tuple[float, float]:
    """World vector a (m) from the level free surface's midpoint to the crest, vessel tilted by ``theta``."""
    (x0, z0), (x1, z1) = _static_chord(geom, theta, area)
    cx, cz = geom.crest
    return rotate(theta, (cx - 0.5 * (x0 + x1), cz - 0.5 * (z0 + z1)))


def deepest_crest_tilt(geom: VesselGeometry, area: float) -> float:
    """Tilt (rad) beyond which tilting on raises the crest over the level surface of ``area`` (m^2): where the crest
    lever (:func:`crest_lever`) turns vertical, a_x = 0, and the liquid at rest stands highest over the crest.

    Turning by dtheta lowers the crest by a_x dtheta relative to the surface's midpoint; as the liquid left becomes a
    wedge against the lip wall (past about 84 deg in a pour), a_x falls through zero within a degree (the wedge's
    midpoint moves along the wall as the vessel turns). Past that tilt the vector step answers a head below its
    reference with a turn back, short of it with a turn forward: at the rate limit, of either sign from one step to
    the next. CFS stops at this tilt instead (:class:`controllers.pour.PourController`), which rises as the vessel
    drains. Bisection of a_x over [0, 90 deg) (a_x > 0 upright: the crest lies toward the lip from the midpoint);
    ``math.inf`` where a_x stays positive up to 90 deg."""
    if crest_lever(geom, MAX_STATIC_TILT, area)[0] > 0.0 or crest_lever(geom, 0.0, area)[0] <= 0.0:
        return math.inf
    lo, hi = 0.0, MAX_STATIC_TILT
    for _ in range(DEEPEST_TILT_HALVINGS):
        mid = 0.5 * (lo + hi)
        if crest_lever(geom, mid, area)[0] > 0.0:
            lo = mid
        else:
            hi = mid
    return lo


def level_drop(geom: VesselGeometry, theta: float, area: float, outflow: float) -> float:
    """Drop (m) of the free surface when ``outflow`` (m^3) leaves: volume / (inner depth * chord length)."""
    (x0, z0), (x1, z1) = _static_chord(geom, theta, area)
    return outflow / (geom.inner_depth * max(math.hypot(x1 - x0, z1 - z0), 1e-9))


def cfs_increment(
    geom: VesselGeometry,
    theta: float,
    area: float,
    h_q: float,
    h_ref: float,
    fraction: float,
    outflow: float,
    max_step: float,
) -> float:
    """Tilt increment (rad) of one CFS step, clipped to +-max_step.

    theta: commanded tilt (rad); area: liquid area in the pour plane (m^2); h_q, h_ref: m; fraction: dt /
    time_constant; outflow: m^3 that left the pourer during this step (filtered rate * dt).
    """
    dh = level_drop(geom, theta, area, outflow) + fraction * (h_ref - h_q)
    dtheta = vector_step(crest_lever(geom, theta, area), dh)
    return min(max(dtheta, -max_step), max_step)


def cfs_pivot(geom: VesselGeometry, model: SloshModel, theta: float, margin: float) -> tuple[float, float]:
    """Vessel-frame pivot (m) of the CFS rotation at tilt ``theta``: the lip, raised along world z if needed
    to stay ``margin`` (m) above the pendulum's hinge."""
    need = margin - model.pivot_above_hinge(geom.lip, theta)
    if need <= 0.0:
        return geom.lip
    up_x, up_z = rotate(-theta, (0.0, need))  # world (0, need) in the vessel frame
    return (geom.lip[0] + up_x, geom.lip[1] + up_z)


def after_flow_volume(
    outflow_rate: float,
    h_q: float,
    lever: tuple[float, float],
    max_rate: float,
    max_accel: float,
    tilt_rate: float = 0.0,
    lag: float = 0.0,
) -> float:
    """Volume (m^3) that still leaves after the return starts, to stop a partial pour early by that much.

    The vessel follows its commands ``lag`` s late (the task-space smoothing and the arm): for that long it still
    carries out CFS commands given before the stop, which hold the head, so the outflow goes on at
    ``outflow_rate`` (m^3/s). Then the return acts: it starts from the tilt rate ``tilt_rate`` (rad/s, + forward;
    CFS is usually still tilting forward), turns back with ``max_accel`` (rad/s^2) up to ``max_rate`` (rad/s); the
    crest rises over the surface in proportion to the angle turned back (and sinks further while the vessel still
    moves forward) until, after the vector-step angle for -h_q about ``lever`` (a, m), it clears the head ``h_q``
    (m). Over a sharp crest the outflow goes as h^(3/2), so that part is outflow_rate times the integral of
    (1 - back / angle)^(3/2) over that time, back(t) the angle turned back.
    """
    if h_q <= 0.0 or outflow_rate <= 0.0:
        return 0.0
    angle = -vector_step(lever, -h_q)
    w0 = max(tilt_rate, 0.0)
    t_turn = (w0 + max_rate) / max_accel  # until the backward rate reaches max_rate
    back_at_turn = -w0 * t_turn + 0.5 * max_accel * t_turn**2
    if back_at_turn >= angle:  # clears the head while still accelerating back: -w0 t + a t^2 / 2 = angle
        duration = (w0 + math.sqrt(w0 * w0 + 2.0 * max_accel * angle)) / max_accel
    else:
        duration = t_turn + (angle - back_at_turn) / max_rate
    t = np.linspace(0.0, duration, AFTER_FLOW_SAMPLES)
    back = np.where(t < t_turn, -w0 * t + 0.5 * max_accel * t**2, back_at_turn + max_rate * (t - t_turn))
    head = np.clip(1.0 - back / angle, 0.0, None)
    return float(outflow_rate * (max(lag, 0.0) + np.trapezoid(head**1.5, t)))
