"""The controller's measurement contract (controllers.measurement.LiquidMeasurement): the device probe on
synthetic particles with known answers, and against the plain numpy transcription of the contract on a real SPH
pour state (particles in the solver's cell order, on its device)."""

import math

import numpy as np
import pytest
import warp as wp

from controllers.geometry import VesselGeometry, static_h_q
from cosim.coupling.measure import LiquidProbe, MeasurementGeometry
from cosim.fluid.config import FluidConfig
from cosim.frames import Pose, rotation_y
from cosim.validation.scripted import domain_around, run_scripted, tilt_about_lip
from cosim.vessel import VesselShape, VesselSpec, seed_pouring_vessel
from tests.support.measure_reference import reference_crossing_x, reference_measure

SPEC = seed_pouring_vessel()
DX = SPEC.inner_width / 40
H = 1.5 * DX
WALL = 3 * DX
GEO = MeasurementGeometry(SPEC, WALL, 0.16, H, DX, initial_volume=0.003, dim=2)
# A lattice surface is exact to half a spacing: angles within atan(dx / B) of the truth, heights within dx.
ANGLE_TOLERANCE = math.atan(DX / SPEC.inner_width)


def measure(t, geo, pose, catcher, x, v, active, volume):
    """The probe's measurement of numpy particles (world frame) on the CPU."""
    arrays = (wp.array(x.astype(np.float32), dtype=wp.vec3, device="cpu"), wp.array(v.astype(np.float32), dtype=wp.vec3, device="cpu"),
              wp.array(active.astype(np.int32), dtype=wp.int32, device="cpu"))
    return LiquidProbe(geo, len(x), "cpu").measure(t, pose, catcher, *arrays, volume)


def _level_liquid(tilt: float, area: float) -> tuple[Pose, np.ndarray]:
    """A resting liquid of cross-section ``area`` (m^2) in the pouring vessel of Camporredondo et al. (2019)
    tilted by ``tilt`` about the lip."""
    lip = SPEC.lip_local
    rot = rotation_y(tilt)
    pose = Pose(lip - rot @ lip, rot)
    geom = VesselGeometry(SPEC.inner_width, SPEC.inner_height, WALL, SPEC.inner_depth)
    level = static_h_q(geom, tilt, area)  # crest height above the surface, world z
    crest = pose.transform(np.array([[0.5 * SPEC.inner_width, 0.0, SPEC.inner_height]]))[0]
    surface_z = crest[2] + level
    b = 0.5 * SPEC.inner_width
    xs = np.arange(-b + 0.5 * DX, b, DX)
    zs = np.arange(0.5 * DX, SPEC.inner_height, DX)
    local = np.array([(x, 0.0, z) for x in xs for z in zs])
    world = pose.transform(local)
    return pose, world[world[:, 2] <= surface_z]


@pytest.mark.parametrize("tilt_deg", [0.0, 10.0, 25.0])
def test_level_liquid_gives_theta1_equal_to_tilt(tilt_deg):
    tilt = math.radians(tilt_deg)
    pose, x = _level_liquid(tilt, 0.191 * 0.12)
    catcher = Pose((0.4, 0.0, -0.3))
    m = measure(1.0, GEO, pose, catcher, x, np.zeros_like(x), np.ones(len(x), bool), 0.002)
    assert m.tilt == pytest.approx(tilt, abs=1e-9)
    assert abs(m.theta1 - tilt) <= ANGLE_TOLERANCE
    assert m.h_q < 0.0  # the surface is below the crest
    assert m.v_q == 0.0 and m.poured_volume == pytest.approx(0.001)
    assert m.catcher_rim_z == pytest.approx(-0.3 + 0.16)


