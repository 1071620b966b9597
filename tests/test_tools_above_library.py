"""Every command-line tool sits above the library: a module that runs as a command (``python -m``, an argument parser)
lives in a package of the import contract's tool layers (``pyproject.toml``: the layers down to ``cosim.tools``),
never in a core package that the library imports (the layers contract keeps the library from importing the tools)."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LIBRARY_ROOTS = ("cosim", "controllers", "declared_settings")
COMMAND = re.compile(r"""^if __name__ == ["']__main__["']:|^import argparse\b|^from argparse import""", re.MULTILINE)


def _tool_packages() -> tuple[str, ...]:
    """The packages of the layers above the library: from the top layer down to the one of ``cosim.tools``."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    contracts = config["tool"]["importlinter"]["contracts"]
    layers = next(c["layers"] for c in contracts if c["type"] == "layers")
    top = next(i for i, layer in enumerate(layers) if "cosim.tools" in layer.split(" | "))
    return tuple(name for layer in layers[: top + 1] for name in layer.split(" | "))


def _module(path: Path) -> str:
    return ".".join(path.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")


def test_every_command_line_tool_is_in_a_tool_layer():
    tools = _tool_packages()
    assert "cosim.cli" in tools and "cosim.tools" in tools
    commands = [_module(p) for root in LIBRARY_ROOTS for p in sorted((ROOT / root).rglob("*.py"))
                if COMMAND.search(p.read_text(encoding="utf-8"))]
    assert "cosim.tools.generate_models" in commands  # the check sees a tool where one is
    inside_library = [m for m in commands if not any(m == t or m.startswith(t + ".") for t in tools)]
    assert inside_library == [], f"command-line tools inside core packages (move them to cosim.tools): {inside_library}"
