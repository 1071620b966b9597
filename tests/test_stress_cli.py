"""`cosim stress`: a quick run writes the CSV, Markdown and PNG with outcomes consistent with the recorded
measurements; a rerun resumes (skips finished rows); an unexpected exception is recorded as `error` and fails the
run without stopping it; bad input exits 2."""

import csv

import pytest

import cosim.stress.matrix
import cosim.stress.runner
from cosim.cli.main import main
from cosim.stress.classify import DENSITY_ERROR_BOUND, ENERGY_EXCESS_BOUND
from cosim.stress.matrix import DURATION, quick_matrix
from tests.support.stress import CLEAN


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("stress")
    rc = main(["stress", "--quick", "--out", str(out)])
    return rc, out


def _rows(out):
    with (out / "stress.csv").open(newline="") as f:
        return list(csv.DictReader(f))


def test_quick_run_writes_rows_and_report(quick_run):
    rc, out = quick_run
    rows = _rows(out)
    assert [r["id"] for r in rows] == [c.id for c in quick_matrix()]
    for r in rows:
        assert r["outcome"] in ("clean", "instability", "silent", "refused")
        if r["outcome"] == "refused":  # the 10 % fill at 12 across is one particle layer: refused at set-up
            assert "particle layers" in r["message"] and "at least 3" in r["message"]
            continue
        assert float(r["simulated_time"]) == pytest.approx(DURATION) or r["outcome"] == "instability"
        assert 0 < float(r["dt_ratio_min"]) <= 1.0 and int(r["particles"]) > 0 and float(r["wall_time"]) > 0
        garbage = (int(r["nonfinite"]) > 0 or int(r["leaked"]) > 0 or float(r["max_density_error"]) > DENSITY_ERROR_BOUND
                   or float(r["energy_excess"]) > ENERGY_EXCESS_BOUND)
        if r["outcome"] != "instability":
            assert (r["outcome"] == "silent") == garbage and bool(r["message"]) == garbage
    assert rc == (1 if any(r["outcome"] == "silent" for r in rows) else 0)
    md = (out / "stability.md").read_text()
    assert md.count("\n| " + rows[0]["id"][:6]) == 1 and all(r["id"] in md for r in rows)
    assert "cosim stress --out" in md and "--quick" in md and "## Per axis" in md
    assert (out / "stability.png").read_bytes()[:4] == b"\x89PNG"


def test_rerun_resumes_and_docs_writes_from_the_csv(quick_run, tmp_path, monkeypatch, capsys):
    _, out = quick_run
    before = (out / "stress.csv").read_text()

    def must_not_run(config, device):
        raise AssertionError(f"{config.id} was already done")

    monkeypatch.setattr(cosim.stress.runner, "measure", must_not_run)
    main(["stress", "--quick", "--out", str(out)])
    assert "3 already in" in capsys.readouterr().err
    assert (out / "stress.csv").read_text() == before
    assert main(["stress", "--out", str(out), "--docs", str(tmp_path)]) == 0
    assert (tmp_path / "stability.md").read_text().count("| clean |") + (tmp_path / "stability.md").read_text().count("| instability |") >= 1
    assert (tmp_path / "stability.png").exists()


def test_unexpected_exception_is_an_error_row_and_the_run_goes_on(tmp_path, monkeypatch):
    configs = quick_matrix()

    def flaky(config, device):
        if config.id == configs[0].id:
            raise RuntimeError("boom")
        return CLEAN

    monkeypatch.setattr(cosim.stress.runner, "measure", flaky)
    monkeypatch.setattr(cosim.stress.matrix, "quick_matrix", lambda: configs[:2])
    assert main(["stress", "--quick", "--out", str(tmp_path)]) == 1
    rows = {r["id"]: r for r in _rows(tmp_path)}
    assert rows[configs[0].id]["outcome"] == "error" and "RuntimeError: boom" in rows[configs[0].id]["message"]
    assert rows[configs[1].id]["outcome"] == "clean"


@pytest.mark.parametrize("argv", [["stress", "--filter", "speed=1"], ["stress", "--filter", "dim=4"],
                                  ["stress", "--device", "tpu"]])
def test_bad_input_exits_2(argv, tmp_path, capsys):
    assert main(argv + ["--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "error:" in err
    assert not any(tmp_path.iterdir())


def test_docs_without_results_exits_2(tmp_path, capsys):
    assert main(["stress", "--out", str(tmp_path / "none"), "--docs", str(tmp_path / "docs")]) == 2
    assert not (tmp_path / "docs").exists()
