"""The PID compensator on Gp: the ideal PID cannot stabilise it, the filtered one can (paper Sec. 3.1, Eq. 15),
with the actuation delay in the loop."""

import itertools
import math

import control as ct
import numpy as np
import pytest

from controllers.errors import ControllerInputError
from controllers.motion import CriticallyDampedSmoother
from controllers.pid import (
    DiscretePid,
    PidDesignSpec,
    PidGains,
    actuator,
    delayed_loop,
    delayed_loop_figures,
    design_filtered_pid,
    hurwitz_sign_condition,
    loop_chain,
    measurement_cutoff,
    measurement_filter,
    place_filtered_pid,
    ideal_pid_characteristic,
    sampled_plant,
)
from controllers.sampled_filter import SampledFilter
from controllers.slosh import SloshModel, potential_flow_model, printed_paper_model

SEED = potential_flow_model(0.191, 0.1591)  # the paper's vessel and fill (Sec. 4), physical plant
DT = 0.01  # s, the default 100 Hz control period
# A pole with real part above -MARGINAL_RE is not asymptotically stable (numerical zero for these polynomials,
# whose roots are O(1..1e4) rad/s and computed to ~1e-12 relative).
MARGINAL_RE = 1e-7  # rad/s
SETTLE_BAND = 0.02  # 2 % band, as the design's settling time (python-control default)
STEADY_STATE_TOL = 1e-6  # zero steady-state error: final value of a unit step, after 40 time constants
ROOTS_RTOL = 1e-6  # python-control's closed-loop poles against numpy roots of the analytic polynomial


def _gain_grid(magnitudes: list[float]) -> list[tuple[float, float, float]]:
    values = sorted({0.0, *magnitudes, *(-m for m in magnitudes)})
    return [g for g in itertools.product(values, repeat=3) if any(g)]


def test_ideal_pid_sign_conflict_is_analytic() -> None:
    """With b2 < 0: sign(a4) = -sign(Kd), sign(a0) = sign(Ki), and a2 = b2 Ki + g Kd has the sign of -a4 whenever
    a4 and a0 share a sign. So a4, a2, a0 never all share a sign: the Hurwitz necessary condition fails for
    every (Kp, Ki, Kd), whatever the fill (b2 < 0 for every fill)."""
    for fill in (0.054, 0.1, 0.1591, 0.185):
        model = potential_flow_model(0.191, fill)
        assert model.b2 < 0
        for kp, ki, kd in _gain_grid([1e-3, 0.1, 1.0, 10.0, 1e3]):
            a4, a3, a2, a1, a0 = ideal_pid_characteristic(model, kp, ki, kd)
            if a4 * a0 > 0:
                assert a2 * a4 < 0
            assert not hurwitz_sign_condition([a4, a3, a2, a1, a0])


def test_ideal_pid_closed_loop_poles_are_never_all_stable() -> None:
    """python-control's closed-loop poles of (Kd s^2 + Kp s + Ki)/s * Gp over a gain grid of both signs."""
    s = ct.tf("s")
    gp = SEED.plant()
    for kp, ki, kd in _gain_grid([0.01, 1.0, 100.0]):
        loop = ct.feedback((kd * s**2 + kp * s + ki) / s * gp, 1)
        poles = ct.poles(loop)
        assert np.max(poles.real) > -MARGINAL_RE, (kp, ki, kd, poles)
        expected = np.roots(np.trim_zeros(ideal_pid_characteristic(SEED, kp, ki, kd), "f"))
        assert np.allclose(np.sort_complex(poles), np.sort_complex(expected), rtol=ROOTS_RTOL, atol=1e-9)


PLACED = PidDesignSpec(damping=0.7, bandwidth_ratio=1.0, actuation_delay=0.0, noise_frequency=None)  # exact placement, no search
MIN_GAIN_MARGIN_DB, MIN_PHASE_MARGIN_DEG = 6.0, 45.0  # the robustness floor the design is asked for


