"""The host-time split (cosim.bench.host_split): every part timed inside the steps, the originals put back, bad
input refused."""

import dataclasses
import math

import mujoco

from cosim.bench import host_split
from cosim.coupling import loop
from cosim.coupling.pose_filter import PoseFilter


def test_the_parts_are_timed_within_the_steps_and_put_back():
    scene = host_split.default_scene(1)
    scene = dataclasses.replace(scene, fluid=dataclasses.replace(scene.fluid, particles_across=12))
    original_step, original_poses, original_filter = mujoco.mj_step, loop.vessel_poses, PoseFilter.__call__
    calls, steps, wall, substeps = host_split.split_pour(scene, 0.02)
    assert steps == 10
    assert mujoco.mj_step is original_step and loop.vessel_poses is original_poses
    assert PoseFilter.__call__ is original_filter
    assert len(calls[host_split.ADVANCE]) == 10 and len(calls["trajectory generators' step"]) == 20  # two arms
    assert len(calls["mj_step (the live arms and the load monitor's twin)"]) == 20  # the live arms and the twin
    assert len(calls["controller, every control period (measurement, IK, filters, generator targets)"]) == 2  # every 10 ms
    inside = {label.removeprefix(host_split.CONTROLLER): len(times) for label, times in calls.items() if label.startswith(host_split.CONTROLLER)}
    assert inside == {"liquid probe's measurement (launches and read-backs)": 2, "control law": 2, "pose filters": 4,
                      "pose smoothers": 4, "IK": 4, "the arms' generators' targets": 4,
                      "landing probe (stream crossing the rim)": 2}  # per control period: once, or once per arm
    assert 0.0 < sum(calls[host_split.SUBSTEPS]) <= substeps < sum(calls[host_split.ADVANCE]) < wall


def test_bad_input_is_refused(capsys):
    assert host_split.main(["--duration", "0"]) == 2
    assert capsys.readouterr().err.strip() == "error: --duration: must be in (0, 60] s, got 0"
    assert host_split.main(["--threads", "-1"]) == 2


def test_the_calls_per_step_are_counted_the_same_on_a_second_pour():
    scene = host_split.default_scene(1)
    scene = dataclasses.replace(scene, fluid=dataclasses.replace(scene.fluid, particles_across=12))
    first, second = host_split.calls_per_step(scene, 0.02), host_split.calls_per_step(scene, 0.02)
    assert first == second  # a pour's Python work is deterministic, whatever the machine's load
    assert 300 < first < 5000  # the step loop's few hundred to thousand calls a step, the substeps' replay one


def test_the_host_work_median_pairs_each_interval_with_its_replay():
    calls = {host_split.ADVANCE: [3.0, 5.0, 4.0], host_split.SUBSTEPS: [1.0, 1.0, 3.0]}
    assert host_split.host_work_median(calls) == 2.0  # of 2, 4 and 1: not 4 - 1, the medians' difference
    calls[host_split.SUBSTEPS].pop()  # an interval run without a replay (the one before the capture)
    assert math.isnan(host_split.host_work_median(calls))
