"""`cosim bench`: Pareto front, cache and resume, CSV/Markdown generation, pour comparison, bad input exits 2."""

import csv
import io
import math

import pytest
from dataclasses import replace

from cosim.bench.cache import ResultCache
from cosim.bench.config import BenchCase, BenchConfig
from cosim.bench.pareto import pareto_front
from cosim.bench.plan import FULL_AXES, SMOOTHING_RATIO_LEVELS, build_plan
from cosim.bench.pour_compare import compare_pours
from cosim.bench.report import CSV_COLUMNS, GENERATED_BEGIN, GENERATED_END, build_rows, markdown, rows_csv, update_document
from cosim.bench.run import run_plan
from cosim.bench.runners import numerics, pour_scene, run_config
from cosim.cli.main import main
from cosim.coupling.settings import Coupling
from cosim.errors import InputError
from cosim.fluid.config import PressureSolver
from cosim.fluid.solver import FluidInstabilityError
from cosim.pour_scene import FluidSettings, PourScene
from cosim.validation import CASES


def test_pareto_front_of_a_known_example():
    # (cost, error): 1 is dominated by 0 (same cost, larger error), 3 by 2, 5 is a duplicate of 4, 6 has a NaN
    points = [(1.0, 0.5), (1.0, 0.6), (2.0, 0.2), (3.0, 0.3), (4.0, 0.1), (4.0, 0.1), (0.5, math.nan), (5.0, 0.1)]
    assert pareto_front(points) == [0, 2, 4]
    assert pareto_front([]) == []
    assert pareto_front([(2.0, 1.0), (1.0, 2.0)]) == [1, 0]  # by increasing cost


def _fake_runner(calls):
    """Stands in for run_config in the cache tests: records the calls, returns a well-formed validation result."""

    def run(cfg):
        calls.append(cfg)
        return {"config": cfg.to_json(), "status": "ok", "wall_s": 0.5 * cfg.particles_across, "sim_s": cfg.length,
                "particles": cfg.particles_across**2, "errors": {"pressure_error": 1.0 / cfg.particles_across, "density_error": 0.01}}

    return run


def test_second_run_reads_the_cache_and_resumes_after_interruption(tmp_path):
    plan = build_plan("smoke")
    calls = []
    first = run_plan(plan, ResultCache(tmp_path), progress=False, runner=_fake_runner(calls))
    timed = [c for c in calls if c in plan.rows]
    assert first.computed == len(plan.rows) == len(timed)
    calls.clear()
    second = run_plan(plan, ResultCache(tmp_path), progress=False, runner=_fake_runner(calls))
    assert second.computed == 0 and calls == []  # nothing recomputed, not even the warm-up
    assert second.results == first.results
    # an interrupted run left some entries: only the missing ones run
    missing = plan.rows[1:3]
    for cfg in missing:
        (tmp_path / f"{first.keys[cfg]}.json").unlink()
    third = run_plan(plan, ResultCache(tmp_path), progress=False, runner=_fake_runner(calls))
    assert third.computed == 2 and [c for c in calls if c in plan.rows] == list(missing)


def test_cache_key_covers_every_parameter_and_the_code_version():
    a = BenchConfig(BenchCase.HYDROSTATIC, 20, 1.0)
    variants = [BenchConfig(BenchCase.HYDROSTATIC, 21, 1.0), BenchConfig(BenchCase.HYDROSTATIC, 20, 2.0),
                BenchConfig(BenchCase.HYDROSTATIC, 20, 1.0, cfl=0.3), BenchConfig(BenchCase.HYDROSTATIC, 20, 1.0, kernel="cubic_spline"),
                BenchConfig(BenchCase.HYDROSTATIC, 20, 1.0, dim=3), BenchConfig(BenchCase.SLOSH, 20, 1.0),
                BenchConfig(BenchCase.HYDROSTATIC, 20, 1.0, pressure_solver="wcsph"),
                BenchConfig(BenchCase.HYDROSTATIC, 20, 1.0, pressure_solver="dfsph", density_tolerance=1e-4),
                BenchConfig(BenchCase.HYDROSTATIC, 20, 1.0, smoothing_ratio=1.3)]
    keys = {a.key("v1"), a.key("v2"), *(v.key("v1") for v in variants)}
    assert len(keys) == 2 + len(variants)
    assert a.key("v1") == BenchConfig(BenchCase.HYDROSTATIC, 20, 1.0).key("v1")


