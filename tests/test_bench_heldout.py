"""The held-out pours (examples/heldout, cosim.bench.heldout): the scene files pass the checks `cosim scene --check`
runs and cover what the set is for; the report reads a pour's summary.json against the thresholds and marks a
failing check, a failed pour and a missing one FAIL. No pour runs here (`cosim bench --plan heldout` runs them)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from cosim.bench.heldout import (
    DEFAULT_SCENES,
    LANDING_LIMIT_MM,
    PARTIAL_LIMIT_PERCENT,
    SPILL_LIMIT_PERCENT,
    bench_scene,
    collect_rows,
    criteria,
    load_pours,
    markdown,
    rows_csv,
)
from cosim.cli.main import main
from cosim.pour_checks import check_pour
from cosim.pour_scene import PourScene, load_scene
from cosim.sweep.store import SweepStore

ROOT = Path(__file__).resolve().parent.parent
SCENES = sorted((ROOT / DEFAULT_SCENES).glob("*.toml"))


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_every_heldout_scene_passes_the_checks_of_cosim_scene_check(path):
    check_pour(load_scene(path))  # the checks `cosim scene --check` runs, without --yes; raises InputError


def test_the_heldout_set_covers_fills_partial_pours_catcher_offsets_shapes_sizes_and_both_solvers():
    default = PourScene()
    scenes = [bench_scene(p) for p in SCENES]
    assert len(scenes) >= 12
    fills = [s.liquid.fill_depth / s.vessels.pourer.inner_height for s in scenes]
    assert min(fills) <= 0.40 + 1e-9 and max(fills) >= 0.95
    assert sum(s.liquid.pour_fraction < 1.0 for s in scenes) >= 2
    assert {s.placement.catcher_home_x for s in scenes if s.vessels == default.vessels} - {default.placement.catcher_home_x}
    assert {s.vessels.pourer.shape.value for s in scenes} == {"box", "cylinder"}
    assert {s.vessels.pourer.inner_width for s in scenes} - {default.vessels.pourer.inner_width}
    assert {s.fluid.pressure_solver.value for s in scenes} == {"dfsph", "wcsph"}
    assert all(s.fluid.dim == 2 and s.fluid.particles_across == default.fluid.particles_across for s in scenes)
    assert all(not s.logging.enabled and s.fluid.cpu_threads == 1 for s in scenes)


def _summary(poured=1.0e-3, spilled=0.0, landing_mm=2.0, target=None, target_error=None, done=True) -> dict:
    """A summary.json's fields the report reads (volumes in m^3, the landing error in m)."""
    landing = {"samples": 50, "median_abs_error": landing_mm / 1e3} if landing_mm is not None else {"samples": 0}
    return {"poured_volume": poured, "caught_volume": poured - spilled, "spilled_volume": spilled,
            "target_volume": target, "target_error": target_error, "landing": landing, "pour_done": done,
            "wall_time": 1.0}


def test_criteria_compare_spill_landing_and_partial_error_with_their_limits():
    ok = criteria(_summary(poured=1e-3, spilled=0.5 * SPILL_LIMIT_PERCENT / 100 * 1e-3, landing_mm=LANDING_LIMIT_MM - 0.1))
    assert ok["spill"].value == pytest.approx(0.5 * SPILL_LIMIT_PERCENT) and ok["spill"].passed
    assert ok["landing"].value == pytest.approx(LANDING_LIMIT_MM - 0.1) and ok["landing"].passed
    assert not ok["partial"].applies and ok["partial"].passed  # a pour until empty has no target

    bad = criteria(_summary(poured=1e-3, spilled=2 * SPILL_LIMIT_PERCENT / 100 * 1e-3, landing_mm=LANDING_LIMIT_MM + 0.1,
                            target=5e-4, target_error=-(PARTIAL_LIMIT_PERCENT + 1) / 100 * 5e-4))
    assert not bad["spill"].passed and not bad["landing"].passed
    assert bad["partial"].applies and bad["partial"].value == pytest.approx(PARTIAL_LIMIT_PERCENT + 1)
    assert not bad["partial"].passed

    none = criteria(_summary(poured=0.0, landing_mm=None))  # nothing poured, no landing sample: nothing passes
    assert none["spill"].value is None and not none["spill"].passed
    assert none["landing"].value is None and not none["landing"].passed


