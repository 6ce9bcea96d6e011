"""The frequency response as a sum over poles: O(n) per frequency after one eigen-decomposition.

With the state ``y = [x, ẋ]`` and ``G = V diag(s) W`` (W = V⁻¹, thesis eq. 4.53–4.58), the steady
state of ``M ẍ + C ẋ + K x = F(Ω) e^{iΩt}`` is

    X(Ω) = V_x diag(1 / (iΩ − s_k)) W_v M⁻¹ F(Ω),

where ``V_x`` are the displacement rows of V and ``W_v`` the velocity columns of W.  For an output
row c, differentiated q times, and a forcing ``F(Ω) = Σ_t e^{−iΩτ_t} Σ_j (iΩ)^j A_tj``:

    H(Ω) = (iΩ)^q Σ_t e^{−iΩτ_t} Σ_j (iΩ)^j Σ_k R_ktj / (iΩ − s_k),   R_ktj = (c·V_x[:, k]) (W_v M⁻¹ A_tj)_k.

The residues R are computed once, so sampling H on a dense grid costs O(2n) per frequency and
output instead of an O(n³) solve.  The form loses accuracy as the eigenvector matrix V becomes
ill-conditioned (near-defective, i.e. nearly repeated roots): relative errors grow like
cond(V)·ε.  :data:`CONDITION_LIMIT` bounds cond₁(V) = ‖V‖₁‖W‖₁; beyond it callers fall back to
direct solves.
"""

from __future__ import annotations

import cmath
import math

import numpy as np

from railopt.models.forcing import Forcing
from railopt.models.modal import Modal


