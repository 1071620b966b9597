"""TOML tables <-> frozen configuration dataclasses, 1:1.

``from_mapping(cls, table, path)`` builds ``cls`` from a (nested) mapping: keys are field names, nested dataclasses
are sub-tables (a sub-table changes only its own keys of the parent's default, e.g. ``[coupling] start_delay = 1``
keeps the scene's ``max_duration``, not the section class's), enums are given by their string value, tuples as
arrays, ``None`` fields are left out of the file. An unknown key, a wrong type or a value out of range is one
:class:`InputError` line naming the dotted field (range checks are the dataclasses' own ``__post_init__``).
``to_toml(obj)`` writes the TOML document of a configuration with every field's documentation as a comment: a field
declared as a :class:`declared_settings.setting.Setting` with its meaning and allowed values (under a comment
naming its group where the table has several; a class's ``derived_settings``, the settings it does not set, as
comments saying where they come from); other fields with their lines of the dataclass docstring (unit and range).
"""

from __future__ import annotations

import dataclasses
import enum
import inspect
import re
import tomllib
import types
import typing
from pathlib import Path
from typing import Any

from cosim.errors import InputError
from declared_settings.setting import SETTING, Setting, groups_of

_FIELD_DOC = re.compile(r"^\s*([a-z_][a-z0-9_]*)\s*:\s*(.*)$")


def field_docs(cls: type) -> dict[str, str]:
    """Field name -> its description, read from lines ``name: text`` in the class docstring (continuation lines,
    indented deeper, are joined)."""
    doc = inspect.getdoc(cls) or ""
    names = {f.name for f in dataclasses.fields(cls)}
    out: dict[str, str] = {}
    current = None
    for line in doc.splitlines():
        # several fields may share a line, separated by 3+ spaces ("max_rate: rad/s. (0, 2]   max_accel: ...")
        segments = [(seg, _FIELD_DOC.match(seg)) for seg in re.split(r"\s{3,}", line.strip())]
        if segments[0][1] and segments[0][1].group(1) in names:
            for seg, m in segments:
                if m and m.group(1) in names:
                    current = m.group(1)
                    out[current] = m.group(2).strip()
                elif current:
                    out[current] += " " + seg
        elif current and line.startswith(" ") and line.strip():
            out[current] += " " + line.strip()
        else:
            current = None
    return out


def _type_name(tp: Any) -> str:
    return getattr(tp, "__name__", str(tp).replace("typing.", ""))


def _convert(value: Any, tp: Any, path: str, default: Any = None) -> Any:
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(tp) if a is not type(None)]
        if len(args) == 1:
            return _convert(value, args[0], path, default)
        raise TypeError(f"unsupported union at {path}")
    if dataclasses.is_dataclass(tp):
        if not isinstance(value, dict):
            raise InputError(f"{path}: must be a table, got {type(value).__name__}")
        return from_mapping(tp, value, path, default if isinstance(default, tp) else None)
    if isinstance(tp, type) and issubclass(tp, enum.Enum):
        allowed = [m.value for m in tp]
        if value not in allowed:
            raise InputError(f"{path}: must be one of {', '.join(map(repr, allowed))}, got {value!r}")
        return tp(value)
    if origin is dict:
        if not isinstance(value, dict):
            raise InputError(f"{path}: must be a table, got {type(value).__name__}")
        key_type, item = typing.get_args(tp)
        return {str(k): _convert(v, item, f"{path}.{k}") for k, v in value.items()}
    if origin is tuple or tp is tuple:
        if not isinstance(value, list):
            raise InputError(f"{path}: must be an array, got {type(value).__name__}")
        args = typing.get_args(tp)
        item = args[0] if args else Any
        return tuple(_convert(v, item, f"{path}[{i}]") for i, v in enumerate(value))
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(f"{path}: must be a number, got {value!r} ({type(value).__name__})")
        return float(value)
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise InputError(f"{path}: must be an integer, got {value!r} ({type(value).__name__})")
        return value
    if tp is bool:
        if not isinstance(value, bool):
            raise InputError(f"{path}: must be true or false, got {value!r}")
        return value
    if tp is str:
        if not isinstance(value, str):
            raise InputError(f"{path}: must be a string, got {value!r} ({type(value).__name__})")
        return value
    return value


