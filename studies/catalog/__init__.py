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
import pkgutil
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Annotated, Any, ClassVar, Protocol

import numpy as np
from pydantic import AfterValidator, BaseModel, Field, model_validator

from railopt.models import ParametricSystem
from railopt.models.stability import critical_speed, least_damping, spectral_abscissa
from railopt.studies.config import Interval, StrictModel, StudyHeader, field_errors

__all__ = [
    "MODELS",
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
    "catalog_entry",
    "discover_models",
    "register_model",
    "require_unique",
]

Transform = Callable[[dict[str, float]], tuple[dict[str, float], dict[str, dict[str, float]]]]
"""Derived design values {name: v} -> (parameters {p: value}, dp/dv {p: {name: derivative}})."""


@dataclass(frozen=True)
class CheckResult:
    """The outcome of a check of one design: its value, boolean flags (e.g. ``stable``) and numbers."""

    value: float
    flags: dict[str, bool] = field(default_factory=dict)
    data: dict[str, float] = field(default_factory=dict)

    def payload(self) -> dict[str, Any]:
        """Data then flags, one flat mapping (the columns of a check in a table)."""
        return {**self.data, **self.flags}


class Check(Protocol):
    """A check of a parameter vector p (the family's parameters); ``flag_names`` are its flags' keys."""

    flag_names: tuple[str, ...]

    def __call__(self, p: np.ndarray) -> CheckResult: ...


def _values(family: ParametricSystem, parameters: Sequence[str], p: np.ndarray) -> dict[str, float]:
    """p over ``parameters`` as values of ``family``'s own parameters (a subset of them, by name)."""
    given = dict(zip(parameters, np.asarray(p, dtype=float), strict=True))
    return {n: given[n] for n in family.parameters}


@dataclass(frozen=True)
class AbscissaCheck:
    """The largest real part of the roots (neutral rigid-body roots ignored), 1/s; stable when negative (4.59)."""

    family: ParametricSystem
    speed: float | None = None
    flag_names: ClassVar[tuple[str, ...]] = ("stable",)

    def __call__(self, p: np.ndarray) -> CheckResult:
        value = spectral_abscissa(self.family.at(np.asarray(p, dtype=float), self.speed))
        return CheckResult(value, {"stable": value < 0})


@dataclass(frozen=True)
class HuntingCheck:
    """Critical speed on each track of ``stability`` and the least damping ratio up to the maximum operating
    speed.  Value: the lowest critical speed (m/s); ``stable``: every critical speed above ``max_speed`` and
    every least damping ratio positive.  ``parameters`` names p; each family takes its own by name."""

    stability: Mapping[str, ParametricSystem]
    parameters: tuple[str, ...]
    search: tuple[float, float]
    max_speed: float
    tol: float = 0.01
    grid: int = 16
    damping_points: int = 24
    flag_names: ClassVar[tuple[str, ...]] = ("stable",)

    def __call__(self, p: np.ndarray) -> CheckResult:
        data: dict[str, float] = {}
        speeds, damping = [], []
        for track, family in self.stability.items():
            model = family.with_values(_values(family, self.parameters, p))
            cs = critical_speed(model, speed_range=self.search, tol=self.tol, grid=self.grid)
            zeta = least_damping(model, np.linspace(self.search[0], self.max_speed, self.damping_points))
            data[f"critical_speed_{track}_m_s"] = cs.speed
            data[f"least_damping_{track}"] = zeta
            speeds.append(cs.speed)
            damping.append(zeta)
        speed = min(speeds)
        data["required_speed_m_s"] = self.max_speed
        return CheckResult(speed, {"stable": bool(speed > self.max_speed and min(damping) > 0)}, data)


UNITS = {"stiffness": "N/m", "damping coefficient": "N·s/m", "rotational stiffness": "N·m/rad",
         "rotational damping coefficient": "N·m·s/rad", "mass": "kg", "moment of inertia": "kg·m²",
         "frequency ratio": "–", "damping ratio": "–"}
