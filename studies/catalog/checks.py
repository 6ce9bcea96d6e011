"""Typed checks of finished designs: ``p -> CheckResult`` (the spectral abscissa, hunting).

A :class:`Check` runs on a parameter vector p of a model's family; :class:`AbscissaCheck` is the largest
real part of the roots, :class:`HuntingCheck` the critical speed and least damping on each track.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol

import numpy as np

from railopt.models import ParametricSystem
from railopt.models.stability import critical_speed, least_damping, spectral_abscissa

__all__ = ["AbscissaCheck", "Check", "CheckResult", "HuntingCheck"]


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
