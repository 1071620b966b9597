"""A configuration field declared once: its group, unit, default, allowed values and meaning.

A frozen configuration dataclass declares each field as ``name: type = setting(default, group, meaning, ...)``: the
default goes to the dataclass, the rest to the field's metadata as a :class:`Setting`. From that one declaration
:func:`check_settings` checks a value (one :class:`declared_settings.errors.InputError` line naming the field and its
allowed values), :func:`settings_reference` writes the class's reference (its docstring, :func:`documented`) and
``cosim.config_mapping`` the scene file's comments. :func:`like` declares a field of another class as the same
setting, with the same default. A bound may name another field (or a property) of the same object, e.g. a stop's
deceleration at most the turn's acceleration: ``setting(0.9, ..., lo=0.0, hi="max_accel", lo_open=True)``.
"""

from __future__ import annotations

import dataclasses
import math
import textwrap
from dataclasses import dataclass
from enum import Enum
from operator import attrgetter
from typing import Any

from declared_settings.checks import check_choice, check_int, check_range, check_vector, interval_text
from declared_settings.errors import InputError

SETTING = "setting"  # the metadata key of a field's Setting
REQUIRED = dataclasses.MISSING  # the default of a setting that has none: every configuration must give it
LISTS = ("vector", "components", "per_joint")  # the kinds whose value is a list (an empty one: not set, where that is
# allowed)

Bound = float | str | None  # a number, the name of another field (or property) of the same object, or unbounded


@dataclass(frozen=True)
class Bounds:
    """The closed (or, with ``lo_open``/``hi_open``, open) interval ``[lo, hi]``; None: unbounded on that side; a
    name: the value of that attribute (a dotted path) of the object the setting belongs to."""

    lo: Bound = None
    hi: Bound = None
    lo_open: bool = False
    hi_open: bool = False

    def text(self) -> str:
        """The interval as written in references, e.g. ``(0, 0.05]`` or ``(0, max_accel]``."""
        return interval_text(self.lo, self.hi, self.lo_open, self.hi_open)

    def of(self, owner: Any) -> "Bounds":
        """These bounds with each named bound replaced by its value in ``owner``."""
        def value(bound: Bound) -> float | None:
            return attrgetter(bound)(owner) if isinstance(bound, str) else bound
        return dataclasses.replace(self, lo=value(self.lo), hi=value(self.hi))


@dataclass(frozen=True)
class Setting:
    """One configuration field's declaration (the field's name is the dataclass field's).

    group: the concern it belongs to (a reference lists fields group by group).
    meaning: what it is and why it matters (equations and references where physics), one or a few sentences.
    unit: SI unit, '' where dimensionless.
    kind: 'float', 'int', 'bool', 'choice' (an :class:`enum.Enum`, ``choices``), 'vector' (``length`` numbers),
      'components' (``length`` numbers, each bounded, e.g. a box's half sizes) or 'per_joint' (a number per joint of
      the arm the setting belongs to: as many as its ``joint_count``).
    bounds: a number's allowed interval; a vector's magnitude's; each of a per-joint setting's or components' numbers'.
    choices: the Enum of a 'choice'.
    optional: not setting it is allowed too (None; an empty list for a vector or a per-joint setting), ``none_means``
      saying what that stands for.
    """

    group: str
    meaning: str
    unit: str = ""
    kind: str = "float"
    bounds: Bounds | None = None
    choices: type[Enum] | None = None
    optional: bool = False
    none_means: str = ""
    length: int = 3

    def allowed(self) -> str:
        """The allowed values in words, e.g. ``(0, 0.05] m``, ``one of 'wcsph', 'dfsph'``, ``true or false``."""
        unit = f" {self.unit}" if self.unit else ""
        if self.kind == "bool":
            text = "true or false"
        elif self.kind == "choice":
            text = "one of " + ", ".join(repr(m.value) for m in self.choices)
        elif self.kind == "vector":
            numbers = f"{self.length} numbers"
            text = f"{numbers}, magnitude in {self.bounds.text()}{unit}" if self.bounds else f"{numbers} ({self.unit})"
        elif self.kind == "components":
            text = f"{self.length} numbers, each in {(self.bounds or Bounds()).text()}{unit}"
        elif self.kind == "per_joint":
            text = f"a number per joint, each in {(self.bounds or Bounds()).text()}{unit}"
        else:
            text = (self.bounds or Bounds()).text() + unit
        unset = "[]" if self.kind in LISTS else "not set"
        return f"{text}; or {unset}: {self.none_means}" if self.optional else text

    def check(self, name: str, value: Any, owner: Any = None) -> Any:
        """``value`` checked (and coerced: an enum from its value, a vector to a tuple of floats); an
        :class:`InputError` line naming ``name`` and the allowed values where it is not allowed. ``owner``: the
        object the setting belongs to, whose attributes a named bound reads."""
        if self.optional and (value is None or (self.kind in LISTS and _empty(value))):
            return None if value is None else ()
        b = (self.bounds or Bounds()).of(owner)
        if self.kind == "bool":
            if not isinstance(value, bool):
                raise InputError(f"{name}: must be true or false, got {value!r}")
            return value
        if self.kind == "choice":
            return check_choice(name, value, self.choices)
        if self.kind == "vector":
            vector = check_vector(name, value, self.length)
            if self.bounds is not None:
                check_range(f"{name} magnitude", math.hypot(*vector), b.lo, b.hi, self.unit, b.lo_open, b.hi_open)
            return vector
        if self.kind in ("per_joint", "components"):
            vector = check_vector(name, value, owner.joint_count if self.kind == "per_joint" else self.length)
            for i, v in enumerate(vector):
                check_range(f"{name}[{i}]", v, b.lo, b.hi, self.unit, b.lo_open, b.hi_open)
            return vector
        if self.kind == "int":
            check_int(name, value)
            check_range(name, value, b.lo, b.hi, self.unit, b.lo_open, b.hi_open)
            return value
        return check_range(name, value, b.lo, b.hi, self.unit, b.lo_open, b.hi_open)


