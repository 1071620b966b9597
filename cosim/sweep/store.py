"""Where a sweep keeps its pours, and what a rerun resumes from.

Each pour is keyed by a hash of its scene and of the code version (:func:`pour_key`): the installed ``cosim`` and
``controllers`` source files, byte for byte, and the versions a pour's summary records (Python, warp, MuJoCo, numpy
and its BLAS kernels, ...: each changes a pour's bits). Under the sweep's output folder:

``pours/<key>/``
    the pour's run folder, written by :func:`cosim.pour_run.run_pour` into a hidden temporary folder and renamed
    into place when it succeeded: a folder there is complete.
``failed/<key>.json``
    a failed pour's error (its kind and one line), removed when a rerun succeeds.
``sweep.json``
    the sweep's manifest: the code version its report describes.

A rerun skips the pours whose folder is there, runs the failed and the missing ones, and, the key holding the code
version, never counts a pour another code version wrote: other code's folders stay on disk, unused.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING

from cosim.atomic_files import PARTIAL_TAG, write_text_atomic
from cosim.errors import InputError

if TYPE_CHECKING:
    from cosim.pour_scene import PourScene

KEY_LENGTH = 16  # hex digits of the sha256 a key keeps: 64 bits, no collision among any sweep's pours
SOURCE_PACKAGES = ("cosim", "controllers")
MANIFEST = "sweep.json"


def _digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()[:KEY_LENGTH]


def source_hash() -> str:
    """sha256 over every file of the installed :data:`SOURCE_PACKAGES` (relative path and bytes, in path order;
    byte-code caches left out), following linked folders (the robot models)."""
    import importlib

    digest = hashlib.sha256()
    for package in SOURCE_PACKAGES:
        root = Path(importlib.import_module(package).__file__).parent
        files = []
        for folder, subfolders, names in os.walk(root, followlinks=True):
            subfolders[:] = [s for s in subfolders if s != "__pycache__"]
            files += [Path(folder) / n for n in names if not n.endswith(".pyc")]
        for path in sorted(files):
            digest.update(f"{package}/{path.relative_to(root).as_posix()}\0".encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()


def code_version() -> dict[str, str]:
    """The code a pour ran: the source hash (:func:`source_hash`) and the package versions a pour's summary records
    (:func:`cosim.pour_run.package_versions`)."""
    from cosim.pour_run import package_versions

    return {"source": source_hash(), **package_versions()}


def code_id(version: dict[str, str]) -> str:
    """A short hash of a :func:`code_version`."""
    return _digest(json.dumps(version, sort_keys=True))


def scene_json(scene: PourScene) -> str:
    """The scene as canonical JSON (sorted keys, enums as their values): equal scenes, equal text."""
    return json.dumps(asdict(scene), sort_keys=True, default=lambda o: getattr(o, "value", str(o)))


def pour_key(scene: PourScene, code: str) -> str:
    """The pour's key: a hash of its scene and of the code id ``code``."""
    return _digest(f"{code}\0{scene_json(scene)}")


class SweepStore:
    """The pours and failures of a sweep under ``root`` (module docstring)."""

    def __init__(self, root: Path):
        self.root = Path(root)
        self.pours = self.root / "pours"
        self.failed = self.root / "failed"

    def check_root(self, field: str = "--out") -> None:
        """Refuse a ``root`` that exists and holds something other than a sweep (nothing is written into it)."""
        if self.root.exists() and (not self.root.is_dir() or (any(self.root.iterdir()) and not (self.root / MANIFEST).is_file())):
            raise InputError(f"{field}: {self.root} exists and is not a sweep's output folder (no {MANIFEST}); "
                             f"give a new or empty folder, or the folder of the sweep to resume")

    def write_manifest(self, manifest: dict) -> None:
        write_text_atomic(self.root / MANIFEST, json.dumps(manifest, indent=2) + "\n")

    def run_folder(self, key: str) -> Path:
        return self.pours / key

    def is_complete(self, key: str) -> bool:
        """The pour's run folder is there (it appears only complete, with its summary.json)."""
        return (self.run_folder(key) / "summary.json").is_file()

    def failure(self, key: str) -> dict | None:
        """The recorded failure of the pour (kind, error, axes), or None."""
        path = self.failed / f"{key}.json"
        return json.loads(path.read_text()) if path.is_file() else None

    def record_failure(self, key: str, record: dict) -> None:
        write_text_atomic(self.failed / f"{key}.json", json.dumps(record, indent=2, default=str) + "\n")

    def clear_failure(self, key: str) -> None:
        (self.failed / f"{key}.json").unlink(missing_ok=True)

    def remove_partial(self, key: str) -> None:
        """Remove what a worker that died without cleaning up (killed, its node lost) left of the pour: its hidden
        temporary run folders. Call only before the pour runs again."""
        for leftover in self.pours.glob(f".{key}{PARTIAL_TAG}*"):
            shutil.rmtree(leftover, ignore_errors=True)
