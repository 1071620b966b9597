"""`cosim sweep` on a local Ray with two CPUs: four short pours, one of them refused by its worker (its fill above
the pourer's rim); the sweep finishes with that pour recorded, a rerun recomputes none of the finished pours, and each
pour's trajectory is byte-identical to `cosim pour` of the same scene; a worker killed mid-pour is recorded as lost."""

from __future__ import annotations

import csv
import json
import os
import signal
import threading
import time
from pathlib import Path

import pytest
import ray
import ray.exceptions

from cosim.cli.main import main
from cosim.pour_scene import PourScene, dump_scene
from cosim.sweep.expand import SweepPoint, expand
from cosim.sweep.plan import PlannedPour
from cosim.sweep.runner import CodeVersionMismatch, failure_record, pour_task
from cosim.sweep.spec import load_sweep

pytestmark = pytest.mark.slow  # starts a local Ray cluster and runs several pours
FILLS = (0.08, 0.10, 0.12, 0.5)  # m; the pourer is 0.191 m deep inside: 0.5 is refused when its pour is checked
BASE = """
[scene]
[scene.fluid]
particles_across = 8
[scene.coupling]
max_duration = 1.0
[scene.logging]
enabled = false
"""
SWEEP = BASE + f'[axes]\n"liquid.fill_depth" = {list(FILLS)}\n'


@pytest.fixture(scope="module")
def local_ray():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


@pytest.fixture(scope="module")
def sweep(local_ray, tmp_path_factory):
    """The sweep file, its output after a first run, and that run's exit status."""
    folder = tmp_path_factory.mktemp("sweep")
    path = folder / "fills.toml"
    path.write_text(SWEEP)
    out = folder / "out"
    status = main(["sweep", str(path), "--out", str(out), "--quiet"])
    return path, out, status


def _rows(out: Path) -> list[dict]:
    with open(out / "sweep.csv", newline="") as f:
        return list(csv.DictReader(f))


def _stats(out: Path) -> dict[str, tuple[int, int]]:
    return {str(p.relative_to(out)): (p.stat().st_ino, p.stat().st_mtime_ns) for p in (out / "pours").rglob("*")}


def test_the_sweep_finishes_with_the_failed_pour_recorded(sweep):
    _, out, status = sweep
    rows = _rows(out)
    assert status == 1  # a pour failed
    assert [float(r["liquid.fill_depth"]) for r in rows] == list(FILLS)
    assert [r["status"] for r in rows] == ["done", "done", "done", "failed"]
    assert rows[3]["failure"] == "bad input" and rows[3]["error"].startswith("liquid.fill_depth: must be in (0, 0.191) m")
    for row in rows[:3]:
        summary = json.loads((out / row["run_folder"] / "summary.json").read_text())
        assert float(row["poured_mL"]) == pytest.approx(summary["poured_volume"] * 1e6)
        assert float(row["wall_time_s"]) == summary["wall_time"] > 0
    assert len(list((out / "failed").iterdir())) == 1
    assert not list((out / "pours").glob(".*"))  # no partial folder left behind


def test_the_library_and_plots_point_at_the_pours(sweep):
    _, out, _ = sweep
    library = json.loads((out / "library.json").read_text())
    assert library["axes"] == ["liquid.fill_depth"]
    assert [e["axes"]["liquid.fill_depth"] for e in library["pours"]] == list(FILLS[:3])
    for entry in library["pours"]:
        assert all((out / f).is_file() for f in entry["trajectory"].values())
    assert (out / "plots" / "liquid.fill_depth.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_rerun_recomputes_no_finished_pour(sweep, capsys):
    path, out, _ = sweep
    before = _stats(out)
    capsys.readouterr()
    assert main(["sweep", str(path), "--out", str(out), "--quiet"]) == 1  # the refused pour fails again
    assert "this run: 0 poured, 1 failed; 3 skipped" in capsys.readouterr().out
    assert _stats(out) == before  # the same files, untouched
    assert [r["status"] for r in _rows(out)] == ["done", "done", "done", "failed"]


def test_each_pour_is_byte_identical_to_cosim_pour(sweep, tmp_path):
    path, out, _ = sweep
    rows = _rows(out)
    for pour, row in zip(expand(load_sweep(path)), rows[:3]):
        scene_file = tmp_path / f"pour{pour.index}.toml"
        scene_file.write_text(dump_scene(pour.scene))
        single = tmp_path / f"single{pour.index}"
        assert main(["pour", str(scene_file), "--no-log", "--quiet", "--out", str(single)]) == 0
        assert (single / "trajectory.csv").read_bytes() == (out / row["run_folder"] / "trajectory.csv").read_bytes()


def test_a_worker_with_other_code_writes_nothing(tmp_path):
    with pytest.raises(CodeVersionMismatch):
        pour_task(PourScene(), str(tmp_path / "run"), code="0" * 16)
    assert not (tmp_path / "run").exists()


def test_a_lost_worker_is_recorded_as_such():
    pour = PlannedPour(SweepPoint(0, {"liquid.fill_depth": 0.1}, PourScene()), "k", None)
    record = failure_record(pour, ray.exceptions.WorkerCrashedError())
    assert record["kind"] == "lost worker" and record["axes"] == {"liquid.fill_depth": 0.1} and record["error"]


def _parent_pid(pid: int) -> int:
    """The parent of process ``pid`` (0 when it is gone)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return 0
    return int(stat.rpartition(")")[2].split()[1])


def _pid_of(title: str) -> int | None:
    """This test's own process (a descendant of the test: its Ray's workers) whose command line is ``title`` (Ray
    sets a running task's to 'ray::<task name>'); other Ray sessions on the machine are never matched."""
    for proc in Path("/proc").iterdir():
        try:
            if not proc.name.isdigit() or (proc / "cmdline").read_bytes().split(b"\0")[0].split()[0] != title.encode():
                continue
        except (OSError, IndexError):
            continue
        pid = ancestor = int(proc.name)
        while ancestor > 1 and ancestor != os.getpid():
            ancestor = _parent_pid(ancestor)
        if ancestor == os.getpid():
            return pid
    return None


def test_a_killed_worker_is_recorded_and_the_sweep_goes_on(local_ray, tmp_path):
    path = tmp_path / "durations.toml"
    path.write_text(BASE + '[axes]\n"coupling.max_duration" = [0.3, 60.0]\n')
    result = {}
    sweep = threading.Thread(target=lambda: result.update(status=main(["sweep", str(path), "--out", str(tmp_path / "out"), "--quiet"])))
    sweep.start()
    deadline = time.monotonic() + 60.0
    while (pid := _pid_of("ray::pour-1")) is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert pid is not None, "the second pour's worker never showed up"
    os.kill(pid, signal.SIGKILL)
    sweep.join(timeout=120.0)
    rows = _rows(tmp_path / "out")
    assert result["status"] == 1
    assert [r["status"] for r in rows] == ["done", "failed"] and rows[1]["failure"] == "lost worker"
