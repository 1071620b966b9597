"""Configuration settings declared once, for every package of the project (no dependency on any of them).

A frozen configuration dataclass declares each field with :func:`declared_settings.setting.setting`: its default,
group, meaning, unit and allowed values. From that one declaration come the field's check (one
:class:`declared_settings.errors.InputError` line naming the field and the allowed values), the class's reference
in its docstring and the comments of a scene file. :mod:`declared_settings.checks` holds the checks themselves.
"""
