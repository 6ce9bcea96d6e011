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
import operator
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import brentq, minimize_scalar

from railopt.models.modal import NEUTRAL_ROOT, mode_order
from railopt.models.sensitivity import (
    damping_ratio_jacobian,
    eigenvalue_derivatives,
    root_jacobian,
    root_speed_derivative,
)
from railopt.models.system import LinearSystem
from railopt.models.units import rad_s_to_hz
from railopt.models.validation import number
from railopt.records import ArrayRecord


def abscissa(s: np.ndarray) -> float:
    """max Re s over the roots that are not neutral rigid-body roots (|s| ≤ 1e-8 max|s| counts as s = 0)."""
    scale = float(np.max(np.abs(s))) if s.size else 0.0
    live = s[np.abs(s) > NEUTRAL_ROOT * scale]
    return float(np.max(live.real)) if live.size else 0.0


def _resolve(model: object, track: str | None) -> object:
    """The model with ``at(speed=S)``: as given, or a vehicle's lateral view on ``track``."""
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


def _speed_function(model: object, track: str | None) -> Callable[[float], LinearSystem]:
    """``S -> LinearSystem`` for a model with ``at(speed=S)``, or a vehicle with ``lateral(track)``."""
    resolved = _resolve(model, track)
    return lambda S: resolved.at(speed=S)


class _Counted:
    """``S -> system`` with a count of eigen-solves."""

    def __init__(self, model: object, track: str | None) -> None:
        resolved = _resolve(model, track)
        self.at = lambda S: resolved.at(speed=S)
        self.solves = 0
        self.groups, self.main = getattr(resolved, "groups", None), getattr(resolved, "main_body", None)

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
        items = list(speeds) if isinstance(speeds, Sequence | np.ndarray) and not isinstance(speeds, str) else [speeds]
        values = [number(f"{name}[{i}]", s, positive=True) for i, s in enumerate(items)]
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


