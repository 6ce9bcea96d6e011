"""Analytic sensitivities of a family member: response maxima and damped frequencies (thesis (4.71)–(4.73)).

A :class:`~railopt.models.system.LinearSystem` built by ``family.at(p, speed=S)`` carries its
:class:`~railopt.models.system.Tangent` (∂M/∂p, ∂C/∂p, ∂K/∂p, ∂F/∂p), so every function here takes
the system alone and shares its one eigen-decomposition:

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

import numpy as np

from railopt.models.modal import mode_order
from railopt.models.response_maxima import ResponseMaxima, all_response_maxima
from railopt.models.system import LinearSystem, Tangent
from railopt.models.validation import band_arg


def _tangent(system: LinearSystem) -> Tangent:
    if system.tangent is None:
        raise ValueError("system: carries no parameter derivatives; build it with ParametricSystem.at(p)")
    return system.tangent


def eigenvalue_derivatives(system: LinearSystem, dM: np.ndarray, dC: np.ndarray, dK: np.ndarray) -> np.ndarray:
    """``ds_k/dθ`` (2n, Q) of every root of G (4.53) for Q perturbations ``(dM, dC, dK)`` (Q, n, n) each.

    First-order perturbation with the left/right eigenvectors of the system's decomposition:
    ``ds_k = W_k dG V_k`` with ``dG = −[0; M⁻¹(dK − dM M⁻¹K), M⁻¹(dC − dM M⁻¹C)]`` (only the lower
    block row of G moves).  Roots in the order of ``system.modal().s``.
    """
    m = system.modal()
    n = system.n
    AB = np.linalg.solve(system.M, np.hstack([system.K, system.C]))  # [M⁻¹K, M⁻¹C]
    out = np.zeros((2 * n, len(dK)), dtype=complex)
    for i in range(len(dK)):
        dAB = -np.linalg.solve(system.M, np.hstack([dK[i], dC[i]]) - dM[i] @ AB)
        out[:, i] = np.einsum("kj,jk->k", m.W[:, n:], dAB @ m.V)
    return out


def damped_frequency_jacobian(system: LinearSystem) -> np.ndarray:
    """``dω_dj/dp_i`` (n, P) of a family member, modes in :func:`~railopt.models.modal.mode_order`."""
    t = _tangent(system)
    s = system.modal().s
    idx = mode_order(s)[1::2]
    ds = eigenvalue_derivatives(system, t.dM, t.dC, t.dK)[idx]
    return np.where(s[idx].imag[:, None] == 0.0, 0.0, np.sign(s[idx].imag)[:, None] * ds.imag)


def _partials(system: LinearSystem, omega: float, cols: list[int]) -> tuple[np.ndarray, ...]:
    """H (m,), ∂H/∂p (m, P), ∂H/∂Ω (m,) at one frequency for the output columns ``cols``."""
    t = _tangent(system)
    outs = [list(system.outputs.values())[c] for c in cols]
    rows = np.array([o.row for o in outs], dtype=complex)
    q = np.array([o.order for o in outs])
    Z = system.impedance(omega)
    F = system.forcing_at(omega)
    X = np.linalg.solve(Z, F)
    w = np.linalg.solve(Z.T, rows.T).T  # (m, n) adjoints: Zᵀ w = c
    gain = (1j * omega) ** q
    d = np.array([o.feedthrough.value(omega)[0] if o.feedthrough is not None else 0.0 for o in outs])
    dd = np.array([o.feedthrough.derivative(omega)[0] if o.feedthrough is not None else 0.0 for o in outs])
    H = gain * (w @ F + d)
    P = len(t.parameters)
    rhs = np.zeros((system.n, P), dtype=complex)
    for i in range(P):
        Zi = t.dK[i] - omega**2 * t.dM[i] + 1j * omega * t.dC[i]
        Fi = t.dF[i].value(omega) if t.dF[i] is not None else 0.0
        rhs[:, i] = Fi - Zi @ X
    dH = gain[:, None] * (w @ rhs)
    dZ = -2 * omega * system.M + 1j * system.C
    dgain = np.where(q > 0, q * 1j * (1j * omega) ** np.maximum(q - 1, 0), 0.0)
    dHw = dgain * (w @ F + d) + gain * (w @ (system.forcing.derivative(omega) - dZ @ X) + dd)
    return H, dH, dHw


def maxima_jacobians(system: LinearSystem, band: object = None, *, band_hz: tuple[float, float] | None = None,
                     band_rad_s: tuple[float, float] | None = None, exact: bool = False,
                     outputs: Sequence[str] | None = None, maxima: Mapping[str, ResponseMaxima] | None = None,
                     ) -> dict[str, tuple[ResponseMaxima, np.ndarray]]:
    """f_k and their analytic Jacobians ``df_k/dp_i`` (n+2, P) for several outputs of a family member,
    sharing its eigen-decomposition.  The band as ``band_hz=`` (Hz) or ``band_rad_s=`` (rad/s).  Entries with
    f_k = inf (zero damping, singular Z, no steady state) get a zero gradient row.  ``maxima``: the
    :func:`~railopt.models.response_maxima.all_response_maxima` of these outputs already computed with the same
    band and method (an optimiser asked for the values first), used instead of computing them again."""
    t = _tangent(system)
    lo, hi = band_arg(band, band_hz, band_rad_s)
    names = list(system.output_names if outputs is None else outputs)
    if maxima is None or any(n not in maxima for n in names):
        maxima = all_response_maxima(system, band_rad_s=(lo, hi), exact=exact, outputs=names)
    else:
        for name in names:
            rm = maxima[name]
            if bool(rm.exact) != bool(exact) or tuple(rm.band) != (lo, hi):
                raise ValueError(f"maxima: {name!r} was computed with exact={rm.exact} over {tuple(rm.band)} rad/s, "
                                 f"not exact={exact} over {(lo, hi)}")
    n, P = system.n, len(t.parameters)
    dwd = damped_frequency_jacobian(system)
    wd = system.damped_frequencies()
    inside = (wd > lo) & (wd < hi)
    dclip = np.where(inside[:, None], dwd, 0.0)
    result = {}
    for name in names:
        rm = maxima[name]
        col = system.output_index(name)
        dOmega = np.zeros((n + 2, P))
        if exact:
            clipped = np.clip(wd, lo, hi)
            bounds = np.concatenate([[lo], 0.5 * (clipped[1:] + clipped[:-1]), [hi]])
            dbounds = np.zeros((n + 1, P))
            dbounds[1:-1] = 0.5 * (dclip[1:] + dclip[:-1])
            for j in range(n):
                for b in (j, j + 1):
                    if abs(rm.frequencies[j] - bounds[b]) <= 1e-9 * max(hi, 1.0):
                        dOmega[j] = dbounds[b]
        else:
            dOmega[:n] = dclip
        J = np.zeros((n + 2, P))
        for k, omega in enumerate(rm.frequencies):
            if not np.isfinite(rm.values[k]) or rm.values[k] == 0.0:
                continue
            H, dH, dHw = _partials(system, float(omega), [col])
            J[k] = (np.real(np.conj(H[0]) * dH[0]) + np.real(np.conj(H[0]) * dHw[0]) * dOmega[k]) / abs(H[0])
        result[name] = (rm, J)
    return result


def response_maxima_jacobian(system: LinearSystem, band: object = None, *,
                             band_hz: tuple[float, float] | None = None, band_rad_s: tuple[float, float] | None = None,
                             exact: bool = False, output: str | None = None) -> tuple[ResponseMaxima, np.ndarray]:
    """f_k of one output of a family member and its analytic Jacobian ``df_k/dp_i``, shape (n+2, P)."""
    name = system.output_names[system.output_index(output)]
    return maxima_jacobians(system, band, band_hz=band_hz, band_rad_s=band_rad_s, exact=exact, outputs=[name])[name]


def root_jacobian(system: LinearSystem) -> np.ndarray:
    """``ds_k/dp_i`` (2n, P) of every root of a family member, roots in ``system.modal().s`` order.

    For the quadratic eigenproblem (s²M + sC + K)v = 0 with left vector w this is
    ``ds/dp = −wᴴ(s²M′ + sC′ + K′)v / wᴴ(2sM + C)v`` (SPEC §2.5); computed here as the first-order
    perturbation of G (4.53) with its left and right eigenvectors, which is the same number.
    """
    t = _tangent(system)
    return eigenvalue_derivatives(system, t.dM, t.dC, t.dK)


def root_speed_derivative(system: LinearSystem) -> np.ndarray:
    """``ds_k/dS`` (2n,) of every root of a family member with respect to the forward speed (the creep damping
    C_speed/S), roots in ``system.modal().s`` order."""
    t = _tangent(system)
    if t.dC_dspeed is None:
        raise ValueError("system: its family has no speed term in the damping (C_speed)")
    n = system.n
    zero = np.zeros((1, n, n))
    return eigenvalue_derivatives(system, zero, t.dC_dspeed[None], zero)[:, 0]


def damping_ratio_jacobian(s: np.ndarray, ds: np.ndarray) -> np.ndarray:
    """``dζ/dθ`` of ζ = −Re s/|s| for roots ``s`` (k,) with derivatives ``ds`` (k, Q)."""
    mag = np.abs(s)[:, None]
    dmag = np.real(np.conj(s)[:, None] * ds) / mag
    return -(ds.real * mag - s.real[:, None] * dmag) / mag**2


__all__ = [
    "damped_frequency_jacobian", "damping_ratio_jacobian", "eigenvalue_derivatives", "maxima_jacobians",
    "response_maxima_jacobian", "root_jacobian", "root_speed_derivative",
]
