"""A command-line refusal as the tests read it: exit status 2 and one error line on stderr."""

from __future__ import annotations

from cosim.cli.main import main


def refusal(capsys, argv: list[str], command: str) -> str:
    """Run ``cosim argv``, assert that it refuses with exit status 2 and one line ``cosim <command>: error: ...`` on
    stderr, and return that line's message."""
    assert main(argv) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"cosim {command}: error: "), captured.err
    return lines[0].removeprefix(f"cosim {command}: error: ")