def _default(obj: Any, f: dataclasses.Field) -> Any:
    """The value field ``f`` has when the table leaves it out: ``obj``'s where a parent default is given, else the
    field's own default (None where it has none)."""
    if obj is not None:
        return getattr(obj, f.name)
    if f.default is not dataclasses.MISSING:
        return f.default
    if f.default_factory is not dataclasses.MISSING:
        return f.default_factory()
    return None


def from_mapping(cls: type, table: dict[str, Any], path: str, default: Any = None) -> Any:
    """Build the dataclass ``cls`` from ``table``; fields missing from the table keep the values of ``default`` (an
    instance of ``cls``: the parent's default for this section), or the class defaults where it is None."""
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    unknown = sorted(set(table) - set(fields))
    if unknown:
        raise InputError(f"{path}.{unknown[0]}: unknown key (known keys: {', '.join(sorted(fields))})")
    kwargs = {name: _convert(value, hints[name], f"{path}.{name}", _default(default, fields[name]))
              for name, value in table.items()}
    try:
        return dataclasses.replace(default, **kwargs) if default is not None else cls(**kwargs)
    except InputError:
        raise
    except TypeError as exc:  # a required field is missing
        raise InputError(f"{path}: {exc}") from None
    except ValueError as exc:  # a check that raises a plain ValueError
        raise InputError(f"{path}: {exc}" if not str(exc).startswith(path.split(".")[-1]) else str(exc)) from None


def _plain(value: Any) -> Any:
    if isinstance(value, enum.Enum):
        return value.value
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value


def _setting_comment(spec: Setting) -> str:
    return f"{spec.meaning} Allowed: {spec.allowed()}."


def _fill_table(table, obj: Any) -> None:
    import tomlkit  # only to write a document: reading one (and refusing it) does without

    docs = field_docs(type(obj))
    nested = []
    group = None
    headed = len(groups_of(type(obj))) > 1  # a table of one group needs no heading
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        spec = f.metadata.get(SETTING)
        if spec is not None:
            if spec.group != group and headed:
                table.add(tomlkit.comment(f"-- {spec.group} --"))
            group = spec.group
            if value is None:
                table.add(tomlkit.comment(f"{f.name} = (not set)  # {_setting_comment(spec)}"))
            else:
                table.add(f.name, tomlkit.item(_plain(value)).comment(_setting_comment(spec)))
            continue
        if dataclasses.is_dataclass(value):
            nested.append((f.name, value, docs.get(f.name, "")))
            continue
        if isinstance(value, dict):
            sub = tomlkit.table()
            if docs.get(f.name):
                sub.add(tomlkit.comment(docs[f.name]))
            for key, item in value.items():
                entry = tomlkit.table()
                _fill_table(entry, item)
                sub.add(key, entry)
            nested.append((f.name, sub, None))
            continue
        if value is None:
            table.add(tomlkit.comment(f"{f.name} = (not set)  # {docs.get(f.name, '')}".rstrip("# ")))
            continue
        item = tomlkit.item(_plain(value))
        text = docs.get(f.name, "")
        if isinstance(value, enum.Enum):
            text = f"{text} One of: {', '.join(repr(m.value) for m in type(value))}.".strip()
        if text:
            item.comment(text)
        table.add(f.name, item)
    derived = getattr(type(obj), "derived_settings", ())
    if derived:
        table.add(tomlkit.comment("-- not set here: where each comes from --"))
    for d in derived:
        table.add(tomlkit.comment(f"{d.name}: {_setting_comment(d.spec)} Set by: {d.source}."))
    for name, value, doc in nested:
        if doc is None:  # an already built table (a dict field)
            table.add(name, value)
            continue
        sub = tomlkit.table()
        if doc:
            sub.add(tomlkit.comment(doc))
        _fill_table(sub, value)
        table.add(name, sub)


def to_toml(obj: Any, header: str = "") -> str:
    """The TOML document of the configuration ``obj`` (a dataclass), every field commented with its docs."""
    import tomlkit

    doc = tomlkit.document()
    for line in header.splitlines():
        doc.add(tomlkit.comment(line))
    _fill_table(doc, obj)
    return tomlkit.dumps(doc)


def read_toml_file(path: Path, what: str) -> dict[str, Any]:
    """The table of the TOML file ``path``; a file that cannot be read or parsed is one InputError line naming it
    and what it was meant to be (``what``, e.g. "scene file")."""
    try:
        return tomllib.loads(path.read_text())
    except OSError as exc:
        raise InputError(f"{path}: cannot read the {what} ({exc.strerror})") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not a valid TOML file ({exc})") from None
