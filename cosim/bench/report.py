"""Tables and plots of benchmark results: the rows (with their errors), CSV, Markdown, Pareto PNGs.

A row's errors: validation cases report theirs against the analytic or experimental reference; a pour row is
compared with the fine reference pour over the simulated time (:mod:`cosim.bench.pour_compare`). The cost axis is
``wall_per_sim_s``, wall-clock seconds per simulated second (what :mod:`cosim.bench.runners` times).
"""

from __future__ import annotations

import csv
import io
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from cosim.atomic_files import atomic_path, write_text_atomic
from cosim.bench.config import BenchCase, BenchConfig
from cosim.bench.pareto import pareto_front
from cosim.bench.plan import BenchPlan
from cosim.bench.pour_compare import POUR_ERRORS, compare_pours
from cosim.fluid.lanes import MIN_PARTICLES_PER_LANE, available_cores

# Errors per case, in table order, with their headers (relative errors unless the unit says otherwise).
CASE_ERRORS = {
    BenchCase.HYDROSTATIC: ("pressure_error", "density_error"),
    BenchCase.SLOSH: ("frequency_error",),
    BenchCase.DAM_BREAK: ("front_error",),
    BenchCase.FREE_FALL: ("fall_error_m",),
    BenchCase.COUPLING_STATIC: ("reaction_error", "torque_error"),
    BenchCase.POUR: POUR_ERRORS,
}
ERROR_TITLES = {
    "pressure_error": "worst probe pressure error vs rho0 g (H - z)",
    "density_error": "max density error",
    "frequency_error": "slosh frequency error vs Eq. 17",
    "front_error": "worst front error vs Martin & Moyce (T <= 3)",
    "fall_error_m": "median landing error vs own free-fall parabola (m)",
    "reaction_error": "vertical reaction error vs weight",
    "torque_error": "joint torque error vs rigid payload",
    "poured_curve_error": "poured-volume curve RMS diff / initial volume",
    "landing_error_m": "landing point diff (m)",
    "joint_rms_rad": "joint trajectory RMS diff (rad)",
    "final_caught_error": "final caught volume diff / initial volume",
}
CSV_COLUMNS = ("case", "dim", "particles_across", "kernel", "cfl", "pressure_solver", "density_tolerance", "device", "length", "options",
               "status", "particles", "sim_s", "wall_s", "wall_per_sim_s", *ERROR_TITLES, "compared_with", "key")


@dataclass
class Row:
    """One configuration's outcome. errors: name -> value (see :data:`ERROR_TITLES`); compared_with: what a
    pour's errors are against ('' for validation cases)."""

    config: BenchConfig
    key: str
    status: str
    message: str = ""
    particles: int = 0
    sim_s: float = math.nan
    wall_s: float = math.nan
    errors: dict[str, float] = field(default_factory=dict)
    compared_with: str = ""

    @property
    def wall_per_sim_s(self) -> float:
        return self.wall_s / self.sim_s if self.sim_s > 0 else math.nan


def build_rows(plan: BenchPlan, results: dict[BenchConfig, dict], keys: dict[BenchConfig, str]) -> list[Row]:
    """Rows of every configuration of ``plan`` (in plan order) from their raw ``results``."""
    ref = results.get(plan.reference) if plan.reference is not None else None
    compared = set(plan.compared_pours())
    rows = []
    for cfg in plan.rows:
        raw = results[cfg]
        row = Row(cfg, keys[cfg], raw["status"], raw.get("message", ""))
        if raw["status"] == "ok":
            row.particles, row.sim_s, row.wall_s = raw["particles"], raw["sim_s"], raw["wall_s"]
            if cfg.case is not BenchCase.POUR:
                row.errors = dict(raw["errors"])
            elif cfg in compared and ref is not None and ref["status"] == "ok":
                row.errors = compare_pours(raw, ref)
                row.compared_with = plan.reference.label
        rows.append(row)
    return rows


def skip_table(plan: BenchPlan, results: dict[BenchConfig, dict]) -> list[dict]:
    """Per skip option: wall s per simulated s with and without it, the speed-up (the ratio of the runs' wall times:
    the early stop saves simulated seconds, the others the cost of each), and the errors of the skipping run
    against the full one (:mod:`cosim.bench.pour_compare`)."""
    out = []
    for s in plan.skips:
        a, b = results[s.skip], results[s.full]
        entry = {"name": s.name, "setting": s.setting, "skip": s.skip, "full": s.full}
        if a["status"] == "ok" and b["status"] == "ok":
            skip_cost, full_cost = a["wall_s"] / a["sim_s"], b["wall_s"] / b["sim_s"]
            entry.update(skip_cost=skip_cost, full_cost=full_cost, speedup=b["wall_s"] / a["wall_s"],
                         sim_skip=a["sim_s"], sim_full=b["sim_s"],
                         wall_skip=a["wall_s"], wall_full=b["wall_s"], errors=compare_pours(a, b))
        else:
            entry["failed"] = "; ".join(r.get("message", "") for r in (a, b) if r["status"] != "ok")
        out.append(entry)
    return out


