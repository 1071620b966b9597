"""Result cache of the benchmark: one JSON file per configuration, named by its key.

The key (:meth:`cosim.bench.config.BenchConfig.key`) hashes the configuration and :func:`code_version` of the
sources its case runs through, so an edit to that code or a different warp/MuJoCo/numpy version reruns the
affected rows (an edit to the controller reruns the pours, not the fluid validations), while an interrupted bench
resumes where it stopped. Files are written atomically: a run killed mid-write leaves no entry, never a
broken one.
"""

from __future__ import annotations

import hashlib
import json
from importlib import metadata
from pathlib import Path

from cosim.atomic_files import write_text_atomic
from cosim.bench.config import BenchCase

# What a result depends on, per case (paths relative to the repository root; "cosim/models" is a link to the MJCF
# models in a checkout): the fluid cases run the fluid core only; coupling-static adds the robots and the coupling;
# the pour runs everything. The benchmark and CLI code are never part of it.
_FLUID_SOURCES = ("cosim/fluid", "cosim/validation", "cosim/frames.py", "cosim/vessel.py", "cosim/checks.py", "cosim/errors.py")
_COUPLED_SOURCES = _FLUID_SOURCES + ("cosim/coupling", "cosim/robots", "cosim/models")
_ALL_SOURCES = ("cosim", "controllers", "cosim/models")
SOURCES = {
    BenchCase.HYDROSTATIC: _FLUID_SOURCES,
    BenchCase.SLOSH: _FLUID_SOURCES,
    BenchCase.DAM_BREAK: _FLUID_SOURCES,
    BenchCase.FREE_FALL: _FLUID_SOURCES,
    BenchCase.COUPLING_STATIC: _COUPLED_SOURCES,
    BenchCase.POUR: _ALL_SOURCES,
}
_NOT_SIMULATION = ("cosim/bench/", "cosim/cli/")
_SUFFIXES = (".py", ".xml", ".csv", ".toml", ".stl", ".obj")
_DEPENDENCIES = ("warp-lang", "mujoco", "numpy", "ruckig", "control")


def _files(base: Path, source: str) -> list[tuple[str, Path]]:
    root = (base / source).resolve()
    if root.is_file():
        return [(source, root)]
    out = []
    for path in root.rglob("*"):
        rel = f"{source}/{path.relative_to(root).as_posix()}"
        if path.is_file() and path.suffix in _SUFFIXES and not rel.startswith(_NOT_SIMULATION) and "__pycache__" not in rel:
            out.append((rel, path))
    return out


def code_version(case: BenchCase) -> str:
    """Hash of the sources ``case`` runs through (:data:`SOURCES`) and of the installed versions of the numerical
    dependencies."""
    import cosim

    base = Path(cosim.__file__).resolve().parent.parent
    files = dict(f for source in SOURCES[case] for f in _files(base, source))
    h = hashlib.sha256()
    for rel in sorted(files):
        h.update(rel.encode() + b"\0" + files[rel].read_bytes() + b"\0")
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
