"""MuJoCo vessel bodies generated from :class:`cosim.vessel.VesselSpec` (the one source of vessel geometry).

The body frame is the VesselSpec local frame exactly: origin at the centre of the inner floor, +x toward the pour
lip, +z up the axis (SI units). A box vessel is its ``wall_boxes()`` as box geoms; a cylindrical vessel is a floor
disc plus a ring of :data:`CYLINDER_STAVES` box staves whose outer edges touch, so the ring is closed. Mass, centre of
mass and inertia are set explicitly from the specification (walls of uniform ``wall_density``), so the MuJoCo body
weighs exactly ``VesselSpec.mass`` whatever the collision approximation.

Sites (all in the vessel frame): ``<name>/frame`` at the origin (the inverse-kinematics target), ``<name>/lip`` at
``lip_local`` (the pour lip).

``python -m cosim.tools.generate_models`` writes ``models/vessels/<name>.xml`` from :func:`vessel_mjcf`.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from cosim.robots.vessel_mesh_mjcf import add_mesh_geoms
from cosim.vessel import VesselSpec

# Number of box staves approximating a cylindrical wall (15 deg each).
CYLINDER_STAVES = 24
# Vessel geoms: visible in the default viewer groups, colliding with arms, table and the other vessel.
VESSEL_GEOM_GROUP = 1
VESSEL_RGBA = (0.55, 0.75, 0.95, 0.45)
SITE_SIZE = 0.005


def frame_site(vessel: VesselSpec) -> str:
    """Name of the site at the vessel frame origin."""
    return f"{vessel.name}/frame"


def lip_site(vessel: VesselSpec) -> str:
    """Name of the site at the pour lip."""
    return f"{vessel.name}/lip"


def _box_inertia(mass: float, half: np.ndarray) -> np.ndarray:
    """Diagonal inertia (kg m^2) of a solid box about its centre, axes along its edges."""
    a, b, c = 2.0 * half
    return mass / 12.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])


def _cylinder_parts(vessel: VesselSpec) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """(mass kg, centre m, diagonal inertia about centre kg m^2) of a cylinder vessel's floor disc and tube."""
    r, t, h, rho = 0.5 * vessel.inner_width, vessel.wall_thickness, vessel.inner_height, vessel.wall_density
    big = r + t
    m_floor = rho * math.pi * big**2 * t
    i_floor = m_floor * np.array([(3 * big**2 + t**2) / 12, (3 * big**2 + t**2) / 12, big**2 / 2])
    m_tube = rho * math.pi * (big**2 - r**2) * h
    i_tube = m_tube * np.array(
        [(3 * (big**2 + r**2) + h**2) / 12, (3 * (big**2 + r**2) + h**2) / 12, (big**2 + r**2) / 2]
    )
    return [(m_floor, np.array([0.0, 0.0, -0.5 * t]), i_floor), (m_tube, np.array([0.0, 0.0, 0.5 * h]), i_tube)]


def vessel_inertia(vessel: VesselSpec) -> np.ndarray:
    """Diagonal inertia (3,) kg m^2 of the empty vessel about its centre of mass, vessel-frame axes.

    Sum of the wall parts with the parallel-axis theorem. The walls are symmetric in x and in y about the vessel
    axis, so the products of inertia vanish and the tensor is diagonal in the vessel frame.
    """
    if vessel.is_box:
        parts = []
        for wall in vessel.wall_boxes():
            half = np.array(wall.half_size)
            mass = vessel.wall_density * 8.0 * float(np.prod(half))
            parts.append((mass, np.array(wall.center), _box_inertia(mass, half)))
    else:
        parts = _cylinder_parts(vessel)
    com = vessel.com_local
    total = np.zeros(3)
    for mass, centre, inertia in parts:
        d = centre - com
        total += inertia + mass * np.array([d[1] ** 2 + d[2] ** 2, d[0] ** 2 + d[2] ** 2, d[0] ** 2 + d[1] ** 2])
    return total


