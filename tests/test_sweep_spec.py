"""Sweep files: axes (lists, ranges, uniform draws), grid and sample expansion, refused keys and values; refused
cluster addresses; pour keys and the resources a pour asks Ray for. No Ray cluster is started and no pour runs."""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import pytest

from cosim.cli.main import main
from cosim.errors import InputError
from cosim.pour_scene import PourScene
from cosim.sweep.expand import axis_points, expand
from cosim.sweep.resources import PourResources, pour_resources, worker_scene
from cosim.sweep.spec import load_sweep, parse_sweep
from cosim.sweep.store import SweepStore, pour_key, scene_json


def _spec(table: dict):
    return parse_sweep(table, Path("."), "test")


def test_grid_is_every_combination_last_axis_fastest():
    spec = _spec({"axes": {"liquid.fill_depth": [0.08, 0.12], "fluid.particles_across": {"start": 16, "stop": 32, "num": 3}}})
    points = axis_points(spec)
    assert points == [{"liquid.fill_depth": f, "fluid.particles_across": n} for f in (0.08, 0.12) for n in (16, 24, 32)]
    assert all(isinstance(p["fluid.particles_across"], int) for p in points)


def test_range_of_floats_includes_both_ends():
    (axis,) = _spec({"axes": {"liquid.fill_depth": {"start": 0.08, "stop": 0.16, "num": 5}}}).axes
    assert axis.values == pytest.approx((0.08, 0.10, 0.12, 0.14, 0.16))


def test_uniform_grid_axis_draws_its_samples_from_the_seed():
    table = {"seed": 7, "axes": {"liquid.pour_fraction": {"uniform": [0.3, 0.9], "samples": 4}}}
    first, again = _spec(table).axes[0].values, _spec(table).axes[0].values
    other = _spec({**table, "seed": 8}).axes[0].values
    assert first == again and first != other and len(first) == 4
    assert all(0.3 <= v < 0.9 for v in first)


def test_sample_mode_draws_each_point_from_its_axes():
    table = {"mode": "sample", "samples": 20, "seed": 3,
             "axes": {"liquid.fill_depth": [0.08, 0.12], "liquid.pour_fraction": {"uniform": [0.3, 0.9]}}}
    points = axis_points(_spec(table))
    assert len(points) == 20 and points == axis_points(_spec(table))
    assert {p["liquid.fill_depth"] for p in points} == {0.08, 0.12}
    assert all(0.3 <= p["liquid.pour_fraction"] < 0.9 for p in points)


def test_a_refused_value_fails_its_pour_only():
    pours = expand(_spec({"axes": {"liquid.pour_fraction": [0.5, 1.5]}}))
    assert pours[0].scene is not None and pours[0].scene.liquid.pour_fraction == 0.5
    assert pours[1].scene is None and "liquid.pour_fraction: must be in (0, 1]" in pours[1].error


def test_axes_set_their_keys_on_the_base_scene_file(tmp_path):
    (tmp_path / "cell.toml").write_text("[coupling]\nmax_duration = 2.0\n")
    (tmp_path / "s.toml").write_text('scene = "cell.toml"\n[axes]\n"liquid.fill_depth" = [0.1]\n')
    (pour,) = expand(load_sweep(tmp_path / "s.toml"))
    assert pour.scene.coupling.max_duration == 2.0 and pour.scene.liquid.fill_depth == 0.1
    assert pour.scene.name == "cell"  # named as `cosim pour cell.toml` names it


@pytest.mark.parametrize("table, message", [
    ({"axes": {"liquid.fill_dept": [0.1]}}, "axes.liquid.fill_dept: 'fill_dept' is not a key of liquid"),
    ({"axes": {"liquid": [0.1]}}, "axes.liquid: a section of the scene, not a value"),
    ({"axes": {"device.x": ["cpu"]}}, "axes.device.x: device is a value, it has no keys"),
    ({"axes": {"liquid.fill_depth": []}}, "axes.liquid.fill_depth: an empty list"),
    ({"axes": {"liquid.fill_depth": {"start": 0.1, "stop": 0.2}}}, "axes.liquid.fill_depth: a table must be"),
    ({"axes": {"liquid.fill_depth": {"start": 0.1, "stop": 0.2, "num": 0}}}, "axes.liquid.fill_depth.num: must be in [1, 100000]"),
    ({"axes": {"liquid.fill_depth": {"uniform": [0.2, 0.1], "samples": 2}}}, "axes.liquid.fill_depth.uniform: lo must be below hi"),
    ({"axes": {"liquid.fill_depth": {"uniform": [0.1, 0.2]}}}, "axes.liquid.fill_depth.samples: a uniform axis in mode 'grid'"),
    ({"axes": {"liquid.fill_depth": {"uniform": [-1e308, 1e308], "samples": 2}}}, "axes.liquid.fill_depth.uniform: hi - lo must be a finite number"),
    ({"axes": {"liquid.fill_depth": {"start": -1e308, "stop": 1e308, "num": 3}}}, "axes.liquid.fill_depth: stop - start must be a finite number"),
    ({"mode": "sample", "axes": {"liquid.fill_depth": [0.1]}}, "samples: mode 'sample' needs the number of pours"),
    ({"mode": "grid", "samples": 3, "axes": {"liquid.fill_depth": [0.1]}}, "samples: only in mode 'sample'"),
    ({"mode": "random", "axes": {"liquid.fill_depth": [0.1]}}, "mode: must be one of 'grid', 'sample'"),
    ({"axes": {}}, "axes: needs at least one axis"),
    ({"axis": {}}, "axis: unknown key"),
    ({"scene": 3, "axes": {"liquid.fill_depth": [0.1]}}, "scene: must be a scene file's path or a [scene] table"),
])
def test_bad_sweep_files_are_refused_naming_the_key(table, message):
    with pytest.raises(InputError) as refused:
        _spec(table)
    assert str(refused.value).startswith(message)


