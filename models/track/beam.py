"""The track beam: an infinite Euler beam on a Kelvin foundation with an axial force (thesis Ch. 3).

Governing equation (3.2), SI units, deflection ``y`` positive in the direction of the load::

    EI y'''' + N y'' + m y_tt + c y_t + k y = q(x, t)

``N > 0`` is compression (a rise in rail temperature), ``N < 0`` tension.  All parameters are per
rail: ``EI`` of one rail, ``k`` the track modulus per rail, ``m`` the effective mass per unit length
of one rail with its share of the ties, ``c`` the foundation damping per unit length.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from railopt.models.units import rad_s_to_hz
from railopt.models.validation import number as _check_finite


def _check_positive(name: str, value: float) -> float:
    value = _check_finite(name, value)
    if value <= 0.0:
        raise ValueError(f"{name}: must be positive, got {value!r}")
    return value


@dataclass(frozen=True)
class Beam:
    """Infinite Euler beam on a Kelvin foundation with axial force, equation (3.2).

    Parameters
    ----------
    EI : float
        Bending stiffness of one rail, N·m².
    m : float
        Effective mass per unit length (rail plus participating tie mass), kg/m.
    k : float
        Foundation (track) modulus per rail, N/m² (force per unit length per unit deflection).
    c : float, optional
        Foundation viscous damping per unit length, N·s/m².  Default 0.
    N : float, optional
        Axial force, N; positive in compression.  Must be below the buckling load
        ``N_cr = 2 sqrt(k EI)``: at and above it the straight beam is not an equilibrium
        (§3.2.3) and none of the solutions of this package apply.

    Raises
    ------
    ValueError
        If ``EI``, ``m`` or ``k`` are not positive, ``c`` is negative, any value is NaN or
        infinite, or ``N >= N_cr``.  The message names the field.
    """

    EI: float
    m: float
    k: float
    c: float = 0.0
    N: float = 0.0

    def __post_init__(self) -> None:
        for name in ("EI", "m", "k"):
            object.__setattr__(self, name, _check_positive(name, getattr(self, name)))
        c = _check_finite("c", self.c)
        if c < 0.0:
            raise ValueError(f"c: must be non-negative, got {c!r}")
        object.__setattr__(self, "c", c)
        n = _check_finite("N", self.N)
        n_cr = self.buckling_load()
        if n >= n_cr:
            raise ValueError(
                f"N = {n:.6g} N must be below the buckling load N_cr = 2 sqrt(k EI) = {n_cr:.6g} N; "
                "the straight beam is not an equilibrium there (thesis §3.2.3)"
            )
        object.__setattr__(self, "N", n)

    # --- derived constants -------------------------------------------------------------------
    @property
    def beta(self) -> float:
        """Hetényi's wavenumber ``β = (k / 4EI)^(1/4)``, 1/m (ω of (3.19), (4.38))."""
        return (self.k / (4.0 * self.EI)) ** 0.25

    @property
    def omega0(self) -> float:
        """Rigid-body frequency of the rail on its foundation ``sqrt(k/m)``, rad/s (4.33)."""
        return math.sqrt(self.k / self.m)

    @property
    def f0(self) -> float:
        """Natural frequency ``sqrt(k/m) / 2π``, Hz (4.35)."""
        return rad_s_to_hz(self.omega0)

    @property
    def critical_damping(self) -> float:
        """Critical damping ``c_cr = 2 sqrt(k m)``, N·s/m² (corrected (3.27))."""
        return 2.0 * math.sqrt(self.k * self.m)

    @property
    def damping_ratio(self) -> float:
        """Damping ratio ``c / c_cr = c / (2 sqrt(k m))``, dimensionless."""
        return self.c / self.critical_damping

    @property
    def axial_ratio(self) -> float:
        """``N / N_cr``, dimensionless (negative in tension)."""
        return self.N / self.buckling_load()

    def buckling_load(self) -> float:
        """Buckling load of the beam on its foundation ``N_cr = 2 sqrt(k EI)``, N."""
        return 2.0 * math.sqrt(self.k * self.EI)

    def critical_velocity(self) -> float:
        """Critical velocity ``v_cr = sqrt((2 sqrt(k EI) - N) / m)``, m/s.

        This is the minimum phase velocity of free waves of the undamped beam (3.3).  The
        transcript's (3.4) lost a square root: ``4kEI/m²`` must read ``2 sqrt(kEI)/m``.  Always
        real because ``N < N_cr`` is enforced on construction.
        """
        return math.sqrt((self.buckling_load() - self.N) / self.m)

    # --- constructors ------------------------------------------------------------------------
    @classmethod
    def from_ratios(
        cls, EI: float, m: float, k: float, damping_ratio: float = 0.0, axial_ratio: float = 0.0
    ) -> Beam:
        """Build a beam from the damping ratio ``c/c_cr`` and the axial ratio ``N/N_cr``.

        Parameters
        ----------
        EI, m, k : float
            As in :class:`Beam` (N·m², kg/m, N/m²).
        damping_ratio : float
            ``c / (2 sqrt(k m))``, dimensionless, >= 0.
        axial_ratio : float
            ``N / (2 sqrt(k EI))``, dimensionless, < 1 (negative for tension).
        """
        damping_ratio = _check_finite("damping_ratio", damping_ratio)
        axial_ratio = _check_finite("axial_ratio", axial_ratio)
        if damping_ratio < 0.0:
            raise ValueError(f"damping_ratio: must be non-negative, got {damping_ratio!r}")
        if axial_ratio >= 1.0:
            raise ValueError(f"axial_ratio: N/N_cr must be below 1, got {axial_ratio!r}")
        EI, m, k = (_check_positive(n, v) for n, v in (("EI", EI), ("m", m), ("k", k)))
        c = damping_ratio * 2.0 * math.sqrt(k * m)
        N = axial_ratio * 2.0 * math.sqrt(k * EI)
        return cls(EI=EI, m=m, k=k, c=c, N=N)

    def with_(self, **changes: float) -> Beam:
        """A copy with some fields changed (validated again)."""
        unknown = set(changes) - {"EI", "m", "k", "c", "N"}
        if unknown:
            raise ValueError(f"unknown Beam field(s): {sorted(unknown)}")
        fields = {"EI": self.EI, "m": self.m, "k": self.k, "c": self.c, "N": self.N}
        fields.update(changes)
        return Beam(**fields)


def hetenyi_deflection(x: np.ndarray | float, P: float, k: float, EI: float) -> np.ndarray:
    """Hetényi's static deflection of an infinite beam on a Winkler foundation, equation (3.19).

    ``y = P β / (2k) e^{-β|x|} (cos β|x| + sin β|x|)``, ``β = (k / 4EI)^{1/4}``.

    Parameters
    ----------
    x : array_like
        Distance from the load, m.
    P : float
        Load, N (positive in the direction of the deflection).
    k : float
        Foundation modulus, N/m².
    EI : float
        Bending stiffness, N·m².

    Returns
    -------
    numpy.ndarray
        Deflection, m, same shape as ``x``.
    """
    beta = (k / (4.0 * EI)) ** 0.25
    ax = beta * np.abs(np.asarray(x, dtype=float))
    return P * beta / (2.0 * k) * np.exp(-ax) * (np.cos(ax) + np.sin(ax))


__all__ = ["Beam", "hetenyi_deflection"]
