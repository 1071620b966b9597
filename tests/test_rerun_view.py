"""`cosim view RUN`: bad RUN is one line and exit 2; a good one gives the viewer command, or, with no display,
instructions instead of a viewer that would hang."""

from __future__ import annotations

import shlex
import subprocess
import sys

import mujoco
import pytest

from cosim.cli import view
from cosim.cli.main import main
from cosim.io.recording import PourRecorder

SINGLE_BODY = "<mujoco><worldbody><body name='cup'><joint type='hinge'/><geom type='box' size='.1 .1 .1'/></body></worldbody></mujoco>"


@pytest.fixture
def run_dir(tmp_path):
    """A run folder holding a small but complete pour.rrd."""
    with PourRecorder(tmp_path / "pour.rrd", mujoco.MjModel.from_xml_string(SINGLE_BODY)) as rec:
        rec.log_scalars(0.0, 0, {"pourer/theta": 0.0})
    return tmp_path


def test_missing_run_exits_2_with_one_line(tmp_path, capsys):
    assert main(["view", str(tmp_path / "nowhere")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("cosim view: error: RUN: no recording at ") and err.count("\n") == 1
    assert main(["view", str(tmp_path)]) == 2  # a folder without pour.rrd


def test_a_run_made_without_its_recording_says_so(tmp_path, capsys):
    (tmp_path / "summary.json").write_text("{}")  # a run folder of `cosim pour --no-log`: outputs, no pour.rrd
    assert main(["view", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("cosim view: error: RUN: ") and "without its recording" in err and "--no-log" in err and err.count("\n") == 1


@pytest.mark.parametrize("content", [b"", b"not a recording\n"])
def test_unreadable_file_exits_2_with_one_line(tmp_path, capsys, content):
    bad = tmp_path / "pour.rrd"
    bad.write_bytes(content)
    assert main(["view", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("cosim view: error: RUN: ") and "not a readable Rerun recording" in err and err.count("\n") == 1


def test_truncated_recording_exits_2(run_dir, capsys):
    data = (run_dir / "pour.rrd").read_bytes()
    (run_dir / "pour.rrd").write_bytes(data[: len(data) // 2])
    assert main(["view", str(run_dir)]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_print_only_gives_a_working_viewer_command(run_dir, capsys):
    assert main(["view", str(run_dir), "--print-only"]) == 0
    command = shlex.split(capsys.readouterr().out.strip())
    assert command[-1] == str((run_dir / "pour.rrd").resolve())
    # the same rerun CLI answers (without opening a window): it is installed and runnable
    version = subprocess.run(command[:-1] + ["--version"], capture_output=True, text=True)
    assert version.returncode == 0 and version.stdout.startswith("rerun-cli")


def test_headless_prints_instructions_and_starts_nothing(run_dir, capsys, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")

    def no_spawn(*args, **kwargs):
        raise AssertionError("a viewer was started without a display")

    monkeypatch.setattr(subprocess, "call", no_spawn)
    assert main(["view", str(run_dir / "pour.rrd")]) == 0
    out = capsys.readouterr().out
    assert "no display" in out and f"rerun {run_dir / 'pour.rrd'}" in out


def test_with_a_display_the_viewer_is_run_on_the_file(run_dir, monkeypatch):
    monkeypatch.setenv("DISPLAY", ":0")
    calls = []
    monkeypatch.setattr(subprocess, "call", lambda command: calls.append(command) or 0)
    assert main(["view", str(run_dir)]) == 0
    assert calls == [view.viewer_command((run_dir / "pour.rrd").resolve())]