def test_liquid_over_the_crest_and_leaving_at_the_lip():
    pose = Pose()
    crest = np.array([0.5 * SPEC.inner_width, 0.0, SPEC.inner_height])
    over = crest + np.array([0.0, 0.0, 0.004])  # a particle centre 4 mm over the crest
    lip = GEO.lip_local
    # two particles past the lip by one to four spacings (measured), one still at the lip (not: the liquid behind
    # it still pushes it there)
    leaving = np.array([lip + [1.5 * DX, 0.0, 0.001], lip + [3.5 * DX, 0.0, -5.0 * DX], lip + [0.5 * DX, 0.0, 0.0]])
    x = np.vstack([over, leaving])
    v = np.array([[0.0, 0.0, 0.0], [0.3, 0.0, -0.1], [0.5, 0.0, -0.3], [0.1, 0.0, 0.0]])
    m = measure(0.5, GEO, pose, Pose((0.4, 0.0, -0.3)), x, v, np.ones(4, bool), 0.0029)
    assert m.v_q == pytest.approx(0.4)
    assert m.v_q_z == pytest.approx(-0.2)
    assert (m.lip_x, m.lip_z) == pytest.approx((lip[0], lip[2]))


def _liquid_over_the_crest(level: float, shift: float) -> np.ndarray:
    """A particle lattice (spacing DX, shifted by ``shift`` m along x) in the upright pourer whose top layer stands
    ``level - DX / 2`` over the crest, reaching past both ends of the head's window."""
    crest = np.array([0.5 * SPEC.inner_width, 0.0, SPEC.inner_height])
    xs = crest[0] + shift + DX * np.arange(-8, 5)
    zs = crest[2] + level - 0.5 * DX - DX * np.arange(8)
    return np.array([(x, 0.0, z) for x in xs for z in zs])


@pytest.mark.parametrize("level_spacings, shift_spacings", [(2.0, 0.0), (2.3, 0.37), (3.1, 0.81)])
def test_the_head_of_a_lattice_is_its_top_layer_plus_half_a_spacing(level_spacings, shift_spacings):
    # the B-spline's translates sum to one: any lattice phase in x, any level at least two spacings over the crest
    x = _liquid_over_the_crest(level_spacings * DX, shift_spacings * DX)
    m = measure(0.0, GEO, Pose(), Pose(), x, np.zeros_like(x), np.ones(len(x), bool), 0.002)
    assert m.h_q == pytest.approx(level_spacings * DX, abs=1e-6)  # float32 positions


def test_the_head_is_continuous_when_another_particle_becomes_the_highest():
    # One particle passes over the liquid's top layer from upstream, through the head's window and past the crest,
    # as the highest particle there: the head read from the highest particle over the crest jumped by about a spacing
    # where it entered that band. Here the head follows it at most at the window's slope: max |B'| = 2/3 per width
    # of two spacings, times a particle's weight dx / 2 in a window that wide, 1/6 of the distance moved (the level's
    # inverse gain 1/C(v) is 1 at levels over two spacings).
    level, step = 2.3 * DX, 1e-4
    liquid = _liquid_over_the_crest(level, 0.0)
    crest = np.array([0.5 * SPEC.inner_width, 0.0, SPEC.inner_height])
    path_x = np.arange(crest[0] - 8.0 * DX, crest[0] + 3.0 * DX, step)
    heads = []
    for px in path_x:
        x = np.vstack([liquid, [px, 0.0, crest[2] + level + 0.2 * DX]])
        heads.append(measure(0.0, GEO, Pose(), Pose(), x, np.zeros_like(x), np.ones(len(x), bool), 0.002).h_q)
    heads = np.array(heads)
    assert heads.max() - heads[0] > 0.1 * DX  # it does add to the head while in the window
    assert np.abs(np.diff(heads)).max() <= step / 6.0 + 1e-6  # float32 positions: 1e-6 m


