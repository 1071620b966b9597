"""A vessel from a mesh file: its solid walls as a watertight triangle mesh, and what the pour needs from it.

The file (OBJ or STL, loaded with trimesh) holds the vessel's walls as one closed solid, in metres, its opening up
(+z). :func:`load_vessel_mesh` checks it, turns it so that ``pour_direction`` (deg about +z from the file's +x) is
+x, and moves it into the vessel frame of :mod:`cosim.vessel` (origin at the centre of the inner floor, +x toward the
pour lip, +z up). From the mesh it derives:

- the cavity: the space outside the solid that is closed below and on all four horizontal sides (a ray from it along
  -z, +x, -x, +y and -y meets the walls) and open above (a ray along +z meets nothing). A handle's eye is open to the
  sides, the space around the vessel is open below or to the sides, a sealed hollow is closed above: none of them
  holds liquid. Here it is evaluated on a voxel grid of the walls' surface; the liquid solver evaluates the same
  rule with warp's mesh queries (:mod:`cosim.fluid.mesh_boundary`);
- the liquid-facing faces: those whose outward normal points into the cavity (the inner walls and floor);
- the crest: the rim's lowest point on the pour side (azimuth within :data:`CREST_HALF_ANGLE` of +x), the height
  the liquid leaves at; the inner and outer wall faces there, in the pour plane, give the inner rim and the lip;
- the fill volume V(z) below a height z: by the divergence theorem on the liquid-facing faces clipped at z,
  V(z) = sum_f (z - z_f) a_f,z over the faces (a_f: the face's area vector, z_f: its centroid's height), exact
  for a triangle mesh; it is the integral of the inner cross-section A(z') from the floor to z. The pour-plane
  section's area S(z) comes the same way from the section's segments, and the 2-D liquid's depth is V / S at the
  crest;
- the walls' mass properties (trimesh, uniform density);
- whether the cavity is box-like or cylinder-like (its cross-section constant and the product of its widths, or
  pi / 4 times it), so that the slosh plant has a closed form (:mod:`controllers.slosh`).
"""

from __future__ import annotations

import functools
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cosim.errors import InputError

MESH_SUFFIXES = (".obj", ".stl")
# The mesh's bounding box, m: a vessel a robot arm pours from, in metres (a file in millimetres is 1000 x larger).
MESH_SIZE_RANGE = (0.005, 2.0)
# Azimuth around the pour direction (deg) within which the rim's lowest point is the crest.
CREST_HALF_ANGLE = 45.0
# Azimuth step (deg) at which the rim's height is taken.
RIM_BIN = 5.0
# Voxels across the mesh's largest extent for the cavity classification of faces.
VOXELS_ACROSS = 64
# Relative spread of the cavity's cross-section (and its widths) within which it counts as a box or a cylinder.
CLOSED_FORM_TOLERANCE = 0.02


def _trimesh():
    import trimesh  # imported on use: `cosim --help` and every vessel without a mesh do without it

    return trimesh


