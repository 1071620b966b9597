"""`cosim scene --check` runs the checks `cosim pour` runs before simulating (cosim.pour_checks.check_pour): the
two refuse the same scenes with the same line and exit status 2, and write nothing (bad fills, vessels, placements,
out-of-reach poses, memory); the estimate gates long runs."""

from __future__ import annotations

import json
import time

import pytest

import cosim.fluid.memory
from cosim.fluid.config import KernelType
from cosim.fluid.wall_sampling import one_layer_depth
from cosim.cli.main import main
from cosim.pour_checks import LONG_RUN_S, SECONDS_PER_PARTICLE_STEP, check_pour, estimate_wall_time
from cosim.pour_scene import PourScene
from tests.support.cli_refusal import refusal

REFUSED = {
    "fill above the rim": ("[liquid]\nfill_depth = 0.5\n", "liquid.fill_depth: must be in (0, 0.191) m (below the pourer's rim)"),
    "3-D needing hundreds of GB": ("[fluid]\ndim = 3\nparticles_across = 400\n", "need at least 285.3 GB, more than the 64.0 GB"),
    "negative size": ("[liquid]\nfill_depth = -0.1\n", "liquid.fill_depth: must be in (0, 2] m, got -0.1"),
    "unknown key": ("[fluid]\nparticles_acros = 32\n", "scene.fluid.particles_acros: unknown key"),
    "joint limit of no arm": ("[trajectory.limits.'left_arm/elbow']\nmax_velocity = 1.0\n", "trajectory.limits.left_arm/elbow"),
    "3-D estimated over an hour": ("[fluid]\ndim = 3\n", "pass --yes, or make it cheaper"),
    "fill above a smaller pourer's rim": ("[vessels.pourer]\ninner_height = 0.1\n[liquid]\nfill_depth = 0.12\n",
                                          "liquid.fill_depth: must be in (0, 0.1) m (below the pourer's rim), got 0.12"),
    "vessel too heavy for the arm": ("[vessels.pourer]\ninner_width = 0.4\ninner_depth = 0.3\ninner_height = 0.4\n"
                                     "[vessels.catcher]\ninner_width = 0.6\ninner_depth = 0.6\ninner_height = 0.3\n"
                                     "[liquid]\nfill_depth = 0.3\n", "vessels.pourer: 40.3 kg with its liquid and mount, more than the arm's rated payload of 12.5 kg"),
    "catcher smaller than the pour": ("[vessels.catcher]\ninner_width = 0.1\ninner_depth = 0.05\ninner_height = 0.05\n",
                                      "vessels.catcher: holds 0.25 L up to its rim, less than the 3.04 L the pour pours"),
    "wall thinner than 1 mm": ("[vessels.catcher]\nwall_thickness = 0.0005\n",
                               "vessels.catcher.wall_thickness: must be in [0.001, 0.05] m, got 0.0005"),
    "wall thicker than the cup is wide": ("[vessels.pourer]\nshape = 'cylinder'\ninner_width = 0.02\nwall_thickness = 0.03\n",
                                          "vessels.pourer.wall_thickness: must be in [0.001, 0.02) m, got 0.03"),
    "pourer tilt out of reach": ("[placement]\npourer_height = 1.0\n", "placement: the pourer tilted 86 deg about its bottom "
                                 "middle (controller.cfs.max_tilt 100 deg) is out of pour_arm's reach"),
    "catch arm folding into itself": ("[placement]\ncatcher_home_x = 0.45\n", "placement: the catcher moved +0.050 m from its "
                                      "home (controller.catcher.travel 0.15 m): geom 47 (catch_arm/upper_arm_link) touches "
                                      "geom 62 (catch_arm/wrist_2_link) (arm-arm"),
    "catcher below the table": ("[placement]\npour_height = 1.0\n",
                                "placement.pour_height: 1 m puts the catcher's bottom 474 mm below the table top"),
    "vessels touching at home": ("[placement]\npour_height = 0.15\n",
                                 "placement: the vessels at home: pourer/floor (pourer) touches catcher/back (catcher) (vessel-vessel"),
    "pourer tilting into the catcher": ("[placement]\npour_height = 0.30\n", "placement: the pourer tilted 100 deg about its "
                                        "bottom middle (controller.cfs.max_tilt 100 deg): pourer/front (pourer) touches catcher/back (catcher)"),
    "vessels with a scene file": ("[robots]\nscene = 'my_scene.xml'\n[vessels.pourer]\ninner_width = 0.1\n",
                                  "robots.scene: a scene file brings its own vessels and placement"),
    # taken from the scene file's folder, and named
    "a scene file that is not there": ("[robots]\nscene = 'my_scene.xml'\n", "robots.scene: scene "),
    "a trajectory of fewer than two samples": ("[trajectory]\nsample_rate_hz = 1e-9\n", "trajectory.sample_rate_hz: must give "
                                               "at least 2 samples over coupling.max_duration = 60 s (cosim pour --duration), >= 0.0166667 Hz, or a longer run; got 1e-09"),
}


