"""Run a benchmark plan: cached rows are read back, the others run one at a time (progress bar) and are cached as
soon as each finishes, so an interrupted bench resumes without redoing finished rows."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from dataclasses import dataclass

from tqdm import tqdm

from cosim.bench.cache import ResultCache, code_version
from cosim.bench.config import BenchCase, BenchConfig
from cosim.bench.plan import BenchPlan
from cosim.bench.runners import run_config

WARM_UP = dict(particles_across=8, length=0.01)  # a hydrostatic tank held 10 ms: loads the compiled kernels


@dataclass
class BenchOutcome:
    """results and keys per configuration; computed: how many rows ran (the rest came from the cache);
    versions: the code version of each case."""

    results: dict[BenchConfig, dict]
    keys: dict[BenchConfig, str]
    computed: int
    versions: dict[BenchCase, str]


def warm_up(todo: list[BenchConfig], runner: Callable[[BenchConfig], dict]) -> None:
    """Load (or compile) the kernels of each pressure solver and device before anything is timed."""
    for solver, device in dict.fromkeys((c.pressure_solver, c.device) for c in todo):
        runner(BenchConfig(BenchCase.HYDROSTATIC, pressure_solver=solver, device=device, **WARM_UP))


def run_plan(plan: BenchPlan, cache: ResultCache, fresh: bool = False, progress: bool = True,
             runner: Callable[[BenchConfig], dict] = run_config) -> BenchOutcome:
    """Results of every row of ``plan``; ``fresh`` ignores (and overwrites) cached ones."""
    versions = {case: code_version(case) for case in dict.fromkeys(c.case for c in plan.rows)}
    keys = {c: c.key(versions[c.case]) for c in plan.rows}
    results: dict[BenchConfig, dict] = {}
    todo = []
    for cfg in plan.rows:
        cached = None if fresh else cache.get(keys[cfg])
        if cached is not None:
            results[cfg] = cached
        else:
            todo.append(cfg)
    print(f"cosim bench: {len(plan.rows)} configurations, {len(plan.rows) - len(todo)} cached, {len(todo)} to run "
          f"(code versions {', '.join(f'{k.value} {v}' for k, v in versions.items())})", file=sys.stderr)
    if todo:
        warm_up(todo, runner)
    bar = tqdm(todo, unit="config", disable=not progress, file=sys.stderr, mininterval=1.0)
    for cfg in bar:
        bar.set_description_str(cfg.label)
        result = dict(runner(cfg), load_average=os.getloadavg()[0])  # others' jobs on the machine skew wall times
        cache.put(keys[cfg], result)
        results[cfg] = result
    bar.close()
    return BenchOutcome(results, keys, len(todo), versions)
