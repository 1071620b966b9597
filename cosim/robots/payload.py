"""The liquid as a rigid payload, for runs without the fluid solver (``cosim replay``).

Conventions: SI units; the payload is a child body ``<vessel>/liquid`` of the vessel body, in the vessel frame (origin
at the centre of the inner floor, +z up): a uniform block of water filling the upright vessel to the fill depth (a
box, or a cylinder for a cylindrical vessel). Rigid: no slosh. Its gravity compensation equals the vessel's, as a
UR controller compensates a payload whose mass and centre of gravity were entered in its installation.
"""

from __future__ import annotations

from enum import Enum
from typing import TYPE_CHECKING

import numpy as np

from cosim.vessel import VesselSpec

if TYPE_CHECKING:  # only the annotations name MuJoCo: `cosim replay --help` lists PayloadMode without loading it
    import mujoco

# Density of the liquid, kg/m^3 (water, the fluid's rest density rho0).
LIQUID_DENSITY = 1000.0


class PayloadMode(Enum):
    """Closed choice of the rigid liquid payload."""

    EMPTY = "empty"  # no liquid: the vessels' own mass only
    FULL = "full"  # pourer filled to the rim; the catcher holding that same volume (the end of a complete pour)


def payload_fill_depths(pourer: VesselSpec, catcher: VesselSpec, mode: PayloadMode) -> dict[str, float]:
    """Fill depth (m) of each vessel for ``mode``; 0 means no payload body. Keys are the vessel names."""
    if mode is PayloadMode.EMPTY:
        return {pourer.name: 0.0, catcher.name: 0.0}
    volume = pourer.capacity
    return {pourer.name: pourer.inner_height, catcher.name: min(volume / catcher.inner_floor_area, catcher.inner_height)}


def add_liquid_payload(spec: mujoco.MjSpec, vessel: VesselSpec, fill_depth: float) -> None:
    """Add the rigid water block filling ``vessel`` to ``fill_depth`` (m) under the vessel body of ``spec``."""
    vessel_body = spec.body(vessel.name)
    mass = LIQUID_DENSITY * vessel.inner_floor_area * fill_depth
    if vessel.is_box:
        a, b, c = vessel.inner_width, vessel.inner_depth, fill_depth
        inertia = mass / 12.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    else:
        r = 0.5 * vessel.inner_width
        transverse = mass * (3.0 * r * r + fill_depth**2) / 12.0
        inertia = np.array([transverse, transverse, 0.5 * mass * r * r])
    body = vessel_body.add_body(name=f"{vessel.name}/liquid")
    body.gravcomp = vessel_body.gravcomp
    body.explicitinertial = True
    body.mass = mass
    body.ipos = [0.0, 0.0, 0.5 * fill_depth]
    body.inertia = list(map(float, inertia))

