"""Error types shared by every layer.

``InputError`` is bad user input (a scene field out of range, a corrupt file, an unreachable target): the CLI
prints its one-line message and exits with status 2. ``SimulationError`` is a run that broke (a numerical
instability): the CLI prints it and exits with status 1.
"""


class InputError(ValueError):
    """Bad input. The message is one line naming the field (or file) and the allowed range."""


class SimulationError(RuntimeError):
    """A simulation that broke while running (non-finite values, a wall breached, ...)."""


def count_of(count: int, noun: str) -> str:
    """A count in a message: '1 particle', '3 particles' (nouns with a plain plural)."""
    return f"{count} {noun}{'' if count == 1 else 's'}"
