"""``cosim bench``: wall time against error for the solver's resolutions and numerics, and the scenes' skip options.

For each configuration of the plan (:mod:`cosim.bench.plan`: dimension, particles across, kernel, CFL number,
smoothing ratio h/dx, pressure solver, DFSPH's density tolerance, device) it measures the wall time per simulated
second and the errors: the validation cases (hydrostatic, slosh, dam-break, free fall, coupling-static) against
their references, the pour against a finer reference pour
(poured-volume curve, landing point, joint trajectories). Writes ``bench.csv``, ``bench.md`` and one Pareto plot
per case (``bench_<case>.png``) to ``--out``; with ``--docs FILE`` it also rewrites the generated part of that
Markdown file and puts the plots beside it. Results are cached per configuration under ``--cache`` (key: the
configuration and the simulation code's version), so a rerun, or a run after an interruption, only computes what
is missing.

``--plan targets`` measures the speed targets instead (:mod:`cosim.bench.targets`: the 3-D throughput at 1M
particles beside warp's example_sph, the 2-D steps per second at 10k, the 3-D pour's real-time factor, all on a CUDA
device when one is present; the default pour's wall time on the CPU), afresh each time, into ``targets.md`` and
``targets.json``; with ``--docs`` it rewrites that file's block for this machine's kind (cpu or cuda).

``--plan heldout`` runs the held-out pours (:mod:`cosim.bench.heldout`: every scene of ``--scenes``, default
examples/heldout, one pour at a time on one thread, no recording) and reports per scene its spill, landing error and
partial-pour error against the acceptance thresholds, PASS or FAIL, into ``heldout.md`` and ``heldout.csv``; with
``--docs`` it rewrites that file's generated block. The pours are kept under ``--cache`` (default OUT/heldout), keyed
by the scene and the simulation code, so a rerun only runs what is missing; Ctrl-C or SIGTERM stops the pour in
flight and still writes the report (the pours not run marked so). Exit status 1 when a row fails.
"""

from __future__ import annotations

import argparse
import shutil
from datetime import datetime, timezone
from pathlib import Path

from cosim.atomic_files import check_output_file, check_output_folder, write_text_atomic
from cosim.errors import InputError

DEFAULT_OUT = Path("recordings") / "bench"
PLANS = ("full", "smoke", "targets", "heldout")
HELDOUT_BEGIN, HELDOUT_END = "<!-- cosim bench heldout: generated, begin -->", "<!-- cosim bench heldout: generated, end -->"


