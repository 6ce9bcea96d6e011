"""Forcing amplitudes ``F(Ω)`` as sums of delayed terms (thesis eqs. 4.63–4.66).

A vehicle on a sinusoidal irregularity is forced through each axle's springs and dampers by the
same profile delayed by the axle's distance over the speed, so

    F(Ω) = Σ_i a_i(Ω) e^{−iΩτ_i},   τ_i ≥ 0 (s),

with ``a_i(Ω)`` either a polynomial in ``iΩ`` with vector coefficients (springs and dampers:
``(K_i + iΩ C_i) u``) or an arbitrary callable.  Declaring the delays matters: the band maximum of
such a response has more local maxima than modes (wheelbase filtering), and the certified search
of :mod:`railopt.models.response_maxima` resolves ``e^{−iΩτ}`` only when it knows the largest τ.
A plain callable with no declared ``max_delay`` is therefore never certified.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

Amplitude = np.ndarray | Sequence[complex] | Callable[[float], np.ndarray]


@dataclass(frozen=True, eq=False)
class DelayedTerm:
    """One term ``a(Ω) e^{−iΩτ}``.

    ``coefficients`` (p+1, n) complex gives ``a(Ω) = Σ_j (iΩ)^j coefficients[j]``; otherwise
    ``function(Ω) -> (n,)`` is called.  ``delay`` τ in seconds.
    """

    delay: float
    coefficients: np.ndarray | None = None
    function: Callable[[float], np.ndarray] | None = None

    def amplitude(self, omega: float) -> np.ndarray:
        """The amplitude ``a(Ω)`` at ``omega`` (rad/s), complex, shape (n,) (without the delay factor).

        Polynomial terms evaluate ``Σ_j (iΩ)^j coefficients[j]``; callable terms return ``function(omega)``.
        """
        if self.coefficients is not None:
            powers = (1j * omega) ** np.arange(self.coefficients.shape[0])
            return powers @ self.coefficients
        return np.asarray(self.function(omega), dtype=complex)

    def amplitude_derivative(self, omega: float) -> np.ndarray | None:
        """``da/dΩ`` for polynomial terms (exact); ``None`` for callables."""
        if self.coefficients is None:
            return None
        j = np.arange(1, self.coefficients.shape[0])
        if j.size == 0:
            return np.zeros(self.coefficients.shape[1], dtype=complex)
        return (1j * j * (1j * omega) ** (j - 1)) @ self.coefficients[1:]

    def scaled(self, factor: float) -> DelayedTerm:
        """The same term with its amplitude multiplied by ``factor`` (same delay; polynomial terms stay polynomial)."""
        if self.coefficients is not None:
            return DelayedTerm(self.delay, coefficients=factor * self.coefficients)
        fn = self.function
        return DelayedTerm(self.delay, function=lambda w: factor * np.asarray(fn(w), dtype=complex))


def _term(amplitude: Amplitude, delay: float, n: int | None, where: str) -> DelayedTerm:
    try:
        delay = float(delay)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}.delay: must be a number of seconds, got {delay!r}") from exc
    if not (np.isfinite(delay) and delay >= 0):
        raise ValueError(f"{where}.delay: must be finite and ≥ 0 s, got {delay}")
    if callable(amplitude):
        return DelayedTerm(delay, function=amplitude)
    arr = np.asarray(amplitude)
    if not np.issubdtype(arr.dtype, np.number):
        raise ValueError(f"{where}.amplitude: must be numeric, got dtype {arr.dtype}")
    coeffs = np.atleast_2d(arr.astype(complex))
    if coeffs.ndim != 2 or (n is not None and coeffs.shape[1] != n):
        raise ValueError(f"{where}.amplitude: must have shape (n,) or (p+1, n) with n = {n}, got {arr.shape}")
    if not np.all(np.isfinite(coeffs)):
        raise ValueError(f"{where}.amplitude: contains NaN or infinite entries")
    return DelayedTerm(delay, coefficients=coeffs)


class Forcing:
    """Complex forcing amplitude ``F(Ω)`` (N or N·m per unit input), a sum of delayed terms.

    Build with :meth:`constant`, :meth:`delayed` or :meth:`polynomial`, or wrap any callable:
    ``Forcing(value=f, max_delay=τ)``.  ``max_delay`` (s) is the largest delay inside ``F``;
    ``None`` means undeclared, and then no band maximum of the response is ``certified``.
    """

    def __init__(
        self,
        value: Callable[[float], np.ndarray] | None = None,
        derivative_fn: Callable[[float], np.ndarray] | None = None,
        max_delay: float | None = None,
        *,
        terms: Iterable[DelayedTerm] = (),
    ) -> None:
        self.terms = tuple(terms)
        self._derivative_fn = derivative_fn
        if value is not None:
            if self.terms:
                raise ValueError("Forcing: give either value or terms, not both")
            if not callable(value):
                raise ValueError(f"value: must be callable Ω -> (n,), got {type(value).__name__}")
            self.terms = (DelayedTerm(0.0, function=value),)
            if max_delay is not None and not (np.isfinite(max_delay) and max_delay >= 0):
                raise ValueError(f"max_delay: must be finite and ≥ 0 s, got {max_delay}")
            self.max_delay = None if max_delay is None else float(max_delay)
        else:
            self.max_delay = max((t.delay for t in self.terms), default=0.0)

    # ------------------------------------------------------------------ constructors
    @classmethod
    def constant(cls, amplitude: np.ndarray | Sequence[complex]) -> Forcing:
        """A frequency-independent amplitude, shape (n,)."""
        return cls(terms=[_term(amplitude, 0.0, None, "F")])

    @classmethod
    def polynomial(cls, coefficients: np.ndarray, delay: float = 0.0) -> Forcing:
        """``Σ_j (iΩ)^j coefficients[j] e^{−iΩτ}``, coefficients (p+1, n)."""
        return cls(terms=[_term(coefficients, delay, None, "F")])

    @classmethod
    def delayed(cls, terms: Iterable[tuple[Amplitude, float]]) -> Forcing:
        """``F(Ω) = Σ_i a_i(Ω) e^{−iΩτ_i}`` from ``[(a_i, τ_i), ...]``.

        ``a_i``: an (n,) array, a (p+1, n) array of coefficients of (iΩ)^0..p, or a callable
        ``Ω -> (n,)`` (assumed free of hidden delays).  τ_i in seconds.
        """
        built = []
        n = None
        for i, item in enumerate(terms):
            try:
                amplitude, delay = item
            except (TypeError, ValueError) as exc:
                raise ValueError(f"terms[{i}]: must be a pair (amplitude, delay_s), got {item!r}") from exc
            term = _term(amplitude, delay, n, f"terms[{i}]")
            if term.coefficients is not None:
                n = term.coefficients.shape[1]
            built.append(term)
        if not built:
            raise ValueError("terms: at least one (amplitude, delay) term is needed")
        return cls(terms=built)

    @classmethod
    def combine(cls, weighted: Iterable[tuple[float, Forcing]]) -> Forcing:
        """``Σ w_k F_k`` (parametric forcing); the delays stay declared only if all were.

        Polynomial terms of equal delay are summed into one (a vehicle's many suspension parameters all
        act through the same few axle inputs), so evaluating the sum costs one term per distinct delay.
        """
        by_delay: dict[float, np.ndarray] = {}
        others: list[DelayedTerm] = []
        declared = True
        max_delay = 0.0
        for w, f in weighted:
            if w == 0.0:
                continue
            for t in f.terms:
                if t.coefficients is None:
                    others.append(t if w == 1.0 else t.scaled(w))
                    continue
                c = w * t.coefficients
                acc = by_delay.get(t.delay)
                if acc is None:
                    by_delay[t.delay] = c.astype(complex)
                else:
                    size = max(acc.shape[0], c.shape[0])
                    merged = np.zeros((size, c.shape[1]), dtype=complex)
                    merged[: acc.shape[0]] += acc
                    merged[: c.shape[0]] += c
                    by_delay[t.delay] = merged
            declared = declared and f.max_delay is not None
            max_delay = max(max_delay, f.max_delay or 0.0)
        terms = [DelayedTerm(d, coefficients=c) for d, c in by_delay.items()] + others
        out = cls(terms=terms)
        out.max_delay = max_delay if declared else None
        return out

    # ------------------------------------------------------------------ evaluation
    @property
    def declared(self) -> bool:
        """True when every delay inside F is known (the band search can certify its maximum)."""
        return self.max_delay is not None

    @property
    def is_polynomial(self) -> bool:
        """All terms are polynomial in iΩ (the pole–residue form needs no callable per frequency)."""
        for t in self.terms:
            if t.coefficients is None:
                return False
        return True

    def value(self, omega: float) -> np.ndarray:
        """``F(Ω)``, (n,) complex, Ω in rad/s."""
        total = 0j
        for t in self.terms:
            a = t.amplitude(omega)
            total = total + (a if t.delay == 0.0 else a * np.exp(-1j * omega * t.delay))
        return np.asarray(total, dtype=complex)

    def values(self, omegas: np.ndarray) -> np.ndarray:
        """``F(Ω)`` at many frequencies, shape (len(omegas), n); polynomial terms vectorised over Ω."""
        w = np.asarray(omegas, dtype=float).ravel()
        if not self.is_polynomial:
            return np.array([self.value(float(x)) for x in w], dtype=complex)
        iw = 1j * w
        total = None
        for t in self.terms:
            part = (iw[:, None] ** np.arange(t.coefficients.shape[0])[None, :]) @ t.coefficients
            if t.delay != 0.0:
                part *= np.exp(-1j * w * t.delay)[:, None]
            total = part if total is None else total + part
        return total

    def derivative(self, omega: float) -> np.ndarray:
        """``dF/dΩ``: exact for polynomial terms and delays; callables by a central difference
        (relative step 1e-6, accurate to ~1e-10 for smooth amplitudes) unless ``derivative_fn``."""
        if self._derivative_fn is not None:
            return np.asarray(self._derivative_fn(omega), dtype=complex)
        total = 0j
        for t in self.terms:
            da = t.amplitude_derivative(omega)
            if da is None:
                h = 1e-6 * max(abs(omega), 1.0)
                da = (t.amplitude(omega + h) - t.amplitude(omega - h)) / (2 * h)
            phase = np.exp(-1j * omega * t.delay)
            total = total + (da - 1j * t.delay * t.amplitude(omega)) * phase
        return np.asarray(total, dtype=complex)

    def __repr__(self) -> str:
        kinds = "polynomial" if self.is_polynomial else "callable"
        delay = "undeclared" if self.max_delay is None else f"{self.max_delay:.6g} s"
        return f"Forcing({len(self.terms)} {kinds} term(s), max_delay={delay})"


ForcingLike = np.ndarray | Sequence[complex] | Callable[[float], np.ndarray] | Forcing


def as_forcing(F: ForcingLike, n: int, field: str = "F") -> Forcing:
    """Wrap an (n,) array or a callable ``F(Ω) -> (n,)`` as a :class:`Forcing` and check its shape.

    A plain callable becomes a forcing with undeclared delays (never certified).
    """
    if isinstance(F, Forcing):
        forcing = F
    elif callable(F):
        forcing = Forcing(value=F)
    else:
        arr = np.asarray(F)
        if arr.shape != (n,):
            raise ValueError(f"{field}: forcing amplitude must have shape ({n},), got {arr.shape}")
        forcing = Forcing(terms=[_term(arr, 0.0, n, field)])
    for t in forcing.terms:
        if t.coefficients is not None and t.coefficients.shape[1] != n:
            raise ValueError(f"{field}: terms must have n = {n} entries, got {t.coefficients.shape[1]}")
    probe = np.asarray(forcing.value(1.0))
    if probe.shape != (n,):
        raise ValueError(f"{field}: F(omega) must return shape ({n},), got {probe.shape}")
    if not np.all(np.isfinite(probe)):
        raise ValueError(f"{field}: F(1.0) is not finite ({probe})")
    return forcing


class DistanceForcing:
    """Inputs at fixed distances behind a leading point: ``F(Ω; S) = Σ_i a_i(Ω) e^{−iΩ d_i/S}``.

    A vehicle running at speed S over a profile meets it at an axle d_i metres behind the leading
    axle d_i/S seconds later (thesis (4.63)–(4.66)), so the delays of a vehicle's forcing depend on
    the speed while the amplitudes ``a_i(Ω) = Σ_j (iΩ)^j A_ij`` do not.  :meth:`at_speed` gives the
    :class:`Forcing` with its delays declared, which is what a parametric family with a speed term
    (:class:`~railopt.models.parametric.ParametricSystem`) evaluates at each speed.

    Parameters
    ----------
    terms : iterable of (coefficients, distance_m)
        ``coefficients`` (p+1, n) (or (n,)) of powers of iΩ; ``distance_m`` ≥ 0 behind the leading point.
    """

    def __init__(self, terms: Iterable[tuple[np.ndarray, float]]) -> None:
        built = []
        for i, item in enumerate(terms):
            try:
                coefficients, distance = item
            except (TypeError, ValueError) as exc:
                raise ValueError(f"terms[{i}]: must be a pair (coefficients, distance_m), got {item!r}") from exc
            term = _term(coefficients, distance, None if not built else built[0][0].shape[1], f"terms[{i}]")
            built.append((term.coefficients, term.delay))  # the delay slot holds the distance (m) here
        if not built:
            raise ValueError("terms: at least one (coefficients, distance_m) term is needed")
        self.terms = tuple(built)

    @property
    def n(self) -> int:
        """Number of coordinates the forcing acts on (length of each amplitude vector)."""
        return self.terms[0][0].shape[1]

    def at_speed(self, speed: float) -> Forcing:
        """The forcing at forward speed ``speed`` (m/s): delays ``d_i / S`` declared."""
        return Forcing(terms=[DelayedTerm(d / speed, coefficients=c) for c, d in self.terms])

    def __repr__(self) -> str:
        far = max(d for _, d in self.terms)
        return f"DistanceForcing({len(self.terms)} term(s), up to {far:.6g} m behind)"


def at_speed(forcing: Forcing | DistanceForcing | None, speed: float | None) -> Forcing | None:
    """``forcing`` resolved at a speed: a :class:`DistanceForcing` needs one (m/s), a :class:`Forcing` is kept."""
    if isinstance(forcing, DistanceForcing):
        if speed is None:
            raise ValueError("speed: this system's inputs are at distances along the track; give a forward speed "
                             "(m/s)")
        return forcing.at_speed(speed)
    return forcing


__all__ = ["Amplitude", "DelayedTerm", "DistanceForcing", "Forcing", "ForcingLike", "as_forcing", "at_speed"]
