"""The stability map of a speed family: every stable and unstable speed interval of a range, certified.

For a margin σ (1/s; usually ≥ 0) a speed is *stable* when every root that is not a neutral rigid-body root has
Re s ≤ −σ (σ = 0: no hunting; σ > 0: a decay-rate margin).  The margin function m(S) = a(S) + σ, with a(S)
the spectral abscissa, changes sign only at a speed where a root meets the line Re s = −σ; for a family with the
creep term C_speed/S every such speed is a real eigenvalue of a pencil (:mod:`railopt.models.crossings`), found
without a speed grid.  Between consecutive candidates the sign of m is constant, so one eigen-solve in each
interval reads it; each crossing is then confirmed by eigen-solves to within ``tol`` on both sides.

*Certified* (``StabilityMap.certified``) means: the candidates came from the pencil, every interval's state was
read by an eigen-solve, every crossing between a stable and an unstable interval was confirmed by eigen-solves
within ``tol`` m/s, and the margin sampled at both ends of the range agrees with the first and last interval.
A family without a declared speed term (a user's ``at(speed=S)``) is scanned on a grid: ``method="sampled"``,
never certified.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import brentq, minimize_scalar

from railopt.models.crossings import crossing_speeds, speed_pencil
from railopt.models.modal import neutral_roots
from railopt.models.mode_names import _named_roots
from railopt.models.protocols import SpeedFamily, StabilityModel
from railopt.models.system import LinearSystem
from railopt.models.validation import number

SAMPLED_GRID = 64  # speeds of the scan of a family without a pencil


def checked_speed_range(speed_range: object) -> tuple[float, float]:
    """``(lowest, highest)`` forward speeds (m/s) of a range, checked (ValueError naming ``speed_range``)."""
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


def abscissa(s: np.ndarray) -> float:
    """max Re s over the roots that are not neutral rigid-body roots (:func:`~railopt.models.modal.neutral_roots`)."""
    live = s[~neutral_roots(s)]
    return float(np.max(live.real)) if live.size else 0.0


def resolve_model(model: StabilityModel, track: str | None) -> SpeedFamily:
    """The model with ``at(speed=S)``: as given, or a vehicle's lateral view on ``track`` (ValueError otherwise)."""
    if isinstance(model, LinearSystem):
        raise ValueError("model: a LinearSystem has one speed; give a model with at(speed=S) (a vehicle view or a "
                         "ParametricSystem with a speed term)")
    if track is not None or (not hasattr(model, "at") and hasattr(model, "lateral")):
        if not hasattr(model, "lateral"):
            raise ValueError("track: only a vehicle (with a lateral(track) view) takes track=")
        model = model.lateral(track=track or "rigid")
    if not callable(getattr(model, "at", None)):
        raise ValueError(f"model: needs a method at(speed=S) returning a LinearSystem, got {type(model).__name__}")
    return model


class CountedFamily:
    """``S -> system`` of a resolved model, counting eigen-solves; ``margin(S, σ)`` = a(S) + σ."""

    def __init__(self, model: StabilityModel, track: str | None) -> None:
        resolved = resolve_model(model, track)
        self.model = resolved
        self.at: Callable[[float], LinearSystem] = lambda S: resolved.at(speed=S)
        self.solves = 0
        self.groups, self.main = getattr(resolved, "groups", None), getattr(resolved, "main_body", None)

    def roots(self, speed: float) -> np.ndarray:
        """All roots at ``speed`` (one eigen-solve)."""
        self.solves += 1
        return self.at(speed).eigenvalues()

    def __call__(self, speed: float) -> float:
        return abscissa(self.roots(speed))

    def least_damping(self, speed: float) -> float:
        """The least damping ratio −Re s/|s| of the non-neutral roots at ``speed`` (one eigen-solve; inf if none)."""
        s = self.roots(float(speed))
        live = s[~neutral_roots(s)]
        return float(np.min(-live.real / np.abs(live))) if live.size else math.inf

    def margin(self, speed: float, sigma: float) -> float:
        """a(S) + σ, 1/s: positive where a root lies right of Re s = −σ."""
        return self(speed) + sigma

    def crossing_mode(self, speed: float, sigma: float) -> str:
        """The name of the root nearest the line Re s = −σ at ``speed`` (one eigen-solve with vectors)."""
        self.solves += 1
        system = self.at(speed)
        s = system.modal().s
        live = ~neutral_roots(s)
        if not live.any():
            return ""
        j = int(np.argmin(np.where(live, np.abs(s.real + sigma), np.inf)))
        return str(_named_roots(system, [j], self.groups, self.main)[0]["name"])


