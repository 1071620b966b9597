"""Error types shared by every layer.

``InputError`` is bad user input (a scene field out of range, a corrupt file, an unreachable target), the one
error of :mod:`declared_settings.errors` that the settings' checks and the controllers raise too: the CLI prints its
one-line message and exits with status 2. ``SimulationError`` is a run that broke (a numerical instability): the
CLI prints it and exits with status 1.
"""

from declared_settings.errors import InputError  # noqa: F401 (every cosim layer imports it from here)


class SimulationError(RuntimeError):
    """A simulation that broke while running (non-finite values, a wall breached, ...)."""


def count_of(count: int, noun: str) -> str:
    """A count in a message: '1 particle', '3 particles' (nouns with a plain plural)."""
    return f"{count} {noun}{'' if count == 1 else 's'}"
