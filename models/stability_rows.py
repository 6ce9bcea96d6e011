"""Stability as design constraints: one row per mode and speed, values now and derivatives when asked
(SPEC §2.5, thesis eqs. (4.53)–(4.58)).

:class:`StabilityRows` builds a design's state matrices at all speeds as one stack, solves them by one
stacked eigen-decomposition and keeps the roots one per mode (mode order) with the mask of kept (vehicle)
modes; :func:`root_constraints` (``Re s + σ_min ≤ 0``) and :func:`damping_constraints` (``ζ_min − ζ ≤ 0``)
return the rows and their Jacobians at once.  The rows' count is fixed as the design changes (a dropped mode
gets the constant row −1 with a zero gradient).  Mode
names come from :mod:`railopt.models.mode_names`.  This module never imports the vehicle package.
"""

from __future__ import annotations

import operator
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from railopt.models import kernels
from railopt.models.modal import mode_order, neutral_roots
from railopt.models.mode_names import _body_dof, _shares, _track_body, named_modes
from railopt.models.sensitivity import (
    damping_ratio_jacobian,
    stacked_eigenvalue_derivatives,
    stacked_left_eigenvectors,
)
from railopt.models.system import LinearSystem
from railopt.models.validation import forward_speeds, number

if TYPE_CHECKING:
    from railopt.models.parametric import ParametricSystem

__all__ = ["StabilityRows", "damping_constraints", "root_constraints"]


@dataclass(frozen=True)
class _SpeedStack:
    """One design's members at all K speeds, solved by one stacked eigen-decomposition (n coordinates, N = 2n).

    ``member`` is the family's member at the first speed (its M, K, tangent and names serve every speed: only the
    creep damping C_speed/S moves with S); ``AB`` (K, n, N) = M⁻¹[K, C(S_k)]; ``G`` (K, N, N) the state matrices
    (4.53); ``s`` (K, N) and ``V`` (K, N, N) their roots and right eigenvectors; ``idx`` (K, n) one root per mode
    in mode order; ``keep`` (K, n) the kept (vehicle) modes; ``speeds`` (K,) m/s."""

    speeds: np.ndarray
    member: LinearSystem
    AB: np.ndarray
    G: np.ndarray
    s: np.ndarray
    V: np.ndarray
    idx: np.ndarray
    keep: np.ndarray

    @property
    def roots(self) -> np.ndarray:
        """One root per mode (K, n), mode order, 1/s."""
        return np.take_along_axis(self.s, self.idx, axis=1)


def _damping_stack(member: LinearSystem, speeds: np.ndarray) -> np.ndarray:
    """C(S_k) (K, n, n) from the member at S_0 = speeds[0]: ``C(S) = C(S_0) + C_speed (1/S − 1/S_0)`` with
    C_speed = −S_0² ∂C/∂S read from the member's tangent (the family's declared creep term, as
    :func:`~railopt.models.crossings.speed_pencil` reads it); C is the same at every speed without one."""
    t = member.tangent
    if t is None:
        raise ValueError("family: its members carry no parameter derivatives (Tangent); the stability rows need a "
                         "ParametricSystem (a vehicle view's family(), a study's stability family)")
    C_speed = t.creep_damping  # the member is at S_0 = speeds[0]
    if C_speed is None:
        return np.broadcast_to(member.C, (len(speeds), member.n, member.n))
    return member.C + (1.0 / speeds - 1.0 / float(speeds[0]))[:, None, None] * C_speed


def _family_rows(family: ParametricSystem, p: Sequence[float] | None, speeds: Sequence[float],
                 exclude: Sequence[str]) -> _SpeedStack:
    """All speeds of one design at once: the state matrices as a stack, one stacked eigen-decomposition, the roots
    one per mode (mode order) and the mask of the kept (vehicle) modes.

    A mode is dropped when neutral, when lumped track bodies carry most of its energy (what
    :func:`~railopt.models.mode_names.named_modes` calls "track") or, with ``exclude``, when its name, group or
    a prefix is listed; the names are only worked out when something is excluded (the rows need the mask alone),
    from a system of the same M, C(S_k), K (the same state matrix, so the same roots in the same order)."""
    if isinstance(exclude, str):  # a bare string would be read letter by letter
        raise ValueError(f"exclude: a list of mode names, groups or prefixes, got the string {exclude!r}; "
                         f"write [{exclude!r}]")
    speeds = forward_speeds(speeds)
    member = family.at(p, speed=float(speeds[0]))
    n, K = member.n, len(speeds)
    C = _damping_stack(member, speeds)
    AB = np.linalg.solve(member.M, np.concatenate([np.broadcast_to(member.K, C.shape), C], axis=2))
    G = np.array([kernels.state_matrix(kernels.c_array(ab)) for ab in AB])  # M⁻¹[K C(S_k)] → G(S_k), eq. 4.53
    s, V = kernels.stacked_eigen_pairs(G)
    idx = mode_order(s)[:, 1::2]  # mode_order sorts each row of a stack alone
    shapes = np.take_along_axis(V[:, :n, :], idx[:, None, :], axis=2)  # (K, n, n): coordinates × modes
    shares = _shares(member, shapes.transpose(1, 0, 2).reshape(n, K * n)).reshape(n, K, n)  # M shared by all
    track = np.array([_track_body(_body_dof(c)[0]) for c in member.names], dtype=bool)
    keep = ~np.take_along_axis(neutral_roots(s), idx, axis=1) & (shares[track].sum(axis=0) <= 0.5)
    groups, main = getattr(family, "groups", None), getattr(family, "main_body", None)
    for k in range(K) if exclude else ():
        named = named_modes(LinearSystem(member.M, C[k], member.K, names=member.names), groups, main)
        for j in np.flatnonzero(keep[k]):
            name, group = named[j].name, named[j].group
            if any(x == name or x == group or name.startswith(x) for x in exclude):
                keep[k, j] = False
    return _SpeedStack(speeds, member, AB, G, s, V, idx, keep)


