"""Stability as design constraints: one row per mode and speed, values now and derivatives when asked
(SPEC §2.5, thesis eqs. (4.53)–(4.58)).

:class:`StabilityRows` solves a family's member once at each speed and keeps its roots one per mode (mode
order) with the mask of kept (vehicle) modes; :func:`root_constraints` (``Re s + σ_min ≤ 0``) and
:func:`damping_constraints` (``ζ_min − ζ ≤ 0``) return the rows and their Jacobians at once.  The rows'
count is fixed as the design changes (a dropped mode gets the constant row −1 with a zero gradient).  Mode
names come from :mod:`railopt.models.mode_names`.  This module never imports the vehicle package.
"""

from __future__ import annotations

import operator
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from railopt.models.modal import NEUTRAL_ROOT, mode_order
from railopt.models.mode_names import _body_dof, _shares, _track_body, named_modes
from railopt.models.sensitivity import damping_ratio_jacobian, eigenvalue_derivatives, root_jacobian
from railopt.models.system import LinearSystem
from railopt.models.validation import forward_speeds, number

if TYPE_CHECKING:
    from railopt.models.parametric import ParametricSystem

__all__ = ["StabilityRows", "damping_constraints", "root_constraints"]


def _family_rows(family: ParametricSystem, p: Sequence[float] | None, speeds: Sequence[float], exclude: Sequence[str]):
    """Per speed: the member, its roots one per mode (mode order) and a mask of the kept (vehicle) modes.

    A mode is dropped when neutral, when lumped track bodies carry most of its energy (what
    :func:`~railopt.models.mode_names.named_modes` calls "track") or, with ``exclude``, when its name, group or
    a prefix is listed; the names are only worked out when something is excluded (the rows need the mask alone)."""
    if isinstance(exclude, str):  # a bare string would be read letter by letter
        raise ValueError(f"exclude: a list of mode names, groups or prefixes, got the string {exclude!r}; "
                         f"write [{exclude!r}]")
    groups, main = getattr(family, "groups", None), getattr(family, "main_body", None)
    track: np.ndarray | None = None
    for S in forward_speeds(speeds):
        system = family.at(p, speed=float(S))
        if track is None:
            track = np.array([_track_body(_body_dof(c)[0]) for c in system.names], dtype=bool)
        m = system.modal()
        idx = mode_order(m.s)[1::2]
        roots = m.s[idx]
        shares = _shares(system, m.V[:system.n, idx])
        keep = (np.abs(roots) > NEUTRAL_ROOT * float(np.max(np.abs(m.s)))) & (shares[track].sum(axis=0) <= 0.5)
        named = named_modes(system, groups, main) if exclude else []
        for j in np.flatnonzero(keep) if exclude else ():
            name, group = named[j].name, named[j].group
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

    def __init__(self, family: ParametricSystem, p: Sequence[float] | None, speeds: Sequence[float],
                 exclude: Sequence[str] = ()) -> None:
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


def root_constraints(family: ParametricSystem, p: Sequence[float] | None, speeds: Sequence[float],
                     sigma_min: float = 0.0, exclude: Sequence[str] = (),
                     wrt: Sequence[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
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


def damping_constraints(family: ParametricSystem, p: Sequence[float] | None, speeds: Sequence[float], zeta_min: float,
                        exclude: Sequence[str] = (), wrt: Sequence[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Rows ``g = ζ_min − ζ_j(p, S_k) ≤ 0``: every vehicle mode at least ``ζ_min`` damped at every speed (SPEC §2.5).

    Conventions as :func:`root_constraints` (excluded rows −1); ζ = −Re s/|s| with
    dζ/dp from the root derivatives.  Returns ``(g (K·n,), dg/dp (K·n, P))``.
    """
    rows = StabilityRows(family, p, speeds, exclude)
    return rows.damping(zeta_min), rows.damping_jacobian(wrt)
