"""The pour's own discharge coefficient: its outflow rate against its head over the crest in CFS.

    python -m cosim.bench.pour_outflow RUN [--window S] [--crest-length M] [--json]

Reads a run folder of ``cosim pour`` (series.csv: the controller's ``h_q``, m, the liquid's height over the crest,
and ``volume_in_pourer``, m^3, every control step; summary.json) and fits the coefficient C_d of the sharp-crested
weir law the catcher's placement assumes (``catcher.discharge_coefficient``, 0.6):

    Q = (2/3) C_d sqrt(2 g) L h_q^(3/2)

Q being the pourer's outflow (m^3/s) and L the crest length (m, the pourer's inner depth). The CFS phase is cut into
consecutive windows of ``window`` s in which every sample has a measured head (the probe reports -inner height for a
vessel too empty to have a surface, and heads outside +-CFS_MAX_HEAD are not CFS heads); in each window the volume
that left, dV, is set against the integral of h_q^(3/2) over the window. The fit is their ratio over all windows,

    C_d = sum dV / ((2/3) sqrt(2 g) L sum integral h_q^(3/2) dt),

the least-squares fit of dV weighted by the window's outflow; negative heads count as no head (no outflow
predicted). A window must be long enough to hold a few particles' volume (one particle of the default 2-D scene
is 3.6 mL, about 0.13 s of the default pour's CFS outflow), so the per-window coefficients, reported as median and
interquartile range, scatter by the count's steps; the ratio does not.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from controllers.config import CFS_MAX_HEAD
from cosim.checks import check_positive
from cosim.coupling.outflow import RATE_WINDOW
from cosim.errors import InputError
from cosim.fluid.config import GRAVITY


@dataclass(frozen=True)
class DischargeFit:
    """coefficient: the fitted C_d. windows: windows used. outflow: m^3 that left in them. median, q1, q3: the
    per-window coefficients' median and quartiles (windows with a mean head above zero). mean_head: m, the
    outflow-weighted mean head, (sum integral h^(3/2) dt / sum duration)^(2/3). crest_length: m. window: s."""

    coefficient: float
    windows: int
    outflow: float
    median: float
    q1: float
    q3: float
    mean_head: float
    crest_length: float
    window: float


def weir_factor(crest_length: float, gravity: float = GRAVITY) -> float:
    """(2/3) sqrt(2 g) L (m^(3/2)/s): the weir law's Q / (C_d h^(3/2))."""
    return (2.0 / 3.0) * math.sqrt(2.0 * gravity) * crest_length


def fit_discharge_coefficient(
    t: np.ndarray, h_q: np.ndarray, volume_in_pourer: np.ndarray, in_cfs: np.ndarray, crest_length: float, window: float = RATE_WINDOW
) -> DischargeFit:
    """C_d of Q = (2/3) C_d sqrt(2 g) L h_q^(3/2) from control-step series (module docstring): ``t`` s, ``h_q`` m,
    ``volume_in_pourer`` m^3, ``in_cfs`` bool, ``crest_length`` L m, ``window`` s. NaN where no window qualifies."""
    t, h_q, volume = (np.asarray(a, float) for a in (t, h_q, volume_in_pourer))
    usable = np.asarray(in_cfs, bool) & (np.abs(h_q) < CFS_MAX_HEAD)
    dt = float(np.median(np.diff(t))) if len(t) > 1 else math.nan
    n = max(1, round(window / dt)) if math.isfinite(dt) else 1
    head15 = np.clip(h_q, 0.0, None) ** 1.5
    outflows, integrals, durations = [], [], []
    k = 0
    while k + n < len(t):
        if usable[k : k + n + 1].all():
            outflows.append(volume[k] - volume[k + n])
            integrals.append(float(np.trapezoid(head15[k : k + n + 1], t[k : k + n + 1])))
            durations.append(t[k + n] - t[k])
            k += n
        else:
            k += 1
    outflow, integral = np.array(outflows), np.array(integrals)
    factor = weir_factor(crest_length)
    if len(outflow) == 0 or integral.sum() <= 0.0:
        return DischargeFit(math.nan, len(outflow), float(outflow.sum()), math.nan, math.nan, math.nan, math.nan, crest_length, window)
    headed = integral > 0.0
    each = outflow[headed] / (factor * integral[headed])
    q1, median, q3 = np.percentile(each, [25, 50, 75])
    mean_head = (integral.sum() / sum(durations)) ** (2.0 / 3.0)
    return DischargeFit(
        float(outflow.sum() / (factor * integral.sum())), len(outflow), float(outflow.sum()), float(median), float(q1), float(q3),
        float(mean_head), crest_length, window,
    )


