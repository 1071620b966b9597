"""The vessel specification: one source of truth for the fluid boundary and the MuJoCo body.

Both the SPH solver (``cosim.fluid``) and the robot scene (``cosim.robots``, ``models/``) build their vessel from
a :class:`VesselSpec`, so the liquid's walls and the rigid body the arm holds are the same shape.

Vessel frame (the "local frame" everywhere in this project): origin at the centre of the inner floor (the paper's
"bottom middle" pivot of SIM), +x toward the pour lip (the pour direction), +z up the vessel's axis, +y completing
a right-handed frame (perpendicular to the pour plane). The pour lip is the outer top edge of the +x wall, where
the liquid leaves the vessel (the paper's pivot during CFS).
"""

from __future__ import annotations

import functools
import math
import operator
from dataclasses import dataclass
from enum import Enum

import numpy as np

from cosim.checks import check_choice, check_positive, check_range

# Poly(methyl methacrylate), a common lab vessel material (kg/m^3).
ACRYLIC_DENSITY = 1180.0


def _left_to_right_sum(values) -> float:
    """The floats added left to right, whatever the Python version. Python 3.12's built-in sum() compensates its
    rounding (Neumaier) and 3.11's does not: the two gave the default vessels' wall volumes one ulp apart, so the
    vessels' masses in MuJoCo differed and, the pour being chaotic, so did the whole default pour (README, Known
    limitations, reproducibility)."""
    return functools.reduce(operator.add, values, 0.0)


class VesselShape(Enum):
    """Closed choice of vessel shapes."""

    BOX = "box"  # open rectangular box (the paper's vessel)
    CYLINDER = "cylinder"  # open cylindrical cup


@dataclass(frozen=True)
class WallBox:
    """One rectangular slab of a box vessel's walls, in the vessel frame (m)."""

    name: str
    center: tuple[float, float, float]
    half_size: tuple[float, float, float]


