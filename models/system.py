"""The linear second-order system every railopt model returns.

``M x'' + C x' + K x = F(Ω) e^{iΩt}`` (thesis eqs. 4.62, 4.67) with real, possibly non-symmetric
``M, C, K`` (creep and gravity terms make them so) and a complex forcing amplitude that may depend
on the forcing frequency (base excitation through springs and dampers, axles delayed by their
distance over the speed: :class:`~railopt.models.forcing.Forcing`).  A system has one or more
named outputs, each a real row ``c`` applied to the displacement vector and differentiated
``q`` times in time (displacement, velocity, acceleration); all outputs share one
eigen-decomposition and one solve per frequency.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.linalg as sla

from railopt.models import response_maxima as maxima
from railopt.models.forcing import Forcing, ForcingLike, as_forcing
from railopt.models.kernels import c_array, direct_solutions, member_state, state_eigen_pairs, state_matrix
from railopt.models.modal import CONDITION_LIMIT, UNDAMPED_ROOT, Modal, modal, mode_order
from railopt.models.pole_residue import PoleResidue
from railopt.models.validation import frequencies_arg, real_array, square_matrix

if TYPE_CHECKING:  # pragma: no cover
    from railopt.models.response_maxima import ResponseMaxima

RESPONSE_ORDER = {"displacement": 0, "velocity": 1, "acceleration": 2}
SINGULAR_PIVOT = 1e-14  # relative LU pivot below which Z(Ω) counts as singular (response = inf)
DEFAULT_OUTPUT = "output"


@dataclass(frozen=True, eq=False)
class Output:
    """One output ``y = c·x + d(Ω)``: the real row ``c`` (n,), the quantity ``"displacement" |
    "velocity" | "acceleration"`` of y (units of x, per second, per second squared), and an optional
    feedthrough ``d(Ω)`` of the input itself (a one-component :class:`Forcing`), e.g. the rail
    displacement subtracted from a body displacement to give a suspension stroke."""

    row: np.ndarray
    quantity: str = "displacement"
    feedthrough: Forcing | None = None

    @property
    def order(self) -> int:
        """Derivative order of the quantity: 0 displacement, 1 velocity, 2 acceleration."""
        return RESPONSE_ORDER[self.quantity]

    def feedthrough_values(self, omega: np.ndarray) -> np.ndarray:
        """``d(Ω)`` at the frequencies (zeros without a feedthrough)."""
        w = np.asarray(omega, dtype=float).ravel()
        if self.feedthrough is None:
            return np.zeros(len(w), dtype=complex)
        return self.feedthrough.values(w)[:, 0]


def _output(name: str, spec: object, n: int) -> Output:
    feedthrough = None
    if isinstance(spec, Output):
        row, quantity, feedthrough = spec.row, spec.quantity, spec.feedthrough
    elif isinstance(spec, tuple) and len(spec) in (2, 3) and isinstance(spec[1], str):
        row, quantity, feedthrough = (*spec, None)[:3]
    else:
        row, quantity = spec, "displacement"
    if quantity not in RESPONSE_ORDER:
        raise ValueError(f"{name}.quantity: must be one of {sorted(RESPONSE_ORDER)}, got {quantity!r}")
    arr = real_array(name, row, shape=(n,))
    arr.setflags(write=False)
    if feedthrough is not None:
        feedthrough = as_forcing(feedthrough, 1, f"{name}.feedthrough")
    return Output(arr, quantity, feedthrough)


class LinearSystem:
    """A forced linear system ``M x'' + C x' + K x = F(Ω) e^{iΩt}`` with named outputs.

    Parameters
    ----------
    M, C, K : (n, n) array_like
        Mass, damping and stiffness matrices (SI, real; need not be symmetric). ``M`` nonsingular.
    F : (n,) array_like, callable or Forcing
        Complex forcing amplitude, constant or a function of the forcing frequency Ω (rad/s);
        use :meth:`Forcing.delayed` for axle inputs so that band maxima can be certified.
    output : (n,) array_like, optional
        One output row ``c`` (named ``"output"``), with ``response`` its quantity.
    response : {"displacement", "velocity", "acceleration"}
        Quantity of ``output``.
    names : sequence of str, optional
        Coordinate names, for tables and error messages.
    outputs : mapping name -> row, (row, quantity) or Output, optional
        Several named outputs instead of ``output``; the first is the default everywhere.
    """

    def __init__(
        self,
        M: np.ndarray,
        C: np.ndarray,
        K: np.ndarray,
        F: ForcingLike | None = None,
        output: np.ndarray | None = None,
        response: str = "displacement",
        names: Sequence[str] | None = None,
        outputs: Mapping[str, object] | None = None,
    ) -> None:
        self.M = square_matrix("M", M)
        n = self.M.shape[0]
        self.C = square_matrix("C", C, n)
        self.K = square_matrix("K", K, n)
        if output is not None and outputs is not None:
            raise ValueError("output: give one of output (a row) or outputs (a mapping of named rows), not both")
        if response not in RESPONSE_ORDER:
            raise ValueError(f"response: must be one of {sorted(RESPONSE_ORDER)}, got {response!r}")
        specs = {DEFAULT_OUTPUT: (output, response)} if output is not None else dict(outputs or {})
        self.outputs = {str(k): _output("output" if output is not None else f"outputs[{k!r}]", v, n)
                        for k, v in specs.items()}
        self.forcing = as_forcing(np.zeros(n) if F is None else F, n)
        self.names = tuple(names) if names is not None else tuple(f"x{i}" for i in range(n))
        if len(self.names) != n:
            raise ValueError(f"names: expected {n} names, got {len(self.names)}")
        self.tangent: Tangent | None = None
        self._prepare()

    @classmethod
    def _trusted(cls, M: np.ndarray, C: np.ndarray, K: np.ndarray, forcing: Forcing,
                 outputs: dict[str, Output], names: tuple[str, ...], tangent: Tangent | None = None) -> LinearSystem:
        """Fast path for a family's members: inputs already validated, only M re-checked."""
        self = cls.__new__(cls)
        self.M, self.C, self.K, self.forcing, self.outputs, self.names = M, C, K, forcing, outputs, names
        self.tangent = tangent
        self._prepare()
        return self

    def _prepare(self) -> None:
        """M⁻¹[K C] for the state matrix (4.53); a singular M is an error naming the field."""
        # M, C, K as the kernels take them (C-contiguous float64, copied only when not already so)
        self._mck = (c_array(self.M), c_array(self.C), c_array(self.K))
        self._minv_kc, regular = member_state(self._mck[0], self._mck[2], self._mck[1], 1e-14)
        if not regular:
            raise ValueError("M: is singular (a coordinate without inertia); eliminate it first")
        self._eigvals: np.ndarray | None = None
        self._modal: Modal | None = None
        self._eig: tuple[np.ndarray, np.ndarray] | None = None  # (s, V) of np.linalg.eig before any Modal record
        self._left: tuple[np.ndarray, float] | None = None  # (W, cond₁ V) worked out by the compiled path
        self._pole_residue: PoleResidue | None | bool = False  # False: not built yet

    # ------------------------------------------------------------------ properties
    @property
    def n(self) -> int:
        """Number of degrees of freedom."""
        return self.M.shape[0]

    @property
    def output_names(self) -> tuple[str, ...]:
        """Names of the output rows, in order (the first is the default output)."""
        return tuple(self.outputs)

    def _out(self, output: str | None) -> Output:
        if not self.outputs:
            raise ValueError("output: this system has no outputs (it was built for eigen-analysis only)")
        if output is None:
            return next(iter(self.outputs.values()))
        try:
            return self.outputs[output]
        except KeyError:
            raise ValueError(f"output: unknown output {output!r}; outputs are {list(self.outputs)}") from None

    @property
    def output(self) -> np.ndarray:
        """Row of the default (first) output."""
        return self._out(None).row

    @property
    def response(self) -> str:
        """Quantity of the default (first) output."""
        return self._out(None).quantity

    @property
    def order(self) -> int:
        """Derivative order of the default (first) output: 0 displacement, 1 velocity, 2 acceleration."""
        return self._out(None).order

    @property
    def parameters(self) -> tuple[str, ...]:
        """Names of the parameters whose derivatives the system carries (a family's member), else ()."""
        return () if self.tangent is None else self.tangent.parameters

    def __repr__(self) -> str:
        outs = ", ".join(f"{k} ({o.quantity})" for k, o in self.outputs.items())
        extra = "" if self.tangent is None else f", parameters={list(self.tangent.parameters)}"
        if self.tangent is not None and self.tangent.speed is not None:
            extra += f", speed={self.tangent.speed:g} m/s"
        return f"LinearSystem(n={self.n}, outputs=[{outs}], forcing={self.forcing!r}{extra})"

    # ------------------------------------------------------------------ eigen-analysis (4.51-4.58)
    def state_matrix(self) -> np.ndarray:
        """State matrix ``G = [[0, I], [-M⁻¹K, -M⁻¹C]]`` of thesis eq. (4.53), shape (2n, 2n)."""
        return state_matrix(self._minv_kc)

    def modal(self) -> Modal:
        """Roots s of G with right (V) and left (W = V⁻¹) eigenvectors, cached (eqs. 4.56-4.58)."""
        if self._modal is None:
            self._modal = Modal(*self._eig) if self._eig is not None else modal(self.state_matrix())
            if self._left is not None:
                self._modal.remember_left(*self._left)
        return self._modal

    def eigen_pairs(self) -> tuple[np.ndarray, np.ndarray]:
        """(s (2n,), V (2n, 2n)) complex128 of ``np.linalg.eig(G)`` (to rounding, by the compiled
        :func:`railopt.models.kernels.state_eigen_pairs`), cached, without building the :class:`Modal` record (the
        compiled certified path takes the arrays as they are); the same arrays :meth:`modal` then holds."""
        if self._modal is not None:
            return self._modal.s, self._modal.V
        if self._eig is None:
            self._eig = state_eigen_pairs(self._minv_kc)
        return self._eig

    def remember_left(self, W: np.ndarray, condition: float) -> None:
        """Keep W = V⁻¹ and cond₁(V) of :meth:`eigen_pairs` worked out by a compiled kernel, for :meth:`modal`."""
        if self._modal is not None:
            self._modal.remember_left(W, condition)
        else:
            self._left = (W, condition)

    def _roots(self) -> np.ndarray:
        """All 2n eigenvalues of G, unsorted, cached (vectors are computed only when asked for)."""
        if self._eigvals is None:
            if self._modal is not None:
                self._eigvals = self._modal.s
            elif self._eig is not None:
                self._eigvals = self._eig[0]
            else:
                self._eigvals = np.linalg.eigvals(self.state_matrix())
        return self._eigvals

    def eigenvalues(self) -> np.ndarray:
        """The 2n roots ``s_j = μ_j ± iω_dj`` of (4.58), 1/s, in railopt's one order: ascending |Im s|,
        then ascending Re s (:func:`~railopt.models.modal.mode_order`)."""
        s = self._roots()
        return s[mode_order(s)]

    def mode_roots(self) -> np.ndarray:
        """One root per mode, n values, in ascending order of ω_d = |Im s| (see :func:`mode_order`)."""
        s = self._roots()
        return s[mode_order(s)[1::2]]

    def undamped_modes(self) -> np.ndarray:
        """Boolean (n,): modes whose root lies on the imaginary axis to rounding (|Re s| ≤ UNDAMPED_ROOT·|s|)."""
        s = self.mode_roots()
        return (np.abs(s.real) <= UNDAMPED_ROOT * np.abs(s)) & (s.imag != 0)

    def damped_frequencies(self) -> np.ndarray:
        """Damped natural frequencies ω_dj (rad/s), n values sorted ascending (eq. 4.58)."""
        return np.abs(self.mode_roots().imag)

    def is_stable(self, tol: float = 0.0) -> bool:
        """True when every root has Re s ≤ tol (eq. 4.59)."""
        return bool(np.all(self._roots().real <= tol))

    def pole_residue(self) -> PoleResidue | None:
        """The pole–residue form of every output's H, or ``None`` when cond(V) > CONDITION_LIMIT."""
        if self._pole_residue is False:
            m = self.modal()
            if m.condition > CONDITION_LIMIT:
                self._pole_residue = None
            else:
                rows = np.array([o.row for o in self.outputs.values()])
                orders = np.array([o.order for o in self.outputs.values()])
                feedthroughs = [o.feedthrough for o in self.outputs.values()]
                self._pole_residue = PoleResidue(self.M, m, rows, orders, self.forcing, feedthroughs)
        return self._pole_residue

    # ------------------------------------------------------------------ frequency response (4.69)
    def impedance(self, omega: float | np.ndarray) -> np.ndarray:
        """``Z(Ω) = K − Ω²M + iΩC`` of thesis eq. (4.69): (n, n) at one Ω (rad/s), (N, n, n) stacked at the N
        frequencies of a 1-D array."""
        if np.ndim(omega) == 0:
            return self.K - omega**2 * self.M + 1j * omega * self.C
        w = np.asarray(omega, dtype=float)[:, None, None]
        return self.K[None] - w**2 * self.M[None] + 1j * w * self.C[None]

    def forcing_at(self, omega: float) -> np.ndarray:
        """``F(Ω)``; a non-finite value is an error naming the forcing (never a silent inf)."""
        F = np.asarray(self.forcing.value(omega), dtype=complex)
        if not np.all(np.isfinite(F)):
            raise ValueError(f"F: the forcing returned a non-finite value at Ω = {omega:g} rad/s")
        return F

    def solve(self, omega: float) -> np.ndarray:
        """Complex amplitude ``X = Z⁻¹F`` (eq. 4.70); all-inf when Z is singular."""
        return self.solve_many(np.array([omega]))[0]

    def solve_many(self, omegas: np.ndarray) -> np.ndarray:
        """``X(Ω)`` at several frequencies, shape (N, n); rows of inf where Z(Ω) is singular."""
        w = np.asarray(omegas, dtype=float).ravel()
        F = np.array([self.forcing_at(float(x)) for x in w], dtype=complex).reshape(len(w), self.n)
        X = np.full((len(w), self.n), np.inf + 0j)
        for i, x in enumerate(w):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", sla.LinAlgWarning)
                try:
                    lu = sla.lu_factor(self.impedance(float(x)), check_finite=False)
                except (ValueError, np.linalg.LinAlgError):
                    continue
            pivots = np.abs(np.diag(lu[0]))
            if np.min(pivots) > SINGULAR_PIVOT * np.max(pivots):
                X[i] = sla.lu_solve(lu, F[i], check_finite=False)
        return X

    def frf_outputs(self, omega: object = None, *, frequencies_hz: object = None,
                    omega_rad_s: object = None) -> np.ndarray:
        """Complex FRF of every output by direct solves, shape (N, m) (eqs. 4.69-4.70), at ``frequencies_hz=``
        (Hz) or ``omega_rad_s=`` (rad/s) (:func:`~railopt.models.validation.frequencies_arg`).

        ``H_o(Ω) = (iΩ)^q_o c_o·Z(Ω)⁻¹F(Ω)``; a singular Z (an undamped resonance hit exactly)
        gives ``inf``.
        """
        self._out(None)  # a system without outputs has no response
        w = frequencies_arg(omega, frequencies_hz, omega_rad_s)
        F = np.array([self.forcing_at(float(x)) for x in w], dtype=complex).reshape(len(w), self.n)
        try:
            X, overflow = direct_solutions(*self._mck, c_array(w),
                                           c_array(F, complex))
        except np.linalg.LinAlgError:  # a singular Z somewhere: point by point with pivot checks
            X, overflow = self.solve_many(w), np.zeros(len(w), dtype=bool)
        if overflow.any():
            raise ValueError(f"omega: Z(Ω) = K − Ω²M + iΩC overflows at {w[overflow][:3].tolist()} rad/s; "
                             "no response can be computed there")
        rows = np.array([o.row for o in self.outputs.values()])
        orders = np.array([o.order for o in self.outputs.values()])
        with np.errstate(over="ignore", invalid="ignore"):
            H = (X @ rows.T + self._feedthroughs(w)) * (1j * w[:, None]) ** orders[None, :]
        H[~np.isfinite(H)] = np.inf
        return H

    def _feedthroughs(self, w: np.ndarray) -> np.ndarray | float:
        """``d_o(Ω)`` of every output, (N, m), or 0 when no output has one."""
        if all(o.feedthrough is None for o in self.outputs.values()):
            return 0.0
        return np.column_stack([o.feedthrough_values(w) for o in self.outputs.values()])

    @property
    def max_delay(self) -> float | None:
        """Largest declared delay of the forcing and the feedthroughs (s); None if any is undeclared."""
        largest = self.forcing.max_delay
        for o in self.outputs.values():
            if o.feedthrough is not None:
                if largest is None or o.feedthrough.max_delay is None:
                    return None
                largest = max(largest, o.feedthrough.max_delay)
        return largest

    def output_index(self, output: str | None) -> int:
        """Column of ``output`` in :meth:`frf_outputs` (0 for the default)."""
        self._out(output)
        return 0 if output is None else list(self.outputs).index(output)

    def frf(self, omega: object = None, output: str | None = None, *, frequencies_hz: object = None,
            omega_rad_s: object = None) -> complex | np.ndarray:
        """Complex frequency response of one output at ``frequencies_hz=`` (Hz) or ``omega_rad_s=`` (rad/s),
        scalar or array (direct solves)."""
        shape = np.shape(frequencies_hz if frequencies_hz is not None else omega_rad_s)
        w = frequencies_arg(omega, frequencies_hz, omega_rad_s)
        h = self.frf_outputs(omega_rad_s=w)[:, self.output_index(output)]
        return complex(h[0]) if len(shape) == 0 else h.reshape(shape)

    def magnitude(self, omega: object = None, output: str | None = None, *, frequencies_hz: object = None,
                  omega_rad_s: object = None) -> float | np.ndarray:
        """``f(Ω) = |H(Ω)|``: the real-valued transfer function of (4.71)."""
        return np.abs(self.frf(omega, output, frequencies_hz=frequencies_hz, omega_rad_s=omega_rad_s))

    # ------------------------------------------------------------------ thin delegates (railopt.models.response_maxima)
    def response_maxima(self, band: object = None, *, band_hz: tuple[float, float] | None = None,
                        band_rad_s: tuple[float, float] | None = None, exact: bool = False,
                        output: str | None = None) -> ResponseMaxima:
        """The n+2 response maxima f_k of (4.71)-(4.73) over ``band_hz=`` (Hz) or ``band_rad_s=`` (rad/s);
        see :func:`railopt.models.response_maxima.response_maxima`."""
        return maxima.response_maxima(self, band, band_hz=band_hz, band_rad_s=band_rad_s, exact=exact, output=output)

    def peak(self, band: object = None, *, band_hz: tuple[float, float] | None = None,
             band_rad_s: tuple[float, float] | None = None, exact: bool = True, output: str | None = None) -> float:
        """``U = max_k f_k`` (4.74) over ``band_hz=`` (Hz) or ``band_rad_s=`` (rad/s);
        see :func:`railopt.models.response_maxima.peak`."""
        return maxima.peak(self, band, band_hz=band_hz, band_rad_s=band_rad_s, exact=exact, output=output)