def _fmt(x: float, digits: int = 3) -> str:
    return "" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{digits}g}"


def rows_csv(rows: list[Row]) -> str:
    """The rows as CSV text (:data:`CSV_COLUMNS`)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_COLUMNS)
    for r in rows:
        c = r.config
        w.writerow([c.case.value, c.dim, c.particles_across, c.kernel.value, c.cfl, c.pressure_solver.value,
                    "" if c.density_tolerance is None else c.density_tolerance, c.device,
                    c.length, " ".join(f"{k}={v}" for k, v in c.options), r.status if not r.message else f"{r.status}: {r.message}",
                    r.particles, _fmt(r.sim_s, 6), _fmt(r.wall_s, 6), _fmt(r.wall_per_sim_s, 6),
                    *(_fmt(r.errors.get(name, math.nan), 6) for name in ERROR_TITLES), r.compared_with, r.key])
    return buf.getvalue()


def _scored(rows: list[Row], case: BenchCase, error: str, device: str) -> list[Row]:
    """The rows of ``case`` on ``device`` with a finite ``error``."""
    return [r for r in rows if r.config.case is case and r.config.device == device and math.isfinite(r.errors.get(error, math.nan))]


def front_members(rows: list[Row], case: BenchCase, error: str, device: str = "cpu") -> list[Row]:
    """The rows of ``case`` on ``device`` on the Pareto front of (wall s per simulated s, ``error``)."""
    pool = _scored(rows, case, error, device)
    return [pool[i] for i in pareto_front([(r.wall_per_sim_s, r.errors[error]) for r in pool])]


def _describe(cfg: BenchConfig, default: BenchConfig) -> str:
    """What distinguishes ``cfg`` from the case's default configuration."""
    diffs = []
    if cfg.particles_across != default.particles_across:
        diffs.append(f"{cfg.particles_across} across")
    for name in ("dim", "kernel", "cfl", "pressure_solver", "density_tolerance", "smoothing_ratio", "device"):
        a, b = getattr(cfg, name), getattr(default, name)
        if a != b:
            diffs.append(f"{name} {getattr(a, 'value', a)}")
    diffs += [f"{k} = {v}" for k, v in cfg.options if (k, v) not in default.options]
    diffs += [f"{k} unset" for k, v in default.options if k not in dict(cfg.options)]
    if cfg.length != default.length:
        diffs.append(f"length {cfg.length:g}")
    return ", ".join(diffs) or "**default**"


def markdown(plan: BenchPlan, results: dict[BenchConfig, dict], rows: list[Row], skips: list[dict], plots: dict[BenchCase, str],
             header: str) -> str:
    """The generated part of docs/benchmarks.md: per case a table (fastest first) with the Pareto membership and
    the plot, then the skip options."""
    loads = [raw["load_average"] for raw in results.values() if "load_average" in raw]
    out = [header]
    if loads:
        out.append(f"1-minute load average after each computed row: {min(loads):.1f} to {max(loads):.1f} "
                   f"(on {os.cpu_count()} logical cores; above that, other jobs shared the CPU and the wall times are longer). "
                   f"CPU rows split each substep over one thread per core this process may use ({available_cores()} here), at most "
                   f"one per {MIN_PARTICLES_PER_LANE} particles (`fluid.cpu_threads` = 0), unless a row sets it.\n")
    for case, errors in CASE_ERRORS.items():
        case_rows = sorted((r for r in rows if r.config.case is case), key=lambda r: (r.config.device, r.wall_per_sim_s))
        if not case_rows:
            continue
        default = plan.defaults[case]
        fronts = {e: {id(r) for d in {r.config.device for r in case_rows} for r in front_members(rows, case, e, d)} for e in errors}
        out.append(f"\n### {case.value}\n")
        if case is BenchCase.POUR and plan.reference is not None:
            ref = results.get(plan.reference) or {}
            ended = f"; the reference simulated {ref['sim_s']:.2f} s" if ref.get("status") == "ok" else ""
            held = ", ".join(f"{k} = {v:g}" for k, v in plan.reference.options)
            out.append(f"Errors against the reference pour `{plan.reference.label}`, whole pours: each row ends when its pour is "
                       f"done, at most {plan.reference.length:g} s{ended} (cosim.bench.pour_compare). Every pour row holds "
                       f"the default scene's CFS head ({held}; cosim.bench.plan.equal_head_options).\n")
        out.append("| configuration | particles | simulated s | wall s | wall s per simulated s | "
                   + " | ".join(ERROR_TITLES[e] for e in errors) + " |")
        out.append("|---" * (4 + len(errors) + 1) + "|")
        for r in case_rows:
            desc = _describe(r.config, default)
            if r.config == plan.reference:
                desc += " (reference)"
            if r.status != "ok":
                out.append(f"| {desc} | | | | failed: {r.message} |" + " |" * len(errors))
                continue
            cells = []
            for e in errors:
                v = r.errors.get(e, math.nan)
                cells.append(("**" + _fmt(v) + "**") if id(r) in fronts[e] else _fmt(v))
            out.append(f"| {desc} | {r.particles} | {r.sim_s:.3g} | {r.wall_s:.3g} | {r.wall_per_sim_s:.3g} | " + " | ".join(cells) + " |")
        on_front = [ERROR_TITLES[e] for e in errors if any(r.config == default and id(r) in fronts[e] for r in case_rows)]
        out.append(f"\nBold: on the Pareto front of wall time against that error. The default configuration "
                   f"({default.particles_across} across, {default.kernel.value}, CFL {default.cfl:g}, "
                   f"{default.pressure_solver.value}) is on the front for: {', '.join(on_front) if on_front else 'none of them'}.\n")
        if case in plots:
            out.append(f"![{case.value}: wall time against error]({plots[case]})\n")
    if skips:
        out.append("\n### Skip options (pour)\n")
        out.append("Each pair differs only in the option; the error columns compare the run that skips with the one "
                   "that does the full work.\n")
        out.append("| option | setting | at | simulated s (skip / full) | wall s per simulated s (skip / full) | speed-up (wall s full / skip) | "
                   + " | ".join(ERROR_TITLES[e] for e in POUR_ERRORS) + " |")
        out.append("|---" * (6 + len(POUR_ERRORS)) + "|")
        for s in skips:
            at = f"{s['skip'].particles_across} across, at most {s['skip'].length:g} s"
            if "failed" in s:
                out.append(f"| {s['name']} | `{s['setting']}` | {at} | failed: {s['failed']} |" + " |" * (2 + len(POUR_ERRORS)))
                continue
            errs = " | ".join(_fmt(s["errors"][e]) for e in POUR_ERRORS)
            out.append(f"| {s['name']} | `{s['setting']}` | {at} | {s['sim_skip']:.3g} / {s['sim_full']:.3g} | "
                       f"{s['skip_cost']:.3g} / {s['full_cost']:.3g} | "
                       f"{s['speedup']:.2f}x | {errs} |")
    return "\n".join(out) + "\n"


