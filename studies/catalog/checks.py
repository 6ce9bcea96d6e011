"""Typed checks of finished designs: ``p -> CheckResult`` (the spectral abscissa, hunting).

A :class:`Check` runs on a parameter vector p of a model's family; :class:`AbscissaCheck` is the largest
real part of the roots, :class:`HuntingCheck` the critical speed and least damping on each track.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar, Protocol

import numpy as np

from railopt.models import ParametricSystem
from railopt.models.stability import critical_speed, spectral_abscissa
from railopt.models.stability_map import least_damping_ratio, stability_map

__all__ = ["CRITERION_TOL", "MEMO_SIZE", "AbscissaCheck", "Check", "CheckResult", "HuntingCheck",
           "NonlinearHuntingCheck"]

MEMO_SIZE = 256  # designs a hunting check remembers
CRITERION_TOL = 1e-6  # 1/s and damping ratio: the constraint rows' feasibility tolerance, allowed by the check too


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
    """The stability criterion of a design on each track of ``stability``, certified.

    Value: the lowest critical speed over the tracks (m/s, :func:`~railopt.models.stability.critical_speed` over
    ``search``: every crossing from the bialternate pencil).  Flag ``stable``: on every track the critical speed is
    above ``max_speed`` (the required speed), every root has Re s ≤ −``sigma_min`` from ``lowest_speed`` to
    ``max_speed`` (the certified :func:`~railopt.models.stability_map.stability_map`), the least damping ratio there
    is ≥ ``zeta_min`` and > 0 (both to :data:`CRITERION_TOL`, the rows' feasibility tolerance; sampled on
    ``damping_points`` speeds and refined by Brent: the decay rate is certified, the damping ratio is sampled), and
    both maps are certified.  A study's ``[stability]`` sets ``sigma_min``, ``zeta_min``, ``lowest_speed`` and
    ``max_speed`` (:meth:`with_criterion`), so the check and the constraint rows state one criterion.
    ``parameters`` names p; each family takes its own by name.
    """

    stability: Mapping[str, ParametricSystem]
    parameters: tuple[str, ...]
    search: tuple[float, float]
    max_speed: float
    tol: float = 0.01
    grid: int = 16
    damping_points: int = 24
    sigma_min: float = 0.0
    zeta_min: float = 0.0
    lowest_speed: float | None = None
    flag_names: ClassVar[tuple[str, ...]] = ("stable", "certified")
    _memo: dict = field(default_factory=dict, init=False, compare=False, repr=False)

    def __getstate__(self) -> dict:
        """Pickled (into a dask task) without the results it remembers."""
        return {k: v for k, v in self.__dict__.items() if k != "_memo"}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state, _memo={})

    def with_criterion(self, *, sigma_min: float, zeta_min: float | None, lowest_speed: float | None,
                       max_speed: float) -> HuntingCheck:
        """The same check with a study's stability criterion (σ_min 1/s, ζ_min, speeds in m/s)."""
        return replace(self, sigma_min=float(sigma_min), zeta_min=float(zeta_min or 0.0),
                       lowest_speed=lowest_speed, max_speed=float(max_speed))

    def critical_speed(self, p: np.ndarray) -> float:
        """The check's value alone (the lowest certified critical speed over the tracks, m/s): what a surface's
        boundary needs, without the margin and damping searches."""
        return min(critical_speed(family.with_values(_values(family, self.parameters, p)), speed_range=self.search,
                                  tol=self.tol, grid=self.grid).speed for family in self.stability.values())

    def __call__(self, p: np.ndarray) -> CheckResult:
        key = np.asarray(p, dtype=float).tobytes()  # a trade-off asks the same design for its front, pick, quantity
        if key not in self._memo:
            if len(self._memo) >= MEMO_SIZE:
                self._memo.clear()
            self._memo[key] = self._check(p)
        return self._memo[key]

    def _check(self, p: np.ndarray) -> CheckResult:
        data: dict[str, float] = {}
        speeds, holds, certified = [], [], []
        lo = self.lowest_speed if self.lowest_speed is not None else self.search[0]
        for track, family in self.stability.items():
            model = family.with_values(_values(family, self.parameters, p))
            cs = critical_speed(model, speed_range=self.search, tol=self.tol, grid=self.grid)
            margin = stability_map(model, (lo, self.max_speed), sigma=self.sigma_min - CRITERION_TOL, tol=self.tol)
            zeta, at = least_damping_ratio(model, (lo, self.max_speed), points=self.damping_points, tol=self.tol)
            data.update({f"critical_speed_{track}_m_s": cs.speed, f"least_damping_{track}": zeta,
                         f"least_damping_speed_{track}_m_s": at})
            speeds.append(cs.speed)
            holds.append(cs.speed > self.max_speed and margin.stable and zeta >= self.zeta_min - CRITERION_TOL
                         and zeta > 0)
            certified.append(cs.certified and margin.certified)
        speed = min(speeds)
        data.update(required_speed_m_s=self.max_speed, sigma_min=self.sigma_min, zeta_min=self.zeta_min)
        return CheckResult(speed, {"stable": bool(all(holds) and all(certified)), "certified": bool(all(certified))},
                           data)


