"""Side-by-side timing of the skip pairs (cosim.bench.interleave): ABBA order, medians, speed-up, the table and
its place in the document, with a stand-in runner (no simulation)."""

from pathlib import Path

import pytest

from cosim.bench.interleave import BEGIN, END, table, time_pair
from cosim.bench.plan import build_plan
from cosim.bench.report import update_document

OPTION = next(s for s in build_plan("full").skips if s.name == "neighbour grid restricted to the liquid")


def test_runs_alternate_in_abba_order_and_the_speed_up_is_the_ratio_of_medians():
    calls = []
    wall = {OPTION.skip: [1.0, 3.0, 2.0, 9.0], OPTION.full: [4.0, 6.0, 5.0, 20.0]}

    def runner(cfg):
        calls.append("skip" if cfg == OPTION.skip else "full")
        return {"wall_s": wall[cfg].pop(0), "sim_s": 2.0}

    timing = time_pair(OPTION, 4, runner)
    assert calls == ["skip", "full", "full", "skip", "skip", "full", "full", "skip"]
    assert timing.skip == (0.5, 1.5, 1.0, 4.5) and timing.full == (2.0, 3.0, 2.5, 10.0)
    assert timing.speed_up == pytest.approx(2.75 / 1.25)


def test_table_goes_between_its_own_markers(tmp_path: Path):
    timing = time_pair(OPTION, 1, lambda cfg: {"wall_s": 3.0 if cfg == OPTION.full else 2.0, "sim_s": 1.0})
    text = table([timing], 1, "python -m cosim.bench.interleave --repeats 1")
    assert "| neighbour grid restricted to the liquid" in text and "1.50x" in text
    doc = tmp_path / "b.md"
    doc.write_text(f"# B\n\nbefore\n{BEGIN}\nold\n{END}\nafter\n")
    update_document(doc, text, BEGIN, END)
    out = doc.read_text()
    assert "old" not in out and out.index("before") < out.index("1.50x") < out.index("after")
