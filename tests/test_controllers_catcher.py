"""The catcher: landing point from the free-fall parabola (Camporredondo et al. 2019, Eqs. 6-7) and
rate-limited following; the motion helpers it shares with the controller."""

import math

import control as ct
import numpy as np
import pytest

from controllers.catcher import CatcherFollower, fall_time, jet_path, landing_x, weir_velocity
from controllers.motion import CriticallyDampedSmoother, JerkLimitedMove, RateLimitedTracker, fitted_delay, stop_time
from controllers.slosh import GRAVITY

EXACT = 1e-12  # m: closed-form identities in float64
# Symplectic-Euler integration of the free fall with step 1e-6 s over < 0.3 s: position error < g h t = 3e-6 m.
BALLISTIC_TOL = 1e-5  # m
DT = 0.01  # s, control period


def _integrate_fall(x0: float, z0: float, vx: float, vz: float, rim: float, h: float = 1e-6) -> float:
    x, z, w = x0, z0, vz
    while True:
        w -= GRAVITY * h
        x_new, z_new = x + vx * h, z + w * h
        if z_new <= rim:
            return x + (x_new - x) * (z - rim) / (z - z_new)
        x, z = x_new, z_new


@pytest.mark.parametrize("vx, vz", [(0.125, 0.0), (0.3, 0.0), (0.2, -0.15), (0.2, 0.1)])
def test_landing_point_is_on_the_parabola(vx: float, vz: float) -> None:
    lip_x, lip_z, rim = 0.16, 0.45, 0.20
    x = landing_x(lip_x, lip_z, rim, vx, vz)
    t = (x - lip_x) / vx
    assert lip_z + vz * t - 0.5 * GRAVITY * t * t == pytest.approx(rim, abs=EXACT)  # Eq. 6 at the rim
    assert x == pytest.approx(_integrate_fall(lip_x, lip_z, vx, vz, rim), abs=BALLISTIC_TOL)
    if vz == 0.0:
        assert t == pytest.approx(math.sqrt(2 * (lip_z - rim) / GRAVITY), abs=EXACT)  # the paper's form


def test_jet_path_runs_from_the_lip_down_the_parabola_to_the_landing_point() -> None:
    lip_x, lip_z, rim, vx, vz = 0.16, 0.45, 0.20, 0.2, 0.1
    x, z = jet_path(lip_x, lip_z, vx, vz, lip_z - rim, samples=20)
    assert x.shape == z.shape == (20,)
    assert (x[0], z[0]) == (lip_x, lip_z)
    assert x[-1] == pytest.approx(landing_x(lip_x, lip_z, rim, vx, vz), abs=EXACT)
    assert z[-1] == pytest.approx(rim, abs=EXACT)
    t = (x - lip_x) / vx
    np.testing.assert_allclose(z, lip_z + vz * t - 0.5 * GRAVITY * t * t, atol=EXACT)  # Eq. 6 at every point


def test_weir_velocity_and_degenerate_cases() -> None:
    assert weir_velocity(0.005, 0.6) == pytest.approx(2 / 3 * 0.6 * math.sqrt(2 * GRAVITY * 0.005), abs=EXACT)
    assert weir_velocity(-0.002, 0.6) == 0.0
    assert fall_time(-0.01) == 0.0  # lip below the rim: no fall


def test_tracker_respects_rate_and_acceleration_and_arrives() -> None:
    tr = RateLimitedTracker(max_rate=0.2, max_accel=0.5, dt=DT)
    pos, vel = [tr.position], [0.0]
    target = 0.15
    for k in range(400):
        tr.step(target if k < 300 else -0.05)
        pos.append(tr.position)
        vel.append(tr.velocity)
    v = np.diff(pos) / DT
    assert np.max(np.abs(v)) <= 0.2 + 1e-12
    assert np.max(np.abs(np.diff(vel))) <= 0.5 * DT + 1e-12
    assert pos[300] == pytest.approx(target, abs=1e-9)
    assert np.max(pos) <= target + 0.5 * DT * DT + 1e-12  # no overshoot beyond one step of acceleration
    assert stop_time(0.15, 0.2, 0.5) == pytest.approx(0.15 / 0.2 + 0.2 / (2 * 0.5))


