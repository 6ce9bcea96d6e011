"""Study configs: loading and validating a study TOML, the one field-error format, the shared bases.

Every error is one line naming the file and the offending field once: ``"<file>: <field.path>: <what is wrong>
(got <value>)"`` (``railopt: error:`` in front on the command line).  The config tables of every kind derive from
:class:`StrictModel`: unknown keys are errors with a did-you-mean, strings are never numbers, every number is
finite (NaN and inf are refused naming the field) and integers must fit their field; intervals and bands are
:data:`Interval` and :data:`BandHz`; a method name is a :data:`MethodName`, validated against the design layer's
registry; a name that becomes a file or folder name (the study's, a model label, a trade-off's) is a
:data:`FileName`.  Relative paths in a study
(``vehicle = "car.toml"`` in ``[[models]].options``) are resolved from the study file's folder
(:func:`resolve_paths`).  :mod:`railopt.studies.reference` writes ``docs/config-reference.md`` from the config
models.
"""

from __future__ import annotations

import math
import re
import types
import typing
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
)

from railopt.models.vehicle.schema import did_you_mean
from railopt.studies.kind import StudyKind, discover_kinds
from railopt.tomlfile import read_toml as _read_toml

__all__ = [
    "INT64_MAX",
    "INT_LIMITS",
    "PATH_OPTIONS",
    "BandHz",
    "NAME_MAX",
    "ConfigError",
    "FileName",
    "FiniteModel",
    "Interval",
    "MethodName",
    "StrictModel",
    "StudyHeader",
    "field_errors",
    "load_study",
    "not_one_of",
    "read_toml",
    "registered_method",
    "resolve_paths",
    "study_kind",
]


class ConfigError(ValueError):
    """A study config that cannot be used; the message names the file and the field."""


_PATH = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]*(\[\d+\]|\.\d+|\.[A-Za-z_][A-Za-z0-9_\-]*)*$")


def _is_path(segment: str) -> bool:
    return bool(_PATH.match(segment))


def _dedupe(text: str) -> str:
    """``"a: a.b: msg"`` → ``"a.b: msg"``: a field path that the next segment repeats or extends is dropped."""
    out: list[str] = []
    for seg in text.split(": "):
        if out and _is_path(out[-1]) and _is_path(seg) and (
                seg == out[-1] or seg.startswith((out[-1] + ".", out[-1] + "["))):
            out[-1] = seg
        else:
            out.append(seg)
    return ": ".join(out)


def _shown(value: Any) -> str:
    """``repr(value)``, or its length when it is long (a 300-character name is not repeated in the error)."""
    text = repr(value)
    if len(text) <= 80:
        return text
    return f"a string of {len(value)} characters" if isinstance(value, str) else text[:77] + "..."


def _step(annotation: Any, part: str | int) -> Any:
    """The annotation one location ``part`` below ``annotation`` (a field of a model, an item of a list or
    table); None when it cannot be followed."""
    origin = typing.get_origin(annotation)
    if origin is Annotated:
        return _step(typing.get_args(annotation)[0], part)
    if origin in (typing.Union, types.UnionType):
        for arg in typing.get_args(annotation):
            found = _step(arg, part)
            if found is not None:
                return found
        return None
    if isinstance(part, int) and origin in (list, tuple):
        args = [a for a in typing.get_args(annotation) if a is not Ellipsis]
        return args[min(part, len(args) - 1)] if args else None
    if origin is dict:
        args = typing.get_args(annotation)
        return args[1] if len(args) == 2 else None
    if isinstance(annotation, type) and issubclass(annotation, BaseModel) and isinstance(part, str):
        field = annotation.model_fields.get(part)
        return None if field is None else field.annotation
    return None


def _table_keys(model: type[BaseModel] | None, loc: tuple) -> list[str]:
    """The keys the table at ``loc`` inside ``model`` accepts ([] when unknown)."""
    annotation: Any = model
    for part in loc:
        annotation = _step(annotation, part)
    while typing.get_origin(annotation) in (Annotated, typing.Union, types.UnionType):
        args = [a for a in typing.get_args(annotation) if isinstance(a, type) and issubclass(a, BaseModel)]
        annotation = args[0] if args else typing.get_args(annotation)[0]
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return list(annotation.model_fields)
    return []


