"""The linear second-order system every railopt model returns.

``M x'' + C x' + K x = F e^{iΩt}`` (thesis eq. 4.62, 4.67) with real, possibly non-symmetric
``M, C, K`` (creep and gravity terms make them so) and a complex forcing amplitude that may depend
on the forcing frequency (base excitation through springs and dampers, axles delayed by their
distance over the speed).  The output is one real row ``c`` applied to the displacement vector,
differentiated ``q`` times in time (``q = 0, 1, 2`` for displacement, velocity, acceleration).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

RESPONSE_ORDER = {"displacement": 0, "velocity": 1, "acceleration": 2}
SINGULAR_PIVOT = 1e-14  # relative LU pivot below which Z(Ω) counts as singular (response = inf)
UNDAMPED_ROOT = 1e-12  # |Re s| / |s| below which a mode counts as undamped (its peak is inf)

ForcingLike = np.ndarray | Sequence[complex] | Callable[[float], np.ndarray]


def _real_square(name: str, a: np.ndarray, n: int | None) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    if a.ndim != 2 or a.shape[0] != a.shape[1]:
        raise ValueError(f"{name}: must be a square 2-D array, got shape {a.shape}")
    if n is not None and a.shape[0] != n:
        raise ValueError(f"{name}: shape {a.shape} does not match M's ({n}, {n})")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: contains NaN or infinite entries")
    return a


@dataclass(frozen=True)
class Forcing:
    """Complex forcing amplitude ``F(Ω)`` (N or N·m per unit input) and its Ω-derivative.

    ``value(omega)`` returns an (n,) complex vector for scalar ``omega`` (rad/s).
    ``derivative(omega)`` returns ``dF/dΩ``; when it is not supplied it is taken by a central
    difference with a relative step of 1e-6 (accurate to ~1e-10 for the smooth polynomial and
    exponential forms that base excitation produces).
    ``max_delay`` (s) bounds the largest time delay inside ``F`` (axle spacing over speed); the
    certified band search uses it to resolve the oscillation ``e^{-iΩτ}``.
    """

    value: Callable[[float], np.ndarray]
    derivative_fn: Callable[[float], np.ndarray] | None = None
    max_delay: float = 0.0

    @classmethod
    def constant(cls, amplitude: np.ndarray) -> Forcing:
        amp = np.asarray(amplitude, dtype=complex)
        zero = np.zeros_like(amp)
        return cls(value=lambda omega: amp, derivative_fn=lambda omega: zero)

    def derivative(self, omega: float) -> np.ndarray:
        if self.derivative_fn is not None:
            return np.asarray(self.derivative_fn(omega), dtype=complex)
        h = 1e-6 * max(abs(omega), 1.0)
        return (np.asarray(self.value(omega + h)) - np.asarray(self.value(omega - h))) / (2 * h)


def as_forcing(F: ForcingLike | Forcing, n: int) -> Forcing:
    """Wrap an (n,) array or a callable ``F(omega) -> (n,)`` as a :class:`Forcing`."""
    if isinstance(F, Forcing):
        forcing = F
    elif callable(F):
        forcing = Forcing(value=F)
    else:
        amp = np.asarray(F, dtype=complex)
        if amp.shape != (n,):
            raise ValueError(f"F: forcing amplitude must have shape ({n},), got {amp.shape}")
        if not np.all(np.isfinite(amp)):
            raise ValueError("F: contains NaN or infinite entries")
        return Forcing.constant(amp)
    probe = np.asarray(forcing.value(1.0))
    if probe.shape != (n,):
        raise ValueError(f"F: F(omega) must return shape ({n},), got {probe.shape}")
    return forcing


def mode_order(s: np.ndarray) -> np.ndarray:
    """Order of 2n roots by |Im s| then Re s; every second entry ([1::2]) is one root per mode.

    Sorting by |Im s| puts each conjugate pair side by side; real (overdamped) roots also pair
    up, each pair counting as one mode with ω_d = 0, so the count is always n, as the clipping
    rule of SPEC §2.4 needs.
    """
    return np.lexsort((s.real, np.abs(s.imag)))


class LinearSystem:
    """A forced linear system ``M x'' + C x' + K x = F(Ω) e^{iΩt}`` with one scalar output.

    Parameters
    ----------
    M, C, K : (n, n) array_like
        Mass, damping and stiffness matrices (SI; need not be symmetric). ``M`` must be nonsingular.
    F : (n,) array_like, callable or Forcing
        Complex forcing amplitude, constant or a function of the forcing frequency Ω (rad/s).
    output : (n,) array_like
        Real row ``c``: the output is ``c · x`` (or its time derivatives).
    response : {"displacement", "velocity", "acceleration"}
        Which time derivative of ``c · x`` the frequency response reports.
    names : sequence of str, optional
        Coordinate names, for tables and error messages.
    """

    def __init__(
        self,
        M: np.ndarray,
        C: np.ndarray,
        K: np.ndarray,
        F: ForcingLike | Forcing,
        output: np.ndarray,
        response: str = "displacement",
        names: Sequence[str] | None = None,
    ) -> None:
        self.M = _real_square("M", M, None)
        n = self.M.shape[0]
        self.C = _real_square("C", C, n)
        self.K = _real_square("K", K, n)
        if response not in RESPONSE_ORDER:
            raise ValueError(f"response: must be one of {sorted(RESPONSE_ORDER)}, got {response!r}")
        self.response = response
        self.order = RESPONSE_ORDER[response]
        out = np.asarray(output, dtype=float)
        if out.shape != (n,):
            raise ValueError(f"output: must have shape ({n},), got {out.shape}")
        if not np.all(np.isfinite(out)):
            raise ValueError("output: contains NaN or infinite entries")
        self.output = out
        self.forcing = as_forcing(F, n)
        self.names = tuple(names) if names is not None else tuple(f"x{i}" for i in range(n))
        if len(self.names) != n:
            raise ValueError(f"names: expected {n} names, got {len(self.names)}")
        self._prepare()

    @classmethod
    def _trusted(cls, M: np.ndarray, C: np.ndarray, K: np.ndarray, forcing: Forcing, output: np.ndarray,
                 response: str, names: tuple[str, ...]) -> LinearSystem:
        """Fast path for parametric updates: inputs already validated (finite, shapes), only M re-checked."""
        self = cls.__new__(cls)
        self.M, self.C, self.K, self.forcing, self.output = M, C, K, forcing, output
        self.response, self.order, self.names = response, RESPONSE_ORDER[response], names
        self._prepare()
        return self

    def _prepare(self) -> None:
        """M⁻¹[K C] for the state matrix (4.53); a singular M is an error naming the field."""
        try:
            self._minv_kc = np.linalg.solve(self.M, np.hstack([self.K, self.C]))
        except np.linalg.LinAlgError as exc:
            raise ValueError("M: is singular (a coordinate without inertia); eliminate it first") from exc
        self._eigvals: np.ndarray | None = None
        self._eig: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    @property
    def n(self) -> int:
        """Number of degrees of freedom."""
        return self.M.shape[0]

    # ------------------------------------------------------------------ eigen-analysis (4.51-4.58)
    def state_matrix(self) -> np.ndarray:
        """State matrix ``G = [[0, I], [-M⁻¹K, -M⁻¹C]]`` of thesis eq. (4.53), shape (2n, 2n)."""
        n = self.n
        G = np.zeros((2 * n, 2 * n))
        G[:n, n:] = np.eye(n)
        G[n:, :] = -self._minv_kc
        return G

    def eigen(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Eigenvalues ``s`` (1/s) of G with left and right eigenvectors, cached (eq. 4.56-4.58)."""
        if self._eig is None:
            s, vl, vr = sla.eig(self.state_matrix(), left=True, right=True, check_finite=False)
            self._eig = (s, vl, vr)
        return self._eig

    def _roots(self) -> np.ndarray:
        """All 2n eigenvalues of G, unsorted, cached (vectors are computed only when asked for)."""
        if self._eigvals is None:
            self._eigvals = self._eig[0] if self._eig is not None else np.linalg.eigvals(self.state_matrix())
        return self._eigvals

    def eigenvalues(self) -> np.ndarray:
        """The 2n roots ``s_j = μ_j ± iω_dj`` of (4.58), sorted by |Im s| then Re s."""
        s = self._roots()
        return s[mode_order(s)]

    def mode_roots(self) -> np.ndarray:
        """One root per mode, n values, in ascending order of ω_d = |Im s| (see :func:`mode_order`)."""
        s = self._roots()
        return s[mode_order(s)[1::2]]

    def undamped_modes(self) -> np.ndarray:
        """Boolean (n,): modes whose root lies on the imaginary axis to rounding (|Re s| ≤ 1e-12 |s|)."""
        s = self.mode_roots()
        return (np.abs(s.real) <= UNDAMPED_ROOT * np.abs(s)) & (s.imag != 0)

    def damped_frequencies(self) -> np.ndarray:
        """Damped natural frequencies ω_dj (rad/s), n values sorted ascending (eq. 4.58)."""
        return np.abs(self.mode_roots().imag)

    def is_stable(self, tol: float = 0.0) -> bool:
        """True when every root has Re s ≤ tol (eq. 4.59)."""
        return bool(np.all(self._roots().real <= tol))

    # ------------------------------------------------------------------ frequency response (4.69)
    def impedance(self, omega: float) -> np.ndarray:
        """``Z(Ω) = K − Ω²M + iΩC`` of thesis eq. (4.69)."""
        return self.K - omega**2 * self.M + 1j * omega * self.C

    def solve(self, omega: float) -> np.ndarray:
        """Complex amplitude ``X = Z⁻¹F`` (eq. 4.70); all-inf when Z is singular."""
        Z = self.impedance(omega)
        F = np.asarray(self.forcing.value(omega), dtype=complex)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", sla.LinAlgWarning)
                lu = sla.lu_factor(Z, check_finite=False)
        except (ValueError, np.linalg.LinAlgError):
            return np.full(self.n, np.inf + 0j)
        pivots = np.abs(np.diag(lu[0]))
        if np.min(pivots) <= SINGULAR_PIVOT * np.max(pivots):
            return np.full(self.n, np.inf + 0j)
        return sla.lu_solve(lu, F, check_finite=False)

    def frf(self, omega: float | np.ndarray) -> complex | np.ndarray:
        """Complex frequency response of the output at Ω (rad/s), scalar or array.

        ``H(Ω) = (iΩ)^q c·Z(Ω)⁻¹F(Ω)`` with q = 0, 1, 2 for displacement, velocity, acceleration.
        A singular Z (an undamped resonance hit exactly) gives ``inf``.
        """
        w = np.asarray(omega, dtype=float)
        if w.ndim == 0:
            return self._frf_scalar(float(w))
        flat = w.ravel()
        Z = (self.K[None] - flat[:, None, None] ** 2 * self.M[None]) + 1j * flat[:, None, None] * self.C[None]
        F = np.array([self.forcing.value(float(x)) for x in flat], dtype=complex)
        try:
            X = np.linalg.solve(Z, F[..., None])[..., 0]
        except np.linalg.LinAlgError:  # a singular Z somewhere: fall back point by point
            return np.array([self._frf_scalar(float(x)) for x in flat]).reshape(w.shape)
        with np.errstate(over="ignore", invalid="ignore"):
            h = (1j * flat) ** self.order * (X @ self.output)
        h[~np.isfinite(h)] = np.inf
        return h.reshape(w.shape)

    def _frf_scalar(self, omega: float) -> complex:
        X = self.solve(omega)
        if not np.all(np.isfinite(X)):
            return complex(np.inf)
        with np.errstate(over="ignore", invalid="ignore"):
            h = complex((1j * omega) ** self.order * (self.output @ X))
        return h if np.isfinite(h) else complex(np.inf)

    def magnitude(self, omega: float | np.ndarray) -> float | np.ndarray:
        """``f(Ω) = |H(Ω)|``: the real-valued transfer function of (4.71)."""
        return np.abs(self.frf(omega))

    # ------------------------------------------------------------------ response maxima (4.71-4.73)
    def response_maxima(self, band: tuple[float, float], exact: bool = False):
        """The n+2 response maxima f_k of (4.71)-(4.73); see :func:`response_maxima`."""
        from railopt.models.response_maxima import response_maxima

        return response_maxima(self, band, exact=exact)

    def peak(self, band: tuple[float, float], exact: bool = True) -> float:
        """``U = max_k f_k`` (4.74) over ``band``; ``exact=True`` gives the certified band maximum."""
        return self.response_maxima(band, exact=exact).value