def test_cli_refuses_a_bad_sweep_file_with_status_2(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text('[axes]\n"fluid.particles_acros" = [8]\n')
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--dry-run"]) == 2
    assert "axes.fluid.particles_acros: 'particles_acros' is not a key of fluid" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_cli_refuses_an_output_folder_that_is_not_a_sweep(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text('[axes]\n"liquid.fill_depth" = [0.1]\n')
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "notes.txt").write_text("mine")
    assert main(["sweep", str(path), "--out", str(tmp_path / "out")]) == 2
    assert "is not a sweep's output folder" in capsys.readouterr().err


@pytest.mark.parametrize("address", ["bogus", "ray:/host", "host:port"])
def test_cli_refuses_an_address_ray_cannot_join_and_writes_nothing(tmp_path, capsys, address):
    path = tmp_path / "s.toml"
    path.write_text('[axes]\n"liquid.fill_depth" = [0.1]\n')
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--address", address]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"cosim sweep: error: --address: must be 'auto', 'ray://HOST:PORT' or 'HOST:PORT', got {address!r}"]
    assert not (tmp_path / "out").exists()


def test_cli_without_the_cluster_it_names_writes_nothing(tmp_path, capsys, monkeypatch):
    # its manifest (sweep.json) is written once the cluster is joined
    monkeypatch.delenv("RAY_ADDRESS", raising=False)
    path = tmp_path / "s.toml"
    path.write_text('[axes]\n"liquid.fill_depth" = [0.1]\n')
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--address", "auto"]) == 2
    assert capsys.readouterr().err.startswith("cosim sweep: error: --address: no Ray cluster at auto (")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("address", ["127.0.0.1:1", "ray://127.0.0.1:1"])
def test_cli_refuses_an_address_where_nothing_listens_at_once(tmp_path, capsys, address):
    # Ray retries a head's address for minutes, logging each try; Ray Client waits 30 s
    path = tmp_path / "s.toml"
    path.write_text('[axes]\n"liquid.fill_depth" = [0.1]\n')
    start = time.perf_counter()
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--address", address]) == 2
    assert time.perf_counter() - start < 20.0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"cosim sweep: error: --address: no Ray cluster at {address} (nothing accepts"), err
    assert not (tmp_path / "out").exists()


def test_pour_key_follows_the_scene_and_the_code():
    scene = PourScene()
    other = replace(scene, liquid=replace(scene.liquid, fill_depth=0.1))
    assert pour_key(scene, "a") == pour_key(PourScene(), "a")
    assert len({pour_key(scene, "a"), pour_key(scene, "b"), pour_key(other, "a")}) == 3
    assert scene_json(scene) == scene_json(PourScene())


def test_a_pour_asks_for_its_threads_or_a_gpu():
    scene = PourScene()
    threads = replace(scene, fluid=replace(scene.fluid, cpu_threads=3))
    gpu = replace(scene, device="cuda:1")
    assert pour_resources(scene) == PourResources(cpus=1, gpus=0)  # 0 (one per core): one core per pour
    assert worker_scene(scene).fluid.cpu_threads == 1
    assert pour_resources(threads) == PourResources(cpus=3, gpus=0) and worker_scene(threads) == threads
    assert pour_resources(gpu) == PourResources(cpus=1, gpus=1) and worker_scene(gpu).device == "cuda"


def test_a_rerun_removes_only_the_partial_folders_of_the_pour_it_reruns(tmp_path):
    store = SweepStore(tmp_path)
    for name in (".k1.partial-abc", ".k2.partial-def", "k1"):
        (store.pours / name).mkdir(parents=True)
    store.remove_partial("k1")
    assert sorted(p.name for p in store.pours.iterdir()) == [".k2.partial-def", "k1"]
