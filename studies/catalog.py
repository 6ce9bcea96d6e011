"""The models a study config can name, and what a study needs to know about each.

A study names a model (``model = "tmd"``) and its options; the catalog turns them into a
:class:`ModelSetup`: a :class:`~railopt.models.ParametricSystem`, the default parameter values,
the names a study may design, named designs (an existing suspension, published optima) and
checks of finished designs (stability).  Models register themselves with :func:`register_model`;
options are validated by a pydantic model, so ``railopt validate`` catches what a run would reject.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from pydantic import BaseModel, Field, model_validator

from railopt.models import ParametricSystem
from railopt.studies.base import StrictModel, StudyHeader

Check = Callable[[np.ndarray], tuple[float, Mapping[str, Any]]]
"""A check of a parameter vector p: (value, flags such as {"stable": True})."""


@dataclass
class ModelSetup:
    """A model ready for a study.

    Attributes
    ----------
    system : ParametricSystem
        The model, affine in its parameters.
    defaults : (P,) ndarray
        Parameter values used for every parameter a study does not design (SI).
    named_designs : mapping name -> {variable: value}
        Designs a config can start from or compare against (e.g. ``"existing"``).
    checks : mapping name -> Check
        Checks of finished designs, run on the parameter vector.
    derived : mapping name -> (inputs, function)
        Design variables that are functions of several parameters' worth of physics (e.g. the
        TMD's tuning ratio): ``function(values dict) -> (p dict, dp/dvalues dict of dicts)``.
    """

    system: ParametricSystem
    defaults: np.ndarray
    named_designs: dict[str, dict[str, float]] = field(default_factory=dict)
    checks: dict[str, Check] = field(default_factory=dict)
    transform: Callable[[dict[str, float]], tuple[dict[str, float], dict[str, dict[str, float]]]] | None = None
    transform_variables: tuple[str, ...] = ()
    description: str = ""
    speed_model: Callable[[np.ndarray], Any] | None = None
    """For models with forward speed: p -> a model with ``M, K, C_const, C_creep`` whose damping is
    ``C_const + C_creep / S`` (what :mod:`railopt.models.stability` takes)."""
    aliases: dict[str, str] = field(default_factory=dict)
    """Readable names of parameters (e.g. ``secondary_lateral_stiffness`` → ``K2``), designable too."""

    @property
    def designable(self) -> tuple[str, ...]:
        """Names a study may use as design variables."""
        return tuple(self.system.parameters) + self.transform_variables + tuple(
            a for a, k in self.aliases.items() if k in self.system.parameters)

    def parameters(self, names: Sequence[str], x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Parameter vector p (P,) for design values ``x`` of ``names``, and dp/dx (P, d)."""
        params = list(self.system.parameters)
        p = np.array(self.defaults, dtype=float)
        J = np.zeros((len(params), len(names)))
        derived = {n: float(v) for n, v in zip(names, x, strict=True) if n in self.transform_variables}
        for j, (n, v) in enumerate(zip(names, x, strict=True)):
            n = self.aliases.get(n, n)
            if n in params:
                p[params.index(n)] = v
                J[params.index(n), j] = 1.0
        if derived:
            values, jac = self.transform(derived)
            for pname, val in values.items():
                i = params.index(pname)
                p[i] = val
                for vname, d in jac[pname].items():
                    J[i, list(names).index(vname)] += d
        return p, J


@dataclass(frozen=True)
class CatalogEntry:
    name: str
    options: type[BaseModel]
    build: Callable[[BaseModel], ModelSetup]
    description: str


MODELS: dict[str, CatalogEntry] = {}


def register_model(name: str, options: type[BaseModel], description: str = ""):
    """Decorator: ``@register_model("tmd", TMDOptions)`` on ``build(options) -> ModelSetup``."""

    def wrap(build: Callable[[BaseModel], ModelSetup]) -> Callable[[BaseModel], ModelSetup]:
        if name in MODELS:
            raise ValueError(f"model: {name!r} is registered twice")
        MODELS[name] = CatalogEntry(name, options, build, description)
        return build

    return wrap


def catalog_entry(name: str, field_name: str = "model") -> CatalogEntry:
    import railopt.studies.models  # noqa: F401  (registers the bundled models)
    import railopt.studies.ride_models  # noqa: F401

    if name not in MODELS:
        raise ValueError(f"{field_name}: unknown model {name!r}; known models: {sorted(MODELS)}")
    return MODELS[name]


class ModelRef(StrictModel):
    """``[[models]]`` entry of a study: a label, a registered model name and its options."""

    label: str = Field(pattern=r"^[A-Za-z0-9_.\-]+$")
    model: str
    options: dict[str, Any] = Field(default_factory=dict)

    def validated_options(self, where: str) -> BaseModel:
        entry = catalog_entry(self.model, f"{where}.model")
        try:
            return entry.options.model_validate(self.options)
        except Exception as exc:  # pydantic.ValidationError: re-raise naming the config field
            from railopt.studies.validation import field_errors

            raise ValueError(field_errors(exc, f"{where}.options")) from None

    def setup(self, where: str = "models") -> ModelSetup:
        entry = catalog_entry(self.model, f"{where}.model")
        try:
            return entry.build(self.validated_options(where))
        except ValueError as exc:
            raise ValueError(f"{where}.options: {exc}") from None


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