def crest_length_of(summary: dict) -> float:
    """m, the pourer's crest length: in 2-D the pour plane's out-of-plane depth, which is the initial volume over
    the particle count times dx^2 (each 2-D particle holds dx^2 times that depth)."""
    if summary["dim"] != 2:
        raise InputError("--crest-length: needed for a 3-D run (m, the pourer's inner depth), in (0, 2]")
    return summary["initial_volume"] / (summary["particles"] * summary["particle_spacing"] ** 2)


def fit_run(folder: Path, window: float = RATE_WINDOW, crest_length: float | None = None) -> DischargeFit:
    """The fit of one run folder's series.csv over its CFS phase."""
    try:
        summary = json.loads((folder / "summary.json").read_text())
        with open(folder / "series.csv", newline="") as f:
            rows = list(csv.DictReader(f))
        length = crest_length_of(summary) if crest_length is None else crest_length
        t, h_q, volume = (np.array([float(r[name]) for r in rows]) for name in ("t", "h_q", "volume_in_pourer"))
        in_cfs = np.array([r["phase"] == "cfs" for r in rows])
    except InputError:
        raise
    except (OSError, ValueError, KeyError, TypeError) as err:
        raise InputError(f"RUN: {folder} is not a readable run folder of `cosim pour` ({type(err).__name__}: {err})") from None
    return fit_discharge_coefficient(t, h_q, volume, in_cfs, length, window)


def report(fit: DischargeFit, assumed: float) -> str:
    """Plain-text lines: the fit against the coefficient the catcher assumes."""
    return "\n".join([
        f"windows: {fit.windows} of {fit.window:g} s in CFS, {1e6 * fit.outflow:.1f} mL, mean head {1e3 * fit.mean_head:.2f} mm, "
        f"crest length {fit.crest_length:.4g} m",
        f"C_d fitted: {fit.coefficient:.3f} (per window: median {fit.median:.3f}, IQR {fit.q1:.3f}..{fit.q3:.3f})",
        f"C_d assumed by the catcher's weir estimate: {assumed:.3f} ({100 * (fit.coefficient - assumed) / assumed:+.1f} %)",
    ])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.bench.pour_outflow", description=__doc__.split("\n")[0])
    parser.add_argument("run", type=Path, help="a run folder of `cosim pour` (series.csv, summary.json)")
    parser.add_argument("--window", type=float, default=RATE_WINDOW, help=f"s, window length (default {RATE_WINDOW:g})")
    parser.add_argument("--crest-length", type=float, help="m, the crest length (default: the 2-D run's depth)")
    parser.add_argument("--json", action="store_true", help="print the fit as JSON")
    args = parser.parse_args(argv)
    try:
        check_positive("--window", args.window, "s", 10.0)
        if args.crest_length is not None:
            check_positive("--crest-length", args.crest_length, "m", 2.0)
        fit = fit_run(args.run, args.window, args.crest_length)
        summary = json.loads((args.run / "summary.json").read_text())
        try:
            assumed = float(summary["scene"]["controller"]["catcher"]["discharge_coefficient"])
        except (KeyError, TypeError, ValueError):
            raise InputError(f"RUN: {args.run / 'summary.json'} has no scene.controller.catcher.discharge_coefficient") from None
    except InputError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(json.dumps(dict(asdict(fit), assumed=assumed)) if args.json else report(fit, assumed))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