@pytest.mark.parametrize("case", REFUSED)
def test_scene_check_and_pour_refuse_the_same_scene_with_the_same_line(case, tmp_path, capsys, monkeypatch):
    toml, expected = REFUSED[case]
    monkeypatch.chdir(tmp_path)  # a pour without --out would write under ./recordings
    monkeypatch.setattr(cosim.fluid.memory, "available_bytes", lambda device: 64_000_000_000)  # not the live, moving value
    (tmp_path / "scene.toml").write_text(toml)
    start = time.perf_counter()
    checked = refusal(capsys, ["scene", "--check", "scene.toml"], "scene")
    assert time.perf_counter() - start < 60.0  # seconds, not the minutes a fine 3-D liquid takes to seed
    poured = refusal(capsys, ["pour", "scene.toml", "--quiet"], "pour")
    assert checked == poured and expected in checked
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.toml"]  # nothing written


def test_yes_accepts_a_long_run_in_both_commands(tmp_path, capsys):
    scene = tmp_path / "scene.toml"
    scene.write_text("[fluid]\ndim = 3\n")
    assert main(["scene", "--check", str(scene), "--yes"]) == 0
    err = capsys.readouterr().err
    assert "liquid particles (3-D" in err and "estimated wall time at most" in err and " h (" in err


def test_the_estimate_is_particles_times_substeps_times_the_measured_cost():
    plan = check_pour(PourScene(), long_run_ok=False)
    assert plan.particles == 864  # 32 across x 27 layers: the default pour's count
    assert plan.substeps == round(PourScene().coupling.max_duration / plan.fluid.fixed_time_step)
    assert plan.wall_time == estimate_wall_time(plan.particles, plan.substeps) == pytest.approx(
        plan.particles * plan.substeps * SECONDS_PER_PARTICLE_STEP)
    assert plan.wall_time < LONG_RUN_S


def test_pour_prints_the_checks_particle_count_and_estimate_before_its_first_step(tmp_path, capsys):
    scene = tmp_path / "coarse.toml"
    scene.write_text("[fluid]\nparticles_across = 8\n[logging]\nenabled = false\n[coupling]\nmax_duration = 0.05\n")
    assert main(["scene", "--check", str(scene)]) == 0
    checked = capsys.readouterr().err.strip().splitlines()
    assert main(["pour", str(scene), "--out", str(tmp_path / "run")]) == 0
    poured = capsys.readouterr().err.strip().splitlines()
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert len(checked) == 2 and poured[:2] == checked
    # 8 across: the 5 mm wall holds no layer at dx / 2 = 11.9 mm; its one layer stands at one_layer_depth past the real lip
    depth = one_layer_depth(KernelType.WENDLAND_C2, 1.5, 2) * 0.191 / 8
    assert checked[1].startswith(f"walls: real_thickness, {depth * 1e3:.1f} mm of dummy layers for the pourer's 5.0 mm wall")
    assert summary["walls"]["pourer"] == {"wall_model": "real_thickness", "lip_outside_real_m": pytest.approx(depth - 0.005)}
    assert checked[0].startswith(f"{summary['particles']} liquid particles (2-D")  # exact for a box in 2-D


def test_a_relative_robots_scene_is_taken_from_the_scene_files_folder(tmp_path, monkeypatch):
    from cosim.pour_scene import load_scene

    (tmp_path / "cell").mkdir()
    (tmp_path / "cell" / "scene.toml").write_text("[robots]\nscene = 'my_scene.xml'\n")
    monkeypatch.chdir(tmp_path)
    assert load_scene("cell/scene.toml").robots.scene == str(tmp_path / "cell" / "my_scene.xml")
