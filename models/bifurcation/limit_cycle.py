"""Limit-cycle detector: amplitude, frequency and growth of one watched coordinate over a time window.

Method.  The extrema of the sampled coordinate q(t) are located (three-point parabola through each discrete
extremum); successive maximum/minimum pairs give half-cycle amplitudes a_k = |q_{k+1} − q_k|/2 at the mid-times
t_k.  The growth rate σ (1/s) is the least-squares slope of ln a_k against t_k; the relative amplitude change per
cycle is g = σ T, with T twice the least-squares spacing of the successive extremum times (for an exponentially
decaying or growing sinusoid the extrema are exactly equally spaced).  For a linear oscillator of damping ratio
ζ, g = −2πζ/√(1−ζ²) (minus the logarithmic decrement).  The watched coordinate must have one maximum and one
minimum per period (a near-sinusoidal cycle, as hunting is): a cycle with extra local extrema would be read at a
multiple of its frequency.

Classification (``CycleTolerances``):

* ``"rest"`` — the last full cycle's amplitude is below ``amplitude_floor`` (or the record has no extrema and
  its range is below it);
* ``"undetermined"`` — fewer than ``min_cycles`` full cycles in the window;
* ``"steady"`` — |g| ≤ ``growth_per_cycle``;
* ``"decaying"`` / ``"growing"`` — g below / above that band.

A transient that decays more slowly than the tolerance (ζ < ``growth_per_cycle``/2π, about 1.6e-4 with the
default 1e-3) is indistinguishable from a cycle over any window and is called steady: the window must hold
enough cycles, and the tolerance be small enough, for the damping one needs to resolve.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

CLASSES = ("steady", "decaying", "growing", "rest", "undetermined")

Coordinate = int | Callable[[np.ndarray], float]
"""The watched coordinate: a state index, or ``h(x) -> float`` of one state x (n,)."""


@dataclass(frozen=True)
class CycleTolerances:
    """The detector's thresholds.

    Attributes
    ----------
    growth_per_cycle : float
        |relative amplitude change per cycle| at or below which an oscillation is ``"steady"`` (default 1e-3).
    amplitude_floor : float
        Amplitude (state units) below which the motion is ``"rest"`` (default 1e-6).
    min_cycles : int
        Full cycles the window must hold for a verdict (default 3).
    """

    growth_per_cycle: float = 1e-3
    amplitude_floor: float = 1e-6
    min_cycles: int = 3

    def __post_init__(self) -> None:
        if not self.growth_per_cycle > 0:
            raise ValueError(f"growth_per_cycle: must be > 0, got {self.growth_per_cycle!r}")
        if not self.amplitude_floor >= 0:
            raise ValueError(f"amplitude_floor: must be >= 0, got {self.amplitude_floor!r}")
        if not (isinstance(self.min_cycles, int) and self.min_cycles >= 2):
            raise ValueError(f"min_cycles: must be an int >= 2, got {self.min_cycles!r}")


@dataclass(frozen=True)
class CycleVerdict:
    """What the detector saw in one window.

    Attributes
    ----------
    classification : str
        ``"steady"``, ``"decaying"``, ``"growing"``, ``"rest"`` or ``"undetermined"``.
    amplitude : float
        Half the peak-to-peak of the last full cycle (state units); the range/2 when there is no cycle.
    frequency_hz : float
        1/T from the spacing of the extrema (Hz); NaN with fewer than three extrema.
    growth_rate : float
        σ = d ln(amplitude)/dt (1/s), least squares over the half-cycle amplitudes; NaN without cycles.
    growth_per_cycle : float
        σ T, the relative amplitude change per cycle (negative: decaying).
    cycles : int
        Full cycles in the window ((extrema − 1) // 2).
    reason : str
        Why this classification, with the numbers compared.
    """

    classification: str
    amplitude: float
    frequency_hz: float
    growth_rate: float
    growth_per_cycle: float
    cycles: int
    reason: str

    def to_dict(self) -> dict[str, object]:
        """The fields as a plain dict (for tables)."""
        return {"classification": self.classification, "amplitude": self.amplitude,
                "frequency_hz": self.frequency_hz, "growth_rate_1_s": self.growth_rate,
                "growth_per_cycle": self.growth_per_cycle, "cycles": self.cycles, "reason": self.reason}


def watched_values(states: np.ndarray, coordinate: Coordinate) -> np.ndarray:
    """The watched coordinate along a trajectory: ``states`` (n, m) → (m,)."""
    states = np.asarray(states, dtype=float)
    if isinstance(coordinate, int | np.integer):
        if not 0 <= coordinate < states.shape[0]:
            raise ValueError(f"coordinate: index {coordinate} is outside a state of size {states.shape[0]}")
        return states[int(coordinate)].copy()
    if callable(coordinate):
        return np.array([float(coordinate(states[:, j])) for j in range(states.shape[1])])
    raise ValueError(f"coordinate: must be a state index or a function of the state, got {coordinate!r}")


def _extrema(t: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Times and values of the alternating local extrema of the sampled q (parabolic refinement)."""
    sign = np.sign(np.diff(q))
    for i in range(1, sign.size):  # a flat step (two equal samples) keeps the previous direction
        if sign[i] == 0:
            sign[i] = sign[i - 1]
    turns = np.nonzero(sign[1:] * sign[:-1] < 0)[0] + 1
    times, values, kinds = [], [], []
    for i in turns:
        t0, t1, t2 = t[i - 1], t[i], t[i + 1]
        q0, q1, q2 = q[i - 1], q[i], q[i + 1]
        denom = (t0 - t1) * (t0 - t2) * (t1 - t2)
        a = (t2 * (q1 - q0) + t1 * (q0 - q2) + t0 * (q2 - q1)) / denom
        b = (t2 * t2 * (q0 - q1) + t1 * t1 * (q2 - q0) + t0 * t0 * (q1 - q2)) / denom
        c = q1 - a * t1 * t1 - b * t1
        tv = -b / (2 * a) if a != 0 else t1
        if not t0 <= tv <= t2:
            tv = t1
        kind = 1 if q1 > q0 else -1  # maximum: rising into the turn
        value = a * tv * tv + b * tv + c
        if kinds and kinds[-1] == kind:  # two maxima (or minima) in a row: keep the more extreme
            if kind * value > kind * values[-1]:
                times[-1], values[-1] = tv, value
            continue
        times.append(tv)
        values.append(value)
        kinds.append(kind)
    return np.array(times), np.array(values)


def detect_limit_cycle(t: np.ndarray, values: np.ndarray,
                       tolerances: CycleTolerances | None = None) -> CycleVerdict:
    """Classify the oscillation of one sampled coordinate.

    Parameters
    ----------
    t : (m,) ndarray
        Strictly increasing sample times (s); sample densely (≥ 30 samples per period) for amplitudes to ~1e-5.
    values : (m,) ndarray
        The watched coordinate at those times (state units).
    tolerances : CycleTolerances, optional

    Returns
    -------
    CycleVerdict

    Raises
    ------
    ValueError
        If t and values differ in shape, have fewer than 5 samples, or t is not strictly increasing.
    """
    tol = tolerances or CycleTolerances()
    t = np.asarray(t, dtype=float)
    q = np.asarray(values, dtype=float)
    if t.shape != q.shape or t.ndim != 1:
        raise ValueError(f"values: shape {q.shape} does not match t {t.shape} (both (m,))")
    if t.size < 5:
        raise ValueError(f"t: need at least 5 samples, got {t.size}")
    if not np.all(np.diff(t) > 0):
        raise ValueError("t: must be strictly increasing")
    nan = math.nan
    times, extrema = _extrema(t, q)
    if extrema.size < 3:
        half_range = float(np.ptp(q)) / 2
        if half_range <= tol.amplitude_floor:
            return CycleVerdict("rest", half_range, nan, nan, nan, 0,
                                f"no oscillation; half range {half_range:.3g} <= floor {tol.amplitude_floor:.3g}")
        return CycleVerdict("undetermined", half_range, nan, nan, nan, 0,
                            f"fewer than 3 extrema in the window; half range {half_range:.3g}")
    half = np.abs(np.diff(extrema)) / 2
    mid = (times[1:] + times[:-1]) / 2
    amplitude = float(np.mean(half[-2:]))
    cycles = (extrema.size - 1) // 2
    # successive extrema are half a period apart (also for an exponentially decaying or growing sinusoid)
    frequency = 1.0 / (2.0 * float(np.polyfit(np.arange(extrema.size), times, 1)[0]))
    positive = half > 0
    if positive.sum() >= 2:
        sigma = float(np.polyfit(mid[positive], np.log(half[positive]), 1)[0])
    else:
        sigma = nan
    per_cycle = sigma / frequency if np.isfinite(frequency) else nan
    if amplitude <= tol.amplitude_floor:
        return CycleVerdict("rest", amplitude, frequency, sigma, per_cycle, cycles,
                            f"amplitude {amplitude:.3g} <= floor {tol.amplitude_floor:.3g}")
    if cycles < tol.min_cycles:
        return CycleVerdict("undetermined", amplitude, frequency, sigma, per_cycle, cycles,
                            f"{cycles} full cycles in the window, need {tol.min_cycles}")
    if abs(per_cycle) <= tol.growth_per_cycle:
        kind, relation = "steady", "<="
    else:
        kind, relation = ("decaying" if per_cycle < 0 else "growing"), ">"
    return CycleVerdict(kind, amplitude, frequency, sigma, per_cycle, cycles,
                        f"|growth per cycle| {abs(per_cycle):.3g} {relation} {tol.growth_per_cycle:.3g} "
                        f"over {cycles} cycles")


def verdicts_table(speeds: np.ndarray, verdicts: tuple[CycleVerdict, ...]) -> pd.DataFrame:
    """One row per speed (m/s) with the verdict's fields."""
    rows = [{"speed_m_s": float(v), **d.to_dict()} for v, d in zip(speeds, verdicts, strict=True)]
    return pd.DataFrame(rows)


__all__ = [
    "CLASSES",
    "Coordinate",
    "CycleTolerances",
    "CycleVerdict",
    "detect_limit_cycle",
    "verdicts_table",
    "watched_values",
]