def _empty(value: Any) -> bool:
    return not isinstance(value, (str, bytes)) and hasattr(value, "__len__") and len(value) == 0


def setting(
    default: Any, group: str, meaning: str, unit: str = "", lo: Bound = None, hi: Bound = None,
    lo_open: bool = False, hi_open: bool = False, kind: str | None = None, none_means: str = "",
    choices: type[Enum] | None = None,
) -> Any:
    """A dataclass field with ``default`` declared as a :class:`Setting` (``kind`` from the default where not given:
    a bool, an Enum member, a tuple (vector, of the tuple's length), an int or a float; a None default, or an empty tuple for a list kind,
    makes it optional, ``none_means`` saying what not setting it stands for; ``none_means`` with another default
    makes it optional too, with that default, for code that passes None; :data:`REQUIRED`: no default, a float
    unless ``kind`` says otherwise). A bound given as a name is that attribute of the object the setting belongs to
    (:meth:`Bounds.of`). ``choices``: the Enum of a 'choice' whose default is None (otherwise the default's)."""
    if kind is None:
        kind = ("bool" if isinstance(default, bool) else "choice" if isinstance(default, Enum)
                else "vector" if isinstance(default, tuple) else "int" if isinstance(default, int) else "float")
    bounds = None if lo is None and hi is None else Bounds(lo, hi, lo_open, hi_open)
    optional = default is None or (kind in LISTS and default == ()) or bool(none_means)
    length = len(default) if isinstance(default, tuple) and default else 3
    if kind == "choice" and choices is None:
        choices = type(default)
    spec = Setting(group, meaning, unit, kind, bounds, choices, optional, none_means, length)
    return dataclasses.field(default=default, metadata={SETTING: spec})


def argument(group: str, meaning: str, unit: str = "", lo: Bound = None, hi: Bound = None, lo_open: bool = False,
             hi_open: bool = False, kind: str = "float") -> Setting:
    """The declaration of an argument that is no configuration field (a building block's rate limit or time step,
    given by the configuration that builds it): the same :class:`Setting` a field gets, declared once beside the
    code that takes it and checked by :meth:`Setting.check` (a named bound reads the ``owner`` passed there)."""
    bounds = None if lo is None and hi is None else Bounds(lo, hi, lo_open, hi_open)
    return Setting(group, meaning, unit, kind, bounds)


def argument_field(spec: Setting, default: Any) -> Any:
    """A dataclass field declared by the :func:`argument` ``spec``, with ``default``: a configuration's setting that
    a building block below it takes as an argument, declared once beside that building block (its default too), so
    that both check it from the same declaration."""
    return dataclasses.field(default=default, metadata={SETTING: spec})


def declared(cls: type, name: str) -> Setting:
    """The :class:`Setting` of field ``name`` of the dataclass ``cls``."""
    return cls.__dataclass_fields__[name].metadata[SETTING]


