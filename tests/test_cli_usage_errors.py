"""Every command's malformed command line (a value of the wrong type, an unknown option or command, no command) is
one line on stderr and exit status 2, as every other bad input: argparse's own usage block is not printed."""

from __future__ import annotations

import pytest

from cosim.cli.main import SUBCOMMANDS, main

WRONG = [
    (["pour", "--threads", "abc"], "cosim pour: error: argument --threads: invalid int value: 'abc' (see cosim pour --help)"),
    (["pour", "--duration", ""], "cosim pour: error: argument --duration: invalid float value: '' (see cosim pour --help)"),
    (["validate", "--solver", "bogus"], "cosim validate: error: argument --solver: invalid choice: 'bogus'"),
    (["replay", "x.csv", "--payload", "bogus"], "cosim replay: error: argument --payload: invalid choice: 'bogus'"),
    (["sweep", "s.toml", "--max-parallel", "1.5"], "cosim sweep: error: argument --max-parallel: invalid int value: '1.5'"),
    (["nosuch"], "cosim: error: argument COMMAND: invalid choice: 'nosuch'"),
    (["pour", "--bogus"], "cosim: error: unrecognized arguments: --bogus"),
    (["scene", "--check"], "cosim scene: error: argument --check: expected one argument"),
]


@pytest.mark.parametrize(("argv", "expected"), WRONG, ids=lambda v: " ".join(v) if isinstance(v, list) else "")
def test_a_malformed_command_line_is_one_line_and_exit_2(argv, expected, capsys):
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(expected), captured.err
    assert captured.out == ""


def test_no_command_prints_the_help_and_one_error_line(capsys):
    assert main([]) == 2
    captured = capsys.readouterr()
    assert captured.err.strip() == f"cosim: error: a command is required: {', '.join(SUBCOMMANDS)}"
    assert "usage: cosim" in captured.out
