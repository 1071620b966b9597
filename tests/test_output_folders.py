"""Every command refuses an output folder it could not create or write in, before doing any work: one line naming
the option, exit status 2, nothing written (instead of a traceback after the run); and a pour whose default run
folder another pour took meanwhile keeps its outputs under the next free name; a pour stopped by SIGTERM removes its
partial run folder."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

import cosim.atomic_files
import cosim.pour_run
from cosim.atomic_files import PARTIAL_TAG, check_output_folder
from cosim.cli.main import main
from cosim.errors import InputError

# (command line with {blocked} for a path below a regular file, the option the error must name)
COMMANDS = [
    ("pour --out {blocked}/run --quiet", "--out"),
    ("scene --dump --out {blocked}/scene.toml", "--out"),
    ("validate coupling-static --out {blocked}/plots", "--out"),
    ("bench --plan smoke --out {blocked}/bench --quiet", "--out"),
    ("bench --plan smoke --out {ok}/bench --docs {blocked}/benchmarks.md --quiet", "--docs"),
    ("bench --plan smoke --out {ok}/bench --cache {blocked}/cache --quiet", "--cache"),
    ("bench --plan targets --out {blocked}/targets", "--out"),
    ("stress --quick --out {blocked}/stress", "--out"),
]


def _files(root):
    return sorted(p.relative_to(root) for p in root.rglob("*"))


@pytest.mark.parametrize("command,option", COMMANDS, ids=["pour", "scene", "validate", "bench", "bench-docs", "bench-cache", "targets", "stress"])
def test_an_output_folder_below_a_file_is_one_line_exit_2_and_nothing_written(tmp_path, capsys, command, option):
    blocked = tmp_path / "a_file"
    blocked.write_text("not a folder")
    before = _files(tmp_path)
    argv = command.format(blocked=blocked, ok=tmp_path / "ok").split()
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"error: {option}:" in err[0] and "a_file is a file, not a folder" in err[0], err
    assert _files(tmp_path) == before
    assert blocked.read_text() == "not a folder"


def test_a_folder_without_write_permission_is_refused_by_name(tmp_path, monkeypatch):
    # root may write anywhere, so the permission is taken away at the check's trial folder itself
    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(cosim.atomic_files.tempfile, "mkdtemp", refuse)
    with pytest.raises(InputError, match=r"^--out: cannot write in .*\(Permission denied\)$"):
        check_output_folder(tmp_path / "new" / "deeper", "--out")
    assert _files(tmp_path) == []


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs Linux's /proc")
def test_a_folder_that_grants_write_permission_but_takes_no_folder_is_refused(tmp_path):
    # os.access grants root /proc; only trying shows that no folder can be made there
    assert os.access("/proc", os.W_OK) or os.geteuid() != 0
    with pytest.raises(InputError, match=r"^--out: cannot write in /proc \("):
        check_output_folder("/proc/no_such_folder/run", "--out")


LONG = "n" * 300  # bytes: a name no common file system takes (255 at most)

# (command line with {long} for a path whose last name is too long, the name's length in the error)
LONG_NAMES = [
    ("pour --out {long} --quiet --no-log", "300 bytes long; at most 237"),  # its unfinished sibling adds 18
    ("scene --dump --out {long}.toml", "305 bytes long; at most 240"),  # its temporary sibling adds 10 and the suffix
    ("validate coupling-static --out {long}", "300 bytes long; at most 255"),
    ("stress --quick --out {long}", "300 bytes long; at most 255"),
]


@pytest.mark.parametrize("command,expected", LONG_NAMES, ids=["pour", "scene", "validate", "stress"])
def test_a_name_too_long_for_the_file_system_is_one_line_exit_2_and_nothing_written(tmp_path, capsys, command, expected):
    argv = command.format(long=tmp_path / LONG).split()
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "error: --out: the name 'nnnn" in err[0] and expected in err[0], err
    assert _files(tmp_path) == []


def test_an_output_path_that_is_a_link_loop_is_refused_before_the_work(tmp_path, capsys):
    # it exists as a name but is no folder: the pour ran to its end and failed at its rename before
    (tmp_path / "a").symlink_to(tmp_path / "b")
    (tmp_path / "b").symlink_to(tmp_path / "a")
    before = _files(tmp_path)
    assert main(["pour", "--out", str(tmp_path / "a"), "--quiet", "--no-log", "--duration", "0.01"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"cosim pour: error: --out: {tmp_path / 'a'} is a broken link, not a folder"]
    assert _files(tmp_path) == before


def test_an_input_path_the_system_refuses_is_one_line_exit_2(tmp_path, capsys):
    # an OSError about a path the user gave (here a name too long to look up) is bad input, not a traceback
    assert main(["view", "--print-only", str(tmp_path / LONG)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("cosim view: error: [Errno ") and "File name too long" in err[0], err


def test_a_scene_name_too_long_for_a_run_folder_is_refused_and_a_long_file_name_is_cut(tmp_path):
    from cosim.pour_scene import MAX_NAME_LENGTH, PourScene

    with pytest.raises(InputError, match=rf"^scene.name: at most {MAX_NAME_LENGTH} characters"):
        PourScene(name="x" * (MAX_NAME_LENGTH + 1))
    named = PourScene().named_after(tmp_path / ("f" * 240 + ".toml"))
    assert named.name == "f" * MAX_NAME_LENGTH


def test_a_writable_path_passes_and_creates_nothing(tmp_path):
    check_output_folder(tmp_path / "new" / "deeper", "--out")
    check_output_folder(tmp_path, "--out")
    assert _files(tmp_path) == []


def test_a_pour_whose_run_folder_cannot_be_made_is_one_line_exit_2(tmp_path, capsys, monkeypatch):
    # a folder that passes the check but cannot be made all the same (as under /proc): refused by name, not a
    # traceback, and nothing left behind
    real = cosim.pour_run.tempfile.mkdtemp

    def refuse(*args, prefix="", **kwargs):  # the run's own folder only: the check's trial folder is made
        if PARTIAL_TAG in prefix:
            raise PermissionError(13, "Permission denied")
        return real(*args, prefix=prefix, **kwargs)

    monkeypatch.setattr(cosim.pour_run.tempfile, "mkdtemp", refuse)
    assert main(["pour", "--out", str(tmp_path / "run"), "--quiet", "--no-log", "--duration", "0.01"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "error: --out: cannot create a folder in" in err[0] and "Permission denied" in err[0], err
    assert _files(tmp_path) == []


def test_two_pours_that_pick_the_same_default_folder_both_keep_their_outputs(tmp_path, capsys, monkeypatch):
    # two pours started in the same second choose the same recordings/ name; the one finishing second gets the next
    # free name instead of failing at its end (and losing its outputs)
    monkeypatch.chdir(tmp_path)
    real = cosim.pour_run.destination
    taken = []

    def destination_taken_meanwhile(out, name):
        final = real(out, name)
        final.mkdir(parents=True)
        (final / "summary.json").write_text("the other run's")
        taken.append(final)
        return final

    monkeypatch.setattr(cosim.pour_run, "destination", destination_taken_meanwhile)
    assert main(["pour", "--quiet", "--no-log", "--duration", "0.01"]) == 0
    runs = sorted(p.relative_to(tmp_path) for p in (tmp_path / "recordings").iterdir())
    assert len(runs) == 2 and taken[0] in runs  # taken[0] is relative to the working directory, tmp_path
    assert (taken[0] / "summary.json").read_text() == "the other run's"
    ours = next(p for p in runs if p != taken[0])
    assert (ours / "summary.json").is_file() and (ours / "trajectory.csv").is_file()
    assert f"wrote {ours}:" in capsys.readouterr().out


@pytest.mark.slow
def test_a_terminated_pour_leaves_nothing_behind_and_exits_143(tmp_path):
    # a batch scheduler stops a job with SIGTERM: the pour unwinds as on Ctrl-C, removing its partial run folder
    out = tmp_path / "run"
    proc = subprocess.Popen([sys.executable, "-m", "cosim", "pour", "--out", str(out), "--no-log", "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60.0
    while not list(tmp_path.glob(f".run{PARTIAL_TAG}*")) and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(1.0)  # into the step loop
    assert proc.poll() is None, proc.communicate()
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert err.strip().splitlines()[-1] == "cosim pour: terminated", err
    assert list(tmp_path.iterdir()) == []
