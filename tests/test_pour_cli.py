"""`cosim pour` contract on a coarse, short pour: outputs, recording read-back, exported trajectory (independent
numerical differentiation, limits, replay), determinism, and bad input (one line, exit 2, nothing written)."""

import json
import subprocess
import sys

import mujoco
import numpy as np
import pytest

from controllers.config import CFS_MAX_HEAD
from cosim.cli.main import main
from cosim.frames import tilt_about_y
from cosim.io.pour_series import read_series_csv
from cosim.io.rerun_framing import VIEW_FILL
from cosim.io.rerun_read import (
    blueprint_camera, entity_paths, read_component, read_scalar_series, recording_properties, series_names,
)
from cosim.pour_scene import LiquidSettings, PourScene, load_scene
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.trajectory.csv_file import read_trajectory_csv
from cosim.trajectory.json_file import read_trajectory_json
from declared_settings.setting import declared
from tests.support.view_projection import image_coordinates

COARSE = """
name = "test-pour"
[fluid]
particles_across = 10
[coupling]
max_duration = {duration}
[logging.recording]
particle_rate_hz = 20.0
"""
# The coarsest liquid (8 particles across), without a recording: a pour's outputs in a few seconds.
TINY = "[fluid]\nparticles_across = 8\n[logging]\nenabled = false\n"
# Central differences of samples h = 1/500 s apart of a trajectory whose jerk is bounded by J (Taylor with integral
# remainder): positions -> velocity within J h^2 / 6 (the second-order terms cancel); velocities -> acceleration within
# J h / 2 (the remainders only cancel where the jerk does not change over [t - h, t + h]; ruckig switches it at every
# re-plan); plus float round-off of the CSV's 9 significant digits.
SAMPLE_SPACING = 1.0 / 500.0
ROUND_OFF = 1e-6
LIMIT_TOLERANCE = 1e-6  # relative slack on the limits (float round-off of the checks)
REPLAY_TOLERANCE_M = 0.002  # replay tracks the vessel path within 2 mm


def _pour(tmp_path, name, duration=0.6, extra=()):
    scene = tmp_path / f"{name}.toml"
    scene.write_text(COARSE.format(duration=duration))
    out = tmp_path / name
    assert main(["pour", str(scene), "--out", str(out), "--quiet", *extra]) == 0
    return out


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return _pour(tmp_path_factory.mktemp("pour"), "run", duration=0.8)


def test_outputs_and_summary(run):
    files = ["pour.rrd", "series.csv", "summary.json", "trajectory.csv", "trajectory.json", "trajectory.mcap"]
    assert sorted(p.name for p in run.iterdir()) == files
    summary = json.loads((run / "summary.json").read_text())
    assert sorted(summary["outputs"]) == files
    for key in ("initial_volume", "poured_volume", "spilled_volume", "phases", "sim_time", "wall_time", "real_time_factor", "device", "versions"):
        assert key in summary
    # a pour until empty has no target; what is left in the pourer is what the last measurement counted
    assert summary["target_volume"] is summary["target_error"] is summary["target_relative_error"] is None
    assert summary["volume_left_in_pourer"] == pytest.approx(summary["initial_volume"] - summary["poured_volume"], rel=1e-12)
    assert 0.0 < summary["volume_left_in_pourer"] <= summary["initial_volume"]
    assert summary["initial_volume"] > 0 and summary["sim_time"] == pytest.approx(0.8)
    # 2-D, 10 across: 3 spacings would be 57 mm, over the 0.05 m CFS accepts
    assert summary["cfs_head_reference"] == pytest.approx(CFS_MAX_HEAD) and CFS_MAX_HEAD < 3.0 * summary["particle_spacing"]
    assert [p["phase"] for p in summary["phases"]][0] == "idle"
    assert "landing" in summary
    assert type(summary["guard_corrections"]) is int and summary["guard_corrections"] >= 0  # the guard's count, reported
    series = read_series_csv(run / "series.csv")
    assert len(series["t"]) == round(0.8 / 0.01) and series["phase"][0] == "idle"
    assert series["volume_in_pourer"][0] == pytest.approx(summary["initial_volume"])


