"""The model figures (seed Figs. 13-16) render from the command line."""

from pathlib import Path

import pytest

from controllers.figures import main

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def test_figures_are_written(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--out", str(tmp_path)]) == 0
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == [
        "fig13_theta1_ratio.png",
        "fig14_root_locus.png",
        "fig15_step_response.png",
        "fig16_sim_timeline.png",
    ]
    for name in names:
        assert (tmp_path / name).read_bytes()[:8] == PNG_MAGIC
    out = capsys.readouterr().out
    assert "closed-loop poles (rad/s):" in out and "settling time" in out
