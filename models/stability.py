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

The model types are :class:`~railopt.models.protocols.SpeedFamily` and
:class:`~railopt.models.protocols.LateralModel`.  The mode-naming vocabulary lives in
:mod:`railopt.models.mode_names` and the stability constraint rows in :mod:`railopt.models.stability_rows`;
their public names are re-exported here, so ``from railopt.models.stability import mode_name, StabilityRows``
keeps working.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
from scipy.optimize import brentq, minimize_scalar

from railopt.models.crossings import declares_creep
from railopt.models.modal import mode_order, neutral_roots
from railopt.models.mode_names import (
    HUNTING_CIRCULATION,
    HUNTING_DAMPING,
    MOTIONS,
    SIDES,
    WORDS,
    _named_roots,
    mode_name,
    named_modes,
    readable,
)
from railopt.models.protocols import LateralModel, SpeedFamily, StabilityModel
from railopt.models.sensitivity import root_jacobian, root_speed_derivative
from railopt.models.stability_map import CountedFamily as _Counted
from railopt.models.stability_map import (
    StabilityInterval,
    StabilityMap,
    abscissa,
    checked_speed_range,
    resolve_model,
    stability_map,
    worst_speed,
)
from railopt.models.stability_rows import StabilityRows, damping_constraints, root_constraints
from railopt.models.system import LinearSystem
from railopt.models.units import rad_s_to_hz
from railopt.models.validation import forward_speeds, number
from railopt.records import ArrayRecord

if TYPE_CHECKING:
    from railopt.models.parametric import ParametricSystem

__all__ = [
    # the analyses
    "CriticalSpeed", "RootLocus", "abscissa", "critical_speed", "critical_speed_gradient", "first_crossing",
    "least_damping", "modes", "root_locus", "spectral_abscissa",
    # re-exported: the stability map (railopt.models.stability_map)
    "StabilityInterval", "StabilityMap", "resolve_model", "stability_map", "worst_speed",
    # re-exported: the model types (railopt.models.protocols)
    "LateralModel", "SpeedFamily", "StabilityModel",
    # re-exported: the mode-naming vocabulary (railopt.models.mode_names)
    "HUNTING_CIRCULATION", "HUNTING_DAMPING", "MOTIONS", "SIDES", "WORDS", "mode_name", "named_modes", "readable",
    # re-exported: the stability constraint rows (railopt.models.stability_rows)
    "StabilityRows", "damping_constraints", "root_constraints",
]


def _speed_function(model: StabilityModel, track: str | None) -> Callable[[float], LinearSystem]:
    """``S -> LinearSystem`` for a model with ``at(speed=S)``, or a vehicle with ``lateral(track)``."""
    resolved = resolve_model(model, track)
    return lambda S: resolved.at(speed=S)


def spectral_abscissa(system: LinearSystem | StabilityModel, speed: float | None = None,
                      track: str | None = None) -> float:
    """Largest real part of the roots, 1/s (neutral rigid-body roots ignored): a system, or a model at ``speed``
    (its own speed when omitted)."""
    if not isinstance(system, LinearSystem):
        system = _speed_function(system, track)(speed)
    return abscissa(system.eigenvalues())


@dataclass(frozen=True, eq=False, repr=False)
class RootLocus(ArrayRecord):
    """Roots against forward speed (Fig 4.4).

    Attributes
    ----------
    speeds : (N,) ndarray
        Forward speeds, m/s.
    roots : (N, 2n) ndarray
        Roots at each speed (1/s), in railopt's mode order (ascending |Im s|, then Re s).
    names : (N, 2n) ndarray of str, optional
        The mode name of each root (:func:`mode_name`, from its eigenvector's kinetic-energy shares).
    """

    speeds: np.ndarray
    roots: np.ndarray
    names: np.ndarray | None = None

    def to_pandas(self) -> pd.DataFrame:
        """One row per root with Im s ≥ 0: ``speed`` (m/s), ``mode`` (rank by frequency at that speed), ``real``,
        ``imag`` (1/s, rad/s), ``damping_ratio`` (−Re s/|s|), ``frequency_hz`` and, when the locus has them,
        ``name`` (:func:`mode_name` of that root's eigenvector: "body hunting", "front bogie hunting", ...)."""
        rows = []
        names = self.names if self.names is not None else np.full(self.roots.shape, "", dtype=object)
        for S, s, label in zip(self.speeds, self.roots, names, strict=True):
            up = s.imag >= 0.0
            s, label = s[up], label[up]
            order = np.lexsort((s.real, s.imag))
            for j, (r, name) in enumerate(zip(s[order], label[order], strict=True)):
                mag = abs(r)
                rows.append((float(S), j, r.real, r.imag, -r.real / mag if mag > 0 else 1.0, rad_s_to_hz(r.imag),
                             name))
        table = pd.DataFrame(rows, columns=["speed", "mode", "real", "imag", "damping_ratio", "frequency_hz", "name"])
        return table if self.names is not None else table.drop(columns="name")


