"""Error types of the controllers package (no dependency on ``cosim``).

``ControllerInputError`` is bad configuration (a field out of range, an inconsistent choice): one line that names
the field and the allowed range. The CLI maps it to exit status 2, like ``cosim.errors.InputError``.

``MeasurementError`` is a measurement the controller cannot act on (NaN, time running backwards): the
simulation that produced it broke, so the CLI maps it to exit status 1, like ``cosim.errors.SimulationError``.
"""


class ControllerInputError(ValueError):
    """Bad controller configuration. The message is one line naming the field and the allowed range."""


class MeasurementError(ValueError):
    """A liquid measurement the controller cannot use (non-finite value, time not increasing)."""
