"""Systems whose M, C, K, F are affine in a parameter vector, with analytic gradients of f_k.

Suspension rates enter the equations of motion linearly, so a model is assembled once as
``M(p) = M0 + Σ p_i M_i`` (likewise C, K and the forcing F(Ω)); a new parameter vector then costs
no re-assembly.  :meth:`ParametricSystem.response_maxima_jacobian` differentiates the response
maxima of (4.71)-(4.73):

- thesis method: ``f_j = |H(Ω_j(p), p)|`` with Ω_j the clipped ω_dj, so
  ``df_j/dp = ∂|H|/∂p + ∂|H|/∂Ω · dω_dj/dp`` (the second term only while ω_dj is inside the band);
  ``dω_dj/dp`` is the eigenvalue derivative ``ds = ψᴴ G_p φ / ψᴴ φ`` of the state matrix (4.53)
  with left/right eigenvectors ψ, φ;
- exact method: f_j is a maximum over Ω, so by the envelope theorem ``df_j/dp = ∂|H|/∂p`` at the
  maximiser (plus the motion of a cell boundary when the maximum sits on one).

``∂H/∂p_i = (iΩ)^q wᵀ(F_i − Z_i X)`` with the adjoint ``Zᵀw = c`` (one extra solve per frequency).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from railopt.models.linear_system import Forcing, ForcingLike, LinearSystem, as_forcing, mode_order
from railopt.models.response_maxima import ResponseMaxima, response_maxima, validate_band


@dataclass(frozen=True)
class ParameterPart:
    """The matrices multiplying one parameter: ``M_i, C_i, K_i`` (n, n) and forcing ``F_i(Ω)``."""

    M: np.ndarray | None = None
    C: np.ndarray | None = None
    K: np.ndarray | None = None
    F: ForcingLike | Forcing | None = None


class ParametricSystem:
    """``M(p) = M0 + Σ p_i M_i`` (and C, K, F alike), one output row, one response kind.

    Parameters
    ----------
    M0, C0, K0 : (n, n) array_like
        Constant parts (SI).
    F0 : (n,) array_like, callable or Forcing
        Constant part of the forcing amplitude.
    output : (n,) array_like
        Output row c.
    parts : mapping name -> ParameterPart
        Parameter-weighted parts, in parameter order.
    response : str
        "displacement", "velocity" or "acceleration".
    names : sequence of str, optional
        Coordinate names.
    """

    def __init__(
        self,
        M0: np.ndarray,
        C0: np.ndarray,
        K0: np.ndarray,
        F0: ForcingLike | Forcing,
        output: np.ndarray,
        parts: Mapping[str, ParameterPart],
        response: str = "displacement",
        names: Sequence[str] | None = None,
    ) -> None:
        self._base = LinearSystem(M0, C0, K0, F0, output, response=response, names=names)
        n = self._base.n
        self.parameters = tuple(parts)
        self._M = np.zeros((len(parts), n, n))
        self._C = np.zeros((len(parts), n, n))
        self._K = np.zeros((len(parts), n, n))
        self._F: list[Forcing | None] = []
        for i, (name, part) in enumerate(parts.items()):
            for attr, store in (("M", self._M), ("C", self._C), ("K", self._K)):
                a = getattr(part, attr)
                if a is not None:
                    a = np.asarray(a, dtype=float)
                    if a.shape != (n, n) or not np.all(np.isfinite(a)):
                        raise ValueError(f"parts[{name!r}].{attr}: must be a finite ({n}, {n}) array")
                    store[i] = a
            self._F.append(None if part.F is None else as_forcing(part.F, n))

    @property
    def n(self) -> int:
        return self._base.n

    def _check(self, p: np.ndarray) -> np.ndarray:
        p = np.asarray(p, dtype=float)
        if p.shape != (len(self.parameters),):
            raise ValueError(f"p: expected {len(self.parameters)} parameters {self.parameters}, got {p.shape}")
        if not np.all(np.isfinite(p)):
            bad = [self.parameters[i] for i in np.flatnonzero(~np.isfinite(p))]
            raise ValueError(f"p: non-finite value for {bad}")
        return p

    def _forcing(self, p: np.ndarray) -> Forcing:
        base = self._base.forcing
        terms = [(pi, f) for pi, f in zip(p, self._F, strict=True) if f is not None and pi != 0.0]
        if not terms:
            return base
        return Forcing(
            value=lambda w: base.value(w) + sum(pi * f.value(w) for pi, f in terms),
            derivative_fn=lambda w: base.derivative(w) + sum(pi * f.derivative(w) for pi, f in terms),
            max_delay=max([base.max_delay] + [f.max_delay for _, f in terms]),
        )

    def at(self, p: Sequence[float]) -> LinearSystem:
        """The :class:`LinearSystem` for parameter vector ``p`` (no re-assembly)."""
        p = self._check(p)
        b = self._base
        n = b.n
        return LinearSystem._trusted(
            b.M + (p @ self._M.reshape(len(p), -1)).reshape(n, n),
            b.C + (p @ self._C.reshape(len(p), -1)).reshape(n, n),
            b.K + (p @ self._K.reshape(len(p), -1)).reshape(n, n),
            self._forcing(p),
            b.output,
            b.response,
            b.names,
        )

    def response_maxima(self, p: Sequence[float], band: tuple[float, float], exact: bool = False) -> ResponseMaxima:
        """f_k(p) of (4.71)-(4.73); see :func:`railopt.models.response_maxima.response_maxima`."""
        return response_maxima(self.at(p), band, exact=exact)

    # ------------------------------------------------------------------ gradients
    def damped_frequency_jacobian(self, p: Sequence[float]) -> np.ndarray:
        """``dω_dj/dp_i`` (n, P), from first-order eigenvalue perturbation of G (4.53)."""
        sys = self.at(p)
        return self._dwd(sys)

    def _dwd(self, sys: LinearSystem) -> np.ndarray:
        s, vl, vr = sys.eigen()
        idx = mode_order(s)[1::2]
        n = sys.n
        AB = sys._minv_kc  # [M⁻¹K, M⁻¹C]
        out = np.zeros((len(idx), len(self.parameters)))
        for i in range(len(self.parameters)):
            # d(M⁻¹K)/dp = M⁻¹(K_p − M_p M⁻¹K), likewise for C
            Gp = np.zeros((2 * n, 2 * n))
            Gp[n:, :] = -np.linalg.solve(sys.M, np.hstack([self._K[i], self._C[i]]) - self._M[i] @ AB)
            for j, k in enumerate(idx):
                if s[k].imag == 0.0:
                    continue  # overdamped: ω_d ≡ 0
                psi, phi = vl[:, k], vr[:, k]
                ds = (psi.conj() @ Gp @ phi) / (psi.conj() @ phi)
                out[j, i] = np.sign(s[k].imag) * ds.imag
        return out

    def _partials(self, sys: LinearSystem, omega: float) -> tuple[complex, np.ndarray, complex]:
        """H, ∂H/∂p (P,), ∂H/∂Ω at one frequency."""
        q = sys.order
        Z = sys.impedance(omega)
        F = np.asarray(sys.forcing.value(omega), dtype=complex)
        lu = sla.lu_factor(Z, check_finite=False)
        X = sla.lu_solve(lu, F, check_finite=False)
        w = sla.lu_solve(lu, sys.output.astype(complex), trans=1, check_finite=False)
        gain = (1j * omega) ** q
        H = gain * (w @ F)
        dH = np.empty(len(self.parameters), dtype=complex)
        for i in range(len(self.parameters)):
            Zi = self._K[i] - omega**2 * self._M[i] + 1j * omega * self._C[i]
            Fi = self._F[i].value(omega) if self._F[i] is not None else 0.0
            dH[i] = gain * (w @ (Fi - Zi @ X))
        dZ = -2 * omega * sys.M + 1j * sys.C
        dgain = q * 1j * (1j * omega) ** (q - 1) if q > 0 else 0.0
        dHw = dgain * (w @ F) + gain * (w @ (sys.forcing.derivative(omega) - dZ @ X))
        return H, dH, dHw

    def response_maxima_jacobian(
        self, p: Sequence[float], band: tuple[float, float], exact: bool = False
    ) -> tuple[ResponseMaxima, np.ndarray]:
        """f_k(p) and their analytic Jacobian ``df_k/dp_i``, shape (n+2, P).

        Entries with f_k = inf (zero damping, singular Z) get a zero gradient row.
        """
        lo, hi = validate_band(band)
        sys = self.at(p)
        rm = response_maxima(sys, (lo, hi), exact=exact)
        n = sys.n
        dwd = self._dwd(sys)
        wd = rm.damped_frequencies
        inside = (wd > lo) & (wd < hi)
        dOmega = np.zeros((n + 2, len(self.parameters)))
        if exact:
            clipped = np.clip(wd, lo, hi)
            bounds = np.concatenate([[lo], 0.5 * (clipped[1:] + clipped[:-1]), [hi]])
            dclip = np.where(inside[:, None], dwd, 0.0)
            dbounds = np.zeros((n + 1, len(self.parameters)))
            dbounds[1:-1] = 0.5 * (dclip[1:] + dclip[:-1])
            for j in range(n):
                for b in (j, j + 1):
                    if abs(rm.frequencies[j] - bounds[b]) <= 1e-9 * max(hi, 1.0):
                        dOmega[j] = dbounds[b]
        else:
            dOmega[:n] = np.where(inside[:, None], dwd, 0.0)
        J = np.zeros((n + 2, len(self.parameters)))
        for k, omega in enumerate(rm.frequencies):
            if not np.isfinite(rm.values[k]) or rm.values[k] == 0.0:
                continue
            H, dH, dHw = self._partials(sys, float(omega))
            J[k] = (np.real(np.conj(H) * dH) + np.real(np.conj(H) * dHw) * dOmega[k]) / abs(H)
        return rm, J
