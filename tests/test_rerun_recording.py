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
from cosim.io import recording
from cosim.io.recording import SPEED_COLORMAP, PourRecorder, RecordingConfig
from rerun.chunk import RrdReader
from cosim.frames import quat_wxyz_to_matrix
from cosim.io.rerun_read import entity_paths, read_component, read_scalar_series, recording_properties, series_names

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
        "/world",  # the floor plane is not drawn
        "/world/robot/arm",
        "/world/robot/arm/link",
        "/world/robot/cup",
        "/world/robot/cup/cup_floor",
        "/world/robot/cup/cylinder",  # unnamed geom: its type
        "/world/liquid",
        "/signals/pourer/theta",
        "/signals/volume/in_pourer",
        "/events/phase",
        "/legend",
    }
    assert entity_paths(path) == expected
    # geometry is static; body poses are on both timelines
    assert read_component(path, "world/robot/cup/cup_floor", "Boxes3D:half_sizes").sim_time is None
    pose = read_component(path, "world/robot/cup", "Transform3D:translation")
    np.testing.assert_allclose(pose.values[0][0], data.xpos[model.body("cup").id], atol=1e-6)
    assert pose.step.tolist() == [0]
    text = read_component(path, rerun_paths.PHASE, "TextLog:text")
    assert text.values[0].tolist() == ["SIM: start"]


def test_scalar_series_read_back_equals_what_was_logged(model, tmp_path, monkeypatch):
    monkeypatch.setattr(recording, "FLUSH_BYTES", 8 * 1000)  # a flush every 1000 rows of one float64
    path = tmp_path / "pour.rrd"
    rng = np.random.default_rng(1)
    n = 2 * 1000 + 37  # several column flushes plus a remainder sent at close
    dt = 0.002
    theta = rng.normal(size=n)
    late = rng.normal(size=(n, 3))
    with PourRecorder(path, model) as rec:
        for k in range(n):
            values = {"pourer/theta": theta[k]}
            if k >= 500:  # a signal with three series that appears mid-run
                values["wrench/pourer/force N"] = {"x": late[k, 0], "y": late[k, 1], "z": late[k, 2]}
            rec.log_scalars(k * dt, k, values)
    series = read_scalar_series(path, "pourer/theta")
    np.testing.assert_array_equal(series.values, theta)
    np.testing.assert_array_equal(series.step, np.arange(n))
    np.testing.assert_allclose(series.sim_time, np.arange(n) * dt, rtol=0, atol=TIME_TOL)
    assert series_names(path, "wrench/pourer/force N") == ["x", "y", "z"]
    for j, axis in enumerate("xyz"):
        series = read_scalar_series(path, "wrench/pourer/force N", axis)
        np.testing.assert_array_equal(series.values, late[500:, j])
        np.testing.assert_array_equal(series.step, np.arange(500, n))
    assert "/signals/wrench/pourer/force_N" in entity_paths(path)  # the space cleaned away, no escapes
    chunks = [c for c in RrdReader(path).store().stream() if c.entity_path == "/signals/pourer/theta" and not c.is_static]
    assert [c.num_rows for c in chunks] == [1000, 1000, 37]


def test_a_signal_keeps_its_series(model, tmp_path):
    with pytest.raises(ValueError, match="series"):
        with PourRecorder(tmp_path / "pour.rrd", model) as rec:
            rec.log_scalars(0.0, 0, {"pour/volume_mL": {"in pourer": 1.0, "in catcher": 0.0}})
            rec.log_scalars(0.01, 1, {"pour/volume_mL": {"in pourer": 1.0}})
    assert list(tmp_path.iterdir()) == []