@dataclass(frozen=True, eq=False)
class Tangent:
    """Derivatives of a family member's matrices with respect to its parameters and its speed.

    A :class:`~railopt.models.parametric.ParametricSystem` attaches one to every system it builds, so
    analyses of sensitivity (:mod:`railopt.models.sensitivity`) need only the system.

    Attributes
    ----------
    parameters : tuple of str
        Parameter names, length P.
    p : (P,) ndarray
        Parameter values of this member (SI).
    dM, dC, dK : (P, n, n) ndarray
        ∂M/∂p_i, ∂C/∂p_i, ∂K/∂p_i.
    dF : tuple of Forcing or None
        ∂F/∂p_i (None where F does not depend on p_i).
    speed : float or None
        Forward speed S of this member, m/s (None for a family without a speed term).
    dC_dspeed : (n, n) ndarray or None
        ∂C/∂S (= −C_speed/S²).
    dF_dspeed : callable or None
        ``Ω -> ∂F/∂S (n,)`` at this speed (delays d/S and creep inputs F_speed/S), or None.
    """

    parameters: tuple[str, ...]
    p: np.ndarray
    dM: np.ndarray
    dC: np.ndarray
    dK: np.ndarray
    dF: tuple[Forcing | None, ...]
    speed: float | None = None
    dC_dspeed: np.ndarray | None = None
    dF_dspeed: object = None

    @property
    def creep_damping(self) -> np.ndarray | None:
        """C_speed (n, n) of the family's creep term C(S) = C₀ + C_speed/S, read back as −S²·∂C/∂S; None without
        one (or without a speed)."""
        if self.dC_dspeed is None or self.speed is None:
            return None
        S = float(self.speed)
        return -(S * S) * np.asarray(self.dC_dspeed, dtype=float)


__all__ = ["DEFAULT_OUTPUT", "LinearSystem", "Output", "RESPONSE_ORDER", "SINGULAR_PIVOT", "Tangent"]