@dataclass(frozen=True)
class StabilityInterval:
    """One interval of a :class:`StabilityMap`: ``start``–``end`` (m/s), ``stable`` throughout, the largest margin
    a(S) + σ read in it (at the middles between candidates, 1/s), and the mode that crosses at each end ("" at an
    end of the range)."""

    start: float
    end: float
    stable: bool
    margin: float
    mode_at_start: str = ""
    mode_at_end: str = ""


@dataclass(frozen=True)
class StabilityMap:
    """Every stable and unstable interval of ``speed_range`` for the line Re s = −``sigma``.

    Attributes
    ----------
    speed_range : (float, float)
        The range mapped, m/s.
    sigma : float
        The decay-rate margin σ, 1/s (0: the imaginary axis).
    intervals : tuple of StabilityInterval
        Consecutive, alternating stable/unstable, covering the range.
    method : {"pencil", "sampled"}
        Candidates from the crossing pencil, or a scan of ``SAMPLED_GRID`` speeds (never certified).
    certified : bool
        Every crossing in the range found and confirmed by eigen-solves within ``tol`` (see the module).
    eigen_solves : int
        Eigen-solves of the state matrix used (the pencil's QZ not counted).
    pencil_size : int
        Size m of the bialternate pencil (0 when sampled).
    candidates : tuple of float
        The pencil's candidate speeds, m/s (a superset of the crossings).
    tol : float
        Speed tolerance of the crossings, m/s.
    note : str
        Why the map is not certified ("" when it is).
    """

    speed_range: tuple[float, float]
    sigma: float
    intervals: tuple[StabilityInterval, ...]
    method: str
    certified: bool
    eigen_solves: int
    pencil_size: int
    candidates: tuple[float, ...]
    tol: float
    note: str = ""

    @property
    def crossings(self) -> tuple[float, ...]:
        """The speeds (m/s) where the state changes, ascending."""
        return tuple(iv.start for iv in self.intervals[1:])

    @property
    def first_unstable(self) -> float:
        """The lowest speed of the range that is not stable (m/s); inf when the whole range is stable."""
        return next((iv.start for iv in self.intervals if not iv.stable), math.inf)

    @property
    def stable(self) -> bool:
        """True when the whole range is stable (certified or not: read ``certified`` with it)."""
        return all(iv.stable for iv in self.intervals)

    def to_pandas(self) -> pd.DataFrame:
        """One row per interval: ``start_m_s``, ``end_m_s``, ``state`` ("stable"/"unstable"), ``margin_1_s``
        (a(S) + σ at the middle), ``mode_at_start``, ``mode_at_end``; ``attrs`` hold sigma, method, certified."""
        table = pd.DataFrame([{"start_m_s": iv.start, "end_m_s": iv.end,
                               "state": "stable" if iv.stable else "unstable", "margin_1_s": iv.margin,
                               "mode_at_start": iv.mode_at_start, "mode_at_end": iv.mode_at_end}
                              for iv in self.intervals])
        table.attrs.update(sigma_1_s=self.sigma, method=self.method, certified=self.certified,
                           eigen_solves=self.eigen_solves, pencil_size=self.pencil_size)
        return table