def test_filtered_pid_places_the_poles_and_is_stable() -> None:
    design = design_filtered_pid(SEED, PLACED, DT)
    poles = ct.poles(design.closed_loop())
    assert poles.size == 4
    assert np.max(poles.real) < 0
    assert np.allclose(np.sort_complex(poles), np.sort_complex(PLACED.target_poles(SEED.omega1, 0.7, 1.0)), rtol=1e-6)
    assert design.min_damping == pytest.approx(PLACED.damping, rel=1e-9)
    assert design.gains.tf > 2 * DT  # the 100 Hz loop resolves the derivative filter
    assert np.max(np.abs(design.discrete_poles)) < 1.0


def test_the_papers_design_is_unstable_on_the_physical_plant() -> None:
    """Poles placed on the printed plant (hinge 64 mm) leave a right-half-plane pole on the physical one."""
    printed = design_filtered_pid(printed_paper_model(0.191, 0.1591), PLACED)
    poles = ct.poles(ct.feedback(printed.gains.transfer_function() * SEED.plant(), 1))
    assert np.max(poles.real) > 30.0  # rad/s


@pytest.mark.parametrize("delay", [0.01, 0.02, 0.03])
@pytest.mark.parametrize("fill", [0.12, 0.1591, 0.185])
def test_design_with_the_actuation_delay_keeps_the_margins(fill: float, delay: float) -> None:
    """The default design, verified with python-control on the sampled loop with the smoother, the delay as z^-n and
    the measurement filter: stable, at least 6 dB and 45 deg, and it damps: the slowest closed-loop pole decays
    faster than 2 /s."""
    model = potential_flow_model(0.191, fill)
    spec = PidDesignSpec(actuation_delay=delay)
    design = design_filtered_pid(model, spec, DT)
    loop = design.gains.discrete_tf(DT) * sampled_plant(model, DT) * ct.tf(*actuator(spec, DT), DT) * measurement_filter(spec, model, DT)
    assert design.delay_steps == round(delay / DT)
    assert np.max(np.abs(ct.poles(ct.feedback(loop, 1)))) < 1.0
    gms, pms, *_ = ct.stability_margins(loop, returnall=True)
    assert min(abs(20 * math.log10(g)) for g in np.atleast_1d(gms)) >= MIN_GAIN_MARGIN_DB
    assert min(abs(p) for p in np.atleast_1d(pms)) >= MIN_PHASE_MARGIN_DEG
    assert design.decay_rate > 2.0


def test_placement_ignoring_the_delay_is_short_of_the_margins() -> None:
    """Why the chain is in the design: the placed design on Gp alone, closed through the smoother and 20 ms."""
    placed = design_filtered_pid(SEED, PLACED, DT)
    _, gm, pm = delayed_loop_figures(placed.gains, SEED, DT, actuator(PidDesignSpec(actuation_delay=0.02), DT))
    assert gm < MIN_GAIN_MARGIN_DB or pm < MIN_PHASE_MARGIN_DEG


def test_filtered_pid_has_zero_steady_state_error() -> None:
    design = design_filtered_pid(SEED)
    loop = design.closed_loop()
    assert ct.dcgain(loop) == pytest.approx(1.0, abs=1e-12)
    slowest = float(np.min(-ct.poles(loop).real))
    t = np.linspace(0.0, 40.0 / slowest, 8001)
    _, y = ct.step_response(loop, T=t)
    assert abs(y[-1] - 1.0) < STEADY_STATE_TOL
    settled = np.abs(y - 1.0) <= SETTLE_BAND
    first_settled = t[np.argmax(settled & np.flip(np.cumprod(np.flip(settled))).astype(bool))]
    assert first_settled == pytest.approx(design.settling_time, abs=t[1] - t[0] + 1e-3)


@pytest.mark.slow
def test_designs_across_sim_fills_are_stable() -> None:
    """SIM runs for h_e <= (B/2) tan 20 deg, i.e. A >= 156 mm in the paper's vessel; also lower fills. The loop that
    runs is the sampled one with the smoother, the delay and the measurement filter: stable, within the margins.
    (The continuous C Gp alone, without the filter the gains were chosen with, is not that loop: this non-minimum
    phase plant's loop is conditionally stable, and taking the filter's lag out can destabilise it.)"""
    for fill in (0.12, 0.156, 0.1591, 0.175, 0.189):
        design = design_filtered_pid(potential_flow_model(0.191, fill), dt=DT)
        assert np.max(np.abs(design.discrete_poles)) < 1.0
        assert design.gain_margin >= MIN_GAIN_MARGIN_DB and design.phase_margin >= MIN_PHASE_MARGIN_DEG
        assert design.decay_rate > 0.0