@dataclass(frozen=True, eq=False)
class VesselMesh:
    """The vessel's solid in the vessel frame and what is derived from it (SI units).

    source: the file; pour_direction: deg about +z of the file's pour direction.
    vertices (n, 3) m, faces (m, 3) int, outward-wound; liquid_facing (m,) bool.
    crest_height: m, the crest above the inner floor; inner_x: m, the inner wall's x at the crest in the pour
    plane; lip_x: m, the outer wall's x there; depth_2d: m, V / S at the crest (the 2-D liquid's depth).
    volume: m^3 of wall material; centre_of_mass (3,) m; inertia (3, 3) kg m^2 per kg/m^3 of density about the
    centre of mass.
    closed_form: per dimension (2, 3), 'box', 'cylinder' or '' (none: the plant is identified from the liquid).
    """

    source: str
    pour_direction: float
    vertices: np.ndarray = field(repr=False)
    faces: np.ndarray = field(repr=False)
    liquid_facing: np.ndarray = field(repr=False)
    crest_height: float
    inner_x: float
    lip_x: float
    depth_2d: float
    volume: float
    centre_of_mass: np.ndarray = field(repr=False)
    inertia: np.ndarray = field(repr=False)
    closed_form: dict = field(repr=False)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, VesselMesh) and (self.source, self.pour_direction) == (other.source, other.pour_direction)

    def __hash__(self) -> int:
        return hash((self.source, self.pour_direction))

    @property
    def bounds(self) -> np.ndarray:
        """(2, 3) m, the solid's bounding box in the vessel frame."""
        return np.stack([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    def cavity_volume(self, height: float) -> float:
        """m^3 of cavity below ``height`` (m above the inner floor): V(z) = sum_f (z - z_f) a_f,z over the
        liquid-facing faces clipped at z (the divergence theorem with the field (0, 0, z' - z), which vanishes on the
        cap at z)."""
        tri = _clipped_below(self.vertices, self.faces[self.liquid_facing], height)
        if len(tri) == 0:
            return 0.0
        area_z = 0.5 * np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, 2]
        return float(np.sum((height - tri[:, :, 2].mean(axis=1)) * area_z))

    def section_segments(self) -> np.ndarray:
        """(k, 2, 3) m: the liquid-facing faces' section by the pour plane y = 0, the walls the 2-D liquid sees."""
        return _plane_section(self.vertices, self.faces[self.liquid_facing])[0]

    def section_area(self, height: float) -> float:
        """m^2 of the cavity's pour-plane section (y = 0) below ``height`` (m): S(z) = sum_s L_s (z - z_s) n_s,z over
        the section's segments clipped at z (n_s: the wall's outward normal in the plane)."""
        segments, normals = _plane_section(self.vertices, self.faces[self.liquid_facing])
        lo, hi = segments[:, 0], segments[:, 1]
        keep = np.minimum(lo[:, 2], hi[:, 2]) < height
        lo, hi, normals = lo[keep], hi[keep], normals[keep]
        for a, b in ((lo, hi), (hi, lo)):  # clip the end above the height onto it
            above = a[:, 2] > height
            f = (height - b[above, 2]) / (a[above, 2] - b[above, 2])
            a[above] = b[above] + f[:, None] * (a[above] - b[above])
        length = np.linalg.norm(hi - lo, axis=1)
        return float(np.sum(length * (height - 0.5 * (lo[:, 2] + hi[:, 2])) * normals[:, 1]))


def _clipped_below(vertices: np.ndarray, faces: np.ndarray, height: float) -> np.ndarray:
    """(k, 3, 3) triangles: ``faces`` cut by the plane z = ``height``, the parts below it."""
    trimesh = _trimesh()
    v, f = trimesh.intersections.slice_faces_plane(vertices, faces, np.array([0.0, 0.0, -1.0]), np.array([0.0, 0.0, height]))[:2]
    return v[f] if len(f) else np.zeros((0, 3, 3))


def _plane_section(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The faces' section by the pour plane y = 0: segments (k, 2, 3) m and each one's face normal in the plane
    (k, 2) as (x, z), unit length."""
    trimesh = _trimesh()
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    segments, face_index = trimesh.intersections.mesh_plane(mesh, [0.0, 1.0, 0.0], [0.0, 0.0, 0.0], return_faces=True)
    normals = mesh.face_normals[face_index][:, [0, 2]]
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
    return np.asarray(segments, dtype=float).copy(), normals


def _crossings(segments: np.ndarray, height: float) -> np.ndarray:
    """x (m) where the pour-plane section's segments cross the line z = ``height``, sorted."""
    a, b = segments[:, 0], segments[:, 1]
    cross = (np.minimum(a[:, 2], b[:, 2]) <= height) & (height < np.maximum(a[:, 2], b[:, 2]))  # half-open: one per vertex
    a, b = a[cross], b[cross]
    f = (height - a[:, 2]) / (b[:, 2] - a[:, 2])
    return np.sort(a[:, 0] + f * (b[:, 0] - a[:, 0]))


def _cavity_voxels(mesh) -> tuple[np.ndarray, np.ndarray, float]:
    """(cavity bool grid, the grid's origin m, pitch m): voxels of the walls' surface are solid; a voxel is cavity
    when it is not solid, solid lies below it and on all four horizontal sides, and nothing above it."""
    trimesh = _trimesh()
    pitch = float(np.max(mesh.extents)) / VOXELS_ACROSS
    grid = trimesh.voxel.creation.voxelize_subdivide(mesh, pitch)
    solid = np.pad(grid.matrix, 1)
    origin = grid.transform[:3, 3] - pitch

    def seen(axis: int, forward: bool) -> np.ndarray:
        s = solid if forward else np.flip(solid, axis)
        hit = np.maximum.accumulate(s, axis=axis)
        return hit if forward else np.flip(hit, axis)

    # seen(axis, True)[i] = solid at or before i along the axis, i.e. in the -axis direction from i
    enclosed = seen(0, True) & seen(0, False) & seen(1, True) & seen(1, False) & seen(2, True) & ~seen(2, False)
    return enclosed & ~solid, origin, pitch


def _liquid_facing(mesh) -> np.ndarray:
    """(m,) bool: faces whose outward normal points into the cavity (their centroid moved 1.5 voxels along the normal
    lands in a cavity voxel)."""
    cavity, origin, pitch = _cavity_voxels(mesh)
    probe = mesh.triangles_center + 1.5 * pitch * mesh.face_normals
    index = np.round((probe - origin) / pitch).astype(int)
    inside = np.all((index >= 0) & (index < np.array(cavity.shape)), axis=1)
    facing = np.zeros(len(mesh.faces), bool)
    facing[inside] = cavity[tuple(index[inside].T)]
    return facing


def _rim_height(vertices: np.ndarray, faces: np.ndarray) -> float:
    """m: the lowest of the rim's heights within :data:`CREST_HALF_ANGLE` of +x, every :data:`RIM_BIN` of azimuth; the
    rim's height at an azimuth is the top of the liquid-facing ``faces``' section by the half-plane there."""
    trimesh = _trimesh()
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    heights = []
    for angle in np.radians(np.arange(-CREST_HALF_ANGLE, CREST_HALF_ANGLE + 1e-9, RIM_BIN)):
        toward = np.array([math.cos(angle), math.sin(angle), 0.0])
        segments = trimesh.intersections.mesh_plane(mesh, [-toward[1], toward[0], 0.0], [0.0, 0.0, 0.0]).reshape(-1, 3)
        ahead = segments[segments @ toward > 0.0]
        if len(ahead):
            heights.append(float(ahead[:, 2].max()))
    return min(heights)


def _closed_form(vessel: VesselMesh, widths: list[tuple[float, float]], heights: np.ndarray) -> dict:
    """'box', 'cylinder' or '' per dimension: the closed form the cavity's shape allows (see the module doc)."""
    h = 1e-3 * vessel.crest_height
    area = np.array([(vessel.cavity_volume(z + h) - vessel.cavity_volume(z - h)) / (2 * h) for z in heights])
    wx, wy = np.array(widths).T
    tol = CLOSED_FORM_TOLERANCE

    def constant(values: np.ndarray) -> bool:
        return float(np.ptp(values)) <= tol * float(np.mean(values))

    def near(a: np.ndarray, b: np.ndarray) -> bool:
        return bool(np.all(np.abs(a - b) <= tol * b))

    out = {2: "box" if constant(wx) else "", 3: ""}
    if constant(area) and constant(wx) and constant(wy):
        if near(area, wx * wy):
            out[3] = "box"
        elif near(area, 0.25 * math.pi * wx * wy) and near(wx, wy):
            out[3] = "cylinder"
    return out


def _load(path: Path, field_name: str):
    trimesh = _trimesh()
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise InputError(f"{field_name}: {path} is not an OBJ or STL file (allowed: {', '.join(MESH_SUFFIXES)})")
    if not path.is_file():
        raise InputError(f"{field_name}: no file {path} (an OBJ or STL mesh of the vessel, in metres)")
    try:
        mesh = trimesh.load_mesh(str(path), process=True)
    except Exception as exc:  # noqa: BLE001 (trimesh raises many types for a bad file)
        raise InputError(f"{field_name}: {path} is not a readable mesh ({exc})") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise InputError(f"{field_name}: {path} holds no triangle mesh")
    return mesh


def _check_solid(mesh, path: Path, field_name: str) -> None:
    extent = float(np.max(mesh.extents))
    lo, hi = MESH_SIZE_RANGE
    if not lo <= extent <= hi:
        hint = " (in millimetres? scale by 0.001)" if extent > hi else " (scale it to metres)"
        raise InputError(f"{field_name}: {path}'s bounding box is {extent:.4g} m across; allowed [{lo:g}, {hi:g}] m, "
                         f"the file in metres{hint}")
    if not mesh.is_watertight:
        raise InputError(f"{field_name}: {path} is not watertight ({len(mesh.edges_unique) - len(mesh.face_adjacency)} "
                         "open edges); allowed: one closed solid of the vessel's walls")


def _turned(mesh, pour_direction: float):
    """The mesh turned about +z so that the pour direction (deg from the file's +x) is +x, its winding outward."""
    trimesh = _trimesh()
    mesh = mesh.copy()
    if mesh.volume < 0.0:
        mesh.invert()
    mesh.apply_transform(trimesh.transformations.rotation_matrix(-math.radians(pour_direction), [0.0, 0.0, 1.0]))
    return mesh


@functools.lru_cache(maxsize=16)
def _cached(path: str, pour_direction: float, mtime: float, field_name: str) -> VesselMesh:
    trimesh = _trimesh()
    source = Path(path)
    mesh = _load(source, field_name)
    _check_solid(mesh, source, field_name)
    mesh = _turned(mesh, pour_direction)
    facing = _liquid_facing(mesh)
    if not facing.any():
        raise InputError(f"{field_name}: {source} has no opening: no space inside it is closed below and around and "
                         "open above (allowed: an open vessel, its opening toward +z)")
    wet = mesh.vertices[np.unique(mesh.faces[facing])]
    lo, hi = wet.min(axis=0), wet.max(axis=0)
    mesh.apply_translation([-0.5 * (lo[0] + hi[0]), -0.5 * (lo[1] + hi[1]), -lo[2]])
    vertices = np.asarray(mesh.vertices, dtype=float)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    crest = _rim_height(vertices, faces[facing])
    below_rim = crest - min(1e-4, 0.01 * crest)
    inner = _crossings(_plane_section(vertices, faces[facing])[0], below_rim)
    walls = _crossings(_plane_section(vertices, faces)[0], below_rim)
    if len(inner) == 0 or inner[-1] <= 0.0:
        raise InputError(f"{field_name}: {source}'s opening does not cross the pour plane y = 0 on the pour side "
                         "(allowed: the vessel's axis at its centre, the pour direction toward a wall)")
    inner_x = float(inner[-1])
    outer = walls[walls > inner_x + 1e-9]
    if len(outer) == 0:
        raise InputError(f"{field_name}: {source}'s wall at the crest has no outer face in the pour plane")
    props = trimesh.Trimesh(vertices, faces, process=False)
    heights = np.linspace(0.2, 0.8, 5) * crest
    widths = []
    for z in heights:
        xs = _crossings(_plane_section(vertices, faces[facing])[0], z)
        turned = vertices[:, [1, 0, 2]] * np.array([1.0, -1.0, 1.0])  # the section x = 0 as the plane y = 0
        ys = _crossings(_plane_section(turned, faces[facing])[0], z)
        widths.append((float(xs[-1] - xs[0]) if len(xs) > 1 else 0.0, float(ys[-1] - ys[0]) if len(ys) > 1 else 0.0))
    vessel = VesselMesh(
        source=path, pour_direction=pour_direction, vertices=vertices, faces=faces, liquid_facing=facing,
        crest_height=crest, inner_x=inner_x, lip_x=float(outer[0]), depth_2d=0.0, volume=float(props.volume),
        centre_of_mass=np.asarray(props.center_mass, dtype=float), inertia=np.asarray(props.moment_inertia, dtype=float),
        closed_form={},
    )
    depth = vessel.cavity_volume(crest) / vessel.section_area(crest)
    object.__setattr__(vessel, "depth_2d", depth)
    object.__setattr__(vessel, "closed_form", _closed_form(vessel, widths, heights))
    for array in (vertices, faces, facing, vessel.centre_of_mass, vessel.inertia):
        array.flags.writeable = False
    return vessel


def load_vessel_mesh(path: str | Path, pour_direction: float = 0.0, field_name: str = "mesh") -> VesselMesh:
    """The vessel mesh in ``path`` (OBJ or STL, metres, opening up), its pour direction ``pour_direction`` deg about
    +z from the file's +x. Raises InputError naming ``field_name`` for a missing or unreadable file, a bounding box
    outside :data:`MESH_SIZE_RANGE` (units), a mesh that is not watertight, or one without an opening."""
    path = Path(os.path.abspath(path))
    mtime = os.stat(path).st_mtime if os.path.isfile(path) else 0.0  # os.path: False for a name too long or a loop
    return _cached(str(path), float(pour_direction), mtime, field_name)