class StabilityRows:
    """The stability constraint rows of one design: the members solved once, values now, derivatives when asked.

    ``StabilityRows(family, p, speeds, exclude)`` builds the state matrices of every speed S_k as one stack and
    solves them by one stacked eigen-decomposition, keeping the roots one per mode (mode order) with the kept-mode
    mask (see :func:`root_constraints`).  A derivative-free optimiser reads :meth:`roots` / :meth:`damping` only; a
    gradient method then asks :meth:`roots_jacobian` / :meth:`damping_jacobian`, which reuse the same
    decompositions (the root derivatives ds/dp, thesis eqs. (4.53)–(4.58) with the left eigenvectors, are
    computed for all speeds in one stacked call for each ``wrt`` asked and shared by both kinds of row).

    ``family`` is a ParametricSystem with a speed term (P parameters), ``p`` its parameters (None: its values),
    ``speeds`` (K,) in m/s, ``exclude`` a list of mode names, groups or name prefixes (never a bare string).
    ``wrt`` (the Jacobians' columns): indices into the family's parameters, None for all P.

    Raises
    ------
    ValueError
        No speed, a speed ≤ 0, ``exclude`` given as a string, ``wrt`` not whole numbers in [−P, P), a
        negative ``sigma_min``, a family whose members carry no Tangent (not a ParametricSystem).
    """

    def __init__(self, family: ParametricSystem, p: Sequence[float] | None, speeds: Sequence[float],
                 exclude: Sequence[str] = ()) -> None:
        self._stack = _family_rows(family, p, speeds, exclude)
        self._parameters = len(family.parameters)
        self._W: np.ndarray | None = None
        self._ds: dict[tuple[int, ...] | None, np.ndarray] = {}

    @property
    def mode_roots(self) -> np.ndarray:
        """The roots one per mode at every speed (K, n), complex, 1/s, mode order (dropped modes included)."""
        return self._stack.roots

    @property
    def kept(self) -> np.ndarray:
        """The kept (vehicle) modes at every speed (K, n), bool: False for a neutral, track or excluded mode (its
        rows are the constant −1)."""
        return self._stack.keep.copy()

    def _root_derivatives(self, wrt: Sequence[int] | None) -> np.ndarray:
        """ds/dp (K, n, len(wrt) or P) of the roots one per mode, all speeds in one stacked call."""
        key = _indices("wrt", wrt, self._parameters)
        if key not in self._ds:  # the same indices index the tangent as key the cache
            st = self._stack
            if self._W is None:
                self._W = stacked_left_eigenvectors(st.G, st.s, st.V)
            t = st.member.tangent
            cols = slice(None) if key is None else list(key)
            ds = stacked_eigenvalue_derivatives(st.member.M, st.AB, st.V, self._W, t.dM[cols], t.dC[cols],
                                                t.dK[cols])
            self._ds[key] = np.take_along_axis(ds, st.idx[:, :, None], axis=1)
        return self._ds[key]

    def roots(self, sigma_min: float = 0.0) -> np.ndarray:
        """``g = Re s_j + σ_min`` (K·n,), 1/s; −1 for a dropped mode."""
        sigma_min = number("sigma_min", sigma_min, non_negative=True)
        return np.where(self._stack.keep, self._stack.roots.real + sigma_min, -1.0).ravel()

    def roots_jacobian(self, wrt: Sequence[int] | None = None) -> np.ndarray:
        """``dg/dp`` of :meth:`roots` (K·n, len(wrt) or P), 1/s per unit of each parameter; zero rows for dropped
        modes."""
        ds = self._root_derivatives(wrt)
        K, n, Q = ds.shape
        return np.where(self._stack.keep[:, :, None], ds.real, 0.0).reshape(K * n, Q)

    def damping(self, zeta_min: float) -> np.ndarray:
        """``g = ζ_min − ζ_j`` (K·n,), dimensionless, with ζ = −Re s/|s|; −1 for a dropped mode."""
        zeta_min = number("zeta_min", zeta_min)
        s = self._stack.roots
        with np.errstate(invalid="ignore"):  # a neutral root s = 0 is a dropped row
            return np.where(self._stack.keep, zeta_min + s.real / np.abs(s), -1.0).ravel()

    def damping_jacobian(self, wrt: Sequence[int] | None = None) -> np.ndarray:
        """``dg/dp`` of :meth:`damping` (K·n, len(wrt) or P), per unit of each parameter, from
        dζ/dp = damping_ratio_jacobian(s, ds/dp); zero rows for dropped modes."""
        ds = self._root_derivatives(wrt)
        K, n, Q = ds.shape
        with np.errstate(invalid="ignore", divide="ignore"):  # a neutral root s = 0 is a dropped row
            dzeta = damping_ratio_jacobian(self._stack.roots.ravel(), ds.reshape(K * n, Q))
        return np.where(self._stack.keep.reshape(-1, 1), -dzeta, 0.0)


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
