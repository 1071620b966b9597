"""WCSPH's delta-SPH density diffusion, pair by pair (``cosim.fluid.wcsph.add_liquid_density_rate``): the
'fourtakas' term (``FluidConfig.density_diffusion_term``) diffuses only the density a pair holds beyond the Tait
equation's hydrostatic difference between their heights, and of a particle expanded past the tension clamp only
the density its pressure sees; the 'antuono' term relies on the renormalised gradients for the hydrostatic part,
and without them diffuses the hydrostatic difference itself."""

from __future__ import annotations

import math

import pytest
import warp as wp

from cosim.fluid.config import FluidConfig
from cosim.fluid.params import SPHParams, make_params
from cosim.fluid.sph_kernels import kernel_dw
from cosim.fluid.wcsph import add_liquid_density_rate, hydrostatic_density_difference

DX = 0.005  # m
RHO_J = 1001.0  # kg/m^3, the upper particle's density (compressed: every test's pair but the expanded one's lies above rho0)


@wp.kernel
def _pair_rate(prm: SPHParams, r: wp.vec3, rho_i: float, rho_j: float, grad: wp.vec3, out: wp.array(dtype=float)):
    r2 = wp.dot(r, r)
    dist = wp.sqrt(r2)
    gw = r * (kernel_dw(dist, prm.inv_h, prm.sigma, prm.kernel) / dist)
    diffusion = prm.delta * prm.h * prm.sound_speed
    still = wp.vec3(0.0)
    out[0] = add_liquid_density_rate(prm, 0.0, diffusion, rho_i, grad, still, r, r2, gw, still, rho_j, grad, prm.mass)
    out[1] = hydrostatic_density_difference(prm, r)


def _rate(
    term: str, below: float, rho_i: float, grad: tuple[float, float, float] = (0.0, 0.0, 0.0), **settings: object
) -> tuple[float, float]:
    """Particle i's density rate (kg/m^3/s) from a neighbour j at rest ``below`` m above it, and the pair's
    hydrostatic density difference rho^H_i - rho^H_j (kg/m^3); ``settings``: more FluidConfig fields."""
    cfg = FluidConfig(dim=2, spacing=DX, pressure_solver="wcsph", max_expected_speed=1.0, density_diffusion_term=term, **settings)
    out = wp.zeros(2, dtype=float, device="cpu")
    r = wp.vec3(0.0, 0.0, -below)  # r = x_i - x_j: i lies below j
    wp.launch(_pair_rate, 1, inputs=[make_params(cfg, 1), r, rho_i, RHO_J, wp.vec3(*grad), out], device="cpu")
    rate, hydro = out.numpy()
    return float(rate), float(hydro)


def test_the_hydrostatic_difference_is_the_tait_density_at_rho0_g_dz():
    cfg = FluidConfig(dim=2, spacing=DX, pressure_solver="wcsph", max_expected_speed=1.0)
    b = cfg.rest_density * cfg.sound_speed**2 / cfg.gamma
    _, hydro = _rate("fourtakas", DX, RHO_J)
    expected = cfg.rest_density * ((1.0 + cfg.rest_density * cfg.gravity_magnitude * DX / b) ** (1.0 / cfg.gamma) - 1.0)
    assert hydro == pytest.approx(expected, rel=1e-3)  # float32: (1 + x)^(1/gamma) - 1 keeps about 2e-4 of 5e-4
    assert hydro > 0.0  # the lower particle is the denser at rest


def test_a_resting_pair_at_its_hydrostatic_densities_exchanges_nothing_under_fourtakas():
    _, hydro = _rate("fourtakas", DX, RHO_J)
    rate, _ = _rate("fourtakas", DX, RHO_J + hydro)
    assert abs(rate) < 1e-3 * abs(_rate("fourtakas", DX, RHO_J)[0])  # float32 densities: 6e-5 kg/m^3 of 0.5


def test_without_gradients_antuonos_term_diffuses_the_hydrostatic_difference():
    _, hydro = _rate("fourtakas", DX, RHO_J)
    rate, _ = _rate("antuono", DX, RHO_J + hydro)
    assert rate < 0.0  # the lower particle loses the density that holds the column up
    # with the exact gradient of the hydrostatic field (d rho / dz = -hydro / DX) the linear part cancels, but for
    # the regularisation eta^2 = 0.01 h^2 in the first term's r^2 + eta^2: what is left is -eta^2 / DX^2 of it
    exact, _ = _rate("antuono", DX, RHO_J + hydro, grad=(0.0, 0.0, -hydro / DX))
    eta2 = 0.01 * (FluidConfig().smoothing_ratio * DX) ** 2
    assert exact / rate == pytest.approx(-eta2 / DX**2, rel=1e-2)  # float32: the cancellation amplifies 1e-4 errors 44 x


@pytest.mark.parametrize("excess", [0.5, -0.5])
def test_fourtakas_diffuses_the_dynamic_density_from_the_denser_particle(excess):
    _, hydro = _rate("fourtakas", DX, RHO_J)
    rate, _ = _rate("fourtakas", DX, RHO_J + hydro + excess)
    assert math.copysign(1.0, rate) == -math.copysign(1.0, excess)
    # the same dynamic difference diffuses at the same rate as Antuono's term would with no density gradient
    level, _ = _rate("antuono", DX, RHO_J + excess)
    assert rate == pytest.approx(level, rel=1e-3)  # float32 densities: 6e-5 kg/m^3 of 0.5


def test_without_tension_fourtakas_diffuses_an_expanded_particle_at_rho0():
    """Below rho0 a particle without tension has no pressure: its deficit is a void, not a density to spread into
    the liquid around it (whose pressure nothing would give back). The pair term reads max(rho, rho0)."""
    at_rest_density, _ = _rate("fourtakas", DX, 1000.0, max_tension=0.0)
    for expanded in (999.0, 990.0, 850.0):
        rate, _ = _rate("fourtakas", DX, expanded, max_tension=0.0)
        assert rate == at_rest_density
    assert at_rest_density > 0.0  # i still takes the compressed neighbour's excess over rho0 (its dynamic density)


def test_under_a_tension_clamp_fourtakas_reads_the_density_down_to_the_clamp():
    cfg = FluidConfig(dim=2, spacing=DX, pressure_solver="wcsph", max_expected_speed=1.0, max_tension=1000.0)
    rho_t = make_params(cfg, 1).tension_density  # kg/m^3, where the Tait pressure reaches -1 kPa
    assert 980.0 < rho_t < 999.0
    stretched, _ = _rate("fourtakas", DX, 999.0, max_tension=1000.0)
    assert stretched > _rate("fourtakas", DX, 1000.0, max_tension=1000.0)[0]  # the tension it carries is diffused
    past, _ = _rate("fourtakas", DX, rho_t - 5.0, max_tension=1000.0)
    assert past == pytest.approx(_rate("fourtakas", DX, rho_t, max_tension=1000.0)[0], rel=1e-5)