def root_locus(model: StabilityModel, speeds: Sequence[float], track: str | None = None) -> RootLocus:
    """Roots of ``model`` at each forward speed (m/s), one eigen-solve each (Fig. 4.4).

    Raises
    ------
    ValueError
        A speed that is not a positive finite number (naming ``speeds[i]``), a model without ``at(speed=S)``.
    """
    S = forward_speeds(speeds)
    resolved = resolve_model(model, track)
    groups, main = getattr(resolved, "groups", None), getattr(resolved, "main_body", None)
    roots, names = [], []
    for v in S:
        system = resolved.at(speed=float(v))
        order = mode_order(system.modal().s)
        roots.append(system.modal().s[order])
        names.append([row["name"] for row in _named_roots(system, order, groups, main)])
    return RootLocus(S, np.array(roots), np.array(names, dtype=object))


@dataclass(frozen=True)
class CriticalSpeed:
    """Result of :func:`critical_speed`.

    Attributes
    ----------
    speed : float
        Critical speed, m/s: the first speed of the range where a root has Re s > 0; ``inf`` when stable over
        the whole range; the lower end of the range when ``unstable_at_lower_end``.
    frequency : float
        Hunting frequency |Im s|/2π of the critical root, Hz (nan when stable over the range).
    mode : str
        Name of the critical mode (:func:`mode_name`, e.g. "body hunting", "front bogie hunting"; "" if none).
    eigen_solves : int
        Number of eigenvalue problems of the state matrix solved (the pencil's QZ not counted).
    bracket : tuple of float
        Speed bracket (m/s) around the crossing; (hi, inf) when stable over the range.
    unstable_at_lower_end : bool
        True when a root already has Re s > 0 at the lowest speed of the range.
    tol : float
        Absolute speed tolerance, m/s.
    coordinate : str
        Coordinate with the largest amplitude in the critical root's eigenvector ("" if none).
    method : {"pencil", "sampled"}
        Every crossing from the bialternate pencil (:mod:`railopt.models.crossings`), or the sampled search
        of a family without a declared creep term.
    certified : bool
        True only when every crossing of the range was found by the pencil and confirmed by eigen-solves
        within ``tol`` (see :class:`~railopt.models.stability_map.StabilityMap`); never for ``"sampled"``.
    map : StabilityMap or None
        Every stable and unstable interval of the range (None for the sampled search).
    """

    speed: float
    frequency: float
    mode: str
    eigen_solves: int
    bracket: tuple[float, float]
    unstable_at_lower_end: bool
    tol: float
    coordinate: str = ""
    method: str = "sampled"
    certified: bool = False
    map: StabilityMap | None = None

    @property
    def stable_over_range(self) -> bool:
        """True when no root crossed into Re s > 0 anywhere in the searched range (speed is +inf)."""
        return math.isinf(self.speed)

    @property
    def intervals(self) -> pd.DataFrame:
        """The stable and unstable intervals of the range (:meth:`StabilityMap.to_pandas`); empty when sampled."""
        return self.map.to_pandas() if self.map is not None else pd.DataFrame()

    def to_pandas(self) -> pd.DataFrame:
        """One row: every field but the map, the bracket as ``bracket_low``, ``bracket_high`` (m/s)."""
        return pd.DataFrame([{"speed": self.speed, "frequency_hz": self.frequency, "mode": self.mode,
                              "coordinate": self.coordinate,
                              "eigen_solves": self.eigen_solves, "bracket_low": self.bracket[0],
                              "bracket_high": self.bracket[1], "unstable_at_lower_end": self.unstable_at_lower_end,
                              "stable_over_range": self.stable_over_range, "tol": self.tol, "method": self.method,
                              "certified": self.certified}])