def test_recording_verifies_and_its_tilt_is_the_trajectorys(run):
    rrd = run / "pour.rrd"
    verify = subprocess.run([sys.executable, "-m", "rerun", "rrd", "verify", str(rrd)], capture_output=True, text=True)
    assert verify.returncode == 0, verify.stderr
    paths = entity_paths(rrd)
    assert "/world/liquid" in paths and "/signals/pour/tilt_deg" in paths and "/events/phase" in paths
    tilt = read_scalar_series(rrd, "pour/tilt_deg", "commanded")
    traj = read_trajectory_csv(run / "trajectory.csv")
    scene = RobotScene.load()
    arm = scene.arms[ArmRole.POUR]
    cols = [traj.joint_names.index(j) for j in arm.joints]
    data = mujoco.MjData(scene.model)
    checked = 0
    for t, logged in zip(tilt.sim_time, tilt.values):
        k = int(np.argmin(np.abs(traj.time - t)))
        if abs(traj.time[k] - t) > 1e-9:
            continue
        data.qpos[arm.qpos_adr] = traj.positions[k, cols]
        mujoco.mj_kinematics(scene.model, data)
        assert logged == pytest.approx(np.degrees(tilt_about_y(data.xmat[arm.vessel_body].reshape(3, 3))), abs=1e-7)
        checked += 1
    assert checked >= 0.9 * len(tilt.values) > 50


def test_recording_holds_what_a_robotics_user_reads(run):
    """Units in every plot's name, clean entity paths named after bodies and geoms, tool frames, the liquid's force,
    the run's name and scene as properties, and a camera framed between the vessels."""
    rrd = run / "pour.rrd"
    paths = entity_paths(rrd)
    assert not any("\\" in p or "geom_" in p for p in paths)
    for entity in ("/world/robot/pour_arm/wrist_3_link", "/world/robot/pourer/front", "/world/robot/catcher/floor",
                   "/world/scene/table", "/world/frames/pourer/frame", "/world/frames/catcher/frame",
                   "/world/liquid_force", "/world/lip_path/commanded", "/signals/pour_arm/joint_angle_deg",
                   "/signals/pourer/liquid_force_N", "/signals/catcher/liquid_torque_N_m", "/signals/pour/volume_mL"):
        assert entity in paths, entity
    assert not any(p.startswith("/world/scene/floor") for p in paths)  # the ground plane stays out of the bounds
    joints = series_names(rrd, "pour_arm/joint_angle_deg")
    assert joints == [j.split("/")[-1] for j in RobotScene.load().arms[ArmRole.POUR].joints]
    volume = read_scalar_series(rrd, "pour/volume_mL", "in pourer").values
    summary = json.loads((run / "summary.json").read_text())
    assert volume[0] == pytest.approx(1e6 * summary["initial_volume"])  # mL
    properties = recording_properties(rrd)
    assert properties["scene_name"] == "test-pour" and "particles_across = 10" in properties["scene_toml"]
    eye, target = blueprint_camera(rrd)
    frames = {v: np.concatenate(read_component(rrd, f"world/frames/{v}/frame", "Transform3D:translation").values)
              for v in ("pourer", "catcher")}
    lip_path = np.stack(read_component(rrd, "world/lip_path/commanded", "LineStrips3D:strips").values[0][0])
    assert frames["pourer"][:, 0].max() < eye[0] < frames["catcher"][:, 0].min()  # between the vessels
    assert frames["catcher"][:, 2].min() < target[2] < lip_path[:, 2].max()
    assert eye[1] > 0  # the pour arm stands at y < 0: seen from the other side, its links do not hide the pour
    for points in (*frames.values(), lip_path):  # the vessels and the lip, all the run long, in the view
        assert np.all(np.abs(image_coordinates(eye, target, points)) <= VIEW_FILL)