def _unknown_key(loc: tuple, prefix: str, model: type[BaseModel] | None) -> str:
    key, table = str(loc[-1]), loc[:-1]
    keys = _table_keys(model, table)
    hint = did_you_mean(key, keys) or (f"; keys are {keys}" if keys else "")
    where = ".".join(p for p in (prefix, ".".join(str(x) for x in loc)) if p)
    what = "unknown table or key at the top level" if not table and not prefix else "unknown key"
    return _dedupe(f"{where}: {what}{hint}")


def _own_key(loc: str, at: tuple, msg: str, model: type[BaseModel] | None) -> tuple[str, str]:
    """``("design", "options.xtol: bad")`` → ``("design.options.xtol", "bad")``: a message of a table's validator
    that starts with one of that table's own keys names the field by its dotted path."""
    head, sep, rest = msg.partition(": ")
    if sep and _is_path(head) and re.split(r"[.\[]", head)[0] in _table_keys(model, at):
        return f"{loc}.{head}", rest
    return loc, msg


def field_errors(exc: Exception, prefix: str = "", model: type[BaseModel] | None = None) -> str:
    """Join a pydantic ``ValidationError`` (or any error) into one line naming each field once.

    ``"<field.path>: <what is wrong> (got <value>)"``; an error of the whole file has no path in front, and a
    message that starts with its own field's path (or a longer one) does not repeat it.  With ``model`` (the
    config model validated), an unknown key gets a did-you-mean among the keys of its table."""
    if not isinstance(exc, ValidationError):
        if not prefix:
            return _dedupe(str(exc))
        loc, msg = _own_key(prefix, (), str(exc), model)
        return _dedupe(f"{loc}: {msg}")
    lines = []
    for err in exc.errors():
        if err["type"] == "extra_forbidden":
            lines.append(_unknown_key(tuple(err["loc"]), prefix, model))
            continue
        loc = ".".join(p for p in (prefix, ".".join(str(x) for x in err["loc"])) if p)
        msg = err["msg"].removeprefix("Value error, ")
        if err["loc"]:
            loc, msg = _own_key(loc, tuple(err["loc"]), msg, model)
        got = err.get("input")
        got_text = ("" if isinstance(got, dict | list | tuple) or err["type"] == "value_error"
                    else f" (got {_shown(got)})")
        lines.append(_dedupe(f"{loc}: {msg}{got_text}" if loc else f"{msg}{got_text}"))
    return "; ".join(lines)


def not_one_of(name: str, choices: Sequence[str], what: str, listed: int = 12) -> str:
    """``"unknown parameter 'K2x'; did you mean 'K2'?"``: an unknown name with the closest choice; without a close
    one the choices are listed when there are at most ``listed`` of them, else only counted (no 70-name dump)."""
    hint = did_you_mean(name, choices)
    if not hint:
        hint = (f"; known: {list(choices)}" if len(choices) <= listed
                else f"; none of the {len(choices)} known names is close")
    return f"unknown {what} {name!r}{hint}"


# ---------------------------------------------------------------------------------------------- shared bases
def _ordered_interval(v: tuple[float, float]) -> tuple[float, float]:
    lo, hi = v
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ValueError(f"must be finite, got ({lo}, {hi})")
    if not lo < hi:
        raise ValueError(f"inverted or empty: lower {lo} ≥ upper {hi}")
    return v


Interval = Annotated[tuple[float, float], AfterValidator(_ordered_interval)]
"""A (lower, upper) pair with lower < upper, both finite: bounds and frequency bands in configs."""


def _non_negative_lower(v: tuple[float, float]) -> tuple[float, float]:
    if v[0] < 0:
        raise ValueError(f"lower edge must be ≥ 0 Hz, got {v[0]}")
    return v


BandHz = Annotated[tuple[float, float], AfterValidator(_ordered_interval), AfterValidator(_non_negative_lower)]
"""A frequency band in Hz: finite, 0 ≤ lower < upper."""


def registered_method(name: str) -> str:
    """A design method name registered in :data:`railopt.design.METHODS` (the one list of methods)."""
    from railopt.design import METHODS

    if name not in METHODS:
        raise ValueError(not_one_of(name, sorted(METHODS), "method"))
    return name


