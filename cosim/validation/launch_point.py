"""Where a poured stream leaves its vessel: the crossing of the stream's lower surface with the plane of the wall's
outer face, measured from the wall's outer top edge.

The physics (an overfall at a sharp edge: Rouse 1936, "Discharge characteristics of the free overfall"; Henderson
1966, "Open channel flow", the free overfall and the sharp-crested weir): liquid running over the top face of a
wall leaves it at the face's outer edge, and the nappe's lower surface springs from that edge tangent to the face;
from there each liquid particle is in free fall (zero pressure on both surfaces of the nappe). So the lower
surface of a stream that leaves the real vessel passes through the real lip, the wall's outer top edge. A stream
held on a crest that reaches past the real wall (dummy layers thicker than the wall) stays on the top face's line
for longer and only then bends down: its lower surface, traced back along its free-fall parabola, passes the real
outer face below the lip, inside the wall. One that the wall pushes off early passes above it.

The measure, per launched particle (the pour plane x-z, world frame, the vessel's pose at launch): its free-fall
parabola p(s) = p0 + v s + g s^2 / 2 (g = (0, -g), s <= 0) traced back to its latest crossing of the plane
n . (p - P) = 0, with P the wall's outer top edge and n the wall's outward normal (the vessel's +x); the crossing's
coordinate along the outer face, e = u . (p(s) - P) with u the vessel's +z (positive: clear of the wall, on the
opening's side; negative: behind the real lip, through the wall). The lowest particles of the stream are its lower
row, whose centres lie half a spacing inside the liquid's surface (the liquid's first row lies dx / 2 from a wall's
surface), so the lower surface passes at e_low - dx / 2. Tangential departure makes where along the stream it leaves
ill-conditioned (a tangent and a parabola part quadratically) and, for the same reason, of second order for where
it lands; the offset across the stream at the real lip is what moves the whole stream, and is what this measures.
"""

from __future__ import annotations

import numpy as np

from cosim.fluid.config import GRAVITY

# Acceptance: the stream's lower surface, on its free-fall path, passes the real wall's outer face no more than this
# below the lip. Below it, the stream left from a crest the real vessel does not have; above it, the nappe sprang
# clear of the wall's top face, as a thin wall's does (a narrow-crested weir's nappe leaves its upstream edge).
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
