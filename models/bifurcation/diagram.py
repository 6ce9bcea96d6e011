"""The bifurcation diagram of a periodic orbit family, and the nonlinear critical speed it yields.

A diagram holds the points of one continued branch (:mod:`.continuation`) in order of arclength: speed,
amplitude, period, non-trivial Floquet multipliers and stability; ``branch`` counts the folds passed (0 before the
first fold, 1 after it, …).  The **nonlinear critical speed** is the lowest fold speed — below it no cycle exists
and every disturbance decays — *confirmed* when the descending speed ramp (:mod:`.ramp`) lost its steady cycle
within the ramp step that brackets it (the lowest speed at which a stable hunting cycle exists).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from railopt.models.bifurcation.ramp import RampResult
from railopt.records import ArrayRecord


@dataclass(frozen=True, eq=False, repr=False)
class Fold(ArrayRecord):
    """A fold (saddle-node of cycles, a Floquet multiplier at +1) located on the branch.

    Attributes
    ----------
    speed : float
        m/s.
    amplitude : float
        Watched coordinate's half peak-to-peak at the fold (state units).
    period : float
        s.
    point : (n,) ndarray
        The orbit's point on the Poincaré section at the fold.
    located : str
        How the speed was found: ``"brent"`` — the zero of the tangent's speed component, each trial point
        corrected onto the branch (as accurate as the corrector); ``"hermite"`` — the corrector failed inside the
        step (a non-smooth map: contact tables), so the speed is the extremum of the cubic Hermite interpolant of
        V(s) through the closest pair of corrected points around the turn and their tangents (error O(L⁴) in the
        chord L where the branch is smooth between them), and ``amplitude``, ``period`` and ``point`` are
        interpolated linearly between that pair (``point`` is then near, not on, the fold's orbit).
    between : (float, float)
        Speeds of the two corrected branch points around the turn that located it (m/s); a fold to lower speeds
        lies at or below both.
    """

    speed: float
    amplitude: float
    period: float
    point: np.ndarray
    located: str = "brent"
    between: tuple[float, float] = (math.nan, math.nan)


@dataclass(frozen=True)
class NonlinearCriticalSpeed:
    """The fold speed and whether the ramp confirms it.

    Attributes
    ----------
    speed : float
        The nonlinear critical speed (m/s): the continuation's fold speed when ``confirmed``, NaN otherwise.
    fold_speed : float
        The lowest fold speed of the diagram (m/s); NaN without a fold.
    ramp_bracket : tuple of float or None
        (V_low, V_high) from the ramp (m/s); None without a ramp or without a lost cycle.
    confirmed : bool
        The fold lies in the ramp's bracket.
    reason : str
    """

    speed: float
    fold_speed: float
    ramp_bracket: tuple[float, float] | None
    confirmed: bool
    reason: str


@dataclass(frozen=True, eq=False, repr=False)
class BifurcationDiagram(ArrayRecord):
    """Periodic orbits continued in speed: one row per point, in arclength order.

    Attributes
    ----------
    speed : (m,) ndarray
        m/s.
    amplitude : (m,) ndarray
        Half peak-to-peak of the watched coordinate (state units).
    period : (m,) ndarray
        s.
    multipliers : (m, n−1) complex ndarray
        Non-trivial Floquet multipliers, largest modulus first.
    stable : (m,) bool ndarray
        All |non-trivial multipliers| < 1.
    branch : (m,) int ndarray
        Number of folds passed before this point.
    points : (m, n) ndarray
        Each orbit's point on the Poincaré section.
    folds : tuple of Fold
        The folds located between points, in arclength order.
    stop_reason : str
        Why the continuation ended (speed range edge, amplitude floor, step too small, point limit).
    linear_critical_speed : float
        The linear (Hopf) critical speed for reference (m/s); NaN when not given.
    ramp : RampResult or None
        The descending ramp that confirms the fold, when run.
    """

    speed: np.ndarray
    amplitude: np.ndarray
    period: np.ndarray
    multipliers: np.ndarray
    stable: np.ndarray
    branch: np.ndarray
    points: np.ndarray
    folds: tuple[Fold, ...]
    stop_reason: str
    linear_critical_speed: float = math.nan
    ramp: RampResult | None = None

    @property
    def fold_speed(self) -> float:
        """The lowest fold speed (m/s); NaN when the branch has no fold."""
        return min((f.speed for f in self.folds), default=math.nan)

    def to_pandas(self) -> pd.DataFrame:
        """One row per point: speed_m_s, amplitude, period_s, frequency_hz, max_abs_multiplier, stable, branch.

        ``attrs`` carry fold_speeds_m_s, fold_located (how each was found), linear_critical_speed_m_s and
        stop_reason.
        """
        largest = np.abs(self.multipliers).max(axis=1) if self.multipliers.size else np.full(self.speed.size, np.nan)
        table = pd.DataFrame({"speed_m_s": self.speed, "amplitude": self.amplitude, "period_s": self.period,
                              "frequency_hz": 1.0 / self.period, "max_abs_multiplier": largest,
                              "stable": self.stable, "branch": self.branch})
        table.attrs.update(fold_speeds_m_s=[f.speed for f in self.folds],
                           fold_located=[f.located for f in self.folds],
                           linear_critical_speed_m_s=self.linear_critical_speed, stop_reason=self.stop_reason)
        return table

    def nonlinear_critical_speed(self, slack: float = 1e-9) -> NonlinearCriticalSpeed:
        """The fold speed, confirmed when it lies in the ramp's bracket (widened by ``slack``·V_high m/s)."""
        fold = self.fold_speed
        bracket = self.ramp.fold_bracket if self.ramp is not None else None
        if math.isnan(fold):
            return NonlinearCriticalSpeed(math.nan, fold, bracket, False, "no fold on the continued branch")
        if self.ramp is None:
            return NonlinearCriticalSpeed(math.nan, fold, None, False, "no ramp attached to confirm the fold")
        if bracket is None:
            return NonlinearCriticalSpeed(math.nan, fold, None, False, "the ramp never lost a steady cycle")
        low, high = bracket
        inside = low - slack * high <= fold <= high + slack * high
        if inside:
            return NonlinearCriticalSpeed(fold, fold, bracket, True,
                                          f"fold {fold:.6g} m/s inside the ramp bracket ({low:.6g}, {high:.6g}]")
        return NonlinearCriticalSpeed(math.nan, fold, bracket, False,
                                      f"fold {fold:.6g} m/s outside the ramp bracket ({low:.6g}, {high:.6g}]")


__all__ = [
    "BifurcationDiagram",
    "Fold",
    "NonlinearCriticalSpeed",
]
