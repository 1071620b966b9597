"""Where a stream leaves its vessel (cosim.validation.launch_point): synthetic streams on known free-fall paths."""

import math

import numpy as np
import pytest

from cosim.fluid.config import GRAVITY
from cosim.validation import launch_point
from cosim.validation.free_fall import ParticleFollower
from cosim.vessel import seed_pouring_vessel

DX = 0.006  # m, particle spacing
SPEED = 0.5  # m/s along the top face where the stream leaves it
ROWS = 3


def stream(edge, normal, along, times, shift=0.0):
    """Launch states (N, 4: x, z, v_x, v_z) and launch times of a stream of ROWS rows (centres dx/2, 3 dx/2, ... above
    the top face's line through ``edge``) that leaves the top face at ``edge`` + ``shift`` ``normal`` (m) tangent to it at
    SPEED and falls freely; each particle is caught ``times`` (s) after it left (negative: before), one per row and launch
    time, launched at 0.01 s steps."""
    normal, along, edge = (np.asarray(a, float) for a in (normal, along, edge))
    g = np.array([0.0, -GRAVITY])
    states, t_launch = [], []
    for k, s in enumerate(times):
        for row in range(ROWS):
            start = edge + shift * normal + (row + 0.5) * DX * along
            states.append(np.concatenate([start + SPEED * normal * s + 0.5 * g * s * s, SPEED * normal + g * s]))
            t_launch.append(0.01 * k)
    return np.array(states), np.array(t_launch)


def lower_surface(states, t_launch, edge, normal, along):
    crossings = launch_point.plane_crossings(states, normal, along, edge)
    return crossings, launch_point.lower_edge(t_launch, crossings, DX)[1]


def test_a_horizontal_stream_from_the_lip_passes_it_at_its_rows():
    crossings, lower = lower_surface(*stream((0.1, 0.2), (1, 0), (0, 1), np.linspace(0.01, 0.05, 20)), (0.1, 0.2), (1, 0), (0, 1))
    assert crossings == pytest.approx(np.tile((np.arange(ROWS) + 0.5) * DX, 20), abs=1e-12)
    assert len(lower) == 4 and lower == pytest.approx(0.0, abs=1e-12)


def test_a_stream_held_on_a_longer_crest_passes_below_the_real_lip():
    # the crest reaches 12.9 mm past the real lip (dummy layers 17.9 mm thick for a 5 mm wall) and the stream runs
    # horizontally to its end: traced back along its free path it passes the real outer face g l^2 / (2 U^2) below the
    # lip, through the wall; at the crest's own end it passes at 0. The liquid's own positions at the real face would
    # say 0 (it runs over the crest there): only the free path tells the lip it left from.
    crest = 0.0129
    states, t = stream((0.0, 0.0), (1, 0), (0, 1), np.linspace(0.001, 0.05, 20), shift=crest)
    _, at_real = lower_surface(states, t, (0.0, 0.0), (1, 0), (0, 1))
    _, at_crest = lower_surface(states, t, (crest, 0.0), (1, 0), (0, 1))
    drop = GRAVITY * crest**2 / (2.0 * SPEED**2)  # 3.26 mm
    assert at_real == pytest.approx(-drop, abs=1e-12) and at_crest == pytest.approx(0.0, abs=1e-12)
    assert np.median(at_real) < -launch_point.LIP_TOLERANCE  # the check fails it


@pytest.mark.parametrize("tilt", [30.0, 60.0, 75.0])
def test_a_tilted_stream_from_the_lip_passes_it_whether_launched_before_or_after(tilt):
    # tilted about y: the top face points along n = (cos, -sin), the outer face along u = (sin, cos); particles caught
    # before they pass the outer face (a thick stream's upper rows) are followed forward along their free path
    th = math.radians(tilt)
    normal, along, edge = (math.cos(th), -math.sin(th)), (math.sin(th), math.cos(th)), (0.3, -0.1)
    states, t = stream(edge, normal, along, np.linspace(-0.02, 0.04, 30))
    crossings, lower = lower_surface(states, t, edge, normal, along)
    assert crossings == pytest.approx(np.tile((np.arange(ROWS) + 0.5) * DX, 30), abs=1e-12)
    assert lower == pytest.approx(0.0, abs=1e-12)


def test_a_path_that_never_passes_out_through_the_plane_gives_nan():
    # the upright vessel's outer face (a vertical plane, gravity along it): a particle behind it moving inward
    assert np.isnan(launch_point.plane_crossings(np.array([[-0.01, 0.0, -0.3, 0.0]]), (1.0, 0.0), (0.0, 1.0), (0.0, 0.0)))[0]


def test_windows_with_too_few_crossings_are_left_out_and_the_summary_says_so():
    t = np.array([0.0, 0.001, 0.002, 0.2])
    starts, lower = launch_point.lower_edge(t, np.full(4, DX), DX)
    assert len(starts) == 0 and len(lower) == 0
    assert launch_point.summary(lower)["windows"] == 0 and math.isnan(launch_point.summary(lower)["median"])
    s = launch_point.summary(np.array([0.001, 0.002, 0.004]))
    assert (s["median"], s["min"], s["max"], s["windows"]) == (0.002, 0.001, 0.004, 3)


def test_the_follower_measures_at_the_real_lip_and_at_the_lip_the_liquid_sees():
    # the case's wiring: upright vessel, the real lip at the wall's outer top edge, the lip the liquid sees 12.9 mm out
    spec = seed_pouring_vessel()
    follower = ParticleFollower(spec, DX, 0.25)
    real = spec.lip_local[[0, 2]]
    seen = real + (0.0129, 0.0)
    states, t = stream(seen, (1, 0), (0, 1), np.linspace(0.001, 0.05, 20))
    follower.launch = np.column_stack([t, states])
    follower.launch_frame = np.tile(np.concatenate([(1.0, 0.0, 0.0, 1.0), real, seen]), (len(t), 1))
    follower.passed_face = np.full((len(t), 2, 2), np.nan)
    out = follower.departure(DX)
    assert out["seen_free_lower"] == pytest.approx(0.0, abs=1e-12)
    assert out["real_free_lower"] == pytest.approx(-GRAVITY * 0.0129**2 / (2.0 * SPEED**2), abs=1e-12)
    assert len(out["real_passed_lower"]) == 0  # no particle passed a face in this synthetic record


def test_the_follower_records_where_particles_pass_out_through_each_outer_face():
    spec = seed_pouring_vessel()
    follower = ParticleFollower(spec, DX, 0.25)
    follower.faces = np.array([spec.lip_local[0], spec.lip_local[0] + 0.0129])
    follower.passed_face = np.full((3, 2, 2), np.nan)
    h, face = spec.inner_height, spec.lip_local[0]
    previous = np.array([[face - 0.002, 0.0, h + 0.004], [face - 0.002, 0.0, h + 0.010], [face + 0.001, 0.0, h + 0.02]])
    local = previous + np.array([[0.004, 0.0, -0.002], [0.001, 0.0, 0.0], [0.001, 0.0, 0.0]])
    follower._pass_faces(0.5, previous, local, np.ones(3, bool))
    # the first passes the real face halfway through the sample, 3 mm over the lip; the second stops short of it; the
    # third was already beyond it
    assert follower.passed_face[0, 0] == pytest.approx((0.5, 0.003))
    assert np.isnan(follower.passed_face[1:, 0]).all() and np.isnan(follower.passed_face[:, 1]).all()
