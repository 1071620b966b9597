"""``cosim scene --dump``: print the default pour scene as TOML (every field with its unit and range), the
starting point of a scene file for ``cosim pour SCENE.toml``. ``--check FILE`` runs every check ``cosim pour FILE``
runs before it simulates (:func:`cosim.pour_checks.check_pour`: the fields, the robot cell of the scene's vessels and
placement, the fill below the rim, the catcher's size and height, the arms' payload and reach over the pour's poses,
the joint limits, the liquid's resolution and memory, the run-time estimate), in seconds: a scene it refuses,
``cosim pour`` refuses with the same line; one it passes, it prints in full with the particle counts and the
estimate."""

from __future__ import annotations

import sys
from pathlib import Path

from cosim.atomic_files import check_output_file, write_text_atomic


def register(subparsers, summary: str) -> None:
    p = subparsers.add_parser("scene", help=summary, description=__doc__)
    action = p.add_mutually_exclusive_group(required=True)
    action.add_argument("--dump", action="store_true", help="print the default scene (or write it with --out)")
    action.add_argument("--check", type=Path, metavar="FILE", help="run the checks `cosim pour FILE` runs before simulating, "
                        "then print the scene in full")
    p.add_argument("--yes", action="store_true", help="with --check: accept a run estimated at over an hour, as `cosim pour --yes` does")
    p.add_argument("--out", type=Path, help="write the TOML to this file instead of printing it")
    p.set_defaults(func=run)


def run(args) -> int:
    from cosim.pour_scene import PourScene, dump_scene, load_scene

    if args.out is not None:
        check_output_file(args.out, "--out")
    scene = load_scene(args.check) if args.check else PourScene()
    if args.check:
        from cosim.pour_checks import check_pour

        print(check_pour(scene, long_run_ok=args.yes).summary(), file=sys.stderr)
    text = dump_scene(scene)
    if args.out:
        write_text_atomic(args.out, text)
        print(f"wrote {args.out}")
    else:
        print(text, end="")
    return 0