MethodName = Annotated[str, AfterValidator(registered_method)]
"""A method name of the design registry; configs never list the methods themselves."""


INT64_MAX = 2**63 - 1
"""The largest integer a study file may hold in an integer field (SQLite and numpy store int64)."""

INT_LIMITS: dict[str, int] = {"seed": INT64_MAX, "maxeval": 2**31 - 1, "n_starts": 10**7}
"""Upper limits of integer fields by name, in every kind: a seed is stored as int64, ``maxeval`` is a C int of
NLopt, and ``n_starts`` beyond ten million is a slip (the start points alone would not fit in memory)."""


def _check_value(annotation: Any, value: Any, name: str, where: str = "") -> Any:
    """``value`` checked against ``annotation`` before pydantic sees it: a string where a number belongs is
    refused, an integer beyond its limit too, and TOML arrays become tuples where the annotation is a tuple
    (strict mode accepts only tuples).  ``where`` is the position inside the field (``"[1]: "``)."""
    origin = typing.get_origin(annotation)
    if origin is Annotated:
        return _check_value(typing.get_args(annotation)[0], value, name, where)
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        if value is not None and len(args) == 1:
            return _check_value(args[0], value, name, where)
        if isinstance(value, str) and args and all(a in (int, float) for a in args):
            raise ValueError(f"{where}must be a number, not a string (got {value!r})")
        return value
    if annotation in (int, float):
        if isinstance(value, str):
            raise ValueError(f"{where}must be a number, not a string (got {value!r})")
        if annotation is int and isinstance(value, int) and not isinstance(value, bool):
            limit = INT_LIMITS.get(name, INT64_MAX)
            if value > limit:
                raise ValueError(f"{where}must be at most {limit} (got an integer of {len(str(value))} digits)")
            if value < -INT64_MAX - 1:
                raise ValueError(f"{where}must be at least {-INT64_MAX - 1} (got an integer of "
                                 f"{len(str(-value))} digits)")
        return value
    if origin is tuple and isinstance(value, list | tuple):
        args = typing.get_args(annotation)
        if len(args) == 2 and args[1] is Ellipsis:
            args = (args[0],) * len(value)
        if len(args) != len(value):
            return tuple(value)  # pydantic names the wrong length
        pairs = enumerate(zip(args, value, strict=True))
        return tuple(_check_value(a, v, name, where or f"[{i}]: ") for i, (a, v) in pairs)
    if origin is list and isinstance(value, list | tuple):
        (arg,) = typing.get_args(annotation) or (Any,)
        return [_check_value(arg, v, name, where or f"[{i}]: ") for i, v in enumerate(value)]
    if origin is dict and isinstance(value, dict):
        args = typing.get_args(annotation)
        arg = args[1] if len(args) == 2 else Any
        return {k: _check_value(arg, v, name, where or f"{k}: ") for k, v in value.items()}
    return value


NAME_MAX = 100
"""The longest name (characters) that becomes part of a file or folder name: the study's name, model labels,
trade-off and case labels; the file names made from them stay far below the file system's 255 bytes."""

_NAME_CHARS = re.compile(r"[A-Za-z0-9_.\-]")


def _file_name(value: Any) -> Any:
    if not isinstance(value, str):
        return value  # the type check names it
    if not value:
        raise ValueError("must not be empty (it names files of the results)")
    if len(value) > NAME_MAX:
        raise ValueError(f"too long for a file name: {len(value)} characters, at most {NAME_MAX}")
    bad = sorted({c for c in value if not _NAME_CHARS.fullmatch(c)})
    if bad:
        raise ValueError(f"{''.join(bad)!r} cannot be part of a file name: use letters, digits, '_', '-' and '.' "
                         f"(got {_shown(value)})")
    if set(value) == {"."}:
        raise ValueError(f"{value!r} is not a file name")
    return value


FileName = Annotated[str, BeforeValidator(_file_name), Field(max_length=NAME_MAX)]
"""A name that becomes (part of) a file name: letters, digits, ``_``, ``-`` and ``.``, 1 to :data:`NAME_MAX`
characters; refused on validation naming the field, never after the work when the file is written."""