@dataclass(frozen=True)
class NonlinearHuntingCheck:
    """The nonlinear critical speed of a design on the vehicle's wheel and rail profiles (issue 26 item 6).

    Runs :func:`railopt.models.vehicle.hunting.nonlinear_hunting` on the vehicle with the design's values: a
    descending speed ramp with the state carried over (coarse, then fine through the speed where the hunting cycle
    is lost) and, with ``analysis.continuation``, shooting and pseudo-arclength continuation of the cycle through its
    fold.  Value: the lowest speed at which a stable hunting cycle was found (m/s): the continuation's fold when the
    ramp confirms it, else the lowest ramp speed with a steady cycle; inf when none was seen.  Flag
    ``nonlinear_stable``: no stable hunting cycle at or below ``max_speed`` (the required speed) — the confirmed
    fold is above it, or the ramp lost the cycle at a speed at or above it, or no speed of the ramp (from its top
    speed down) held a cycle; a bracket that straddles the required speed without a confirmed fold is not a pass.
    Data: the lowest hunting speed (inf: none from the ramp's top speed down), the ramp's top speed and bracket, the
    fold and whether it is confirmed (1/0), the linear critical speed, the gap linear − lowest hunting speed (m/s)
    and the required speed.  Minutes per design:
    the campaign runs it on each distinct optimum as a task.  ``parameters`` names p; the vehicle takes them by
    name (:meth:`~railopt.models.vehicle.Vehicle.with_parameters`).
    """

    vehicle: Any
    parameters: tuple[str, ...]
    max_speed: float
    analysis: Any = None
    expensive: ClassVar[bool] = True  # not run by ``railopt validate``'s warnings (minutes per design)
    flag_names: ClassVar[tuple[str, ...]] = ("nonlinear_stable",)
    _memo: dict = field(default_factory=dict, init=False, compare=False, repr=False)

    def __getstate__(self) -> dict:
        """Pickled (into a dask task) without the results it remembers."""
        return {k: v for k, v in self.__dict__.items() if k != "_memo"}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state, _memo={})

    def with_analysis(self, analysis: Any, max_speed: float | None = None) -> NonlinearHuntingCheck:
        """The same check with a study's ``[nonlinear_hunting]`` settings (and required speed, m/s)."""
        return replace(self, analysis=analysis, max_speed=float(max_speed if max_speed is not None
                                                                 else self.max_speed))

    def result(self, p: np.ndarray) -> Any:
        """The full :class:`~railopt.models.vehicle.hunting.HuntingResult` of design p (remembered)."""
        from railopt.models.vehicle.hunting import nonlinear_hunting

        key = np.asarray(p, dtype=float).tobytes()
        if key not in self._memo:
            if len(self._memo) >= 16:
                self._memo.clear()
            values = dict(zip(self.parameters, np.asarray(p, dtype=float).tolist(), strict=True))
            self._memo[key] = nonlinear_hunting(self.vehicle.with_parameters(values), self.analysis)
        return self._memo[key]

    def __call__(self, p: np.ndarray) -> CheckResult:
        r = self.result(p)
        low, high = r.bracket if r.bracket is not None else (float("nan"), float("nan"))
        lowest = r.lowest_hunting_speed()
        passes = r.passes(self.max_speed)
        data = {"lowest_hunting_speed_m_s": lowest, "ramp_top_speed_m_s": float(r.ramp.speeds[0]),
                "ramp_last_cycle_m_s": high, "ramp_lost_cycle_at_m_s": low, "fold_speed_m_s": r.critical.fold_speed,
                "fold_confirmed": float(r.critical.confirmed), "linear_critical_speed_m_s": r.linear_critical_speed,
                "hunting_gap_m_s": r.gap(),
                "nonlinear_required_speed_m_s": self.max_speed}
        return CheckResult(lowest, {"nonlinear_stable": passes is True}, data)
