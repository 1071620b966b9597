"""Where a poured stream leaves its vessel: the height over the wall's outer top edge (the lip) at which the
stream's lower surface passes the plane of the wall's outer face.

The physics of an overfall (Rouse 1936, "Discharge characteristics of the free overfall"; Henderson 1966, "Open
channel flow", sharp-, narrow- and broad-crested weirs): once the nappe has left the wall its particles are in free
fall (zero pressure on both of its surfaces), and its lower surface leaves from an edge of the wall's top face. A
stream that stays on the top face leaves it at the face's outer edge, tangent to the face, and its lower surface
passes the outer face's plane at the lip: height 0. A nappe over a top face short against its head (a narrow crest:
length / head below about 0.4) springs from the face's upstream (inner) edge and passes the outer face above the lip:
height > 0. A stream held on a crest that reaches past the real wall (dummy layers thicker than the wall) bends down
only at that crest's end, so its free path, traced back, passes the real outer face below the lip, through the wall:
height < 0, the lip a real vessel does not have. Which edge a thin wall's nappe leaves from depends on the head, so
the height is checked on that side only, in every window of the pour (:data:`LIP_TOLERANCE`), and reported in full.

The measure, per launched particle (the pour plane x-z, world frame, the vessel's pose at launch): its free-fall
path p(s) = p0 + v s + g s^2 / 2 (g = (0, -g)) through its launch state, where it passes out through the plane
n . (p - P) = 0, with P the lip and n the wall's outward normal (the vessel's +x); the crossing's coordinate along
the outer face, e = u . (p(s) - P), u the vessel's +z (positive: clear of the wall, on the opening's side; negative:
below the lip, through the wall). The stream's lowest particles are its lower row, whose centres lie half a spacing
inside the liquid's surface (the liquid's first row lies dx / 2 from a wall's surface), so the lower surface passes at
e_low - dx / 2. This is the offset across the stream at the lip, which moves the whole stream; where along the
stream an attached nappe leaves is ill-conditioned (a tangent and a parabola part quadratically) and, for the same
reason, of second order for where it lands.
"""

from __future__ import annotations

import numpy as np

from cosim.fluid.config import GRAVITY

# Acceptance: in every window of launch times, the stream's lower surface, on its free-fall path, passes the real
# wall's outer face no more than this below the lip. Below it, the stream left from a crest the real vessel does not
# have; above it, the nappe sprang clear of the wall's top face, as a thin wall's does under a head several times its
# thickness (a narrow-crested weir's nappe leaves its upstream edge).
LIP_TOLERANCE = 0.001  # m
WINDOW = 0.05  # s of launch time per lower-edge sample: several particles of the lower row launch in each
LOWER_QUANTILE = 0.1  # of a window's crossings, taken as its lower row (robust to a single stray particle)
MIN_PER_WINDOW = 5  # crossings a window needs for its lower quantile to mean anything


def plane_crossings(launch: np.ndarray, normal: np.ndarray, along: np.ndarray, edge: np.ndarray) -> np.ndarray:
    """Where each particle's free-fall path through its launch state passes out through the plane through ``edge``
    with unit outward normal ``normal``: the coordinate along unit ``along`` of the crossing, from ``edge`` (m).

    launch: (N, 4) x, z, v_x, v_z (m, m/s); normal, along: (N, 2) or (2,) unit vectors in x-z; edge: (N, 2) or
    (2,) m. NaN where the path never passes out through the plane.

    n . (p(s) - P) = a + b s + c s^2 with a = n . (p0 - P), b = n . v, c = n . g / 2; the outward crossing is the root
    where the derivative b + 2 c s = +sqrt(b^2 - 4 a c) > 0, s = -2 a / (b + sqrt(b^2 - 4 a c)) (the form that holds
    for c = 0 too): before launch (s < 0) for a particle already beyond the plane, after it for one launched while
    still over the crest (a thick stream's upper part when the opening faces sideways)."""
    normal, along, edge = (np.broadcast_to(np.asarray(x, float), (len(launch), 2)) for x in (normal, along, edge))
    p0, v = launch[:, :2], launch[:, 2:4]
    gvec = np.array([0.0, -GRAVITY])
    a = np.einsum("ij,ij->i", normal, p0 - edge)
    b = np.einsum("ij,ij->i", normal, v)
    c = 0.5 * normal @ gvec
    disc = b * b - 4.0 * a * c
    denominator = b + np.sqrt(np.where(disc >= 0.0, disc, np.nan))
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(denominator > 0.0, -2.0 * a / denominator, np.nan)
    p = p0 + v * s[:, None] + 0.5 * gvec * (s * s)[:, None]
    return np.einsum("ij,ij->i", along, p - edge)


def lower_edge(t_launch: np.ndarray, crossings: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """The stream's lower surface at the plane, one value per :data:`WINDOW` of launch times (s, m): each window's
    :data:`LOWER_QUANTILE` of the crossings (its lower row of particle centres) less ``spacing`` / 2 (m). Windows with
    fewer than :data:`MIN_PER_WINDOW` crossings are left out; returns (window start times, lower surface)."""
    ok = np.isfinite(crossings)
    t, e = t_launch[ok], crossings[ok]
    if len(t) == 0:
        return np.empty(0), np.empty(0)
    index = np.floor((t - t.min()) / WINDOW).astype(int)
    starts, edges = [], []
    for k in np.unique(index):
        inside = e[index == k]
        if len(inside) >= MIN_PER_WINDOW:
            starts.append(t.min() + k * WINDOW)
            edges.append(np.quantile(inside, LOWER_QUANTILE) - 0.5 * spacing)
    return np.asarray(starts), np.asarray(edges)


def summary(lower: np.ndarray) -> dict[str, float]:
    """Median, quartiles and extremes (m) of the windows' lower-surface values, and how many windows there were."""
    if len(lower) == 0:
        return {"median": float("nan"), "q25": float("nan"), "q75": float("nan"), "min": float("nan"), "max": float("nan"), "windows": 0}
    q25, median, q75 = np.quantile(lower, [0.25, 0.5, 0.75])
    return {"median": float(median), "q25": float(q25), "q75": float(q75), "min": float(lower.min()), "max": float(lower.max()),
            "windows": len(lower)}