def like(cls: type, name: str, default: Any = dataclasses.MISSING, none_means: str = "", kind: str | None = None) -> Any:
    """A field declared as the same setting as ``cls``'s field ``name``, with its default; ``default=None`` (an empty
    tuple for a list kind) makes it an optional override (not set: ``none_means``, e.g. the fluid's own default).
    No other default: a setting has one, and a caller that wants another value names it where it builds the
    configuration. ``kind``: 'per_joint' declares a number per joint of a setting of one joint, 'float' one joint's
    of a per-joint setting (the same unit, bounds and meaning; required unless the default says otherwise)."""
    spec = declared(cls, name)
    declared_default = cls.__dataclass_fields__[name].default
    if kind is not None:
        if {kind, spec.kind} != {"float", "per_joint"}:
            raise ValueError(f"like({cls.__name__}, {name!r}): only a setting's one-joint and per-joint kinds convert")
        spec = dataclasses.replace(spec, kind=kind, optional=False, none_means="")
        declared_default = REQUIRED  # one joint's value is no list's default, nor the other way round
    if default is dataclasses.MISSING:
        default = declared_default
    elif default is None or (spec.kind in LISTS and default == ()):
        spec = dataclasses.replace(spec, optional=True, none_means=none_means)
    else:
        raise ValueError(f"like({cls.__name__}, {name!r}): only None (or an empty list) may replace the declared default")
    return dataclasses.field(default=default, metadata={SETTING: spec})


@dataclass(frozen=True)
class Derived:
    """A setting of another class that a configuration does not set itself: ``name``, its declaration ``spec``
    and ``source``, where its value comes from instead."""

    name: str
    spec: Setting
    source: str


def derived(cls: type, name: str, source: str) -> Derived:
    """``cls``'s setting ``name``, taken from ``source`` (see :class:`Derived`)."""
    return Derived(name, declared(cls, name), source)


def declared_fields(cls: type) -> list[tuple[str, Setting]]:
    """(name, Setting) of every declared field of the dataclass ``cls``, in field order."""
    return [(f.name, f.metadata[SETTING]) for f in dataclasses.fields(cls) if SETTING in f.metadata]


def check_settings(obj: Any, prefix: str = "") -> None:
    """Check every declared field of the frozen dataclass instance ``obj`` and store its coerced value; errors name
    the field as ``<prefix>.<name>`` (``<name>`` with no prefix)."""
    for name, spec in declared_fields(type(obj)):
        value = spec.check(f"{prefix}.{name}" if prefix else name, getattr(obj, name), obj)
        object.__setattr__(obj, name, value)


def default_text(value: Any) -> str:
    """A default as the reference writes it."""
    if value is REQUIRED:
        return "none, required"
    if isinstance(value, Enum):
        return repr(value.value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, tuple):
        return "(" + ", ".join(f"{v:g}" for v in value) + ")" if value else "[]"
    return "not set" if value is None else f"{value:g}" if isinstance(value, float) else str(value)


def groups_of(cls: type) -> tuple[str, ...]:
    """The groups of ``cls``'s declared fields, in the order they first appear."""
    return tuple(dict.fromkeys(spec.group for _, spec in declared_fields(cls)))


def settings_reference(cls: type, groups: tuple[str, ...] | None = None) -> str:
    """The reference of ``cls``'s declared fields, group by group in the order ``groups`` (None: as declared; a class
    of one group is listed without its heading): each field's name, meaning, allowed values and default."""
    groups = groups_of(cls) if groups is None else groups
    lines = []
    fields = declared_fields(cls)
    for group in groups:
        if len(groups) > 1:
            lines.append(f"{group}:")
        for name, spec in fields:
            if spec.group == group:
                default = cls.__dataclass_fields__[name].default
                entry = f"{name}: {spec.meaning} Allowed: {spec.allowed()}. Default: {default_text(default)}."
                lines.append(f"    {entry}" if len(groups) > 1 else entry)
    return "\n".join(lines)


def documented(cls: type) -> type:
    """The configuration class ``cls`` with the reference of its declared settings (:func:`settings_reference`)
    added to its docstring: the class decorator (over ``@dataclass``) of a class whose settings are declared."""
    cls.__doc__ = (cls.__doc__ or "").rstrip() + "\n\n" + textwrap.indent(settings_reference(cls), "    ")
    return cls
