"""Creep-force saturation: the Shen–Hedrick–Elkins law (closed form, vectorised, with its Jacobian).

Source: Z.Y. Shen, J.K. Hedrick & J.A. Elkins, "A comparison of alternative creep force models for rail
vehicle dynamic analysis", Proc. 8th IAVSD Symposium, Cambridge MA, 1983, pp. 591–605.  Their heuristic
takes the linear (Kalker) forces *including the spin contribution to the lateral force*, forms the
resultant and saturates it with the cubic of Vermeulen & Johnson (J. Appl. Mech. 31:338, 1964):

    T'_x = −f11 ξ_x,   T'_y = −f22 ξ_y − f23 ξ_sp,   M'_z = −f32 ξ_y − f33 ξ_sp          (creep.py, (4.9))
    F' = √(T'_x² + T'_y²),   r = F'/(μN)
    F  = μN (r − r²/3 + r³/27)  for r ≤ 3,   F = μN  for r > 3
    ε  = F/F' = 1 − r/3 + r²/27 (r ≤ 3),  1/r (r > 3);   ε(0) = 1
    T_x = ε T'_x,   T_y = ε T'_y

The cubic is Vermeulen & Johnson's F/μN = 1 − (1 − r/3)³; dF/dF' = (1 − r/3)² vanishes at r = 3, so force
and slope are continuous there, and the law is monotone in r.  The direction of (T_x, T_y) is that of the
linear forces.

Spin moment.  The saturation law of Shen et al. is stated for the tangential force resultant; what happens
to M_z is a modelling choice of the user of the law.  ``spin_moment="scaled"`` (default) applies the same
factor, M_z = ε M'_z, so the moment saturates with the forces and the Jacobian at zero creep is still the
linear law; ``"linear"`` keeps M_z = M'_z (unsaturated).  (The original paper could not be consulted here to
say which of the two it uses; see ``docs/creep_saturation.md``.)

Sign convention: that of :mod:`railopt.models.contact.creep` — forces on the wheel, T = −f ξ.  Units: ξ_x,
ξ_y dimensionless, ξ_sp in 1/m, N in N, forces in N, moment in N·m.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numba import njit

from railopt.models.contact.creep import CreepCoefficients
from railopt.models.kernels import JIT, c_array
from railopt.models.validation import real_array

SpinMoment = Literal["scaled", "linear"]
SPIN_MOMENT_CHOICES: tuple[str, ...] = ("scaled", "linear")


@dataclass(frozen=True)
class SaturatedCreepForces:
    """Saturated creep forces of one or many contacts (arrays of the broadcast input shape ``S``).

    Attributes
    ----------
    Tx, Ty : numpy.ndarray
        Longitudinal and lateral creep force on the wheel, N, shape ``S``.
    Mz : numpy.ndarray
        Spin moment, N·m, shape ``S``.
    epsilon : numpy.ndarray
        Saturation factor ε = F/F' ∈ (0, 1], shape ``S`` (1 where F' = 0).
    ratio : numpy.ndarray
        r = F'/(μN), the linear resultant over the friction limit, shape ``S``.
    """

    Tx: np.ndarray
    Ty: np.ndarray
    Mz: np.ndarray
    epsilon: np.ndarray
    ratio: np.ndarray


@njit(**JIT)
def she_ratio(r: float) -> float:
    """The cubic of :func:`she_force_ratio` at one r ≥ 0, compiled: the one implementation, which the compiled
    wheel/rail forces (:mod:`railopt.models.vehicle.wheelset_kernel`) call too."""
    if r <= 3.0:
        return r * (1.0 - r / 3.0 + r * r / 27.0)
    return 1.0


@njit(**JIT)
def _she_ratios(r: np.ndarray, out: np.ndarray) -> None:
    for j in range(r.size):
        out[j] = she_ratio(r[j])


def she_force_ratio(r: np.ndarray | float) -> np.ndarray:
    """Saturated resultant over μN as a function of r = F'/(μN) ≥ 0: r − r²/3 + r³/27 (r ≤ 3), else 1.

    Raises
    ------
    ValueError
        A negative r."""
    r = np.asarray(r, dtype=float)
    if np.any(r < 0.0):
        raise ValueError("r: the linear-force ratio F'/(μN) must be >= 0")
    out = np.empty(r.size)
    _she_ratios(c_array(r.reshape(-1)), out)
    return out.reshape(r.shape)


def _epsilon(r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """ε(r) = F/F' and its derivative dε/dr (the cubic's branch for r ≤ 3, 1/r beyond)."""
    inside = r <= 3.0
    safe = np.where(inside, 1.0, r)
    eps = np.where(inside, 1.0 - r / 3.0 + r * r / 27.0, 1.0 / safe)
    deps = np.where(inside, -1.0 / 3.0 + 2.0 * r / 27.0, -1.0 / (safe * safe))
    return eps, deps


def _coefficient_arrays(coefficients: CreepCoefficients | Sequence[CreepCoefficients]) -> tuple[np.ndarray, ...]:
    if isinstance(coefficients, CreepCoefficients):
        c = coefficients
        return tuple(np.float64(v) for v in (c.f11, c.f22, c.f23, c.f32, c.f33))
    items = list(coefficients)
    if not items or not all(isinstance(c, CreepCoefficients) for c in items):
        raise ValueError("coefficients: give a CreepCoefficients or a non-empty sequence of them")
    return tuple(np.array([getattr(c, n) for c in items], dtype=float) for n in ("f11", "f22", "f23", "f32", "f33"))


def _inputs(
    coefficients: CreepCoefficients | Sequence[CreepCoefficients], xi_x: object, xi_y: object, xi_sp: object,
    N: object, mu: object, spin_moment: str,
) -> list[np.ndarray]:
    """Checked inputs broadcast to one shape: f11, f22, f23, f32, f33, ξ_x, ξ_y, ξ_sp, N, μ."""
    if spin_moment not in SPIN_MOMENT_CHOICES:
        raise ValueError(f"spin_moment: unknown {spin_moment!r}; choose one of {', '.join(SPIN_MOMENT_CHOICES)}")
    f11, f22, f23, f32, f33 = _coefficient_arrays(coefficients)
    xx, xy, xs = (real_array(n, v) for n, v in (("xi_x", xi_x), ("xi_y", xi_y), ("xi_sp", xi_sp)))
    NN, mm = real_array("N", N), real_array("mu", mu)
    if np.any(NN <= 0.0):
        raise ValueError("N: normal loads must be > 0 (N)")
    if np.any(mm <= 0.0):
        raise ValueError("mu: friction coefficients must be > 0")
    try:
        arrays = np.broadcast_arrays(f11, f22, f23, f32, f33, xx, xy, xs, NN, mm)
    except ValueError as exc:
        raise ValueError(f"xi_x, xi_y, xi_sp, N, mu, coefficients: shapes do not broadcast ({exc})") from None
    return arrays


def shen_hedrick_elkins(
    coefficients: CreepCoefficients | Sequence[CreepCoefficients],
    xi_x: np.ndarray | float,
    xi_y: np.ndarray | float,
    xi_sp: np.ndarray | float,
    N: np.ndarray | float,
    mu: np.ndarray | float,
    *,
    spin_moment: SpinMoment = "scaled",
) -> SaturatedCreepForces:
    """Saturated creep forces by Shen, Hedrick & Elkins (1983) (module docstring).

    Parameters
    ----------
    coefficients : CreepCoefficients or sequence of K of them
        Linear creep coefficients (per wheel).  A sequence is an array of shape (K,) that broadcasts with
        the other inputs.
    xi_x, xi_y : array_like
        Longitudinal and lateral creepage (dimensionless).
    xi_sp : array_like
        Spin creepage, 1/m.
    N : array_like
        Normal load, N (> 0).
    mu : array_like
        Coefficient of friction (> 0).
    spin_moment : {"scaled", "linear"}
        M_z = ε M'_z (default) or M'_z.

    All array inputs broadcast to one shape ``S``; every output has shape ``S``.

    Returns
    -------
    SaturatedCreepForces
        T_x, T_y (N), M_z (N·m), ε and r.

    Raises
    ------
    ValueError
        Non-finite or complex inputs, N ≤ 0, μ ≤ 0, shapes that do not broadcast, an unknown ``spin_moment``.
    """
    f11, f22, f23, f32, f33, xx, xy, xs, NN, mm = _inputs(coefficients, xi_x, xi_y, xi_sp, N, mu, spin_moment)
    tx, ty = -f11 * xx, -f22 * xy - f23 * xs
    mz = -f32 * xy - f33 * xs
    r = np.hypot(tx, ty) / (mm * NN)
    eps, _ = _epsilon(r)
    mz_out = eps * mz if spin_moment == "scaled" else mz
    return SaturatedCreepForces(eps * tx, eps * ty, mz_out, eps, r)


def shen_hedrick_elkins_jacobian(
    coefficients: CreepCoefficients | Sequence[CreepCoefficients],
    xi_x: np.ndarray | float,
    xi_y: np.ndarray | float,
    xi_sp: np.ndarray | float,
    N: np.ndarray | float,
    mu: np.ndarray | float,
    *,
    spin_moment: SpinMoment = "scaled",
) -> np.ndarray:
    """Analytic Jacobian ∂(T_x, T_y, M_z)/∂(ξ_x, ξ_y, ξ_sp) of :func:`shen_hedrick_elkins`, shape ``S + (3, 3)``.

    With T' = −A ξ (A the 3×3 matrix of (4.9): rows T_x, T_y, M_z) and r = |T'_{x,y}|/(μN):

        ∂T_i/∂ξ_j = −ε A_ij + T'_i ε'(r) ∂r/∂ξ_j,   ∂r/∂ξ_j = −(T'_x A_xj + T'_y A_yj) / (F' μN)

    (for M_z with ``spin_moment="linear"`` the row is −A_zj).  At zero creep T' = 0 and the second term
    vanishes, so the Jacobian is exactly −A: linearising the saturated law at zero gives back the linear
    coefficients (−f11, −f22, −f23, −f32, −f33).  Where F' = 0 but M'_z ≠ 0 (pure spin with f23 = 0) the
    moment is not differentiable (|T'| is a cone); the ε' term is then taken as 0.  Units: N, N·m, N·m².
    """
    f11, f22, f23, f32, f33, xx, xy, xs, NN, mm = _inputs(coefficients, xi_x, xi_y, xi_sp, N, mu, spin_moment)
    zero = np.zeros_like(f11)
    A = np.stack([np.stack([f11, zero, zero], -1), np.stack([zero, f22, f23], -1),
                  np.stack([zero, f32, f33], -1)], -2)  # S + (3, 3)
    xi = np.stack([xx, xy, xs], -1)
    t = -np.einsum("...ij,...j->...i", A, xi)  # T'_x, T'_y, M'_z
    muN = mm * NN
    F = np.hypot(t[..., 0], t[..., 1])
    r = F / muN
    eps, deps = _epsilon(r)
    with np.errstate(invalid="ignore", divide="ignore"):
        dr = -(t[..., 0, None] * A[..., 0, :] + t[..., 1, None] * A[..., 1, :]) / (F * muN)[..., None]
    dr = np.where((F > 0.0)[..., None], dr, 0.0)
    J = -eps[..., None, None] * A + t[..., :, None] * (deps[..., None] * dr)[..., None, :]
    if spin_moment == "linear":
        J[..., 2, :] = -A[..., 2, :]
    return J


__all__ = [
    "SPIN_MOMENT_CHOICES",
    "SaturatedCreepForces",
    "SpinMoment",
    "she_force_ratio",
    "she_ratio",
    "shen_hedrick_elkins",
    "shen_hedrick_elkins_jacobian",
]
