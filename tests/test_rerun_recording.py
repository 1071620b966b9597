"""PourRecorder: the .rrd it writes verifies, reads back with the entities and values that were logged, rate-limits
and decimates the liquid as configured, and is written atomically."""

from __future__ import annotations

import subprocess
import sys

import mujoco
import numpy as np
import pytest
from matplotlib import colormaps

from cosim.errors import InputError
from cosim.io import rerun_paths
from cosim.io.recording import FLUSH_ROWS, SPEED_COLORMAP, PourRecorder, RecordingConfig
from cosim.io.rerun_read import entity_paths, read_component, read_scalar_series

# s: resolution of the sim_time timeline (integer nanoseconds) -> round-trip tolerance of a time stamp.
TIME_TOL = 1e-9

MJCF = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 0.1" rgba="0.8 0.8 0.8 1"/>
    <body name="arm" pos="0 0 0.5">
      <joint name="shoulder" type="hinge" axis="0 1 0"/>
      <geom name="link" type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
      <body name="cup" pos="0.3 0 0">
        <joint name="wrist" type="hinge" axis="0 1 0"/>
        <geom name="cup_floor" type="box" size="0.05 0.05 0.005"/>
        <geom type="cylinder" size="0.01 0.02" pos="0 0 0.03"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.fixture(scope="module")
def model() -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(MJCF)


def posed_data(model: mujoco.MjModel, shoulder: float, wrist: float) -> mujoco.MjData:
    data = mujoco.MjData(model)
    data.qpos[:] = [shoulder, wrist]
    mujoco.mj_forward(model, data)
    return data


def test_recording_verifies_and_has_the_expected_entities(model, tmp_path):
    path = tmp_path / "pour.rrd"
    data = posed_data(model, 0.2, -0.4)
    with PourRecorder(path, model, RecordingConfig()) as rec:
        rec.log_state(0.0, 0, data, np.zeros((10, 3)), np.zeros(10))
        rec.log_scalars(0.0, 0, {"pourer/theta": 0.1, "volume/in_pourer": 1e-3})
        rec.log_phase(0.0, 0, "SIM", "start")
    verify = subprocess.run([sys.executable, "-m", "rerun", "rrd", "verify", str(path)], capture_output=True, text=True)
    assert verify.returncode == 0, verify.stderr

    expected = {
        "/world",
        "/world/robot/world/floor",
        "/world/robot/arm",
        "/world/robot/arm/link",
        "/world/robot/cup",
        "/world/robot/cup/cup_floor",
        "/world/robot/cup/geom_3",  # unnamed geom: its index
        "/world/liquid",
        "/signals/pourer/theta",
        "/signals/volume/in_pourer",
        "/events/phase",
    }
    assert entity_paths(path) == expected
    # geometry is static; body poses are on both timelines
    assert read_component(path, "world/robot/cup/cup_floor", "Boxes3D:half_sizes").sim_time is None
    pose = read_component(path, "world/robot/cup", "Transform3D:translation")
    np.testing.assert_allclose(pose.values[0][0], data.xpos[model.body("cup").id], atol=1e-6)
    assert pose.step.tolist() == [0]
    text = read_component(path, rerun_paths.PHASE, "TextLog:text")
    assert text.values[0].tolist() == ["SIM: start"]


def test_scalar_series_read_back_equals_what_was_logged(model, tmp_path):
    path = tmp_path / "pour.rrd"
    rng = np.random.default_rng(1)
    n = 2 * FLUSH_ROWS + 37  # several column flushes plus a remainder sent at close
    dt = 0.002
    theta = rng.normal(size=n)
    late = rng.normal(size=n)
    with PourRecorder(path, model) as rec:
        for k in range(n):
            values = {"pourer/theta": theta[k]}
            if k >= 500:  # a signal that appears mid-run
                values["wrench/pourer/force z"] = late[k]
            rec.log_scalars(k * dt, k, values)
    series = read_scalar_series(path, "pourer/theta")
    np.testing.assert_array_equal(series.values, theta)
    np.testing.assert_array_equal(series.step, np.arange(n))
    np.testing.assert_allclose(series.sim_time, np.arange(n) * dt, rtol=0, atol=TIME_TOL)
    series = read_scalar_series(path, "wrench/pourer/force z")
    np.testing.assert_array_equal(series.values, late[500:])
    np.testing.assert_array_equal(series.step, np.arange(500, n))
    names = read_component(path, rerun_paths.signal_path("wrench/pourer/force z"), "SeriesLines:names")
    assert names.values[0].tolist() == ["pourer/force z"]


def test_state_is_rate_limited_in_sim_time(model, tmp_path):
    path = tmp_path / "pour.rrd"
    data = posed_data(model, 0.0, 0.0)
    dt, steps = 0.002, 500  # 1 s at 500 Hz
    logged = []
    with PourRecorder(path, model, RecordingConfig(particle_rate_hz=50.0)) as rec:
        for k in range(steps):
            due = rec.state_due(k * dt)
            did = rec.log_state(k * dt, k, data, np.zeros((4, 3)))
            assert due == did
            logged.append(did)
        assert rec.log_state((steps - 1) * dt, steps - 1, data, np.zeros((4, 3)), force=True)
    assert sum(logged) == 50
    points = read_component(path, "world/liquid", "Points3D:positions")
    expected = np.append(np.arange(50) * 0.02, (steps - 1) * dt)
    np.testing.assert_allclose(points.sim_time, expected, rtol=0, atol=TIME_TOL)
    np.testing.assert_array_equal(points.step, np.append(np.arange(50) * 10, steps - 1))
    poses = read_component(path, "world/robot/arm", "Transform3D:quaternion")
    np.testing.assert_allclose(poses.sim_time, expected, rtol=0, atol=TIME_TOL)


