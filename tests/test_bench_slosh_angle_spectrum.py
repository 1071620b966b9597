"""The slosh-angle spectrum bench's analysis on synthetic records (the SPH case itself is run by hand)."""

import math

import numpy as np
import pytest

from cosim.bench.slosh_angle_spectrum import acoustic_mode, band_powers, gravity_wave_limit, largest_band, ring_down_residual


def test_the_ring_down_comes_out_and_a_fast_mode_stays() -> None:
    """A damped 2 Hz slosh of 0.03 rad plus 1e-4 rad at 57 Hz, recorded every 2 ms: the residual's content above
    10 Hz is the 57 Hz tone (RMS 1e-4 / sqrt 2), in the band 55-57.5 Hz, and folds to 42.5-45 Hz at 10 ms."""
    t = np.arange(0.0, 3.0, 0.002)
    tone = 1e-4 * np.sin(2 * math.pi * 57.0 * t)
    sigma = 0.002 + 0.03 * np.exp(-0.3 * t) * np.cos(2 * math.pi * 2.0 * t + 0.4) + tone
    residual = ring_down_residual(t, sigma)
    rms, bands = band_powers(residual, 0.002, 10.0)
    assert rms == pytest.approx(1e-4 / math.sqrt(2.0), rel=0.05)
    assert largest_band(bands, 11.4)[0] == pytest.approx(55.0)
    _, folded = band_powers(residual[::5], 0.01, 10.0)
    assert largest_band(folded, 11.4)[0] == pytest.approx(42.5)


def test_shortest_gravity_wave_of_the_pour_lattice() -> None:
    """Wavelength two spacings at 32 across 0.191 m: sqrt(g pi / dx) / 2 pi = 11.4 Hz."""
    assert gravity_wave_limit(0.191 / 32) == pytest.approx(11.43, abs=0.01)


def test_lowest_surface_tilting_acoustic_mode_of_the_pourer() -> None:
    """c0 = 20 m/s in the default pourer (0.191 m) filled to 0.1591 m: 10 sqrt(1 / 0.191^2 + 1 / 0.3182^2) Hz."""
    assert acoustic_mode(20.0, 0.191, 0.1591) == pytest.approx(61.06, abs=0.01)
