"""Eigen-decomposition of the state matrix G (thesis eqs. 4.53–4.58) and the one mode ordering.

The 2n roots of ``G`` come as conjugate pairs ``s = μ ± iω_d`` (and real pairs for overdamped
modes).  railopt orders roots in one way everywhere (:func:`mode_order`): **ascending |Im s|, then
ascending Re s**, so each conjugate pair sits side by side and every second entry is one root per
mode in ascending damped natural frequency.  Stability questions (the largest real part) never
rely on an ordering: they use :func:`railopt.models.stability.spectral_abscissa`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from railopt.models.kernels import c_array, eigen_pairs, left_vectors
from railopt.records import ArrayRecord

UNDAMPED_ROOT = 1e-12  # |Re s| / |s| below which a mode counts as undamped (its peak is inf)
NEUTRAL_ROOT = 1e-8  # |s| ≤ NEUTRAL_ROOT · max|s| counts as s = 0 (a free rigid-body motion, not instability)
# A free motion x = a + bt (a body free to drift, undamped: a Jordan block at s = 0) is split by rounding into a
# pair ±δ or ±iδ with δ ≈ √ε·max|s| — measured up to 1.3e-8·max|s| on one CPU, below 1e-8 on another, up to 1.6e-8
# on 3,000 random free chains — so NEUTRAL_ROOT alone judges it by the machine's rounding.  Such a pair within
# DEFECTIVE_ZERO·max|s| whose two roots are each other's negative within PAIR_RTOL·|s| (rounding keeps the
# block's trace) is neutral too (neutral_roots).  The cap is tight on purpose: a genuine slow mode is not hidden
# unless it is this slow, and then only if it is undamped to PAIR_RTOL (see neutral_roots).
DEFECTIVE_ZERO = 1e-7
PAIR_RTOL = 1e-3
CONDITION_LIMIT = 1e8  # cond₁(V) above which the pole–residue form is not used (errors ≳ 1e-8)


@dataclass(frozen=True, eq=False, repr=False)
class Modal(ArrayRecord):
    """Eigen-decomposition of the state matrix G (4.53): roots s (2n,), right eigenvectors V
    (columns) and left ones W = V⁻¹ (rows, so W V = I); ``condition`` = ‖V‖₁‖W‖₁ (inf when V
    is exactly singular; a defective G's eigenvectors are singular only to rounding, which shows as a huge
    condition, far past :data:`CONDITION_LIMIT`).

    W and the condition are worked out when first read (one solve ``V W = I``): the roots and their
    mode shapes (stability rows, root loci) never pay for them; derivatives and the pole–residue form do.
    """

    s: np.ndarray
    V: np.ndarray

    @cached_property
    def _left(self) -> tuple[np.ndarray, float]:
        try:  # the compiled W = V⁻¹ and cond₁(V) (inf when the product overflows)
            W, condition = left_vectors(c_array(self.V, complex))
        except np.linalg.LinAlgError:
            W = np.full(self.V.shape, np.nan, dtype=complex)
            condition = float("inf")
        W.setflags(write=False)
        return W, condition

    def remember_left(self, W: np.ndarray, condition: float) -> None:
        """Keep W = V⁻¹ and cond₁(V) worked out elsewhere (the compiled certified path) for later reads."""
        if "_left" not in self.__dict__:
            W = np.array(W)
            W.setflags(write=False)
            self.__dict__["_left"] = (W, float(condition))

    @property
    def W(self) -> np.ndarray:
        """Left eigenvectors (2n, 2n), rows, W = V⁻¹ (NaN when V is exactly singular)."""
        return self._left[0]

    @property
    def condition(self) -> float:
        """cond₁(V) = ‖V‖₁‖W‖₁ (inf when V is exactly singular or the product overflows)."""
        return self._left[1]


def modal(G: np.ndarray) -> Modal:
    """Roots and right eigenvectors of G (N, N), those of ``np.linalg.eig`` (a real G by the compiled
    :func:`railopt.models.kernels.eigen_pairs`, a complex one by numpy); the left ones (normalised W V = I) when
    first read."""
    if np.iscomplexobj(G):
        return Modal(*np.linalg.eig(G))
    return Modal(*eigen_pairs(c_array(G)))


def mode_order(s: np.ndarray) -> np.ndarray:
    """Order of 2n roots by |Im s| then Re s (ascending); every second entry ([1::2]) is one root per mode.

    Sorting by |Im s| puts each conjugate pair side by side; real (overdamped) roots also pair
    up, each pair counting as one mode with ω_d = 0, so the count is always n, as the clipping
    rule of SPEC §2.4 needs.
    """
    return np.lexsort((s.real, np.abs(s.imag)))


def neutral_roots(s: np.ndarray) -> np.ndarray:
    """Which roots are s = 0 up to rounding (free rigid-body motion), a bool mask of the shape of ``s`` (…, 2n);
    each row of a stack (the last axis) is judged alone.

    Neutral: a simple zero, |s| ≤ NEUTRAL_ROOT·max|s|; or the two roots of a split Jordan block at 0 (an undamped
    free drift x = a + bt, split by rounding to ±δ or ±iδ, δ ≈ √ε·max|s|): two roots, each with |s| ≤
    DEFECTIVE_ZERO·max|s|, whose sum is within PAIR_RTOL·|s| of 0, matched in pairs (the closest to each other's
    negative first).  Not neutral: a lone slow root (a slow divergence), a slow mode damped beyond PAIR_RTOL
    (−a ± iω with 2a > PAIR_RTOL·|s|), and every root beyond DEFECTIVE_ZERO·max|s|.

    Limit: an undamped slow mode or saddle (±iω, ±δ) with |s| ≤ DEFECTIVE_ZERO·max|s| = 1e-7·max|s| cannot be
    told from a split block by its roots alone, and is taken as neutral (a quadruple ±a ± iω that slow pairs
    off the same way).  The structural count (the null spaces of K and C) would settle it; not built.
    """
    s = np.asarray(s)
    if s.size == 0:
        return np.zeros(s.shape, dtype=bool)
    size = np.abs(s)
    scale = np.max(size, axis=-1, keepdims=True)
    neutral = size <= NEUTRAL_ROOT * scale
    near = (size <= DEFECTIVE_ZERO * scale) & ~neutral
    if not near.any():
        return neutral
    flat_s, flat_near, out = s.reshape(-1, s.shape[-1]), near.reshape(-1, s.shape[-1]), neutral.reshape(-1, s.shape[-1])
    for row in np.flatnonzero(flat_near.any(axis=1)):
        free = list(np.flatnonzero(flat_near[row]))
        while len(free) >= 2:  # the pair closest to a negation first
            a, b = min(((a, b) for i, a in enumerate(free) for b in free[i + 1:]),
                       key=lambda ab: abs(flat_s[row, ab[0]] + flat_s[row, ab[1]]))
            if abs(flat_s[row, a] + flat_s[row, b]) > PAIR_RTOL * max(abs(flat_s[row, a]), abs(flat_s[row, b])):
                break
            out[row, a] = out[row, b] = True
            free.remove(a)
            free.remove(b)
    return out.reshape(s.shape)


def growing_roots(s: np.ndarray) -> np.ndarray:
    """The roots with Re s > 0 beyond round-off (Re s > UNDAMPED_ROOT·|s|), neutral roots s ≈ 0
    (:func:`neutral_roots`) excepted: with any of them the system has no steady-state response (thesis (4.59);
    SPEC §2.4)."""
    s = np.asarray(s)
    if s.size == 0:
        return s
    return s[(s.real > UNDAMPED_ROOT * np.abs(s)) & ~neutral_roots(s)]


__all__ = ["CONDITION_LIMIT", "DEFECTIVE_ZERO", "Modal", "NEUTRAL_ROOT", "PAIR_RTOL", "UNDAMPED_ROOT", "growing_roots",
           "modal", "mode_order", "neutral_roots"]
