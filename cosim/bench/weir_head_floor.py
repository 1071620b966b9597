"""The smallest head over a crest that the liquid resolves: the weir case at heads of a few particle spacings.

    python -m cosim.bench.weir_head_floor [--across 32] [--spacings 2,2.5,3,4] [--duration 3.2] [--dim 2|3]
                                          [--depth 0.1] [--json]

The pour's constant-flow stage holds the liquid's height over the pourer's crest at a floor of
``controller.stream_particles`` particle spacings (:data:`cosim.pour_scene.STREAM_PARTICLES`): the paper's 5 mm
head is under one spacing at the default resolution, and a head of a fraction of a spacing is not a flow the liquid
resolves. This study measures where the resolved range starts, on the outflow validation rather than on a pour: the
sharp-crested weir (:mod:`cosim.validation.weir`) at the spacing of ``--across`` particles across the default
pourer's 0.191 m, at nominal heads of each of ``--spacings`` spacings, each run for ``--duration`` s and measured
over its second half (3.2 s by default, twice the weir case's 1.6 s, over which the channel still drains:
docs/walls.md). ``--dim 3`` runs the 3-D channel, ``--depth`` m wide (default the default pourer's 0.10 m, the width
of the sheet a 3-D pour sends over its lip). Per head: the measured head,
the discharge against the piston's supply, the discharge coefficient against Rehbock's (the case's 5 %
tolerance), and how high the nappe's lower surface rises above the crest against Bazin's 0.112 H (reported:
the case checks it at its own resolution). The floor it reports is the smallest head from which on every head run
is within the tolerance.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass

from cosim.bench.fluid_throughput import machine_description
from cosim.errors import InputError
from cosim.validation import weir
from cosim.validation.common import whole_spacings
from cosim.vessel import VesselSpec

POURER_WIDTH = 0.191  # m, the default pourer's inner width, which particles_across divides
POURER_DEPTH = VesselSpec().inner_depth  # m, the default pourer's: the width of the sheet over its lip in a 3-D pour


@dataclass(frozen=True)
class HeadRun:
    """One weir run at a nominal head of ``spacings`` particle spacings."""

    spacings: float
    nominal_head: float  # m
    head: float  # m, measured over the window
    discharge_over_supply: float
    coefficient_error: float  # C_d / C_Rehbock(H) - 1
    head_drift: float  # m, over the window
    nappe_rise: float  # m, the nappe's lower surface's highest point above the crest (weir.Nappe)
    particles: int
    wall_time: float  # s

    @property
    def passed(self) -> bool:
        return abs(self.coefficient_error) <= weir.COEFFICIENT_TOLERANCE


def resolved_floor(runs: list[HeadRun]) -> float | None:
    """The smallest head (spacings) from which on every run passes the weir's tolerance; None if the largest fails."""
    floor = None
    for run in sorted(runs, key=lambda r: r.spacings, reverse=True):
        if not run.passed:
            break
        floor = run.spacings
    return floor


def run_head(spacings: float, spacing: float, duration: float, dim: int = 2, depth: float = POURER_DEPTH) -> HeadRun:
    """The weir case at a nominal head of ``spacings`` x ``spacing`` (m), ``duration`` s, measured over its second half;
    in 3-D (``dim``) in a channel ``depth`` m wide."""
    p = weir.Params(head=spacings * spacing, spacing=spacing, duration=duration, window=0.5 * duration, dim=dim, depth=depth)
    r = weir.run(p)
    supply = weir.piston_speed(p.head, p.crest_height) * (p.crest_height + p.head)
    return HeadRun(spacings, p.head, r.raw["head"], r.raw["discharge"] / supply, r.raw["coefficient"] / r.raw["rehbock"] - 1.0,
                   r.raw["head_drift_in_window"], r.raw["nappe_rise"], r.raw["particles"], r.wall_time)


def parse_spacings(text: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        values = []
    if not values or any(v < weir.MIN_HEAD_SPACINGS or v > 20.0 for v in values):
        raise InputError(f"--spacings: a comma-separated list of heads in particle spacings, each in "
                         f"[{weir.MIN_HEAD_SPACINGS:g}, 20], got {text!r}")
    return sorted(set(values))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m cosim.bench.weir_head_floor", description=__doc__.split("\n\n")[0])
    ap.add_argument("--across", type=int, default=32, help="particles across the default pourer's 0.191 m (default 32)")
    ap.add_argument("--spacings", default="2,2.5,3,4", help="nominal heads in particle spacings (default 2,2.5,3,4)")
    ap.add_argument("--duration", type=float, default=3.2, help="simulated s per head, measured over the second half (default 3.2)")
    ap.add_argument("--dim", type=int, default=2, help="2: the 2-D channel (default); 3: the 3-D channel")
    ap.add_argument("--depth", type=float, default=POURER_DEPTH,
                    help=f"3-D: the channel's width across the flow, m, rounded to whole spacings (default {POURER_DEPTH:g})")
    ap.add_argument("--json", action="store_true", help="print the runs as JSON")
    args = ap.parse_args(argv)
    try:
        if not 8 <= args.across <= 128:
            raise InputError(f"--across: particles across the pourer, an integer in [8, 128], got {args.across}")
        if not 0.4 <= args.duration <= 10.0:
            raise InputError(f"--duration: simulated s per head, in [0.4, 10], got {args.duration:g}")
        heads = parse_spacings(args.spacings)
        if args.dim not in (2, 3):
            raise InputError(f"--dim: 2 or 3, got {args.dim}")
        spacing = POURER_WIDTH / args.across
        for n in heads:  # the weir's own checks (the head in spacings, the 3-D channel's width), before any run
            weir.Params(head=n * spacing, spacing=spacing, dim=args.dim, depth=args.depth)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    runs = [run_head(n, spacing, args.duration, args.dim, args.depth) for n in heads]
    floor = resolved_floor(runs)
    if args.json:
        print(json.dumps({"across": args.across, "spacing": spacing, "duration": args.duration, "dim": args.dim,
                          **({"depth": whole_spacings(args.depth, spacing)} if args.dim == 3 else {}),
                          "floor_spacings": floor,
                          "runs": [dict(r.__dict__, passed=r.passed) for r in runs]}, indent=2))
        return 0
    print(f"Machine: {machine_description()}. Command: `python -m cosim.bench.weir_head_floor "
          f"{' '.join(argv if argv is not None else sys.argv[1:])}`.\n")
    channel = "2-D" if args.dim == 2 else f"3-D, the channel {1e3 * whole_spacings(args.depth, spacing):.1f} mm wide"
    print(f"The weir ({channel}) at dx = {spacing * 1e3:.2f} mm ({args.across} across the pourer), {args.duration:g} s a head, "
          "measured over the second half; C_d against Rehbock's within 5 %.\n")
    print("| head, spacings | nominal head (mm) | measured head (mm) | discharge / supply | C_d error | head's drift (mm) | "
          f"nappe's rise (mm; {weir.NAPPE_RISE:g} H) | particles | verdict |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in runs:
        print(f"| {r.spacings:g} | {r.nominal_head * 1e3:.2f} | {r.head * 1e3:.2f} | {r.discharge_over_supply:.3f} | "
              f"{r.coefficient_error * 100:+.2f} % | {r.head_drift * 1e3:+.2f} | {r.nappe_rise * 1e3:.2f} ({weir.NAPPE_RISE * r.head * 1e3:.2f}) | "
              f"{r.particles} | {'pass' if r.passed else 'FAIL'} |")
    print(f"\nResolved from {floor:g} spacings on." if floor is not None else "\nNo head run here is resolved.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
