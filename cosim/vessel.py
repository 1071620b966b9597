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
from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING

from cosim.checks import check_range
from declared_settings.setting import check_settings, documented, setting

if TYPE_CHECKING:  # NumPy is imported by the methods that use it: a scene's settings are checked without it
    import numpy as np

    from cosim.mesh_vessel import VesselMesh

# Poly(methyl methacrylate), a common lab vessel material (kg/m^3).
ACRYLIC_DENSITY = 1180.0


def _left_to_right_sum(values) -> float:
    """The floats added left to right, whatever the Python version. Python 3.12's built-in sum() compensates its
    rounding (Neumaier) and 3.11's does not: the two gave the default vessels' wall volumes one ulp apart, so the
    vessels' masses in MuJoCo differed and, the pour being chaotic, so did the whole default pour
    (docs/reproducibility.md, Across machines)."""
    return functools.reduce(operator.add, values, 0.0)


class VesselShape(Enum):
    """Closed choice of vessel shapes."""

    BOX = "box"  # open rectangular box (the paper's vessel)
    CYLINDER = "cylinder"  # open cylindrical cup
    MESH = "mesh"  # the walls from a mesh file (cosim.mesh_vessel)


@dataclass(frozen=True)
class WallBox:
    """One rectangular slab of a box vessel's walls, in the vessel frame (m)."""

    name: str
    center: tuple[float, float, float]
    half_size: tuple[float, float, float]


VESSEL = "vessel"


