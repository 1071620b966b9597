"""The head-floor study: which heads it counts as resolved, its input checks, and one coarse run end to end."""

from __future__ import annotations

import pytest

from cosim.bench import weir_head_floor as study
from cosim.errors import InputError
from cosim.validation import weir


def _run(spacings: float, error: float) -> study.HeadRun:
    return study.HeadRun(spacings, 0.01, 0.01, 1.0, error, 0.0, 0.0011, 100, 1.0)


def test_the_floor_is_the_smallest_head_from_which_on_every_head_passes() -> None:
    runs = [_run(2.0, -0.17), _run(2.5, -0.08), _run(3.0, -0.03), _run(4.0, 0.002)]
    assert study.resolved_floor(runs) == 3.0
    # a failing head above a passing one ends the range: the floor is above it
    assert study.resolved_floor([_run(2.5, 0.01), _run(3.0, -0.06), _run(4.0, 0.0)]) == 4.0
    assert study.resolved_floor([_run(3.0, 0.0), _run(4.0, 0.051)]) is None
    assert study.resolved_floor([_run(3.0, 0.05)]) == 3.0  # the tolerance's edge passes, as the case's does


def test_the_heads_are_checked_against_the_weirs_own_range() -> None:
    assert study.parse_spacings("4,2.5,2.5") == [2.5, 4.0]
    assert study.parse_spacings("1") == [1.0]  # the 3-D pour's floor, one row of particles over the crest
    for bad in ("", "x", "0.5", "2,30"):
        with pytest.raises(InputError, match=r"^--spacings: .*\[1, 20\]"):
            study.parse_spacings(bad)
    with pytest.raises(InputError, match=r"^spacing: .* needs >= 1$"):
        weir.Params(head=0.007, spacing=0.008)


@pytest.mark.parametrize("argv, field", [(["--across", "4"], "--across"), (["--duration", "0"], "--duration"),
                                          (["--spacings", "0.5,2"], "--spacings"), (["--dim", "4"], "--dim"),
                                          (["--dim", "3", "--depth", "0.01"], "depth"),
                                          (["--dim", "3", "--depth", "0.035"], "depth")])
def test_bad_input_is_one_line_and_exit_status_2(argv, field, capsys) -> None:
    assert study.main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and field in err


def test_a_coarse_head_run_measures_the_weir() -> None:
    run = study.run_head(4.0, 0.191 / 16, 0.4)  # 47.8 mm head at 16 across, 0.4 s: a flow, not yet a steady one
    assert run.nominal_head == pytest.approx(4.0 * 0.191 / 16)
    assert 0.5 * run.nominal_head < run.head < 1.5 * run.nominal_head
    assert 0.5 < run.discharge_over_supply < 2.0 and run.particles > 100
