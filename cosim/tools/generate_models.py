"""Regenerate the MJCF files derived from code: ``models/vessels/<name>.xml`` and ``models/scene.xml``.

Run ``python -m cosim.tools.generate_models`` after changing :mod:`cosim.vessel`, :mod:`cosim.robots.scene_config`,
:mod:`cosim.robots.scene_builder` or ``models/ur10e/ur10e.xml``; ``tests/test_robot_models.py`` fails while the
committed files differ from what this produces. Files are written atomically (:mod:`cosim.atomic_files`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from cosim.atomic_files import atomic_path
from cosim.robots import assets
from cosim.robots.scene_builder import scene_mjcf
from cosim.robots.scene_config import default_scene_config
from cosim.robots.vessel_mjcf import vessel_mjcf


def generated_files() -> dict[str, str]:
    """Relative path (under the models directory) -> MJCF text, for every generated model file."""
    config = default_scene_config()
    files = {f"{assets.VESSEL_DIR}/{p.vessel.name}.xml": vessel_mjcf(p.vessel) for p in config.placements}
    files[assets.DEFAULT_SCENE] = scene_mjcf(config)
    return files


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", type=Path, default=None, help="models directory (default: the package's)")
    args = parser.parse_args(argv)
    root = args.models or assets.models_dir()
    for relative, text in generated_files().items():
        with atomic_path(root / relative) as tmp:
            tmp.write_text(text, encoding="utf-8")
        print(f"wrote {root / relative}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
