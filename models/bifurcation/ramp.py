"""The descending speed ramp: dwell at each speed, carry the state over, watch for the cycle to be lost.

At each speed V_k of a strictly decreasing list the system is integrated for the dwell from the state the
previous speed ended in (the first from ``x0``); the limit-cycle detector (:mod:`.limit_cycle`) judges the last
``window`` fraction of the dwell.  Where a steady cycle at V_k is followed by ``"decaying"`` or ``"rest"`` at
V_{k+1}, the fold of the cycle branch lies in (V_{k+1}, V_k]: the cycle existed at V_k and its basin was left (or
the cycle vanished) by V_{k+1}.  The bracket is as good as the ramp step and the dwell: close to the fold the
cycle's approach and the decay past the fold both slow down (the multiplier tends to 1), so a short dwell may
call the speed just above the fold ``"decaying"`` (transient not yet settled) or the one below ``"steady"``.

The dwell is set in seconds or in wavelengths (n wavelengths of length L take n L / V seconds at speed V, the
usual ramp setting for hunting, where L is the kinematic or the expected hunting wavelength).

A right-hand side that raises :class:`~.integration.ModelLimit` (its model stops applying, e.g. a wheel lifts
off the rail in flange contact) gives the verdict ``"model_limit"`` at that speed, with the message as the reason;
the next speed starts again from ``x0``.  Such a speed never ends a fold bracket.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp

from railopt.models.bifurcation.integration import IntegrationSettings, ModelLimit, RightHandSide, check_state
from railopt.models.bifurcation.limit_cycle import (
    Coordinate,
    CycleTolerances,
    CycleVerdict,
    detect_limit_cycle,
    verdicts_table,
    watched_values,
)
from railopt.records import ArrayRecord


@dataclass(frozen=True)
class Dwell:
    """How long the ramp stays at each speed: ``seconds``, or ``wavelengths`` of length ``wavelength_m``.

    Attributes
    ----------
    seconds : float or None
        Fixed dwell (s).
    wavelengths : float or None
        Number of wavelengths travelled at each speed (needs ``wavelength_m``).
    wavelength_m : float or None
        The wavelength (m).
    """

    seconds: float | None = None
    wavelengths: float | None = None
    wavelength_m: float | None = None

    def __post_init__(self) -> None:
        if (self.seconds is None) == (self.wavelengths is None):
            raise ValueError("dwell: give exactly one of seconds or wavelengths")
        if self.seconds is not None and not self.seconds > 0:
            raise ValueError(f"seconds: must be > 0, got {self.seconds!r}")
        if self.wavelengths is not None:
            if not self.wavelengths > 0:
                raise ValueError(f"wavelengths: must be > 0, got {self.wavelengths!r}")
            if self.wavelength_m is None or not self.wavelength_m > 0:
                raise ValueError(f"wavelength_m: must be > 0 with wavelengths, got {self.wavelength_m!r}")

    def duration(self, speed: float) -> float:
        """The dwell at ``speed`` (m/s) in seconds."""
        if self.seconds is not None:
            return float(self.seconds)
        if not speed > 0:
            raise ValueError(f"speed: a dwell in wavelengths needs speed > 0, got {speed!r}")
        return float(self.wavelengths * self.wavelength_m / speed)


@dataclass(frozen=True, eq=False, repr=False)
class RampResult(ArrayRecord):
    """The ramp's verdict at each speed.

    Attributes
    ----------
    speeds : (k,) ndarray
        The speeds run (m/s), decreasing; fewer than asked when the ramp stopped at rest.
    verdicts : tuple of CycleVerdict
        The detector's verdict on the last window of each dwell.
    states : (k, n) ndarray
        The state at the end of each dwell (carried to the next speed).
    step : float
        The largest speed step of the ramp (m/s).
    """

    speeds: np.ndarray
    verdicts: tuple[CycleVerdict, ...]
    states: np.ndarray
    step: float

    @property
    def fold_bracket(self) -> tuple[float, float] | None:
        """(V_low, V_high) (m/s): the last steady speed V_high and the next speed V_low, where the cycle was
        lost (``"decaying"`` or ``"rest"``); None when the ramp never lost a steady cycle."""
        kinds = [v.classification for v in self.verdicts]
        for k in range(len(kinds) - 1):
            if kinds[k] == "steady" and kinds[k + 1] in ("decaying", "rest"):
                return float(self.speeds[k + 1]), float(self.speeds[k])
        return None

    @property
    def last_steady(self) -> int | None:
        """Index of the speed that ends the bracket (the last steady speed before the loss); None without one."""
        bracket = self.fold_bracket
        if bracket is None:
            return None
        return int(np.nonzero(self.speeds == bracket[1])[0][0])

    def to_pandas(self) -> pd.DataFrame:
        """One row per speed: speed_m_s and the verdict's fields."""
        return verdicts_table(self.speeds, self.verdicts)