def stability_map(model: StabilityModel, speed_range: tuple[float, float] = (1.0, 100.0), *,
                  track: str | None = None, sigma: float = 0.0, tol: float = 0.01) -> StabilityMap:
    """The stability map of ``model`` over ``speed_range`` for the line Re s = −σ, without a speed grid.

    Parameters
    ----------
    model : SpeedFamily, or a LateralModel (a vehicle) with ``track``
        A vehicle view or a ParametricSystem with the creep term (certified); any other ``at(speed=S)`` model
        is scanned (``method="sampled"``).
    speed_range : (float, float)
        Lowest and highest forward speed, m/s.
    track : {"rigid", "flexible"}, optional
        For a vehicle definition: the lateral view on this track.
    sigma : float
        Decay-rate margin σ, 1/s: the line Re s = −σ (σ < 0, a line right of the axis, is a tolerance).
    tol : float
        Speed tolerance of each crossing, m/s.

    Raises
    ------
    ValueError
        A bad ``speed_range``, ``sigma`` or ``tol`` (naming it), or a model without ``at(speed=S)``.
    """
    lo, hi = checked_speed_range(speed_range)
    sigma = number("sigma", sigma)
    tol = number("tol", tol, positive=True)
    family = CountedFamily(model, track)
    pencil = speed_pencil(family.at(0.5 * (lo + hi)))
    note = ""
    if pencil is None:
        points, method, size, note = list(np.linspace(lo, hi, SAMPLED_GRID)), "sampled", 0, \
            "the family declares no creep term C_speed/S: scanned on a grid"
        candidates: tuple[float, ...] = ()
    else:
        try:
            cands = crossing_speeds(pencil, (lo, hi), sigma)
        except ValueError as exc:
            cands, note = np.linspace(lo, hi, SAMPLED_GRID), str(exc)
        candidates = tuple(float(c) for c in cands)
        inner = [c for c in candidates if lo < c < hi]
        points, method, size = [lo, *_merge(inner, tol / 4), hi], "pencil", pencil.bialternate_size
    intervals = _intervals(family, points, sigma, tol)
    ends_agree = _ends_agree(family, intervals, lo, hi, sigma, tol)
    if method == "pencil" and not note and not ends_agree:
        note = "the margin at an end of the range disagrees with the map"
    certified = method == "pencil" and not note
    named = _named(family, intervals, sigma)
    return StabilityMap((lo, hi), sigma, named, method, certified, family.solves, size, candidates, tol, note)


def _merge(speeds: list[float], gap: float) -> list[float]:
    out: list[float] = []
    for s in sorted(speeds):
        if not out or s - out[-1] > gap:
            out.append(s)
    return out


def _intervals(family: CountedFamily, points: list[float], sigma: float, tol: float) -> list[StabilityInterval]:
    """Read each piece's state at its middle, merge equal neighbours, and locate each crossing within tol.

    Where two neighbouring pieces differ, their middles bracket the crossing (the margin changes sign between them),
    so the candidate between them is confirmed by two eigen-solves within ±tol/2, or else the crossing is located by
    Brent between the middles to ``tol``: a state change is always located by eigen-solves.
    """
    mids = [0.5 * (a + b) for a, b in zip(points[:-1], points[1:], strict=True)]
    margins = [family.margin(m, sigma) for m in mids]
    stable = [m <= 0.0 for m in margins]
    merged = [[points[0], points[1], stable[0], margins[0]]]
    for i in range(1, len(mids)):
        if stable[i] == merged[-1][2]:
            merged[-1][1], merged[-1][3] = points[i + 1], max(merged[-1][3], margins[i])
        else:
            crossing = _confirm(family, points[i], mids[i - 1], mids[i], stable[i], sigma, tol)
            merged[-1][1] = crossing
            merged.append([crossing, points[i + 1], stable[i], margins[i]])
    return [StabilityInterval(a, b, bool(st), float(m)) for a, b, st, m in merged]


