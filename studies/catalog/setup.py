"""A model ready for a study: :class:`ModelSetup` and its :class:`ParameterMap` (design variables ->
parameter vector and Jacobian), with the SI :data:`UNITS` of each kind of parameter.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from railopt.models import ParametricSystem
from railopt.studies.catalog.checks import Check, _values
from railopt.studies.config import not_one_of

__all__ = ["UNITS", "ModelSetup", "ParameterMap", "Transform"]

Transform = Callable[[dict[str, float]], tuple[dict[str, float], dict[str, dict[str, float]]]]
"""Derived design values {name: v} -> (parameters {p: value}, dp/dv {p: {name: derivative}})."""


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

    def check_names(self, names: Sequence[str], where: str, model: str = "the model") -> None:
        """Refuse a name that is not designable: ``ValueError`` ``"<where>[i].name: <model>: unknown parameter
        'K2x'; did you mean 'K2'?"`` (the closest name, never the whole list of a vehicle's parameters)."""
        for i, name in enumerate(names):
            if name not in self.designable:
                raise ValueError(f"{where}[{i}].name: {model}: {not_one_of(name, self.designable, 'parameter')}")

    def check_variables(self, variables: Sequence[Any], where: str = "design.variables", model: str = "the model"
                        ) -> None:
        """:meth:`check_names` of the variables (objects with ``name``, ``lower``, ``upper``), then
        :meth:`check_bounds` of each, naming ``<where>[i].name`` or ``<where>[i].lower``."""
        self.check_names([v.name for v in variables], where, model)
        for i, v in enumerate(variables):
            self.check_bounds(v.name, v.lower, v.upper, f"{where}[{i}]")

    def check_values(self, values: Mapping[str, float], where: str) -> None:
        """Refuse a design ``{variable: value}`` that puts a physical parameter below its least value, naming
        ``<where>.<variable>``."""
        for name, value in values.items():
            limit = self.lower_limit(name)
            if limit is not None and not value >= limit[0]:
                raise ValueError(f"{where}.{name}: a {limit[1]} cannot be below {limit[0]:g}, got {value:g}")

    def rows(self, names: Sequence[str], X: np.ndarray) -> np.ndarray:
        """Parameter vectors (B, P) for the designs in the rows of X (B, d): row b equals ``self(names, X[b])[0]``
        (the values only).  Direct variables (ids and aliases) fill their columns at once; a map with derived
        variables goes row by row (the transform takes one design)."""
        X = np.asarray(X, dtype=float)
        if any(n in self.derived for n in names):
            return np.array([self(names, x)[0] for x in X]).reshape(len(X), len(self.parameters))
        params = list(self.parameters)
        P = np.repeat(np.array(self.defaults, dtype=float)[None, :], len(X), axis=0)
        for j, n in enumerate(names):
            n = self.aliases.get(n, n)
            if n in params:
                P[:, params.index(n)] = X[:, j]
        return P

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
    other_tracks : mapping track -> ParametricSystem
        The same family on the vehicle's other tracks: not checked by default, but a study's ``[stability]
        tracks`` may constrain them (a rigid-track ride model required not to hunt on flexible track too).
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
    other_tracks: dict[str, ParametricSystem] = field(default_factory=dict)
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
