"""Loading and validating a study TOML: every error names the offending field (and the file)."""

from __future__ import annotations

import importlib
import pkgutil
import tomllib
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from railopt.studies.base import KINDS, StudyKind
from railopt.studies.validation import field_errors


class ConfigError(ValueError):
    """A study config that cannot be used; the message names the field."""


def _import_kinds() -> None:
    import railopt.studies.kinds as package

    for info in pkgutil.iter_modules(package.__path__):
        importlib.import_module(f"{package.__name__}.{info.name}")


def study_kind(name: str) -> StudyKind:
    """The registered kind called ``name``."""
    _import_kinds()
    if name not in KINDS:
        raise ConfigError(f"study.kind: unknown kind {name!r}; known kinds: {sorted(KINDS)}")
    return KINDS[name]


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