def _liquid_under_a_plane(spec, dim: int, slope: float, level: float, dx: float = DX) -> np.ndarray:
    """A particle lattice (spacing ``dx``, vessel frame of the upright ``spec``) filling its inner section below the
    plane z = level + slope x: in 2-D the pour-plane slice, in 3-D the box or the cylinder."""
    b = 0.5 * spec.inner_width
    xs = np.arange(-b + 0.5 * dx, b, dx)
    ys = np.arange(-0.5 * spec.section_depth + 0.5 * dx, 0.5 * spec.section_depth, dx) if dim == 3 else np.zeros(1)
    zs = np.arange(0.5 * dx, spec.inner_height, dx)
    x, y, z = (a.ravel() for a in np.meshgrid(xs, ys, zs, indexing="ij"))
    keep = z < level + slope * x
    if spec.shape is VesselShape.CYLINDER:
        keep &= x**2 + y**2 <= b**2
    return np.column_stack([x, y, z])[keep]


@pytest.mark.parametrize("slope, phase", [(0.05, 0.0), (0.05, 0.5), (0.2, 0.3), (0.5, 0.0)])
def test_free_surface_of_a_lattice_under_a_plane_recovers_its_slope(slope, phase):
    # the lattice's surface is a staircase within half a spacing of the plane: its angle within atan(dx / B)
    x = _liquid_under_a_plane(SPEC, 2, slope, 0.1 + phase * DX)
    m = measure(0.0, GEO, Pose(), Pose(), x, np.zeros_like(x), np.ones(len(x), bool), 0.002)
    assert abs(m.theta1 - math.atan(slope)) <= ANGLE_TOLERANCE


@pytest.mark.parametrize("shape", [VesselShape.BOX, VesselShape.CYLINDER])
def test_free_surface_in_3d_is_the_depth_average(shape):
    # 3-D: each particle's share is divided by the section's extent across the pour plane at its x (a cylinder's
    # chord varies with x: divided by the diameter, its columns read the chord's profile and the slope 0.4 as 0.31)
    spec = VesselSpec(shape=shape, inner_width=0.08, inner_depth=0.06, inner_height=0.08)
    dx = spec.inner_width / 32
    geo = MeasurementGeometry(spec, 3 * dx, 0.16, 1.5 * dx, dx, initial_volume=0.0003, dim=3)
    assert geo.columns == 13
    for slope in (0.0, 0.15, 0.4):
        x = _liquid_under_a_plane(spec, 3, slope, 0.0413, dx)
        m = measure(0.0, geo, Pose(), Pose(), x, np.zeros_like(x), np.ones(len(x), bool), 0.0003)
        assert abs(m.theta1 - math.atan(slope)) <= math.atan(dx / spec.inner_width), slope


