"""``cosim stress``: the numerical-stability matrix of the SPH liquid (see ``cosim.stress``).

Runs every configuration of the matrix (or ``--quick``'s three, or those matching ``--filter FIELD=VALUE``),
appending one row per configuration to ``OUT/stress.csv`` (rewritten atomically after each); a rerun skips the
configurations already in the file, so an interrupted run continues where it stopped (``--fresh`` starts over).
Then writes ``OUT/stability.md`` and ``OUT/stability.png``. ``--docs DIR`` runs nothing and writes the report
from ``OUT/stress.csv`` into DIR. Exit status 1 when any configuration is ``silent`` (garbage without an error)
or ``error`` (an unexpected exception); ``instability`` (the solver's clear error) and ``refused`` (its one-line
input error at set-up) are acceptable outcomes.
"""

from __future__ import annotations

import argparse
import shlex
import sys
import traceback
from collections import Counter
from pathlib import Path
from typing import TYPE_CHECKING

from cosim.atomic_files import check_output_folder, write_text_atomic
from cosim.checks import check_device
from cosim.errors import InputError
from cosim.stress.filters import FILTER_FIELDS, select

if TYPE_CHECKING:  # the matrix, the runner and the report import warp and MuJoCo: imported by run
    from cosim.stress.store import ResultStore

DEFAULT_OUT = Path("recordings") / "stress"
RESULTS = "stress.csv"
COMMANDS = "commands.txt"  # the command lines that produced the results, one a line


def register(subparsers, summary: str) -> None:
    p = subparsers.add_parser("stress", help=summary, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, help=f"result folder (default {DEFAULT_OUT})")
    p.add_argument("--quick", action="store_true", help="three cheap configurations (a smoke run)")
    p.add_argument("--filter", action="append", default=[], metavar="FIELD=VALUE",
                   help=f"only configurations with FIELD=VALUE (repeatable; FIELD: {', '.join(FILTER_FIELDS)})")
    p.add_argument("--fresh", action="store_true", help="discard the results in OUT and run everything again")
    p.add_argument("--docs", type=Path, metavar="DIR", help="run nothing: write stability.md/png into DIR from OUT")
    p.add_argument("--list", action="store_true", help="print the selected configurations and exit")
    p.add_argument("--device", default="cpu", help="cpu or cuda[:N] (default cpu)")
    p.set_defaults(func=run)


def _command_line(args) -> str:
    parts = ["cosim", "stress", "--out", str(args.out)]
    parts += ["--quick"] if args.quick else []
    for f in args.filter:
        parts += ["--filter", f]
    parts += ["--fresh"] if args.fresh else []
    parts += ["--device", args.device] if args.device != "cpu" else []
    return shlex.join(parts)


def _ordered(store: ResultStore) -> list[dict]:
    """Rows in matrix order (then any others, e.g. quick configurations, in completion order)."""
    from cosim.stress.matrix import build_matrix

    order = {c.id: k for k, c in enumerate(build_matrix())}
    return sorted(store.rows.values(), key=lambda r: order.get(r["id"], len(order)))


def _commands(out: Path) -> list[str]:
    path = out / COMMANDS
    return path.read_text().splitlines() if path.exists() else []


def _run_one(config, device: str) -> dict:
    """The row of one configuration; an unexpected exception becomes an ``error`` row, not a crash."""
    from cosim.stress.classify import Outcome, classify
    from cosim.stress.runner import measure
    from cosim.stress.store import make_row

    try:
        m = measure(config, device)  # returns the solver's instability as a result; Ctrl-C is no Exception
    except InputError as exc:  # refused at set-up with the one-line message a user would get
        return make_row(config, Outcome.REFUSED, str(exc), None)
    except Exception as exc:  # noqa: BLE001 - any other failure is recorded as this configuration's outcome
        message = f"{type(exc).__name__}: {exc} ({traceback.extract_tb(exc.__traceback__)[-1].filename.split('/')[-1]})"
        return make_row(config, Outcome.ERROR, message, None)
    outcome, message = classify(m)
    return make_row(config, outcome, message, m)


def run(args) -> int:
    from cosim.stress.classify import FAILURES, Outcome
    from cosim.stress.matrix import build_matrix, quick_matrix
    from cosim.stress.report import write_report
    from cosim.stress.store import ResultStore

    if args.docs is not None:
        store = ResultStore(args.out / RESULTS)
        if not store.rows:
            raise InputError(f"--docs: no results in {args.out / RESULTS}; run `cosim stress --out {args.out}` first")
        check_output_folder(args.docs, "--docs")
        commands = _commands(args.out) + [f"cosim stress --out {shlex.quote(str(args.out))} --docs {shlex.quote(str(args.docs))}"]
        write_report(_ordered(store), commands, args.docs)
        print(f"wrote {args.docs / 'stability.md'} and {args.docs / 'stability.png'} ({len(store.rows)} configurations)")
        return 0
    check_device("--device", args.device)
    configs = select(quick_matrix() if args.quick else build_matrix(), args.filter)
    if not configs:
        raise InputError(f"--filter {' '.join(args.filter)}: matches no configuration")
    if args.list:
        for c in configs:
            print(c.id, c.label)
        return 0
    from tqdm import tqdm

    check_output_folder(args.out, "--out")
    if args.device != "cpu":  # an absent device refused here, not as every configuration's outcome
        from cosim.fluid.runtime import resolve_device

        resolve_device(args.device)
    store = ResultStore(args.out / RESULTS, fresh=args.fresh)
    todo = [c for c in configs if c.id not in store]
    commands = [] if args.fresh else _commands(args.out)
    write_text_atomic(args.out / COMMANDS, "\n".join(commands + [_command_line(args)]) + "\n")
    print(f"{len(configs)} configurations, {len(configs) - len(todo)} already in {args.out / RESULTS}", file=sys.stderr)
    counts = Counter(store.rows[c.id]["outcome"] for c in configs if c.id in store)
    with tqdm(todo, unit="config", file=sys.stderr, dynamic_ncols=True) as bar:
        for config in bar:
            bar.set_description(config.label)
            row = _run_one(config, args.device)
            store.add(row)
            counts[row["outcome"]] += 1
            bar.set_postfix({o.value: counts.get(o.value, 0) for o in Outcome})
    write_report(_ordered(store), _commands(args.out), args.out)
    summary = ", ".join(f"{o.value} {counts.get(o.value, 0)}" for o in Outcome)
    print(f"{summary}; results {args.out / RESULTS}, report {args.out / 'stability.md'}")
    failed = sum(counts.get(o.value, 0) for o in FAILURES)
    if failed:
        print(f"{failed} configurations ended silent or in error (see {args.out / 'stability.md'})", file=sys.stderr)
    return 1 if failed else 0
