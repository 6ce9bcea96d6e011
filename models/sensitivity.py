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

``∂H/∂p_i = (iΩ)^q wᵀ(F_i − Z_i X)`` with the adjoint ``Zᵀw = c`` (the direct and adjoint solves of every
maximum's frequency, of all outputs, stacked in one call each).  Where free rigid-body roots make Z(Ω) singular to
rounding (a band from 0 Hz: below :class:`~railopt.models.response_maxima.ZeroZone`'s step), H and ∂H/∂p are the
same limit model the values use: the quadratic through the partials at ε, 2ε and 4ε, so the derivative is that of
the value reported at Ω → 0.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from functools import partial

import numpy as np

from railopt.models.forcing import DelayedTerm, Forcing
from railopt.models.modal import mode_order, neutral_roots
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


_TANGENT_FORCINGS: dict[tuple[int, ...], tuple[tuple[Forcing | None, ...], Forcing | None]] = {}


def _tangent_forcing(t: Tangent, n: int) -> Forcing | None:
    """``∂F/∂p_i`` of all P parameters as one :class:`~railopt.models.forcing.Forcing` of P·n components
    (parameter i in components ``i·n … i·n + n − 1``), so ``values(Ω)`` (K, P·n) evaluates every column at every
    frequency in one call; None when F depends on no parameter.  Cached on the identity of the ∂F/∂p_i (a family
    hands every member at one speed the same objects); the cache holds them, so a reused id is never mistaken."""
    key = tuple(id(f) for f in t.dF)
    held = _TANGENT_FORCINGS.get(key)
    if held is not None and all(a is b for a, b in zip(held[0], t.dF, strict=True)):
        return held[1]
    P = len(t.dF)
    blocks: dict[float, np.ndarray] = {}  # delay -> (J, P·n) polynomial coefficients
    others: list[DelayedTerm] = []
    for i, f in enumerate(t.dF):
        for term in (f.terms if f is not None else ()):
            if term.coefficients is None:  # a callable term: its values placed in parameter i's components
                others.append(DelayedTerm(term.delay, function=partial(_embedded, term.function, i, P, n)))
                continue
            c = term.coefficients
            acc = blocks.get(term.delay)
            if acc is None or acc.shape[0] < c.shape[0]:
                grown = np.zeros((c.shape[0], P * n), dtype=complex)
                if acc is not None:
                    grown[: acc.shape[0]] = acc
                acc = blocks[term.delay] = grown
            acc[: c.shape[0], i * n:(i + 1) * n] += c
    terms = [DelayedTerm(d, coefficients=c) for d, c in blocks.items()] + others
    stacked = Forcing(terms=terms) if terms else None
    if len(_TANGENT_FORCINGS) > 64:
        _TANGENT_FORCINGS.clear()
    _TANGENT_FORCINGS[key] = (t.dF, stacked)
    return stacked


def _embedded(function, i: int, P: int, n: int, omega: float) -> np.ndarray:
    """A callable term ``function(Ω)`` (n,) of parameter i placed in components ``i·n … i·n + n − 1`` of P·n."""
    out = np.zeros(P * n, dtype=complex)
    out[i * n:(i + 1) * n] = function(omega)
    return out


def _partials(system: LinearSystem, omega: np.ndarray, cols: np.ndarray,
              slope: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """H (K,), ∂H/∂p (K, P) and ∂H/∂Ω (K,) of output ``cols[k]`` at frequency ``omega[k]``, all K at once.

    One stacked solve ``Z(Ω_k) X_k = F(Ω_k)`` and one stacked adjoint solve ``Z(Ω_k)ᵀ w_k = c_k``; then
    ``∂H/∂p_i = (iΩ)^q w_kᵀ(F_i − Z_i X_k)`` with ``Z_i = K_i − Ω²M_i + iΩC_i``, the parameter contractions
    ``w_kᵀ Z_i X_k`` as one product of the outer products ``w_k X_kᵀ`` (K, n²) with the stacked ``(K_i, M_i, C_i)``
    (n², 3P).  ∂H/∂Ω only where ``slope[k]`` (elsewhere 0: its factor dΩ/dp is 0).  Raises
    ``numpy.linalg.LinAlgError`` if any Z(Ω_k) is exactly singular."""
    t = _tangent(system)
    n, P, K = system.n, len(t.parameters), len(omega)
    outs = list(system.outputs.values())
    rows = np.array([outs[c].row for c in cols], dtype=complex).reshape(K, n)
    q = np.array([outs[c].order for c in cols], dtype=int)
    Z = system.impedance(omega)
    F = system.forcing.values(omega).reshape(K, n)
    if not np.all(np.isfinite(F)):
        bad = omega[~np.all(np.isfinite(F), axis=1)]
        raise ValueError(f"F: the forcing returned a non-finite value at Ω = {bad[0]:g} rad/s")
    X = np.linalg.solve(Z, F[..., None])[..., 0]
    w = np.linalg.solve(np.swapaxes(Z, -1, -2), rows[..., None])[..., 0]  # adjoints: Zᵀ w = c
    d = np.zeros(K, dtype=complex)
    for c in np.unique(cols):  # one call per output with a feedthrough d(Ω)
        if outs[c].feedthrough is not None:
            d[cols == c] = outs[c].feedthrough_values(omega[cols == c])
    gain = (1j * omega) ** q
    wF = np.einsum("kj,kj->k", w, F)
    H = gain * (wF + d)
    outer = (w[:, :, None] * X[:, None, :]).reshape(K, n * n)
    tangents = np.concatenate([t.dK, t.dM, t.dC]).reshape(3 * P, n * n)
    wZX = outer @ tangents.T  # (K, 3P): w_kᵀ K_i X_k, w_kᵀ M_i X_k, w_kᵀ C_i X_k
    rate = -(wZX[:, :P] - omega[:, None] ** 2 * wZX[:, P:2 * P] + 1j * omega[:, None] * wZX[:, 2 * P:])
    dF = _tangent_forcing(t, n)
    if dF is not None:
        rate += np.einsum("kj,kij->ki", w, dF.values(omega).reshape(K, P, n))
    dH = gain[:, None] * rate
    dHw = np.zeros(K, dtype=complex)
    for k in np.flatnonzero(slope):  # dF/dΩ and dd/dΩ are evaluated frequency by frequency (Forcing.derivative)
        o, wk = outs[cols[k]], float(omega[k])
        dd = o.feedthrough.derivative(wk)[0] if o.feedthrough is not None else 0.0
        dZX = (-2 * wk * system.M + 1j * system.C) @ X[k]
        dgain = q[k] * 1j * (1j * wk) ** (q[k] - 1) if q[k] > 0 else 0.0
        dHw[k] = dgain * (wF[k] + d[k]) + gain[k] * (w[k] @ (system.forcing.derivative(wk) - dZX) + dd)
    return H, dH, dHw


def _partials_at(system: LinearSystem, omega: np.ndarray, cols: np.ndarray, slope: np.ndarray,
                 zone: ZeroZone | None, hi: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_partials` at every ``omega[k]``, or where Z(Ω) is singular to rounding (free rigid-body roots near 0,
    inside ``zone``) or exactly singular, the limit model: the quadratic through the partials at three frequencies
    above Ω (the zone's ε, 2ε, 4ε; or Ω + (1, 2, 4)·1e-7·hi), evaluated at Ω.  All frequencies and their nodes in
    one stacked :func:`_partials` (a second one when some Z(Ω_k) is exactly singular)."""
    models = {} if zone is None else {int(k): (zone, 0.0) for k in np.flatnonzero(omega < zone.step)}
    try:
        return _limit_models(system, omega, cols, slope, models)
    except np.linalg.LinAlgError:  # a finite value at a singular Z: its limit from above
        Z = system.impedance(omega)
        singular = np.linalg.slogdet(Z)[0] == 0  # the zero pivot that made the solve fail
        limit = ZeroZone(1e-7 * hi)
        models |= {int(k): (limit, float(omega[k])) for k in np.flatnonzero(singular) if k not in models}
        return _limit_models(system, omega, cols, slope, models)


def _limit_models(system: LinearSystem, omega: np.ndarray, cols: np.ndarray, slope: np.ndarray,
                  models: dict[int, tuple[ZeroZone, float]]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_partials` at ``omega``, except at the frequencies k of ``models`` = {k: (zone, origin)}: there the
    quadratic through the partials at ``origin + zone.nodes`` (Lagrange weights ``zone.weights(Ω_k − origin)``)."""
    K = len(omega)
    direct = np.ones(K, dtype=bool)
    direct[list(models)] = False
    at, weight, owner = [omega[direct]], [np.ones(int(direct.sum()))], [np.flatnonzero(direct)]
    for k, (z, origin) in models.items():
        at.append(origin + z.nodes)
        weight.append(z.weights(float(omega[k]) - origin))
        owner.append(np.full(3, k))
    at, owner = np.concatenate(at), np.concatenate(owner)
    parts = _partials(system, at, cols[owner], slope[owner])
    m = int(direct.sum())
    result = []
    for part in parts:
        out = np.empty((K,) + part.shape[1:], dtype=part.dtype)
        out[direct] = part[:m]
        for j, k in enumerate(models):  # each limit model: its three nodes' weighted sum
            out[k] = np.tensordot(weight[1 + j], part[m + 3 * j:m + 3 * j + 3], axes=1)
        result.append(out)
    return tuple(result)


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
    if not names:
        return {}
    wd = system.damped_frequencies()
    zone = zero_zone(system, hi)
    neutral = neutral_roots(system.eigenvalues())[1::2]  # one per mode, as mode_roots() = eigenvalues()[1::2]
    inside = (wd > lo) & (wd < hi) & ~neutral  # rigid-body roots (s ≈ 0) do not move a maximum's frequency
    dclip = None  # dω_dj/dp of the modes inside the band, computed when a maximum's frequency moves with one

    def moving() -> np.ndarray:
        nonlocal dclip
        if dclip is None:
            dclip = np.where(inside[:, None], damped_frequency_jacobian(system), 0.0)
        return dclip

    clipped = np.clip(wd, lo, hi)
    bounds = np.concatenate([[lo], 0.5 * (clipped[1:] + clipped[:-1]), [hi]])
    tol = 1e-9 * max(hi, 1.0)
    omegas, cols, where, dOmegas = [], [], [], []
    for name in names:
        rm = maxima[name]
        dOmega = np.zeros((n + 2, P))
        if exact:  # a maximum on a cell boundary moves with it (the upper one where it is on both)
            f = np.asarray(rm.frequencies[:n], dtype=float)
            on_hi, on_lo = np.abs(f - bounds[1:]) <= tol, np.abs(f - bounds[:-1]) <= tol
            # a cell boundary moves with its two modes: not at all where neither is inside the band (nor lo, hi)
            movable = inside[1:] | inside[:-1]
            if np.any((on_hi[:-1] | on_lo[1:]) & movable):
                dbounds = np.zeros((n + 1, P))
                dbounds[1:-1] = 0.5 * (moving()[1:] + moving()[:-1])
                dOmega[:n] = np.where(on_hi[:, None], dbounds[1:], np.where(on_lo[:, None], dbounds[:-1], 0.0))
        else:
            dOmega[:n] = moving()
        keep = np.flatnonzero(np.isfinite(rm.values) & (rm.values != 0.0))
        omegas.append(np.asarray(rm.frequencies, dtype=float)[keep])
        cols.append(np.full(len(keep), system.output_index(name)))
        where.append(keep)
        dOmegas.append(dOmega[keep])
    omega, dOmega = np.concatenate(omegas), np.concatenate(dOmegas)
    slope = np.any(dOmega != 0.0, axis=1)
    rows = np.zeros((0, P))
    if len(omega):
        H, dH, dHw = _partials_at(system, omega, np.concatenate(cols), slope, zone, hi)
        rows = (np.real(np.conj(H)[:, None] * dH) + np.real(np.conj(H) * dHw)[:, None] * dOmega) / np.abs(H)[:, None]
    result, start = {}, 0
    for name, keep in zip(names, where, strict=True):
        J = np.zeros((n + 2, P))
        J[keep] = rows[start:start + len(keep)]
        start += len(keep)
        result[name] = (maxima[name], J)
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
