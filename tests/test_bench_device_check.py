"""The prepared device check (cosim.bench.device_check): its machinery, run on the CPU at its quick sizes."""

import pytest

from cosim.bench import device_check, host_overhead
from cosim.pour_scene import FluidSettings


@pytest.mark.slow
def test_quick_agreement_on_the_cpu_reports_identical_runs(tmp_path):
    # The CPU against itself: the solver is deterministic and its captured substeps replay the same launches, so
    # every difference the check reports must be exactly 0 (on a CUDA device the same table shows the CPU/CUDA
    # differences).
    assert device_check.main(["--device", "cpu", "--quick", "--only", "agreement", "--out", str(tmp_path)]) == 0
    rows = device_check.check_agreement("cpu", quick=True)
    assert [(r["dim"], r["solver"]) for r in rows] == [(2, "wcsph"), (2, "dfsph"), (3, "wcsph"), (3, "dfsph")]
    for r in rows:
        for pair in ("cpu_vs_device", "graphs_vs_launches"):
            assert r[pair]["max_dx_over_spacing"] == 0.0 and r[pair]["max_wrench_over_weight"] == 0.0
        assert r["one_ulp"]["max_dx_over_spacing"] > 0.0  # the yardstick run does start one ulp apart
    report = (tmp_path / "device_check.md").read_text()
    assert "| 2-D wcsph |" in report and "| 3-D dfsph |" in report
    assert all(r["graphs"] == "captured" for r in rows)  # warp replays captured substeps on the CPU too


def test_a_failing_check_is_reported_and_sets_the_exit_status(tmp_path):
    # no such device: the check's own process fails with the solver's one-line error, the report says so
    assert device_check.main(["--device", "cuda:7", "--quick", "--only", "agreement", "--out", str(tmp_path)]) == 1
    report = (tmp_path / "device_check.md").read_text()
    assert "failed (exit" in report and "cuda:7" in report


def test_pour_rows_split_the_wall_time_into_substeps_and_the_rest():
    row = host_overhead.pour_rate("cpu", 2, 12, 0.02)
    assert row["particles"] > 0 and row["sph_substeps"] > 0 and row["graphs"] == "captured"
    steps = round(row["simulated_s"] / 0.002)  # 2 ms MuJoCo steps
    assert 0.0 < row["substeps_ms_per_step"] and 0.0 < row["host_ms_per_step"]
    assert abs((row["substeps_ms_per_step"] + row["host_ms_per_step"]) * steps - 1e3 * row["wall_s"]) < 1e-6
    table = "\n".join(device_check._pour_table([row]))
    default = FluidSettings()
    label = f"{default.pressure_solver.value} ({default.density_iteration.value})"  # the default scene's solver is DFSPH
    assert f"| 2-D, 12 across, {label} |" in table and "the rest (host) ms per step" in table
    needed = row["particles"] * row["sph_substeps"] / row["simulated_s"] / 1e9  # G particle-substeps per second
    assert f"| {needed:.3f} |" in table


def test_a_check_past_its_limit_is_reported_with_what_it_printed(tmp_path, monkeypatch):
    # a limit far below the child's start-up (Python, numpy, warp): the check is stopped, the report says so, and its
    # log is written (what it printed before the limit, in the output folder, which is all a remote run may return)
    monkeypatch.setitem(device_check.TIME_LIMITS, "agreement", 0.01)
    assert device_check.main(["--device", "cpu", "--quick", "--only", "agreement", "--out", str(tmp_path)]) == 1
    assert "timed out after" in (tmp_path / "device_check.md").read_text()
    assert (tmp_path / "agreement.log").exists()


def test_the_profile_check_reports_each_case(tmp_path):
    # on the CPU warp times no kernel: each case reports its substeps and wall time (the CUDA run adds the table)
    assert device_check.main(["--device", "cpu", "--quick", "--only", "profile", "--out", str(tmp_path)]) == 0
    report = (tmp_path / "device_check.md").read_text()
    assert "### 3-D, 1872 particles, wcsph, cpu" in report and "### 2-D, 484 particles, dfsph (jacobi), cpu" in report
    assert "# Kernel profile" not in report  # the profile's own title is dropped inside the report