def _add_cylinder_geoms(body: mujoco.MjsBody, vessel: VesselSpec) -> None:
    r, t, h = 0.5 * vessel.inner_width, vessel.wall_thickness, vessel.inner_height
    body.add_geom(
        name=f"{vessel.name}/floor",
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[r + t, 0.5 * t, 0.0],
        pos=[0.0, 0.0, -0.5 * t],
        group=VESSEL_GEOM_GROUP,
        rgba=list(VESSEL_RGBA),
    )
    half_width = (r + t) * math.tan(math.pi / CYLINDER_STAVES)  # outer edges of neighbouring staves touch
    for k in range(CYLINDER_STAVES):
        angle = 2.0 * math.pi * k / CYLINDER_STAVES  # stave 0 is the +x wall (the lip)
        body.add_geom(
            name=f"{vessel.name}/stave_{k:02d}",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[0.5 * t, half_width, 0.5 * h],
            pos=[(r + 0.5 * t) * math.cos(angle), (r + 0.5 * t) * math.sin(angle), 0.5 * h],
            quat=[math.cos(0.5 * angle), 0.0, 0.0, math.sin(0.5 * angle)],
            group=VESSEL_GEOM_GROUP,
            rgba=list(VESSEL_RGBA),
        )


def add_vessel_body(
    parent: mujoco.MjsBody,
    vessel: VesselSpec,
    pos: np.ndarray = np.zeros(3),
    quat: np.ndarray = np.array([1.0, 0.0, 0.0, 0.0]),
    gravcomp: float = 0.0,
    spec: mujoco.MjSpec | None = None,
) -> mujoco.MjsBody:
    """Add the vessel as a child body of ``parent`` at ``pos`` (3,) m / ``quat`` (4,) [w, x, y, z] in the parent frame.

    ``gravcomp`` is the body's gravity-compensation fraction (1 when the holding arm's controller compensates the
    vessel's weight, as for the project's arms). ``spec``: the MjSpec ``parent`` belongs to, which takes a mesh
    vessel's mesh assets (:mod:`cosim.robots.vessel_mesh_mjcf`). Returns the new body, named ``vessel.name``.
    """
    body = parent.add_body(name=vessel.name, pos=list(map(float, pos)), quat=list(map(float, quat)))
    body.gravcomp = gravcomp
    body.explicitinertial = True
    body.mass = vessel.mass
    body.ipos = list(map(float, vessel.com_local))
    if vessel.is_mesh:
        inertia = vessel.wall_density * np.asarray(vessel.mesh.inertia)  # full tensor about the centre of mass
        body.fullinertia = [inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2]]
        if spec is None:
            raise ValueError(f"vessel {vessel.name!r}: a mesh vessel's body needs the MjSpec for its mesh assets")
        add_mesh_geoms(spec, body, vessel, VESSEL_GEOM_GROUP, VESSEL_RGBA)
    elif vessel.is_box:
        body.inertia = list(map(float, vessel_inertia(vessel)))
        for wall in vessel.wall_boxes():
            body.add_geom(
                name=f"{vessel.name}/{wall.name}",
                type=mujoco.mjtGeom.mjGEOM_BOX,
                size=list(wall.half_size),
                pos=list(wall.center),
                group=VESSEL_GEOM_GROUP,
                rgba=list(VESSEL_RGBA),
            )
    else:
        body.inertia = list(map(float, vessel_inertia(vessel)))
        _add_cylinder_geoms(body, vessel)
    body.add_site(name=frame_site(vessel), size=[SITE_SIZE] * 3, group=4)
    body.add_site(name=lip_site(vessel), pos=list(map(float, vessel.lip_local)), size=[SITE_SIZE] * 3, group=4)
    return body


def vessel_mjcf(vessel: VesselSpec) -> str:
    """Standalone MJCF text of the vessel (a static body at the world origin), as written to models/vessels/."""
    spec = mujoco.MjSpec()
    spec.modelname = vessel.name
    spec.comment = (
        f" GENERATED by `python -m cosim.tools.generate_models` from cosim.vessel ({vessel.name!r}); do not edit.\n"
        f"     {vessel.shape.value} vessel: inner width {vessel.inner_width} m (pour direction, local x), "
        f"depth {vessel.inner_depth} m, height {vessel.inner_height} m,\n"
        f"     walls {vessel.wall_thickness} m at {vessel.wall_density} kg/m^3 -> {vessel.mass:.4f} kg. "
        "Frame: origin at the centre of the inner floor, +x toward the pour lip, +z up. "
    )
    spec.compiler.degree = False
    add_vessel_body(spec.worldbody, vessel, spec=spec)
    return spec.to_xml()
