"""Suspension elements: linear springs and dampers between two bodies (or a body and ground).

An element acts along a unit direction between a point on body A and a point on body B; its
deformation is the relative displacement of the two points projected on the direction,
``Δ = d · (δ_A − δ_B)``, so it adds ``value · g gᵀ`` to K (spring) or C (damper) with ``g`` the
row that maps all coordinates to Δ.  A rotational element does the same with the relative
rotation about an axis.  Elements sharing an id share one parameter: the parameter's weight
matrix is the sum of ``g gᵀ`` over them (``K = K0 + Σ p_i K_i``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from railopt.models.vehicle.geometry import DOFS, coordinate, point_jacobian, unit

GROUND = "ground"
ELEMENT_TYPES = {
    "spring": ("K", False),
    "damper": ("C", False),
    "rotational_spring": ("K", True),
    "rotational_damper": ("C", True),
}
VALUE_KEYS = {
    "spring": "stiffness_N_per_m",
    "damper": "damping_N_s_per_m",
    "rotational_spring": "stiffness_N_m_per_rad",
    "rotational_damper": "damping_N_m_s_per_rad",
}


@dataclass(frozen=True)
class Element:
    """One spring or damper.

    Attributes
    ----------
    id : str
        Parameter id (thesis K1…K12, C1…C18 or any name); elements with one id share its value.
    alias : str
        Readable parameter name, e.g. ``"secondary_lateral_stiffness"``.
    type : str
        ``"spring"``, ``"damper"``, ``"rotational_spring"`` or ``"rotational_damper"``.
    body_a, body_b : str
        Body names; ``body_b`` may be ``"ground"``.
    point_a, point_b : tuple of float
        Attachment points relative to each body's CG, m (vehicle axes); on ground, absolute.
    direction : tuple of float
        Unit line of action (translational) or rotation axis (rotational), vehicle axes.
    value : float
        N/m, N·s/m, N·m/rad or N·m·s/rad according to ``type``.
    source : str
        Origin of the value (``"estimate"`` when estimated).
    """

    id: str
    alias: str
    type: str
    body_a: str
    point_a: tuple[float, float, float]
    body_b: str
    point_b: tuple[float, float, float]
    direction: tuple[float, float, float]
    value: float
    source: str = "estimate"

    def __post_init__(self) -> None:
        if self.type not in ELEMENT_TYPES:
            raise ValueError(f"element {self.id!r}: type must be one of {sorted(ELEMENT_TYPES)}, got {self.type!r}")
        if not math.isfinite(self.value) or self.value < 0.0:
            raise ValueError(f"element {self.id!r}: value must be finite and >= 0, got {self.value!r}")
        if self.body_a == self.body_b:
            raise ValueError(f"element {self.id!r}: body_a and body_b are both {self.body_a!r}")
        object.__setattr__(self, "direction", tuple(unit(self.direction, f"element {self.id!r}")))
        for name in ("point_a", "point_b"):
            p = tuple(float(c) for c in getattr(self, name))
            if len(p) != 3 or not all(math.isfinite(c) for c in p):
                raise ValueError(f"element {self.id!r}: {name} must be 3 finite numbers (m)")
            object.__setattr__(self, name, p)

    @property
    def matrix(self) -> str:
        """``"K"`` for springs, ``"C"`` for dampers."""
        return ELEMENT_TYPES[self.type][0]

    @property
    def rotational(self) -> bool:
        """True for rotational springs and dampers (N·m/rad, N·m·s/rad), False for translational ones."""
        return ELEMENT_TYPES[self.type][1]

    def mirrored_y(self) -> Element:
        """The mirror image in the x–z plane (y → −y on points and on a translational direction)."""
        d = np.array(self.direction)
        d = d * (np.array([-1.0, 1.0, -1.0]) if self.rotational else np.array([1.0, -1.0, 1.0]))
        pa, pb = np.array(self.point_a), np.array(self.point_b)
        pa[1], pb[1] = -pa[1], -pb[1]
        return Element(self.id, self.alias, self.type, self.body_a, tuple(pa), self.body_b, tuple(pb), tuple(d),
                       self.value, self.source)

    def row(self, index: Mapping[str, int], n: int) -> np.ndarray:
        """Row ``g`` (n,) with ``Δ = g · z``: the element deformation per unit coordinates ``z``."""
        g = np.zeros(n)
        d = np.asarray(self.direction)
        for body, point, sign in ((self.body_a, self.point_a, 1.0), (self.body_b, self.point_b, -1.0)):
            if body == GROUND:
                continue
            if self.rotational:
                local = np.r_[np.zeros(3), d]
            else:
                local = d @ point_jacobian(np.asarray(point))
            for dof, value in zip(DOFS, local, strict=True):
                g[index[coordinate(body, dof)]] += sign * value
        return g

    def unit_matrix(self, index: Mapping[str, int], n: int) -> np.ndarray:
        """``g gᵀ``: the element's contribution to K or C per unit value."""
        g = self.row(index, n)
        return np.outer(g, g)


__all__ = ["ELEMENT_TYPES", "Element", "GROUND", "VALUE_KEYS"]
