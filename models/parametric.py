"""Systems whose M, C, K, F are affine in a parameter vector, with analytic gradients of f_k.

Suspension rates enter the equations of motion linearly, so a model is assembled once as
``M(p) = M0 + Σ p_i M_i`` (likewise C, K and the forcing F(Ω)); a new parameter vector then costs
no re-assembly.  :meth:`ParametricSystem.maxima_jacobians` differentiates the response maxima of
(4.71)-(4.73) of any of the named outputs, sharing one eigen-decomposition:

- thesis method: ``f_j = |H(Ω_j(p), p)|`` with Ω_j the clipped ω_dj, so
  ``df_j/dp = ∂|H|/∂p + ∂|H|/∂Ω · dω_dj/dp`` (the second term only while ω_dj is inside the band);
  ``dω_dj/dp`` is the eigenvalue derivative ``ds_k = W_k G_p V_k`` of the state matrix (4.53)
  with the left (rows of W = V⁻¹) and right (columns of V) eigenvectors;
- exact method: f_j is a maximum over Ω, so by the envelope theorem ``df_j/dp = ∂|H|/∂p`` at the
  maximiser (plus the motion of a cell boundary when the maximum sits on one).

``∂H/∂p_i = (iΩ)^q wᵀ(F_i − Z_i X)`` with the adjoint ``Zᵀw = c`` (one extra solve per frequency,
all outputs at once).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from railopt.models.forcing import Forcing, ForcingLike, as_forcing
from railopt.models.linear_system import LinearSystem, mode_order
from railopt.models.response_maxima import ResponseMaxima, all_response_maxima, validate_band
from railopt.models.validation import real_array


@dataclass(frozen=True)
class ParameterPart:
    """The matrices multiplying one parameter: ``M_i, C_i, K_i`` (n, n) and forcing ``F_i(Ω)``."""

    M: np.ndarray | None = None
    C: np.ndarray | None = None
    K: np.ndarray | None = None
    F: ForcingLike | None = None


class ParametricSystem:
    """``M(p) = M0 + Σ p_i M_i`` (and C, K, F alike) with named outputs.

    Parameters
    ----------
    M0, C0, K0 : (n, n) array_like
        Constant parts (SI).
    F0 : (n,) array_like, callable or Forcing
        Constant part of the forcing amplitude.
    output : (n,) array_like, optional
        One output row c (with ``response``); or give ``outputs``.
    parts : mapping name -> ParameterPart
        Parameter-weighted parts, in parameter order.
    response : str
        "displacement", "velocity" or "acceleration" (of ``output``).
    names : sequence of str, optional
        Coordinate names.
    outputs : mapping name -> row, (row, quantity) or Output, optional
        Several named outputs sharing every eigen-decomposition.
    """

    def __init__(
        self,
        M0: np.ndarray,
        C0: np.ndarray,
        K0: np.ndarray,
        F0: ForcingLike,
        output: np.ndarray | None = None,
        parts: Mapping[str, ParameterPart] | None = None,
        response: str = "displacement",
        names: Sequence[str] | None = None,
        outputs: Mapping[str, object] | None = None,
    ) -> None:
        self._base = LinearSystem(M0, C0, K0, F0, output, response=response, names=names, outputs=outputs)
        parts = dict(parts or {})
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
                    store[i] = real_array(f"parts[{name!r}].{attr}", a, shape=(n, n))
            self._F.append(None if part.F is None else as_forcing(part.F, n, f"parts[{name!r}].F"))

    @property
    def n(self) -> int:
        return self._base.n

    @property
    def output_names(self) -> tuple[str, ...]:
        return self._base.output_names

    @property
    def names(self) -> tuple[str, ...]:
        return self._base.names

    def __repr__(self) -> str:
        return (f"ParametricSystem(n={self.n}, parameters={list(self.parameters)}, "
                f"outputs={list(self.output_names)})")

    def _check(self, p: Sequence[float]) -> np.ndarray:
        p = np.asarray(p)
        if p.shape != (len(self.parameters),):
            raise ValueError(f"p: expected {len(self.parameters)} parameters {self.parameters}, got shape {p.shape}")
        if np.iscomplexobj(p):
            raise ValueError("p: parameters must be real")
        p = p.astype(float)
        if not np.all(np.isfinite(p)):
            bad = [self.parameters[i] for i in np.flatnonzero(~np.isfinite(p))]
            raise ValueError(f"p: non-finite value for {bad}")
        return p

    def _forcing(self, p: np.ndarray) -> Forcing:
        terms = [(pi, f) for pi, f in zip(p, self._F, strict=True) if f is not None and pi != 0.0]
        if not terms:
            return self._base.forcing
        return Forcing.combine([(1.0, self._base.forcing), *terms])

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
            b.outputs,
            b.names,
        )

    def response_maxima(self, p: Sequence[float], band: tuple[float, float], exact: bool = False,
                        output: str | None = None) -> ResponseMaxima:
        """f_k(p) of (4.71)-(4.73); see :func:`railopt.models.response_maxima.response_maxima`."""
        return self.at(p).response_maxima(band, exact=exact, output=output)

    # ------------------------------------------------------------------ gradients
    def damped_frequency_jacobian(self, p: Sequence[float]) -> np.ndarray:
        """``dω_dj/dp_i`` (n, P), from first-order eigenvalue perturbation of G (4.53)."""
        return self._dwd(self.at(p))

    def _dwd(self, sys: LinearSystem) -> np.ndarray:
        m = sys.modal()
        idx = mode_order(m.s)[1::2]
        n = sys.n
        AB = np.linalg.solve(sys.M, np.hstack([sys.K, sys.C]))  # [M⁻¹K, M⁻¹C]
        out = np.zeros((len(idx), len(self.parameters)))
        for i in range(len(self.parameters)):
            # d(M⁻¹K)/dp = M⁻¹(K_p − M_p M⁻¹K), likewise for C; only the lower block row of G moves
            dAB = -np.linalg.solve(sys.M, np.hstack([self._K[i], self._C[i]]) - self._M[i] @ AB)
            ds = np.einsum("kj,jk->k", m.W[idx][:, n:], dAB @ m.V[:, idx])
            out[:, i] = np.where(m.s[idx].imag == 0.0, 0.0, np.sign(m.s[idx].imag) * ds.imag)
        return out

    def _partials(self, sys: LinearSystem, omega: float, cols: list[int]) -> tuple[np.ndarray, ...]:
        """H (m,), ∂H/∂p (m, P), ∂H/∂Ω (m,) at one frequency for the output columns ``cols``."""
        outs = [list(sys.outputs.values())[c] for c in cols]
        rows = np.array([o.row for o in outs], dtype=complex)
        q = np.array([o.order for o in outs])
        Z = sys.impedance(omega)
        F = sys.forcing_at(omega)
        X = np.linalg.solve(Z, F)
        w = np.linalg.solve(Z.T, rows.T).T  # (m, n) adjoints: Zᵀ w = c
        gain = (1j * omega) ** q
        d = np.array([o.feedthrough.value(omega)[0] if o.feedthrough is not None else 0.0 for o in outs])
        dd = np.array([o.feedthrough.derivative(omega)[0] if o.feedthrough is not None else 0.0 for o in outs])
        H = gain * (w @ F + d)
        rhs = np.zeros((self.n, len(self.parameters)), dtype=complex)
        for i in range(len(self.parameters)):
            Zi = self._K[i] - omega**2 * self._M[i] + 1j * omega * self._C[i]
            Fi = self._F[i].value(omega) if self._F[i] is not None else 0.0
            rhs[:, i] = Fi - Zi @ X
        dH = gain[:, None] * (w @ rhs)
        dZ = -2 * omega * sys.M + 1j * sys.C
        dgain = np.where(q > 0, q * 1j * (1j * omega) ** np.maximum(q - 1, 0), 0.0)
        dHw = dgain * (w @ F + d) + gain * (w @ (sys.forcing.derivative(omega) - dZ @ X) + dd)
        return H, dH, dHw

    def maxima_jacobians(self, sys: LinearSystem, band: tuple[float, float], exact: bool = False,
                         outputs: Sequence[str] | None = None) -> dict[str, tuple[ResponseMaxima, np.ndarray]]:
        """f_k and their analytic Jacobians ``df_k/dp_i`` (n+2, P) for several outputs of
        ``sys = self.at(p)``, sharing its eigen-decomposition.  Entries with f_k = inf (zero
        damping, singular Z) get a zero gradient row."""
        lo, hi = validate_band(band)
        names = list(sys.output_names if outputs is None else outputs)
        maxima = all_response_maxima(sys, (lo, hi), exact=exact, outputs=names)
        n = sys.n
        dwd = self._dwd(sys)
        wd = sys.damped_frequencies()
        inside = (wd > lo) & (wd < hi)
        dclip = np.where(inside[:, None], dwd, 0.0)
        result = {}
        for name in names:
            rm = maxima[name]
            col = sys.output_index(name)
            dOmega = np.zeros((n + 2, len(self.parameters)))
            if exact:
                clipped = np.clip(wd, lo, hi)
                bounds = np.concatenate([[lo], 0.5 * (clipped[1:] + clipped[:-1]), [hi]])
                dbounds = np.zeros((n + 1, len(self.parameters)))
                dbounds[1:-1] = 0.5 * (dclip[1:] + dclip[:-1])
                for j in range(n):
                    for b in (j, j + 1):
                        if abs(rm.frequencies[j] - bounds[b]) <= 1e-9 * max(hi, 1.0):
                            dOmega[j] = dbounds[b]
            else:
                dOmega[:n] = dclip
            J = np.zeros((n + 2, len(self.parameters)))
            for k, omega in enumerate(rm.frequencies):
                if not np.isfinite(rm.values[k]) or rm.values[k] == 0.0:
                    continue
                H, dH, dHw = self._partials(sys, float(omega), [col])
                J[k] = (np.real(np.conj(H[0]) * dH[0]) + np.real(np.conj(H[0]) * dHw[0]) * dOmega[k]) / abs(H[0])
            result[name] = (rm, J)
        return result

    def response_maxima_jacobian(
        self, p: Sequence[float], band: tuple[float, float], exact: bool = False, output: str | None = None
    ) -> tuple[ResponseMaxima, np.ndarray]:
        """f_k(p) of one output and its analytic Jacobian ``df_k/dp_i``, shape (n+2, P)."""
        sys = self.at(p)
        name = sys.output_names[sys.output_index(output)]
        return self.maxima_jacobians(sys, band, exact=exact, outputs=[name])[name]
