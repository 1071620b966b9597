"""How long `cosim --help` and refused input take to come back: wall time of new processes, median of several.

Each command runs as a new ``python -m cosim ...`` process, the commands in turn round after round, beside the bare
interpreter's start (``python -c pass``) as the floor no command can go under. Bad scene files are written to a
temporary folder (:data:`BAD_SCENES`: an unknown key, and a value out of range in each of four sections), so that
their refusal by ``cosim pour`` and ``cosim scene --check``, which needs the scene's schema, is timed too.

    python -m cosim.bench.startup [--repeats 5] [--before DIR]

``--before DIR`` times another checkout (e.g. the revision before a change) side by side: each command runs from
DIR and from this checkout in turn, every round, so that both see the same load, and the table gives their ratio.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Hashable
from pathlib import Path

from cosim.bench.fluid_throughput import machine_description
from cosim.bench.options import REPEATS
from cosim.errors import InputError

THIS_TREE = Path(__file__).resolve().parents[2]  # the checkout this module is in

# What is wrong with each bad scene file -> its text.
BAD_SCENES = {
    "an unknown key": "[fluid]\nparticles_acros = 32\n",
    "fluid.cfl out of range": "[fluid]\ncfl = 0.9\n",
    "controller.sim.trigger_angle out of range": "[controller.sim]\ntrigger_angle = 5.0\n",
    "vessels.pourer.inner_width out of range": "[vessels.pourer]\ninner_width = 5.0\n",
    "arms.pour.base_yaw out of range": "[arms.pour]\nbase_yaw = 10.0\n",
}


def write_bad_scenes(folder: Path) -> dict[str, Path]:
    """Each of :data:`BAD_SCENES` written to ``folder``: what is wrong -> its file."""
    paths = {}
    for number, (wrong, text) in enumerate(BAD_SCENES.items()):
        paths[wrong] = folder / f"BAD{number}.toml"
        paths[wrong].write_text(text)
    return paths


def commands(bad_scenes: dict[str, Path]) -> dict[str, list[str]]:
    """Label -> command line (the label is what a user types); ``bad_scenes`` from :func:`write_bad_scenes`."""
    cosim = [sys.executable, "-m", "cosim"]
    lines = {
        "python -c pass (the interpreter alone)": [sys.executable, "-c", "pass"],
        "cosim --help": [*cosim, "--help"],
        "cosim pour --help": [*cosim, "pour", "--help"],
        "cosim pour --duration -1": [*cosim, "pour", "--duration", "-1"],
        "cosim pour --threads -1": [*cosim, "pour", "--threads", "-1"],
    }
    for wrong, path in bad_scenes.items():
        lines[f"cosim pour BAD.toml ({wrong})"] = [*cosim, "pour", str(path)]
        lines[f"cosim scene --check BAD.toml ({wrong})"] = [*cosim, "scene", "--check", str(path)]
    return lines


def from_tree(line: list[str], root: Path) -> list[str]:
    """``line`` run in the checkout ``root``, its folder and import path first, so that ``python -m cosim`` is that
    checkout's."""
    return ["env", "-C", str(root), f"PYTHONPATH={root}", *line]


def time_commands(lines: dict[Hashable, list[str]], repeats: int) -> dict[Hashable, list[float]]:
    """Wall s of every run of each command, the commands in turn each round; each run's exit status must be 0 or 2."""
    times: dict[Hashable, list[float]] = {label: [] for label in lines}
    for _ in range(repeats):
        for label, line in lines.items():
            start = time.perf_counter()
            done = subprocess.run(line, capture_output=True)
            times[label].append(time.perf_counter() - start)
            if done.returncode not in (0, 2):
                raise RuntimeError(f"{label}: exit status {done.returncode}: {done.stderr.decode()[-2000:]}")
    return times


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m cosim.bench.startup", description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=5, help="runs of each command; the median is printed (default 5)")
    ap.add_argument("--before", type=Path, metavar="DIR", help="another checkout of cosim, timed in turn with this one")
    args = ap.parse_args(argv)
    try:
        REPEATS.check("--repeats", args.repeats)
        if args.before is not None and not (args.before / "cosim" / "__main__.py").is_file():
            raise InputError(f"--before: must be a checkout of cosim (with cosim/__main__.py), got {args.before}")
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory(prefix="cosim-startup-") as tmp:
        lines = commands(write_bad_scenes(Path(tmp)))
        trees = {} if args.before is None else {"before": args.before.resolve(), "this": THIS_TREE}
        timed = {(label, tree): from_tree(line, root) for label, line in lines.items() for tree, root in trees.items()}
        times = time_commands(timed or {(label, ""): line for label, line in lines.items()}, args.repeats)
    command = "python -m cosim.bench.startup " + " ".join(argv if argv is not None else sys.argv[1:])
    print(f"Machine: {machine_description()}, 1-minute load average {os.getloadavg()[0]:.1f} at the end. "
          f"Command: `{command.strip()}`. Wall s of a new process, median of {args.repeats} (every run in order).\n")

    def runs(key: tuple[str, str]) -> str:
        return ", ".join(f"{t:.3f}" for t in times[key])

    if not trees:
        print("| command | wall s, median | runs |\n|---|---|---|")
        for label in lines:
            print(f"| `{label}` | {statistics.median(times[label, '']):.3f} | {runs((label, ''))} |")
        return 0
    print("| command | before, s | this, s | before / this | runs before; this |\n|---|---|---|---|---|")
    for label in lines:
        before, this = statistics.median(times[label, "before"]), statistics.median(times[label, "this"])
        print(f"| `{label}` | {before:.3f} | {this:.3f} | {before / this:.1f}x | "
              f"{runs((label, 'before'))}; {runs((label, 'this'))} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
