"""Run one benchmark configuration and return its raw result (a JSON-ready dict, the unit the cache stores).

Validation cases go through the :mod:`cosim.validation` API, which already compares with the references; their
errors are taken from its metrics. A pour goes through :func:`cosim.pour_run.run_pour` (the product's own path,
into a temporary folder) and keeps what the comparison with another pour needs (:mod:`cosim.bench.pour_compare`):
the poured volume and the measured landing point per control step, and the joint trajectories.

What the time measures: ``wall_s`` is the case's timed section: for a validation case its simulation loop
(``CaseResult.wall_time``, set-up excluded), for a pour the whole ``run_pour`` call (scene set-up, the coupled
loop, logging when on, writing the outputs). ``sim_s`` is the simulated time of that section.
"""

from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from cosim.bench.config import BenchCase, BenchConfig
from cosim.config_mapping import from_mapping
from cosim.errors import SimulationError
from cosim.io.pour_series import read_series_csv
from cosim.pour_scene import PourScene
from cosim.trajectory.csv_file import read_trajectory_csv
from cosim.validation import CASES
from cosim.validation.common import CaseResult

# Rate (Hz) at which a pour's joint trajectories are kept for the comparison (the 500 Hz export, decimated: the
# jerk-limited trajectories carry nothing above a few Hz).
TRAJECTORY_KEEP_HZ = 100.0


def numerics(cfg: BenchConfig) -> tuple[tuple[str, Any], ...]:
    """The configuration's numerical settings as FluidConfig overrides (``FluidCaseParams.numerics``)."""
    tolerance = () if cfg.density_tolerance is None else (("density_tolerance", cfg.density_tolerance),)
    ratio = () if cfg.smoothing_ratio is None else (("smoothing_ratio", cfg.smoothing_ratio),)
    return (("kernel", cfg.kernel), ("cfl", cfg.cfl), *tolerance, *ratio)


def case_width(cfg: BenchConfig) -> float:
    """m, the width the configuration's ``particles_across`` spans."""
    if cfg.case in (BenchCase.COUPLING_STATIC, BenchCase.POUR):
        from cosim.robots.scene import RobotScene
        from cosim.robots.scene_config import ArmRole

        return RobotScene.load().arms[ArmRole.POUR].vessel.inner_width
    if cfg.case is BenchCase.FREE_FALL:
        return CASES[cfg.case.value].params().spec().inner_width
    return CASES[cfg.case.value].params().width


def _validation_params(cfg: BenchConfig):
    spacing = case_width(cfg) / cfg.particles_across
    common = dict(spacing=spacing, dim=cfg.dim, device=cfg.device, solver=cfg.pressure_solver, numerics=numerics(cfg))
    length = {
        BenchCase.HYDROSTATIC: "duration", BenchCase.SLOSH: "periods", BenchCase.DAM_BREAK: "t_max",
        BenchCase.FREE_FALL: "hold", BenchCase.COUPLING_STATIC: "duration",
    }[cfg.case]
    return CASES[cfg.case.value].params(**common, **{length: cfg.length})


def validation_errors(case: BenchCase, result: CaseResult) -> dict[str, float]:
    """The errors a validation result reports, as positive numbers (relative unless the name says otherwise)."""
    m = result.metrics
    if case is BenchCase.HYDROSTATIC:
        return {"pressure_error": abs(m[0].error), "density_error": abs(m[1].error)}
    if case is BenchCase.SLOSH:
        return {"frequency_error": abs(m[0].error)}
    if case is BenchCase.DAM_BREAK:
        scored = [abs(x.error) for x in m if math.isfinite(x.tolerance)]  # the acceptance window T <= 3
        return {"front_error": max(scored) if scored else math.nan}
    if case is BenchCase.FREE_FALL:
        return {"fall_error_m": float(result.raw["median_abs_error"])}
    return {"reaction_error": abs(m[0].error), "torque_error": abs(m[1].error)}


def _simulated_time(case: BenchCase, result: CaseResult) -> float:
    if case in (BenchCase.SLOSH, BenchCase.DAM_BREAK):
        return float(result.raw["t"][-1])
    if case is BenchCase.FREE_FALL:
        return float(result.raw["simulated_time"])
    return float(result.parameters["duration"])


def pour_scene(cfg: BenchConfig) -> PourScene:
    """The pour scene of ``cfg``: the default scene with its resolution, numerics, duration and options, logging off
    unless an option turns it on; built through the scene-file mapping, so options are checked like a TOML file."""
    table: dict[str, Any] = {
        "device": cfg.device,
        "fluid": {"dim": cfg.dim, "particles_across": cfg.particles_across, "kernel": cfg.kernel.value, "cfl": cfg.cfl,
                  "pressure_solver": cfg.pressure_solver.value},
        "coupling": {"max_duration": cfg.length},
        "logging": {"enabled": False},
    }
    if cfg.density_tolerance is not None:
        table["fluid"]["density_tolerance"] = cfg.density_tolerance
    if cfg.smoothing_ratio is not None:
        table["fluid"]["smoothing_ratio"] = cfg.smoothing_ratio
    for key, value in cfg.options:
        *path, leaf = key.split(".")
        node = table
        for part in path:
            node = node.setdefault(part, {})
        node[leaf] = value
    return from_mapping(PourScene, table, "scene")


def _run_pour(cfg: BenchConfig) -> dict:
    from cosim.pour_run import run_pour

    scene = pour_scene(cfg)
    with tempfile.TemporaryDirectory(prefix="cosim-bench-") as tmp:
        start = time.perf_counter()
        folder, summary = run_pour(scene, Path(tmp) / "run", progress=False, long_run_ok=True)  # the plan chose it
        wall = time.perf_counter() - start
        series = read_series_csv(folder / "series.csv")
        trajectory = read_trajectory_csv(folder / "trajectory.csv")
    keep = max(1, round(1.0 / (TRAJECTORY_KEEP_HZ * float(np.median(np.diff(trajectory.time))))))
    return {
        "wall_s": wall,
        "sim_s": float(summary["sim_time"]),
        "particles": int(summary["particles"]),
        "outcome": {k: summary[k] for k in ("initial_volume", "poured_volume", "caught_volume", "spilled_volume", "pour_done")},
        "series": {
            "t": series["t"],
            "poured_volume": series["poured_volume"],
            "landing_measured_x": [None if math.isnan(x) else x for x in series["landing_measured_x"]],
            "trajectory_time": trajectory.time[::keep].tolist(),
            "joint_names": list(trajectory.joint_names),
            "joint_positions": trajectory.positions[::keep].tolist(),
        },
    }


def run_config(cfg: BenchConfig) -> dict:
    """Run ``cfg``; a simulation that breaks is an outcome (``status`` 'failed' with the message), not a crash."""
    try:
        if cfg.case is BenchCase.POUR:
            out = _run_pour(cfg)
        else:
            params = _validation_params(cfg)
            result = CASES[cfg.case.value].run(params)
            out = {
                "wall_s": result.wall_time,
                "sim_s": _simulated_time(cfg.case, result),
                "particles": int(result.raw.get("particles", 0)),
                "errors": validation_errors(cfg.case, result),
            }
    except SimulationError as exc:
        return {"config": cfg.to_json(), "status": "failed", "message": str(exc)}
    return {"config": cfg.to_json(), "status": "ok", **out}

