"""Linearised wheel/rail contact geometry (thesis §4.2.1, (4.1)–(4.8)).

Conventions (the thesis's): ``v`` is the wheelset's lateral displacement, positive towards the
**right** rail; ``α_de`` the roll of the track under the wheelset.  Per unit ``v``

* contact-plane angles  θ_r = θ0 + ε v/e0 − α_de,  θ_l = θ0 − ε v/e0 + α_de          (4.1)–(4.2)
* contact positions     e_r = e0 − η v,            e_l = e0 + η v                      (4.3)–(4.4)
  (distances from the track centre line, as the list of symbols defines e_l, e_r and η)
* rolling radii         r_r = r0 + λ v,            r_l = r0 − λ v                      (4.5)–(4.6)
* roll constraint       α_d = −ψ v,  ψ = θ0/(e0 − r0 θ0)                              (4.7)–(4.8)

Thesis length symbols: ℓ₁₈ = 2 e0 (lateral spacing of the contact points, see the yaw creep term
ℓ₁₈² f1/(2S) = 2 e0² f1/S of (4.47)) and ℓ₂₀ = r0 (the pitch/roll creep arms of (4.40), (4.42), (4.44)).

Circular-arc profiles (Wickens' model, the thesis's Figure 4.3): a concave wheel tread of transverse
radius R_w on a rail head of radius R_r < R_w, nominal contact angle δ0.  The first-order expansions
of the exact geometry (both centre distances stay R_w − R_r; derivation in ``docs/contact.md``) are,
with D = R_w − R_r and d = e0 cos δ0 − r0 sin δ0:

    λ = R_w sin δ0 (e0 + R_r sin δ0) / (d D)
    ε = e0 (e0 + R_w sin δ0) / (d D)
    η = R_r cos δ0 (e0 + R_w sin δ0) / (d D)
    roll per unit v = sin δ0 / d   (→ ψ of (4.8) for small δ0)

For small angles λ reduces to Wickens' δ0 R_w (e0 + R_r δ0)/((R_w − R_r)(e0 − r0 δ0)); a coned wheel
(R_w → ∞) on a knife-edge rail (R_r = 0) gives ε = λ, as the thesis says for new wheels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from railopt.models.validation import number as finite
from railopt.models.validation import positive


@dataclass(frozen=True)
class WheelRailGeometry:
    """Linearised geometry of one wheelset on its two rails (SI units).

    Attributes
    ----------
    r0 : float
        Rolling radius in the central position, m.
    e0 : float
        Half the lateral distance between the two contact points, m (ℓ₁₈ = 2 e0).
    conicity : float
        Effective conicity λ = d r_r / d v, dimensionless (4.5)–(4.6).
    theta0 : float
        Contact-plane angle θ0 in the central position, rad (4.1)–(4.2).
    epsilon : float
        ε = e0 dθ_r/dv, dimensionless (4.1)–(4.2); equals λ for new coned wheels.
    eta : float
        η = −d e_r/dv, dimensionless (4.3)–(4.4).
    """

    r0: float
    e0: float
    conicity: float
    theta0: float
    epsilon: float
    eta: float = 0.0

    def __post_init__(self) -> None:
        positive("r0", self.r0)
        positive("e0", self.e0)
        for name in ("conicity", "theta0", "epsilon", "eta"):
            finite(name, getattr(self, name))
        if self.e0 - self.r0 * self.theta0 <= 0.0:
            raise ValueError("theta0: e0 - r0*theta0 must be > 0 for the roll constraint (4.8)")

    # -- derived constants ---------------------------------------------------------------------
    @property
    def psi(self) -> float:
        """ψ = θ0 / (e0 − r0 θ0), rad/m (4.8)."""
        return self.theta0 / (self.e0 - self.r0 * self.theta0)

    @property
    def l18(self) -> float:
        """Thesis ℓ₁₈ = 2 e0, m."""
        return 2.0 * self.e0

    @property
    def l20(self) -> float:
        """Thesis ℓ₂₀ = r0, m."""
        return self.r0

    # -- (4.1)–(4.7) ------------------------------------------------------------------------------
    def contact_angles(self, v: float, alpha_de: float = 0.0) -> tuple[float, float]:
        """(θ_r, θ_l), rad, for lateral displacement ``v`` (m) and track roll ``alpha_de`` (rad) (4.1)–(4.2)."""
        d = self.epsilon * v / self.e0
        return self.theta0 + d - alpha_de, self.theta0 - d + alpha_de

    def contact_distances(self, v: float) -> tuple[float, float]:
        """(e_r, e_l), m, from the track centre line (4.3)–(4.4)."""
        return self.e0 - self.eta * v, self.e0 + self.eta * v

    def rolling_radii(self, v: float) -> tuple[float, float]:
        """(r_r, r_l), m (4.5)–(4.6)."""
        return self.r0 + self.conicity * v, self.r0 - self.conicity * v

    def roll(self, v: float) -> float:
        """Wheelset roll α_d = −ψ v, rad (4.7)."""
        return -self.psi * v

    # -- constructors ---------------------------------------------------------------------------
    @classmethod
    def coned(cls, r0: float, e0: float, conicity: float) -> WheelRailGeometry:
        """New coned wheels on knife-edge rails: θ0 = ε = λ, η = 0 (thesis §4.2.1, "for new wheels ε becomes λ")."""
        lam = finite("conicity", conicity)
        return cls(r0=r0, e0=e0, conicity=lam, theta0=lam, epsilon=lam, eta=0.0)

    @classmethod
    def from_circular_profiles(
        cls, r0: float, e0: float, delta0: float, R_wheel: float, R_rail: float
    ) -> WheelRailGeometry:
        """Geometry of circular-arc profiles (Wickens' model, Fig. 4.3).

        Parameters
        ----------
        r0, e0 : float
            Rolling radius and half contact-point spacing, m.
        delta0 : float
            Contact angle in the central position, rad (θ0).
        R_wheel : float
            Transverse radius of the concave (worn) wheel tread, m; ``math.inf`` for a coned tread.
        R_rail : float
            Rail-head transverse radius, m (0 for a knife edge); must be < ``R_wheel``.
        """
        r0 = positive("r0", r0)
        e0 = positive("e0", e0)
        delta0 = finite("delta0", delta0)
        R_rail = finite("R_rail", R_rail)
        if R_rail < 0.0:
            raise ValueError(f"R_rail: must be >= 0, got {R_rail}")
        R_wheel = float(R_wheel)
        if math.isnan(R_wheel) or R_wheel <= R_rail:
            raise ValueError(f"R_wheel: must exceed R_rail (conformal contact), got {R_wheel}")
        s, c = math.sin(delta0), math.cos(delta0)
        d = e0 * c - r0 * s
        if d <= 0.0:
            raise ValueError("delta0: e0 cos(delta0) - r0 sin(delta0) must be > 0")
        if math.isinf(R_wheel):  # limits R_w / (R_w - R_r) -> 1, 1/(R_w - R_r) -> 0
            lam = s * (e0 + R_rail * s) / d
            eps = e0 * s / d
            eta = R_rail * c * s / d
        else:
            D = R_wheel - R_rail
            lam = R_wheel * s * (e0 + R_rail * s) / (d * D)
            eps = e0 * (e0 + R_wheel * s) / (d * D)
            eta = R_rail * c * (e0 + R_wheel * s) / (d * D)
        return cls(r0=r0, e0=e0, conicity=lam, theta0=delta0, epsilon=eps, eta=eta)


__all__ = ["WheelRailGeometry"]