def test_too_slow_control_rate_is_a_one_line_error() -> None:
    with pytest.raises(ControllerInputError, match=r"^control_rate: 20 Hz .* is too slow") as info:
        design_filtered_pid(SEED, PidDesignSpec(damping=0.7, bandwidth_ratio=3.0, noise_frequency=None), dt=0.05)
    assert "\n" not in str(info.value)


def _run_pid(pid: DiscretePid, r: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.array([pid.step(ri, yi) for ri, yi in zip(r, y)])


def test_discrete_pid_is_its_discrete_transfer_function() -> None:
    """Unsaturated, with r = 0 (derivative on the measurement equals derivative on the error)."""
    gains = design_filtered_pid(SEED).gains
    rng = np.random.default_rng(4)
    y = np.cumsum(rng.normal(0.0, 0.01, 300))
    pid = DiscretePid(gains, DT, -1e9, 1e9, 1e9)
    pid.reset(u0=0.0, y0=0.0, r0=0.0)
    u = _run_pid(pid, np.zeros_like(y), y)
    e = -y
    _, u_tf = ct.forced_response(gains.discrete_tf(DT), T=np.arange(y.size) * DT, U=e)
    # reset(y0 = 0) makes the first derivative sample -(y0 - 0); the transfer function assumes e_{-1} = 0 too
    assert np.allclose(u, u_tf, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("y_rate, u_rate", [(0.0, 0.0), (0.4, 0.0), (-0.3, 0.05)])
def test_discrete_pid_restarts_bumpless_in_value_and_rate(y_rate: float, u_rate: float) -> None:
    """reset(u0, y0, r0, y_rate, u_rate): the first output is u0 and the second u0 + u_rate dt while the measurement
    moves on at y_rate, with a tracking error at the start (where the start with the derivative at rest steps the
    output's rate); afterwards it is the same PID: its outputs' differences follow its transfer function."""
    gains = design_filtered_pid(SEED).gains
    u0, y0, r0 = 0.2, 0.05, 0.12
    pid = DiscretePid(gains, DT, -1e9, 1e9, 1e9)
    pid.reset(u0=u0, y0=y0, r0=r0, y_rate=y_rate, u_rate=u_rate)
    y = y0 + y_rate * DT * np.arange(200) + 0.01 * np.sin(np.arange(200) * DT * 12.0)
    u = _run_pid(pid, np.full_like(y, r0), y)
    assert u[0] == pytest.approx(u0, abs=1e-12)
    # the sinusoid's own contribution to the second output is kp and kd/(tf+dt) times its first step
    drift = (gains.kp + gains.kd / (gains.tf + DT)) * (y[1] - y0 - y_rate * DT)
    assert u[1] - u[0] == pytest.approx(u_rate * DT - drift, abs=1e-12)
    # the same controller from there on: a change of the measurement after the start changes the output as C(z) does
    delta = np.concatenate([[0.0], np.random.default_rng(5).normal(0.0, 0.01, y.size - 1)])
    other = DiscretePid(gains, DT, -1e9, 1e9, 1e9)
    other.reset(u0=u0, y0=y0, r0=r0, y_rate=y_rate, u_rate=u_rate)
    changed = _run_pid(other, np.full_like(y, r0), y + delta)
    _, response = ct.forced_response(gains.discrete_tf(DT), T=np.arange(y.size) * DT, U=-delta)
    assert np.allclose(changed - u, response, rtol=1e-9, atol=1e-12)


def test_discrete_loop_on_the_sampled_plant_settles() -> None:
    """DiscretePid, the smoother and the measurement filter in closed loop with the exact sampled plant (ZOH input,
    theta1 measured before each new command), stepped by hand: it settles to the reference; its poles are those of
    the design's check."""
    design = design_filtered_pid(SEED, PLACED, dt=DT)
    assert np.allclose(
        np.sort_complex(ct.poles(ct.feedback(delayed_loop(design.gains, SEED, DT, loop_chain(PLACED, SEED, DT)), 1))),
        np.sort_complex(design.discrete_poles),
    )
    assert np.max(np.abs(design.discrete_poles)) < 1.0
    plant = ct.c2d(ct.tf2ss(SEED.plant()), DT, "zoh")
    a, b, c = np.asarray(plant.A), np.asarray(plant.B)[:, 0], np.asarray(plant.C)[0]
    d = SEED.b2 / SEED.l1
    pid = DiscretePid(design.gains, DT, -10.0, 10.0, 100.0)
    pid.reset(u0=0.0, y0=0.0, r0=0.0)
    smoother = CriticallyDampedSmoother(PLACED.smoothing_bandwidth, DT)
    measured = SampledFilter(*design.measurement)
    measured.reset(0.0)
    x, u, r = np.zeros(a.shape[0]), 0.0, 0.1  # rad step
    y_hist = []
    k = int(2.0 * math.log(1.0 / SETTLE_BAND) / design.decay_rate / DT)  # twice the 2 % time of the slowest pole
    for _ in range(2 * k):
        y = float(c @ x) + d * u  # measured before the new command: feed-through of the held one
        y_hist.append(y)
        u = smoother.step(pid.step(r, measured.step(y)))
        x = a @ x + b * u
    y_hist = np.array(y_hist)
    assert np.all(np.abs(y_hist[k:] - r) <= SETTLE_BAND * r)
    assert abs(y_hist[-1] - r) < SETTLE_BAND**2 * r


def test_discrete_pid_respects_limits_and_unwinds() -> None:
    """A reference beyond the output limit: the output stays within limits and rate, and the integrator does not
    wind up (the output leaves the limit as soon as the error changes sign)."""
    gains = design_filtered_pid(SEED).gains
    pid = DiscretePid(gains, DT, 0.0, 0.3, 1.0)
    pid.reset(u0=0.0, y0=0.0, r0=0.0)
    u_prev, outs = 0.0, []
    y = 0.0
    for k in range(400):
        r = 1.0 if k < 200 else 0.1  # unreachable, then reachable
        u = pid.step(r, y)
        assert 0.0 <= u <= 0.3
        assert abs(u - u_prev) <= 1.0 * DT + 1e-12
        u_prev = u
        y += 0.2 * (u - y)  # a stable first-order stand-in: y follows u
        outs.append(u)
    outs = np.array(outs)
    assert outs[199] == pytest.approx(0.3)
    # without anti-windup, 2 s of error 0.7 rad * ki = 3.7/s would keep the output saturated for seconds
    assert outs[200 + int(0.5 / DT)] < 0.3


def test_bumpless_reset() -> None:
    pid = DiscretePid(design_filtered_pid(SEED).gains, DT, 0.0, 1.0, 2.0)
    pid.reset(u0=0.29, y0=0.31, r0=0.35)
    assert pid.step(0.35, 0.31) == pytest.approx(0.29, abs=1e-15)


def test_gains_validation() -> None:
    with pytest.raises(ControllerInputError, match=r"^pid\.tf: must be in \(0, 10\] s, got -0\.1$"):
        PidGains(1.0, 1.0, 0.1, -0.1)
    with pytest.raises(ControllerInputError, match=r"^pid\.damping: "):
        PidDesignSpec(damping=1.5)
    assert PidDesignSpec().damping is None  # searched


def test_placement_on_a_damped_plant_is_exact() -> None:
    """An identified plant carries a damping ratio; the placement's linear solve includes Gp's first-order term."""
    damped = SloshModel(SEED.l1, SEED.hinge_height, 0.05)
    target = PLACED.target_poles(damped.omega1, 0.7, 1.0)
    gains = place_filtered_pid(damped, target)
    poles = ct.poles(ct.feedback(gains.transfer_function() * damped.plant(), 1))
    assert np.allclose(np.sort_complex(poles), np.sort_complex(target), rtol=1e-6)


def test_measurement_filter_sits_between_the_slosh_mode_and_the_noise_band() -> None:
    """The cut-off is sqrt(omega1 w_n); the bilinear transform prewarped there keeps the Butterworth's -3 dB point
    and bends lower frequencies lower and higher ones higher, so the sampled filter passes omega1 at least as well
    as M(s) does and stops w_n at least as well: within 1 - (omega1 / wc)^4 / 2 at omega1, at most
    (wc / w_n)^2 = omega1 / w_n at w_n and above (at 30-50 Hz, -24 dB and less; 0 at the Nyquist frequency)."""
    spec = PidDesignSpec()
    wc = measurement_cutoff(spec, SEED)
    assert wc == pytest.approx(math.sqrt(SEED.omega1 * spec.noise_frequency), rel=1e-12)
    m = measurement_filter(spec, SEED, DT)
    gain = lambda w: float(abs(m(np.exp(1j * w * DT))))  # noqa: E731
    assert ct.dcgain(m) == pytest.approx(1.0, abs=1e-12)
    assert gain(wc) == pytest.approx(1.0 / math.sqrt(2.0), rel=1e-9)
    assert gain(SEED.omega1) >= 1.0 - 0.5 * (SEED.omega1 / wc) ** 4
    for w in np.linspace(spec.noise_frequency, math.pi / DT * (1 - 1e-9), 50):
        assert gain(w) <= SEED.omega1 / spec.noise_frequency
    assert gain(math.pi / DT * (1 - 1e-6)) < 1e-9


def test_the_designs_margins_include_the_measurement_filter() -> None:
    """The margins the design reports are python-control's of C A Gz M, the filter's phase lag included; the same
    gains read theta1 unfiltered have other margins (the filter is part of the loop the gains were chosen on)."""
    spec = PidDesignSpec()
    design = design_filtered_pid(SEED, spec, DT)
    forward = design.gains.discrete_tf(DT) * sampled_plant(SEED, DT) * ct.tf(*actuator(spec, DT), DT)
    gms, pms, *_ = ct.stability_margins(forward * measurement_filter(spec, SEED, DT), returnall=True)
    assert design.gain_margin == pytest.approx(min(abs(20 * math.log10(g)) for g in np.atleast_1d(gms)), abs=1e-6)
    assert design.phase_margin == pytest.approx(min(abs(p) for p in np.atleast_1d(pms)), abs=1e-6)
    assert design.gain_margin >= MIN_GAIN_MARGIN_DB and design.phase_margin >= MIN_PHASE_MARGIN_DEG
    unfiltered = delayed_loop_figures(design.gains, SEED, DT, actuator(spec, DT))
    assert abs(unfiltered[2] - design.phase_margin) > 1.0


def test_the_filter_stops_the_noise_band_on_its_way_to_the_tilt() -> None:
    """theta1's content at 30-50 Hz reaches the tilt command through C F (the PID's derivative and the smoother);
    read through the filter, at least 20 times less of it does at every frequency of the band."""
    spec, plain = PidDesignSpec(), PidDesignSpec(noise_frequency=None)
    filtered, unfiltered = design_filtered_pid(SEED, spec, DT), design_filtered_pid(SEED, plain, DT)
    assert unfiltered.measurement == ([1.0], [1.0]) and math.isnan(unfiltered.measurement_cutoff)

    def to_tilt(design, s):
        chain = design.gains.discrete_tf(DT) * ct.tf(*actuator(s, DT), DT) * ct.tf(*design.measurement, DT)
        return lambda f: float(abs(chain(np.exp(2j * math.pi * f * DT))))

    with_filter, without = to_tilt(filtered, spec), to_tilt(unfiltered, plain)
    for f in np.linspace(spec.noise_frequency / (2 * math.pi), 0.5 / DT - 1e-6, 21):
        assert with_filter(f) <= without(f) / 20.0


@pytest.mark.parametrize("value, pattern", [(5.0, r"^pid\.noise_frequency: .*20"), (-1.0, r"^pid\.noise_frequency")])
def test_noise_frequency_out_of_range_is_one_line(value: float, pattern: str) -> None:
    with pytest.raises(ControllerInputError, match=pattern) as info:
        PidDesignSpec(noise_frequency=value)
    assert "\n" not in str(info.value)


def test_noise_band_at_or_below_the_slosh_mode_is_refused() -> None:
    """A 5 cm cup's first mode (24.7 rad/s) lies above a noise band said to start at 21 rad/s: no filter between."""
    small = potential_flow_model(0.05, 0.04)
    with pytest.raises(ControllerInputError, match=r"^pid\.noise_frequency: must be above the slosh frequency"):
        measurement_cutoff(PidDesignSpec(noise_frequency=21.0), small)
