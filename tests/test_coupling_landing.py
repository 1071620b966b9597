"""Landing-point measurement (the stream crossing vessel B's rim plane) and its pairing with the prediction."""

import math

import numpy as np
import pytest

import warp as wp

from cosim.coupling.landing import landing_accuracy
from cosim.coupling.measure import LiquidProbe, MeasurementGeometry
from cosim.vessel import seed_pouring_vessel
from cosim.io.pour_series import COLUMNS, read_series_csv, write_series_csv

G = 9.81
DX = 0.006  # m


def stream_crossing_x(x, v, rim_z, lip_z, dx, gravity, active=None):
    """The probe's rim-plane crossing of numpy particles on the CPU."""
    geo = MeasurementGeometry(seed_pouring_vessel(), 3 * dx, 0.16, 1.5 * dx, dx, initial_volume=0.003, dim=2)
    active = np.ones(len(x), np.int32) if active is None else active.astype(np.int32)
    arrays = [wp.array(a.astype(np.float32), dtype=wp.vec3, device="cpu") for a in (x, v)] + [wp.array(active, dtype=wp.int32, device="cpu")]
    return LiquidProbe(geo, len(x), "cpu").stream_crossing_x(*arrays, rim_z, lip_z, gravity)


def test_crossing_is_the_falling_stream_only() -> None:
    rim_z, lip_z = 0.5, 0.9
    stream = np.column_stack([np.full(5, 0.31), np.zeros(5), rim_z + np.linspace(-DX, DX, 5)])
    pool = np.column_stack([np.linspace(0.2, 0.4, 7), np.zeros(7), np.full(7, rim_z)])  # resting at the rim height
    splash = np.array([[0.45, 0.0, rim_z]])  # falling, but slowly
    far = np.array([[0.10, 0.0, rim_z + 5 * DX]])  # fast, but outside the band
    x = np.vstack([stream, pool, splash, far])
    v = np.zeros_like(x)
    v[:5, 2] = -2.8
    v[12, 2] = -0.5
    v[13, 2] = -2.8
    assert stream_crossing_x(x, v, rim_z, lip_z, DX, G) == pytest.approx(0.31)
    assert math.isnan(stream_crossing_x(x[5:13], v[5:13], rim_z, lip_z, DX, G))
    spilled = np.ones(len(x), bool)
    spilled[:3] = False  # three of the five stream particles deactivated (moved away): not counted
    x[:3, 0] = 0.5
    assert stream_crossing_x(x, v, rim_z, lip_z, DX, G, active=spilled) == pytest.approx(0.31)


def test_prediction_is_paired_with_the_arrival_of_its_liquid() -> None:
    t = np.arange(0.0, 2.0, 0.01)
    fall = np.full_like(t, 0.3)
    in_cfs = t >= 0.5
    fall[~in_cfs] = np.nan
    predicted = 0.30 + 0.01 * t  # the aim drifts; the liquid launched at t lands where predicted at t, + 4 mm
    measured = np.where(t >= 0.8, 0.30 + 0.01 * (t - 0.3) + 0.004, np.nan)
    acc = landing_accuracy(t, predicted, fall, measured, in_cfs)
    assert acc["samples"] == np.count_nonzero(t >= 0.8 - 1e-9)
    assert acc["median_abs_error"] == pytest.approx(0.004, abs=1e-9)
    assert acc["max_abs_error"] == pytest.approx(0.004, abs=1e-9)
    # a measurement without flowing CFS liquid to pair it with is not counted
    assert landing_accuracy(t, predicted, np.full_like(t, np.nan), measured, in_cfs) == {"samples": 0}


def test_scatter_about_the_stream_centre_is_split_from_the_centre_error() -> None:
    t = np.arange(0.0, 6.0, 0.01)
    fall = np.full_like(t, 0.2)
    in_cfs = np.ones_like(t, bool)
    predicted = np.full_like(t, 0.20)
    # the stream's centre lands 1 mm beyond the prediction; single particles scatter +-6 mm about it, alternately
    scatter = np.where(np.arange(len(t)) % 2 == 0, 0.006, -0.006)
    measured = 0.201 + scatter
    acc = landing_accuracy(t, predicted, fall, measured, in_cfs)
    assert acc["median_abs_error"] == pytest.approx(0.006, abs=1.1e-3)  # 5 or 7 mm per sample
    assert acc["centre_median_abs_error"] == pytest.approx(0.001, abs=2e-4)  # the window's mean: the centre's 1 mm
    assert acc["scatter_median_abs"] == pytest.approx(0.006, abs=2e-4)


def test_series_csv_round_trip(tmp_path) -> None:
    rows = {c: [0.1, 0.2] for c in COLUMNS}
    rows["phase"] = ["cfs", "return"]
    rows["landing_measured_x"] = [math.nan, 0.3]
    write_series_csv(rows, tmp_path / "series.csv")
    back = read_series_csv(tmp_path / "series.csv")
    assert back["phase"] == ["cfs", "return"]
    assert math.isnan(back["landing_measured_x"][0]) and back["landing_measured_x"][1] == 0.3
    assert back["t"] == [0.1, 0.2]


def test_outflow_timing_finds_the_start_of_a_steady_rate() -> None:
    from cosim.coupling.outflow import RATE_WINDOW, outflow_timing

    t = np.arange(0.0, 10.0, 0.01)
    # a slosh-driven burst, then a steady 0.2 L/s from 4 s, then a trickle
    rate = np.where(t < 2.0, 0.0, np.where(t < 4.0, 3e-4 * (1 + np.sin(6 * t)), np.where(t < 8.0, 2e-4, 1e-5)))
    poured = np.concatenate([[0.0], np.cumsum(rate[:-1] * 0.01)])
    timing = outflow_timing(t, poured, t >= 4.0, start=0.5)
    assert timing["first_outflow"] == pytest.approx(2.01 - 0.5, abs=0.011)
    # the first window wholly in the steady stretch starts at 4 s
    assert timing["steady_outflow"] + 0.5 == pytest.approx(4.0, abs=0.02 + RATE_WINDOW * 0.15)
    # never steady: a rate that keeps swinging by +-50 %
    swinging = 2e-4 * (1 + 0.5 * np.sin(8 * t))
    assert math.isnan(outflow_timing(t, np.cumsum(swinging * 0.01), t >= 0, 0.0)["steady_outflow"])
