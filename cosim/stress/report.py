"""The stability report from the result rows: Markdown (summary per outcome and per axis, the command line, one
row per configuration) and a plot (max density error and created energy per configuration, coloured by outcome)."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path

from cosim.atomic_files import atomic_path, write_text_atomic
from cosim.stress.classify import DENSITY_ERROR_BOUND, ENERGY_EXCESS_BOUND, Outcome
from cosim.stress.matrix import CARRY_TIME, DEFAULT_CFL, DURATION

OUTCOME_COLOURS = {"clean": "tab:green", "instability": "tab:orange", "silent": "tab:red", "refused": "tab:gray",
                   "error": "tab:purple"}
AXES = [("motion", "motion"), ("level", "level (rad/s, m or m/s)"), ("fill", "fill (of the height)"),
        ("across", "particles across"), ("layers", "particle layers of liquid"), ("cfl_factor", "CFL factor"), ("dim", "dim"), ("solver", "solver")]
OUTCOMES = [o.value for o in Outcome]


def _fmt(value, digits: int = 3) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    return str(value)


def _axis_table(rows: list[dict], key: str, title: str) -> list[str]:
    values = sorted({r[key] for r in rows}, key=lambda v: (isinstance(v, str), v))
    lines = [f"| {title} | " + " | ".join(OUTCOMES) + " |", "|---" * (len(OUTCOMES) + 1) + "|"]
    for v in values:
        counts = Counter(r["outcome"] for r in rows if r[key] == v)
        lines.append(f"| {_fmt(v)} | " + " | ".join(str(counts.get(o, 0)) for o in OUTCOMES) + " |")
    return lines


def markdown(rows: list[dict], commands: list[str]) -> str:
    """The whole stability page."""
    counts = Counter(r["outcome"] for r in rows)
    wall = sum(r["wall_time"] for r in rows if not math.isnan(r["wall_time"]))
    lines = [
        "# Numerical stability matrix",
        "",
        f"{len(rows)} configurations of the SPH liquid in the pouring vessel of Camporredondo et al. (2019) "
        "(0.191 x 0.1 x 0.191 m), each "
        f"simulated for {DURATION:g} s under a scripted motion: `tilt` about the pour lip at a constant rate (rad/s) "
        "up to 90 deg, `shake` sideways at the first sloshing mode (the paper's Eq. 17) with an amplitude (m), `carry` "
        f"sideways with a cosine speed profile reaching a peak speed (m/s) and stopping after {CARRY_TIME:g} s. "
        "Axes: fill (fraction of the inner height), particles across the inner width (dx = 0.191 m / across), "
        f"CFL factor (x the default Courant number {DEFAULT_CFL:g}), dimension and pressure solver. See `cosim stress --help` "
        "and `cosim/stress/` for the definitions.",
        "",
        "Outcomes: **clean**; **instability** (the solver stopped with its clear `FluidInstabilityError`; its "
        "message is in the table); **silent** (finished, but garbage: non-finite values, a leaked particle -- "
        "inside or through a wall, or out of the vessel where the motion cannot spill --, "
        f"|rho - rho0| / rho0 > {DENSITY_ERROR_BOUND:g}, or energy created by the numerics "
        f"(E - E0 - W) / (M g L) > {ENERGY_EXCESS_BOUND:g}); **refused** (the solver refused the configuration at "
        "set-up with its one-line input error: a liquid fewer than 3 particle layers deep or 4 across, which the "
        "particles cannot resolve; the message is in the table); **error** (an unexpected exception). "
        "Silent and error must be 0.",
        "",
        "## Summary",
        "",
        "| outcome | configurations |",
        "|---|---|",
        *[f"| {o} | {counts.get(o, 0)} |" for o in OUTCOMES],
        "",
        f"Total wall time {wall / 60:.1f} min (sum over configurations).",
        "",
        "Produced by:",
        "",
        "```",
        *commands,
        "```",
        "",
        "## Per axis",
        "",
    ]
    for key, title in AXES:
        lines += _axis_table(rows, key, title) + [""]
    lines += [
        "## Configurations",
        "",
        "Columns: particles; leaked particles; max |rho - rho0| / rho0; energy created (E - E0 - W) / (M g L) at "
        "its maximum, final energy change and wall work, same unit; smallest substep / the planned step at rest; "
        "largest particle speed / the expected maximum speed that sets c0 (v/v_max); "
        "wall-guard corrections; fraction spilled out of the domain; wall time (s).",
        "",
        "| id | motion | level | fill | across | layers | CFL x | dim | solver | particles | outcome | leaked | rho err "
        "| E created | dE | W | dt min/nom | v/v_max | guard | spilled | wall s | message |",
        "|---" * 22 + "|",
    ]
    for r in rows:
        cells = [r["id"], r["motion"], _fmt(r["level"]), _fmt(r["fill"]), r["across"], r["layers"], _fmt(r["cfl_factor"]), r["dim"],
                 r["solver"], _fmt(r["particles"]), f"**{r['outcome']}**" if r["outcome"] in ("silent", "error") else r["outcome"],
                 _fmt(r["leaked"]), _fmt(r["max_density_error"]), _fmt(r["energy_excess"]), _fmt(r["energy_change"]),
                 _fmt(r["work_in"]), _fmt(r["dt_ratio_min"]), _fmt(r["speed_ratio"]), _fmt(r["guard_corrections"]), _fmt(r["spilled_fraction"], 2),
                 _fmt(r["wall_time"], 2), (r["message"] or "").replace("|", "/")]
        lines.append("| " + " | ".join(str(c) for c in cells) + " |")
    return "\n".join(lines) + "\n"


def plot(rows: list[dict], path) -> None:
    """Two panels over the configurations (matrix order): max density error and created energy, log scale,
    coloured by outcome, with the silent-failure bounds."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(11, 7), dpi=110, sharex=True)
    floor = 1e-4
    for ax, key, bound, label in (
        (axes[0], "max_density_error", DENSITY_ERROR_BOUND, "max |rho - rho0| / rho0"),
        (axes[1], "energy_excess", ENERGY_EXCESS_BOUND, "energy created (E - E0 - W) / (M g L)"),
    ):
        for outcome in OUTCOMES:
            idx = [i for i, r in enumerate(rows) if r["outcome"] == outcome and not math.isnan(r[key])]
            if idx:
                ax.scatter(idx, [max(rows[i][key], floor) for i in idx], s=12, c=OUTCOME_COLOURS[outcome],
                           label=f"{outcome} ({len(idx)})")
        ax.axhline(bound, color="k", ls="--", lw=0.8, label=f"silent-failure bound {bound:g}")
        ax.set_yscale("log")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=8, loc="upper left")
    axes[0].set_title(f"Stability matrix: {len(rows)} configurations (values below {floor:g} drawn at {floor:g})")
    axes[1].set_xlabel("configuration (matrix order: solver, dim, resolution, CFL, motion, fill)")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)


def write_report(rows: list[dict], commands: list[str], folder) -> None:
    """stability.md and stability.png into ``folder`` (atomically)."""
    folder = Path(folder)
    write_text_atomic(folder / "stability.md", markdown(rows, commands))
    plot(rows, folder / "stability.png")
