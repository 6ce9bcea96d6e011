"""Loading and validating a study TOML: every error names the offending field."""

from __future__ import annotations

import importlib
import tomllib
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from railopt.studies.base import StudyKind

# kind name -> "module:attribute" of its StudyKind, imported on demand
KINDS: dict[str, str] = {
    "tmd_hinf": "railopt.studies.tmd_hinf:KIND",
    "track": "railopt.studies.track:KIND",
}


class ConfigError(ValueError):
    """A study config that cannot be used; the message names the field."""


def study_kind(name: str) -> StudyKind:
    if name not in KINDS:
        raise ConfigError(f"study.kind: unknown kind {name!r}; known kinds: {sorted(KINDS)}")
    module, attr = KINDS[name].split(":")
    return getattr(importlib.import_module(module), attr)


def _format_errors(exc: ValidationError) -> str:
    lines = []
    for err in exc.errors():
        loc = ".".join(str(p) for p in err["loc"]) or "(top level)"
        got = err.get("input")
        got_text = "" if isinstance(got, dict) else f" (got {got!r})"
        lines.append(f"{loc}: {err['msg']}{got_text}")
    return "; ".join(lines)


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
        raise ConfigError(f"{path}: not valid TOML ({exc})") from exc
    header = raw.get("study")
    if not isinstance(header, dict) or "kind" not in header:
        raise ConfigError("study.kind: missing; every study file needs a [study] table with name and kind")
    kind = study_kind(str(header["kind"]))
    try:
        config = kind.config_model.model_validate(raw)
    except ValidationError as exc:
        raise ConfigError(_format_errors(exc)) from None
    except ValueError as exc:  # model validators raising plain ValueError
        raise ConfigError(str(exc)) from None
    return kind, config, raw
