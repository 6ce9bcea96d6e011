"""The likely slip behind an out-of-range value: which unit or power of ten brings it back into its usual band.

A value written in the wrong unit is off by that unit's factor (mm for m: ×1000; kN/m for N/m: ÷1000; per cent
for a ratio: ×100); a slipped decimal point is off by a power of ten.  :func:`rescalings` tries the named units
of the quantity first, then every power of ten from 10⁻³ to 10³, and keeps those that land the value in the
quantity's usual band; :func:`likely_slip` words the one or two most likely as ``"looks like mm: 1280 → 1.28
m?"`` — or nothing when no rescaling lands in the band, so a warning never suggests a wrong value (conicity 1.5
is 10× of 0.15, not per cent of 0.015: with the band 0.02–0.5 only the first lands).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from railopt.models.units import FOOT, INCH, LB_PER_YARD, PSI

Units = Sequence[tuple[str, float]]
"""``(label, factor)`` pairs: the value written in unit ``label`` times ``factor`` is the SI value."""

LENGTH_UNITS: Units = (("mm", 1e-3), ("cm", 1e-2), ("inches", INCH), ("feet", FOOT))
RATIO_UNITS: Units = (("per cent", 1e-2),)
MASS_UNITS: Units = (("tonnes", 1e3),)
INERTIA_UNITS: Units = (("t·m²", 1e3),)
STIFFNESS_UNITS: Units = (("kN/m (or N/mm)", 1e3), ("MN/m", 1e6))
DAMPING_UNITS: Units = (("kN·s/m", 1e3),)
ROTATIONAL_STIFFNESS_UNITS: Units = (("kN·m/rad", 1e3), ("MN·m/rad", 1e6))
ROTATIONAL_DAMPING_UNITS: Units = (("kN·m·s/rad", 1e3),)
FORCE_UNITS: Units = (("kN", 1e3), ("MN", 1e6))
MODULUS_UNITS: Units = (("MN/m² (MPa)", 1e6), ("lb/in²", PSI), ("GPa", 1e9))
BENDING_UNITS: Units = (("kN·m²", 1e3), ("MN·m²", 1e6), ("N·mm²", 1e-6))
MASS_PER_LENGTH_UNITS: Units = (("t/m", 1e3), ("lb/yd", LB_PER_YARD))
ANGLE_UNITS: Units = (("degrees", math.pi / 180.0),)
IMPERIAL = frozenset({"inches", "feet", "lb/in²", "lb/yd"})  # named after the powers of ten: rarer in a metric file
POWERS = tuple(k for k in range(-3, 4) if k != 0)  # 10^k tried after the named units (a slipped point or two)


def rescalings(value: float, band: tuple[float, float], units: Units = ()) -> list[tuple[str, float]]:
    """The rescalings of ``value`` that land in ``band``: ``[(label, corrected value), ...]``, named units first.

    Parameters
    ----------
    value : float
        The value as loaded (SI).
    band : (float, float)
        The usual band of the quantity (inclusive), same unit.
    units : sequence of (label, factor)
        Units the quantity is often written in by mistake; ``value × factor`` is what was meant.

    Returns
    -------
    list of (str, float)
        Each rescaling that lands: the metric named units in their order, then powers of ten ("10× too large",
        "1000× too small", ...) not already covered by a named unit (the nearest first), then the imperial units
        (:data:`IMPERIAL`); empty when none lands or ``value`` is zero or not finite.
    """
    if not math.isfinite(value) or value == 0.0:
        return []
    lo, hi = band
    out: list[tuple[str, float]] = []
    factors: list[float] = []
    for label, factor in units:
        x = value * factor
        if lo <= abs(x) <= hi:
            out.append((label, x))
            factors.append(factor)
    for k in POWERS:
        factor = 10.0 ** k
        if any(math.isclose(factor, f, rel_tol=1e-9) for f in factors):
            continue
        x = value * factor
        if lo <= abs(x) <= hi:
            label = f"{10.0 ** -k:g}× too large" if k < 0 else f"{factor:g}× too small"
            out.append((label, x))
    named = [r for r in out if not r[0].endswith(("too large", "too small"))]
    powers = sorted((r for r in out if r not in named), key=lambda r: abs(math.log10(abs(r[1] / value))))
    late = [r for r in named if r[0] in IMPERIAL]
    return [r for r in named if r not in late] + powers + late


def likely_slip(value: float, band: tuple[float, float], units: Units = (), unit: str = "") -> str:
    """The likely slip in words: ``"looks like mm: 1280 → 1.28 m?"``; ``""`` when no rescaling lands in ``band``.

    Parameters
    ----------
    value, band, units
        As for :func:`rescalings`.
    unit : str
        The SI unit printed after the corrected value (``"m"``, ``"N/m"``; ``""`` for a ratio).

    Returns
    -------
    str
        One candidate: ``"looks like <unit label>: <value> → <corrected> <unit>?"`` (``"looks 10× too large: …"``
        for a power of ten); two or more: the two most likely, ``"looks like <label> (<value> → <corrected>
        <unit>) or <label> (→ <corrected> <unit>)?"``.
    """
    found = rescalings(value, band, units)
    u = f" {unit}" if unit else ""
    if not found:
        return ""
    if len(found) == 1:
        label, x = found[0]
        return f"looks {_like(label)}: {value:g} → {x:.4g}{u}?"
    (l1, x1), (l2, x2) = found[:2]
    return f"looks {_like(l1)} ({value:g} → {x1:.4g}{u}) or {_like(l2)} (→ {x2:.4g}{u})?"


def _like(label: str) -> str:
    return label if label.endswith(("too large", "too small")) else f"like {label}"


__all__ = [
    "ANGLE_UNITS", "BENDING_UNITS", "DAMPING_UNITS", "FORCE_UNITS", "IMPERIAL", "INERTIA_UNITS", "LENGTH_UNITS",
    "MASS_PER_LENGTH_UNITS", "MASS_UNITS", "MODULUS_UNITS", "POWERS", "RATIO_UNITS", "ROTATIONAL_DAMPING_UNITS",
    "ROTATIONAL_STIFFNESS_UNITS", "STIFFNESS_UNITS", "Units", "likely_slip", "rescalings",
]