@documented
@dataclass(frozen=True)
class VesselSpec:
    """An open vessel: inner dimensions, wall thickness and wall material (SI units); by default the paper's pouring
    vessel (Camporredondo et al. 2019).

    name: identifier used for MuJoCo bodies, log entities and summaries.
    mesh: the walls of a 'mesh' vessel (:class:`cosim.mesh_vessel.VesselMesh`, vessel frame); its box equivalent
      (:func:`mesh_vessel_spec`) gives the sizes. None for a box or cylinder.
    """

    name: str = "pourer"
    shape: VesselShape = setting(VesselShape.BOX, VESSEL, "The vessel's shape: a box, a cylinder or a mesh's walls.")
    inner_width: float = setting(0.191, VESSEL, "Inner size along the pour direction (local x); a cylinder's inner "
                                 "diameter.", "m", 0.0, 2.0, lo_open=True)
    inner_depth: float = setting(0.100, VESSEL, "Inner size perpendicular to the pour plane (local y); ignored for a "
                                 "cylinder.", "m", 0.0, 2.0, lo_open=True)
    inner_height: float = setting(0.191, VESSEL, "Inner floor to rim (local z); the paper's L.", "m", 0.0, 2.0,
                                  lo_open=True)
    wall_thickness: float = setting(0.005, VESSEL, "Thickness of floor and walls.", "m", 0.0, 0.05, lo_open=True)
    wall_density: float = setting(ACRYLIC_DENSITY, VESSEL, "Wall material density (sets the empty vessel's mass).",
                                  "kg/m^3", 0.0, 25000.0, lo_open=True)
    mesh: VesselMesh | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        p = f"vessel[{self.name}]"
        check_settings(self, p)
        if (self.shape is VesselShape.MESH) != (self.mesh is not None):
            raise ValueError(f"{p}: a mesh vessel needs its mesh, and only a mesh vessel has one")

    # ---- derived geometry -------------------------------------------------------------------------------------
    @property
    def is_box(self) -> bool:
        return self.shape is VesselShape.BOX

    @property
    def is_mesh(self) -> bool:
        return self.shape is VesselShape.MESH

    @property
    def section_depth(self) -> float:
        """m, inner extent perpendicular to the pour plane (box depth, cylinder diameter; a mesh's cavity volume over
        its pour-plane section's area)."""
        return self.inner_width if self.shape is VesselShape.CYLINDER else self.inner_depth

    @property
    def inner_floor_area(self) -> float:
        """m^2, inner horizontal cross-section (upright vessel); a mesh's mean one, its capacity over its height."""
        if self.is_box:
            return self.inner_width * self.inner_depth
        if self.is_mesh:
            return self.capacity / self.inner_height
        return math.pi * (0.5 * self.inner_width) ** 2

    @property
    def capacity(self) -> float:
        """m^3, inner volume up to the rim (a mesh's up to its crest)."""
        if self.is_mesh:
            return self.mesh.cavity_volume(self.inner_height)
        return self.inner_floor_area * self.inner_height

    def liquid_depth(self, dim: int) -> float:
        """m, the depth that times the liquid's area in the pour plane gives its volume: the section depth in 2-D (the
        liquid is the pour-plane slice times it) and for a box; for a 3-D cylinder pi D / 4, the depth of the box of
        width D with the cylinder's floor area, which holds the same volume at every fill."""
        return self.section_depth if dim == 2 or self.is_box else self.inner_floor_area / self.inner_width

    def liquid_shape(self, dim: int) -> VesselShape:
        """The horizontal section of the ``dim``-D liquid, which sets its slosh mode: a 2-D liquid is a pour-plane
        slice, so a box whatever the vessel; a 3-D liquid takes the vessel's shape (a mesh's closed form, else
        the box of its equivalent sizes; :attr:`has_closed_form` says which)."""
        if dim == 2:
            return VesselShape.BOX
        if self.is_mesh:
            return VesselShape(self.mesh.closed_form[3] or "box")
        return self.shape

    def has_closed_form(self, dim: int) -> bool:
        """Whether potential flow describes the ``dim``-D liquid's slosh: always for a box or a cylinder; for a mesh
        when its cavity is box- or cylinder-like (:mod:`cosim.mesh_vessel`)."""
        return not self.is_mesh or bool(self.mesh.closed_form[dim])

    def fill_volume(self, fill_depth: float) -> float:
        """m^3 of liquid that fills the upright vessel to ``fill_depth`` (m); checked against the rim."""
        check_range(f"vessel[{self.name}].fill_depth", fill_depth, 0.0, self.inner_height, "m (rim height)", lo_open=True)
        if self.is_mesh:
            return self.mesh.cavity_volume(fill_depth)
        return self.inner_floor_area * fill_depth

    @property
    def lip_local(self) -> np.ndarray:
        """Pour lip in the vessel frame (m): outer top edge of the +x wall, in the pour plane."""
        import numpy as np

        return np.array([0.5 * self.inner_width + self.wall_thickness, 0.0, self.inner_height])

    @property
    def rim_inner_local(self) -> np.ndarray:
        """Inner top edge of the +x wall in the vessel frame (m): where liquid height over the crest begins."""
        import numpy as np

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
        import numpy as np

        if self.is_mesh:
            return [(self.mesh.volume, np.array(self.mesh.centre_of_mass))]
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
        import numpy as np

        t = self.wall_thickness
        if self.is_mesh:
            lo, hi = self.mesh.bounds
            return np.array([max(-lo[0], hi[0]), max(-lo[1], hi[1]), 0.5 * (hi[2] - lo[2])])
        half_y = 0.5 * self.section_depth + t
        return np.array([0.5 * self.inner_width + t, half_y, 0.5 * (self.inner_height + t)])


def seed_pouring_vessel() -> VesselSpec:
    """The paper's pouring vessel: B = L = 0.191 m in the pour plane, 0.10 m deep (Camporredondo et al. 2019)."""
    return VesselSpec(name="pourer")


def default_catching_vessel() -> VesselSpec:
    """The catching vessel: wider and deeper than the pourer so that a full pour fits with margin."""
    return VesselSpec(name="catcher", inner_width=0.26, inner_depth=0.14, inner_height=0.16)


def mesh_vessel_spec(name: str, mesh: VesselMesh, wall_density: float = ACRYLIC_DENSITY) -> VesselSpec:
    """The vessel of ``mesh`` with walls of ``wall_density`` (kg/m^3). Its sizes are the box equivalent the pour
    controller and the checks read: inner width twice the inner rim's x at the crest (the lip then sits at the mesh's
    outer wall, ``inner_width / 2 + wall_thickness``), inner depth the 2-D liquid's depth (cavity volume over the
    pour-plane section's area), inner height the crest's, wall thickness the wall's at the crest in the pour plane."""
    return VesselSpec(name, VesselShape.MESH, 2.0 * mesh.inner_x, mesh.depth_2d, mesh.crest_height,
                      mesh.lip_x - mesh.inner_x, wall_density, mesh)