def test_particles_are_decimated_by_index_masked_and_coloured_by_speed(model, tmp_path):
    path = tmp_path / "pour.rrd"
    rng = np.random.default_rng(2)
    n, stride, vmax = 1000, 7, 1.5
    positions = rng.uniform(-0.2, 0.2, (n, 3))
    speeds = rng.uniform(0.0, 2.0 * vmax, n)  # half above the top of the colour map
    active = rng.uniform(size=n) > 0.3
    data = posed_data(model, 0.0, 0.0)
    with PourRecorder(path, model, RecordingConfig(particle_stride=stride, speed_color_max=vmax), particle_radius=0.004) as rec:
        rec.log_state(0.0, 0, data, positions, speeds, active=active)
        rec.log_state(0.1, 50, data, positions)  # no speeds, no mask
    rows = read_component(path, "world/liquid", "Points3D:positions")
    keep = np.arange(0, n, stride)
    keep = keep[active[keep]]
    np.testing.assert_array_equal(rows.values[0], positions[keep].astype(np.float32))
    np.testing.assert_array_equal(rows.values[1], positions[::stride].astype(np.float32))
    colors = read_component(path, "world/liquid", "Points3D:colors").values[0]
    rgba = colormaps[SPEED_COLORMAP](np.clip(speeds[keep] / vmax, 0.0, 1.0), bytes=True)
    packed = (rgba[:, 0].astype(np.uint32) << 24) | (rgba[:, 1].astype(np.uint32) << 16) | (rgba[:, 2].astype(np.uint32) << 8) | rgba[:, 3]
    np.testing.assert_array_equal(colors, packed)
    radii = read_component(path, "world/liquid", "Points3D:radii").values[0]
    np.testing.assert_allclose(radii, [0.004], rtol=1e-6)


def test_file_appears_only_at_close_and_an_exception_leaves_nothing(model, tmp_path):
    path = tmp_path / "pour.rrd"
    rec = PourRecorder(path, model)
    rec.log_scalars(0.0, 0, {"a": 1.0})
    assert not path.exists()
    assert rec.close() == path
    assert [p.name for p in tmp_path.iterdir()] == ["pour.rrd"]

    failed = tmp_path / "failed"
    failed.mkdir()
    with pytest.raises(ZeroDivisionError):
        with PourRecorder(failed / "pour.rrd", model) as rec:
            rec.log_scalars(0.0, 0, {"a": 1.0})
            1 / 0
    assert list(failed.iterdir()) == []
    with pytest.raises(RuntimeError, match="closed"):
        rec.log_scalars(0.1, 1, {"a": 2.0})


def test_recorders_in_one_process_do_not_mix(model, tmp_path):
    a, b = tmp_path / "a.rrd", tmp_path / "b.rrd"
    with PourRecorder(a, model) as rec_a, PourRecorder(b, model) as rec_b:
        for k in range(10):
            rec_a.log_scalars(k * 0.01, k, {"only_a": float(k)})
            rec_b.log_scalars(k * 0.01, k, {"only_b": float(-k)})
    assert "/signals/only_a" in entity_paths(a) and "/signals/only_b" not in entity_paths(a)
    assert "/signals/only_b" in entity_paths(b) and "/signals/only_a" not in entity_paths(b)
    np.testing.assert_array_equal(read_scalar_series(b, "only_b").values, -np.arange(10.0))


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"particle_stride": 0}, "recording.particle_stride"),
        ({"particle_stride": 1001}, "recording.particle_stride"),
        ({"particle_stride": 2.5}, "recording.particle_stride"),
        ({"particle_rate_hz": 0.0}, "recording.particle_rate_hz"),
        ({"particle_rate_hz": 1000.5}, "recording.particle_rate_hz"),
        ({"particle_rate_hz": float("nan")}, "recording.particle_rate_hz"),
        ({"speed_color_max": -1.0}, "recording.speed_color_max"),
        ({"speed_color_max": float("inf")}, "recording.speed_color_max"),
        ({"speed_color_max": "fast"}, "recording.speed_color_max"),
    ],
)
def test_bad_config_is_an_input_error_naming_the_field(kwargs, field):
    with pytest.raises(InputError, match=rf"^{field}: ") as err:
        RecordingConfig(**kwargs)
    assert "\n" not in str(err.value)


def test_bad_radius_or_folder_is_an_input_error(model, tmp_path):
    with pytest.raises(InputError, match=r"^recording.particle_radius: must be in \(0, 0.1\] m"):
        PourRecorder(tmp_path / "pour.rrd", model, particle_radius=0.0)
    with pytest.raises(InputError, match="does not exist"):
        PourRecorder(tmp_path / "missing" / "pour.rrd", model)
    assert list(tmp_path.iterdir()) == []
