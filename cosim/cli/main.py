"""Entry point of the ``cosim`` command.

Each subcommand lives in its own module under ``cosim.cli`` and provides ``register(subparsers)`` (adds its parser,
sets ``func``) and a ``run(args) -> int``. Bad input (:class:`InputError`, or the controllers' own
``ControllerInputError``) prints one line and exits with 2; a simulation that broke (:class:`SimulationError`, the
controllers' ``MeasurementError``) prints one line and exits with 1; Ctrl-C exits with 130, SIGTERM (a batch
scheduler's stop) with 143, both through the same clean-up, so neither leaves a half-written output behind.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import signal
import sys
import threading
from typing import Iterator

from controllers.errors import ControllerInputError, MeasurementError
from cosim import __version__
from cosim.errors import InputError, SimulationError

# Subcommand modules, in the order `cosim --help` lists them.
SUBCOMMAND_MODULES: list[str] = [
    "cosim.cli.pour",
    "cosim.cli.scene",
    "cosim.cli.validate",
    "cosim.cli.bench",
    "cosim.cli.stress",
    "cosim.cli.replay",
    "cosim.cli.view",
]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="cosim",
        description="Simulate robot pours: MuJoCo arms holding vessels, a warp-lang SPH liquid, "
        "slosh-induction pouring control, jerk-limited joint trajectories and Rerun logs.",
    )
    parser.add_argument("--version", action="version", version=f"cosim {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in SUBCOMMAND_MODULES:
        importlib.import_module(name).register(subparsers)
    return parser


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where Python next runs in the main thread: unwinds like Ctrl-C (every ``except
    BaseException`` clean-up runs: the pour's partial run folder is removed, the liquid's lanes are stopped)."""


def _raise_terminated(signum, frame) -> None:
    raise Terminated


@contextlib.contextmanager
def _sigterm_unwinds() -> Iterator[None]:
    """SIGTERM raises :class:`Terminated` inside the block (main thread only; the previous handler restored)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        with _sigterm_unwinds():
            return int(args.func(args) or 0)
    except (InputError, ControllerInputError) as exc:
        print(f"cosim {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except (SimulationError, MeasurementError) as exc:
        print(f"cosim {args.command}: simulation failed: {exc}", file=sys.stderr)
        return 1
    except Terminated:
        print(f"cosim {args.command}: terminated", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print(f"cosim {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    raise SystemExit(main())
