"""The one parametric system family: M, C, K and F affine in parameters, with a speed term.

Suspension rates enter the equations of motion linearly and creep damping scales as 1/S, so a
model is assembled once as

    M(p)    = M0 + Σ p_i M_i
    C(p, S) = C0 + Σ p_i C_i + C_speed / S
    K(p)    = K0 + Σ p_i K_i
    F(p, S) = F0(S) + Σ p_i F_i(S) + F_speed(S) / S

(thesis (4.51)–(4.53) and (4.60)–(4.70); the F terms of a vehicle are its axle inputs at distances
d_i, so their delays d_i/S depend on the speed: :class:`~railopt.models.forcing.DistanceForcing`).
``family.at(p, speed=S)`` returns the :class:`~railopt.models.system.LinearSystem` — the only place
in railopt where K and C are summed (:func:`affine`) — with a :class:`~railopt.models.system.Tangent`
attached, so gradients (:mod:`railopt.models.sensitivity`) and stability
(:mod:`railopt.models.stability`) take the system or the family alone.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from railopt.models.forcing import DelayedTerm, DistanceForcing, Forcing, ForcingLike, as_forcing, at_speed
from railopt.models.system import LinearSystem, Output, Tangent
from railopt.models.validation import number, real_array

FamilyForcing = ForcingLike | DistanceForcing


@dataclass(frozen=True)
class ParameterPart:
    """The matrices multiplying one parameter: ``M_i, C_i, K_i`` (n, n) and forcing ``F_i(Ω)``
    (a :class:`Forcing`, an (n,) array, a callable, or a :class:`DistanceForcing` for inputs at distances)."""

    M: np.ndarray | None = None
    C: np.ndarray | None = None
    K: np.ndarray | None = None
    F: FamilyForcing | None = None


def affine(base: np.ndarray, parts: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``base + Σ_i p_i parts[i]``: the one place railopt sums parameter-weighted matrices.

    ``base`` (…), ``parts`` (P, …), ``p`` (P,).  Used for M, C, K of every family member and for the
    input matrices of vehicle views.  ``p`` of shape (B, P) gives the B members at once, shape (B, …), each
    the same sums in the same order as its own (P,) call.
    """
    parts = np.asarray(parts)
    p = np.asarray(p)
    if p.ndim == 2:
        if p.shape[1] != len(parts):
            raise ValueError(f"p: expected {len(parts)} values per member, got {p.shape[1]}")
        if parts.dtype == object or p.shape[1] == 0:
            return np.array([affine(base, parts, row) for row in p])
        weights = p.reshape(p.shape + (1,) * (parts.ndim - 1))
        return base + (weights * parts[None]).sum(axis=1)
    if len(p) != len(parts):
        raise ValueError(f"p: expected {len(parts)} values, got {len(p)}")
    if parts.dtype == object or len(p) == 0:
        acc = np.zeros(np.shape(base), dtype=np.result_type(base, parts))
        for pi, part in zip(p, parts, strict=True):
            if pi != 0.0:
                acc += pi * part
        return base + acc
    # one reduction over the parameter axis: numpy adds the P products in parameter order (the same sums as
    # a loop, so exact cancellations stay exact); a zero weight adds only zeros
    return base + (p.reshape((-1,) + (1,) * (parts.ndim - 1)) * parts).sum(axis=0)


def _family_forcing(F: FamilyForcing | None, n: int, field: str) -> Forcing | DistanceForcing | None:
    if F is None or isinstance(F, DistanceForcing):
        if isinstance(F, DistanceForcing) and F.n != n:
            raise ValueError(f"{field}: terms must have n = {n} entries, got {F.n}")
        return F
    return as_forcing(F, n, field)