def plot_case(rows: list[Row], case: BenchCase, default: BenchConfig, path: Path) -> bool:
    """Pareto plot of ``case`` (one panel per error, wall s per simulated s against the error, log-log); False when
    no row of the case has errors."""
    errors = [e for e in CASE_ERRORS[case] if any(_scored(rows, case, e, d) for d in ("cpu", "cuda"))]
    if not errors:
        return False
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cols = min(2, len(errors))
    rows_n = math.ceil(len(errors) / cols)
    fig, axes = plt.subplots(rows_n, cols, figsize=(6.0 * cols, 4.4 * rows_n), dpi=100, squeeze=False)
    for ax, e in zip(axes.ravel(), errors):
        for device, marker in (("cpu", "o"), ("cuda", "s")):
            pool = _scored(rows, case, e, device)
            if not pool:
                continue
            x = [max(r.errors[e], 1e-6) for r in pool]
            y = [r.wall_per_sim_s for r in pool]
            ax.scatter(x, y, marker=marker, color="0.55", s=22, label=f"{device}")
            front = front_members(rows, case, e, device)
            ax.plot([max(r.errors[e], 1e-6) for r in front], [r.wall_per_sim_s for r in front], "-", color="C0", lw=1.2,
                    label=f"Pareto front ({device})")
            for r, xi, yi in zip(pool, x, y):
                ax.annotate(_describe(r.config, default).replace("**", ""), (xi, yi), fontsize=6, xytext=(3, 2),
                            textcoords="offset points")
                if r.config == default:
                    ax.scatter([xi], [yi], marker="*", s=140, color="C3", zorder=3, label="default")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(ERROR_TITLES[e])
        ax.set_ylabel("wall s per simulated s")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    fig.suptitle(f"cosim bench: {case.value}")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)
    return True


GENERATED_BEGIN = "<!-- cosim bench: generated, begin -->"
GENERATED_END = "<!-- cosim bench: generated, end -->"


def update_document(path: Path, generated: str, begin: str = GENERATED_BEGIN, end: str = GENERATED_END) -> None:
    """Put ``generated`` between the markers ``begin`` and ``end`` in ``path`` (kept text outside them); without
    markers the block goes after the document's first heading; a missing file is created."""
    text = path.read_text() if path.exists() else "# Benchmarks\n"
    block = f"{begin}\n{generated.strip()}\n{end}"
    if begin in text and end in text:
        head, rest = text.split(begin, 1)
        text = head + block + rest.split(end, 1)[1]
    else:
        first, _, rest = text.partition("\n")
        text = f"{first}\n\n{block}\n{rest}"
    write_text_atomic(path, text)
