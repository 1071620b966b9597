"""``cosim scene --dump``: print the default pour scene as TOML (every field with its unit and range), the
starting point of a scene file for ``cosim pour SCENE.toml``; ``--check FILE`` validates a scene file."""

from __future__ import annotations

from pathlib import Path

from cosim.atomic_files import check_output_folder, write_text_atomic
from cosim.errors import InputError


def register(subparsers, summary: str) -> None:
    p = subparsers.add_parser("scene", help=summary, description=__doc__)
    action = p.add_mutually_exclusive_group(required=True)
    action.add_argument("--dump", action="store_true", help="print the default scene (or write it with --out)")
    action.add_argument("--check", type=Path, metavar="FILE", help="validate a scene file and print it in full")
    p.add_argument("--out", type=Path, help="write the TOML to this file instead of printing it")
    p.set_defaults(func=run)


def run(args) -> int:
    from cosim.pour_scene import PourScene, dump_scene, load_scene

    if args.out is not None:
        if args.out.is_dir():
            raise InputError(f"--out: {args.out} is a folder; give the scene file's name")
        check_output_folder(args.out.parent, "--out")
    text = dump_scene(load_scene(args.check) if args.check else PourScene())
    if args.out:
        write_text_atomic(args.out, text)
        print(f"wrote {args.out}")
    else:
        print(text, end="")
    return 0
