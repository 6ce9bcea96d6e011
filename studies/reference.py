"""The config reference: ``docs/config-reference.md``, generated from the pydantic config models of every registered
kind and the options of every catalog model (field, type, default, description).

``railopt reference --out docs/config-reference.md`` regenerates it; a test fails when the committed file is stale.
"""

from __future__ import annotations

import types
import typing
from typing import Annotated, Any

from pydantic import BaseModel

from railopt.studies.catalog import discover_models
from railopt.studies.config import INT_LIMITS
from railopt.studies.kind import discover_kinds

__all__ = ["reference_markdown"]


def _type_name(annotation: Any) -> str:
    origin = typing.get_origin(annotation)
    if origin is Annotated:
        return _type_name(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        return " | ".join(_type_name(a) for a in typing.get_args(annotation))
    if origin is typing.Literal:
        return " | ".join(f'"{a}"' if isinstance(a, str) else repr(a) for a in typing.get_args(annotation))
    if origin is tuple:
        return f"[{', '.join(_type_name(a) for a in typing.get_args(annotation))}]"
    if origin is list:
        return f"list of {_type_name(typing.get_args(annotation)[0])}"
    if origin is dict:
        key, value = typing.get_args(annotation)
        return f"table of {_type_name(value)}"
    if annotation is type(None):
        return "none"
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return f"[{annotation.__name__}](#{annotation.__name__.lower()})"
    if annotation is Any:
        return "any"
    return getattr(annotation, "__name__", str(annotation))


def _nested_models(annotation: Any) -> list[type[BaseModel]]:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [m for a in typing.get_args(annotation) for m in _nested_models(a)]


def _default_text(field: Any) -> str:
    if field.is_required():
        return "required"
    value = field.default_factory() if field.default_factory is not None else field.default
    if isinstance(value, BaseModel):
        return "(table defaults)"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, bool):
        return str(value).lower()
    if value is None:
        return "—"
    if isinstance(value, tuple):
        value = list(value)
    return str(value).replace("'", '"')


def _constraints(field: Any) -> str:
    parts = []
    for meta in field.metadata:
        for attr, sign in (("gt", ">"), ("ge", "≥"), ("lt", "<"), ("le", "≤"), ("min_length", "min length"),
                           ("max_length", "max length"), ("pattern", "pattern")):
            value = getattr(meta, attr, None)
            if value is not None:
                parts.append(f"{sign} {value}")
    return ", ".join(parts)


def _model_section(model: type[BaseModel], title: str) -> list[str]:
    doc = (model.__doc__ or "").strip().split("\n\n")[0].replace("\n", " ")
    doc = " ".join(doc.split())
    lines = [f"### {title}", ""]
    if doc and not doc.startswith(("Usage docs:", "A base class")):
        lines += [doc, ""]
    lines += ["| field | type | default | description |", "|---|---|---|---|"]
    for name, field in model.model_fields.items():
        desc = " ".join((field.description or "").split())
        limits = _constraints(field)
        if limits:
            desc = f"{desc} ({limits})" if desc else limits
        if name in INT_LIMITS and field.annotation is int:
            desc = f"{desc}; at most {INT_LIMITS[name]}".lstrip("; ")
        cells = [f"`{name}`", _type_name(field.annotation), _default_text(field), desc]
        lines.append("| " + " | ".join(c.replace("|", "\\|") if i != 1 else c.replace(" | ", " or ")
                                       for i, c in enumerate(cells)) + " |")
    return lines + [""]


def reference_markdown() -> str:
    """``docs/config-reference.md``: every registered kind's config tables and every catalog model's options,
    each field with its type, default and description, generated from the pydantic models.

    Regenerate with ``railopt reference --out docs/config-reference.md`` (a test fails when the file is stale)."""
    lines = ["# Study config reference", "",
             "Generated from the config models by `railopt reference --out docs/config-reference.md`; do not edit "
             "by hand (a test compares this file with the models). How to write a study: "
             "[studies.md](studies.md); a first example: [tutorial.md](tutorial.md).", "",
             "Every table refuses unknown keys (with a did-you-mean); numbers are numbers (a string such as "
             "`\"1e5\"` is refused) and finite (`inf` and `nan` are refused), counts are integers, integers fit int64 "
             "(`seed`), `maxeval` fits a C int (at most 2147483647) and `n_starts` is at most 10000000. Names that "
             "become file names (the study's name, model labels, trade-off names) are letters, digits, `_`, `-` and "
             "`.`, at most 100 characters. Relative file paths in `[[models]].options` (`vehicle = \"car.toml\"`) are "
             "read from the study file's folder.", ""]
    for name, kind in sorted(discover_kinds().items()):
        lines += [f"## Kind `{name}`", ""]
        if kind.summary:
            lines += [kind.summary, ""]
        seen: set[type[BaseModel]] = set()
        todo = [kind.config_model]
        while todo:
            model = todo.pop(0)
            if model in seen:
                continue
            seen.add(model)
            title = f"`{name}`: the study file ({model.__name__})" if model is kind.config_model else model.__name__
            lines += _model_section(model, title)
            for field in model.model_fields.values():
                todo += [m for m in _nested_models(field.annotation) if m not in seen]
    lines += ["## Catalog models (`[[models]]` `model = ...`, their `options`)", ""]
    for name, entry in sorted(discover_models().items()):
        lines += [f"## Model `{name}`", ""]
        if entry.description:
            lines += [entry.description, ""]
        lines += _model_section(entry.options, f"`{name}` options ({entry.options.__name__})")
        nested = [m for f in entry.options.model_fields.values() for m in _nested_models(f.annotation)]
        for model in dict.fromkeys(nested):
            lines += _model_section(model, model.__name__)
    return "\n".join(lines).rstrip() + "\n"
