"""Linear wheel/rail contact of one wheelset: creep forces, gravity stiffness, track roll.

Thesis §4.2.1–4.2.2 and §4.2.4, in our axes (x forward, y left, z up; right wheel at y = −e0).
Creepages per wheel, with S the forward speed (4.11)–(4.18)::

    ξx,left  = (u̇ − r0 β̇ − e0 γ̇)/S − λ (v − v_rail)/r0
    ξx,right = (u̇ − r0 β̇ + e0 γ̇)/S + λ (v − v_rail)/r0
    ξy       = v̇/S + r0 (α̇ − α̇_track)/S − γ            ξsp = γ̇/S

Forces on the wheel (4.9): ``Fx = −f11 ξx``, ``Fy = −f22 ξy + f23 ξsp``, ``Mz = −f23 ξy − f33 ξsp``
(the thesis's ``T_y = −f2 ξy − f23 ξsp``, ``M_z = −f32 ξy − f3 ξsp``, ``f32 = −f23`` written in our axes,
whose lateral axis is opposite to the thesis's).  They act at the contact points (0, ±e0, −r0).

Gravity (4.43)–(4.48), with W the load per wheelset: lateral ``W ε/e0 (v − v_rail) − W α_track``
acting against v, roll ``(W η + r0 ε W/e0) v + r0 W α_track`` and the yaw gravitational stiffness
``−W e0 θ0``.  Track roll (4.49): the weight W at lateral offset v rolls the track, ``+W v`` in its
roll row; contact forces are internal to wheelset + track, so the track roll row receives minus the
wheelset's contact roll moments.

Terms multiplying velocities come as ``C_creep`` (divide by S); the others are speed-independent.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Creep:
    """Linear creep coefficients of one wheel: f11, f22 (N), f23 (N·m), f33 (N·m²) (4.9)."""

    f11: float
    f22: float
    f23: float = 0.0
    f33: float = 0.0

    def __post_init__(self) -> None:
        for name in ("f11", "f22", "f23", "f33"):
            v = getattr(self, name)
            if not math.isfinite(v) or (name in ("f11", "f22", "f33") and v < 0.0):
                raise ValueError(f"creep coefficient {name} must be finite (and >= 0 for f11, f22, f33), got {v!r}")

    def scaled(self, factor: float) -> Creep:
        """All coefficients times ``factor`` (the usual correction factor on theory)."""
        return Creep(self.f11 * factor, self.f22 * factor, self.f23 * factor, self.f33 * factor)


@dataclass(frozen=True)
class WheelRail:
    """Wheel/rail parameters of one wheelset (SI).

    Attributes
    ----------
    conicity : float
        Effective conicity λ.
    r0 : float
        Rolling radius in the central position (thesis l20), m.
    e0 : float
        Half the distance between the contact points (thesis l18/2), m.
    creep : Creep
        Per-wheel creep coefficients (already scaled by any correction factor).
    axle_load : float
        W, gravity force per wheelset, N.
    theta0, epsilon, eta : float
        Contact angle, rate of change of contact angle (rad/m · e0) and of contact distance (4.1)–(4.4).
    spin : bool
        Keep f23, f33.
    gravity_stiffness : bool
        Keep the W terms (gravity stiffness and track-roll coupling).
    """

    conicity: float
    r0: float
    e0: float
    creep: Creep
    axle_load: float = 0.0
    theta0: float = 0.0
    epsilon: float = 0.0
    eta: float = 0.0
    spin: bool = True
    gravity_stiffness: bool = True

    def __post_init__(self) -> None:
        for name in ("conicity", "r0", "e0", "axle_load", "theta0", "epsilon", "eta"):
            v = getattr(self, name)
            if not math.isfinite(v):
                raise ValueError(f"contact {name} must be finite, got {v!r}")
        if self.r0 <= 0.0 or self.e0 <= 0.0:
            raise ValueError("contact: wheel radius r0 and semi-gauge e0 must be positive (m)")
        if self.conicity < 0.0 or self.axle_load < 0.0:
            raise ValueError("contact: conicity and axle load must be >= 0")
        if self.e0 - self.r0 * self.theta0 <= 0.0:
            raise ValueError("contact: e0 - r0*theta0 must be positive (psi of (4.8))")

    @property
    def psi(self) -> float:
        """ψ = θ0/(e0 − r0 θ0) (4.8): wheelset roll per unit lateral displacement."""
        return self.theta0 / (self.e0 - self.r0 * self.theta0)


def contact_matrices(
    wr: WheelRail,
    index: Mapping[str, int],
    wheelset: str,
    track_roll: str | None,
    rail_lateral: str | None,
    track_body: str | None,
    n: int,
) -> tuple[np.ndarray, np.ndarray]:
    """Contributions ``(K, C_creep)`` of one wheelset's contact, the damping being ``C_creep / S``.

    Parameters
    ----------
    wr : WheelRail
    index : mapping coordinate name -> row
    wheelset : str
        Wheelset body name.
    track_roll : str or None
        Coordinate of the track roll under the wheelset (a track body's ``.alpha`` or a prescribed
        cross-level input); None for none.
    rail_lateral : str or None
        Coordinate of the rail's lateral position (prescribed alignment input), or None.
    track_body : str or None
        Name of the lumped track body whose roll row takes the reactions (flexible track).
    n : int
        Number of coordinates.
    """
    K = np.zeros((n, n))
    Cc = np.zeros((n, n))
    r0, e0, lam = wr.r0, wr.e0, wr.conicity
    f11, f22 = wr.creep.f11, wr.creep.f22
    f23, f33 = (wr.creep.f23, wr.creep.f33) if wr.spin else (0.0, 0.0)
    W = wr.axle_load if wr.gravity_stiffness else 0.0

    def c(dof: str) -> int:
        return index[f"{wheelset}.{dof}"]

    u, v, a, b, g = c("u"), c("v"), c("alpha"), c("beta"), c("gamma")
    ta = index[track_roll] if track_roll else None
    rv = index[rail_lateral] if rail_lateral else None

    def add(M: np.ndarray, row: int, col: int | None, value: float) -> None:
        if col is not None:
            M[row, col] += value

    # lateral creep force (and its roll moment r0 Fy about the wheelset centre)
    for row, arm in ((v, 1.0), (a, r0)):
        add(K, row, g, -2.0 * f22 * arm)
        add(Cc, row, v, 2.0 * f22 * arm)
        add(Cc, row, a, 2.0 * f22 * r0 * arm)
        add(Cc, row, ta, -2.0 * f22 * r0 * arm)
        add(Cc, row, g, -2.0 * f23 * arm)
    # yaw: longitudinal creep couple, spin moment
    add(K, g, v, 2.0 * e0 * lam * f11 / r0)
    add(K, g, rv, -2.0 * e0 * lam * f11 / r0)
    add(K, g, g, -2.0 * f23 - W * e0 * wr.theta0)
    add(Cc, g, g, 2.0 * e0**2 * f11 + 2.0 * f33)
    add(Cc, g, v, 2.0 * f23)
    add(Cc, g, a, 2.0 * f23 * r0)
    add(Cc, g, ta, -2.0 * f23 * r0)
    # longitudinal creep: fore-aft and spin-perturbation (pitch) rows (4.40), (4.42)
    add(Cc, u, u, 2.0 * f11)
    add(Cc, u, b, -2.0 * r0 * f11)
    add(Cc, b, u, -2.0 * r0 * f11)
    add(Cc, b, b, 2.0 * r0**2 * f11)
    # gravity stiffness and track roll (4.43)-(4.49)
    k_lat = W * wr.epsilon / e0
    add(K, v, v, k_lat)
    add(K, v, rv, -k_lat)
    add(K, v, ta, W)
    k_roll = W * wr.eta + r0 * W * wr.epsilon / e0
    add(K, a, v, k_roll)
    add(K, a, rv, -k_roll)
    add(K, a, ta, r0 * W)
    if track_body is not None:
        t = index[f"{track_body}.alpha"]
        K[t, :] -= K[a, :]
        Cc[t, :] -= Cc[a, :]
        add(K, t, v, W)  # the weight at lateral offset v - v_rail rolls the track (4.49)
        add(K, t, rv, -W)
    return K, Cc


__all__ = ["Creep", "WheelRail", "contact_matrices"]
