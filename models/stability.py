"""Stability against forward speed: spectral abscissa, root locus, critical speed, least damping
(thesis §4.3.1, (4.51)–(4.59)).

Every analysis takes a *model*: anything with a method ``at(speed=S)`` (or ``at(p, speed=S)``)
returning a :class:`~railopt.models.system.LinearSystem` — a vehicle view, a
:class:`~railopt.models.parametric.ParametricSystem` with its speed term, a small user class.  A
vehicle definition (anything with a ``lateral(track)`` view) is accepted with ``track=``.  The
creep damping scales as 1/S, so one assembly serves every speed and each speed costs one
eigen-solve of the state matrix G (4.53).  The critical speed is the lowest S where the spectral
abscissa ``a(S) = max_j Re s_j`` crosses zero; it is bracketed on a short grid and located by
Brent's method on ``a(S)`` to ``tol`` m/s.  This module never imports the vehicle package.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import brentq, minimize_scalar

from railopt.models.system import LinearSystem
from railopt.models.validation import number
from railopt.records import ArrayRecord

NEUTRAL_ROOT = 1e-8  # |s| ≤ NEUTRAL_ROOT · max|s| counts as s = 0 (a free rigid-body motion, not instability)


def abscissa(s: np.ndarray) -> float:
    """max Re s over the roots that are not neutral rigid-body roots (|s| ≤ 1e-8 max|s| counts as s = 0)."""
    scale = float(np.max(np.abs(s))) if s.size else 0.0
    live = s[np.abs(s) > NEUTRAL_ROOT * scale]
    return float(np.max(live.real)) if live.size else 0.0


def _speed_function(model: object, track: str | None) -> Callable[[float], LinearSystem]:
    """``S -> LinearSystem`` for a model with ``at(speed=S)``, or a vehicle with ``lateral(track)``."""
    if isinstance(model, LinearSystem):
        raise ValueError("model: a LinearSystem has one speed; give a model with at(speed=S) (a vehicle view or a "
                         "ParametricSystem with a speed term)")
    if track is not None or (not hasattr(model, "at") and hasattr(model, "lateral")):
        if not hasattr(model, "lateral"):
            raise ValueError("track: only a vehicle (with a lateral(track) view) takes track=")
        model = model.lateral(track=track or "rigid")
    if not callable(getattr(model, "at", None)):
        raise ValueError(f"model: needs a method at(speed=S) returning a LinearSystem, got {type(model).__name__}")
    return lambda S: model.at(speed=S)


class _Counted:
    """``S -> system`` with a count of eigen-solves."""

    def __init__(self, model: object, track: str | None) -> None:
        self.at = _speed_function(model, track)
        self.solves = 0

    def roots(self, speed: float) -> np.ndarray:
        self.solves += 1
        return self.at(speed).eigenvalues()

    def __call__(self, speed: float) -> float:
        return abscissa(self.roots(speed))


def spectral_abscissa(system: LinearSystem | object, speed: float | None = None, track: str | None = None) -> float:
    """Largest real part of the roots, 1/s (neutral rigid-body roots ignored): a system, or a model at ``speed``
    (its own speed when omitted)."""
    if not isinstance(system, LinearSystem):
        system = _speed_function(system, track)(speed)
    return abscissa(system.eigenvalues())


def _speeds(speeds: object, name: str = "speeds") -> np.ndarray:
    try:
        values = [number(f"{name}[{i}]", s, positive=True) for i, s in enumerate(np.atleast_1d(speeds))]
    except ValueError as exc:
        raise ValueError(f"{exc} (forward speeds in m/s)") from None
    if not values:
        raise ValueError(f"{name}: give at least one forward speed (m/s)")
    return np.array(values)


@dataclass(frozen=True, eq=False, repr=False)
class RootLocus(ArrayRecord):
    """Roots against forward speed (Fig 4.4).

    Attributes
    ----------
    speeds : (N,) ndarray
        Forward speeds, m/s.
    roots : (N, 2n) ndarray
        Roots at each speed (1/s), in railopt's mode order (ascending |Im s|, then Re s).
    """

    speeds: np.ndarray
    roots: np.ndarray

    def to_pandas(self) -> pd.DataFrame:
        """One row per root with Im s ≥ 0: ``speed`` (m/s), ``mode`` (rank by frequency at that speed), ``real``,
        ``imag`` (1/s, rad/s), ``damping_ratio`` (−Re s/|s|), ``frequency_hz``."""
        rows = []
        for S, s in zip(self.speeds, self.roots, strict=True):
            s = s[s.imag >= 0.0]
            s = s[np.lexsort((s.real, s.imag))]
            for j, r in enumerate(s):
                mag = abs(r)
                rows.append((float(S), j, r.real, r.imag, -r.real / mag if mag > 0 else 1.0, r.imag / (2.0 * math.pi)))
        return pd.DataFrame(rows, columns=["speed", "mode", "real", "imag", "damping_ratio", "frequency_hz"])


def root_locus(model: object, speeds: Sequence[float], track: str | None = None) -> RootLocus:
    """Roots of ``model`` at each forward speed (m/s), one eigen-solve each (Fig. 4.4).

    Raises
    ------
    ValueError
        A speed that is not a positive finite number (naming ``speeds[i]``), a model without ``at(speed=S)``.
    """
    S = _speeds(speeds)
    counted = _Counted(model, track)
    return RootLocus(S, np.array([counted.roots(float(v)) for v in S]))


@dataclass(frozen=True)
class CriticalSpeed:
    """Result of :func:`critical_speed`.

    Attributes
    ----------
    speed : float
        Critical speed, m/s; ``inf`` when stable over the whole range; the lower end of the range
        when ``unstable_at_lower_end``.
    frequency : float
        Hunting frequency |Im s|/2π of the critical root, Hz (nan when stable over the range).
    mode : str
        Coordinate with the largest amplitude in the critical root's eigenvector ("" if none).
    eigen_solves : int
        Number of eigenvalue problems solved.
    bracket : tuple of float
        Final speed bracket (m/s) around the crossing; (hi, inf) when stable over the range.
    unstable_at_lower_end : bool
        True when a root already has Re s > 0 at the lowest speed of the range.
    tol : float
        Absolute speed tolerance, m/s.
    """

    speed: float
    frequency: float
    mode: str
    eigen_solves: int
    bracket: tuple[float, float]
    unstable_at_lower_end: bool
    tol: float

    @property
    def stable_over_range(self) -> bool:
        return math.isinf(self.speed)

    def to_pandas(self) -> pd.DataFrame:
        """One row: every field, the bracket as ``bracket_low``, ``bracket_high`` (m/s)."""
        return pd.DataFrame([{"speed": self.speed, "frequency_hz": self.frequency, "mode": self.mode,
                              "eigen_solves": self.eigen_solves, "bracket_low": self.bracket[0],
                              "bracket_high": self.bracket[1], "unstable_at_lower_end": self.unstable_at_lower_end,
                              "stable_over_range": self.stable_over_range, "tol": self.tol}])


def _speed_range(speed_range: object) -> tuple[float, float]:
    try:
        pair = list(speed_range)  # type: ignore[call-overload]
    except TypeError:
        pair = None
    if pair is None or len(pair) != 2:
        raise ValueError(f"speed_range: must be a pair (lowest, highest) of speeds in m/s, got {speed_range!r}")
    lo, hi = (number(f"speed_range[{i}]", v, positive=True) for i, v in enumerate(pair))
    if not hi > lo:
        raise ValueError(f"speed_range: inverted or empty range ({lo}, {hi}) m/s")
    return lo, hi


def critical_speed(
    model: object,
    track: str | None = None,
    speed_range: tuple[float, float] = (1.0, 100.0),
    tol: float = 0.01,
    grid: int = 8,
) -> CriticalSpeed:
    """Lowest forward speed in ``speed_range`` where a root crosses into Re s > 0.

    The spectral abscissa a(S) is evaluated on ``grid`` evenly spaced speeds until it changes
    sign; the first bracket is refined by Brent's method to ``tol`` m/s (:func:`first_crossing`).
    A sampled local maximum of a(S) below zero is searched for a hidden unstable window first.
    What is promised: no crossing was found at the grid's resolution after that search; an unstable
    window that neither changes the sign of a sample nor raises a sampled local maximum (narrower than
    the grid spacing and between samples) can be missed — raise ``grid`` when in doubt.

    Parameters
    ----------
    model : object with ``at(speed=S)``, or a vehicle with ``track``
        A vehicle view, a ParametricSystem with a speed term, any model returning a LinearSystem.
    track : {"rigid", "flexible"}, optional
        For a vehicle definition: the lateral view on this track.
    speed_range : (float, float)
        Lowest and highest forward speed, m/s.
    tol : float
        Absolute tolerance on the critical speed, m/s.
    grid : int
        Number of bracketing speeds (>= 2).

    Raises
    ------
    ValueError
        A bad ``speed_range``, ``tol`` or ``grid`` (naming it), or a model without ``at(speed=S)``.
    """
    lo, hi = _speed_range(speed_range)
    tol = number("tol", tol, positive=True)
    if isinstance(grid, bool) or not isinstance(grid, numbers.Integral) or grid < 2:
        raise ValueError(f"grid: must be an integer number of bracketing speeds ≥ 2, got {grid!r}")
    counted = _Counted(model, track)
    found, bracket = first_crossing(counted, lo, hi, tol, int(grid))
    if found == lo and bracket == (lo, lo):
        f, mode = _critical_root(counted, lo)
        return CriticalSpeed(lo, f, mode, counted.solves, (lo, lo), True, tol)
    if math.isinf(found):
        return CriticalSpeed(math.inf, math.nan, "", counted.solves, bracket, False, tol)
    f, mode = _critical_root(counted, bracket[1])
    return CriticalSpeed(found, f, mode, counted.solves, bracket, False, tol)


def first_crossing(a, lo: float, hi: float, tol: float, grid: int) -> tuple[float, tuple[float, float]]:
    """Lowest S in [lo, hi] where ``a(S)`` (the spectral abscissa) becomes positive.

    ``a`` is sampled on ``grid`` even speeds; the first sign change is refined by Brent's method to
    ``tol``.  Where the samples show an interior local maximum below zero (a root that approaches the
    axis between samples and turns back), ``a`` is maximised there by bounded Brent search first, so an
    unstable window that raises the sampled abscissa is not stepped over.  Returns ``(lo, (lo, lo))``
    when ``a(lo) > 0``, ``(inf, (hi, inf))`` when no crossing is found.
    """
    speeds = np.linspace(lo, hi, grid)
    values = [a(speeds[0])]
    if values[0] > 0.0:
        return lo, (lo, lo)
    for i in range(1, grid):
        values.append(a(speeds[i]))
        if values[i] > 0.0:
            return _refine(a, speeds[i - 1], speeds[i], tol)
        # a sampled local maximum at i-1 (below zero): look between its neighbours for a hidden window
        if i >= 2 and values[i - 1] >= values[i - 2] and values[i - 1] >= values[i]:
            peak = minimize_scalar(lambda S: -a(S), bounds=(speeds[i - 2], speeds[i]), method="bounded",
                                   options={"xatol": tol})
            if -peak.fun > 0.0:
                return _refine(a, speeds[i - 2], float(peak.x), tol)
    return math.inf, (float(hi), math.inf)


def _refine(a, left: float, right: float, tol: float) -> tuple[float, tuple[float, float]]:
    root = brentq(a, left, right, xtol=tol, rtol=4.0 * np.finfo(float).eps)
    return float(root), (float(max(root - tol, left)), float(min(root + tol, right)))


def _critical_root(counted: _Counted, speed: float) -> tuple[float, str]:
    counted.solves += 1
    system = counted.at(speed)
    m = system.modal()
    n = system.n
    real = np.where(np.abs(m.s) > NEUTRAL_ROOT * np.max(np.abs(m.s)), m.s.real, -np.inf)
    j = int(np.argmax(real))
    return float(abs(m.s[j].imag)) / (2.0 * math.pi), system.names[int(np.argmax(np.abs(m.V[:n, j])))]


def least_damping(model: object, speeds: Sequence[float], track: str | None = None) -> float:
    """Smallest damping ratio −Re s/|s| over the roots at ``speeds`` (m/s; neutral roots s ≈ 0 skipped)."""
    counted = _Counted(model, track)
    worst = math.inf
    for S in _speeds(speeds):
        s = counted.roots(float(S))
        live = s[np.abs(s) > NEUTRAL_ROOT * np.max(np.abs(s))]
        worst = min(worst, float(np.min(-live.real / np.abs(live))))
    return worst