def test_the_report_marks_each_row_pass_or_fail_failed_and_missing_pours_included(tmp_path):
    folder = tmp_path / "scenes"
    folder.mkdir()
    for name, text in {"good": "", "spills": "", "broke": "", "missing": "",
                       "partial": "[liquid]\npour_fraction = 0.5\n"}.items():
        (folder / f"{name}.toml").write_text(f"name = '{name}'\n{text}")
    pours = {p.path.stem: p for p in load_pours(folder, "code")}
    store = SweepStore(tmp_path / "store")
    outcomes = {"good": _summary(), "spills": _summary(spilled=2e-5),  # 2 % of the poured volume
                "partial": _summary(target=1e-3, target_error=1e-5)}  # 1 % over the target
    for name, summary in outcomes.items():
        store.run_folder(pours[name].key).mkdir(parents=True)
        (store.run_folder(pours[name].key) / "summary.json").write_text(json.dumps(summary))
    store.record_failure(pours["broke"].key, {"kind": "simulation failed", "error": "step 12: density error 0.4"})

    rows = {r["scene"]: r for r in collect_rows(list(pours.values()), store)}
    assert {n: r["passed"] for n, r in rows.items()} == {"good": True, "spills": False, "broke": False,
                                                         "missing": False, "partial": True}
    assert rows["broke"]["failure"] == "simulation failed: step 12: density error 0.4"
    assert rows["missing"]["failure"].startswith("not run")
    text = markdown(list(rows.values()), "### header")
    table = {line.split("|")[1].strip(): line for line in text.splitlines() if line.startswith("| ") and "---" not in line}
    assert table["spills"].rstrip(" |").endswith("FAIL") and "| 2.00 | FAIL |" in table["spills"]
    assert table["good"].rstrip(" |").endswith("PASS")
    assert "| 1.00 | PASS |" in table["partial"]
    assert table["broke"].rstrip(" |").endswith("FAIL") and table["missing"].rstrip(" |").endswith("FAIL")
    assert "2 of 5 rows pass." in text
    csv_lines = rows_csv(list(rows.values())).splitlines()
    assert len(csv_lines) == 6 and csv_lines[0].endswith(",row")


def test_bench_refuses_scenes_without_the_heldout_plan_and_an_empty_scene_folder(tmp_path, capsys):
    assert main(["bench", "--plan", "smoke", "--scenes", str(tmp_path), "--out", str(tmp_path / "out")]) == 2
    assert "--scenes: only with --plan heldout" in capsys.readouterr().err
    assert main(["bench", "--plan", "heldout", "--scenes", str(tmp_path), "--out", str(tmp_path / "out")]) == 2
    assert f"--scenes: no scene files (*.toml) in {tmp_path}" in capsys.readouterr().err


def test_an_interrupted_heldout_run_still_writes_its_report(tmp_path, monkeypatch, capsys):
    import cosim.bench.heldout

    scenes = tmp_path / "scenes"
    scenes.mkdir()
    (scenes / "one.toml").write_text("[liquid]\nfill_depth = 0.1\n")

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(cosim.bench.heldout, "run_missing", interrupted)
    docs = tmp_path / "heldout.md"
    docs.write_text("# Held-out pours\n\nkept text\n")
    argv = ["bench", "--plan", "heldout", "--scenes", str(scenes), "--out", str(tmp_path / "out"), "--docs", str(docs)]
    assert main(argv) == 130
    report = (tmp_path / "out" / "heldout.md").read_text()
    assert "| one |" in report and "not run: no run folder" in report and "0 of 1 rows pass." in report
    assert "kept text" in docs.read_text() and "| one |" in docs.read_text()
