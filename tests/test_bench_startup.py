"""The start-up benchmark (cosim.bench.startup): its commands come back with status 0 or 2, a failing one is an
error, bad input is refused."""

import sys
from pathlib import Path

import pytest

from cosim.bench import startup


def test_each_command_is_timed_every_round(tmp_path: Path):
    lines = {"pass": [sys.executable, "-c", "pass"], "refused": [sys.executable, "-c", "raise SystemExit(2)"]}
    times = startup.time_commands(lines, 2)
    assert set(times) == {"pass", "refused"} and all(len(runs) == 2 and min(runs) > 0.0 for runs in times.values())


def test_a_command_that_fails_otherwise_is_an_error():
    with pytest.raises(RuntimeError, match="crash: exit status 1"):
        startup.time_commands({"crash": [sys.executable, "-c", "raise SystemExit(1)"]}, 1)


def test_the_bad_scene_is_refused_by_cosim(tmp_path: Path):
    bad = tmp_path / "BAD.toml"
    bad.write_text(startup.BAD_SCENE)
    line = startup.commands(bad)["cosim pour BAD.toml (an unknown key)"]
    assert startup.time_commands({"bad": line}, 1)["bad"][0] > 0.0  # exit status 2, or the call raises


def test_bad_input_is_refused(capsys):
    assert startup.main(["--repeats", "0"]) == 2
    assert capsys.readouterr().err.strip() == "error: --repeats: must be in [1, 50], got 0"
