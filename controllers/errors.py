"""Error types of the controllers package (no dependency on ``cosim``).

``ControllerInputError`` is bad configuration (a field out of range, an inconsistent choice): one line that names
the field and the allowed range. It is the project's one error of bad input,
:class:`declared_settings.errors.InputError`, which the settings' checks raise: the CLI maps it to exit status 2.

``MeasurementError`` is a measurement the controller cannot act on (NaN, time running backwards): the
simulation that produced it broke, so the CLI maps it to exit status 1, like ``cosim.errors.SimulationError``.
"""

from declared_settings.errors import InputError

ControllerInputError = InputError  # bad controller configuration, by the name the controllers raise it


class MeasurementError(ValueError):
    """A liquid measurement the controller cannot use (non-finite value, time not increasing)."""