class StrictModel(BaseModel):
    """Base for config tables: unknown keys, wrong types and non-finite numbers are errors that name the field.

    Strict: a string is never read as a number (``lower = "1e5"`` is refused), nor ``true`` or ``16.0`` as a
    count; every float is finite (``xtol = inf`` and NaN are refused, in nested arrays and tables too); an integer
    must fit its field (:data:`INT_LIMITS`; int64 at most).  TOML arrays are taken as tuples."""

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)

    @field_validator("*", mode="before")
    @classmethod
    def _numbers_and_arrays(cls, value: Any, info: ValidationInfo) -> Any:
        field = cls.model_fields.get(info.field_name or "")
        return value if field is None else _check_value(field.annotation, value, info.field_name)


class FiniteModel(StrictModel):
    """A config table whose floats must be finite: every :class:`StrictModel` now (kept as the name the kinds
    use)."""


class StudyHeader(StrictModel):
    """The ``[study]`` table of every study file."""

    name: FileName = Field(pattern=r"^[A-Za-z0-9_\-]+$", description="the results folder's name")
    kind: str
    description: str = ""


# ---------------------------------------------------------------------------------------------- loading
def study_kind(name: str) -> StudyKind:
    """The registered kind called ``name`` (every kind module is imported first)."""
    kinds = discover_kinds()
    if name not in kinds:
        raise ConfigError(f"study.kind: {not_one_of(name, sorted(kinds), 'kind')}")
    return kinds[name]




def read_toml(path: str | Path, what: str = "study") -> dict[str, Any]:
    """The parsed TOML of ``path``; every failure is a :class:`ConfigError` ``"<file>: <what is wrong>"``
    (:func:`railopt.tomlfile.read_toml`)."""
    try:
        return _read_toml(path, what)
    except ValueError as exc:
        raise ConfigError(str(exc)) from None


PATH_OPTIONS: tuple[str, ...] = ("vehicle",)
"""Options of ``[[models]]`` entries that name a file: resolved from the study file's folder (as are options whose
names end in ``_file`` or ``_path``)."""


def _bundled_vehicles() -> tuple[str, ...]:
    from railopt.models.vehicle.loader import bundled_vehicles

    return bundled_vehicles()


def resolve_paths(raw: dict[str, Any], folder: Path) -> dict[str, Any]:
    """``raw`` with every relative file path in ``[[models]].options`` resolved against ``folder`` (the study
    file's): a study means the same files from any working directory.  Absolute paths and bundled vehicle names
    are kept as they are."""
    models = raw.get("models")
    if not isinstance(models, list):
        return raw
    bundled = _bundled_vehicles()
    out = []
    for entry in models:
        options = entry.get("options") if isinstance(entry, dict) else None
        if isinstance(options, dict):
            options = dict(options)
            for key, value in options.items():
                is_path = key in PATH_OPTIONS or key.endswith(("_file", "_path"))
                if is_path and isinstance(value, str) and value and value not in bundled:
                    target = Path(value).expanduser()
                    if not target.is_absolute():
                        options[key] = str((folder / target).resolve())
            entry = {**entry, "options": options}
        out.append(entry)
    return {**raw, "models": out}


def load_study(path: str | Path) -> tuple[StudyKind, BaseModel, dict[str, Any]]:
    """Read, parse and validate a study file; returns its kind, the validated config and the raw dict (paths
    resolved).  Every error is a :class:`ConfigError` ``"<file>: <field.path>: <what is wrong>"``."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"{path}: study: no such file")
    raw = read_toml(path)
    header = raw.get("study")
    if not isinstance(header, dict) or "kind" not in header:
        raise ConfigError(f"{path}: study.kind: missing; every study file needs a [study] table with name and kind")
    try:
        kind = study_kind(str(header["kind"]))
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None
    raw = resolve_paths(raw, path.resolve().parent)
    try:
        config = kind.config_model.model_validate(raw)
    except (ValidationError, ValueError) as exc:  # model validators may raise plain ValueError
        raise ConfigError(f"{path}: {field_errors(exc, model=kind.config_model)}") from None
    return kind, config, raw
