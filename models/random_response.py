"""Stationary random response of a linear vehicle model to random track irregularity.

A :class:`~railopt.models.LinearSystem` built per metre of irregularity (its forcing is ``F(Ω)`` for a
rail input ``1·e^{iΩt}``, axles delayed by ``Forcing.delayed`` so ``|H|`` already contains wheelbase
filtering) running at speed V over a spectrum ``S(Ω)`` (m²/(rad/m), Ω rad/m, one-sided) sees the
one-sided input PSD in time ``S_ω(ω) = S(ω/V)/V`` (m²/(rad/s), ω = VΩ rad/s), so

    RMS² = ∫_{ω₁}^{ω₂} |H(ω)|² S(ω/V)/V dω          (ω in rad/s, one-sided; band ω = 2π·band_hz)

(Newland, *An Introduction to Random Vibrations, Spectral and Wavelet Analysis*, 3rd ed., §7;
Wickens, *Fundamentals of Rail Vehicle Dynamics*, 2003, Ch. 9).  Independent inputs (profile and
alignment, left and right rails taken as uncorrelated) add in power: :func:`rms_combined`.

Two independent methods:

(a) :func:`rms` / :func:`random_response` — adaptive Gauss–Legendre quadrature with error control:
    the band is cut at a logarithmic grid and at every damped natural frequency ω_d ± (1, 3, 10)|Re s|
    (so lightly damped peaks are bracketed), each panel is integrated with 8- and 16-point rules and
    the panels whose |G16 − G8| dominate are bisected until Σ|G16 − G8| ≤ rtol·RMS².  The final rule
    (nodes, weights) is returned with ``|H|²`` and ``S_ω`` at the nodes (:class:`RandomResponse`), so the
    analytic gradient ``∂RMS/∂p = Σ w_k S_ω,k Re(conj(H_k) ∂H_k/∂p) / RMS`` reuses it
    (:func:`rms_gradient`, :func:`rms_and_gradient` for a parametric family).
(b) :func:`rms_state_space` — exact covariance of the rational model over 0 < ω < ∞: the spectrum is
    the output of the shaping filter ``G(s) = 1/((s + Vp₁)(s + Vp₂))`` driven by white noise of
    intensity ``q = π b₀ V³`` (one-sided ``S_ω = q|G|²/π``); every axle path ``T_i = H_i G`` is
    expanded in poles and residues (plant roots from its state matrix, filter poles) and the delays
    enter *exactly* through the lagged covariances ``E[y_i(t−τ_i) y_k(t−τ_k)]`` — no Padé approximant:
    ``σ² = q Σ_ik Σ_jl R_ij R_kl e^{…}/(−(λ_j + λ_l))``, the modal solution of the Lyapunov equation
    with delay lags.  It needs both corners p₁, p₂ > 0 (ERRI B176, FRA cross-level), polynomial axle
    terms with ``T_i`` strictly proper, no output feedthrough, and an asymptotically stable system
    once free rigid-body modes are removed.

Free rigid-body modes (the vertical vehicle models have a free fore-aft motion: roots at s = 0).
(a) never evaluates Ω = 0 (``band_hz[0] > 0`` is required); the free mode is neither forced nor
observed by a vertical irregularity, so ``|H|`` stays finite as ω → 0.  (b) removes it exactly: with
L the left null space of ``[K C]`` (``Lᵀ K = Lᵀ C = 0``) and ``Lᵀ F ≡ 0`` the motion stays in
``{x : Lᵀ M x = 0}``; the model is projected on a basis T of that subspace
(``Tᵀ M T ÿ + Tᵀ C T ẏ + Tᵀ K T y = Tᵀ F``, exact).  A forcing that drives a free mode is an error.

Measured agreement of (a) and (b) (tests/models/test_random_response.py, ERRI B176 spectra, (a) over
1e-9–1e5 Hz of the extrapolated rational model with rtol = 1e-10): relative differences 4e-15–9e-13 for
body accelerations of the Manchester coach (vertical, lateral) and the SD40-2 with six delayed axles
(vertical 40 m/s, lateral 25 m/s), 2–3e-9 for body displacements (the spectrum below 1e-9 Hz).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.linalg as sla

from railopt.models.system import LinearSystem
from railopt.models.units import RAD_PER_HZ as TWO_PI
from railopt.models.validation import number

if TYPE_CHECKING:  # pragma: no cover
    from railopt.models.parametric import ParametricSystem

_GL8 = np.polynomial.legendre.leggauss(8)
_GL16 = np.polynomial.legendre.leggauss(16)
PER_DECADE = 8  # initial panels per decade of the band
MAX_PANELS = 200_000
UNSTABLE_ROOT = 1e-7  # Re s above this × max|s| is an unstable root (free modes sit at ~1e-9 × max|s|)


@dataclass(frozen=True)
class QuadratureRule:
    """Nodes ω_k (rad/s) and weights w_k (rad/s) with ``∫ f dω ≈ Σ w_k f(ω_k)`` over the band."""

    omega: np.ndarray
    weights: np.ndarray

    @property
    def frequencies_hz(self) -> np.ndarray:
        """The nodes in Hz: ``omega / 2π``, shape (n,)."""
        return self.omega / TWO_PI

    def integrate(self, values: np.ndarray) -> float:
        """``Σ w_k values_k`` for values sampled at :attr:`omega`."""
        return float(np.dot(self.weights, values))


@dataclass(frozen=True)
class RandomResponse:
    """Result of :func:`random_response`.

    Attributes
    ----------
    rms : float
        RMS of the output (output units, e.g. m/s² for an acceleration output per metre of irregularity).
    variance : float
        ``rms²``.
    error_estimate : float
        Estimated absolute error of ``variance`` (Σ |G16 − G8| over the panels; pessimistic).
    rule : QuadratureRule
        The final nodes and weights (rad/s).
    gain_squared : (N,) ndarray
        ``|H(ω_k)|²`` at the nodes (output² per m²).
    input_psd : (N,) ndarray
        ``S_ω(ω_k) = S(ω_k/V)/V`` m²/(rad/s).
    output, speed_m_s, band_hz
        What was computed.
    """

    rms: float
    variance: float
    error_estimate: float
    rule: QuadratureRule
    gain_squared: np.ndarray
    input_psd: np.ndarray
    output: str
    speed_m_s: float
    band_hz: tuple[float, float]


# ---------------------------------------------------------------------------------------------- helpers
def _band(band_hz: object) -> tuple[float, float]:
    try:
        lo, hi = (float(x) for x in band_hz)  # type: ignore[union-attr]
    except (TypeError, ValueError) as exc:
        raise ValueError(f"band_hz: must be two frequencies (lo, hi) in Hz, got {band_hz!r}") from exc
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
        raise ValueError(f"band_hz: must satisfy 0 < lo < hi (Hz; Ω = 0 is excluded: free rigid-body modes "
                         f"make Z(0) singular), got ({lo}, {hi})")
    return lo, hi


def _output_name(system: LinearSystem, output: str | None) -> str:
    names = system.output_names
    if output is None:
        return names[0]
    if output not in names:
        raise ValueError(f"output: unknown output {output!r}; outputs are {list(names)}")
    return output


def _check_spectrum_band(spectrum: object, speed: float, band: tuple[float, float]) -> None:
    if not callable(getattr(spectrum, "psd", None)):
        raise ValueError(f"spectrum: must have a .psd(wavenumber_rad_per_m) method, got {type(spectrum).__name__}")
    validity = getattr(spectrum, "validity", None)
    if validity is None:
        return
    lo, hi = (TWO_PI * f / speed for f in band)
    vlo, vhi = validity
    if lo < vlo * (1 - 1e-12) or hi > vhi * (1 + 1e-12):
        raise ValueError(f"band_hz: at {speed:g} m/s the band {band} Hz means Ω = {lo:.6g}–{hi:.6g} rad/m, outside "
                         f"the spectrum's validity [{vlo:.6g}, {vhi:.6g}] rad/m "
                         f"({getattr(spectrum, 'label', 'spectrum')}); narrow the band")


def _input_psd(spectrum: object, omega: np.ndarray, speed: float) -> np.ndarray:
    """``S_ω(ω) = S(ω/V)/V`` m²/(rad/s)."""
    return np.asarray(spectrum.psd(omega / speed), dtype=float) / speed  # type: ignore[attr-defined]


def _breakpoints(system: LinearSystem, w_lo: float, w_hi: float) -> np.ndarray:
    """Panel edges: a log grid plus ω_d ± (0, 1, 3, 10)|Re s| of every mode inside the band."""
    decades = math.log10(w_hi / w_lo)
    pts = [np.geomspace(w_lo, w_hi, max(2, int(math.ceil(PER_DECADE * decades)) + 1))]
    roots = system.eigenvalues()
    for s in roots[roots.imag > 0]:
        wd, mu = float(s.imag), abs(float(s.real))
        pts.append(wd + np.array([-10, -3, -1, 0, 1, 3, 10]) * mu)
    tau = max((t.delay for t in system.forcing.terms), default=0.0)
    if tau > 0:
        # the delays make |H|² oscillate with period ≤ 2π/τ_max: at least 4 panels per period near the modes
        top = min(w_hi, 4.0 * float(np.max(system.damped_frequencies(), initial=0.0)) + 1.0)
        if top > w_lo:
            pts.append(np.arange(w_lo, top, math.pi / (2 * tau)))
    edges = np.unique(np.concatenate(pts))
    edges = edges[(edges > w_lo) & (edges < w_hi)]
    return np.concatenate([[w_lo], edges, [w_hi]])


def _panel_rule(a: np.ndarray, b: np.ndarray, rule: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    x, w = rule
    half = 0.5 * (b - a)
    nodes = (0.5 * (a + b))[:, None] + half[:, None] * x[None, :]
    return nodes, half[:, None] * w[None, :]


def random_response(system: LinearSystem, spectrum: object, speed_m_s: float, band_hz: tuple[float, float],
                    output: str | None = None, rtol: float = 1e-8) -> RandomResponse:
    """RMS response over a frequency band by adaptive quadrature, with the reusable rule (method (a)).

    Parameters
    ----------
    system : LinearSystem
        Forced per metre of irregularity (``Forcing.delayed`` axle terms), any output quantity.
    spectrum : object with ``.psd(Ω) -> m²/(rad/m)``
        E.g. :func:`railopt.models.track.spectra.irregularity_spectrum`; its ``validity`` (rad/m), if it has
        one, must cover the band at this speed.
    speed_m_s : float
        Forward speed V (m/s), > 0.
    band_hz : (float, float)
        Frequency band (Hz), 0 < lo < hi; ω = 2π f.
    output : str, optional
        Output name (default: the system's first output).
    rtol : float
        Relative tolerance on the variance (estimated error Σ|G16 − G8| ≤ rtol·variance).

    Returns
    -------
    RandomResponse

    Raises
    ------
    ValueError
        ``speed_m_s`` not positive; ``band_hz`` malformed or outside the spectrum's validity; ``output``
        unknown; ``rtol`` not in (0, 0.1); an unstable ``system`` (a root with Re s > 1e-7·max|s|);
        ``|H|`` infinite in the band (an undamped resonance hit);
        the tolerance not reached within 200 000 panels.
    """
    V = number("speed_m_s", speed_m_s, positive=True)
    band = _band(band_hz)
    rtol = number("rtol", rtol, positive=True)
    if rtol >= 0.1:
        raise ValueError(f"rtol: must be < 0.1, got {rtol}")
    name = _output_name(system, output)
    _check_spectrum_band(spectrum, V, band)
    col = system.output_names.index(name)
    roots = system.eigenvalues()
    if np.max(roots.real) > UNSTABLE_ROOT * np.max(np.abs(roots)):
        raise ValueError(f"system: unstable at this speed (max Re s = {np.max(roots.real):.3g} 1/s); a stationary "
                         "random response does not exist")
    w_lo, w_hi = TWO_PI * band[0], TWO_PI * band[1]

    def integrand(nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        flat = nodes.ravel()
        h = system.frf_outputs(omega_rad_s=flat)[:, col]
        g2 = (h.real**2 + h.imag**2).reshape(nodes.shape)
        if not np.all(np.isfinite(g2)):
            raise ValueError(f"system: |H| is infinite in the band (an undamped resonance); output {name!r}")
        return g2, _input_psd(spectrum, flat, V).reshape(nodes.shape)

    def evaluate(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, ...]:
        n8, w8 = _panel_rule(a, b, _GL8)
        n16, w16 = _panel_rule(a, b, _GL16)
        g8, s8 = integrand(n8)
        g16, s16 = integrand(n16)
        i16 = np.sum(w16 * g16 * s16, axis=1)
        return a, b, np.abs(i16 - np.sum(w8 * g8 * s8, axis=1)), i16, n16, w16, g16, s16

    edges = _breakpoints(system, w_lo, w_hi)
    pool = evaluate(edges[:-1], edges[1:])  # per panel: a, b, error, value, nodes, weights, |H|², S_ω
    while True:
        err, val = pool[2], pool[3]
        variance, total_err = float(np.sum(val)), float(np.sum(err))
        target = rtol * abs(variance)
        if total_err <= target or variance == 0.0:
            break
        split = err > target / len(err)  # an equal share of the budget per panel (some always exceed it)
        if len(err) + int(np.sum(split)) > MAX_PANELS:
            raise ValueError(f"rtol: {rtol:g} not reached within {MAX_PANELS} panels (estimated error "
                             f"{total_err:.3g} of {variance:.3g}); loosen rtol or narrow band_hz")
        a, b = pool[0][split], pool[1][split]
        mid = 0.5 * (a + b)
        new = evaluate(np.concatenate([a, mid]), np.concatenate([mid, b]))
        pool = tuple(np.concatenate([old[~split], fresh]) for old, fresh in zip(pool, new, strict=True))
    nodes = pool[4].ravel()
    order = np.argsort(nodes)
    rule = QuadratureRule(nodes[order], pool[5].ravel()[order])
    g2, s = pool[6].ravel()[order], pool[7].ravel()[order]
    variance = rule.integrate(g2 * s)
    return RandomResponse(math.sqrt(max(variance, 0.0)), variance, total_err, rule, g2, s, name, V, band)


def rms(system: LinearSystem, spectrum: object, speed_m_s: float, band_hz: tuple[float, float],
        output: str | None = None, rtol: float = 1e-8) -> float:
    """RMS of ``output`` (its units) over ``band_hz`` at ``speed_m_s``: ``sqrt(∫|H|² S(ω/V)/V dω)``.

    Adaptive quadrature, method (a); see :func:`random_response` for parameters, errors and the
    reusable quadrature rule.
    """
    return random_response(system, spectrum, speed_m_s, band_hz, output, rtol).rms


def rms_gradient(system: LinearSystem, response: RandomResponse, dp: np.ndarray | None = None) -> np.ndarray:
    """Analytic gradient of the RMS of a :class:`RandomResponse` of ``system`` (a family member built by
    ``ParametricSystem.at(p)``, so it carries its tangent) on the response's own quadrature rule.

    ``RMS² = Σ_k w_k S_k |H_k|²`` so ``dRMS = Σ_k w_k S_k Re(conj(H_k) dH_k) / RMS``, with
    ``dH = (iω)^q c·Z⁻¹(dF − dZ X)``, ``X = Z⁻¹F``, ``dZ = dK − ω²dM + iω dC`` (one adjoint solve per node).  The nodes
    are held fixed: this is the derivative of the discrete sum, equal to that of the RMS to the quadrature
    tolerance.

    Parameters
    ----------
    system : LinearSystem
        The member the response was computed for (with its :class:`~railopt.models.system.Tangent`).
    response : RandomResponse
        From :func:`random_response` of ``system``.
    dp : (P, d) ndarray, optional
        dp/dx of design variables x (the chain rule is folded in before the solves, cheap when d is small);
        default the identity, giving the derivative in the family's own parameters.

    Returns
    -------
    (P,) or (d,) ndarray
        dRMS/dp_i (or dRMS/dx_j), output units per parameter unit.

    Raises
    ------
    ValueError
        ``system`` without a tangent; the output has a feedthrough (not covered); ``dp`` not (P, d).
    """
    out = system.outputs[response.output]
    if out.feedthrough is not None:
        raise ValueError(f"output: {response.output!r} has a feedthrough; the analytic RMS gradient does not cover it")
    t = system.tangent
    if t is None:
        raise ValueError("system: carries no parameter derivatives; build it with ParametricSystem.at(p)")
    P = len(t.parameters)
    dp = np.eye(P) if dp is None else np.asarray(dp, dtype=float)
    if dp.ndim != 2 or dp.shape[0] != P:
        raise ValueError(f"dp: must have shape ({P}, d) (dp/dx), got {dp.shape}")
    d = dp.shape[1]
    if response.rms == 0.0:
        return np.zeros(d)
    w = response.rule.omega
    q = {"displacement": 0, "velocity": 1, "acceleration": 2}[out.quantity]
    F = system.forcing.values(w)  # (N, n)
    Z = system.impedance(w)
    X = np.linalg.solve(Z, F[..., None])[..., 0]
    adj = np.linalg.solve(np.swapaxes(Z, 1, 2), np.broadcast_to(out.row.astype(complex), F.shape)[..., None])[..., 0]
    gain = (1j * w) ** q
    H = gain * np.sum(adj * F, axis=1)
    weight = response.rule.weights * response.input_psd
    moving = np.flatnonzero(np.any(dp != 0.0, axis=1))
    grad = np.zeros(d)
    for j in range(d):
        c = dp[moving, j]
        dM, dC, dK = (np.tensordot(c, a[moving], axes=1) for a in (t.dM, t.dC, t.dK))
        dZX = X @ dK.T - (w**2)[:, None] * (X @ dM.T) + 1j * w[:, None] * (X @ dC.T)
        dF = np.zeros_like(F)
        for i, ci in zip(moving, c, strict=True):
            if t.dF[i] is not None and ci != 0.0:
                dF += ci * t.dF[i].values(w)
        dH = gain * np.sum(adj * (dF - dZX), axis=1)
        grad[j] = float(np.dot(weight, (np.conj(H) * dH).real)) / response.rms
    return grad


def rms_and_gradient(family: ParametricSystem, p: Sequence[float], spectrum: object, speed_m_s: float,
                     band_hz: tuple[float, float], output: str | None = None,
                     rtol: float = 1e-8) -> tuple[float, np.ndarray]:
    """RMS of ``output`` of the family member at parameters ``p`` and its analytic gradient ``dRMS/dp``.

    The member is ``family.at(p, speed=speed_m_s)`` when the family has a speed term (else ``family.at(p)``); the
    RMS is :func:`random_response` (adaptive quadrature, ``rtol`` on the variance) and the gradient
    :func:`rms_gradient` on its rule — about the cost of one more RMS, against P + 1 (one-sided) or 2P (central)
    RMS evaluations for finite differences.

    Parameters
    ----------
    family : ParametricSystem
        Forced per metre of irregularity (e.g. a vehicle view's ``family(names, input=...)``).
    p : (P,) sequence of float
        Parameter values (SI), in ``family.parameters`` order.
    spectrum, speed_m_s, band_hz, output, rtol
        As for :func:`random_response` (speed m/s, band Hz).

    Returns
    -------
    (float, (P,) ndarray)
        The RMS (output units) and dRMS/dp_i (output units per parameter unit).

    Raises
    ------
    ValueError
        As :func:`random_response` (unstable member, band, spectrum, output) and :func:`rms_gradient`.
    """
    system = family.at(p, speed=speed_m_s) if family.has_speed else family.at(p)
    response = random_response(system, spectrum, speed_m_s, band_hz, output, rtol)
    return response.rms, rms_gradient(system, response)


def output_psd(system: LinearSystem, spectrum: object, speed_m_s: float, frequencies_hz: object,
               output: str | None = None) -> np.ndarray:
    """One-sided output PSD ``|H(2πf)|² · 2π S(2πf/V)/V`` at ``frequencies_hz`` (Hz), in output²/Hz.

    For an acceleration output per metre of irregularity the result is in (m/s²)²/Hz.

    Raises
    ------
    ValueError
        Frequencies not finite and positive, or outside the spectrum's validity at this speed.
    """
    V = number("speed_m_s", speed_m_s, positive=True)
    f = np.asarray(frequencies_hz, dtype=float)
    if f.size == 0 or not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ValueError("frequencies_hz: must be a non-empty array of finite frequencies > 0 Hz")
    _check_spectrum_band(spectrum, V, (float(np.min(f)), float(np.max(f))))
    h = system.frf(omega_rad_s=TWO_PI * f.ravel(), output=_output_name(system, output))
    return (np.abs(h) ** 2 * TWO_PI * _input_psd(spectrum, TWO_PI * f.ravel(), V)).reshape(f.shape)


def rms_combined(inputs: Iterable[Sequence[object]], speed_m_s: float, band_hz: tuple[float, float],
                 rtol: float = 1e-8) -> float:
    """RMS of the sum of responses to *independent* inputs: ``sqrt(Σ_i RMS_i²)``.

    ``inputs``: ``[(system, spectrum), (system, spectrum, output), ...]`` — e.g. the vertical model under
    the profile spectrum and the lateral model under the alignment spectrum, for one quantity observed
    in both.  Uncorrelated inputs add in power; correlated ones must be one system with one forcing.
    """
    total = 0.0
    items = list(inputs)
    if not items:
        raise ValueError("inputs: at least one (system, spectrum[, output]) is needed")
    for i, item in enumerate(items):
        if not (isinstance(item, Sequence) and len(item) in (2, 3)):
            raise ValueError(f"inputs[{i}]: must be (system, spectrum) or (system, spectrum, output), got {item!r}")
        system, spectrum, *out = item
        total += random_response(system, spectrum, speed_m_s, band_hz, out[0] if out else None, rtol).variance
    return math.sqrt(total)


# ------------------------------------------------------------------------------- method (b): state space
def _free_mode_projection(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(L, T): left null space of [K C] and a basis of {x : Lᵀ M x = 0}; None without free modes."""
    A = np.hstack([K, C]).T
    _, sv, vt = np.linalg.svd(A)
    tol = 1e-10 * max(float(sv[0]), 1e-300)
    rank = int(np.sum(sv > tol))
    if rank == M.shape[0]:
        return None
    L = vt[rank:].T
    T = sla.null_space((M @ L).T)
    return L, T


def rms_state_space(system: LinearSystem, spectrum: object, speed_m_s: float, output: str | None = None) -> float:
    """RMS over the whole band 0 < ω < ∞ of the rational model, by modal covariance with exact delays (b).

    Parameters
    ----------
    system : LinearSystem
        As for :func:`rms`; every forcing term polynomial (``DelayedTerm.coefficients``, real).
    spectrum : RationalSpectrum
        Two positive corners (ERRI B176, FRA cross-level, or ``.unbounded()`` versions); its validity
        range is ignored — the result is the variance of the rational model over all wavenumbers, to
        be compared with quadrature of ``spectrum.unbounded()`` over a wide band.
    speed_m_s : float
        V (m/s).
    output : str, optional

    Returns
    -------
    float
        RMS (output units).  Accuracy: limited by the eigenvector conditioning of the state matrix
        (rounding ~ cond(V)·1e-16 relative); the measured agreement with (a) is better than 1e-6.

    Raises
    ------
    ValueError
        ``spectrum`` not rational with p₁, p₂ > 0; a callable forcing term or complex coefficients
        (``system``); a path ``T_i = H_i G`` that is not strictly proper (infinite full-band variance);
        an output feedthrough; a forcing that drives a free rigid-body mode; an unstable system or a
        defective eigenbasis.
    """
    V = number("speed_m_s", speed_m_s, positive=True)
    corners = getattr(spectrum, "corners", None)
    gain = getattr(spectrum, "gain", None)
    if corners is None or gain is None or not min(corners) > 0:
        raise ValueError("spectrum: the state-space method needs a rational spectrum b₀/((Ω²+p₁²)(Ω²+p₂²)) with "
                         "p₁, p₂ > 0 (ERRI B176, FRA cross-level); FRA profile/alignment (p₁ = 0) integrate with rms()")
    name = _output_name(system, output)
    out = system.outputs[name]
    if out.feedthrough is not None:
        raise ValueError(f"output: {name!r} has a feedthrough, not supported by the state-space method")
    terms = system.forcing.terms
    if not terms or any(t.coefficients is None for t in terms):
        raise ValueError("system: every forcing term must be polynomial (Forcing.delayed with coefficient arrays)")
    coeffs = [np.asarray(t.coefficients) for t in terms]
    if any(np.max(np.abs(c.imag), initial=0.0) > 1e-12 * max(np.max(np.abs(c)), 1e-300) for c in coeffs):
        raise ValueError("system: forcing coefficients must be real for the state-space method")
    coeffs = [c.real for c in coeffs]
    delays = np.array([t.delay for t in terms])
    q_out = {"displacement": 0, "velocity": 1, "acceleration": 2}[out.quantity]
    degree = max(int(np.max(np.nonzero(np.any(c != 0, axis=1))[0], initial=0)) for c in coeffs)
    if q_out + degree > 4:
        raise ValueError(f"system: forcing of degree {degree} in iΩ is not supported by the state-space method")
    if q_out + degree == 4:  # T_i → c M⁻¹ a₂ as s → ∞: must vanish (else white-noise feedthrough)
        for i, c in enumerate(coeffs):
            lead = out.row @ np.linalg.solve(system.M, c[2])
            if abs(lead) > 1e-12 * np.linalg.norm(out.row) * np.linalg.norm(np.linalg.solve(system.M, c[2])):
                raise ValueError(f"system: output {name!r} ({out.quantity}) sees forcing term {i} through c·M⁻¹·a₂ "
                                 "≠ 0: a white-noise feedthrough (infinite full-band variance); use rms() over a band")
    M, C, K, c_row = system.M, system.C, system.K, out.row
    proj = _free_mode_projection(M, C, K)
    if proj is not None:
        L, T = proj
        for i, c in enumerate(coeffs):
            if np.max(np.abs(L.T @ c.T)) > 1e-9 * max(np.max(np.abs(c)), 1e-300):
                raise ValueError(f"system: forcing term {i} drives a free rigid-body mode (no stiffness or damping)")
        M, C, K = T.T @ M @ T, T.T @ C @ T, T.T @ K @ T
        coeffs = [c @ T for c in coeffs]
        c_row = c_row @ T
    n = M.shape[0]
    minv = np.linalg.inv(M)
    decomposition = LinearSystem(M, C, K).modal()  # the one state matrix G (4.53)
    lam, vec, W = decomposition.s, decomposition.V, decomposition.W
    if decomposition.condition > 1e12:
        raise ValueError("system: the state matrix is (nearly) defective; the modal covariance is unreliable")
    alpha, beta = (V * float(p) for p in sorted(corners))
    if math.isclose(alpha, beta, rel_tol=1e-9):
        raise ValueError("spectrum: equal corners p₁ = p₂ are not supported by the state-space method")
    q = math.pi * float(gain) * V**3

    def G(s: np.ndarray) -> np.ndarray:
        return 1.0 / ((s + alpha) * (s + beta))

    def poly(c: np.ndarray, s: np.ndarray) -> np.ndarray:
        return np.stack([s**j for j in range(c.shape[0])], axis=-1) @ c  # (..., n)

    obs = (c_row @ vec[:n]) * lam**q_out  # (2n,)
    ctrl = W[:, n:] @ minv  # (2n, n)
    poles = np.concatenate([lam, [-alpha, -beta]])
    res = []
    for c in coeffs:
        a_lam = poly(c, lam)  # (2n, n): a_i(λ_j)
        r_plant = obs * np.einsum("jk,jk->j", ctrl, a_lam) * G(lam)
        r_filter = []
        for p, other in ((-alpha, -beta), (-beta, -alpha)):
            Z = K + p * C + p * p * M
            h = p**q_out * (c_row @ np.linalg.solve(Z, poly(c, np.array([p]))[0]))
            r_filter.append(h / (p - other))
        res.append(np.concatenate([r_plant, r_filter]))
    R = np.array(res)  # (terms, N)
    # zero roots that remain (a coordinate with damping but no stiffness, e.g. a wheelset's rolling angle):
    # dropped when no path observes them (residue ~ 0), else the variance is infinite
    zero = np.abs(poles) <= 1e-10 * np.max(np.abs(poles))
    if np.any(zero):
        if np.max(np.abs(R[:, zero])) > 1e-10 * np.max(np.abs(R)) * np.max(np.abs(poles[zero]) / np.max(np.abs(poles))):
            raise ValueError(f"system: output {name!r} observes a forced coordinate without stiffness (root s = 0): "
                             "its stationary variance is infinite")
        poles, R = poles[~zero], R[:, ~zero]
    if np.max(poles.real) >= 0:
        raise ValueError(f"system: not asymptotically stable (max Re s = {np.max(poles.real):.3g}); no stationary "
                         "response")
    S = poles[:, None] + poles[None, :]
    total = 0.0 + 0.0j
    for i in range(len(delays)):
        for k in range(len(delays)):
            d = delays[i] - delays[k]  # ∫ h_i(θ) h_k(θ + d) dθ over θ ≥ max(0, −d)
            if d >= 0:
                phase = np.exp(poles * d)[None, :]
            else:
                phase = np.exp(poles * (-d))[:, None]
            total += np.sum(R[i][:, None] * R[k][None, :] * phase / (-S))
    variance = q * total.real
    return math.sqrt(max(variance, 0.0))


__all__ = [
    "QuadratureRule",
    "RandomResponse",
    "output_psd",
    "random_response",
    "rms",
    "rms_and_gradient",
    "rms_combined",
    "rms_gradient",
    "rms_state_space",
]
