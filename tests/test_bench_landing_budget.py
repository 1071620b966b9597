"""The landing error's budget: a synthetic stream whose flight and launch are known term by term."""

import math

import numpy as np
import pytest

from controllers.catcher import fall_time
from cosim.bench.landing_budget import (LANDING_FILE, PARTICLES_FILE, SERIES_FILE, TERMS, StreamParticles, ballistic_x, budget,
                                        decompose, stream_scatter)
from cosim.coupling.landing import BAND_SPACINGS, MIN_FALL_SPEED_FRACTION
from cosim.io.pour_series import COLUMNS, write_series_csv

G = 9.81
DX = 0.006  # m
LIP = (0.10, 1.00)  # m, world x, z of the lip (vessel upright: its inner box lies at x < 0.1)
RIM_Z = 0.60  # m
PERIOD = 0.01  # s
EVERY = 5  # control steps between two launched particles
SPEEDS = (0.37, 0.43)  # m/s, launch speeds along x, alternating


def synthetic_run(folder, drift: float, every: int = EVERY) -> float:
    """A stream of single particles launched from the middle of the probe's window, one every ``every`` steps, and
    ``drift`` (m/s) added to each one's x velocity after its launch but not to what it reports (a force in flight
    that the ballistic prediction does not know). Writes series.csv and particles.npz; returns the fall time (s)."""
    x0, z0 = LIP[0] + 2.5 * DX, LIP[1]
    fall = fall_time(z0 - RIM_Z, 0.0, G)
    steps = 200
    t = PERIOD * np.arange(steps)
    launches = np.arange(10, steps - 40, every)
    n = len(launches)
    state = np.zeros((steps, n, 4))
    active = np.zeros((steps, n), bool)
    for i, k0 in enumerate(launches):
        vx = SPEEDS[i % 2]
        tau = t - t[k0] - (0.0037 * i) % PERIOD  # launched between two control steps
        flying = (tau >= 0.0) & (tau <= 1.2 * fall)
        active[:, i] = flying
        state[:, i] = np.column_stack([x0 + (vx + drift) * tau, z0 - 0.5 * G * tau**2, np.full(steps, vx), -G * tau])
    rows = {c: [0.0] * steps for c in COLUMNS}
    rows.update(t=list(t), phase=["cfs"] * steps, lip_x=[LIP[0]] * steps, lip_z=[LIP[1]] * steps,
                catcher_rim_z=[RIM_Z] * steps, tilt=[0.0] * steps, h_q=[0.015] * steps,
                smoothed_catcher_dx=[0.0] * steps)
    min_speed = MIN_FALL_SPEED_FRACTION * math.sqrt(2.0 * G * (LIP[1] - RIM_Z))
    landing, fall_times, measured = [], [], []
    for k in range(steps):
        window = active[k] & (state[k, :, 0] <= LIP[0] + 4 * DX)
        band = active[k] & (np.abs(state[k, :, 1] - RIM_Z) <= BAND_SPACINGS * DX) & (state[k, :, 3] < -min_speed)
        if window.any():
            x, z, vx, vz = state[k, window].mean(axis=0)
            landing.append(float(ballistic_x(x, z, vx, vz, RIM_Z, G)))
            fall_times.append(fall_time(z - RIM_Z, vz, G))
        else:
            landing.append(landing[-1] if landing else x0)
            fall_times.append(math.nan)
        measured.append(float(np.median(state[k, band, 0])) if band.any() else math.nan)
    rows.update(landing_x=landing, landing_fall_time=fall_times, landing_measured_x=measured)
    write_series_csv(rows, folder / SERIES_FILE)
    np.savez_compressed(folder / PARTICLES_FILE, t=t[1:], state=state[1:].astype(np.float32), active=active[1:],
                        spacing=DX, gravity=G, inner_width=0.191, inner_height=0.191, wall=0.0,
                        catcher_home_x=0.2)
    (folder / LANDING_FILE).write_text("{}\n")
    return fall


def test_terms_add_up_to_the_error_and_name_the_flight(tmp_path) -> None:
    fall = synthetic_run(tmp_path, drift=0.02)
    d = decompose(tmp_path)
    assert d["decomposed"] == d["samples"] > 10
    for row in d["rows"]:
        assert sum(row[term] for term in TERMS) == pytest.approx(row["error"], abs=1e-12)
        assert row["spread"] == pytest.approx(0.0, abs=1e-6)  # one particle in the window: it is the mean
        # the drift acts from the particle's last step in the window (within two steps of its launch) to the rim
        assert 0.02 * (fall - 2 * PERIOD) - 2e-4 <= row["flight"] <= 0.02 * fall + 2e-4
    b = budget(d)
    assert b["flight"]["without_mm"] < b["median_abs_error_mm"]


def test_a_ballistic_stream_has_no_flight_term(tmp_path) -> None:
    synthetic_run(tmp_path, drift=0.0)
    b = budget(decompose(tmp_path))
    assert abs(b["flight"]["median_mm"]) < 0.2  # the crossing interpolated linearly between steps
    assert b["spread"]["median_abs_mm"] < 1e-3


def test_the_stream_scatter_is_the_launch_velocities_spread_and_the_landings_half_width(tmp_path) -> None:
    # a particle spends at most 22.5 ms in the window past its launch point (1.5 DX at 0.4 m/s): launched every two
    # steps, a step's window holds two neighbours at most, one at each speed, each 30 mm/s off their mean; they land
    # +-(SPEEDS[1] - SPEEDS[0]) / 2 * fall = 8.6 mm either side of the stream's centre
    fall = synthetic_run(tmp_path, drift=0.0, every=2)
    scatter = stream_scatter(StreamParticles(tmp_path))
    assert scatter["window_steps"] > 5 and scatter["window_particles"] == 2
    assert scatter["launch_vx_rms_mm_s"] == pytest.approx(1e3 * (SPEEDS[1] - SPEEDS[0]) / 2, rel=1e-6)
    assert scatter["footprint_crossings"] > 20
    assert scatter["footprint_median_abs_mm"] == pytest.approx(1e3 * (SPEEDS[1] - SPEEDS[0]) / 2 * fall, abs=1.0)
    one_at_a_time = tmp_path / "sparse"
    one_at_a_time.mkdir()
    synthetic_run(one_at_a_time, drift=0.0)
    assert stream_scatter(StreamParticles(one_at_a_time))["window_steps"] == 0  # no step holds two: nothing to spread


def test_a_particle_sample_after_the_series_last_row_is_left_out(tmp_path) -> None:
    # a run cut off by its duration samples the particles after its last step, which no series row follows
    synthetic_run(tmp_path, drift=0.0)
    data = dict(np.load(tmp_path / PARTICLES_FILE))
    complete = StreamParticles(tmp_path).state
    data["t"] = np.append(data["t"], data["t"][-1] + PERIOD)
    data["state"] = np.concatenate([data["state"], data["state"][-1:]])
    data["active"] = np.concatenate([data["active"], data["active"][-1:]])
    np.savez_compressed(tmp_path / PARTICLES_FILE, **data)
    np.testing.assert_array_equal(StreamParticles(tmp_path).state, complete)
