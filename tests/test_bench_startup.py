"""The start-up benchmark (cosim.bench.startup): its commands come back with status 0 or 2, a failing one is an
error, bad input is refused."""

import subprocess
import sys
from pathlib import Path

import pytest

from cosim.bench import startup
from cosim.cli.main import main


def test_each_command_is_timed_every_round(tmp_path: Path):
    lines = {"pass": [sys.executable, "-c", "pass"], "refused": [sys.executable, "-c", "raise SystemExit(2)"]}
    times = startup.time_commands(lines, 2)
    assert set(times) == {"pass", "refused"} and all(len(runs) == 2 and min(runs) > 0.0 for runs in times.values())


def test_a_command_that_fails_otherwise_is_an_error():
    with pytest.raises(RuntimeError, match="crash: exit status 1"):
        startup.time_commands({"crash": [sys.executable, "-c", "raise SystemExit(1)"]}, 1)


@pytest.mark.parametrize("wrong", list(startup.BAD_SCENES))
def test_each_bad_scene_is_refused_by_both_commands(wrong, tmp_path: Path, capsys):
    """Each timed bad scene is refused (exit status 2, one line), so that the bench never starts a pour."""
    path = startup.write_bad_scenes(tmp_path)[wrong]
    lines = startup.commands({wrong: path})
    assert lines[f"cosim pour BAD.toml ({wrong})"][-2:] == ["pour", str(path)]
    assert lines[f"cosim scene --check BAD.toml ({wrong})"][-3:] == ["scene", "--check", str(path)]
    for args in (["pour", str(path)], ["scene", "--check", str(path)]):
        assert main(args) == 2
        error = capsys.readouterr().err.strip()
        assert "\n" not in error and f"{path}: " in error


def test_bad_input_is_refused(capsys):
    assert startup.main(["--repeats", "0"]) == 2
    assert capsys.readouterr().err.strip() == "error: --repeats: must be in [1, 50], got 0"


def test_a_command_from_another_tree_runs_there_and_imports_from_there(tmp_path: Path):
    line = startup.from_tree([sys.executable, "-c", "import os, sys; print(os.getcwd(), sys.path[1])"], tmp_path)
    done = subprocess.run(line, capture_output=True, text=True, check=True)
    assert done.stdout.split() == [str(tmp_path), str(tmp_path)]


def test_a_before_tree_that_is_no_checkout_is_refused(tmp_path: Path, capsys):
    assert startup.main(["--before", str(tmp_path)]) == 2
    expected = f"error: --before: must be a checkout of cosim (with cosim/__main__.py), got {tmp_path}"
    assert capsys.readouterr().err.strip() == expected