def test_jerk_limited_move_keeps_its_limits_and_stops_on_the_target() -> None:
    """From 1.5 rad moving on at 0.05 rad/s, to rest at 0: within rate, acceleration and jerk (sampled finely),
    continuous in acceleration from the start (which is at zero acceleration), at rest on the target at its end."""
    move = JerkLimitedMove(1.5, 0.05, 0.0, max_rate=1.0, max_accel=1.5, max_jerk=10.0)
    h = 1e-3
    t = np.arange(0.0, move.duration + 0.2, h)
    p = np.array([move.at(x) for x in t])
    v, a, j = np.diff(p) / h, np.diff(p, 2) / h**2, np.diff(p, 3) / h**3
    assert p[0] == 1.5 and p[-1] == 0.0 and move.at(move.duration) == 0.0
    assert v[0] == pytest.approx(0.05, abs=1e-4) and abs(a[0]) <= 10.0 * h * (1 + 1e-3)
    assert np.max(np.abs(v)) <= 1.0 + 1e-6
    assert np.max(np.abs(a)) <= 1.5 + 1e-3
    assert np.max(np.abs(j)) <= 10.0 * (1 + 1e-3)
    assert np.min(p) >= -1e-9  # no overshoot
    # a stop within the acceleration limit and a 10 rad/s^3 ramp takes longer than without the ramp
    assert move.duration > stop_time(1.5, 1.0, 1.5)
    # a gentler stop: the acceleration that slows the move (here upward, the move going down) within stop_accel
    gentle = JerkLimitedMove(1.5, 0.05, 0.0, max_rate=1.0, max_accel=1.5, max_jerk=10.0, stop_accel=0.5)
    a = np.diff([gentle.at(x) for x in np.arange(0.0, gentle.duration + 0.2, h)], 2) / h**2
    assert np.min(a) == pytest.approx(-1.5, abs=1e-3) and np.max(a) == pytest.approx(0.5, abs=1e-3)
    up = JerkLimitedMove(-1.0, 0.0, 0.0, max_rate=1.0, max_accel=1.5, max_jerk=10.0, stop_accel=0.5)
    a = np.diff([up.at(x) for x in np.arange(0.0, up.duration + 0.2, h)], 2) / h**2
    assert np.max(a) == pytest.approx(1.5, abs=1e-3) and np.min(a) == pytest.approx(-0.5, abs=1e-3)


def test_follower_clips_travel_and_never_steps() -> None:
    f = CatcherFollower(home_x=0.30, travel=(-0.10, 0.05), max_speed=0.2, max_accel=0.5, dt=DT)
    xs = [f.step(0.10) for _ in range(300)]  # landing 0.2 m behind home: clipped to -0.10
    assert xs[-1] == pytest.approx(-0.10, abs=1e-9)
    assert np.max(np.abs(np.diff([0.0] + xs))) <= 0.2 * DT + 1e-12
    held = f.step(None)  # no prediction: keep going to the last target
    assert held == pytest.approx(-0.10, abs=1e-9)


def test_target_filter_keeps_vessel_b_calm_under_a_jittering_prediction() -> None:
    """A prediction jittering by +-20 mm about 0.35 m: the filtered catcher arrives under its mean and swings far
    less than one chasing every step (which also ends off the mean: the tracker's braking is not symmetric)."""
    def swing(filter_time: float) -> tuple[float, float]:
        f = CatcherFollower(home_x=0.30, travel=(-0.1, 0.1), max_speed=0.4, max_accel=1.0, dt=DT, filter_time=filter_time)
        xs = [f.step(0.35 + 0.02 * (-1) ** k) for k in range(int(3.0 / DT))]
        late = np.array(xs[int(2.0 / DT):])
        return float(np.mean(late)), float(np.ptp(late))

    raw_mean, raw_swing = swing(0.0)
    mean, calm_swing = swing(0.2)
    assert mean == pytest.approx(0.05, abs=0.002)
    assert abs(raw_mean - 0.05) > abs(mean - 0.05)
    assert calm_swing < 0.25 * raw_swing


def test_fitted_delay_of_a_delayed_ramp_and_of_a_still_command() -> None:
    t = np.arange(0.0, 0.5, 0.01)
    command = np.where(t < 0.1, 0.0, 0.3 * (t - 0.1))  # rad: still, then a 0.3 rad/s ramp
    response = np.interp(t - 0.08, t, command)
    assert fitted_delay(t, command, response, 0.3, 0.005) == pytest.approx(0.08, abs=1e-9)
    assert fitted_delay(t, np.full_like(t, 0.2), np.full_like(t, 0.2), 0.3, 0.005) == 0.0


def test_smoother_is_its_transfer_function() -> None:
    """CriticallyDampedSmoother's output equals the response of its stated F(z) = a^2 z^2 / (z - (1 - a))^2, and it
    follows a step to within 1e-6 after 20 / bandwidth."""
    dt, bandwidth = 0.01, 60.0
    smoother = CriticallyDampedSmoother(bandwidth, dt)
    rng = np.random.default_rng(3)
    x = rng.normal(0.0, 0.01, 200)
    y = np.array([smoother.step(v) for v in x])
    num, den = smoother.transfer_function_coefficients()
    _, y_tf = ct.forced_response(ct.tf(num, den, dt), T=np.arange(x.size) * dt, U=x)
    assert np.allclose(y, y_tf, rtol=1e-9, atol=1e-15)
    smoother.reset(0.0)
    steps = [smoother.step(1.0) for _ in range(int(20.0 / bandwidth / dt) + 1)]
    assert abs(steps[-1] - 1.0) < 1e-6
