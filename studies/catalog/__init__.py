"""The models a study config can name, and what a study needs to know about each.

A study names a model (``model = "tmd"``) and its options; the catalog turns them into a
:class:`ModelSetup`: the :class:`~railopt.models.ParametricSystem` family (its ``values`` are the
defaults), one :class:`ParameterMap` (aliases, derived design variables such as the TMD's tuning, the
designable names, and ``x -> (p, dp/dx)``), named designs (an existing suspension, published optima),
typed checks of finished designs (``p -> CheckResult``) and the unforced lateral families used for
stability (root loci, :class:`HuntingCheck`).  Models register themselves with :func:`register_model`
in the modules of this package, which :func:`discover_models` imports (``pkgutil``); options are
validated by a pydantic model, so ``railopt validate`` catches what a run would reject.
"""

from __future__ import annotations

import importlib
import json
import pkgutil
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Annotated, Any, ClassVar

from pydantic import AfterValidator, BaseModel, Field, PrivateAttr, model_validator

from railopt.studies.catalog.checks import AbscissaCheck, Check, CheckResult, HuntingCheck, _values  # noqa: F401
from railopt.studies.catalog.setup import UNITS, ModelSetup, ParameterMap, Transform
from railopt.studies.config import FileName, Interval, StrictModel, StudyHeader, field_errors, not_one_of

__all__ = [
    "MODELS",
    "UNITS",
    "AbscissaCheck",
    "CatalogEntry",
    "Check",
    "CheckResult",
    "HuntingCheck",
    "ModelRef",
    "ModelSetup",
    "ModelsStudy",
    "ParameterMap",
    "PositiveInterval",
    "Transform",
    "catalog_entry",
    "discover_models",
    "register_model",
    "require_unique",
]

NOT_MODELS = frozenset({"checks", "setup", "views"})
"""Modules of this package that hold the catalog's own machinery, not models: :func:`discover_models` skips them."""


@dataclass(frozen=True)
class CatalogEntry:
    """A registered model: its name, the pydantic model of its options, ``build(options) -> ModelSetup`` and a
    one-line description."""

    name: str
    options: type[BaseModel]
    build: Callable[[BaseModel], ModelSetup]
    description: str


MODELS: dict[str, CatalogEntry] = {}


def register_model(name: str, options: type[BaseModel], description: str = ""):
    """Decorator: ``@register_model("tmd", TMDOptions)`` on ``build(options) -> ModelSetup``."""

    def wrap(build: Callable[[BaseModel], ModelSetup]) -> Callable[[BaseModel], ModelSetup]:
        if name in MODELS and MODELS[name].build is not build:
            raise ValueError(f"model: {name!r} is registered twice")
        MODELS[name] = CatalogEntry(name, options, build, description)
        return build

    return wrap


def discover_models() -> dict[str, CatalogEntry]:
    """Import every model module of this package (each registers its models; :data:`NOT_MODELS` are skipped);
    returns MODELS."""
    package = importlib.import_module(__name__)
    for info in pkgutil.iter_modules(package.__path__):
        if info.name in NOT_MODELS:
            continue
        importlib.import_module(f"{__name__}.{info.name}")
    return MODELS


def _positive_lower(v: tuple[float, float]) -> tuple[float, float]:
    if not v[0] > 0:
        raise ValueError(f"lower end must be > 0, got {v[0]}")
    return v


PositiveInterval = Annotated[Interval, AfterValidator(_positive_lower)]
"""A (lower, upper) pair with 0 < lower < upper, both finite: speed ranges (m/s, mph) in options and configs."""


def catalog_entry(name: str, field_name: str = "model") -> CatalogEntry:
    """The registered model ``name`` (models discovered first); ``ValueError`` naming ``field_name`` when unknown."""
    models = discover_models()
    if name not in models:
        raise ValueError(f"{field_name}: {not_one_of(name, sorted(models), 'model')}")
    return models[name]


class ModelRef(StrictModel):
    """``[[models]]`` entry of a study: a label, a registered model name and its options."""

    label: FileName = Field(description="names the model's campaigns, stores, files and table rows: letters, "
                                        "digits, _, - and .")
    model: str
    options: dict[str, Any] = Field(default_factory=dict)

    def validated_options(self, where: str) -> BaseModel:
        """The options validated by the catalog entry's options model; errors name ``<where>.options``."""
        entry = catalog_entry(self.model, f"{where}.model")
        try:
            return entry.options.model_validate(self.options)
        except Exception as exc:  # pydantic.ValidationError: re-raise naming the config field
            raise ValueError(field_errors(exc, f"{where}.options", entry.options)) from None

    _built: dict[str, Any] = PrivateAttr(default_factory=dict)

    def built(self, what: str, make: Callable[[], Any]) -> Any:
        """``make()`` once per entry and ``what``: validation builds, ``compute`` gets the same object.

        Keyed on ``what``, the model name and the options, so a ``model_copy(update={"options": ...})`` builds
        its own.  Not pickled (see :meth:`__getstate__`).
        """
        key = json.dumps([what, self.model, self.options], sort_keys=True, default=repr)
        if key not in self._built:
            self._built[key] = make()
        return self._built[key]

    def setup(self, where: str = "models") -> ModelSetup:
        """Build the model: its :class:`ModelSetup`; a ValueError names ``<where>.options`` or ``<where>.model``.

        Built once per entry (:meth:`built`): the run's ``compute`` reuses the model its validation built.
        """

        def make() -> ModelSetup:
            entry = catalog_entry(self.model, f"{where}.model")
            options = self.validated_options(where)  # its errors name the field already
            try:
                return entry.build(options)
            except ValueError as exc:  # "view: ..." names models[i].options.view
                raise ValueError(field_errors(exc, f"{where}.options", entry.options)) from None

        return self.built("setup", make)

    def __getstate__(self) -> dict[Any, Any]:
        """Pickled (e.g. into a dask task) without the built models: a task that needs one is given its setup."""
        state = super().__getstate__()
        private = state.get("__pydantic_private__")
        if private and private.get("_built"):
            state = {**state, "__pydantic_private__": {**private, "_built": {}}}
        return state


def require_unique(field: str, labels: Sequence[str]) -> None:
    """Labels name campaigns, stores and table rows: a repeated one is an error naming the field."""
    dup = sorted({x for x in labels if list(labels).count(x) > 1})
    if dup:
        raise ValueError(f"{field}: labels must be unique, repeated {dup}")


class ModelsStudy(StrictModel):
    """A study over catalogued models: its kind is checked and the model labels are unique."""

    KIND: ClassVar[str] = ""
    study: StudyHeader
    models: list[ModelRef] = Field(min_length=1)

    @model_validator(mode="after")
    def _kind_and_labels(self) -> ModelsStudy:
        if self.study.kind != self.KIND:
            raise ValueError(f"study.kind: must be {self.KIND!r} for this config model, got {self.study.kind!r}")
        require_unique("models", [m.label for m in self.models])
        return self