@dataclass(frozen=True)
class VesselSpec:
    """An open vessel: inner dimensions, wall thickness and wall material.

    Fields (SI units):
      name: identifier used for MuJoCo bodies, log entities and summaries.
      shape: :class:`VesselShape` (box or cylinder).
      inner_width: m, inner size along the pour direction (local x); a cylinder's inner diameter. (0, 2]
      inner_depth: m, inner size perpendicular to the pour plane (local y); ignored for a cylinder. (0, 2]
      inner_height: m, inner floor to rim (local z); the paper's L. (0, 2]
      wall_thickness: m, thickness of floor and walls. (0, 0.05]
      wall_density: kg/m^3, wall material density (sets the empty vessel's mass). (0, 25000]
    """

    name: str = "pourer"
    shape: VesselShape = VesselShape.BOX
    inner_width: float = 0.191
    inner_depth: float = 0.100
    inner_height: float = 0.191
    wall_thickness: float = 0.005
    wall_density: float = ACRYLIC_DENSITY

    def __post_init__(self) -> None:
        p = f"vessel[{self.name}]"
        object.__setattr__(self, "shape", check_choice(f"{p}.shape", self.shape, VesselShape))
        for field_name in ("inner_width", "inner_depth", "inner_height"):
            object.__setattr__(self, field_name, check_positive(f"{p}.{field_name}", getattr(self, field_name), "m", 2.0))
        object.__setattr__(self, "wall_thickness", check_positive(f"{p}.wall_thickness", self.wall_thickness, "m", 0.05))
        object.__setattr__(self, "wall_density", check_positive(f"{p}.wall_density", self.wall_density, "kg/m^3", 25000.0))

    # ---- derived geometry -------------------------------------------------------------------------------------
    @property
    def is_box(self) -> bool:
        return self.shape is VesselShape.BOX

    @property
    def section_depth(self) -> float:
        """m, inner extent perpendicular to the pour plane (box depth, cylinder diameter)."""
        return self.inner_depth if self.is_box else self.inner_width

    @property
    def inner_floor_area(self) -> float:
        """m^2, inner horizontal cross-section (upright vessel)."""
        if self.is_box:
            return self.inner_width * self.inner_depth
        return math.pi * (0.5 * self.inner_width) ** 2

    @property
    def capacity(self) -> float:
        """m^3, inner volume up to the rim."""
        return self.inner_floor_area * self.inner_height

    def liquid_depth(self, dim: int) -> float:
        """m, the depth that times the liquid's area in the pour plane gives its volume: the section depth in 2-D (the
        liquid is the pour-plane slice times it) and for a box; for a 3-D cylinder pi D / 4, the depth of the box of
        width D with the cylinder's floor area, which holds the same volume at every fill."""
        return self.section_depth if dim == 2 or self.is_box else self.inner_floor_area / self.inner_width

    def liquid_shape(self, dim: int) -> VesselShape:
        """The horizontal section of the ``dim``-D liquid, which sets its slosh mode: a 2-D liquid is a pour-plane
        slice, so a box whatever the vessel; a 3-D liquid takes the vessel's shape."""
        return VesselShape.BOX if dim == 2 else self.shape

    def fill_volume(self, fill_depth: float) -> float:
        """m^3 of liquid that fills the upright vessel to ``fill_depth`` (m); checked against the rim."""
        check_range(f"vessel[{self.name}].fill_depth", fill_depth, 0.0, self.inner_height, "m (rim height)", lo_open=True)
        return self.inner_floor_area * fill_depth

    @property
    def lip_local(self) -> np.ndarray:
        """Pour lip in the vessel frame (m): outer top edge of the +x wall, in the pour plane."""
        return np.array([0.5 * self.inner_width + self.wall_thickness, 0.0, self.inner_height])

    @property
    def rim_inner_local(self) -> np.ndarray:
        """Inner top edge of the +x wall in the vessel frame (m): where liquid height over the crest begins."""
        return np.array([0.5 * self.inner_width, 0.0, self.inner_height])

    def wall_boxes(self) -> list[WallBox]:
        """The box vessel's walls as non-overlapping slabs (floor, +x, -x, +y, -y), vessel frame."""
        if not self.is_box:
            raise ValueError("wall_boxes() is defined for box vessels only")
        b, d, h, t = 0.5 * self.inner_width, 0.5 * self.inner_depth, self.inner_height, self.wall_thickness
        return [
            WallBox("floor", (0.0, 0.0, -0.5 * t), (b + t, d + t, 0.5 * t)),
            WallBox("front", (b + 0.5 * t, 0.0, 0.5 * h), (0.5 * t, d + t, 0.5 * h)),
            WallBox("back", (-b - 0.5 * t, 0.0, 0.5 * h), (0.5 * t, d + t, 0.5 * h)),
            WallBox("left", (0.0, d + 0.5 * t, 0.5 * h), (b, 0.5 * t, 0.5 * h)),
            WallBox("right", (0.0, -d - 0.5 * t, 0.5 * h), (b, 0.5 * t, 0.5 * h)),
        ]

    def _wall_parts(self) -> list[tuple[float, np.ndarray]]:
        """(volume m^3, centroid m) of each solid part of the walls."""
        if self.is_box:
            return [(8.0 * float(np.prod(w.half_size)), np.array(w.center)) for w in self.wall_boxes()]
        r, t, h = 0.5 * self.inner_width, self.wall_thickness, self.inner_height
        floor = (math.pi * (r + t) ** 2 * t, np.array([0.0, 0.0, -0.5 * t]))
        side = (math.pi * ((r + t) ** 2 - r**2) * h, np.array([0.0, 0.0, 0.5 * h]))
        return [floor, side]

    @property
    def wall_volume(self) -> float:
        """m^3 of wall material."""
        return _left_to_right_sum(v for v, _ in self._wall_parts())

    @property
    def mass(self) -> float:
        """kg, empty vessel."""
        return self.wall_volume * self.wall_density

    @functools.cached_property
    def com_local(self) -> np.ndarray:
        """Centre of mass of the empty vessel in the vessel frame (m); read-only (computed once: the coupling reads
        it every step)."""
        parts = self._wall_parts()
        com = sum(v * c for v, c in parts) / _left_to_right_sum(v for v, _ in parts)
        com.flags.writeable = False
        return com

    @property
    def outer_half_extents(self) -> np.ndarray:
        """Half sizes (m) of the vessel's outer bounding box, which spans z in [-wall_thickness, inner_height]."""
        t = self.wall_thickness
        half_y = 0.5 * self.section_depth + t
        return np.array([0.5 * self.inner_width + t, half_y, 0.5 * (self.inner_height + t)])


def seed_pouring_vessel() -> VesselSpec:
    """The paper's pouring vessel: B = L = 0.191 m in the pour plane, 0.10 m deep (Camporredondo et al. 2019)."""
    return VesselSpec(name="pourer")


def default_catching_vessel() -> VesselSpec:
    """The catching vessel: wider and deeper than the pourer so that a full pour fits with margin."""
    return VesselSpec(name="catcher", inner_width=0.26, inner_depth=0.14, inner_height=0.16)
