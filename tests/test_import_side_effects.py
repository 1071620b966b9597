"""Importing the packages changes nothing outside them: every module of ``cosim`` and ``controllers`` is imported in
a fresh interpreter, and the process environment, warp's global configuration and warp's runtime (not initialised)
are as they were. The commands set what they need when they run (``cosim.cli.main``, ``cosim.fluid.runtime``)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

IMPORT_ALL = """
import importlib, importlib.util, json, os, pkgutil
import warp as wp

# warp's runtime object (None until wp.init), in warp._src.context in recent releases, warp.context before
context = importlib.import_module("warp._src.context" if importlib.util.find_spec("warp._src") else "warp.context")

def config():
    return {k: repr(v) for k, v in vars(wp.config).items() if not k.startswith("_")}

env, cfg = dict(os.environ), config()
names = []
for package in ("cosim", "controllers"):
    root = importlib.import_module(package)
    for info in pkgutil.walk_packages(root.__path__, package + "."):
        if info.name.rsplit(".", 1)[-1] != "__main__":  # ``python -m cosim`` runs the command
            importlib.import_module(info.name)
            names.append(info.name)
changed_env = sorted(k for k in set(env) | set(os.environ) if env.get(k) != os.environ.get(k))
changed_cfg = sorted(k for k in set(cfg) | set(config()) if cfg.get(k) != config().get(k))
print(json.dumps({"modules": names, "env": changed_env, "warp_config": changed_cfg,
                  "warp_initialised": context.runtime is not None}))
"""


def test_importing_every_module_changes_no_environment_and_no_warp_configuration():
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", IMPORT_ALL], cwd=ROOT, env=env, capture_output=True, text=True, check=True)
    result = json.loads(out.stdout.strip().splitlines()[-1])
    assert "cosim.cli.main" in result["modules"] and "cosim.fluid.solver" in result["modules"]
    assert result["env"] == []
    assert result["warp_config"] == []
    assert result["warp_initialised"] is False
