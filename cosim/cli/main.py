"""Entry point of the ``cosim`` command.

Each subcommand lives in its own module under ``cosim.cli`` and provides ``register(subparsers)`` (adds its parser,
sets ``func``) and a ``run(args) -> int``. Bad input (:class:`InputError`, or the controllers' own
``ControllerInputError``) prints one line and exits with 2; a simulation that broke (:class:`SimulationError`, the
controllers' ``MeasurementError``) prints one line and exits with 1; Ctrl-C exits with 130.
"""

from __future__ import annotations

import argparse
import importlib
import sys

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


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except (InputError, ControllerInputError) as exc:
        print(f"cosim {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except (SimulationError, MeasurementError) as exc:
        print(f"cosim {args.command}: simulation failed: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"cosim {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    raise SystemExit(main())