def critical_speed(
    model: StabilityModel,
    track: str | None = None,
    speed_range: tuple[float, float] = (1.0, 100.0),
    tol: float = 0.01,
    grid: int = 8,
) -> CriticalSpeed:
    """Lowest forward speed in ``speed_range`` where a root crosses into Re s > 0 — certified, without a grid.

    For a family with the creep term C_speed/S (a vehicle view, a ParametricSystem with ``C_speed``) every
    speed where a root meets the imaginary axis is a real eigenvalue of the bialternate pencil
    (:func:`~railopt.models.crossings.crossing_speeds`); the sign of the spectral abscissa between consecutive
    candidates gives the stability map (:func:`~railopt.models.stability_map.stability_map`) and the critical
    speed is its first unstable point, confirmed by eigen-solves within ``tol``: ``certified`` is True and the
    answer does not depend on the range asked (for any range that contains it).  A family without the
    declared term (a user's ``at(speed=S)``) is searched on ``grid`` speeds (:func:`first_crossing`):
    ``method="sampled"``, never certified.

    Parameters
    ----------
    model : SpeedFamily (``at(speed=S)``), or a LateralModel (a vehicle) with ``track``
        A vehicle view, a ParametricSystem with a speed term, any model returning a LinearSystem.
    track : {"rigid", "flexible"}, optional
        For a vehicle definition: the lateral view on this track.
    speed_range : (float, float)
        Lowest and highest forward speed, m/s.
    tol : float
        Absolute tolerance on the critical speed, m/s.
    grid : int
        Bracketing speeds of the sampled search (>= 2; unused when the pencil applies).

    Raises
    ------
    ValueError
        A bad ``speed_range``, ``tol`` or ``grid`` (naming it), or a model without ``at(speed=S)``.
    """
    lo, hi = checked_speed_range(speed_range)
    tol = number("tol", tol, positive=True)
    if isinstance(grid, bool) or not isinstance(grid, numbers.Integral) or grid < 2:
        raise ValueError(f"grid: must be an integer number of bracketing speeds ≥ 2, got {grid!r}")
    counted = _Counted(model, track)
    if declares_creep(counted.at(0.5 * (lo + hi))):
        return _certified_critical(counted.model, lo, hi, tol)  # resolved once (a vehicle's view is assembled)
    found, bracket = first_crossing(counted, lo, hi, tol, int(grid))
    if found == lo and bracket == (lo, lo):
        f, mode, coordinate = _critical_root(counted, lo)
        return CriticalSpeed(lo, f, mode, counted.solves, (lo, lo), True, tol, coordinate)
    if math.isinf(found):
        return CriticalSpeed(math.inf, math.nan, "", counted.solves, bracket, False, tol)
    f, mode, coordinate = _critical_root(counted, bracket[1])
    return CriticalSpeed(found, f, mode, counted.solves, bracket, False, tol, coordinate)


def _certified_critical(model: SpeedFamily, lo: float, hi: float, tol: float) -> CriticalSpeed:
    """The critical speed read from the certified map (σ = 0) of a resolved model."""
    smap = stability_map(model, (lo, hi), tol=tol)
    counted = _Counted(model, None)
    first = smap.intervals[0]
    if not first.stable:
        f, mode, coordinate = _critical_root(counted, lo)
        return CriticalSpeed(lo, f, mode, smap.eigen_solves + counted.solves, (lo, lo), True, tol, coordinate,
                             smap.method, smap.certified, smap)
    speed = smap.first_unstable
    if math.isinf(speed):
        return CriticalSpeed(math.inf, math.nan, "", smap.eigen_solves, (hi, math.inf), False, tol, "",
                             smap.method, smap.certified, smap)
    unstable = next(iv for iv in smap.intervals if not iv.stable)
    above = min(speed + 0.5 * tol, 0.5 * (unstable.start + unstable.end))
    f, mode, coordinate = _critical_root(counted, above)
    bracket = (max(speed - 0.5 * tol, lo), above)
    return CriticalSpeed(speed, f, mode, smap.eigen_solves + counted.solves, bracket, False, tol, coordinate,
                         smap.method, smap.certified, smap)


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