@dataclass(frozen=True)
class MemberStack:
    """B members of a family at one speed, stacked (from :meth:`ParametricSystem.stack`).

    Attributes
    ----------
    M, C, K : (B, n, n) ndarray
    delays : (T,) ndarray
        The forcing's distinct delays (s).
    coefficients : (B, T, J, n) complex ndarray
        Member b's forcing is Σ_t Σ_j (iΩ)^j coefficients[b, t, j] e^{−iΩ delays[t]} (:class:`DelayedTerm`).
    outputs : dict of Output
        Shared by every member (they do not depend on p).
    names : tuple of str
        The degrees of freedom.
    """

    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    delays: np.ndarray
    coefficients: np.ndarray
    outputs: dict[str, Output]
    names: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.M)

    def member(self, b: int) -> LinearSystem:
        """Member b as a :class:`LinearSystem` (checked like any other)."""
        forcing = Forcing(terms=[DelayedTerm(float(d), coefficients=self.coefficients[b, t])
                                 for t, d in enumerate(self.delays)])
        return LinearSystem(self.M[b], self.C[b], self.K[b], forcing, outputs=self.outputs, names=self.names)


class ParametricSystem:
    """A family of linear systems affine in parameters p, with an optional forward-speed term.

    Parameters
    ----------
    M0, C0, K0 : (n, n) array_like
        Constant parts (SI).
    F0 : (n,) array_like, callable, Forcing or DistanceForcing, optional
        Constant part of the forcing amplitude (zero when omitted).
    output : (n,) array_like, optional
        One output row c (with ``response``); or give ``outputs`` (or neither: eigen-analysis only).
    parts : mapping name -> ParameterPart
        Parameter-weighted parts, in parameter order.
    response : str
        "displacement", "velocity" or "acceleration" (of ``output``).
    names : sequence of str, optional
        Coordinate names.
    outputs : mapping name -> row, (row, quantity), (row, quantity, feedthrough) or Output, optional
        Named outputs sharing every eigen-decomposition; a feedthrough may be a DistanceForcing.
    C_speed : (n, n) array_like, optional
        The speed term of the damping, C_speed / S (N·s: creep damping times speed).
    F_speed : DistanceForcing or Forcing, optional
        The speed term of the forcing, F_speed / S (creep forces of the rail inputs).
    values : (P,) array_like or mapping name -> value, optional
        The family's own parameter values (a vehicle file's suspension), used when ``at`` gets no p.
    speed : float, optional
        The family's own forward speed (m/s), used when ``at`` gets no speed.
    groups : mapping body -> group, optional
        How the bodies of the coordinates (``"<body>.<dof>"``) gather for mode names
        (:func:`railopt.models.stability.modes`); ``main_body`` is the car body.

    Raises
    ------
    ValueError
        Shapes, non-finite entries or unknown names, naming the field.
    """

    def __init__(
        self, M0: np.ndarray, C0: np.ndarray, K0: np.ndarray,
        F0: FamilyForcing | None = None,
        output: np.ndarray | None = None,
        parts: Mapping[str, ParameterPart] | None = None,
        response: str = "displacement",
        names: Sequence[str] | None = None,
        outputs: Mapping[str, object] | None = None,
        C_speed: np.ndarray | None = None,
        F_speed: FamilyForcing | None = None,
        values: Sequence[float] | Mapping[str, float] | None = None,
        speed: float | None = None,
        groups: Mapping[str, str] | None = None,
        main_body: str | None = None,
    ) -> None:
        specs = dict(outputs or {})
        feeds = {}
        for k, v in specs.items():  # distance feedthroughs are resolved per speed
            if isinstance(v, tuple) and len(v) == 3 and isinstance(v[2], DistanceForcing):
                feeds[str(k)] = v[2]
                specs[k] = v[:2]
        self._base = LinearSystem(M0, C0, K0, None, output, response=response, names=names,
                                  outputs=specs if outputs is not None else None)
        n = self._base.n
        self._F0 = _family_forcing(F0, n, "F0")
        self._distance_feeds = feeds
        parts = dict(parts or {})
        self.parameters = tuple(parts)
        P = len(parts)
        self._M = np.zeros((P, n, n))
        self._C = np.zeros((P, n, n))
        self._K = np.zeros((P, n, n))
        self._F: list[Forcing | DistanceForcing | None] = []
        for i, (name, part) in enumerate(parts.items()):
            for attr, store in (("M", self._M), ("C", self._C), ("K", self._K)):
                a = getattr(part, attr)
                if a is not None:
                    store[i] = real_array(f"parts[{name!r}].{attr}", a, shape=(n, n))
            self._F.append(_family_forcing(part.F, n, f"parts[{name!r}].F"))
        self._C_speed = None if C_speed is None else real_array("C_speed", C_speed, shape=(n, n))
        self._F_speed = _family_forcing(F_speed, n, "F_speed")
        self.values = None if values is None else self._check(self._vector(values))
        self.speed = None if speed is None else number("speed", speed, positive=True)
        self._at_speed_cache: dict[float | None, tuple] = {}
        self.groups = dict(groups or {})
        self.main_body = main_body

    # ------------------------------------------------------------------ description
    @property
    def n(self) -> int:
        """Number of degrees of freedom (size of M, C and K)."""
        return self._base.n

    @property
    def output_names(self) -> tuple[str, ...]:
        """Names of the output rows, in order (the first is the default output)."""
        return self._base.output_names

    @property
    def names(self) -> tuple[str, ...]:
        """Names of the parameters (the parts of the family), in the order of a parameter vector."""
        return self._base.names

    @property
    def has_speed(self) -> bool:
        """True when C or F depend on the forward speed (a speed must be given to :meth:`at`)."""
        return (self._C_speed is not None or self._F_speed is not None
                or any(isinstance(f, DistanceForcing) for f in [self._F0, *self._F, *self._distance_feeds.values()]))

    def __repr__(self) -> str:
        speed = "" if not self.has_speed else ", speed term"
        if self.speed is not None:
            speed += f", S={self.speed:g} m/s"
        return (f"ParametricSystem(n={self.n}, parameters={list(self.parameters)}, "
                f"outputs={list(self.output_names)}{speed})")

    def _vector(self, values: Sequence[float] | Mapping[str, float]) -> np.ndarray:
        if isinstance(values, Mapping):
            unknown = sorted(set(values) - set(self.parameters))
            if unknown:
                raise ValueError(f"values: unknown parameters {unknown}; parameters are {list(self.parameters)}")
            missing = [k for k in self.parameters if k not in values]
            if missing:
                raise ValueError(f"values: missing parameters {missing}")
            return np.array([number(k, values[k]) for k in self.parameters])
        return np.asarray(values)

    def _check(self, p: Sequence[float]) -> np.ndarray:
        p = np.asarray(p)
        if p.shape != (len(self.parameters),):
            raise ValueError(f"p: expected {len(self.parameters)} parameters {self.parameters}, got shape {p.shape}")
        if p.dtype == object or np.iscomplexobj(p) or p.dtype.kind in "USb":
            raise ValueError("p: parameters must be real numbers")
        p = p.astype(float)
        if not np.all(np.isfinite(p)):
            bad = [self.parameters[i] for i in np.flatnonzero(~np.isfinite(p))]
            raise ValueError(f"p: non-finite value for {bad}")
        return p

    def with_values(self, values: Sequence[float] | Mapping[str, float], speed: float | None = None
                    ) -> ParametricSystem:
        """The same family with other default parameter values (and speed); nothing is re-assembled."""
        new = object.__new__(ParametricSystem)
        new.__dict__.update(self.__dict__)
        new.values = self._check(self._vector(values))
        if speed is not None:
            new.speed = number("speed", speed, positive=True)
        return new

    # ------------------------------------------------------------------ members
    def _resolve_speed(self, speed: float | None) -> float | None:
        if speed is None:
            speed = self.speed
        if speed is None:
            if self.has_speed:
                raise ValueError("speed: this family has a speed term; give a forward speed S (m/s)")
            return None
        return number("speed", speed, positive=True)

    def _speed_parts(self, speed: float | None) -> tuple:
        """Forcings and outputs resolved at ``speed`` (cached: a campaign evaluates many p at one speed)."""
        if speed not in self._at_speed_cache:
            F0 = at_speed(self._F0, speed)
            Fs = at_speed(self._F_speed, speed)
            Fp = [at_speed(f, speed) for f in self._F]
            outputs = dict(self._base.outputs)
            for k, feed in self._distance_feeds.items():
                o = outputs[k]
                outputs[k] = Output(o.row, o.quantity, feed.at_speed(speed))
            if len(self._at_speed_cache) > 64:
                self._at_speed_cache.clear()
            self._at_speed_cache[speed] = (F0, Fs, Fp, outputs, self._forcing_plan(speed, F0, Fs, Fp))
        return self._at_speed_cache[speed]

    def _forcing_plan(self, speed: float | None, F0, Fs, Fp) -> list[tuple[float, np.ndarray, np.ndarray]] | None:
        """For polynomial forcings: per distinct delay, the constant coefficients and the (P, J, n) stack of the
        parameters' coefficients, so a member's F(p) is one :func:`affine` per delay (None: callable terms)."""
        forcings = [f for f in (F0, Fs, *Fp) if f is not None]
        if not all(f.is_polynomial for f in forcings):
            return None
        delays = sorted({t.delay for f in forcings for t in f.terms})
        J = max((t.coefficients.shape[0] for f in forcings for t in f.terms), default=1)
        n, P = self.n, len(self.parameters)
        plan = []
        for d in delays:
            base, stack = np.zeros((J, n), dtype=complex), np.zeros((P, J, n), dtype=complex)
            for weight, f, target in [(1.0, F0, base), (None if speed is None else 1.0 / speed, Fs, base)]:
                for t in (f.terms if f is not None else ()):
                    if t.delay == d:
                        target[: t.coefficients.shape[0]] += weight * t.coefficients
            for i, f in enumerate(Fp):
                for t in (f.terms if f is not None else ()):
                    if t.delay == d:
                        stack[i, : t.coefficients.shape[0]] += t.coefficients
            plan.append((d, base, stack))
        return plan

    def _forcing(self, p: np.ndarray, speed: float | None, F0, Fs, Fp) -> Forcing:
        weighted = [(1.0, F0)] if F0 is not None else []
        if Fs is not None:
            weighted.append((1.0 / speed, Fs))
        weighted += [(pi, f) for pi, f in zip(p, Fp, strict=True) if f is not None and pi != 0.0]
        if len(weighted) == 1 and weighted[0][0] == 1.0:
            return weighted[0][1]
        if not weighted:
            return as_forcing(np.zeros(self.n), self.n)
        return Forcing.combine(weighted)

    def at(self, p: Sequence[float] | Mapping[str, float] | None = None, speed: float | None = None) -> LinearSystem:
        """The :class:`LinearSystem` for parameters ``p`` at forward speed ``speed`` (no re-assembly).

        ``p`` (P,) or a mapping name → value; omitted: the family's own :attr:`values`.  ``speed`` in
        m/s; omitted: the family's own :attr:`speed` (required when the family has a speed term).
        """
        if p is None:
            if self.values is None:
                raise ValueError("p: this family has no default values; give the parameter vector p")
            p = self.values
        else:
            p = self._check(self._vector(p))
        speed = self._resolve_speed(speed)
        b = self._base
        C = affine(b.C, self._C, p)
        dC_dspeed = None
        if self._C_speed is not None:
            C = C + self._C_speed / speed
            dC_dspeed = -self._C_speed / speed**2
        F0, Fs, Fp, outputs, plan = self._speed_parts(speed)
        tangent = Tangent(self.parameters, p, self._M, self._C, self._K, tuple(Fp), speed, dC_dspeed,
                          self._speed_derivative(p, speed) if speed is not None else None)
        if plan is None:
            forcing = self._forcing(p, speed, F0, Fs, Fp)
        else:
            forcing = Forcing(terms=[DelayedTerm(d, coefficients=affine(base, stack, p)) for d, base, stack in plan]
                              or [DelayedTerm(0.0, coefficients=np.zeros((1, self.n), dtype=complex))])
        return LinearSystem._trusted(affine(b.M, self._M, p), C, affine(b.K, self._K, p), forcing, outputs,
                                     b.names, tangent)

    def stack(self, P: np.ndarray, speed: float | None = None) -> MemberStack:
        """The members for the rows of ``P`` (B, P) at one speed, as stacked arrays (no :class:`LinearSystem`
        per member): what a batch of designs needs for its band maxima or roots in one call.

        Raises
        ------
        ValueError
            If ``P`` is not (B, P) with finite values, or the family's forcing has callable terms (a batch needs
            the polynomial form, :meth:`at` handles the rest).
        """
        P = np.asarray(P, dtype=float)
        if P.ndim != 2 or P.shape[1] != len(self.parameters) or not np.all(np.isfinite(P)):
            raise ValueError(f"P: expected a finite (B, {len(self.parameters)}) array, got shape {P.shape}")
        speed = self._resolve_speed(speed)
        b = self._base
        C = affine(b.C, self._C, P)
        if self._C_speed is not None:
            C = C + self._C_speed / speed
        _, _, _, outputs, plan = self._speed_parts(speed)
        if plan is None:
            raise ValueError("P: the family's forcing has callable terms; a stack needs polynomial forcing")
        delays = np.array([d for d, _, _ in plan], dtype=float)
        coefficients = (np.stack([affine(base, parts, P) for _, base, parts in plan], axis=1) if plan
                        else np.zeros((len(P), 1, 1, self.n), dtype=complex))
        return MemberStack(affine(b.M, self._M, P), C, affine(b.K, self._K, P), delays if plan else np.zeros(1),
                           coefficients, outputs, b.names)

    def _speed_derivative(self, p: np.ndarray, speed: float):
        """``Ω -> ∂F/∂S`` at (p, S): the delays d/S and the F_speed/S term of every distance forcing."""
        terms = [(1.0, self._F0)] + [(pi, f) for pi, f in zip(p, self._F, strict=True) if pi != 0.0]
        distance = [(w, f) for w, f in terms if isinstance(f, DistanceForcing)]
        Fs = self._F_speed
        if not distance and Fs is None:
            return None

        def dF(omega: float) -> np.ndarray:
            out = np.zeros(self.n, dtype=complex)
            for w, f in distance:  # ∂/∂S e^{−iΩd/S} = (iΩd/S²) e^{−iΩd/S}
                for c, d in f.terms:
                    a = (1j * omega) ** np.arange(c.shape[0]) @ c
                    out += w * a * (1j * omega * d / speed**2) * np.exp(-1j * omega * d / speed)
            if Fs is not None:
                value = at_speed(Fs, speed).value(omega)
                out -= value / speed**2
                if isinstance(Fs, DistanceForcing):
                    for c, d in Fs.terms:
                        a = (1j * omega) ** np.arange(c.shape[0]) @ c
                        out += a * (1j * omega * d / speed**2) * np.exp(-1j * omega * d / speed) / speed
            return out

        return dF

    # ------------------------------------------------------------------ thin delegates
    def response_maxima(self, p: Sequence[float], band: object = None, *, band_hz: tuple[float, float] | None = None,
                        band_rad_s: tuple[float, float] | None = None, exact: bool = False,
                        output: str | None = None, speed: float | None = None):
        """f_k(p) of (4.71)-(4.73) over ``band_hz=`` (Hz) or ``band_rad_s=`` (rad/s);
        see :func:`railopt.models.response_maxima.response_maxima`."""
        return self.at(p, speed).response_maxima(band, band_hz=band_hz, band_rad_s=band_rad_s, exact=exact,
                                                 output=output)

    def response_maxima_jacobian(self, p: Sequence[float], band: object = None, *,
                                 band_hz: tuple[float, float] | None = None,
                                 band_rad_s: tuple[float, float] | None = None, exact: bool = False,
                                 output: str | None = None, speed: float | None = None):
        """f_k(p) and df_k/dp (n+2, P); see :func:`railopt.models.sensitivity.response_maxima_jacobian`."""
        from railopt.models.sensitivity import response_maxima_jacobian

        return response_maxima_jacobian(self.at(p, speed), band, band_hz=band_hz, band_rad_s=band_rad_s, exact=exact,
                                        output=output)

    def damped_frequency_jacobian(self, p: Sequence[float], speed: float | None = None) -> np.ndarray:
        """dω_dj/dp (n, P); see :func:`railopt.models.sensitivity.damped_frequency_jacobian`."""
        from railopt.models.sensitivity import damped_frequency_jacobian

        return damped_frequency_jacobian(self.at(p, speed))


__all__ = ["FamilyForcing", "MemberStack", "ParameterPart", "ParametricSystem", "affine"]
