"""Where the MJCF models live: one lookup for the source tree and for an installed package.

``models/`` sits at the repository root. A non-editable ``pip install .`` ships it inside the package as
``cosim/models`` (``cosim/models`` is a symbolic link to ``../models`` in the source tree; setuptools copies the
files it points to, see ``[tool.setuptools.package-data]`` in pyproject.toml). Everything that opens a model file goes
through :func:`models_dir` / :func:`model_path`.
"""

from __future__ import annotations

from pathlib import Path

from cosim.errors import InputError

# The default scene, relative to the models directory.
DEFAULT_SCENE = "scene.xml"
# The hand-written UR10e arm, relative to the models directory.
UR10E_ARM = "ur10e/ur10e.xml"
# Generated vessel files live here, relative to the models directory.
VESSEL_DIR = "vessels"

_PACKAGE_DIR = Path(__file__).resolve().parent.parent  # .../cosim


def models_dir() -> Path:
    """The directory holding the project's MJCF models (``scene.xml``, ``ur10e/``, ``vessels/``).

    Looks in the installed package (``cosim/models``, also the symlink in a source checkout) first, then in the
    repository root next to the package (a checkout whose file system has no symbolic links).
    """
    for candidate in (_PACKAGE_DIR / "models", _PACKAGE_DIR.parent / "models"):
        if (candidate / UR10E_ARM).is_file():
            return candidate.resolve()
    raise FileNotFoundError(
        f"cosim models not found in {_PACKAGE_DIR / 'models'} or {_PACKAGE_DIR.parent / 'models'}; "
        "reinstall the package (pip install .)"
    )


def model_path(relative: str) -> Path:
    """Absolute path of a model file given relative to the models directory; ``InputError`` if it is missing."""
    path = models_dir() / relative
    if not path.is_file():
        raise InputError(f"model file {relative!r}: not found under {models_dir()}")
    return path