def speed_ramp(rhs: RightHandSide, x0: np.ndarray, speeds: np.ndarray, dwell: Dwell, coordinate: Coordinate, *,
               sample_rate_hz: float, window: float = 0.5, settings: IntegrationSettings | None = None,
               tolerances: CycleTolerances | None = None, stop_at_rest: bool = True) -> RampResult:
    """Run the descending ramp with the state carried over and classify the motion at each speed.

    Parameters
    ----------
    rhs : callable
        ``rhs(t, x, speed) -> dx/dt`` (n,) → (n,); t in s, speed in m/s.
    x0 : (n,) ndarray
        State at the start of the first dwell (e.g. a perturbation large enough to reach the cycle).
    speeds : (k,) array_like
        Strictly decreasing speeds (m/s).
    dwell : Dwell
    coordinate : int or callable
        The watched coordinate (state index or ``h(x) -> float``); its amplitude is in the state's units.
    sample_rate_hz : float
        Samples per second handed to the detector (≥ 30 per period of the cycle recommended).
    window : float
        Fraction (0, 1] of each dwell, at its end, that the detector judges.
    settings : IntegrationSettings, optional
    tolerances : CycleTolerances, optional
    stop_at_rest : bool
        Stop after the first ``"rest"`` verdict that follows a lost cycle (nothing left to lose).

    Returns
    -------
    RampResult

    Raises
    ------
    ValueError
        On bad arguments (each message names the argument), or when the integrator fails.
    """
    settings = settings or IntegrationSettings()
    x = check_state(x0)
    start_state = x.copy()
    speeds = np.asarray(speeds, dtype=float)
    if speeds.ndim != 1 or speeds.size < 2 or not np.all(np.isfinite(speeds)):
        raise ValueError(f"speeds: need a finite 1-D array of at least 2 speeds, got shape {speeds.shape}")
    if not np.all(np.diff(speeds) < 0):
        raise ValueError("speeds: must be strictly decreasing (a descending ramp)")
    if not 0 < window <= 1:
        raise ValueError(f"window: must be in (0, 1], got {window!r}")
    if not sample_rate_hz > 0:
        raise ValueError(f"sample_rate_hz: must be > 0, got {sample_rate_hz!r}")
    done_speeds, verdicts, states = [], [], []
    t0 = 0.0
    for speed in speeds:
        duration = dwell.duration(speed)
        start = t0 + (1.0 - window) * duration
        count = max(int(math.ceil(window * duration * sample_rate_hz)) + 1, 5)
        samples = np.linspace(start, t0 + duration, count)
        try:
            sol = solve_ivp(rhs, (t0, t0 + duration), x, t_eval=samples, args=(float(speed),),
                            **settings.options())
        except ModelLimit as limit:
            verdict = CycleVerdict("model_limit", math.nan, math.nan, math.nan, math.nan, 0,
                                   f"the model stopped applying: {limit}")
            x = start_state.copy()  # the next speed starts afresh from the ramp's initial state
        else:
            if sol.status != 0:
                raise ValueError(f"rhs: integration failed at speed {speed} m/s: {sol.message}")
            verdict = detect_limit_cycle(sol.t, watched_values(sol.y, coordinate), tolerances)
            x = sol.y[:, -1].copy()
        t0 += duration
        done_speeds.append(float(speed))
        verdicts.append(verdict)
        states.append(x)
        kinds = [v.classification for v in verdicts]
        if stop_at_rest and verdict.classification == "rest" and "steady" in kinds:
            break
    step = float(np.max(-np.diff(speeds)))
    return RampResult(np.array(done_speeds), tuple(verdicts), np.array(states), step)


__all__ = [
    "Dwell",
    "RampResult",
    "speed_ramp",
]