def test_everything_on_the_timelines_is_one_chunk_per_entity(model, tmp_path):
    path = tmp_path / "pour.rrd"
    data = posed_data(model, 0.1, 0.2)
    with PourRecorder(path, model, RecordingConfig(particle_rate_hz=100.0), frames=()) as rec:
        for k in range(300):
            t = 0.01 * k
            rec.log_state(t, k, data, np.zeros((20, 3)) + k, np.ones(20))
            rec.log_scalars(t, k, {"pour/tilt_deg": {"commanded": k, "measured": k}})
            rec.log_arrows(t, k, "liquid_force", np.zeros((2, 3)), np.ones((2, 3)), ["a", "b"])
            rec.log_points(t, k, "landing/measured", np.zeros((k % 2, 3)), 0.01, (255, 0, 0, 255), "measured")
            rec.log_text(t, k, f"line {k}")
    temporal = [c for c in RrdReader(path).store().stream() if not c.is_static]
    per_entity = {}
    for c in temporal:
        per_entity[c.entity_path] = per_entity.get(c.entity_path, 0) + 1
    assert set(per_entity.values()) == {1}, per_entity
    assert {"/world/liquid", "/world/robot/arm", "/world/liquid_force", "/world/landing/measured", "/events/phase"} <= set(per_entity)
    landing = read_component(path, "world/landing/measured", "Points3D:positions")
    assert [len(v) for v in landing.values[:4]] == [0, 1, 0, 1]  # no point where nothing was measured
    assert read_component(path, "world/liquid_force", "Arrows3D:labels").values[7].tolist() == ["a", "b"]


def test_tool_frames_are_drawn_where_mujoco_has_the_sites(tmp_path):
    model = mujoco.MjModel.from_xml_string(MJCF.replace("<geom name=\"cup_floor\"", "<site name=\"tool/tcp\" pos=\"0.1 0 0.02\" euler=\"0 0.5 0\"/><geom name=\"cup_floor\""))
    data = posed_data(model, 0.3, -0.6)
    path = tmp_path / "pour.rrd"
    with PourRecorder(path, model, frames=["tool/tcp"]) as rec:
        rec.log_state(0.0, 0, data)
    pose = read_component(path, "world/frames/tool/tcp", "Transform3D:translation")
    np.testing.assert_allclose(pose.values[0][0], data.site_xpos[0], atol=1e-6)
    xyzw = read_component(path, "world/frames/tool/tcp", "Transform3D:quaternion").values[0][0]
    np.testing.assert_allclose(quat_wxyz_to_matrix(np.asarray(xyzw, float)[[3, 0, 1, 2]]), data.site_xmat[0].reshape(3, 3), atol=2e-6)
    assert read_component(path, "world/frames/tool/tcp", "TransformAxes3D:axis_length").values[0].tolist() == [pytest.approx(0.08)]


def test_each_state_keeps_the_poses_it_was_logged_with(tmp_path):
    """A simulation updates one MjData in place: every logged row holds the poses of its own step, not the last."""
    model = mujoco.MjModel.from_xml_string(MJCF.replace("<geom name=\"cup_floor\"", "<site name=\"tool/tcp\" pos=\"0.1 0 0.02\"/><geom name=\"cup_floor\""))
    data = mujoco.MjData(model)
    path = tmp_path / "pour.rrd"
    cups, tools = [], []
    with PourRecorder(path, model, RecordingConfig(particle_rate_hz=10.0), frames=["tool/tcp"]) as rec:
        for k in range(4):
            data.qpos[:] = [0.3 * k, -0.2 * k]
            mujoco.mj_kinematics(model, data)
            assert rec.log_state(0.1 * k, k, data)
            cups.append(data.xpos[model.body("cup").id].copy())
            tools.append(data.site_xpos[0].copy())
    assert np.ptp(np.array(cups), axis=0).max() > 0.1  # the poses differ from row to row
    for entity, expected in (("world/robot/cup", cups), ("world/frames/tool/tcp", tools)):
        logged = np.concatenate(read_component(path, entity, "Transform3D:translation").values)
        np.testing.assert_allclose(logged, np.array(expected), atol=1e-6)


def test_name_and_properties_travel_with_the_recording(model, tmp_path):
    path = tmp_path / "pour.rrd"
    with PourRecorder(path, model, name="my-run", properties={"scene_toml": "[fluid]\ndim = 3\n", "particles": 12}):
        pass
    assert recording_properties(path) == {"scene_toml": "[fluid]\ndim = 3\n", "particles": 12}
    names = [c.to_record_batch().column("RecordingInfo:name").to_pylist()[-1][0] for c in RrdReader(path).store().stream()
             if "RecordingInfo:name" in c.to_record_batch().schema.names]
    assert names == ["my-run"]


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