def register(subparsers, summary: str) -> None:
    p = subparsers.add_parser("bench", help=summary, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--plan", default="full", help="which configurations: full (default), smoke (seconds, for checks), targets (the speed targets on "
                   "this machine's devices, measured afresh: no cache) or heldout (the held-out pours against their acceptance thresholds)")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, help=f"folder for bench.csv, bench.md and the plots (default {DEFAULT_OUT})")
    p.add_argument("--cache", type=Path, help="result cache folder (default OUT/cache; with --plan heldout: the pours' folder, default OUT/heldout)")
    p.add_argument("--scenes", type=Path, help="with --plan heldout: the folder of held-out scene files (default examples/heldout)")
    p.add_argument("--docs", type=Path, help="also rewrite the generated part of this Markdown file (e.g. docs/benchmarks.md), plots beside it")
    p.add_argument("--fresh", action="store_true", help="recompute every configuration (overwrites the cache)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def _machine_line() -> str:
    """'Machine: ...; CUDA .... Versions: ...' for a report's header."""
    from cosim.bench.fluid_throughput import machine_description
    from cosim.fluid.runtime import cuda_available
    from cosim.pour_run import package_versions

    versions = ", ".join(f"{k} {v}" for k, v in package_versions().items() if k != "cosim")
    cuda = "a CUDA device is present: cuda rows included" if cuda_available() else "no CUDA device here: CPU rows only"
    return f"Machine: {machine_description()}; {cuda}. Versions: {versions}."


def _header(command: str, code_versions: dict) -> str:
    return (f"## Wall time against error ({datetime.now(timezone.utc):%Y-%m-%d})\n\n{_machine_line()}\n"
            f"Command: `{command}`. Code versions (cosim.bench.cache.code_version): "
            f"{', '.join(f'{k.value} {v}' for k, v in code_versions.items())}.\n")


def _run_targets(args) -> int:
    """``--plan targets``: the speed targets measured on this machine (:mod:`cosim.bench.targets`)."""
    from cosim.bench.report import update_document
    from cosim.bench.targets import measure_all, write_report
    from cosim.fluid.runtime import cuda_available

    cuda = "cuda" if cuda_available() else None
    kind = "cuda" if cuda else "cpu"  # the docs block this machine rewrites
    command = "cosim bench --plan targets" + (f" --docs {args.docs}" if args.docs else "")
    header = (f"### Speed targets, {kind} ({datetime.now(timezone.utc):%Y-%m-%d})\n\n{_machine_line()}\n"
              f"Command: `{command}` (cosim.bench.targets: what each row measures).")
    measurements = measure_all(cuda=cuda, on_row=lambda rows: write_report(rows, header, args.out))
    text = write_report(measurements, header, args.out)
    if args.docs is not None:
        update_document(args.docs, text, f"<!-- cosim bench targets, {kind}: generated, begin -->",
                        f"<!-- cosim bench targets, {kind}: generated, end -->")
    print(text)
    print(f"wrote {args.out / 'targets.md'} and {args.out / 'targets.json'}" + (f"; updated {args.docs}" if args.docs else ""))
    return 1 if any(m.failed for m in measurements) else 0


def _run_heldout(args) -> int:
    """``--plan heldout``: the held-out pours against their acceptance thresholds (:mod:`cosim.bench.heldout`)."""
    from cosim.bench.cache import code_version
    from cosim.bench.config import BenchCase
    from cosim.bench.heldout import DEFAULT_SCENES, collect_rows, load_pours, markdown, rows_csv, run_missing
    from cosim.bench.report import update_document
    from cosim.sweep.store import SweepStore

    scenes = args.scenes if args.scenes is not None else DEFAULT_SCENES
    code = code_version(BenchCase.POUR)
    pours = load_pours(scenes, code)
    store = SweepStore(args.cache or args.out / "heldout")
    try:
        run_missing(pours, store, fresh=args.fresh, progress=not args.quiet)
    finally:  # the report of what is done, also after Ctrl-C or SIGTERM (the pours not run are rows marked so)
        rows = collect_rows(pours, store)
        command = ("cosim bench --plan heldout" + (f" --scenes {args.scenes}" if args.scenes is not None else "")
                   + (f" --docs {args.docs}" if args.docs else ""))
        header = (f"### Held-out pours ({datetime.now(timezone.utc):%Y-%m-%d})\n\n{_machine_line()}\n"
                  f"Command: `{command}`; scenes: the files of {scenes}/ (one pour each, one thread, no recording). "
                  f"Code version of the pours (cosim.bench.cache.code_version): {code}.")
        text = markdown(rows, header)
        write_text_atomic(args.out / "heldout.md", text)
        write_text_atomic(args.out / "heldout.csv", rows_csv(rows))
        if args.docs is not None:
            update_document(args.docs, text, HELDOUT_BEGIN, HELDOUT_END)
        print(text)
        print(f"wrote {args.out / 'heldout.md'} and {args.out / 'heldout.csv'}" + (f"; updated {args.docs}" if args.docs else ""))
    return 0 if all(r["passed"] for r in rows) else 1


def run(args) -> int:
    if args.plan not in PLANS:
        raise InputError(f"--plan: must be one of {', '.join(PLANS)}, got {args.plan!r}")
    if args.docs is not None and args.docs.suffix != ".md":
        raise InputError(f"--docs: must be a Markdown file (.md), got {args.docs}")
    if args.plan == "targets" and (args.cache is not None or args.fresh):
        raise InputError(f"{'--cache' if args.cache is not None else '--fresh'}: the targets plan measures afresh every time and caches nothing")
    if args.scenes is not None and args.plan != "heldout":
        raise InputError("--scenes: only with --plan heldout")
    check_output_folder(args.out, "--out")
    if args.docs is not None:
        check_output_file(args.docs, "--docs")
    if args.cache is not None:
        check_output_folder(args.cache, "--cache")
    if args.plan == "targets":
        return _run_targets(args)
    if args.plan == "heldout":
        return _run_heldout(args)
    from cosim.bench.cache import ResultCache
    from cosim.bench.plan import build_plan
    from cosim.bench.report import build_rows, markdown, plot_case, rows_csv, skip_table, update_document
    from cosim.bench.run import run_plan

    plan = build_plan(args.plan)
    cache = ResultCache(args.cache or args.out / "cache")
    outcome = run_plan(plan, cache, fresh=args.fresh, progress=not args.quiet)
    rows = build_rows(plan, outcome.results, outcome.keys)
    skips = skip_table(plan, outcome.results)
    plot_dir = args.docs.parent if args.docs is not None else args.out
    plots = {}
    for case, default in plan.defaults.items():
        name = f"bench_{case.value.replace('-', '_')}.png"
        if plot_case(rows, case, default, args.out / name):
            plots[case] = name
            if args.docs is not None:
                plot_dir.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(args.out / name, plot_dir / name)
    command = "cosim bench" + (f" --plan {args.plan}" if args.plan != "full" else "") + (f" --docs {args.docs}" if args.docs else "")
    text = markdown(plan, outcome.results, rows, skips, plots, _header(command, outcome.versions))
    write_text_atomic(args.out / "bench.csv", rows_csv(rows))
    write_text_atomic(args.out / "bench.md", text)
    if args.docs is not None:
        update_document(args.docs, text)
    print(f"wrote {args.out / 'bench.csv'}, {args.out / 'bench.md'} and {len(plots)} plots"
          + (f"; updated {args.docs}" if args.docs else "") + f" ({outcome.computed} configurations computed, "
          f"{len(plan.rows) - outcome.computed} from the cache)")
    return 0

