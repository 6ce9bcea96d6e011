"""Gravity-stiffness and track-roll terms of a wheelset (thesis (4.43)–(4.49)).

Each function returns the coefficient that multiplies a coordinate on the left-hand side of the
thesis's wheelset equations (so a positive value is a restoring stiffness).  ``W`` is the axle load
(N_r + N_l = W, N), ℓ₁₈ = 2 e0, ℓ₂₀ = r0 (see :mod:`railopt.models.contact.geometry`).

Lateral (4.43)→(4.44):  N_r(θ0 + 2εv/ℓ₁₈ − α_de) − N_l(θ0 − 2εv/ℓ₁₈ + α_de)
                         = (N_r − N_l) θ0 + (2Wε/ℓ₁₈) v − W α_de

Roll (4.45)→(4.46): the printed (4.45) terms combine to
    (ℓ₁₈/2 − ℓ₂₀ θ0)(N_r − N_l) + (−ηW − 2ℓ₂₀εW/ℓ₁₈) v + (ℓ₂₀ W) α_de.
The OCR of (4.46) prints ``+2ℓ₂₀εW/ℓ₁₈``; combining (4.45) term by term gives the minus sign, which is
also the moment −ℓ₂₀ × (lateral gravity force of (4.44)) of a force acting at rail level, ℓ₂₀ below
the axle.  We use the combined form (tested against the printed (4.45)).

Yaw (4.47)→(4.48): with N_l + N_r = W and the products (N_l − N_r) ε v γ dropped (second order),
the yaw gravitational stiffness is −(ℓ₁₈/2) θ0 W = −e0 θ0 W (negative).

Track roll (4.49): inertia ¼ ℓ₁₈² m_e (m_e the lumped track mass under the wheelset, both rails),
stiffness ½ ℓ₁₈² K'_e and damping ½ ℓ₁₈² C'_e (K'_e, C'_e per rail), coupling −W to the wheelset's
lateral displacement (and −W from α_de into the lateral equation (4.44)).
"""

from __future__ import annotations

from dataclasses import dataclass

from railopt.models.contact.geometry import WheelRailGeometry
from railopt.models.validation import number as finite
from railopt.models.validation import positive


def lateral_gravity_stiffness(W: float, geometry: WheelRailGeometry) -> float:
    """Lateral gravitational stiffness 2Wε/ℓ₁₈ = Wε/e0, N/m (coefficient of v in (4.44))."""
    return positive("W", W) * geometry.epsilon / geometry.e0


def lateral_track_roll_coupling(W: float) -> float:
    """Coefficient of the track roll α_de in the lateral equation (4.44): −W, N/rad."""
    return -positive("W", W)


def roll_gravity_stiffness(W: float, geometry: WheelRailGeometry) -> float:
    """Coefficient of v in the roll equation, −ηW − 2ℓ₂₀εW/ℓ₁₈ = −W(η + r0 ε/e0), N (from (4.45); see module doc)."""
    W = positive("W", W)
    return -geometry.eta * W - geometry.r0 * geometry.epsilon * W / geometry.e0


def roll_track_roll_coupling(W: float, geometry: WheelRailGeometry) -> float:
    """Coefficient of α_de in the wheelset roll equation (4.46): ℓ₂₀ W = r0 W, N·m/rad."""
    return positive("W", W) * geometry.r0


def roll_load_transfer_arm(geometry: WheelRailGeometry) -> float:
    """Coefficient of (N_r − N_l) in the roll equation (4.46): ℓ₁₈/2 − ℓ₂₀ θ0 = e0 − r0 θ0, m."""
    return geometry.e0 - geometry.r0 * geometry.theta0


def yaw_gravity_stiffness(W: float, geometry: WheelRailGeometry) -> float:
    """Yaw gravitational stiffness −(ℓ₁₈/2) θ0 W = −e0 θ0 W, N·m/rad (coefficient of γ in (4.48))."""
    return -geometry.e0 * geometry.theta0 * positive("W", W)


@dataclass(frozen=True)
class TrackRollTerms:
    """Track-roll coefficients of (4.49) for one wheelset (SI).

    Attributes
    ----------
    inertia : float
        Added roll inertia ¼ ℓ₁₈² m_e, kg·m².
    stiffness : float
        Roll stiffness ½ ℓ₁₈² K'_e, N·m/rad.
    damping : float
        Roll damping ½ ℓ₁₈² C'_e, N·m·s/rad.
    lateral_coupling : float
        Coefficient of the wheelset lateral displacement v in (4.49): −W, N.
    """

    inertia: float
    stiffness: float
    damping: float
    lateral_coupling: float


def track_roll_terms(W: float, e0: float, K_e_roll: float, C_e_roll: float, m_e: float) -> TrackRollTerms:
    """Track-roll terms of (4.49).

    Parameters
    ----------
    W : float
        Axle load, N.
    e0 : float
        Half the contact-point spacing (ℓ₁₈ = 2 e0), m.
    K_e_roll, C_e_roll : float
        K'_e (N/m) and C'_e (N·s/m) of one rail.
    m_e : float
        Lumped track mass under the wheelset (both rails, as in (4.41)), kg.
    """
    W = positive("W", W)
    e0 = positive("e0", e0)
    K = finite("K_e_roll", K_e_roll)
    C = finite("C_e_roll", C_e_roll)
    m = finite("m_e", m_e)
    if K < 0.0 or C < 0.0 or m < 0.0:
        raise ValueError("K_e_roll, C_e_roll, m_e: must be >= 0")
    l18 = 2.0 * e0
    return TrackRollTerms(
        inertia=0.25 * l18**2 * m, stiffness=0.5 * l18**2 * K, damping=0.5 * l18**2 * C, lateral_coupling=-W
    )


__all__ = [
    "TrackRollTerms", "lateral_gravity_stiffness", "lateral_track_roll_coupling", "roll_gravity_stiffness",
    "roll_load_transfer_arm", "roll_track_roll_coupling", "track_roll_terms", "yaw_gravity_stiffness",
]