def test_free_surface_is_continuous_when_a_particle_crosses_the_columns():
    # One particle slides over a level liquid's top layer across the vessel: the line through the columns' top
    # particles jumped wherever it entered or left a column. Here theta1 follows it at most at the slope of the
    # least-squares weights times the columns' B-spline weights: |d theta1 / d x_i| <= max_k |a_k| (dx^2 / w^2)
    # sum_k |B'|, a_k = x_k / sum x_k^2 the weight of column k's height in the slope, sum_k |B'| <= 4 * 2/3.
    liquid = _liquid_under_a_plane(SPEC, 2, 0.0, 0.1)
    step, w = 1e-4, 2.0 * DX
    xs = (np.arange(GEO.columns) - GEO.columns // 2) * w
    bound = np.abs(xs).max() / (xs**2).sum() * (DX / w) ** 2 * (4 * 2.0 / 3.0) * step
    angles = []
    for px in np.arange(-0.05, 0.05, step):
        x = np.vstack([liquid, [px, 0.0, liquid[:, 2].max() + DX]])
        angles.append(measure(0.0, GEO, Pose(), Pose(), x, np.zeros_like(x), np.ones(len(x), bool), 0.002).theta1)
    angles = np.array(angles)
    assert angles.max() - angles.min() > 10.0 * bound  # it does tilt the line as it crosses
    assert np.abs(np.diff(angles)).max() <= bound + 1e-6  # float32 positions


class _CompareWithReference:
    """Run observer: at every sample, the probe on the solver's device arrays against the numpy reference on
    the particles read back (in the original order)."""

    def __init__(self, geo: MeasurementGeometry):
        self.geo = geo
        self.samples = self.leaving = self.crossing = 0

    def start(self, solver):
        self.probe = LiquidProbe(self.geo, solver.n_particles, solver.device)

    def sample(self, solver, before, after, x, active):
        state = solver.state
        catcher = Pose((0.4, 0.0, -0.3))
        m = self.probe.measure(solver.time, after, catcher, state.x, state.v, state.active, 0.001)
        ref = reference_measure(self.geo, after, catcher, x[active], solver.velocities()[active])
        for name in ("theta1", "h_q", "v_q", "v_q_z", "jet_dx", "jet_dz", "lip_x", "lip_z", "catcher_rim_z"):
            assert getattr(m, name) == pytest.approx(ref[name], abs=PROBE_TOLERANCE[name]), name
        rim_z = m.lip_z - 0.04  # a plane the stream falls through
        crossing = self.probe.stream_crossing_x(state.x, state.v, state.active, rim_z, m.lip_z, 9.81)
        expected = reference_crossing_x(x[active], solver.velocities()[active], rim_z, m.lip_z, self.geo.spacing, 9.81)
        assert crossing == pytest.approx(expected, abs=1e-6, nan_ok=True)
        self.samples += 1
        self.leaving += ref["leaving"] > 0
        self.crossing += math.isfinite(expected)


# Probe (float32 on the device) against the numpy reference (float64 of the same float32 particles): transforms and
# sums in float32 over ~100 particles (1e-6 m, m/s); theta1 from a fit whose inputs agree to 1e-7 m.
PROBE_TOLERANCE = dict(theta1=1e-5, h_q=1e-6, v_q=1e-5, v_q_z=1e-5, jet_dx=1e-6, jet_dz=1e-6, lip_x=1e-9, lip_z=1e-9,
                       catcher_rim_z=1e-9)


# (dim, particles across, rim-plane crossings at least): the coarse 3-D liquid has not fallen 4 cm below the lip
# within the 0.5 s (the crossing does not depend on the dimension; 2-D checks it); 12 across is the coarsest with
# three free-surface columns
@pytest.mark.parametrize("dim, across, crossings", [(2, 16, 5), (3, 12, 0)])
def test_probe_equals_the_numpy_contract_on_a_pouring_sph_liquid(dim, across, crossings):
    # that vessel, half full, tilted about its lip at 4 rad/s to 80 deg: a slosh over the crest, then a stream
    spec = seed_pouring_vessel()
    dx = spec.inner_width / across
    cfg = FluidConfig(dim=dim, spacing=dx, pressure_solver="wcsph", max_expected_speed=1.6, domain_min=domain_around(spec, 0.0)[0],
                      domain_max=domain_around(spec, 0.0)[1])
    geo = MeasurementGeometry(spec, 3 * dx, 0.16, cfg.smoothing_length, dx, initial_volume=0.003, dim=dim)
    observer = _CompareWithReference(geo)
    run = run_scripted(spec, 0.5 * spec.inner_height, cfg, tilt_about_lip(spec, 4.0, math.radians(80.0)), 0.5, observer=observer)
    assert run.failure == ""
    assert observer.samples == 250 and observer.leaving >= 20 and observer.crossing >= crossings  # the stream was measured


def test_a_launch_s_key_reads_the_array_arguments_its_signature_names():
    from cosim.coupling.measure import argument_layout, collect_rim_crossing, sum_leaving_stream

    # frames (an array of one), lip, dx, top, n, chunk, then x, v, active, sums
    assert argument_layout(sum_leaving_stream) == ((0, 6, 7, 8, 9), (1, 2, 3, 4, 5))
    assert argument_layout(collect_rim_crossing) == ((3, 4, 5, 6, 7), (0, 1, 2))
