"""``cosim sweep SWEEP.toml``: many pours of one base scene over axes of scene keys, as Ray tasks.

The sweep file names a base scene and the axes to sweep (docs/sweep.md; examples/fill_sweep.toml). Without
``--address`` the pours run on a local Ray started on this machine's cores; ``--address auto`` joins the cluster
``ray start --head`` started here, ``--address ray://HOST:10001`` a remote one (the workers and this machine must
all see ``--out``: shared storage). Each pour's run folder goes to ``--out``/pours/<key> as ``cosim pour`` writes it; rerunning the
same command resumes: done pours are skipped, failed and missing ones run. Results: sweep.csv, plots/<axis>.png and
library.json (the trajectory library) in ``--out``. Exit status 1 when a pour failed (sweep.csv has its error).
"""

from __future__ import annotations

import argparse
import re
from importlib.util import find_spec
from pathlib import Path
from typing import TYPE_CHECKING

from cosim.atomic_files import check_output_folder
from cosim.errors import InputError
from declared_settings.setting import argument

if TYPE_CHECKING:
    from cosim.sweep.plan import SweepPlan

DEFAULT_ROOT = Path("recordings")
MAX_PARALLEL = argument("sweep", "Most pours running at once.", "", 1, 100_000, kind="int")


def register(subparsers, summary: str) -> None:
    p = subparsers.add_parser("sweep", help=summary, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("sweep", type=Path, help="sweep TOML file: a base scene and its axes")
    p.add_argument("--out", type=Path, help="output folder (default: recordings/sweep-<sweep file name>); "
                   "the folder of an earlier run of the sweep resumes it")
    p.add_argument("--address", help="Ray cluster to join: 'auto' (started here with `ray start --head`) or "
                   "'ray://HOST:10001' (default: start a local Ray on this machine's cores)")
    p.add_argument("--max-parallel", type=int, help="most pours running at once (default: as many as the cluster's "
                   "CPUs and GPUs hold)")
    p.add_argument("--dry-run", action="store_true", help="print the pours, their resources and estimated cost; run nothing")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


ADDRESS = re.compile(r"(ray://)?[A-Za-z0-9._-]+:[0-9]{1,5}")


def check_address(address: str) -> None:
    """Refuse a ``--address`` that is none of the forms Ray joins: 'auto', 'ray://HOST:PORT' (Ray Client) or
    'HOST:PORT' (the head's own address, as ``ray start --head`` prints it)."""
    if address != "auto" and not ADDRESS.fullmatch(address):
        raise InputError(f"--address: must be 'auto', 'ray://HOST:PORT' or 'HOST:PORT', got {address!r}")


def print_dry_run(plan: SweepPlan) -> None:
    """Per pour: its axes, state, the resources its task asks for, its particles and estimated wall time (the
    bound :func:`cosim.pour_checks.check_pour` estimates), or why its scene is refused; then the totals."""
    from cosim.pour_checks import check_pour

    total = 0.0
    to_run = {p.key for p in plan.to_run()}
    for pour in plan.pours:
        axes = ", ".join(f"{k} = {v!r}" for k, v in pour.point.axes.items())
        head = f"{pour.point.index:4d}  {axes}:"
        if pour.key is None:
            print(f"{head} refused: {pour.point.error}")
            continue
        if pour.key not in to_run:
            print(f"{head} done ({plan.store.run_folder(pour.key)})")
            continue
        try:
            checked = check_pour(pour.point.scene, long_run_ok=True)
        except InputError as exc:
            print(f"{head} refused: {exc}")
            continue
        total += checked.wall_time
        print(f"{head} {pour.resources}, {checked.particles:,} particles, estimated at most {checked.wall_time:.3g} s")
    print(f"{len(to_run)} of {len(plan.pours)} pours to run, estimated at most {total:.3g} s of wall time one after "
          f"another (code version {plan.code}, output {plan.store.root})")


def run(args) -> int:
    from cosim.sweep.spec import load_sweep

    if args.max_parallel is not None:
        MAX_PARALLEL.check("--max-parallel", args.max_parallel)
    if args.address is not None:
        check_address(args.address)
    spec = load_sweep(args.sweep)
    out = args.out if args.out is not None else DEFAULT_ROOT / f"sweep-{spec.name}"
    check_output_folder(out, "--out")
    from cosim.sweep.store import SweepStore

    SweepStore(out).check_root()
    if not args.dry_run and find_spec("ray") is None:
        raise InputError("cosim sweep needs Ray, which is not installed: pip install 'cosim[sweep]' (or --dry-run)")
    from cosim.sweep.plan import plan_sweep

    plan = plan_sweep(spec, out)
    if args.dry_run:
        print_dry_run(plan)
        return 0
    import ray

    from cosim.sweep.report import write_report
    from cosim.sweep.runner import connect, run_pours

    connected = connect(args.address)  # before anything is written: a cluster that is not there leaves no sweep.json
    try:
        plan.store.write_manifest({"sweep": spec.name, "code": plan.code, "code_version": plan.version, "pours": len(plan.pours)})
        ran = run_pours(plan, args.max_parallel, progress=not args.quiet)
    finally:
        report = write_report(plan)  # what is done so far, also after Ctrl-C
        if connected:
            ray.shutdown()
    counts = report["counts"]
    print(f"sweep {spec.name}: {counts['done']} done, {counts['failed']} failed, {counts['not run']} not run "
          f"(this run: {ran['done']} poured, {ran['failed']} failed; {len(plan.pours) - ran['done'] - ran['failed']} "
          f"skipped as done or refused)")
    print(f"wrote {report['csv']}, {report['library']}" + "".join(f", {p}" for p in report["plots"]))
    return 1 if counts["failed"] else 0
