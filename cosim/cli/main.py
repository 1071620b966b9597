"""Entry point of the ``cosim`` command.

Each subcommand lives in its own module under ``cosim.cli`` and provides ``register(subparsers, summary)`` (adds its
parser with that one-line help, sets ``func``) and a ``run(args) -> int``. Bad input (:class:`InputError`, or the controllers' own
``ControllerInputError``) prints one line and exits with 2; a simulation that broke (:class:`SimulationError`, the
controllers' ``MeasurementError``) prints one line and exits with 1; Ctrl-C exits with 130, SIGTERM (a batch
scheduler's stop) with 143, both through the same clean-up, so neither leaves a half-written output behind.

Only what ``--help`` needs is imported up front: each subcommand module imports its libraries (warp, MuJoCo,
python-control, Rerun) inside ``run``, so help and bad-input errors come back in a fraction of a second
(tests/test_cli_startup.py checks it).
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import signal
import sys
import threading
from typing import Iterator, NoReturn

from cosim import __version__
from cosim.blas_threads import limit_openblas_threads
from cosim.errors import InputError, SimulationError
from cosim.reproducibility import pin_openblas_core

# Subcommands, in the order `cosim --help` lists them: name -> (its module, the line `cosim --help` shows).
SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "pour": ("cosim.cli.pour", "simulate a robot pour (default scene without a file)"),
    "sweep": ("cosim.cli.sweep", "many pours of one scene over axes of scene keys, on a local or remote Ray cluster"),
    "scene": ("cosim.cli.scene", "print the default scene as TOML, or check a scene file"),
    "validate": ("cosim.cli.validate", "run validation cases against analytic and experimental references"),
    "bench": ("cosim.cli.bench", "wall time against error: resolutions, numerics, skip options (CSV, PNG, Markdown)"),
    "stress": ("cosim.cli.stress", "numerical-stability matrix of the SPH liquid (CSV + Markdown + PNG)"),
    "replay": ("cosim.cli.replay", "play a joint trajectory CSV in MuJoCo (no liquid) and report tracking error"),
    "view": ("cosim.cli.view", "open a run's Rerun recording in the viewer"),
}


def requested_command(argv: list[str]) -> str | None:
    """The subcommand ``argv`` names: its first word that is not an option (``cosim`` itself takes only ``--help``
    and ``--version``, neither with a value), if it is one of :data:`SUBCOMMANDS`."""
    word = next((a for a in argv if not a.startswith("-")), None)
    return word if word in SUBCOMMANDS else None


class OneLineParser(argparse.ArgumentParser):
    """argparse's parser (its subcommands' too: ``add_subparsers`` makes them of the root's class) whose usage errors
    are one line and exit status 2, as every other bad input: ``cosim pour: error: argument --threads: invalid int
    value: 'abc' (see cosim pour --help)``. argparse itself prints the whole usage block first."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``cosim`` parser, with ``command``'s full parser (its module imported and registered) and a bare entry
    for every other subcommand: only the command that runs is imported."""
    parser = OneLineParser(
        prog="cosim",
        description="Simulate robot pours: MuJoCo arms holding vessels, a warp-lang SPH liquid, "
        "slosh-induction pouring control, jerk-limited joint trajectories and Rerun logs.",
    )
    parser.add_argument("--version", action="version", version=f"cosim {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module, summary) in SUBCOMMANDS.items():
        if name == command:
            importlib.import_module(module).register(subparsers, summary)
        else:
            subparsers.add_parser(name, help=summary)
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


def exit_status(exc: Exception) -> int | None:
    """2 for bad input (an OSError about a path among it), 1 for a simulation that broke, None for anything else (a
    bug: raised). The controllers' errors are looked up only where their package is loaded already (nothing else can
    have raised one), so that refusing an option does not import it and NumPy with it."""
    if isinstance(exc, InputError):
        return 2
    if isinstance(exc, SimulationError):
        return 1
    if isinstance(exc, OSError) and exc.filename is not None:  # a path given that the system refuses (too long, a
        return 2  # link loop, not readable, ...): its own one line names it
    errors = sys.modules.get("controllers.errors")
    if errors is not None and isinstance(exc, errors.ControllerInputError):
        return 2
    if errors is not None and isinstance(exc, errors.MeasurementError):
        return 1
    return None


def main(argv: list[str] | None = None) -> int:
    pin_openblas_core()  # both before any subcommand imports numpy
    limit_openblas_threads()
    argv = sys.argv[1:] if argv is None else argv
    parser = build_parser(requested_command(argv))
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        print(f"cosim: error: a command is required: {', '.join(SUBCOMMANDS)}", file=sys.stderr)
        return 2
    try:
        with _sigterm_unwinds():
            return int(args.func(args) or 0)
    except Exception as exc:
        status = exit_status(exc)
        if status is None:
            raise
        print(f"cosim {args.command}: {'error' if status == 2 else 'simulation failed'}: {exc}", file=sys.stderr)
        return status
    except Terminated:
        print(f"cosim {args.command}: terminated", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print(f"cosim {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    raise SystemExit(main())
