"""``cosim view RUN``: open a pour's Rerun recording in the Rerun viewer.

RUN is a run folder holding ``pour.rrd`` or a ``.rrd`` file. The viewer is the ``rerun`` command shipped with
rerun-sdk, run as a child process until it is closed. Without a display (Linux with neither DISPLAY nor
WAYLAND_DISPLAY set) nothing is started: the command prints how to open the file elsewhere, or through a browser.
"""

from __future__ import annotations

import argparse
import os
import shlex
import subprocess
import sys
import warnings
from pathlib import Path

from cosim.errors import InputError

RECORDING_NAME = "pour.rrd"
# Ports of `rerun --web-viewer` (Rerun's defaults): the page over HTTP and the data over gRPC.
WEB_VIEWER_PORT = 9090
GRPC_PORT = 9876


def register(subparsers: argparse._SubParsersAction, summary: str) -> None:
    parser = subparsers.add_parser(
        "view",
        help=summary,
        description="Open a pour's Rerun recording (RUN/pour.rrd, or a .rrd file) in the Rerun viewer.",
    )
    parser.add_argument("run", metavar="RUN", help="run folder containing pour.rrd, or a .rrd file")
    parser.add_argument(
        "--print-only",
        action="store_true",
        help="check the recording and print the viewer command instead of starting it",
    )
    parser.set_defaults(func=run)


def recording_path(run_arg: str) -> Path:
    """The .rrd file RUN designates, checked to be a readable Rerun recording (else InputError)."""
    path = Path(run_arg).expanduser()
    if path.is_dir():
        path = path / RECORDING_NAME
    if not path.is_file():
        if (path.parent / "summary.json").is_file() and path.name == RECORDING_NAME:
            raise InputError(f"RUN: {path.parent} is a run without its recording (made with --no-log or logging.enabled "
                             "= false); run the pour again with logging on to view it")
        raise InputError(f"RUN: no recording at {path} (expected a run folder with {RECORDING_NAME}, or a .rrd file)")
    # imported here, once the file exists: the other subcommands run where rerun-sdk is not installed (a headless
    # machine), and a wrong path is reported without loading it
    from rerun.chunk import RrdReader

    try:
        with warnings.catch_warnings():  # a file without footer warns before failing; the error below says it all
            warnings.simplefilter("ignore")
            recordings = RrdReader(path).recordings()
    except Exception as exc:  # the reader raises various types for a corrupt or foreign file
        raise InputError(f"RUN: {path} is not a readable Rerun recording ({str(exc).splitlines()[0]})") from None
    if not recordings:
        raise InputError(f"RUN: {path} holds no Rerun recording")
    return path.resolve()


def viewer_command(path: Path) -> list[str]:
    """The command that opens ``path`` in the native viewer, with the rerun CLI of this Python environment."""
    return [sys.executable, "-m", "rerun", str(path)]


def has_display() -> bool:
    """False on Linux (and other X11/Wayland systems) when neither DISPLAY nor WAYLAND_DISPLAY is set."""
    if sys.platform in ("darwin", "win32"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def run(args: argparse.Namespace) -> int:
    path = recording_path(args.run)
    command = viewer_command(path)
    if args.print_only:
        print(shlex.join(command))
        return 0
    if not has_display():
        print(
            "cosim view: no display here (DISPLAY and WAYLAND_DISPLAY are unset), so no viewer was started.\n"
            f"  On a machine with a display:  rerun {shlex.quote(str(path))}\n"
            f"  Or serve a web viewer here:   rerun --web-viewer {shlex.quote(str(path))}\n"
            f"    and open http://localhost:{WEB_VIEWER_PORT} after forwarding ports {WEB_VIEWER_PORT} and {GRPC_PORT} "
            f"(ssh -L {WEB_VIEWER_PORT}:localhost:{WEB_VIEWER_PORT} -L {GRPC_PORT}:localhost:{GRPC_PORT} HOST)"
        )
        return 0
    return subprocess.call(command)