def test_real_smoke_rows_csv_and_markdown(tmp_path):
    plan = build_plan("smoke")
    outcome = run_plan(plan, ResultCache(tmp_path), progress=False)
    rows = build_rows(plan, outcome.results, outcome.keys)
    assert all(r.status == "ok" and r.sim_s > 0 and r.wall_s > 0 for r in rows)
    table = list(csv.DictReader(io.StringIO(rows_csv(rows))))
    assert len(table) == len(plan.rows) and tuple(table[0]) == CSV_COLUMNS
    hydro = [t for t in table if t["case"] == "hydrostatic"]
    assert hydro and all(0 <= float(t["pressure_error"]) < math.inf and t["front_error"] == "" for t in hydro)
    text = markdown(plan, outcome.results, rows, [], {}, "## header")
    assert "### hydrostatic" in text and "### dam-break" in text and "**default**" in text
    other = next(s for s in PressureSolver if s is not FluidSettings().pressure_solver)
    assert text.count("| cfl 0.4 |") == 2 and f"pressure_solver {other.value}" in text  # one row per CFL level and solver per case
    assert "load average" in text


def test_the_pour_reference_is_wcsph_and_every_solver_sweeps_the_pour_resolutions():
    plan = build_plan("full")
    assert plan.reference.pressure_solver is PressureSolver.WCSPH and plan.reference.particles_across == 48
    pours = [c for c in plan.compared_pours() if c.kernel is plan.reference.kernel and c.cfl == plan.reference.cfl
             and c.options == plan.reference.options]
    for solver in PressureSolver:  # both solvers at 16, 24 and 32 across, compared with the one reference
        assert {c.particles_across for c in pours if c.pressure_solver is solver} == {16, 24, 32}


def test_every_pour_row_holds_the_default_scenes_cfs_head():
    from cosim.pour_run import cfs_head_reference

    plan = build_plan("full")
    default = PourScene()
    head = cfs_head_reference(default, default.vessels.pourer.inner_width / default.fluid.particles_across)
    for cfg in (c for c in plan.rows if c.case is BenchCase.POUR):
        scene = pour_scene(cfg)
        spacing = scene.vessels.pourer.inner_width / scene.fluid.particles_across
        assert cfs_head_reference(scene, spacing) == head, cfg.label  # the same commanded pour at every resolution
    # without the options the reference would hold 3 of its own spacings, 2/3 of the default's head
    bare = pour_scene(replace(plan.reference, options=()))
    assert cfs_head_reference(bare, bare.vessels.pourer.inner_width / 48) == pytest.approx(head * 32 / 48)


def test_every_case_has_dfsph_rows_at_other_density_tolerances_at_its_default_resolution():
    plan = build_plan("full")
    default_tolerance = FluidSettings().density_tolerance
    for case, default in plan.defaults.items():
        rows = [c for c in plan.rows if c.case is case and c.density_tolerance is not None]
        assert len(rows) == 3 and default_tolerance not in {c.density_tolerance for c in rows}
        assert all(c.pressure_solver is PressureSolver.DFSPH and c.particles_across == default.particles_across for c in rows)


def test_a_density_tolerance_reaches_the_pour_scene_and_the_validation_numerics():
    cfg = BenchConfig(BenchCase.POUR, 20, 2.0, pressure_solver="dfsph", density_tolerance=1e-4)
    assert pour_scene(cfg).fluid.fluid_config(0.1).density_tolerance == 1e-4
    assert "tol0.0001" in cfg.label
    hydro = BenchConfig(BenchCase.HYDROSTATIC, 20, 1.0, pressure_solver="dfsph", density_tolerance=1e-5)
    assert dict(numerics(hydro))["density_tolerance"] == 1e-5
    assert "density_tolerance" not in dict(numerics(replace(hydro, density_tolerance=None)))


