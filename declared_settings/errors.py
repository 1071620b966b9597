"""The error of bad input, shared by every package of the project.

``InputError`` is bad user input (a setting out of range, a corrupt file, an unreachable target): its message is one
line naming the field (or file) and the allowed values, and the command line prints it and exits with status 2.
"""


class InputError(ValueError):
    """Bad input. The message is one line naming the field (or file) and the allowed range."""
