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
all outputs at once).  Where free rigid-body roots make Z(Ω) singular to rounding (a band from 0 Hz: below
:class:`~railopt.models.response_maxima.ZeroZone`'s step), H and ∂H/∂p are the same limit model the values use:
the quadratic through the partials at ε, 2ε and 4ε, so the derivative is that of the value reported at Ω → 0.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from railopt.models.modal import NEUTRAL_ROOT, mode_order
from railopt.models.response_maxima import ResponseMaxima, ZeroZone, all_response_maxima, zero_zone
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
    block row of G moves).  Roots in the order of ``system.modal().s``.  One member of
    :func:`stacked_eigenvalue_derivatives` (a stack of one).
    """
    m = system.modal()
    AB = np.linalg.solve(system.M, np.hstack([system.K, system.C]))  # [M⁻¹K, M⁻¹C]
    W = left_eigenvectors(system)
    return stacked_eigenvalue_derivatives(system.M, AB[None], m.V[None], W[None], dM, dC, dK)[0]


def stacked_eigenvalue_derivatives(M: np.ndarray, AB: np.ndarray, V: np.ndarray, W: np.ndarray, dM: np.ndarray,
                                   dC: np.ndarray, dK: np.ndarray) -> np.ndarray:
    """``ds_k/dθ`` (S, 2n, Q) of every root of S state matrices at once (one member per speed of a family).

    ``G_s = [[0, I], [−AB_s]]`` (4.53) with ``AB_s = M⁻¹[K, C_s]`` (S, n, 2n); ``M`` (n, n), shared by the stack;
    ``V`` (S, 2n, 2n) the right eigenvectors (columns) and ``W`` (S, 2n, 2n) the left ones (rows, ``W V = I``:
    :func:`stacked_left_eigenvectors`); ``(dM, dC, dK)`` (Q, n, n) each, the same perturbations for every member.
    First order: ``ds_k = W_k dG V_k / (W_k V_k)`` with ``W_k V_k = 1`` and
    ``dG_s = −[0; M⁻¹(dK − dM AB_K), M⁻¹(dC − dM AB_C,s)]`` (thesis (4.53)–(4.58); only the lower block row of G
    moves).  Every column is computed alone, so the columns of a subset of the perturbations are those of the whole
    set, bit for bit.  Roots in the order of each member's eigen-decomposition.
    """
    n = M.shape[0]
    rates = np.concatenate([dK, dC], axis=2)  # (Q, n, 2n)
    if np.any(dM):  # (S, Q, n, 2n): a mass perturbation moves both blocks through AB
        rates = rates - np.asarray(dM)[None] @ AB[:, None]
    dAB = -np.linalg.solve(M, rates)  # (Q, n, 2n) or (S, Q, n, 2n)
    T = dAB @ V[:, None]  # (S, Q, n, 2n): the lower block rows of dG V
    # ds[s, k, q] = Σ_j W[s, k, n + j] T[s, q, j, k], each row summed alone over j (a C-ordered product)
    product = np.multiply(W[:, None, :, n:], np.swapaxes(T, -1, -2), order="C")  # (S, Q, 2n, n)
    return np.swapaxes(product.sum(axis=-1), -1, -2)


LEFT_CONDITION = 1e6  # cond₁(V) above which the left eigenvectors come from eig(Gᵀ), not from W = V⁻¹


def left_eigenvectors(system: LinearSystem) -> np.ndarray:
    """Left eigenvectors (rows, (2n, 2n)) of the state matrix G, biorthogonal to the right ones (``W V = I`` within
    each cluster of equal roots), roots in the order of ``system.modal().s``.

    ``W = V⁻¹`` when V is well conditioned (cond₁(V) ≤ :data:`LEFT_CONDITION`).  A defective root — the double
    root s = 0 of free rigid-body motion, a flutter coalescence — makes V nearly singular, and the rounding of V⁻¹
    then spoils the rows of every root, the simple ones too.  There the left vectors are the eigenvectors of Gᵀ (a
    second eigen-decomposition), each root matched to its nearest unused root of Gᵀ, and normalised cluster by
    cluster (roots within 1e-8·max|s| of each other): accurate for every simple root; a
    defective cluster's rows are as ill-determined as its derivatives (inf or NaN where exactly singular).
    """
    m = system.modal()
    if m.condition <= LEFT_CONDITION:
        return m.W
    return _transposed_left(system.state_matrix(), m.s, m.V)


def stacked_left_eigenvectors(G: np.ndarray, s: np.ndarray, V: np.ndarray) -> np.ndarray:
    """:func:`left_eigenvectors` of S state matrices at once: ``G`` (S, N, N), their roots ``s`` (S, N) and right
    eigenvectors ``V`` (S, N, N) → the left ones (S, N, N), rows, ``W V = I``.

    ``W = V⁻¹`` by one stacked solve; a member with cond₁(V) = ‖V‖₁‖V⁻¹‖₁ above :data:`LEFT_CONDITION` (or a V
    singular to working precision) gets its rows from eig(Gᵀ) as :func:`left_eigenvectors` does.
    """
    eye = np.eye(V.shape[-1])
    try:
        W = np.linalg.solve(V, eye)
    except np.linalg.LinAlgError:  # one member exactly singular: solve them one by one, the singular ones NaN
        W = np.full(V.shape, np.nan, dtype=complex)
        for k in range(len(V)):
            try:
                W[k] = np.linalg.solve(V[k], eye)
            except np.linalg.LinAlgError:
                pass
    with np.errstate(over="ignore", invalid="ignore"):  # an overflowing or NaN product: the eig(Gᵀ) rows below
        condition = np.linalg.norm(V, 1, axis=(-2, -1)) * np.linalg.norm(W, 1, axis=(-2, -1))
    for k in np.flatnonzero(~(condition <= LEFT_CONDITION)):
        W[k] = _transposed_left(G[k], s[k], V[k])
    return W


def _transposed_left(G: np.ndarray, s: np.ndarray, V: np.ndarray) -> np.ndarray:
    """The left eigenvectors of one G from eig(Gᵀ), matched root by root and normalised cluster by cluster (see
    :func:`left_eigenvectors`)."""
    s_left, U = np.linalg.eig(G.T)
    distance = np.abs(s[:, None] - s_left[None, :])
    match = np.empty(len(s), dtype=np.intp)
    free = np.ones(len(s_left), dtype=bool)
    for k in np.argsort(np.min(distance, axis=1)):  # each root its nearest unused root of Gᵀ, closest pairs first
        j = int(np.argmin(np.where(free, distance[k], np.inf)))
        match[k], free[j] = j, False
    W = U[:, match].T
    right = mode_order(s)
    sorted_s = s[right]
    tol = 1e-8 * float(np.max(np.abs(s), initial=0.0))
    cuts = np.flatnonzero(np.abs(np.diff(sorted_s)) > tol) + 1
    for cluster in np.split(right, cuts):
        Y, X = W[cluster], V[:, cluster]
        try:
            with np.errstate(all="ignore"):
                W[cluster] = np.linalg.solve(Y @ X, Y)
        except np.linalg.LinAlgError:  # an exactly defective cluster: no derivative exists
            W[cluster] = np.nan
    return W


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


def _partials_at(system: LinearSystem, omega: float, cols: list[int], zone: ZeroZone | None,
                 hi: float) -> tuple[np.ndarray, ...]:
    """:func:`_partials`, or where Z(Ω) is singular to rounding (free rigid-body roots near 0, inside ``zone``) or
    exactly singular, the limit model: the quadratic through the partials at three frequencies above Ω (the
    zone's ε, 2ε, 4ε; or Ω + (1, 2, 4)·1e-7·hi), evaluated at Ω."""
    if zone is not None and omega < zone.step:
        nodes, weights = zone.nodes, zone.weights(omega)
    else:
        try:
            return _partials(system, omega, cols)
        except np.linalg.LinAlgError:  # a finite value at a singular Z: its limit from above
            nodes = omega + 1e-7 * hi * np.array([1.0, 2.0, 4.0])
            weights = ZeroZone(1e-7 * hi).weights(0.0)
    parts = [_partials(system, float(w), cols) for w in nodes]
    return tuple(sum(c * part[k] for c, part in zip(weights, parts, strict=True)) for k in range(3))


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
    modes = system.mode_roots()
    neutral = np.abs(modes) <= NEUTRAL_ROOT * float(np.max(np.abs(system.eigenvalues()), initial=0.0))
    inside = (wd > lo) & (wd < hi) & ~neutral  # rigid-body roots (s ≈ 0) do not move a frequency of the maxima
    zone = zero_zone(system, hi)
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
            H, dH, dHw = _partials_at(system, float(omega), [col], zone, hi)
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
    "LEFT_CONDITION", "damped_frequency_jacobian", "damping_ratio_jacobian", "eigenvalue_derivatives",
    "left_eigenvectors", "maxima_jacobians", "response_maxima_jacobian", "root_jacobian", "root_speed_derivative",
    "stacked_eigenvalue_derivatives", "stacked_left_eigenvectors",
]
