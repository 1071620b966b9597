"""The generator-tracking bench: a small smooth path with its exact derivatives is tracked closely, and the table
prints for every mode."""

from cosim.bench.generator_tracking import MODES, main, track

SMALL_PATH_ERROR = 1e-5  # rad: a 0.002 rad, 2 Hz path given exactly is tracked to round-off of the profiles


def test_small_exact_path_is_tracked() -> None:
    result = track("exact", 0.002, 2.0)
    assert result["max_error"] < SMALL_PATH_ERROR
    assert 0.0 <= result["jerk_at_limit"] <= 1.0


def test_table_prints_every_mode(capsys) -> None:
    assert main(["--amplitudes", "0.002"]) == 0
    out = capsys.readouterr().out
    assert all(mode in out for mode in MODES)
