"""Axes, coordinate names and small-motion kinematics of rigid bodies.

Convention (ours, ISO 8855 style, right-handed): x forward, y to the left, z up, origin at rail
level under the vehicle centre; rotations α (roll about x), β (pitch about y), γ (yaw about z) are
right-handed.  Each body has six coordinates ``"<body>.u", ".v", ".w", ".alpha", ".beta", ".gamma"``.

The thesis's printed equations fix its signs (not a right-handed set): lateral v positive to the
right, vertical w positive up, roll α and yaw γ as ours, pitch β opposite to ours.  So
``u_th = u, v_th = -v, w_th = w, α_th = α, β_th = -β, γ_th = γ`` (:data:`THESIS_SIGNS`) and a
thesis matrix equals ``D M D`` with ``D = diag(THESIS_SIGNS)`` of ours.  Evidence: (B.1.48) and
(B.1.1)–(B.1.3) (v, α, γ), (4.12)–(4.18) (creep: v, β, γ), (4.41) (w, β).
"""

from __future__ import annotations

import numpy as np

DOFS: tuple[str, ...] = ("u", "v", "w", "alpha", "beta", "gamma")
LATERAL_DOFS: tuple[str, ...] = ("v", "alpha", "gamma")
VERTICAL_DOFS: tuple[str, ...] = ("u", "w", "beta")
THESIS_SIGNS: dict[str, float] = {"u": 1.0, "v": -1.0, "w": 1.0, "alpha": 1.0, "beta": -1.0, "gamma": 1.0}


def coordinate(body: str, dof: str) -> str:
    """Name of one coordinate, e.g. ``coordinate("body", "v") == "body.v"``."""
    if dof not in DOFS:
        raise ValueError(f"unknown coordinate {dof!r}; valid: {', '.join(DOFS)}")
    return f"{body}.{dof}"


def split(name: str) -> tuple[str, str]:
    """``"frame_front.gamma" -> ("frame_front", "gamma")``."""
    body, _, dof = name.rpartition(".")
    return body, dof


def point_jacobian(r: np.ndarray) -> np.ndarray:
    """(3, 6) matrix giving the small displacement of a point at ``r`` (m, from the CG).

    ``δ = [u, v, w] + θ × r`` with ``θ = [α, β, γ]``; columns in :data:`DOFS` order.
    """
    rx, ry, rz = (float(c) for c in r)
    return np.array(
        [
            [1.0, 0.0, 0.0, 0.0, rz, -ry],
            [0.0, 1.0, 0.0, -rz, 0.0, rx],
            [0.0, 0.0, 1.0, ry, -rx, 0.0],
        ]
    )


def unit(vector: np.ndarray, what: str) -> np.ndarray:
    """Normalised copy of a direction; raises naming ``what`` when it is zero or not finite."""
    v = np.asarray(vector, dtype=float)
    n = float(np.linalg.norm(v))
    if v.shape != (3,) or not np.isfinite(n) or n == 0.0:
        raise ValueError(f"{what}: direction must be a finite non-zero 3-vector, got {vector!r}")
    return v / n


__all__ = ["DOFS", "LATERAL_DOFS", "THESIS_SIGNS", "VERTICAL_DOFS", "coordinate", "point_jacobian", "split", "unit"]
