"""The speed targets (cosim.bench.targets, ``cosim bench --plan targets``): the verdicts, every measurement's
path at small sizes on the CPU (numbers meaningless there), and the report the command writes."""

import json
import re

import pytest

from cosim.bench import targets
from cosim.bench.targets import DEFAULT_POUR, POUR_3D, STEPS_2D, THROUGHPUT_3D, Measurement, TargetSizes
from cosim.cli.main import main

# seconds of CPU: the measurements' machinery, not their numbers
SMALL = TargetSizes(throughput_3d=2000, throughput_2d=300, steps=4, repeats=1, pour_3d_across=12, pour_3d_seconds=0.02,
                    default_pour_repeats=1, default_pour_duration=0.04)


def test_verdicts_compare_with_the_threshold_in_the_targets_direction():
    assert Measurement(THROUGHPUT_3D, 80.0, "").verdict == "met"  # at least 80 G: the threshold itself meets it
    assert Measurement(THROUGHPUT_3D, 20.0, "").verdict == "missed, 4 x"
    assert Measurement(DEFAULT_POUR, 60.0, "").verdict == "met"  # at most 60 s
    assert Measurement(DEFAULT_POUR, 90.0, "").verdict == "missed, 1.5 x"
    assert Measurement(STEPS_2D, None, "no CUDA device on this machine").verdict == "not measured"
    assert Measurement(POUR_3D, None, "RuntimeError: x", failed=True).verdict == "failed"


@pytest.fixture(scope="module")
def measured():
    # the CUDA targets' measurements run on the CPU here: the same code path a CUDA device takes
    return {m.target: m for m in targets.measure_all(SMALL, cuda="cpu")}


@pytest.mark.slow
def test_every_measurement_runs_and_reports_its_figure(measured):
    assert list(measured) == list(targets.TARGETS)
    assert all(not m.failed and m.value > 0.0 and m.took_s > 0.0 for m in measured.values()), [m.detail for m in measured.values()]
    assert "example_sph at the same count" in measured[THROUGHPUT_3D].detail
    assert all(f"{v}:" in measured[STEPS_2D].detail for v in ("wcsph", "dfsph (gauss_seidel)", "dfsph (jacobi)"))
    assert "the rest (host)" in measured[POUR_3D].detail
    # the default pour ran as a user runs it, to its --duration: 0.04 s simulated
    assert "0.04 s simulated" in measured[DEFAULT_POUR].detail
    assert re.search(r"trajectory\.csv sha256 [0-9a-f]{12} ", measured[DEFAULT_POUR].detail), measured[DEFAULT_POUR].detail


def test_without_cuda_the_cuda_targets_are_listed_not_measured(monkeypatch):
    monkeypatch.setitem(targets.MEASURES, DEFAULT_POUR, lambda device, sizes: (12.5, f"on {device}"))
    rows = targets.measure_all(SMALL, cuda=None)
    assert [m.verdict for m in rows] == ["not measured"] * 3 + ["met"]
    assert rows[-1].detail == "on cpu"


def test_a_failing_measurement_is_a_row_and_the_others_still_run(monkeypatch):
    def broken(device, sizes):
        raise RuntimeError("out of memory\nsecond line")

    for target in targets.TARGETS:
        monkeypatch.setitem(targets.MEASURES, target, lambda device, sizes: (1e9, f"on {device}"))
    monkeypatch.setitem(targets.MEASURES, STEPS_2D, broken)
    seen = []
    rows = targets.measure_all(SMALL, cuda="cuda:3", on_row=lambda so_far: seen.append([m.verdict for m in so_far]))
    assert rows[1].failed and rows[1].detail == "RuntimeError: out of memory"
    assert [m.detail for m in rows] == ["on cuda:3", "RuntimeError: out of memory", "on cuda:3", "on cpu"]  # all ran
    # the report can be rewritten after every row: a run stopped part-way keeps what it measured
    assert seen == [["met"], ["met", "failed"], ["met", "failed", "met"], ["met", "failed", "met", "missed, 1.67e+07 x"]]


def test_cosim_bench_targets_writes_the_report_and_the_docs_block(tmp_path, monkeypatch, capsys):
    rows = [Measurement(THROUGHPUT_3D, None, "no CUDA device on this machine"), Measurement(DEFAULT_POUR, 42.0, "runs: 42.0 s", took_s=170.2)]
    monkeypatch.setattr(targets, "measure_all", lambda cuda=None, on_row=None: rows)
    monkeypatch.setattr("cosim.fluid.runtime.cuda_available", lambda: False)
    docs = tmp_path / "bench.md"
    docs.write_text("# B\n\nkept\n<!-- cosim bench targets, cpu: generated, begin -->\nthe previous run\n<!-- cosim bench targets, cpu: generated, end -->\ntail\n")
    out = tmp_path / "out"
    assert main(["bench", "--plan", "targets", "--out", str(out), "--docs", str(docs)]) == 0
    text = docs.read_text()
    assert "kept" in text and "tail" in text and "the previous run" not in text
    assert "| default pour, `cosim pour --no-log`, compiled kernels cached | cpu | <= 60 s wall | 42 s wall | met | runs: 42.0 s | 170 s |" in text
    assert "| not measured | no CUDA device on this machine | - |" in text
    assert "Command: `cosim bench --plan targets --docs" in text
    saved = json.loads((out / "targets.json").read_text())
    assert [r["verdict"] for r in saved] == ["not measured", "met"] and saved[1]["value"] == 42.0
    assert (out / "targets.md").read_text() in capsys.readouterr().out


def test_a_failed_target_sets_the_exit_status(tmp_path, monkeypatch):
    monkeypatch.setattr(targets, "measure_all", lambda cuda=None, on_row=None: [Measurement(DEFAULT_POUR, None, "RuntimeError: x", failed=True)])
    assert main(["bench", "--plan", "targets", "--out", str(tmp_path)]) == 1


@pytest.mark.parametrize("extra", [["--fresh"], ["--cache", "somewhere"]])
def test_cache_options_with_the_targets_plan_are_one_line_exit_2(extra, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["bench", "--plan", "targets", "--out", str(out), *extra]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and extra[0] in err[0] and "caches nothing" in err[0]
    assert not out.exists()
