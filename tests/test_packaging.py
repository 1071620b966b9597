"""The installed package must carry its data: the MJCF models (`cosim pour` loads the default scene from them) and
the validation reference data. Builds the wheel and lists it (a non-editable install is what users get)."""

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_wheel_ships_models_and_reference_data(tmp_path):
    build = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(tmp_path), str(ROOT)],
        capture_output=True, text=True,
    )
    assert build.returncode == 0, build.stderr[-2000:]
    (wheel,) = tmp_path.glob("cosim-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    for model in sorted(p.relative_to(ROOT / "models") for p in (ROOT / "models").rglob("*.xml")):
        assert f"cosim/models/{model.as_posix()}" in names
    assert "cosim/validation/data/martin_moyce_1952_surge_front.csv" in names
    assert "controllers/pour.py" in names
    assert "declared_settings/setting.py" in names
