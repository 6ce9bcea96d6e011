"""The flow from a point of the Poincaré section to its next crossing, with the variational equations.

Alongside the state x (n,) the integrator carries W = [Φ | s] (n × (n+1)):

    ẋ = f(x, V),   Φ̇ = J(x, V) Φ,  Φ(0) = I,   ṡ = J(x, V) s + ∂f/∂V,  s(0) = 0,

J = ∂f/∂x.  At the return time τ, Φ(τ) is the monodromy matrix when x(0) lies on a periodic orbit and
s(τ) = ∂x(τ)/∂V at fixed time (Seydel, *Practical Bifurcation and Stability Analysis*, 3rd ed., Springer
2010, chapter on periodic solutions; Parker & Chua, *Practical Numerical Algorithms for Chaotic Systems*,
Springer 1989).  J and ∂f/∂V come from the caller's
``jacobian`` when given, else from central differences of ``rhs`` (:func:`.integration.state_jacobian`).

The section event is armed only after ``t_arm`` (the start lies on the section, where solve_ivp would report a
crossing at t = 0): the first stage [0, t_arm] runs without events, the second stops at the first crossing.
For the implicit methods the augmented system gets the Jacobian blockdiag(J, J ⊗ I_{n+1}) (the second
derivatives of f in the coupling block are left out: only the solver's Newton iteration uses it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.integrate import solve_ivp

from railopt.models.bifurcation.integration import (
    IMPLICIT,
    IntegrationSettings,
    Jacobian,
    RightHandSide,
    speed_derivative,
    state_jacobian,
)
from railopt.models.bifurcation.section import PoincareSection
from railopt.records import ArrayRecord


@dataclass(frozen=True, eq=False, repr=False)
class SectionReturn(ArrayRecord):
    """One trip from the section back to it.

    Attributes
    ----------
    returned : bool
        False when no crossing came before ``t_max`` (then the other fields hold the state at t_max).
    time : float
        Return time τ (s).
    state : (n,) ndarray
        x(τ), on the section when ``returned``.
    monodromy : (n, n) ndarray
        Φ(τ) = ∂x(τ)/∂x(0) at fixed time.
    speed_sensitivity : (n,) ndarray
        s(τ) = ∂x(τ)/∂V at fixed time (state units per m/s).
    velocity : (n,) ndarray
        f(x(τ), V).
    message : str
        The solver's message.
    """

    returned: bool
    time: float
    state: np.ndarray
    monodromy: np.ndarray
    speed_sensitivity: np.ndarray
    velocity: np.ndarray
    message: str

    def map_jacobian(self, section: PoincareSection) -> tuple[np.ndarray, np.ndarray]:
        """The Poincaré map's derivatives on the free coordinates: (DP (n−1, n−1), ∂P/∂V (n−1,)).

        With the return time τ(x) fixed by x_i(τ) = value: dτ = −e_iᵀ(Φ dx + s dV)/f_i, so
        dP = (I − f e_iᵀ/f_i)(Φ dx + s dV).
        """
        n = self.state.size
        i = section.index
        f = self.velocity
        if f[i] == 0.0:
            raise ValueError("section: the orbit touches the section tangentially (f_i = 0)")
        projector = np.eye(n) - np.outer(f, np.eye(n)[i]) / f[i]
        free = section.free(n)
        dp = (projector @ self.monodromy)[np.ix_(free, free)]
        dv = (projector @ self.speed_sensitivity)[free]
        return dp, dv


def flow_to_section(rhs: RightHandSide, x0: np.ndarray, speed: float, section: PoincareSection, *,
                    t_arm: float, t_max: float, settings: IntegrationSettings,
                    jacobian: Jacobian | None = None) -> SectionReturn:
    """Integrate x and W = [Φ | s] from ``x0`` until the next crossing of ``section`` after ``t_arm``.

    Parameters
    ----------
    rhs : callable
        ``rhs(t, x, speed) -> (n,)``, autonomous (t is passed but must not matter for a periodic orbit).
    x0 : (n,) ndarray
        Start (normally on the section).
    speed : float
        The parameter (m/s).
    section : PoincareSection
    t_arm, t_max : float
        The crossing counts only after t_arm (s); none by t_max (s) gives ``returned = False``.
    settings : IntegrationSettings
    jacobian : callable, optional
        ``jacobian(t, x, speed) -> (n, n)``; central differences of ``rhs`` when omitted.

    Returns
    -------
    SectionReturn
    """
    n = x0.size
    m = n + 1

    def jac_x(t: float, x: np.ndarray) -> np.ndarray:
        return np.asarray(jacobian(t, x, speed), dtype=float) if jacobian is not None \
            else state_jacobian(rhs, t, x, speed)

    def augmented(t: float, y: np.ndarray) -> np.ndarray:
        x = y[:n]
        w = y[n:].reshape(n, m)
        jx = jac_x(t, x)
        dw = jx @ w
        dw[:, n] += speed_derivative(rhs, t, x, speed)
        return np.concatenate([np.asarray(rhs(t, x, speed), dtype=float), dw.ravel()])

    options = settings.options()
    if settings.method in IMPLICIT:
        sparse = settings.method != "LSODA"

        def augmented_jac(t: float, y: np.ndarray) -> np.ndarray | sp.csr_matrix:
            jx = jac_x(t, y[:n])
            block = sp.block_diag([sp.csr_matrix(jx), sp.kron(sp.csr_matrix(jx), sp.identity(m))], format="csr")
            return block if sparse else block.toarray()

        options["jac"] = augmented_jac

    w0 = np.zeros((n, m))
    w0[:, :n] = np.eye(n)
    y0 = np.concatenate([x0, w0.ravel()])
    first = solve_ivp(augmented, (0.0, t_arm), y0, **options)
    if first.status != 0:
        return _trip(False, first.t[-1], first.y[:, -1], n, rhs, speed, first.message)
    second = solve_ivp(augmented, (t_arm, t_max), first.y[:, -1], events=section.event(), **options)
    if second.status == 1 and second.t_events[0].size:
        return _trip(True, float(second.t_events[0][0]), second.y_events[0][0], n, rhs, speed, second.message)
    return _trip(False, second.t[-1], second.y[:, -1], n, rhs, speed, second.message)


def _trip(returned: bool, t: float, y: np.ndarray, n: int, rhs: RightHandSide, speed: float,
          message: str) -> SectionReturn:
    w = y[n:].reshape(n, n + 1)
    x = y[:n].copy()
    return SectionReturn(returned, float(t), x, w[:, :n].copy(), w[:, n].copy(),
                         np.asarray(rhs(t, x, speed), dtype=float), str(message))


__all__ = [
    "SectionReturn",
    "flow_to_section",
]