def root_locus(model: object, speeds: Sequence[float], track: str | None = None) -> RootLocus:
    """Roots of ``model`` at each forward speed (m/s), one eigen-solve each (Fig. 4.4).

    Raises
    ------
    ValueError
        A speed that is not a positive finite number (naming ``speeds[i]``), a model without ``at(speed=S)``.
    """
    S = _speeds(speeds)
    resolved = _resolve(model, track)
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
        Critical speed, m/s; ``inf`` when stable over the whole range; the lower end of the range
        when ``unstable_at_lower_end``.
    frequency : float
        Hunting frequency |Im s|/2π of the critical root, Hz (nan when stable over the range).
    mode : str
        Name of the critical mode (:func:`mode_name`, e.g. "body hunting", "front bogie hunting"; "" if none).
    eigen_solves : int
        Number of eigenvalue problems solved.
    bracket : tuple of float
        Final speed bracket (m/s) around the crossing; (hi, inf) when stable over the range.
    unstable_at_lower_end : bool
        True when a root already has Re s > 0 at the lowest speed of the range.
    tol : float
        Absolute speed tolerance, m/s.
    coordinate : str
        Coordinate with the largest amplitude in the critical root's eigenvector ("" if none).
    """

    speed: float
    frequency: float
    mode: str
    eigen_solves: int
    bracket: tuple[float, float]
    unstable_at_lower_end: bool
    tol: float
    coordinate: str = ""

    @property
    def stable_over_range(self) -> bool:
        return math.isinf(self.speed)

    def to_pandas(self) -> pd.DataFrame:
        """One row: every field, the bracket as ``bracket_low``, ``bracket_high`` (m/s)."""
        return pd.DataFrame([{"speed": self.speed, "frequency_hz": self.frequency, "mode": self.mode,
                              "coordinate": self.coordinate,
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
        f, mode, coordinate = _critical_root(counted, lo)
        return CriticalSpeed(lo, f, mode, counted.solves, (lo, lo), True, tol, coordinate)
    if math.isinf(found):
        return CriticalSpeed(math.inf, math.nan, "", counted.solves, bracket, False, tol)
    f, mode, coordinate = _critical_root(counted, bracket[1])
    return CriticalSpeed(found, f, mode, counted.solves, bracket, False, tol, coordinate)


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
    real = np.where(np.abs(m.s) > NEUTRAL_ROOT * np.max(np.abs(m.s)), m.s.real, -np.inf)
    j = int(np.argmax(real))
    name = _named_roots(system, [j], counted.groups, counted.main)[0]["name"]
    return (float(rad_s_to_hz(abs(m.s[j].imag))), name, system.names[int(np.argmax(np.abs(m.V[:n, j])))])


def least_damping(model: object, speeds: Sequence[float], track: str | None = None) -> float:
    """Smallest damping ratio −Re s/|s| over the roots at ``speeds`` (m/s; neutral roots s ≈ 0 skipped)."""
    counted = _Counted(model, track)
    worst = math.inf
    for S in _speeds(speeds):
        s = counted.roots(float(S))
        live = s[np.abs(s) > NEUTRAL_ROOT * np.max(np.abs(s))]
        worst = min(worst, float(np.min(-live.real / np.abs(live))))
    return worst


# ---------------------------------------------------------------------------------------------- modes
MOTIONS = {"u": "longitudinal", "v": "lateral", "w": "bounce", "alpha": "roll", "beta": "pitch", "gamma": "yaw"}
HUNTING_DAMPING = 0.3  # a hunting mode is oscillatory and lightly damped (heavily creep-damped sway is not hunting)
HUNTING_COUPLING = 0.05  # share of the energy a body mode must give to its trucks (running gear) to be body hunting
HUNTING_LATERAL = 0.3  # share of a truck group's energy in lateral motion for truck hunting


def _body_dof(name: str) -> tuple[str, str]:
    body, _, dof = name.rpartition(".")
    return (body, dof) if body else (name, "")


def _track_body(body: str) -> bool:
    return body.endswith("_track") or body == "track"


SIDES = ("front", "rear", "leading", "trailing", "middle", "centre", "center")
WORDS = {"frame": "truck"}  # a locomotive's truck frame is "the truck"


def readable(group: str) -> str:
    """A body or group name as words: ``"frame_front"`` → "front truck", ``"bogie_rear"`` → "rear bogie",
    ``"wheelset3"`` → "wheelset 3"; other names unchanged."""
    parts = group.split("_")
    if len(parts) == 2 and parts[1].lower() in SIDES:
        return f"{parts[1]} {WORDS.get(parts[0], parts[0])}"
    return re.sub(r"(\D)(\d+)$", r"\1 \2", group)


def _shares(system: LinearSystem, vectors: np.ndarray) -> np.ndarray:
    """Each coordinate's share of the modal kinetic energy Re(v̄_i (M v)_i) / vᴴMv (sums to 1), for one mode
    vector (n,) or for the columns of (n, k) at once."""
    e = np.real(np.conj(vectors) * (system.M @ vectors))
    total = np.sum(e, axis=0)
    uniform = np.full(e.shape, 1.0 / e.shape[0])
    return np.where(total > 0, e / np.where(total > 0, total, 1.0), uniform)


def mode_name(names: Sequence[str], shares: np.ndarray, damping_ratio: float,
              groups: Mapping[str, str] | None = None, main: str | None = None) -> tuple[str, str, float]:
    """Name of a mode from the coordinates' shares of its kinetic energy: ``(name, group, its share)``.

    Bodies are gathered into groups (``groups``: body → group, e.g. a truck frame with its wheelsets and
    motors; a vehicle view provides them; default: each body its own group).  The group with the largest
    share dominates; a mode dominated by lumped track bodies is "track".  Its motion is the kind of
    coordinate with the largest share within the group ("lateral", "yaw", "roll", "bounce", "pitch").
    A lightly damped (ζ < 0.3) mode is *hunting* when the main body (``main``, the car body) dominates in a
    lateral, yaw or roll motion and gives at least 5 % of the energy to the running gear ("body hunting": the
    kinematic motion of the trucks coupled to the body's lower sway), or when a truck group (or the only body
    of a one-body vehicle) dominates with at least 30 % of its energy in lateral motion ("<truck> hunting").
    """
    groups = dict(groups or {})
    per_group: dict[str, float] = {}
    per_kind: dict[tuple[str, str], float] = {}
    for name, share in zip(names, shares, strict=True):
        body, dof = _body_dof(name)
        group = "track" if _track_body(body) else groups.get(body, body)
        per_group[group] = per_group.get(group, 0.0) + share
        kind = MOTIONS.get(dof, dof or body)
        per_kind[(group, kind)] = per_kind.get((group, kind), 0.0) + share
    if per_group.get("track", 0.0) > 0.5:
        return "track", "track", per_group["track"]
    group = max((g for g in per_group if g != "track"), key=per_group.get)
    own = {k: v for (g, k), v in per_kind.items() if g == group}
    total = max(sum(own.values()), 1e-300)
    motion = max(own, key=own.get)
    if damping_ratio < HUNTING_DAMPING and main is not None:
        running_gear = sum(v for g, v in per_group.items() if g not in (main, "track"))
        if group == main and running_gear >= HUNTING_COUPLING and motion in ("lateral", "yaw", "roll"):
            motion = "hunting"
        elif (group != main or len(per_group) == 1) and own.get("lateral", 0.0) >= HUNTING_LATERAL * total:
            motion = "hunting"  # a truck group; or a vehicle of one body (a single wheelset)
    if not motion or motion == group:
        return readable(group), group, per_group[group]
    return f"{readable(group)} {motion}", group, per_group[group]


def modes(model: LinearSystem | object, speed: float | None = None, track: str | None = None,
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


def _named_roots(system: LinearSystem, indices: np.ndarray, groups: Mapping[str, str] | None,
                 main: str | None) -> list[dict]:
    """One row per root ``system.modal().s[k]`` (k in ``indices``) with its :func:`mode_name`."""
    m = system.modal()
    n = system.n
    scale = float(np.max(np.abs(m.s)))
    rows = []
    for k in indices:
        s = m.s[k]
        shares = _shares(system, m.V[:n, k])
        mag = abs(s)
        zeta = -s.real / mag if mag else 1.0
        if mag <= NEUTRAL_ROOT * scale:
            name, group, share = "rigid body", _body_dof(system.names[int(np.argmax(shares))])[0], float(np.max(shares))
        else:
            name, group, share = mode_name(system.names, shares, zeta, groups, main)
        track_share = float(sum(v for c, v in zip(system.names, shares, strict=True) if _track_body(_body_dof(c)[0])))
        rows.append({"frequency_hz": rad_s_to_hz(abs(s.imag)), "damping_ratio": zeta, "real": s.real,
                     "imag": abs(s.imag), "name": name, "group": group, "share": share, "track_share": track_share})
    return rows


# ---------------------------------------------------------------------------------------------- design constraints
def _family_rows(family, p, speeds: Sequence[float], exclude: Sequence[str]):
    """Per speed: the member, its roots one per mode (mode order) and a mask of the kept (vehicle) modes.

    A mode is dropped when neutral, when lumped track bodies carry most of its energy (what
    :func:`mode_name` calls "track") or, with ``exclude``, when its name, group or a prefix is listed; the
    names are only worked out when something is excluded (the constraint rows need the mask alone)."""
    if isinstance(exclude, str):  # a bare string would be read letter by letter
        raise ValueError(f"exclude: a list of mode names, groups or prefixes, got the string {exclude!r}; "
                         f"write [{exclude!r}]")
    groups, main = getattr(family, "groups", None), getattr(family, "main_body", None)
    track: np.ndarray | None = None
    for S in _speeds(speeds):
        system = family.at(p, speed=float(S))
        if track is None:
            track = np.array([_track_body(_body_dof(c)[0]) for c in system.names], dtype=bool)
        m = system.modal()
        idx = mode_order(m.s)[1::2]
        roots = m.s[idx]
        shares = _shares(system, m.V[:system.n, idx])
        keep = (np.abs(roots) > NEUTRAL_ROOT * float(np.max(np.abs(m.s)))) & (shares[track].sum(axis=0) <= 0.5)
        for j in np.flatnonzero(keep) if exclude else ():
            name, group, _ = mode_name(system.names, shares[:, j], -roots[j].real / abs(roots[j]), groups, main)
            if any(x == name or x == group or name.startswith(x) for x in exclude):
                keep[j] = False
        yield float(S), system, idx, keep


def _wrt_jacobian(system: LinearSystem, wrt: Sequence[int] | None) -> np.ndarray:
    """ds/dp (2n, len(wrt)) for the parameters at indices ``wrt`` (all when None)."""
    if wrt is None:
        return root_jacobian(system)
    t = system.tangent
    idx = list(wrt)
    return eigenvalue_derivatives(system, t.dM[idx], t.dC[idx], t.dK[idx])


class StabilityRows:
    """The stability constraint rows of one design: the members solved once, values now, derivatives when asked.

    ``StabilityRows(family, p, speeds, exclude)`` solves the member at every speed S_k once (one eigen-
    decomposition each) and keeps its roots one per mode (mode order) with the kept-mode mask (see
    :func:`root_constraints`).  A derivative-free optimiser reads :meth:`roots` / :meth:`damping` only; a
    gradient method then asks :meth:`roots_jacobian` / :meth:`damping_jacobian`, which reuse the same
    decompositions (the root derivatives ds/dp, thesis eqs. (4.53)–(4.58) with the left eigenvectors, are
    computed once per speed for each ``wrt`` asked and shared by both kinds of row).

    ``family`` is a ParametricSystem with a speed term (P parameters), ``p`` its parameters (None: its values),
    ``speeds`` (K,) in m/s, ``exclude`` a list of mode names, groups or name prefixes (never a bare string).
    ``wrt`` (the Jacobians' columns): indices into the family's parameters, None for all P.

    Raises
    ------
    ValueError
        No speed, a speed ≤ 0, ``exclude`` given as a string, ``wrt`` not whole numbers in [−P, P), a
        negative ``sigma_min``.
    """

    def __init__(self, family, p: Sequence[float] | None, speeds: Sequence[float], exclude: Sequence[str] = ()) -> None:
        self._members = [(system, idx, keep) for _, system, idx, keep in _family_rows(family, p, speeds, exclude)]
        self._parameters = len(family.parameters)
        self._ds: dict[tuple[int, ...] | None, list[np.ndarray]] = {}

    def _root_derivatives(self, wrt: Sequence[int] | None) -> list[np.ndarray]:
        key = _indices("wrt", wrt, self._parameters)
        if key not in self._ds:  # the same indices index the tangent as key the cache
            self._ds[key] = [_wrt_jacobian(system, key)[idx] for system, idx, _ in self._members]
        return self._ds[key]

    def roots(self, sigma_min: float = 0.0) -> np.ndarray:
        """``g = Re s_j + σ_min`` (K·n,), 1/s; −1 for a dropped mode."""
        sigma_min = number("sigma_min", sigma_min, non_negative=True)
        return np.concatenate([np.where(keep, system.modal().s[idx].real + sigma_min, -1.0)
                               for system, idx, keep in self._members])

    def roots_jacobian(self, wrt: Sequence[int] | None = None) -> np.ndarray:
        """``dg/dp`` of :meth:`roots` (K·n, len(wrt) or P), 1/s per unit of each parameter; zero rows for dropped
        modes."""
        return np.vstack([np.where(keep[:, None], ds.real, 0.0)
                          for (_, _, keep), ds in zip(self._members, self._root_derivatives(wrt), strict=True)])

    def damping(self, zeta_min: float) -> np.ndarray:
        """``g = ζ_min − ζ_j`` (K·n,), dimensionless, with ζ = −Re s/|s|; −1 for a dropped mode."""
        zeta_min = number("zeta_min", zeta_min)
        values = []
        for system, idx, keep in self._members:
            s = system.modal().s[idx]
            values.append(np.where(keep, zeta_min + s.real / np.abs(s), -1.0))
        return np.concatenate(values)

    def damping_jacobian(self, wrt: Sequence[int] | None = None) -> np.ndarray:
        """``dg/dp`` of :meth:`damping` (K·n, len(wrt) or P), per unit of each parameter, from
        dζ/dp = damping_ratio_jacobian(s, ds/dp); zero rows for dropped modes."""
        jac = []
        for (system, idx, keep), ds in zip(self._members, self._root_derivatives(wrt), strict=True):
            dzeta = damping_ratio_jacobian(system.modal().s[idx], ds)
            jac.append(np.where(keep[:, None], -dzeta, 0.0))
        return np.vstack(jac)


def _indices(name: str, wrt: object, count: int) -> tuple[int, ...] | None:
    """``wrt`` as a tuple of whole-number indices into ``count`` parameters (None stays None: all of them)."""
    if wrt is None:
        return None
    try:
        items = list(wrt) if not isinstance(wrt, str) else None
        if items is None or any(isinstance(i, bool | np.bool_) for i in items):  # a mask is not a list of indices
            raise TypeError
        out = tuple(operator.index(i) for i in items)
    except TypeError:
        raise ValueError(f"{name}: parameter indices must be whole numbers (for a mask use np.flatnonzero(mask)), "
                         f"got {wrt!r}") from None
    bad = [i for i in out if not -count <= i < count]
    if bad:
        raise ValueError(f"{name}: indices {bad} are outside the family's {count} parameters")
    return out


def root_constraints(family, p: Sequence[float] | None, speeds: Sequence[float], sigma_min: float = 0.0,
                     exclude: Sequence[str] = (), wrt: Sequence[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Stability constraint rows ``g = Re s_j(p, S_k) + σ_min ≤ 0`` for every mode j at every speed S_k (SPEC §2.5).

    One row per mode (n per speed, mode order), so the count is fixed as the design changes; a neutral root,
    a track mode (lumped track bodies carry most of its energy) or a mode named in ``exclude`` (a name, a body
    or a name prefix) gets the constant row −1 with a zero gradient.  Returns ``(g (K·n,), dg/dp (K·n, P))``,
    1/s.  ``family`` is a ParametricSystem with a speed term; ``p`` its parameters (None: its values);
    ``wrt`` the indices of the parameters to differentiate (default all; the Jacobian has one column each).
    Values alone, or values now and derivatives later: :class:`StabilityRows`.
    """
    rows = StabilityRows(family, p, speeds, exclude)
    return rows.roots(sigma_min), rows.roots_jacobian(wrt)


def damping_constraints(family, p: Sequence[float] | None, speeds: Sequence[float], zeta_min: float,
                        exclude: Sequence[str] = (), wrt: Sequence[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Rows ``g = ζ_min − ζ_j(p, S_k) ≤ 0``: every vehicle mode at least ``ζ_min`` damped at every speed (SPEC §2.5).

    Conventions as :func:`root_constraints` (excluded rows −1); ζ = −Re s/|s| with
    dζ/dp from the root derivatives.  Returns ``(g (K·n,), dg/dp (K·n, P))``.
    """
    rows = StabilityRows(family, p, speeds, exclude)
    return rows.damping(zeta_min), rows.damping_jacobian(wrt)


def critical_speed_gradient(family, p: Sequence[float] | None = None, speed_range: tuple[float, float] = (1.0, 100.0),
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
    live = np.where(np.abs(s) > NEUTRAL_ROOT * np.max(np.abs(s)), s.real, -np.inf)
    k = int(np.argmax(live))
    d_speed = float(root_speed_derivative(system)[k].real)
    if d_speed == 0.0:
        return cs, grad
    return cs, -root_jacobian(system)[k].real / d_speed
