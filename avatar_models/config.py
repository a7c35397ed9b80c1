"""The one config loader: TOML (or parsed data) into frozen dataclasses, checked whole.

A config is described by a frozen dataclass whose field types say what a value may be and
whose :func:`setting` metadata bounds it. :func:`from_data` walks the data against the
class and refuses, with a :class:`ConfigError` naming the dotted field path:

- a key the class does not have (the allowed keys are listed), a required key that is absent;
- a value of the wrong type: ``bool`` only from a TOML boolean (``"yes"`` is a string), ``int``
  only from a TOML integer (neither ``1.5`` nor ``true``), ``float`` from a TOML integer or
  float, always finite, ``str`` only from a string, ``Literal[...]`` only one of its values;
- a number outside its ``ge``/``gt``/``le``/``lt`` bounds, a list or table with more than
  ``max_items`` entries or fewer than ``min_items``.

Supported field types: ``bool``, ``int``, ``float``, ``str``, ``Literal[...]``, ``X | None``
(``None`` only as a default: TOML has no null), ``tuple[X, ...]`` (a TOML array),
``dict[str, X]`` (a TOML table), and nested config dataclasses (a table, or an array of
tables in a ``tuple``). Cross-field rules (fractions summing to 1, one option needing
another) stay with the config that has them and raise the same :class:`ConfigError`.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
import types
import typing
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Literal, TypeVar

from avatarsim.avatar_models.errors import AvatarsimError

T = TypeVar("T")
BOUNDS = {"ge": ">=", "gt": ">", "le": "<=", "lt": "<"}
CHECKS = {
    "ge": lambda v, b: v >= b,
    "gt": lambda v, b: v > b,
    "le": lambda v, b: v <= b,
    "lt": lambda v, b: v < b,
}


class ConfigError(AvatarsimError, ValueError):
    """A config file or table that cannot be used: unreadable, not TOML, an unknown or missing
    key, a value of the wrong type or out of its range (the message names file and field)."""


def setting(
    default: Any = dataclasses.MISSING,
    *,
    default_factory: Any = dataclasses.MISSING,
    ge: float | None = None,
    gt: float | None = None,
    le: float | None = None,
    lt: float | None = None,
    min_items: int | None = None,
    max_items: int | None = None,
    from_file: bool = True,
) -> Any:
    """A dataclass field with bounds that :func:`from_data` checks (module docstring);
    ``from_file=False``: a field the program sets (e.g. the file's own path), never a key."""
    bounds = {"ge": ge, "gt": gt, "le": le, "lt": lt}
    metadata = {k: v for k, v in bounds.items() if v is not None}
    metadata |= {k: v for k, v in (("min_items", min_items), ("max_items", max_items)) if v}
    metadata |= {} if from_file else {"from_file": False}
    return dataclasses.field(default=default, default_factory=default_factory, metadata=metadata)


def read_toml(path: str | Path) -> dict[str, Any]:
    """The parsed TOML file ``path``; :class:`ConfigError` for an unreadable or non-TOML file."""
    path = Path(path)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror or exc}") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None


def load_toml(cls: type[T], path: str | Path) -> T:
    """The config ``cls`` in the TOML file ``path``; every error names the file."""
    data = read_toml(path)
    try:
        return from_data(cls, data)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None


def from_data(cls: type[T], data: Any, where: str = "") -> T:
    """The config ``cls`` from parsed data (a TOML table); ``where`` prefixes field paths."""
    return _table(cls, data, where)


def _name(where: str, key: str) -> str:
    return f"{where}.{key}" if where else key


def _table(cls: type, data: Any, where: str) -> Any:
    if not isinstance(data, Mapping):
        raise ConfigError(f"{where or 'the config'} must be a table, got {_shown(data)}")
    fields = {f.name: f for f in dataclasses.fields(cls) if f.metadata.get("from_file", True)}
    unknown = sorted(set(data) - set(fields), key=str)
    if unknown:
        raise ConfigError(
            f"unknown key {unknown[0]!r} in [{where or 'top level'}]; "
            f"allowed: {', '.join(sorted(fields))}"
        )
    hints = typing.get_type_hints(cls)
    values = {}
    for name, f in fields.items():
        path = _name(where, name)
        if name in data:
            values[name] = _bounded(_value(hints[name], data[name], path), f.metadata, path)
        elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            raise ConfigError(f"{path} is required")
    return cls(**values)


def _value(annotation: Any, value: Any, path: str) -> Any:
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin in (types.UnionType, typing.Union):
        return _value(next(a for a in args if a is not type(None)), value, path)
    if origin is Literal:
        if isinstance(value, str | int | float) and any(
            type(value) is type(a) and value == a for a in args
        ):
            return value
        raise ConfigError(
            f"{path} must be one of {', '.join(map(repr, args))}, got {_shown(value)}"
        )
    if origin is tuple:
        if not isinstance(value, list):
            raise ConfigError(f"{path} must be an array, got {_shown(value)}")
        return tuple(_value(args[0], v, f"{path}[{i}]") for i, v in enumerate(value))
    if origin is dict:
        if not isinstance(value, Mapping):
            raise ConfigError(f"{path} must be a table, got {_shown(value)}")
        return {k: _value(args[1], v, _name(path, k)) for k, v in value.items()}
    if dataclasses.is_dataclass(annotation):
        return _table(annotation, value, path)
    return _scalar(annotation, value, path)


def _scalar(annotation: type, value: Any, path: str) -> Any:
    if annotation is float and type(value) in (int, float):
        try:
            number = float(value)
        except OverflowError:
            number = math.inf
        if not math.isfinite(number):
            raise ConfigError(f"{path} must be a finite number, got {_shown(value)}")
        return number
    if annotation in (int, str, bool) and type(value) is annotation:
        return value
    raise ConfigError(f"{path} must be {_kind(annotation)}, got {_shown(value)}")


def _bounded(value: Any, metadata: Mapping[str, Any], path: str) -> Any:
    if isinstance(value, int | float) and not isinstance(value, bool):
        bounds = {k: b for k, b in metadata.items() if k in CHECKS}
        if not all(CHECKS[k](value, b) for k, b in bounds.items()):
            wanted = " and ".join(f"{BOUNDS[k]} {b:g}" for k, b in bounds.items())
            raise ConfigError(f"{path} must be {wanted}, got {value:g}")
    if isinstance(value, tuple | dict):
        if len(value) > metadata.get("max_items", math.inf):
            raise ConfigError(
                f"{path} must have at most {metadata['max_items']} entries, got {len(value)}"
            )
        if len(value) < metadata.get("min_items", 0):
            raise ConfigError(
                f"{path} must have at least {metadata['min_items']} entries, got {len(value)}"
            )
    return value


def _kind(annotation: type) -> str:
    return {
        bool: "a boolean (true or false)",
        int: "an integer",
        float: "a number",
        str: "a string",
    }.get(annotation, getattr(annotation, "__name__", str(annotation)))


def _shown(value: Any) -> str:
    """``value`` for a message: its TOML type and a short repr."""
    text = repr(value)
    return f"{type(value).__name__} {text if len(text) <= 60 else text[:57] + '...'}"