def test_every_case_has_rows_at_the_other_smoothing_ratios_at_its_axes_resolution():
    plan = build_plan("full")
    for case in plan.defaults:
        rows = [c for c in plan.rows if c.case is case and c.smoothing_ratio is not None]
        assert [c.smoothing_ratio for c in rows] == list(SMOOTHING_RATIO_LEVELS)
        axes = FULL_AXES[case]
        assert all(c.particles_across == (axes.axes_at or axes.resolutions[-1]) for c in rows)
        # one axis at a time: everything else is the default numerics
        assert all(replace(c, smoothing_ratio=None) in plan.rows for c in rows)


def test_a_smoothing_ratio_reaches_the_pour_scene_and_the_validation_numerics():
    cfg = BenchConfig(BenchCase.POUR, 20, 2.0, smoothing_ratio=1.3)
    assert pour_scene(cfg).fluid.fluid_config(0.1).smoothing_ratio == 1.3
    assert cfg.label.endswith("h/dx1.3")
    hydro = BenchConfig(BenchCase.HYDROSTATIC, 20, 1.0, smoothing_ratio=1.8)
    assert dict(numerics(hydro))["smoothing_ratio"] == 1.8
    assert "smoothing_ratio" not in dict(numerics(replace(hydro, smoothing_ratio=None)))
    with pytest.raises(InputError, match="smoothing_ratio"):
        BenchConfig(BenchCase.SLOSH, 20, 1.0, smoothing_ratio=3.0)


def test_update_document_keeps_the_text_around_the_generated_block(tmp_path):
    doc = tmp_path / "benchmarks.md"
    doc.write_text("# Benchmarks\n\nintro\n\n## Fluid step throughput\n\n| table |\n")
    update_document(doc, "generated one")
    update_document(doc, "generated two")
    text = doc.read_text()
    assert text.count(GENERATED_BEGIN) == 1 and text.count(GENERATED_END) == 1
    assert "generated two" in text and "generated one" not in text
    assert text.startswith("# Benchmarks\n") and "intro" in text and text.rstrip().endswith("| table |")


def _pour_raw(poured, landing, q, initial=1.0, done=False):
    t = [float(k) for k in range(len(poured))]
    return {"status": "ok", "outcome": {"initial_volume": initial, "caught_volume": 0.8 * poured[-1], "pour_done": done},
            "series": {"t": t, "poured_volume": poured, "landing_measured_x": landing, "trajectory_time": t,
                       "joint_names": ["a/j"], "joint_positions": [[x] for x in q]}}


def test_pour_comparison_against_hand_computed_values():
    ref = _pour_raw([0.0, 0.0, 0.3], [None, 0.30, 0.32], [0.0, 0.1, 0.2])
    run = _pour_raw([0.0, 0.3, 0.3], [None, None, 0.25], [0.0, 0.1, 0.5])
    err = compare_pours(run, ref)
    assert err["poured_curve_error"] == pytest.approx(math.sqrt(0.09 / 3))
    assert err["landing_error_m"] == pytest.approx(0.31 - 0.25)
    assert err["joint_rms_rad"] == pytest.approx(math.sqrt(0.09 / 3))
    assert err["final_caught_error"] == pytest.approx(0.0)
    assert compare_pours(_pour_raw([0.0, 0.1, 0.2], [None] * 3, [0, 0, 0]), ref)["final_caught_error"] == pytest.approx(0.08)
    assert math.isnan(compare_pours(_pour_raw([0, 0, 0], [None] * 3, [0, 0, 0]), ref)["landing_error_m"])


def test_a_pour_that_was_done_holds_its_volume_until_the_longer_run_ends():
    ref = _pour_raw([0.0, 0.2, 0.3, 0.3, 0.4], [None] * 5, [0.0] * 5)  # the reference pours on to t = 4
    early = _pour_raw([0.0, 0.3, 0.3], [None] * 3, [0.0] * 3, done=True)
    # done at t = 2: its 0.3 holds, so t = 0..4 count: differences 0, 0.1, 0, 0, -0.1
    assert compare_pours(early, ref)["poured_curve_error"] == pytest.approx(math.sqrt(0.02 / 5))
    # the same run cut off by its time limit is compared over t = 0..2 only
    cut = _pour_raw([0.0, 0.3, 0.3], [None] * 3, [0.0] * 3, done=False)
    assert compare_pours(cut, ref)["poured_curve_error"] == pytest.approx(math.sqrt(0.01 / 3))
    # and the other way round: a done reference that stopped first holds its volume against a longer run
    assert compare_pours(ref, early)["poured_curve_error"] == pytest.approx(math.sqrt(0.02 / 5))


