"""The model figures (the paper's Figs. 13-16) render from the command line, on either slosh model."""

from pathlib import Path

import pytest

from cosim.tools.controller_figures import main

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("plant", ["potential-flow", "printed-paper"])
@pytest.mark.slow
def test_figures_are_written(tmp_path: Path, capsys: pytest.CaptureFixture[str], plant: str) -> None:
    assert main(["--out", str(tmp_path), "--plant", plant]) == 0
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
    assert "closed-loop poles (rad/s):" in out and "gain margin" in out and "phase margin" in out
    assert ("potential flow" if plant == "potential-flow" else "as printed") in out
