"""The solver-threads benchmark (cosim.bench.thread_contention) with a stand-in for the pour processes: ABBA order,
medians and their ratio in the table, refused arguments."""

from pathlib import Path

from cosim.bench.thread_contention import PourTiming, main, table, table_row, time_rounds


def test_rounds_alternate_in_abba_order_and_the_row_has_the_ratio_of_medians(tmp_path: Path):
    walls = {0: [10.0, 30.0, 14.0, 50.0], 1: [20.0, 20.0, 22.0, 24.0]}
    calls = []

    def stand_in(threads, duration, folder):
        calls.append(threads)
        return PourTiming(threads, 2 if threads == 0 else 1, walls[threads].pop(0), 90 if threads == 0 else 0, 100, 1.5)

    runs = time_rounds(2.0, 4, tmp_path, "quiet", stand_in)
    assert calls == [0, 1, 1, 0, 0, 1, 1, 0]
    row = table_row("none", runs)
    # default: median of 10, 30, 14, 50 = 22; one thread: median of 20, 20, 22, 24 = 21
    assert "| 22.0 (10.0, 30.0, 14.0, 50.0) | 2 | 90 % | 21.0 (20.0, 20.0, 22.0, 24.0) | 1.05 |" in row
    assert "| 1.5 to 1.5 |" in row
    assert row in table([row], 2.0, 4, "python -m cosim.bench.thread_contention --repeats 4")


def test_out_of_range_arguments_are_refused(capsys):
    assert main(["--duration", "-1"]) == 2
    assert "--duration: must be in (0, 60] s" in capsys.readouterr().err
    assert main(["--repeats", "0"]) == 2