class PoleResidue:
    """``H(Ω)`` of several outputs as sums over the poles of G (see the module docstring)."""

    def __init__(self, M: np.ndarray, decomposition: Modal, rows: np.ndarray, orders: np.ndarray,
                 forcing: Forcing, feedthroughs: list[Forcing | None] | None = None) -> None:
        n = M.shape[0]
        self._feedthroughs = list(feedthroughs or [None] * rows.shape[0])
        self.poles = decomposition.s
        self.orders = np.asarray(orders)
        V, W = decomposition.V, decomposition.W
        self._B = np.linalg.solve(M.T, W[:, n:].T).T  # W_v M⁻¹, (2n, n)
        self._Cv = rows @ V[:n]  # (m, 2n)
        poly = [t for t in forcing.terms if t.coefficients is not None]
        self._callables = [t for t in forcing.terms if t.coefficients is None]
        self._delays = np.array([t.delay for t in poly])
        degree = max((t.coefficients.shape[0] for t in poly), default=1)
        # R[k, o, t, j] = Cv[o, k] · (B A_tj)[k]: every term's coefficients stacked, one product
        A = np.zeros((len(poly), degree, n), dtype=complex)
        for ti, t in enumerate(poly):
            A[ti, : t.coefficients.shape[0]] = t.coefficients
        BA = self._B @ A.reshape(len(poly) * degree, n).T  # (2n, T·J)
        self._R = (self._Cv.T[:, :, None] * BA[:, None, :]).reshape(len(self.poles), rows.shape[0], len(poly), degree)

    def scalar_magnitude(self, output: int):
        """A pure-Python ``Ω -> |H_output(Ω)|`` (no numpy call per frequency: a few microseconds for small n),
        or ``None`` when the forcing has callable terms or the output a feedthrough."""
        if self._callables or self._feedthroughs[output] is not None:
            return None
        poles = [complex(p) for p in self.poles]
        k, _, T, J = self._R.shape
        residues = [[[complex(self._R[kk, output, t, j]) for kk in range(k)] for j in range(J)] for t in range(T)]
        delays = [float(d) for d in self._delays]
        q = int(self.orders[output])

        def magnitude(omega: float) -> float:
            iw = 1j * omega
            try:
                inv = [1.0 / (iw - p) for p in poles]
            except ZeroDivisionError:
                return math.inf
            h = 0j
            for t in range(T):
                term, power = 0j, 1.0 + 0j
                for j in range(J):
                    term += power * sum(r * i for r, i in zip(residues[t][j], inv, strict=True))
                    power *= iw
                h += term * cmath.exp(-1j * omega * delays[t]) if delays[t] else term
            value = abs(h * iw**q)
            return value if math.isfinite(value) else math.inf

        return magnitude

    def magnitude_function(self, output: int):
        """A vectorised ``Ω -> |H_output(Ω)|`` (1-D in, 1-D out; inf at a pole) with the residues of one output
        gathered once: the refinement of every cell's maximum calls it once per Brent step."""
        if self._callables or self._feedthroughs[output] is not None or self._R.shape[2] == 0:
            def general(omega: np.ndarray) -> np.ndarray:
                a = np.abs(self.evaluate(omega)[:, output])
                a[~np.isfinite(a)] = np.inf
                return a

            return general
        k, _, T, J = self._R.shape
        R = np.ascontiguousarray(self._R[:, output].reshape(k, T * J))
        poles = self.poles[None, :]
        q = int(self.orders[output])
        delays = self._delays[None, :] if np.any(self._delays != 0.0) else None
        jpow = np.arange(J)[None, :]

        def magnitude(omega: np.ndarray) -> np.ndarray:
            w = np.asarray(omega, dtype=float).ravel()
            iw = 1j * w[:, None]
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                S = (1.0 / (iw - poles)) @ R  # (N, T·J)
                if J > 1:
                    S = np.einsum("ntj,nj->nt", S.reshape(len(w), T, J), iw**jpow)
                h = (S * np.exp(-1j * w[:, None] * delays)).sum(axis=1) if delays is not None else S.sum(axis=1)
                if q:
                    h = h * iw[:, 0] ** q
                a = np.abs(h)
            a[~np.isfinite(a)] = np.inf
            return a

        return magnitude

    def evaluate(self, omega: np.ndarray, outputs: list[int] | None = None) -> np.ndarray:
        """``H`` at frequencies ``omega`` (rad/s, 1-D), shape (len(omega), m); inf at a pole.  ``outputs``: only
        these output columns, in that order (default all)."""
        w = np.asarray(omega, dtype=float).ravel()
        iw = 1j * w
        with np.errstate(divide="ignore", invalid="ignore"):
            P = 1.0 / (iw[:, None] - self.poles[None, :])
        k, m, T, J = self._R.shape
        cols = list(range(m)) if outputs is None else list(outputs)
        R = self._R if outputs is None else self._R[:, cols]
        m = len(cols)
        H = np.zeros((len(w), m), dtype=complex)
        if T:
            S = (P @ R.reshape(k, m * T * J)).reshape(len(w), m, T, J)
            if J > 1:
                S = np.einsum("nmtj,nj->nmt", S, iw[:, None] ** np.arange(J)[None, :])
            else:
                S = S[..., 0]
            if np.any(self._delays != 0.0):
                H += np.einsum("nmt,nt->nm", S, np.exp(-1j * np.outer(w, self._delays)))
            else:
                H += S.sum(axis=2)
        for t in self._callables:
            A = np.array([t.function(float(x)) for x in w], dtype=complex)  # (N, n)
            BA = A @ self._B.T  # (N, 2n)
            H += ((P * BA) @ self._Cv[cols].T) * np.exp(-1j * w * t.delay)[:, None]
        for i, o in enumerate(cols):  # the input's own part of the output: no poles
            d = self._feedthroughs[o]
            if d is not None:
                H[:, i] += d.values(w)[:, 0]
        with np.errstate(invalid="ignore", over="ignore"):
            H *= iw[:, None] ** self.orders[cols][None, :]
        H[~np.isfinite(H)] = np.inf
        return H


__all__ = ["PoleResidue"]
