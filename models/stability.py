"""Lateral stability against forward speed: root locus and critical speed (thesis §4.3.1, (4.51)–(4.59)).

The creep damping scales as 1/S, so one model assembly serves every speed:
``C(S) = C_const + C_creep / S`` and each speed costs one eigen-solve of the state matrix G (4.53).
The critical speed is the lowest S where the spectral abscissa ``a(S) = max_j Re s_j`` crosses zero;
it is bracketed on a short grid and then located by Brent's method on ``a(S)`` to ``tol`` m/s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import brentq, minimize_scalar

from railopt.models.vehicle.model import VehicleModel, check_speed
from railopt.models.vehicle.vehicle import Vehicle


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


def _model(vehicle: Vehicle | VehicleModel, track: str) -> VehicleModel:
    if isinstance(vehicle, VehicleModel):
        return vehicle
    return vehicle.lateral(track=track)


class _Abscissa:
    """a(S) = max Re s_j with a count of eigen-solves (the model's suspension fixed)."""

    def __init__(self, model: VehicleModel) -> None:
        n = model.n_dof
        Minv = np.linalg.inv(model.M)
        self.n = n
        self.top = np.hstack([np.zeros((n, n)), np.eye(n)])
        self.mk = -Minv @ model.K
        self.mc = -Minv @ model.C_const
        self.mcc = -Minv @ model.C_creep
        self.names = model.coordinates
        self.solves = 0

    def roots(self, speed: float) -> tuple[np.ndarray, np.ndarray]:
        self.solves += 1
        G = np.vstack([self.top, np.hstack([self.mk, self.mc + self.mcc / speed])])
        s, vec = np.linalg.eig(G)
        return s, vec[: self.n]

    def __call__(self, speed: float) -> float:
        s, _ = self.roots(speed)
        return abscissa(s)


def abscissa(s: np.ndarray) -> float:
    """max Re s over the roots that are not neutral rigid-body roots (|s| <= 1e-8 max|s| counts as s = 0)."""
    scale = float(np.max(np.abs(s))) if s.size else 0.0
    live = s[np.abs(s) > 1e-8 * scale]
    return float(np.max(live.real)) if live.size else 0.0


def spectral_abscissa(model: VehicleModel) -> float:
    """Largest real part of the roots of ``model`` at its speed, 1/s."""
    return abscissa(model.eigenvalues())


def root_locus(vehicle: Vehicle | VehicleModel, track: str = "rigid", speeds: Sequence[float] = ()) -> pd.DataFrame:
    """Roots against forward speed (Fig. 4.4).

    Parameters
    ----------
    vehicle : Vehicle or VehicleModel
        A vehicle (its lateral model on ``track`` is used) or a model.
    track : {"rigid", "flexible"}
    speeds : sequence of float
        Forward speeds, m/s (each positive).

    Returns
    -------
    pandas.DataFrame
        One row per root with Im s >= 0: ``speed`` (m/s), ``mode`` (rank by frequency at that
        speed), ``real``, ``imag`` (1/s, rad/s), ``damping_ratio`` (−Re s/|s|), ``frequency_hz``.
    """
    speeds = [check_speed(s) for s in speeds]
    if not speeds:
        raise ValueError("speeds: give at least one forward speed (m/s)")
    ab = _Abscissa(_model(vehicle, track))
    rows = []
    for S in speeds:
        s, _ = ab.roots(S)
        s = s[s.imag >= 0.0]
        s = s[np.lexsort((s.real, s.imag))]
        for j, r in enumerate(s):
            mag = abs(r)
            rows.append((S, j, r.real, r.imag, -r.real / mag if mag > 0 else 1.0, r.imag / (2.0 * math.pi)))
    return pd.DataFrame(rows, columns=["speed", "mode", "real", "imag", "damping_ratio", "frequency_hz"])


def critical_speed(
    vehicle: Vehicle | VehicleModel,
    track: str = "rigid",
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
    vehicle : Vehicle or VehicleModel
    track : {"rigid", "flexible"}
    speed_range : (float, float)
        Lowest and highest forward speed, m/s.
    tol : float
        Absolute tolerance on the critical speed, m/s.
    grid : int
        Number of bracketing speeds (>= 2).
    """
    lo, hi = (check_speed(s) for s in speed_range)
    if not hi > lo:
        raise ValueError(f"speed_range: inverted or empty range ({lo}, {hi}) m/s")
    if not (math.isfinite(tol) and tol > 0.0):
        raise ValueError(f"tol: must be a positive speed (m/s), got {tol!r}")
    if grid < 2:
        raise ValueError(f"grid: need at least 2 speeds, got {grid}")
    ab = _Abscissa(_model(vehicle, track))
    found, bracket = first_crossing(ab, lo, hi, tol, grid)
    if found == lo and bracket == (lo, lo):
        f, mode = _critical_root(ab, lo)
        return CriticalSpeed(lo, f, mode, ab.solves, (lo, lo), True, tol)
    if math.isinf(found):
        return CriticalSpeed(math.inf, math.nan, "", ab.solves, bracket, False, tol)
    f, mode = _critical_root(ab, bracket[1])
    return CriticalSpeed(found, f, mode, ab.solves, bracket, False, tol)


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


def _critical_root(ab: _Abscissa, speed: float) -> tuple[float, str]:
    s, vec = ab.roots(speed)
    real = np.where(np.abs(s) > 1e-8 * np.max(np.abs(s)), s.real, -np.inf)
    j = int(np.argmax(real))
    return float(abs(s[j].imag)) / (2.0 * math.pi), ab.names[int(np.argmax(np.abs(vec[:, j])))]