def test_exported_trajectory_differentiates_consistently_and_holds_every_limit(run):
    traj = read_trajectory_csv(run / "trajectory.csv")
    doc = json.loads((run / "trajectory.json").read_text())
    h = float(np.diff(traj.time).mean())
    assert h == pytest.approx(SAMPLE_SPACING)
    q, qd, qdd = traj.positions, traj.velocities, traj.accelerations
    qd_fd = (q[2:] - q[:-2]) / (2 * h)
    qdd_fd = (qd[2:] - qd[:-2]) / (2 * h)
    limits = {}
    for arm in doc["arms"].values():
        for k, name in enumerate(arm["scene_joint_names"]):
            limits[name] = {f: arm["limits"][f][k] for f in arm["limits"]}
    for j, name in enumerate(traj.joint_names):
        lim = limits[name]
        jerk = lim["max_jerk"]
        assert np.abs(qd_fd[:, j] - qd[1:-1, j]).max() <= jerk * h * h / 6 + ROUND_OFF
        assert np.abs(qdd_fd[:, j] - qdd[1:-1, j]).max() <= jerk * h / 2 + ROUND_OFF
        assert np.abs(qd[:, j]).max() <= lim["max_velocity"] * (1 + LIMIT_TOLERANCE)
        assert np.abs(qdd[:, j]).max() <= lim["max_acceleration"] * (1 + LIMIT_TOLERANCE)
        assert np.abs(np.diff(qdd[:, j]) / h).max() <= jerk * (1 + LIMIT_TOLERANCE)
        assert lim["min_position"] <= q[:, j].min() and q[:, j].max() <= lim["max_position"]
    assert read_trajectory_json(run / "trajectory.json") is not None


