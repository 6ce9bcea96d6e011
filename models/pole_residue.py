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

import numpy as np

from railopt.models.forcing import Forcing
from railopt.models.kernels import c_array, pole_residue_magnitudes, pole_residue_sums, residues
from railopt.models.modal import Modal


class PoleResidue:
    """``H(Ω)`` of several outputs as sums over the poles of G (see the module docstring)."""

    def __init__(self, M: np.ndarray, decomposition: Modal, rows: np.ndarray, orders: np.ndarray,
                 forcing: Forcing, feedthroughs: list[Forcing | None] | None = None) -> None:
        self._feedthroughs = list(feedthroughs or [None] * rows.shape[0])
        self.poles = np.array(decomposition.s, dtype=complex)  # a writeable C copy: the kernels' one signature
        self.orders = np.asarray(orders)
        V = c_array(decomposition.V, complex)
        self._callables = [t for t in forcing.terms if t.coefficients is None]
        A, self._delays = forcing_arrays(forcing, M.shape[0])
        # R[k, o, t, j] = (c_o·V_x[:, k]) (W_v M⁻¹ A_tj)_k; B = W_v M⁻¹ (2n, n) serves the callable terms
        self._R, self._B = residues(c_array(M), V, c_array(decomposition.W, complex), c_array(rows), A)
        self._Cv = rows @ V[: M.shape[0]]  # (m, 2n)

    def kernel_data(self, output: int) -> tuple | None:
        """``(poles, R, output, delays, q)`` for the compiled |H_output| of
        :func:`railopt.models.kernels.pole_residue_magnitudes` (and the compiled cell search), or ``None`` when
        the forcing has callable terms or the output a feedthrough (those stay in :meth:`evaluate`)."""
        if self._callables or self._feedthroughs[output] is not None or self._R.shape[2] == 0:
            return None
        return self.poles, self._R, int(output), self._delays, int(self.orders[output])

    def magnitude_function(self, output: int):
        """A vectorised ``Ω -> |H_output(Ω)|`` (1-D in, 1-D out; inf at a pole): the compiled pole–residue
        magnitude, or :meth:`evaluate` when the forcing has callable terms or the output a feedthrough."""
        data = self.kernel_data(output)
        if data is None:
            def general(omega: np.ndarray) -> np.ndarray:
                a = np.abs(self.evaluate(omega)[:, output])
                a[~np.isfinite(a)] = np.inf
                return a

            return general
        return lambda omega: pole_residue_magnitudes(_floats(omega), *data)

    def evaluate(self, omega: np.ndarray, outputs: list[int] | None = None) -> np.ndarray:
        """``H`` at frequencies ``omega`` (rad/s, 1-D), shape (len(omega), m); inf at a pole.  ``outputs``: only
        these output columns, in that order (default all).  The pole–residue sums are
        :func:`railopt.models.kernels.pole_residue_sums`; a callable term's residues are formed at each Ω and
        summed by the same kernel."""
        w = _floats(omega)
        k, m, T, J = self._R.shape
        cols = np.arange(m, dtype=np.int64) if outputs is None else np.asarray(outputs, dtype=np.int64).ravel()
        H = pole_residue_sums(w, self.poles, self._R, cols, self._delays)
        for t in self._callables:
            delay = np.array([float(t.delay)])
            for i, x in enumerate(w):
                BA = self._B @ np.asarray(t.function(float(x)), dtype=complex)  # (2n,)
                R = np.ascontiguousarray((self._Cv.T * BA[:, None])[:, :, None, None])  # (2n, m_all, 1, 1)
                H[i] += pole_residue_sums(w[i:i + 1], self.poles, R, cols, delay)[0]
        for i, o in enumerate(cols):  # the input's own part of the output: no poles
            d = self._feedthroughs[o]
            if d is not None:
                H[:, i] += d.values(w)[:, 0]
        with np.errstate(invalid="ignore", over="ignore"):
            H *= (1j * w)[:, None] ** self.orders[cols][None, :]
        H[~np.isfinite(H)] = np.inf
        return H


def forcing_arrays(forcing: Forcing, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The polynomial terms of ``forcing`` stacked for the kernels: A (T, J, n) complex128 with
    ``F(Ω) = Σ_t e^{−iΩ delays[t]} Σ_j (iΩ)^j A[t, j]`` (thesis eqs. 4.63–4.66; callable terms left out), delays (T,)
    in s."""
    poly = [t for t in forcing.terms if t.coefficients is not None]
    delays = np.array([t.delay for t in poly], dtype=float)
    degrees = {t.coefficients.shape[0] for t in poly}
    if len(degrees) == 1:  # every term of one degree (the usual case): one stacking copy
        return np.array([t.coefficients for t in poly], dtype=complex), delays
    A = np.zeros((len(poly), max(degrees, default=1), n), dtype=complex)  # every term's coefficients stacked
    for ti, t in enumerate(poly):
        A[ti, : t.coefficients.shape[0]] = t.coefficients
    return A, delays


def _floats(a: object) -> np.ndarray:
    return c_array(np.ravel(a))


__all__ = ["PoleResidue", "forcing_arrays"]
