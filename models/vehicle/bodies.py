"""Rigid bodies of a vehicle model (SI units)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

KINDS = ("body", "wheelset", "track")


@dataclass(frozen=True)
class Body:
    """A rigid body.

    Attributes
    ----------
    name : str
        Unique name; its coordinates are ``"<name>.u"`` … ``"<name>.gamma"``.
    mass : float
        kg.
    inertia : tuple of tuple of float
        3×3 inertia tensor about the CG in the vehicle axes, kg·m² (principal → diagonal).
    cg : tuple of float
        CG position ``(x, y, z)`` in the vehicle frame, m (x forward, y left, z up from rail level).
    kind : str
        ``"body"``, ``"wheelset"`` (gets wheel/rail contact) or ``"track"`` (lumped track mass).
    source : str
        Where the numbers come from (``"estimate"`` when estimated).
    """

    name: str
    mass: float
    inertia: tuple[tuple[float, float, float], ...]
    cg: tuple[float, float, float]
    kind: str = "body"
    source: str = "estimate"

    def __post_init__(self) -> None:
        if not self.name or "." in self.name:
            raise ValueError(f"body name must be non-empty without '.', got {self.name!r}")
        if not math.isfinite(self.mass) or self.mass < 0.0:
            raise ValueError(f"body {self.name!r}: mass must be finite and >= 0 kg, got {self.mass!r}")
        inertia = np.asarray(self.inertia, dtype=float)
        if inertia.shape == (3,):
            inertia = np.diag(inertia)
        if inertia.shape != (3, 3) or not np.all(np.isfinite(inertia)):
            raise ValueError(f"body {self.name!r}: inertia must be 3 values or a finite 3x3 tensor")
        if np.any(np.diag(inertia) < 0.0) or not np.allclose(inertia, inertia.T):
            raise ValueError(f"body {self.name!r}: inertia must be symmetric with non-negative diagonal")
        cg = tuple(float(c) for c in self.cg)
        if len(cg) != 3 or not all(math.isfinite(c) for c in cg):
            raise ValueError(f"body {self.name!r}: cg must be 3 finite numbers (m)")
        if self.kind not in KINDS:
            raise ValueError(f"body {self.name!r}: kind must be one of {KINDS}, got {self.kind!r}")
        object.__setattr__(self, "inertia", tuple(tuple(float(x) for x in row) for row in inertia))
        object.__setattr__(self, "cg", cg)

    @property
    def mass_matrix(self) -> np.ndarray:
        """(6, 6) mass matrix in (u, v, w, α, β, γ) about the CG, kg and kg·m²."""
        m = np.zeros((6, 6))
        m[:3, :3] = self.mass * np.eye(3)
        m[3:, 3:] = np.asarray(self.inertia)
        return m


__all__ = ["Body", "KINDS"]
