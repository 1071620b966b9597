"""Result cache of the benchmark: one JSON file per configuration, named by its key.

The key (:meth:`cosim.bench.config.BenchConfig.key`) hashes the configuration and :func:`code_version`, so an
edit to the simulation code or a different warp/MuJoCo/numpy version reruns everything, while an interrupted
bench resumes where it stopped. Files are written atomically: a run killed mid-write leaves no entry, never a
broken one.
"""

from __future__ import annotations

import hashlib
import json
from importlib import metadata
from pathlib import Path

from cosim.atomic_files import write_text_atomic

# What a result depends on: the packages the simulation runs through and the MJCF models (cosim/models, a link to
# the repository's models/ in a checkout); the benchmark and CLI code are not part of it.
_ROOTS = ("cosim", "controllers")
_NOT_SIMULATION = ("cosim/bench", "cosim/cli")
_SUFFIXES = (".py", ".xml", ".csv", ".toml", ".stl", ".obj")
_DEPENDENCIES = ("warp-lang", "mujoco", "numpy", "ruckig", "control")


def code_version() -> str:
    """Hash of the simulation sources (``cosim`` and ``controllers``, without the bench and the CLI) and of the
    installed versions of the numerical dependencies."""
    import cosim

    base = Path(cosim.__file__).resolve().parent.parent
    roots = [(name, base / name) for name in _ROOTS] + [("models", (base / "cosim" / "models").resolve())]
    h = hashlib.sha256()
    for name, root in roots:
        for path in sorted(root.rglob("*")):
            rel = f"{name}/{path.relative_to(root).as_posix()}"
            if path.is_file() and path.suffix in _SUFFIXES and not rel.startswith(_NOT_SIMULATION):
                h.update(rel.encode() + b"\0" + path.read_bytes() + b"\0")
    for name in _DEPENDENCIES:
        try:
            h.update(f"{name}={metadata.version(name)}".encode())
        except metadata.PackageNotFoundError:
            h.update(f"{name}=none".encode())
    return h.hexdigest()[:16]


class ResultCache:
    """Cached raw results under ``folder`` (``<key>.json``)."""

    def __init__(self, folder: Path):
        self.folder = Path(folder)

    def _path(self, key: str) -> Path:
        return self.folder / f"{key}.json"

    def get(self, key: str) -> dict | None:
        """The cached result of ``key``, or None (also for an unreadable entry, which is then recomputed)."""
        try:
            return json.loads(self._path(key).read_text())
        except (OSError, ValueError):
            return None

    def put(self, key: str, result: dict) -> None:
        write_text_atomic(self._path(key), json.dumps(result, allow_nan=True) + "\n")
