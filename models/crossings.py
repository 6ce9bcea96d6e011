"""Every speed where a root of a speed family crosses a stability line, without a speed grid.

A family member's damping is ``C(S) = C0 + C_speed/S`` (creep damping, thesis (4.51)–(4.53)); M and K do not
depend on the forward speed S.  Its state matrix is therefore affine in u = 1/S::

    G(u) = A + u B,   A = [[0, I], [-M⁻¹K, -M⁻¹C0]],   B = [[0, 0], [0, -M⁻¹C_speed]].

A root crosses the line Re s = −σ at s = −σ ± iω only where G + σI has two eigenvalues summing to zero, i.e.
where the bialternate product 2(G + σI)⊙I — the operator X ↦ (G+σI)X + X(G+σI)ᵀ on antisymmetric X, of size
m = N(N−1)/2 with eigenvalues λ_i + λ_j (i < j) — is singular.  With G affine in u this is the generalized
eigenvalue problem of the pencil (2(A+σI)⊙I, 2B⊙I): its real eigenvalues u are every candidate crossing
speed S = 1/u.  A real root crosses −σ where det(G(u) + σI) = 0: the pencil (A + σI, B) of size N.  Sources:
Guckenheimer, Myers & Sturmfels, "Computing Hopf bifurcations I", SIAM J. Numer. Anal. 34 (1997);
Govaerts, "Numerical Methods for Bifurcations of Dynamical Equilibria", SIAM (2000), §4.4 (bialternate product).

Roots that do not move with the speed — the neutral rigid-body roots s = 0 of a free vehicle, and any mode the
creep never reaches — would make these pencils singular (a pair that sums to zero at every speed).  They live in
the largest A-invariant subspace inside ker B (the unobservable subspace of the pair (B, A)), which G(u) maps
into itself for every u; the pencils are formed on its orthogonal complement, and the constant roots are
returned apart.  The candidates are a superset: a real pair ±a also sums to zero; the caller keeps the sign of
the margin between consecutive candidates (:mod:`railopt.models.stability_map`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from railopt.models.system import LinearSystem
from railopt.records import ArrayRecord

RANK_RTOL = 1e-10  # singular values below this fraction of the largest count as zero (kernel and invariance)
REAL_RTOL = 1e-6  # |Im u| ≤ REAL_RTOL·|u|: a pencil eigenvalue taken as real (a superset is harmless)
SPEED_SLACK = 1e-6  # candidates this fraction outside the speed range are kept (rounding of 1/u)


@dataclass(frozen=True, eq=False, repr=False)
class SpeedPencil(ArrayRecord):
    """The state matrix of a speed family as G(u) = A + u B, u = 1/S (1/m·s), reduced to its moving part.

    Attributes
    ----------
    A, B : (N, N) ndarray
        G at infinite speed and the coefficient of 1/S, on the speed-dependent subspace (orthonormal basis).
    constant_roots : (k,) ndarray
        The roots that do not move with speed (1/s): neutral rigid-body roots and modes the creep never
        reaches; N + k is the member's 2n.
    """

    A: np.ndarray
    B: np.ndarray
    constant_roots: np.ndarray

    @property
    def size(self) -> int:
        """N, the states of the speed-dependent part."""
        return int(self.A.shape[0])

    @property
    def bialternate_size(self) -> int:
        """m = N(N−1)/2, the size of the bialternate pencil."""
        return self.size * (self.size - 1) // 2


def declares_creep(system: LinearSystem) -> bool:
    """True when ``system`` carries the family's creep term (a tangent with ``dC_dspeed`` at a speed)."""
    t = system.tangent
    return t is not None and t.dC_dspeed is not None and t.speed is not None


