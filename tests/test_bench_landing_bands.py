"""The landing-by-band split reads a synthetic pour's lip and throw back per poured-fraction band."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from cosim.bench import landing_bands
from cosim.io.pour_series import COLUMNS, write_series_csv

INITIAL = 0.003  # m^3
DT = 0.01  # s, the control step


def synthetic_run(folder, lip_offset: float, throw: float) -> None:
    """A pour whose poured fraction rises linearly from 0 to 1 over 10 s; the lip at lip_offset - 0.1 f (f the
    poured fraction) and the stream landing ``throw`` past it, except while f < 0.05 (no stream at the rim yet)."""
    t = np.arange(0.0, 10.0 + DT / 2, DT)
    fraction = t / 10.0
    lip = lip_offset - 0.1 * fraction
    landing = np.where(fraction < 0.05, math.nan, lip + throw)
    rows = {c: [math.nan] * len(t) for c in COLUMNS}
    rows.update(t=list(t), phase=["cfs"] * len(t), poured_volume=list(INITIAL * fraction), lip_x=list(lip),
                landing_measured_x=list(landing), tilt=list(0.5 + fraction), v_q=[0.44] * len(t), h_q=[0.018] * len(t))
    folder.mkdir()
    write_series_csv(rows, folder / "series.csv")
    (folder / "summary.json").write_text(json.dumps({"initial_volume": INITIAL}))


def test_each_band_splits_the_landing_into_lip_and_throw(tmp_path) -> None:
    synthetic_run(tmp_path / "coarse", lip_offset=0.10, throw=0.12)
    run = landing_bands.read_run(tmp_path / "coarse")
    for (lo, hi), band in zip(landing_bands.BANDS, run.bands):
        mid = 0.5 * (lo + hi)
        assert band["lip"] == pytest.approx(0.10 - 0.1 * mid, abs=1e-4)
        assert band["throw"] == pytest.approx(0.12, abs=1e-12)
        assert band["landing"] == pytest.approx(0.22 - 0.1 * mid, abs=1e-4)
        assert band["tilt"] == pytest.approx(0.5 + mid, abs=1e-3)
        assert abs(band["steps"] - round(1000 * (hi - lo))) <= 1  # one step per 0.1 % poured; the edges round
    assert run.pour_time == pytest.approx(8.0, abs=DT)


def test_the_reference_table_separates_the_path_from_the_throw(tmp_path) -> None:
    synthetic_run(tmp_path / "coarse", lip_offset=0.095, throw=0.12)
    synthetic_run(tmp_path / "fine", lip_offset=0.10, throw=0.128)
    coarse, fine = (landing_bands.read_run(tmp_path / name) for name in ("coarse", "fine"))
    text = landing_bands.report([coarse, fine], reference=fine)
    row = next(line for line in text.splitlines() if line.startswith("| coarse |") and "(-5.0, -8.0)" in line)
    assert row.count("-13.0 (-5.0, -8.0)") == len(landing_bands.BANDS)


def test_a_band_without_a_landing_is_nan_and_a_bad_folder_is_refused(tmp_path) -> None:
    synthetic_run(tmp_path / "run", lip_offset=0.1, throw=0.12)
    series = {c: [math.nan] * 3 for c in COLUMNS}
    series.update(t=[0.0, 0.01, 0.02], poured_volume=[0.0, 0.0, 0.0])
    bands, pour_time = landing_bands.band_medians(series, INITIAL)
    assert all(math.isnan(b["landing"]) and b["steps"] == 0 for b in bands)
    assert math.isnan(pour_time)
    assert landing_bands.main([str(tmp_path / "missing")]) == 2
