"""The checks the controllers' configurations use: those of :mod:`declared_settings.checks`, each raising one
:class:`controllers.errors.ControllerInputError` line in the project's format
(``field: must be in (lo, hi] unit, got value``), so that the CLI prints controller and scene errors alike."""

from declared_settings.checks import check_choice, check_range  # noqa: F401 (imported by the controllers from here)
