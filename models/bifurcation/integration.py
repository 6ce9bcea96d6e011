"""How every trajectory of the bifurcation layer is integrated: the solver and its tolerances, in one record.

All integrations go through :func:`scipy.integrate.solve_ivp`.  The default is ``"LSODA"`` (ODEPACK; Adams for
non-stiff stretches, BDF with automatic switching where the problem turns stiff) with ``rtol = 1e-10``,
``atol = 1e-12``: a periodic orbit's fixed point is then accurate to about 1e-9 in the state's units, well
inside the Newton tolerance of :mod:`.periodic_orbit`.  ``"Radau"`` (implicit Runge–Kutta, order 5) and
``"BDF"`` are the stiff alternatives for a vehicle with stiff wheel/rail contact; explicit methods (``"RK45"``,
``"DOP853"``) suit non-stiff test systems.  Source: scipy.integrate.solve_ivp documentation; Hairer & Wanner,
*Solving Ordinary Differential Equations II* (Radau IIA); Petzold (1983), LSODA.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

METHODS = ("LSODA", "Radau", "BDF", "RK45", "DOP853", "RK23")
IMPLICIT = ("LSODA", "Radau", "BDF")  # the methods that use a Jacobian

RightHandSide = Callable[[float, np.ndarray, float], np.ndarray]
"""``rhs(t, x, speed) -> dx/dt``: t in s, x of shape (n,), speed in m/s, returns shape (n,) (state units/s)."""

Jacobian = Callable[[float, np.ndarray, float], np.ndarray]
"""``jacobian(t, x, speed) -> ∂f/∂x`` of shape (n, n)."""


class ModelLimit(ValueError):
    """Raised by a right-hand side whose model stops applying in the state reached (e.g. a wheel lifts off its rail).

    Not an input error: the trajectory left the region the model describes.  :func:`~.ramp.speed_ramp` records
    it as the verdict ``"model_limit"`` at that speed (the message as the reason) and starts the next speed from
    the ramp's initial state; everything else lets it propagate.
    """


@dataclass(frozen=True)
class IntegrationSettings:
    """Solver and tolerances handed to :func:`scipy.integrate.solve_ivp` for every trajectory.

    Attributes
    ----------
    method : str
        One of ``"LSODA"`` (default), ``"Radau"``, ``"BDF"`` (stiff), ``"RK45"``, ``"DOP853"``, ``"RK23"``.
    rtol, atol : float
        Relative and absolute local error tolerances (atol in the state's units).
    max_step : float
        Largest step (s); ``inf`` lets the solver choose.
    """

    method: str = "LSODA"
    rtol: float = 1e-10
    atol: float = 1e-12
    max_step: float = math.inf

    def __post_init__(self) -> None:
        if self.method not in METHODS:
            raise ValueError(f"method: {self.method!r} is not one of {METHODS}")
        for name in ("rtol", "atol", "max_step"):
            value = getattr(self, name)
            if not value > 0:
                raise ValueError(f"{name}: must be > 0, got {value!r}")

    def options(self) -> dict[str, object]:
        """The keyword arguments for :func:`scipy.integrate.solve_ivp` (method, rtol, atol, max_step)."""
        return {"method": self.method, "rtol": self.rtol, "atol": self.atol, "max_step": self.max_step}


def state_jacobian(rhs: RightHandSide, t: float, x: np.ndarray, speed: float) -> np.ndarray:
    """∂f/∂x of ``rhs`` at (t, x, speed) by central differences, shape (n, n).

    Step h_j = ε^(1/3)·max(|x_j|, 1) with ε the double-precision machine epsilon (truncation error O(h²), about
    1e-11 relative for smooth right-hand sides whose state is of order 1 or smaller).  2n calls of ``rhs``.
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    jac = np.empty((n, n))
    cube_root_eps = np.finfo(float).eps ** (1.0 / 3.0)
    for j in range(n):
        h = cube_root_eps * max(abs(x[j]), 1.0)
        up, down = x.copy(), x.copy()
        up[j] += h
        down[j] -= h
        jac[:, j] = (np.asarray(rhs(t, up, speed)) - np.asarray(rhs(t, down, speed))) / (2.0 * h)
    return jac


def speed_derivative(rhs: RightHandSide, t: float, x: np.ndarray, speed: float) -> np.ndarray:
    """∂f/∂speed of ``rhs`` at (t, x, speed) by central differences, shape (n,) (state units/s per m/s).

    Step h = ε^(1/3)·max(|speed|, 1) m/s.
    """
    h = np.finfo(float).eps ** (1.0 / 3.0) * max(abs(speed), 1.0)
    return (np.asarray(rhs(t, x, speed + h), dtype=float) - np.asarray(rhs(t, x, speed - h), dtype=float)) / (2 * h)


def check_state(x0: object, name: str = "x0") -> np.ndarray:
    """``x0`` as a finite float vector of shape (n,), n ≥ 2; ValueError naming ``name`` otherwise."""
    x = np.asarray(x0, dtype=float)
    if x.ndim != 1 or x.size < 2:
        raise ValueError(f"{name}: must be a state vector of shape (n,) with n >= 2, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{name}: must be finite")
    return x


__all__ = [
    "IMPLICIT",
    "METHODS",
    "IntegrationSettings",
    "Jacobian",
    "ModelLimit",
    "RightHandSide",
    "check_state",
    "speed_derivative",
    "state_jacobian",
]
