"""Lumped equivalent of the track under a wheelset (thesis §4.2.3, (4.33)–(4.39), and (4.49)).

Per rail (the :class:`~railopt.models.track.beam.Beam` is one rail on its foundation):

* ``K_e = P / y(0) = 2k/β`` (4.37) — Hetényi's stiffness under the load, β = (k/4EI)^{1/4} (4.38);
* ``l_e = 2/β`` (4.39) and ``m_e = m l_e`` so that ``sqrt(K_e/m_e) = sqrt(k/m) = 2π f0`` (4.35)–(4.36);
* ``C_e = 2 ζ_e sqrt(K_e m_e)`` for a chosen damping ratio ζ_e.  With ``ζ_e = c / 2√(km)`` this is
  exactly ``c l_e``, so the distributed and the lumped damping ratios agree.

Wheelset (rail pair).  The vertical equation (4.41) carries one spring, mass and damper under the
wheelset, i.e. both rails in parallel: ``K_e,pair = 2 K_e``, ``m_e,pair = 2 m_e``, ``C_e,pair = 2 C_e``.
Roll (4.49): the track under the wheelset rolls by α about the track centre line, so each rail moves
``± (ℓ/2) α`` with ``ℓ`` (the thesis's ℓ₁₈) the lateral spacing of the two wheel/rail contact points.
Two rail springs ``K'_e`` give the roll stiffness ``2 K'_e (ℓ/2)² = ½ ℓ² K'_e`` and two rail masses
``m_e,pair / 2`` give the roll inertia ``2 (m_e,pair/2)(ℓ/2)² = ¼ ℓ² m_e,pair`` — exactly the terms
``½ ℓ₁₈² K'_e``, ``½ ℓ₁₈² C'_e`` and ``¼ ℓ₁₈² m_e`` of (4.49) when ``m_e`` there is the pair mass of
(4.41).  Hence ``K'_e = K_e`` and ``C'_e = C_e`` are the per-rail values.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import pandas as pd

from railopt.models.track.beam import Beam
from railopt.models.units import rad_s_to_hz
from railopt.records import ArrayRecord


@dataclass(frozen=True, eq=False, repr=False)
class LumpedTrack(ArrayRecord):
    """Lumped track parameters (SI).

    Attributes
    ----------
    l_e : float
        Effective rail length ``2/β``, m (4.39).
    f0 : float
        Natural frequency ``sqrt(k/m)/2π``, Hz (4.35).
    K_e, m_e, C_e : float
        Per rail: stiffness ``2k/β`` (N/m), mass ``m l_e`` (kg), damping (N·s/m) (4.36)–(4.37).
    K_e_pair, m_e_pair, C_e_pair : float
        Both rails under one wheelset, for the vertical equation (4.41): N/m, kg, N·s/m.
    K_e_prime, C_e_prime : float
        ``K'_e``, ``C'_e`` of (4.49): per-rail stiffness (N/m) and damping (N·s/m).
    roll_stiffness, roll_damping, roll_inertia : float
        ``½ℓ²K'_e`` (N·m/rad), ``½ℓ²C'_e`` (N·m·s/rad), ``¼ℓ² m_e,pair`` (kg·m²) of (4.49).
    contact_spacing : float
        ℓ (ℓ₁₈), lateral distance between the two contact points, m.
    damping_ratio : float
        ζ_e used for ``C_e``.
    """

    l_e: float
    f0: float
    K_e: float
    m_e: float
    C_e: float
    K_e_pair: float
    m_e_pair: float
    C_e_pair: float
    K_e_prime: float
    C_e_prime: float
    roll_stiffness: float
    roll_damping: float
    roll_inertia: float
    contact_spacing: float
    damping_ratio: float

    def to_pandas(self) -> pd.DataFrame:
        """One-row table of all fields."""
        return pd.DataFrame([asdict(self)])


def lumped(beam: Beam, damping_ratio: float, contact_spacing: float = 1.5) -> LumpedTrack:
    """Lumped mass–spring–damper equivalent of the track (4.33)–(4.39) and its roll terms (4.49).

    Parameters
    ----------
    beam : Beam
        One rail on its foundation (axial force and damping of the beam are not used).
    damping_ratio : float
        ζ_e >= 0 giving ``C_e = 2 ζ_e sqrt(K_e m_e)``; pass ``beam.damping_ratio`` for ``c l_e``.
    contact_spacing : float, optional
        ℓ₁₈, lateral distance between the wheel/rail contact points, m.  Default 1.5 m (standard
        gauge 1.435 m plus a rail-head width).

    Returns
    -------
    LumpedTrack
    """
    damping_ratio = float(damping_ratio)
    if not math.isfinite(damping_ratio) or damping_ratio < 0.0:
        raise ValueError(f"damping_ratio: must be a finite non-negative number, got {damping_ratio!r}")
    contact_spacing = float(contact_spacing)
    if not math.isfinite(contact_spacing) or contact_spacing <= 0.0:
        raise ValueError(f"contact_spacing: must be a positive length (m), got {contact_spacing!r}")
    b = beam.beta
    l_e = 2.0 / b
    K_e = 2.0 * beam.k / b
    m_e = beam.m * l_e
    C_e = 2.0 * damping_ratio * math.sqrt(K_e * m_e)
    half = 0.5 * contact_spacing**2
    return LumpedTrack(
        l_e=l_e,
        f0=rad_s_to_hz(math.sqrt(K_e / m_e)),
        K_e=K_e,
        m_e=m_e,
        C_e=C_e,
        K_e_pair=2.0 * K_e,
        m_e_pair=2.0 * m_e,
        C_e_pair=2.0 * C_e,
        K_e_prime=K_e,
        C_e_prime=C_e,
        roll_stiffness=half * K_e,
        roll_damping=half * C_e,
        roll_inertia=0.25 * contact_spacing**2 * 2.0 * m_e,
        contact_spacing=contact_spacing,
        damping_ratio=damping_ratio,
    )


__all__ = ["LumpedTrack", "lumped"]
