"""Study configs: loading and validating a study TOML, the one field-error format, the shared bases.

Every error names the offending field (and the file): ``"<field.path>: <what is wrong> (got <value>)"``.
The config tables of every kind derive from :class:`StrictModel` (unknown keys are errors) or
:class:`FiniteModel` (NaN and inf refused too); intervals and bands are :data:`Interval` and :data:`BandHz`;
a method name is a :data:`MethodName`, validated against the design layer's registry.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Annotated, Any

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, ValidationError

from railopt.studies.kind import StudyKind, discover_kinds

__all__ = [
    "BandHz",
    "ConfigError",
    "FiniteModel",
    "Interval",
    "MethodName",
    "StrictModel",
    "StudyHeader",
    "field_errors",
    "load_study",
    "registered_method",
    "study_kind",
]


class ConfigError(ValueError):
    """A study config that cannot be used; the message names the field."""


def field_errors(exc: Exception, prefix: str = "") -> str:
    """Join a pydantic ``ValidationError`` (or any error) into one line naming each field."""
    if not isinstance(exc, ValidationError):
        return f"{prefix}: {exc}" if prefix else str(exc)
    lines = []
    for err in exc.errors():
        loc = ".".join(str(p) for p in err["loc"])
        loc = ".".join(p for p in (prefix, loc) if p) or "(top level)"
        msg = err["msg"].removeprefix("Value error, ")
        got = err.get("input")
        got_text = "" if isinstance(got, dict | list) or err["type"] == "value_error" else f" (got {got!r})"
        lines.append(f"{loc}: {msg}{got_text}")
    return "; ".join(lines)


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
        raise ValueError(f"unknown method {name!r}; registered: {sorted(METHODS)}")
    return name


MethodName = Annotated[str, AfterValidator(registered_method)]
"""A method name of the design registry; configs never list the methods themselves."""


class StrictModel(BaseModel):
    """Base for config tables: unknown keys and wrong types are errors that name the field."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class FiniteModel(StrictModel):
    """A config table whose floats must be finite (NaN and inf are refused naming the field)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class StudyHeader(StrictModel):
    """The ``[study]`` table of every study file."""

    name: str = Field(pattern=r"^[A-Za-z0-9_\-]+$")
    kind: str
    description: str = ""


# ---------------------------------------------------------------------------------------------- loading
def study_kind(name: str) -> StudyKind:
    """The registered kind called ``name`` (every kind module is imported first)."""
    kinds = discover_kinds()
    if name not in kinds:
        raise ConfigError(f"study.kind: unknown kind {name!r}; known kinds: {sorted(kinds)}")
    return kinds[name]


def load_study(path: str | Path) -> tuple[StudyKind, BaseModel, dict[str, Any]]:
    """Read, parse and validate a study file; returns its kind, the validated config and the raw dict."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"study: no such file {path}")
    try:
        raw = tomllib.loads(path.read_bytes().decode("utf-8"))
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read the study file ({exc.strerror})") from None
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{path}: not a text file (byte {exc.start} is not UTF-8); a study is a TOML file") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML ({exc})") from None
    header = raw.get("study")
    if not isinstance(header, dict) or "kind" not in header:
        raise ConfigError(f"study.kind: missing in {path}; every study file needs a [study] table with name and kind")
    kind = study_kind(str(header["kind"]))
    try:
        config = kind.config_model.model_validate(raw)
    except (ValidationError, ValueError) as exc:  # model validators may raise plain ValueError
        raise ConfigError(field_errors(exc)) from None
    return kind, config, raw
