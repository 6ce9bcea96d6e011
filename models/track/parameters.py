"""Rail sections and a conventional wooden-tie track of the thesis's era (1970s North America).

The thesis prints no track data; these are documented estimates.

* Rail: AREA 132 RE (132 lb/yd), I = 88.2 in⁴ (3.671e-5 m⁴), A = 12.95 in², E = 30e6 lb/in²
  (206.8 GPa) — the heavy-haul section of the period; 115 RE (I = 65.6 in⁴) is the lighter option.
* Track modulus u = 3000 lb/in² per rail (20.7 MN/m²): good wooden-tie track on crushed-stone
  ballast (the AREA range is roughly 1000–5000 lb/in²; 2000–3000 for sound wooden-tie track).
* Effective mass: the thesis's f0 ≈ 62 Hz (4.35) with u = 3000 lb/in² needs
  m = k/(2π·62)² = 136 kg/m per rail: the rail (65.5 kg/m) plus about 3/4 of the tie mass share
  (a 200 lb tie every 19.5 in gives 91.6 kg/m per rail).  Rail alone gives 89 Hz, rail plus the
  full tie share 58 Hz; see :func:`f0_table`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pandas as pd

from railopt.models.track.beam import Beam
from railopt.models.units import INCH, LB_PER_YARD, POUND_MASS, PSI, hz_to_rad_s, rad_s_to_hz

E_STEEL = 30.0e6 * PSI  # Pa
TRACK_MODULUS = 3000.0 * PSI  # N/m² per rail
TIE_MASS = 200.0 * POUND_MASS  # kg, 7 in x 9 in x 8 ft 6 in hardwood tie
TIE_SPACING = 19.5 * INCH  # m
THESIS_F0 = 62.0  # Hz, §4.2.3


@dataclass(frozen=True)
class RailSection:
    """A rail section: name, second moment of area I (m⁴), area (m²), mass per length (kg/m)."""

    name: str
    I: float  # noqa: E741 - the engineering symbol
    area: float
    mass: float
    E: float = E_STEEL

    @property
    def EI(self) -> float:
        """Bending stiffness, N·m²."""
        return self.E * self.I


RAIL_132RE = RailSection("132 RE", I=88.2 * INCH**4, area=12.95 * INCH**2, mass=132.0 * LB_PER_YARD)
RAIL_115RE = RailSection("115 RE", I=65.6 * INCH**4, area=11.25 * INCH**2, mass=115.0 * LB_PER_YARD)
RAILS = {r.name: r for r in (RAIL_132RE, RAIL_115RE)}


def tie_mass_per_rail() -> float:
    """Mass of the ties per unit length and per rail, kg/m (half a tie per spacing)."""
    return 0.5 * TIE_MASS / TIE_SPACING


def mass_for_frequency(k: float, f0: float = THESIS_F0) -> float:
    """Effective mass per length giving ``f0 = sqrt(k/m)/2π`` (4.35), kg/m."""
    return k / hz_to_rad_s(f0) ** 2


def wooden_tie_track(rail: RailSection = RAIL_132RE, k: float = TRACK_MODULUS, f0: float = THESIS_F0) -> Beam:
    """The conventional wooden-tie track used for Figs 3.3–3.9: one rail, m chosen for ``f0``."""
    return Beam(EI=rail.EI, m=mass_for_frequency(k, f0), k=k)


def f0_table(rail: RailSection = RAIL_132RE) -> pd.DataFrame:
    """f0 (4.35) for track moduli 2000–4000 lb/in² and three effective-mass assumptions."""
    rows = []
    ties = tie_mass_per_rail()
    for u in (2000.0, 2500.0, 3000.0, 3500.0, 4000.0):
        k = u * PSI
        for label, m in (
            ("rail only", rail.mass),
            ("rail + ties", rail.mass + ties),
            ("m for 62 Hz", mass_for_frequency(k)),
        ):
            rows.append(
                {
                    "u_lb_in2": u,
                    "k_N_m2": k,
                    "mass": label,
                    "m_kg_m": m,
                    "f0_Hz": rad_s_to_hz(math.sqrt(k / m)),
                }
            )
    return pd.DataFrame(rows)


__all__ = [
    "E_STEEL", "RAILS", "RAIL_115RE", "RAIL_132RE", "RailSection", "THESIS_F0", "TIE_MASS", "TIE_SPACING",
    "TRACK_MODULUS", "f0_table", "mass_for_frequency", "tie_mass_per_rail", "wooden_tie_track",
]