def _confirm(family: CountedFamily, c: float, left: float, right: float, stable_after: bool, sigma: float,
             tol: float) -> float:
    """The crossing near candidate ``c``: its sign change checked within ±tol/2, else located by Brent between
    the neighbouring middles ``left`` and ``right`` (whose states differ) to ``tol``."""
    half = 0.5 * tol
    a, b = max(c - half, left), min(c + half, right)
    if (family.margin(a, sigma) <= 0.0) != stable_after and (family.margin(b, sigma) <= 0.0) == stable_after:
        return c
    return float(brentq(lambda S: family.margin(S, sigma), left, right, xtol=tol, rtol=4 * np.finfo(float).eps))


def _ends_agree(family: CountedFamily, intervals: list[StabilityInterval], lo: float, hi: float, sigma: float,
                tol: float) -> bool:
    """The margin just inside each end of the range has the state of the end interval (a crossing within tol of
    an end excepted)."""
    first, last = intervals[0], intervals[-1]
    ok = True
    if first.end - lo > tol:
        ok &= (family.margin(lo, sigma) <= 0.0) == first.stable
    if hi - last.start > tol:
        ok &= (family.margin(hi, sigma) <= 0.0) == last.stable
    return ok


def _named(family: CountedFamily, intervals: list[StabilityInterval], sigma: float) -> tuple[StabilityInterval, ...]:
    modes = [family.crossing_mode(iv.start, sigma) for iv in intervals[1:]]
    out = []
    for k, iv in enumerate(intervals):
        start = modes[k - 1] if k > 0 else ""
        end = modes[k] if k < len(modes) else ""
        out.append(StabilityInterval(iv.start, iv.end, iv.stable, iv.margin, start, end))
    return tuple(out)


def worst_speed(model: StabilityModel, interval: tuple[float, float], *, track: str | None = None,
                tol: float = 0.01) -> tuple[float, float]:
    """The speed (m/s) in ``interval`` where the spectral abscissa is largest, and that abscissa (1/s): bounded
    Brent search (the exchange step of the semi-infinite stability constraints adds this speed to the rows)."""
    family = CountedFamily(model, track)
    a, b = interval
    best = minimize_scalar(lambda S: -family(S), bounds=(a, b), method="bounded", options={"xatol": tol})
    ends = [(family(a), a), (family(b), b), (-float(best.fun), float(best.x))]
    value, speed = max(ends)
    return speed, value


def least_damping_ratio(model: StabilityModel, speed_range: tuple[float, float], *, track: str | None = None,
                        points: int = 24, tol: float = 0.01) -> tuple[float, float]:
    """The least damping ratio ζ = −Re s/|s| of the non-neutral roots over ``speed_range`` (m/s), and its speed.

    Sampled, never certified: ``points`` even speeds, then a bounded Brent search between the neighbours of the
    worst sample (to ``tol`` m/s).  The decay rate −Re s is what :func:`stability_map` certifies; the damping
    ratio is checked this way and says so where it is reported.
    """
    family = CountedFamily(model, track)
    lo, hi = speed_range

    zeta = family.least_damping
    speeds = np.linspace(lo, hi, max(int(points), 2))
    values = np.array([zeta(S) for S in speeds])
    k = int(np.argmin(values))
    a, b = speeds[max(k - 1, 0)], speeds[min(k + 1, len(speeds) - 1)]
    best = minimize_scalar(zeta, bounds=(a, b), method="bounded", options={"xatol": tol})
    if best.fun < values[k]:
        return float(best.fun), float(best.x)
    return float(values[k]), float(speeds[k])


__all__ = ["SAMPLED_GRID", "CountedFamily", "StabilityInterval", "StabilityMap", "abscissa", "checked_speed_range",
           "least_damping_ratio", "resolve_model", "stability_map", "worst_speed"]