def test_replay_tracks_the_vessel_path(run, capsys):
    assert main(["replay", str(run / "trajectory.csv"), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["max_error_m"] <= REPLAY_TOLERANCE_M


def test_same_scene_twice_gives_byte_identical_trajectories(tmp_path):
    a = _pour(tmp_path, "a", 0.4, ("--no-log",))
    b = _pour(tmp_path, "b", 0.4, ("--no-log",))
    for name in ("trajectory.csv", "trajectory.json", "trajectory.mcap"):
        assert (a / name).read_bytes() == (b / name).read_bytes()
    assert not (a / "pour.rrd").exists()


@pytest.mark.parametrize(
    "toml, field",
    [
        ("[fluid]\nparticle_across = 10\n", "scene.fluid.particle_across"),
        ("[fluid]\nparticles_across = 'ten'\n", "scene.fluid.particles_across"),
        ("[liquid]\nfill_depth = -0.1\n", "liquid.fill_depth"),
        ("[liquid]\nfill_depth = 0.5\n", "liquid.fill_depth"),
        ("[liquid]\nfill_depth = nan\n", "liquid.fill_depth"),
        ("[controller.cfs]\nh_q_ref = 1.0\n", "cfs.h_q_ref"),
        ("[controller]\nstream_particles = 11.0\n", "controller.stream_particles"),
        ("[fluid]\nmax_tension = -1.0\n", "fluid.max_tension"),
        ("[fluid]\nfree_artificial_viscosity = 2.0\n", "fluid.free_artificial_viscosity"),
        ("device = 'tpu'\n", "scene.device"),
        ("name = 'my cell'\n", "scene.name"),
        ("[trajectory.joint_prefix]\npour_arm = 'ur-'\n", "trajectory.joint_prefix.pour_arm"),
        ("this is not toml", "not a valid TOML file"),
    ],
)
def test_bad_scene_is_one_line_exit_2_and_writes_nothing(tmp_path, capsys, toml, field):
    scene = tmp_path / "bad.toml"
    scene.write_text(toml)
    out = tmp_path / "out"
    assert main(["pour", str(scene), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0]
    assert not out.exists() and not list(tmp_path.glob(".out*"))


def test_unreadable_scene_file_and_busy_output_folder(tmp_path, capsys):
    assert main(["pour", str(tmp_path / "missing.toml"), "--quiet"]) == 2
    busy = tmp_path / "busy"
    busy.mkdir()
    (busy / "x").write_text("earlier run")
    assert main(["pour", "--out", str(busy), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "missing.toml" in err[0] and "busy" in err[1]
    assert (busy / "x").read_text() == "earlier run"


def test_a_recording_without_rerun_sdk_is_one_line_exit_2_and_writes_nothing(tmp_path, capsys, monkeypatch):
    # as on a machine without rerun-sdk: the pour with its recording is refused before anything runs,
    # the message saying how to run it without the recording (which needs no rerun-sdk)
    import cosim.pour_checks

    real = cosim.pour_checks.find_spec
    monkeypatch.setattr(cosim.pour_checks, "find_spec", lambda name: None if name == "rerun" else real(name))
    out = tmp_path / "out"
    assert main(["pour", "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "logging.enabled" in err[0] and "--no-log" in err[0]
    assert not out.exists() and not list(tmp_path.glob(".out*"))


def test_scene_dump_round_trips(tmp_path, capsys):
    assert main(["scene", "--dump"]) == 0
    text = capsys.readouterr().out
    assert "particles_across" in text and f"# {declared(LiquidSettings, 'fill_depth').meaning}" in text
    path = tmp_path / "scene.toml"
    path.write_text(text)
    assert main(["scene", "--check", str(path)]) == 0
    assert capsys.readouterr().out == text


def test_scene_check_refuses_a_numerical_setting_out_of_range(tmp_path, capsys):
    # the fluid's numerical settings are range-checked when the scene is read, not only when a pour builds the solver
    path = tmp_path / "scene.toml"
    path.write_text("[fluid]\ncfl = 0.9\n")
    assert main(["scene", "--check", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "fluid.cfl" in err[0]


@pytest.mark.parametrize("toml", ["[coupling]\nstart_delay = 0.3\n", "[logging.recording]\nparticle_stride = 2\n"])
def test_a_section_changes_only_its_own_keys_of_the_scene_default(tmp_path, toml):
    # a file that sets one key of a section keeps the scene's defaults for its others (coupling.max_duration 60 s,
    # recording.particle_rate_hz 30 Hz: the section classes' own, declared once)
    path = tmp_path / "scene.toml"
    path.write_text(toml)
    scene, default = load_scene(path), PourScene()
    assert scene.coupling.max_duration == default.coupling.max_duration == 60.0
    assert scene.logging.recording.particle_rate_hz == default.logging.recording.particle_rate_hz == 30.0
    assert scene != default


@pytest.mark.parametrize(
    "toml, dim, across, head_in_spacings",
    [
        ("", 2, 32, 3.0),  # the default scene: 3 dx = 17.9 mm, over the 5 mm of Camporredondo et al. (2019)
        ("[fluid]\ndim = 3\n", 3, 32, 3.0),  # 3-D: 3 spacings too, 17.9 mm
        ("[fluid]\ndim = 3\nparticles_across = 16\n[controller]\nstream_particles = 2.5\n", 3, 16, 2.5),
        ("[controller]\nstream_particles = 1.5\n", 2, 32, 1.5),
    ],
)
def test_cfs_head_floor_is_stream_particles_spacings_by_dimension_unless_set(tmp_path, toml, dim, across, head_in_spacings):
    from cosim.pour_run import cfs_head_reference

    path = tmp_path / "scene.toml"
    path.write_text(toml)
    scene = load_scene(path)
    spacing = 0.191 / across  # the default pourer's inner width over the particles across
    assert scene.fluid.dim == dim
    assert cfs_head_reference(scene, spacing) == pytest.approx(head_in_spacings * spacing, rel=1e-12)
    fine = 0.191 / 150  # a fine liquid (1.27 mm): the paper's h_q_ref (5 mm) is the larger
    assert cfs_head_reference(scene, fine) == scene.controller.cfs.h_q_ref == 0.005


def test_scene_dump_leaves_stream_particles_unset_so_that_changing_dim_keeps_its_default(capsys):
    assert main(["scene", "--dump"]) == 0
    assert "# stream_particles = (not set)" in capsys.readouterr().out


def test_run_folders_are_named_after_the_scene_file_unless_it_names_them(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "my_cell.toml").write_text(TINY)
    (tmp_path / "other cell.v2.toml").write_text(TINY)
    (tmp_path / "named.toml").write_text('name = "line-3"\n' + TINY)
    for scene in ("my_cell.toml", "other cell.v2.toml", "named.toml"):
        assert main(["pour", scene, "--quiet", "--duration", "0.02"]) == 0
    runs = sorted(p.name.split("-", 2)[2] for p in (tmp_path / "recordings").iterdir())
    assert runs == ["line-3", "my_cell", "other_cell_v2"]
    summary = json.loads(next((tmp_path / "recordings").glob("*-my_cell/summary.json")).read_text())
    assert summary["scene_name"] == "my_cell"
    assert PourScene().run_name == "seed-pour"  # the embedded default scene (no file) keeps its name


def _tiny_pour(tmp_path, name: str, head: str) -> dict:
    """summary.json of a 0.05 s pour of the coarsest liquid, without recording, of the scene ``head`` + :data:`TINY`."""
    scene = tmp_path / f"{name}.toml"
    scene.write_text(head + TINY)
    out = tmp_path / name
    assert main(["pour", str(scene), "--out", str(out), "--quiet", "--duration", "0.05"]) == 0
    return json.loads((out / "summary.json").read_text())


def test_a_partial_pour_reports_its_target_and_error(tmp_path):
    summary = _tiny_pour(tmp_path, "half", "[liquid]\npour_fraction = 0.5\n")
    target = 0.5 * summary["initial_volume"]
    assert summary["target_volume"] == pytest.approx(target, rel=1e-12)
    # 0.05 s is still before the pour starts: nothing poured, the whole target missed
    assert summary["poured_volume"] == 0.0 and summary["volume_left_in_pourer"] == summary["initial_volume"]
    assert summary["target_error"] == pytest.approx(-target, rel=1e-12)
    assert summary["target_relative_error"] == pytest.approx(-1.0, rel=1e-12)


def test_coarsest_resolution_pours_with_the_head_floor_capped_at_the_cfs_limit(tmp_path):
    # 8 across: 3 spacings of 23.9 mm would be a 72 mm head, over cfs.h_q_ref's 0.05 m limit (uncapped, the pour
    # would stop with an error about cfs.h_q_ref, a key the scene did not set)
    summary = _tiny_pour(tmp_path, "coarse", "")
    assert summary["cfs_head_reference"] == CFS_MAX_HEAD < 3.0 * summary["particle_spacing"]


def test_the_one_thread_share_prints_in_plain_percent():
    from cosim.cli.pour import _one_thread_note

    assert _one_thread_note({"fluid_substeps_one_thread": 0, "sph_steps": 100}) == ""
    assert _one_thread_note({"fluid_substeps_one_thread": 9962, "sph_steps": 10000}).startswith(", 99.6 % of the substeps")
    assert _one_thread_note({"fluid_substeps_one_thread": 10000, "sph_steps": 10000}).startswith(", 100 % of the substeps")
    assert _one_thread_note({"fluid_substeps_one_thread": 3, "sph_steps": 10000}).startswith(", 0.03 % of the substeps")