def _critical_root(counted: _Counted, speed: float) -> tuple[float, str, str]:
    """Frequency (Hz), mode name and largest-amplitude coordinate of the least stable root at ``speed``."""
    counted.solves += 1
    system = counted.at(speed)
    m = system.modal()
    n = system.n
    real = np.where(neutral_roots(m.s), -np.inf, m.s.real)
    j = int(np.argmax(real))
    name = _named_roots(system, [j], counted.groups, counted.main)[0]["name"]
    return (float(rad_s_to_hz(abs(m.s[j].imag))), name, system.names[int(np.argmax(np.abs(m.V[:n, j])))])


def least_damping(model: StabilityModel, speeds: Sequence[float], track: str | None = None) -> float:
    """Smallest damping ratio −Re s/|s| over the roots at ``speeds`` (m/s; neutral roots s ≈ 0 skipped)."""
    counted = _Counted(model, track)
    return min((counted.least_damping(float(S)) for S in forward_speeds(speeds)), default=math.inf)



def modes(model: LinearSystem | StabilityModel, speed: float | None = None, track: str | None = None,
          groups: Mapping[str, str] | None = None) -> pd.DataFrame:
    """The modes of a system (or of a model at ``speed``, m/s), one row per mode in ascending frequency.

    Columns: ``frequency_hz`` (|Im s|/2π), ``damping_ratio`` (−Re s/|s|), ``real`` (1/s), ``imag`` (rad/s),
    ``name`` (:func:`mode_name`: e.g. "body lateral", "body hunting", "front bogie hunting",
    "wheelset 3 lateral", "track"), ``group`` (the dominant body or group), ``share`` (its share of the modal
    kinetic energy), ``track_share`` (the share of lumped track bodies).  Neutral rigid-body roots (s ≈ 0)
    are named "rigid body".  ``groups`` (body → group) default to the model's own ``groups`` (a vehicle
    view has them: each truck frame with its wheelsets and motors; the car body is its first body).
    """
    if groups is None:
        groups = getattr(model, "groups", None)
    main = getattr(model, "main_body", None)
    system = model if isinstance(model, LinearSystem) else _speed_function(model, track)(speed)
    return pd.DataFrame(_named_roots(system, mode_order(system.modal().s)[1::2], groups, main))


def critical_speed_gradient(family: ParametricSystem, p: Sequence[float] | None = None,
                            speed_range: tuple[float, float] = (1.0, 100.0),
                            tol: float = 1e-6, grid: int = 8) -> tuple[CriticalSpeed, np.ndarray]:
    """The critical speed of ``family`` at ``p`` and its gradient ``dVc/dp`` (P,), m/s per parameter unit.

    By the implicit-function theorem at the crossing, ``dVc/dp = −(∂Re s/∂p)/(∂Re s/∂S)`` for the critical
    root s (SPEC §2.5).  The gradient is zero when the family is stable over the range (or unstable at its
    lower end): there the critical speed does not move with a small change of p.  Note that the lowest
    crossing can switch from one mode to another as p changes: Vc(p) is then continuous but not smooth, which
    is why per-root constraints over a speed grid (:func:`root_constraints`) are the smooth formulation.
    """
    member = family if p is None else family.with_values(p)
    cs = critical_speed(member, speed_range=speed_range, tol=tol, grid=grid)
    grad = np.zeros(len(family.parameters))
    if cs.stable_over_range or cs.unstable_at_lower_end:
        return cs, grad
    system = member.at(speed=cs.speed)
    s = system.modal().s
    live = np.where(neutral_roots(s), -np.inf, s.real)
    k = int(np.argmax(live))
    d_speed = float(root_speed_derivative(system)[k].real)
    if d_speed == 0.0:
        return cs, grad
    return cs, -root_jacobian(system)[k].real / d_speed