def speed_pencil(system: LinearSystem) -> SpeedPencil | None:
    """The pencil of the family ``system`` belongs to, or None when it declares no creep term.

    The structure is read from the member's :class:`~railopt.models.system.Tangent` (``dC_dspeed`` =
    −C_speed/S², declared by :class:`~railopt.models.parametric.ParametricSystem`), never guessed from
    samples: a system built otherwise (a user's ``at(speed=S)``) gives None and is searched by sampling.
    """
    if not declares_creep(system):
        return None
    t = system.tangent
    n, S = system.n, float(t.speed)
    C_speed = t.creep_damping
    C0 = system.C - C_speed / S
    mk = np.linalg.solve(system.M, np.hstack([system.K, C0, C_speed]))
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n], A[n:, n:] = -mk[:, :n], -mk[:, n:2 * n]
    B = np.zeros_like(A)
    B[n:, n:] = -mk[:, 2 * n:]
    Z, constant = _moving_part(A, B)
    return SpeedPencil(Z.T @ A @ Z, Z.T @ B @ Z, constant)


def _moving_part(A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal basis Z of the complement of the largest A-invariant subspace W ⊂ ker B, and the roots on W.

    W = ker B ∩ A⁻¹(ker B) ∩ …, by the subspace iteration W ← {w ∈ W : A w ∈ W}; on W, G(u) w = A w for every
    u, so its roots are constant and W is invariant: in the basis [W, Z], G(u) is block upper-triangular and
    the moving roots are those of Zᵀ G(u) Z.
    """
    N = A.shape[0]
    W = sla.null_space(B, rcond=RANK_RTOL) if np.any(B) else np.eye(N)
    scale = max(float(np.linalg.norm(A, 2)), 1e-300)
    while W.shape[1]:
        image = A @ W
        leak = image - W @ (W.T @ image)  # the part of A W outside W
        if np.linalg.norm(leak, 2) <= RANK_RTOL * scale:
            break
        keep = sla.null_space(leak, rcond=RANK_RTOL * scale / max(np.linalg.norm(leak, 2), 1e-300))
        if keep.shape[1] == W.shape[1]:
            break
        W = sla.orth(W @ keep) if keep.shape[1] else W[:, :0]
    if W.shape[1] == 0:
        return np.eye(N), np.zeros(0, dtype=complex)
    Z = sla.null_space(W.T)
    return Z, np.linalg.eigvals(W.T @ A @ W)


def bialternate(G: np.ndarray) -> np.ndarray:
    """The bialternate product 2G⊙I (m, m), m = N(N−1)/2: X ↦ G X + X Gᵀ on antisymmetric X.

    Basis E_pq = e_p e_qᵀ − e_q e_pᵀ (p > q, in ``numpy.tril_indices(N, -1)`` order); column (r, s) holds the
    coefficients of G E_rs + E_rs Gᵀ, whose (p, q) entry is G_pr δ_qs − G_ps δ_qr + δ_pr G_qs − δ_ps G_qr.
    Eigenvalues λ_i + λ_j (i < j) for the eigenvalues λ of G (Govaerts 2000, §4.4).
    """
    G = np.asarray(G)
    P, Q = np.tril_indices(G.shape[0], -1)
    p, q, r, s = P[:, None], Q[:, None], P[None, :], Q[None, :]
    return G[p, r] * (q == s) - G[p, s] * (q == r) + (p == r) * G[q, s] - (p == s) * G[q, r]


def crossing_speeds(pencil: SpeedPencil, speed_range: tuple[float, float], sigma: float = 0.0) -> np.ndarray:
    """Every candidate speed (m/s, ascending) in ``speed_range`` where a moving root reaches Re s = −σ.

    The real eigenvalues u of the bialternate pencil (complex pairs s = −σ ± iω) and of the state pencil (a
    real root s = −σ), S = 1/u.  A superset: real pairs −σ ± a appear too.  Raises ValueError when a pencil is
    singular (a pair that sums to −2σ at every speed: the constant part was not separated).
    """
    lo, hi = speed_range
    N = pencil.size
    if N == 0:
        return np.zeros(0)
    shifted = pencil.A + sigma * np.eye(N)
    u = np.concatenate([bialternate_values(shifted, pencil.B, 1.0 / math.sqrt(lo * hi)),
                        _pencil_values(shifted, pencil.B)])
    u = u[(u > 0.0)]
    S = np.sort(1.0 / u)
    return S[(S >= lo * (1 - SPEED_SLACK)) & (S <= hi * (1 + SPEED_SLACK))]


def bialternate_factors(B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``L`` (m, rN) and ``R`` (rN, m) with 2B⊙I = L R, r = rank B (B = Ub Vbᵀ).

    On antisymmetric X, B X + X Bᵀ = Z − Zᵀ with Y = Vbᵀ X (r, N) and Z = Ub Y, since X Vb = −(Vbᵀ X)ᵀ: R maps
    the coordinates of X to Y, L maps Y to the coordinates (p > q) of Z − Zᵀ.  The creep term B has the rank of
    C_speed (two per wheelset), so rN is well below m = N(N−1)/2.
    """
    N = B.shape[0]
    U_, sv, Vt = np.linalg.svd(B)
    r = int(np.sum(sv > RANK_RTOL * sv[0])) if sv.size and sv[0] > 0 else 0
    Ub, Vb = U_[:, :r] * sv[:r], Vt[:r].T
    P, Q = np.tril_indices(N, -1)
    c = np.arange(P.size)
    R = np.zeros((r * N, P.size))
    L = np.zeros((P.size, r * N))
    for k in range(r):
        R[k * N + Q, c] += Vb[P, k]
        R[k * N + P, c] -= Vb[Q, k]
        L[c, k * N + Q] += Ub[P, k]
        L[c, k * N + P] -= Ub[Q, k]
    return L, R


def bialternate_values(A: np.ndarray, B: np.ndarray, u0: float) -> np.ndarray:
    """The real finite u with det(2(A + uB)⊙I) = 0, by the low rank of 2B⊙I = L R.

    Shifted at u0 (M0 = 2(A + u0 B)⊙I, nonsingular unless a crossing sits at u0: another shift is tried, then QZ),
    (M0 + (u − u0) L R) v = 0 ⇔ the eigenvalues λ of R M0⁻¹ L (rN × rN) give u = u0 − 1/λ: an LU of size m and an
    eigenproblem of size rN instead of the QZ of size m (the results agree with :func:`_pencil_values`, tested).
    """
    if A.shape[0] < 2:
        return np.zeros(0)
    L, R = bialternate_factors(B)
    if R.shape[0] == 0:
        return np.zeros(0)
    for shift in (u0, 0.7 * u0, 1.9 * u0):
        lu, piv = sla.lu_factor(bialternate(A + shift * B), check_finite=False)
        pivots = np.abs(np.diag(lu))
        if np.min(pivots) > 1e-10 * np.max(pivots):
            lam = np.linalg.eigvals(R @ sla.lu_solve((lu, piv), L, check_finite=False))
            lam = lam[np.abs(lam) > 1e-12 * max(float(np.max(np.abs(lam))), 1e-300)]
            u = shift - 1.0 / lam
            return u[np.abs(u.imag) <= REAL_RTOL * np.abs(u)].real
    return _pencil_values(bialternate(A), bialternate(B))


def _pencil_values(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """The real finite u with det(A + u B) = 0 (QZ on (A, −B), homogeneous form)."""
    if A.shape[0] == 0:
        return np.zeros(0)
    alpha, beta = sla.eig(A, -B, right=False, homogeneous_eigvals=True)
    scale = max(float(np.max(np.abs(alpha))), float(np.max(np.abs(beta))), 1e-300)
    singular = (np.abs(alpha) <= 1e-13 * scale) & (np.abs(beta) <= 1e-13 * scale)
    if np.any(singular):
        raise ValueError("pencil: singular (a pair of roots sums to the line at every speed); cannot certify")
    finite = np.abs(beta) > 1e-13 * scale
    u = alpha[finite] / beta[finite]
    real = np.abs(u.imag) <= REAL_RTOL * np.abs(u)
    return u[real].real


__all__ = ["RANK_RTOL", "REAL_RTOL", "SPEED_SLACK", "SpeedPencil", "bialternate", "bialternate_factors",
           "bialternate_values", "crossing_speeds", "declares_creep", "speed_pencil"]