def test_pour_scene_options_map_onto_the_scene_and_are_checked():
    cfg = BenchConfig(BenchCase.POUR, 20, 2.0, kernel="cubic_spline", cfl=0.3, options=(("coupling.coupling", "one_way"),))
    scene = pour_scene(cfg)
    assert scene.fluid.particles_across == 20 and scene.fluid.cfl == 0.3 and scene.fluid.kernel.value == "cubic_spline"
    assert scene.coupling.coupling is Coupling.ONE_WAY and scene.coupling.max_duration == 2.0
    assert scene.logging.enabled is False
    with pytest.raises(InputError, match="coupling.coupling"):
        pour_scene(BenchConfig(BenchCase.POUR, 20, 2.0, options=(("coupling.coupling", "sideways"),)))


def test_a_broken_simulation_is_a_failed_row_not_a_crash(monkeypatch):
    def explode(params):
        raise FluidInstabilityError(12, 0.003, "compression 0.4 exceeds fluid.max_density_error = 0.3")

    monkeypatch.setattr(CASES["hydrostatic"].implementation(), "run", explode)
    result = run_config(BenchConfig(BenchCase.HYDROSTATIC, 8, 0.05))
    assert result["status"] == "failed" and "SPH step 12" in result["message"]


@pytest.mark.parametrize("argv", [["bench", "--plan", "huge"], ["bench", "--docs", "notes.txt"]])
def test_bad_input_exits_2_with_one_line(argv, capsys, tmp_path):
    assert main(argv + ["--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("cosim bench: error:")
    assert not (tmp_path / "out").exists()


def test_bad_config_is_one_input_error():
    with pytest.raises(InputError, match="particles_across"):
        BenchConfig(BenchCase.POUR, 4, 1.0)
    with pytest.raises(InputError, match="options"):
        BenchConfig(BenchCase.SLOSH, 20, 1.0, options=(("coupling.coupling", "one_way"),))
    with pytest.raises(InputError, match="density_tolerance: applies to the dfsph solver only"):
        BenchConfig(BenchCase.SLOSH, 20, 1.0, pressure_solver="wcsph", density_tolerance=1e-4)
    with pytest.raises(InputError, match="density_tolerance"):
        BenchConfig(BenchCase.SLOSH, 20, 1.0, pressure_solver="dfsph", density_tolerance=0.5)


def test_code_version_is_per_case_sources():
    from cosim.bench.cache import SOURCES, code_version

    assert not any(s.startswith("controllers") for s in SOURCES[BenchCase.HYDROSTATIC])  # a controller edit keeps them
    assert code_version(BenchCase.HYDROSTATIC) == code_version(BenchCase.SLOSH)
    assert code_version(BenchCase.HYDROSTATIC) != code_version(BenchCase.POUR) != code_version(BenchCase.COUPLING_STATIC)


@pytest.mark.slow
def test_cli_smoke_writes_csv_markdown_plots_and_the_doc_block(tmp_path, capsys):
    doc = tmp_path / "docs" / "benchmarks.md"
    out = tmp_path / "out"
    argv = ["bench", "--plan", "smoke", "--out", str(out), "--docs", str(doc), "--quiet"]
    assert main(argv) == 0
    assert "2 from the cache" not in capsys.readouterr().out
    assert {"bench.csv", "bench.md", "bench_hydrostatic.png", "bench_dam_break.png"} <= {p.name for p in out.iterdir()}
    assert (doc.parent / "bench_hydrostatic.png").exists() and GENERATED_BEGIN in doc.read_text()
    assert main(argv) == 0
    assert "(0 configurations computed" in capsys.readouterr().out
