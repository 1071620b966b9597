"""The stream's landing at equal poured fractions, split into where it leaves and how far it is thrown.

    python -m cosim.bench.landing_bands RUN [RUN ...] [--reference RUN] [--json]

Reads run folders of ``cosim pour`` (series.csv, summary.json: :mod:`cosim.io.pour_series`). Pours of one scene
at different resolutions or settings pour at different rates, so their landings are compared at equal poured
fractions, not at equal times. Per band of the poured fraction (poured volume over the initial volume, ``BANDS``),
over the control steps at which the stream crossed the catcher's rim plane, the medians of

* ``landing``: ``landing_measured_x``, m, the world x at which the stream crosses the rim plane;
* ``lip``: ``lip_x``, m, the world x of the pourer's lip at that step: where the controller's path has put the
  vessel (its pivots change between the stages, so the lip's place at a given fraction depends on the path);
* ``throw``: landing less lip, m, per step: how far the stream carries from the lip, which the liquid sets (its
  outflow speed over the crest and its fall to the rim);
* ``tilt`` rad, ``v_q`` m/s (the outflow speed the probe measures) and ``h_q`` m (the head over the crest).

The medians of landing, lip and throw need not add up exactly (a median of differences is not the difference of
medians). With ``--reference``, each band's landing, lip and throw are also given less the reference run's. Also
reported: the time from 10 to 90 % poured, s.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from cosim.errors import InputError
from cosim.io.pour_series import read_series_csv

BANDS = ((0.1, 0.3), (0.3, 0.5), (0.5, 0.7), (0.7, 0.9))  # poured fraction of the initial volume
BAND_KEYS = ("landing", "lip", "throw", "tilt", "v_q", "h_q")


@dataclass(frozen=True)
class RunBands:
    """name: the run folder's name. bands: per band of BANDS, the medians named in BAND_KEYS (m, rad, m/s; NaN
    where no step of that band has a landing) and ``steps``, the steps they are taken over. pour_time: s,
    from 10 to 90 % of the initial volume poured (NaN if the pour never reached 90 %)."""

    name: str
    bands: list[dict[str, float]]
    pour_time: float


def band_medians(series: dict[str, list], initial_volume: float) -> tuple[list[dict[str, float]], float]:
    """Per band of BANDS the medians of BAND_KEYS over the steps with a landing, and the time (s) from 10
    to 90 % poured, from a series.csv's columns and the initial volume (m^3)."""
    col = {c: np.asarray(series[c], float) for c in ("t", "poured_volume", "landing_measured_x", "lip_x", "tilt", "v_q", "h_q")}
    fraction = col["poured_volume"] / initial_volume
    landed = np.isfinite(col["landing_measured_x"])
    values = {
        "landing": col["landing_measured_x"], "lip": col["lip_x"], "throw": col["landing_measured_x"] - col["lip_x"],
        "tilt": col["tilt"], "v_q": col["v_q"], "h_q": col["h_q"],
    }
    bands = []
    for lo, hi in BANDS:
        mask = landed & (fraction >= lo) & (fraction < hi)
        row = {k: float(np.nanmedian(v[mask])) if mask.any() else math.nan for k, v in values.items()}
        row["steps"] = int(mask.sum())
        bands.append(row)
    reached = [np.flatnonzero(fraction >= q) for q in (0.1, 0.9)]
    pour_time = float(col["t"][reached[1][0]] - col["t"][reached[0][0]]) if all(len(r) for r in reached) else math.nan
    return bands, pour_time


def read_run(folder: Path) -> RunBands:
    """The band medians of one run folder."""
    try:
        summary = json.loads((folder / "summary.json").read_text())
        series = read_series_csv(folder / "series.csv")
        bands, pour_time = band_medians(series, float(summary["initial_volume"]))
    except (OSError, ValueError, KeyError, TypeError) as err:
        raise InputError(f"RUN: {folder} is not a readable run folder of `cosim pour` ({type(err).__name__}: {err})") from None
    return RunBands(folder.name, bands, pour_time)


def _mm(x: float) -> str:
    return "-" if math.isnan(x) else f"{1e3 * x:.1f}"


def report(runs: list[RunBands], reference: RunBands | None) -> str:
    """Markdown: one table of landing = lip + throw per band, and with a reference one of the differences."""
    heads = " | ".join(f"{100 * lo:.0f}-{100 * hi:.0f} %" for lo, hi in BANDS)
    lines = [
        "Landing, mm: landing median (lip median + throw median), by poured-volume band; tilt rad and v_q m/s beside.",
        "", f"| run | {heads} | 10 to 90 % poured (s) |", "|---|" + "---|" * (len(BANDS) + 1),
    ]
    for run in runs:
        cells = [
            f"{_mm(b['landing'])} ({_mm(b['lip'])} + {_mm(b['throw'])}); {b['tilt']:.3f} rad, {b['v_q']:.3f} m/s" for b in run.bands
        ]
        lines.append(f"| {run.name} | " + " | ".join(cells) + f" | {run.pour_time:.2f} |")
    if reference is not None:
        lines += [
            "", f"Less the reference run {reference.name}, mm: landing (lip, throw).", "",
            f"| run | {heads} |", "|---|" + "---|" * len(BANDS),
        ]
        for run in runs:
            cells = [
                " ".join([f"{1e3 * (b['landing'] - r['landing']):+.1f}", f"({1e3 * (b['lip'] - r['lip']):+.1f},",
                          f"{1e3 * (b['throw'] - r['throw']):+.1f})"])
                for b, r in zip(run.bands, reference.bands)
            ]
            lines.append(f"| {run.name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.bench.landing_bands", description=__doc__.split("\n")[0])
    parser.add_argument("runs", type=Path, nargs="+", help="run folders of `cosim pour` (series.csv, summary.json)")
    parser.add_argument("--reference", type=Path, help="a run folder to give each band's differences against")
    parser.add_argument("--json", action="store_true", help="print the medians as JSON")
    args = parser.parse_args(argv)
    try:
        runs = [read_run(folder) for folder in args.runs]
        reference = read_run(args.reference) if args.reference is not None else None
    except InputError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps({"bands": BANDS, "runs": [asdict(r) for r in runs],
                          "reference": asdict(reference) if reference else None}, indent=1))
    else:
        print(report(runs, reference))
    return 0


if __name__ == "__main__":
    sys.exit(main())