"""The SI unit of a parameter by what it is (the kinds of :attr:`ParameterMap.limits`); "–": dimensionless."""


@dataclass(frozen=True)
class ParameterMap:
    """Design variables → the family's parameter vector.

    ``parameters`` are the family's names, ``defaults`` its values (every parameter a study does not
    design keeps its default); ``aliases`` map readable names to parameters (designable too);
    ``transform`` maps the ``derived`` variables (designed together) to parameters with their derivatives;
    ``limits`` gives the physical parameters (by parameter or derived name) their least value and what they are
    (``{"K2": (0.0, "stiffness")}``): design bounds below it are refused (:meth:`check_variables`).
    """

    parameters: tuple[str, ...]
    defaults: np.ndarray
    aliases: dict[str, str] = field(default_factory=dict)
    transform: Transform | None = None
    derived: tuple[str, ...] = ()
    limits: dict[str, tuple[float, str]] = field(default_factory=dict)

    @property
    def designable(self) -> tuple[str, ...]:
        """Names a study may use as design variables."""
        return self.parameters + self.derived + tuple(a for a, k in self.aliases.items() if k in self.parameters)

    def unit(self, name: str) -> str:
        """The SI unit of a design variable (id, alias or derived) from what it is (:data:`UNITS`); "" when
        unknown."""
        limit = self.lower_limit(name)
        return UNITS.get(limit[1], "") if limit else ""

    def lower_limit(self, name: str) -> tuple[float, str] | None:
        """(least physical value, what the parameter is) of a design variable (id, alias or derived), or None
        when the parameter may take any sign."""
        return self.limits.get(name) or self.limits.get(self.aliases.get(name, name))

    def check_bounds(self, name: str, lower: float, upper: float, where: str) -> None:
        """Refuse bounds that let a physical parameter (a stiffness, damping, mass, inertia) go below its least
        value: ``ValueError`` naming ``<where>.lower`` (``upper`` > ``lower`` is the config's own rule)."""
        limit = self.lower_limit(name)
        if limit is None or lower >= limit[0]:
            return
        least, what = limit
        key = self.aliases.get(name, name)
        label = name if key == name else f"{name} ({key})"
        raise ValueError(f"{where}.lower: {label} is a {what} and cannot be below {least:g}; got {lower:g}")

    def check_variables(self, variables: Sequence[Any], where: str = "design.variables") -> None:
        """:meth:`check_bounds` of each variable (objects with ``name``, ``lower``, ``upper``), naming
        ``<where>[i].lower``."""
        for i, v in enumerate(variables):
            self.check_bounds(v.name, v.lower, v.upper, f"{where}[{i}]")

    def check_values(self, values: Mapping[str, float], where: str) -> None:
        """Refuse a design ``{variable: value}`` that puts a physical parameter below its least value, naming
        ``<where>.<variable>``."""
        for name, value in values.items():
            limit = self.lower_limit(name)
            if limit is not None and not value >= limit[0]:
                raise ValueError(f"{where}.{name}: a {limit[1]} cannot be below {limit[0]:g}, got {value:g}")

    def __call__(self, names: Sequence[str], x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Parameter vector p (P,) for design values ``x`` of ``names``, and dp/dx (P, d)."""
        params = list(self.parameters)
        p = np.array(self.defaults, dtype=float)
        J = np.zeros((len(params), len(names)))
        derived = {n: float(v) for n, v in zip(names, x, strict=True) if n in self.derived}
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


@dataclass
class ModelSetup:
    """A model ready for a study.

    Attributes
    ----------
    family : ParametricSystem
        The model, affine in its parameters; ``family.values`` are the defaults (SI).
    parameter_map : ParameterMap
        Design variables (ids, aliases, derived variables) → parameter vector and its Jacobian.
    named_designs : mapping name -> {variable: value}
        Designs a config can start from or compare against (e.g. ``"existing"``).
    checks : mapping name -> Check
        Checks of finished designs, run on the parameter vector: ``p -> CheckResult``.
    stability : mapping track -> ParametricSystem
        The vehicle's unforced lateral family on each track (speed term included), its parameters named
        as the family's (a subset of them): root loci and hunting checks.  Empty without forward speed.
    required_speed : float or None
        The speed (m/s) up to which a design must not hunt (the hunting check's maximum operating speed).
    limits : mapping name -> float
        Named limits of the model's outputs (the vehicle file's ``[clearances]``, m), for constraints.
    units : mapping output -> str
        The unit of each output (``"m/s²"``, ``"rad"``), per the input below; figure axes and tables.
    input_label : str
        The input the outputs are per (``"6.35 mm (0.25 in) lateral irregularity"``); empty when unforced or
        per unit force.
    input_amplitude_m : float or None
        The rail irregularity amplitude (m) the forcing is per (the outputs scale with it); None when the model
        is not forced by a rail irregularity at its own speed.  A ride objective divides by it (per metre).
    """

    family: ParametricSystem
    parameter_map: ParameterMap
    named_designs: dict[str, dict[str, float]] = field(default_factory=dict)
    checks: dict[str, Check] = field(default_factory=dict)
    stability: dict[str, ParametricSystem] = field(default_factory=dict)
    description: str = ""
    required_speed: float | None = None
    limits: dict[str, float] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)
    input_label: str = ""
    input_amplitude_m: float | None = None

    def axis_label(self, output: str, inch: bool = False) -> str:
        """An axis label naming the output, its unit and the input it is per:
        ``"|cab_acceleration| (m/s² per 6.35 mm (0.25 in) lateral irregularity)"``; ``inch``: metres shown as
        inches (``in/s²``)."""
        unit = self.units.get(output, "")
        if inch and (unit == "m" or unit.startswith("m/")):
            unit = "in" + unit[1:]
        parts = [p for p in (unit, f"per {self.input_label}" if self.input_label else "") if p]
        return f"|{output}| ({' '.join(parts)})" if parts else f"|H| of {output}"

    @property
    def defaults(self) -> np.ndarray:
        """The family's default parameter values (P,)."""
        return self.parameter_map.defaults

    @property
    def designable(self) -> tuple[str, ...]:
        """Names a study may use as design variables."""
        return self.parameter_map.designable

    def parameters(self, names: Sequence[str], x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Parameter vector p (P,) for design values ``x`` of ``names``, and dp/dx (P, d)."""
        return self.parameter_map(names, x)

    def stability_model(self, p: np.ndarray, track: str | None = None) -> ParametricSystem:
        """The stability family of ``track`` (default: the first) at the parameter vector p."""
        family = self.stability[track or next(iter(self.stability))]
        return family.with_values(_values(family, self.family.parameters, p))


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
        if name in MODELS and MODELS[name].build is not build:
            raise ValueError(f"model: {name!r} is registered twice")
        MODELS[name] = CatalogEntry(name, options, build, description)
        return build

    return wrap


def discover_models() -> dict[str, CatalogEntry]:
    """Import every module of this package (each registers its models); returns MODELS."""
    package = importlib.import_module(__name__)
    for info in pkgutil.iter_modules(package.__path__):
        importlib.import_module(f"{__name__}.{info.name}")
    return MODELS


def _positive_lower(v: tuple[float, float]) -> tuple[float, float]:
    if not v[0] > 0:
        raise ValueError(f"lower end must be > 0, got {v[0]}")
    return v


PositiveInterval = Annotated[Interval, AfterValidator(_positive_lower)]
"""A (lower, upper) pair with 0 < lower < upper, both finite: speed ranges (m/s, mph) in options and configs."""


def catalog_entry(name: str, field_name: str = "model") -> CatalogEntry:
    models = discover_models()
    if name not in models:
        raise ValueError(f"{field_name}: unknown model {name!r}; known models: {sorted(models)}")
    return models[name]


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
            raise ValueError(field_errors(exc, f"{where}.options")) from None

    def setup(self, where: str = "models") -> ModelSetup:
        entry = catalog_entry(self.model, f"{where}.model")
        options = self.validated_options(where)  # its errors name the field already
        try:
            return entry.build(options)
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
