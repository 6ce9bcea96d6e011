"""Nonlinear wheel/rail forces of one wheelset (or many at once) on rigid straight track.

The wheelset's states — lateral shift y relative to the rail, yaw γ, and the rates ẏ, α̇ (roll), γ̇, u̇
(fore-aft), β̇ (spin perturbation) — and the forward speed S give each wheel's contact geometry (from a
:class:`ContactGeometry`), creepages, normal load and creep forces, and from them the generalised forces on
the wheelset's coordinates (u, v, α, β, γ) of :mod:`railopt.models.vehicle.assembly`.  Axes as in
:mod:`railopt.models.vehicle.wheelrail`: x forward, y left, z up; the left wheel is side σ = +1, the right
σ = −1.

Geometry (per wheel, functions of y only: the contact is planar at zero yaw, see
:mod:`railopt.models.contact.rigid_contact`)
    rolling radius r, contact angle δ (positive when the rail surface rises towards that side's field side:
    the normal force pushes the wheel up and towards the track centre), lateral arm a (distance from the
    wheelset centre to the contact point along the track's y, left contact at +a, right at −a) and vertical
    arm h (depth of the contact point below the wheelset centre).  The arms rotate with the wheelset's yaw:
    p = (−σ a sin γ, σ a cos γ, −h).

Creepages (thesis (4.11)–(4.18) with the exact-in-y geometry; ``r0`` the nominal rolling radius, so the
wheelset turns at Ω = S/r0 + β̇)::

    ξx  = (u̇ − σ a γ̇ − r β̇)/S + (r0 − r)/r0                       (r0 − r: the rolling-radius difference, not λy)
    ν   = (ẏ + h α̇)/S − γ                                            (lateral slip of the contact, track plane)
    ξη  = ν / cos δ    (contact plane: the rigid contact has no normal slip)   or  ν   (track plane)
    ξsp = γ̇ cos δ / S − σ sin δ / r0   (contact plane, with the spin of the inclined contact)
          or γ̇/S                        (track plane, the linear model's (4.18))

Creep forces (Fξ, Fη, Mζ) from a :class:`CreepLaw` in the sign convention of :mod:`.wheelrail`
(``Fx = −f11 ξx``, ``Fy = −f22 ξy + f23 ξsp``, ``Mz = −f23 ξy − f33 ξsp``).  Fξ acts along x, Fη along the
contact plane's lateral tangent t = (0, cos δ, σ sin δ) (contact plane) or along y (track plane), Mζ about
the normal n = (0, −σ sin δ, cos δ) (contact plane) or about z (track plane).

Normal loads N_l, N_r (along n) from the quasi-static equilibrium of the wheelset under the static load W
(the axle load; dynamic vertical suspension forces are left out) and the contact forces: vertical
``Σ (N cos δ + Fη t_z) = W`` and roll about the wheelset centre ``Σ (p × F)_x = 0`` — two linear equations
solved per wheelset (Cramer).  The creep forces depend on N through a saturating law, so the two are
iterated to |ΔN| ≤ 1e-10 W (a linear law needs one pass; N balances the forces of the last pass exactly).
The normal forces' lateral components, −σ N sin δ, are the gravitational stiffness: with δ from a conical
geometry, ``tan δ = θ0 ± ε y/e0``, they give the W ε/e0 of
(4.43)–(4.44) and, through the yaw of the arms, the yaw gravitational stiffness −W e0 θ0 of (4.48)
(:func:`linear_model_forces`).  The load transfer ΔN that a linear model eliminates as the reaction of its
roll constraint (4.7) is here solved for, which gives the same linear terms (ψ = tanθ0/(e0 − r0 tanθ0) is
exactly the ratio that makes that reaction workless).

Flange contact comes from the same geometry: near the flange the contact angle grows to ≈ 70° and N sin δ is
the flange force.  A separate dead-band flange spring (:class:`FlangeSpring`) is only added when asked for
(published benchmark models that use one).

Limits: the spin of the inclined contact takes δ in the track frame (the roll φ is left out of δ − σφ);
rigid track only (a flexible, lumped track needs the track roll and the rail's lateral motion in the
contact: not built, :func:`railopt.models.vehicle.nonlinear.nonlinear_vehicle` refuses it); small yaw
(γ, not sin γ, in the creepages); the contact point stays in the axle plane (the yaw shift r tan δ γ is left
out, as in the rigid tables); one contact point per wheel (two-point contact is the table's nearest point);
the creep coefficients scale with the normal load as a Hertz contact of fixed curvatures (ab ∝ N^(2/3)) under
the saturated law — the curvature change along the profile is not followed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal, Protocol, runtime_checkable

import numpy as np
from scipy.interpolate import PchipInterpolator

from railopt.models.bifurcation.integration import ModelLimit
from railopt.models.contact.saturation import SPIN_MOMENT_CHOICES, she_force_ratio
from railopt.models.validation import number
from railopt.models.vehicle.wheelrail import Creep, WheelRail

#: Row order of :meth:`WheelsetForces.generalized_forces`: the wheelset's coordinates that receive a force.
FORCE_ROWS: tuple[str, ...] = ("u", "v", "alpha", "beta", "gamma")
#: Side signs σ: index 0 the left wheel (+1), index 1 the right (−1).
SIDES = np.array([1.0, -1.0])[:, None]


# ---------------------------------------------------------------------------------------------------- geometry
@dataclass(frozen=True)
class ContactPoints:
    """Contact geometry of both wheels of K wheelsets, arrays of shape (2, K): row 0 left, row 1 right (SI).

    Attributes
    ----------
    radius : rolling radius r, m.
    angle : contact angle δ, rad (positive rising towards that side's field side).
    lateral_arm : a, m, distance from the wheelset centre to the contact along y (≥ 0 in practice).
    vertical_arm : h, m, depth of the contact point below the wheelset centre.
    """

    radius: np.ndarray
    angle: np.ndarray
    lateral_arm: np.ndarray
    vertical_arm: np.ndarray


@runtime_checkable
class ContactGeometry(Protocol):
    """What the forces need of a contact geometry: the nominal radius and the contact points at shifts y.

    ``r0`` (m) is the rolling radius of the centred wheelset; ``points(y)`` takes y of shape (K,) (m, positive
    to the left) and returns :class:`ContactPoints` of shape (2, K), raising ValueError outside its range.
    """

    r0: float

    def points(self, y: np.ndarray) -> ContactPoints:
        """Contact points of both wheels at the lateral shifts ``y`` (m, shape (K,)): radii, angles and arms."""
        ...


@dataclass(frozen=True)
class ConicalGeometry:
    """The linear model's contact geometry (thesis (4.1)–(4.8)), exact in y (SI).

    ``r_l,r = r0 ± λ y`` (Δr = 2λy exactly), ``tan δ_l,r = θ0 ± ε y/e0``, lateral arms ``e0 ∓ η y`` (left,
    right), vertical arms r0 (the lever arm ℓ20 of (4.45)).  θ0 is read as tan δ0 (equal to first order to
    the file's θ0); then ψ = θ0/(e0 − r0 θ0) of (4.8) is exactly the ratio that makes the load transfer
    workless, and linearising :class:`WheelsetForces` with this geometry in the linear model's conventions
    gives :func:`~railopt.models.vehicle.wheelrail.contact_matrices` (:func:`linear_model_forces`).  No flange:
    valid for every y (a cone without end).
    """

    conicity: float
    r0: float
    e0: float
    theta0: float = 0.0
    epsilon: float = 0.0
    eta: float = 0.0

    @classmethod
    def from_wheel_rail(cls, wr: WheelRail) -> ConicalGeometry:
        """The geometry of a vehicle's linear contact parameters (``vehicle.wheel_rail()``)."""
        return cls(wr.conicity, wr.r0, wr.e0, wr.theta0, wr.epsilon, wr.eta)

    def points(self, y: np.ndarray) -> ContactPoints:
        """The conical contact points at ``y`` (m, (K,)): exact in y, Δr = 2λy, tan δ = θ0 ± εy/e0."""
        y = np.asarray(y, dtype=float)[None, :]
        sigma = SIDES
        return ContactPoints(
            radius=self.r0 + sigma * self.conicity * y,
            angle=np.arctan(self.theta0 + sigma * self.epsilon * y / self.e0),
            lateral_arm=self.e0 - sigma * self.eta * y,
            vertical_arm=np.full((2, y.shape[1]), self.r0),
        )


@dataclass(frozen=True, eq=False)
class TabulatedGeometry:
    """Contact geometry interpolated in a rigid contact table over y.

    Build it with :meth:`from_table` from a :class:`railopt.models.contact.rigid_contact.ContactTable` (or any
    object with its fields ``y, roll, r_left, r_right, contact_angle_left, contact_angle_right,
    track_contact_left, track_contact_right, r0``).  Arms from the table: a_l = Y_l − y, a_r = y − Y_r (Y the
    contact's lateral position in the track frame); the vertical arm is the contact's depth below the axle
    centre in the track frame, h = r cos φ − u sin φ with u the contact's lateral position in the rolled
    wheelset frame (u = (σ a − r sin φ)/cos φ).

    ``kind="linear"`` interpolates piecewise linearly (keeps the flange's steep rise and a contact jump sharp,
    but the forces then have kinks at every node, which costs an integrator steps); ``"pchip"`` uses the
    monotone piecewise-cubic Hermite interpolant (:class:`scipy.interpolate.PchipInterpolator`: C¹, no
    overshoot across a jump, unlike a spline).

    Raises
    ------
    ValueError
        From :meth:`points`: a shift y outside the table (a wheelset beyond its flange range).
    """

    y: np.ndarray
    radius: np.ndarray  # (2, n)
    angle: np.ndarray
    lateral_arm: np.ndarray
    vertical_arm: np.ndarray
    r0: float
    source: str = "contact table"
    kind: str = "linear"

    def __post_init__(self) -> None:
        if self.kind not in ("linear", "pchip"):
            raise ValueError(f"kind: 'linear' or 'pchip', got {self.kind!r}")
        stacked = np.concatenate([self.radius, self.angle, self.lateral_arm, self.vertical_arm])  # (8, n)
        object.__setattr__(self, "_stacked", stacked)
        if self.kind == "pchip":
            object.__setattr__(self, "_pchip", PchipInterpolator(self.y, stacked, axis=1, extrapolate=False))

    @classmethod
    def from_table(cls, table: object, source: str = "contact table", kind: str = "linear") -> TabulatedGeometry:
        """From a rigid contact table (fields named in the class docstring); ``kind`` of interpolation."""
        y = np.asarray(table.y, dtype=float)
        if y.ndim != 1 or y.size < 2 or not np.all(np.diff(y) > 0.0):
            raise ValueError(f"{source}: y must be a strictly increasing array of at least 2 shifts (m)")
        phi = np.asarray(table.roll, dtype=float)
        r = np.stack([np.asarray(table.r_left, float), np.asarray(table.r_right, float)])
        delta = np.stack([np.asarray(table.contact_angle_left, float), np.asarray(table.contact_angle_right, float)])
        a = np.stack([np.asarray(table.track_contact_left, float) - y,
                      y - np.asarray(table.track_contact_right, float)])
        u = (SIDES * a - r * np.sin(phi)) / np.cos(phi)
        h = r * np.cos(phi) - u * np.sin(phi)
        for name, arr in (("radius", r), ("contact angle", delta), ("lateral arm", a), ("vertical arm", h)):
            if not np.all(np.isfinite(arr)):
                raise ValueError(f"{source}: {name} is not finite everywhere")
        return cls(y=y, radius=r, angle=delta, lateral_arm=a, vertical_arm=h, r0=float(table.r0), source=source,
                   kind=kind)

    def points(self, y: np.ndarray) -> ContactPoints:
        """The table's contact points interpolated at ``y`` (m, (K,)); ValueError naming the table outside it."""
        y = np.asarray(y, dtype=float)
        if y.size and (np.min(y) < self.y[0] or np.max(y) > self.y[-1]):
            raise ValueError(f"{self.source}: lateral shift {float(np.max(np.abs(y))):.6g} m outside the table "
                             f"[{self.y[0]:.6g}, {self.y[-1]:.6g}] m (beyond the flange range)")
        if self.kind == "pchip":
            v = self._pchip(y)
        else:  # the interval of every y once, then the same weights for every field
            i = np.clip(np.searchsorted(self.y, y, side="right") - 1, 0, self.y.size - 2)
            w = (y - self.y[i]) / (self.y[i + 1] - self.y[i])
            v = self._stacked[:, i] * (1.0 - w) + self._stacked[:, i + 1] * w
        return ContactPoints(v[0:2], v[2:4], v[4:6], v[6:8])


# ---------------------------------------------------------------------------------------------------- creep laws
@runtime_checkable
class CreepLaw(Protocol):
    """A creep law: forces of contacts from their creepages and normal loads.

    ``__call__(creep, xi_x, xi_y, xi_sp, N, N0) -> (Fx, Fy, Mz)``: ``creep`` the wheel's linear coefficients
    at the nominal load N0 (N) in the convention of :mod:`.wheelrail`; arrays broadcast; forces in N, moment
    in N·m.  ``load_dependent`` says whether the forces depend on N (else the normal loads need one pass).
    """

    load_dependent: bool

    def __call__(self, creep: Creep, xi_x: np.ndarray, xi_y: np.ndarray, xi_sp: np.ndarray, N: np.ndarray,
                 N0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...


@dataclass(frozen=True)
class LinearCreepLaw:
    """Kalker's linear law (4.9) with the vehicle's constant coefficients (no load dependence): the linear
    model's law.  ``Fx = −f11 ξx``, ``Fy = −f22 ξy + f23 ξsp``, ``Mz = −f23 ξy − f33 ξsp``."""

    load_dependent: bool = field(default=False, init=False)

    def __call__(self, creep: Creep, xi_x, xi_y, xi_sp, N, N0):
        return (-creep.f11 * xi_x, -creep.f22 * xi_y + creep.f23 * xi_sp, -creep.f23 * xi_y - creep.f33 * xi_sp)


@dataclass(frozen=True)
class SaturatedCreepLaw:
    """Shen–Hedrick–Elkins saturation, the law of :func:`railopt.models.contact.saturation.shen_hedrick_elkins`
    (its force ratio :func:`~railopt.models.contact.saturation.she_force_ratio` applied to the resultant of the
    linear forces; written out here without the per-call input checks, which cost 5x the rhs, and tested
    against that function).

    Attributes
    ----------
    mu : float
        Coefficient of friction (> 0).
    spin_moment : {"scaled", "linear"}
        Passed to the saturation law (the spin moment saturated with the forces, or kept linear).
    load_scaling : bool
        Scale the coefficients with the normal load as a Hertz contact of fixed curvatures: f11, f22 ∝
        (N/N0)^(2/3), f23 ∝ N/N0, f33 ∝ (N/N0)^(4/3) (Kalker: f11 = G ab C11, f23 = G (ab)^(3/2) C23,
        f33 = G (ab)² C33 with ab ∝ N^(2/3)).  False keeps the coefficients at N0.
    """

    mu: float
    spin_moment: str = "scaled"
    load_scaling: bool = True
    load_dependent: bool = field(default=True, init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "mu", number("mu", self.mu, positive=True))
        if self.spin_moment not in SPIN_MOMENT_CHOICES:
            raise ValueError(f"spin_moment: one of {SPIN_MOMENT_CHOICES}, got {self.spin_moment!r}")

    def __call__(self, creep: Creep, xi_x, xi_y, xi_sp, N, N0):
        N = np.asarray(N, dtype=float)
        if np.any(N <= 0.0):
            raise WheelLift(f"normal load: a wheel lifts (N = {float(np.min(N)):.4g} N <= 0): the wheelset "
                             "derails in this model; the rigid contact no longer applies")
        k = N / N0 if self.load_scaling else np.ones_like(N)
        c = np.cbrt(k)
        s2, s3, s4 = c * c, k, k * c
        # linear forces (4.9) with the load-scaled coefficients, then the resultant's factor ε = F/F'
        tx = -creep.f11 * s2 * xi_x
        ty = -creep.f22 * s2 * xi_y + creep.f23 * s3 * xi_sp
        mz = -creep.f23 * s3 * xi_y - creep.f33 * s4 * xi_sp
        F = np.hypot(tx, ty)
        r = F / (self.mu * N)
        eps = np.where(r > 0.0, she_force_ratio(r) / np.where(r > 0.0, r, 1.0), 1.0)
        if self.spin_moment == "scaled":
            mz = eps * mz
        return eps * tx, eps * ty, mz


# ---------------------------------------------------------------------------------------------------- flange spring
@dataclass(frozen=True)
class FlangeSpring:
    """Optional dead-band flange spring (only for benchmark models that specify one).

    A lateral force ``−k (y − d)`` for y > d and ``−k (y + d)`` for y < −d on the wheelset centre (v row),
    zero inside the clearance d.  Attributes: ``clearance`` d (m, ≥ 0), ``stiffness`` k (N/m, > 0).
    """

    clearance: float
    stiffness: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "clearance", number("clearance", self.clearance))
        object.__setattr__(self, "stiffness", number("stiffness", self.stiffness, positive=True))
        if self.clearance < 0.0:
            raise ValueError(f"clearance: flange clearance must be >= 0 m, got {self.clearance}")

    def force(self, y: np.ndarray) -> np.ndarray:
        """Lateral force on the wheelset, N, shape of ``y``."""
        y = np.asarray(y, dtype=float)
        return -self.stiffness * (y - np.clip(y, -self.clearance, self.clearance))


# ---------------------------------------------------------------------------------------------------- the forces
Plane = Literal["contact", "track"]


class WheelLift(ModelLimit):
    """A wheel's normal load reached zero: the rigid quasi-static contact no longer applies (a ValueError).

    With the normal loads balancing only the static axle load W, a single flange contact steeper than
    atan(a/h) (≈ 58° for a = 0.75 m, h = 0.46 m) has its line of action below the wheelset centre, so only a
    negative load on the other wheel balances the roll moment (Q_r = N (cos δ − (h/a) sin δ) of the quasi-static
    balance).  The speed ramp records it as the verdict ``"model_limit"``.
    """


@dataclass(frozen=True)
class WheelsetContactState:
    """Everything computed for K wheelsets (arrays (2, K): row 0 left wheel, row 1 right; forces in N).

    Attributes: ``points`` (ContactPoints), creepages ``xi_x``, ``xi_y`` (in the chosen plane), ``xi_sp``
    (1/m), creep forces ``Fx``, ``Fy`` (along the lateral tangent), ``Mz`` (about the normal, N·m), normal
    loads ``N``; the total contact force of the rail on each wheel in track axes, vertical ``Q`` and lateral
    ``Y`` (y positive left: a flange force on the left wheel is negative), so ``|Y/Q|`` is the derailment
    quotient; and the generalised forces ``forces`` (5, K) in :data:`FORCE_ROWS` order.
    """

    points: ContactPoints
    xi_x: np.ndarray
    xi_y: np.ndarray
    xi_sp: np.ndarray
    Fx: np.ndarray
    Fy: np.ndarray
    Mz: np.ndarray
    N: np.ndarray
    Q: np.ndarray
    Y: np.ndarray
    forces: np.ndarray


@dataclass(frozen=True, eq=False)
class WheelsetForces:
    """Nonlinear wheel/rail forces of a wheelset (module docstring for the model).

    Attributes
    ----------
    geometry : ContactGeometry
        Contact points against y (:class:`ConicalGeometry`, :class:`TabulatedGeometry`).
    creep : Creep
        Linear creep coefficients per wheel at the static wheel load W/2 (``vehicle.wheel_rail().creep``).
    axle_load : float
        W, N: the static vertical load the wheelset carries (its normal loads balance it).
    creep_law : CreepLaw
        :class:`LinearCreepLaw` (default) or :class:`SaturatedCreepLaw`.
    plane : {"contact", "track"}
        Creepages and creep forces in the inclined contact plane (with the spin of the inclined contact), or
        in the track plane with the linear model's spin γ̇/S only ((4.11)–(4.18)).
    flange : FlangeSpring or None
        An added dead-band flange spring (default none: flange contact comes from the geometry).
    """

    geometry: ContactGeometry
    creep: Creep
    axle_load: float
    creep_law: CreepLaw = field(default_factory=LinearCreepLaw)
    plane: Plane = "contact"
    flange: FlangeSpring | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.geometry, ContactGeometry):
            raise ValueError("geometry: needs r0 and points(y) (a ConicalGeometry or TabulatedGeometry)")
        if not isinstance(self.creep, Creep):
            raise ValueError("creep: a wheelrail.Creep with the per-wheel linear coefficients")
        object.__setattr__(self, "axle_load", number("axle_load", self.axle_load, positive=True))
        if self.plane not in ("contact", "track"):
            raise ValueError(f"plane: 'contact' or 'track', got {self.plane!r}")
        if not isinstance(self.creep_law, CreepLaw):
            raise ValueError("creep_law: a LinearCreepLaw, SaturatedCreepLaw or another CreepLaw")

    def evaluate(self, y, yaw, dy, droll, dyaw, du, dpitch, speed: float) -> WheelsetContactState:
        """Contact state and generalised forces of K wheelsets.

        Parameters
        ----------
        y, yaw : array_like (K,)
            Lateral shift relative to the rail (m, left positive) and yaw (rad).
        dy, droll, dyaw, du, dpitch : array_like (K,)
            Rates of v, α, γ, u, β (m/s, rad/s).
        speed : float
            Forward speed S, m/s (> 0).

        Raises
        ------
        ValueError
            A non-positive speed; y outside a tabulated geometry; a wheel that lifts (N ≤ 0); normal loads
            that do not converge.
        """
        if not (speed > 0.0 and math.isfinite(speed)):
            raise ValueError(f"speed: forward speed must be a positive finite number of m/s, got {speed!r}")
        y, yaw, dy, droll, dyaw, du, dpitch = (np.atleast_1d(np.asarray(a, dtype=float))
                                               for a in (y, yaw, dy, droll, dyaw, du, dpitch))
        S = float(speed)
        r0 = self.geometry.r0
        W = self.axle_load
        g = self.geometry.points(y)
        sigma = SIDES
        r, a, h = g.radius, g.lateral_arm, g.vertical_arm
        s, c = np.sin(g.angle), np.cos(g.angle)
        sg, cg = np.sin(yaw)[None, :], np.cos(yaw)[None, :]
        px, py = -sigma * a * sg, sigma * a * cg  # arms, rotated with the yaw; pz = −h
        # creepages
        xi_x = (du[None, :] - sigma * a * dyaw[None, :] - r * dpitch[None, :]) / S + (r0 - r) / r0
        nu = (dy[None, :] + h * droll[None, :]) / S - yaw[None, :]
        if self.plane == "contact":
            xi_y = nu / c
            xi_sp = dyaw[None, :] * c / S - sigma * s / r0
            ty, tz = c, sigma * s  # lateral tangent
            my, mz = -sigma * s, c  # normal (spin-moment axis)
        else:
            xi_y = np.broadcast_to(nu, r.shape)
            xi_sp = np.broadcast_to(dyaw[None, :] / S, r.shape)
            ty, tz = np.ones_like(r), np.zeros_like(r)
            my, mz = np.zeros_like(r), np.ones_like(r)
        ny, nz = -sigma * s, c
        # normal loads from the vertical and roll balance, iterated with a load-dependent creep law
        N0 = 0.5 * W
        # roll moment of a unit normal load: (p × n)_x = py nz + h ny
        arm_n = py * nz + h * ny
        N = np.full(r.shape, N0) / c
        for _ in range(50):
            Fx, Fy, Mz = self.creep_law(self.creep, xi_x, xi_y, xi_sp, N, N0)
            Fy_y, Fy_z = Fy * ty, Fy * tz
            rhs_v = W - np.sum(Fy_z, axis=0)
            rhs_r = -np.sum(py * Fy_z + h * Fy_y, axis=0)
            det = nz[0] * arm_n[1] - nz[1] * arm_n[0]
            N_new = np.stack([(rhs_v * arm_n[1] - nz[1] * rhs_r) / det, (nz[0] * rhs_r - arm_n[0] * rhs_v) / det])
            change = float(np.max(np.abs(N_new - N)))
            N = N_new
            if np.any(N <= 0.0):
                i = int(np.argmin(np.min(N, axis=0)))
                raise WheelLift(f"normal load: a wheel lifts (N = {float(np.min(N)):.4g} N <= 0) at y = "
                                 f"{y[i]:.6g} m: the rigid contact no longer applies (derailment)")
            if not self.creep_law.load_dependent:
                break
            if change <= 1e-10 * W:  # N balances these forces exactly; they are those of N within 1e-10 W
                break
        else:
            raise ValueError("normal load: the normal loads and creep forces did not converge in 50 passes")
        # forces on the wheel in track axes
        Fy_y, Fy_z = Fy * ty, Fy * tz
        Ftot_x = Fx
        Ftot_y = Fy_y + N * ny
        Ftot_z = Fy_z + N * nz
        pz = -h
        gen = np.empty((len(FORCE_ROWS), y.size))
        gen[0] = np.sum(Ftot_x, axis=0)
        gen[1] = np.sum(Ftot_y, axis=0)
        gen[2] = np.sum(py * Ftot_z - pz * Ftot_y, axis=0)
        gen[3] = np.sum(pz * Ftot_x - px * Ftot_z + Mz * my, axis=0)
        gen[4] = np.sum(px * Ftot_y - py * Ftot_x + Mz * mz, axis=0)
        if self.flange is not None:
            gen[1] += self.flange.force(y)
        return WheelsetContactState(points=g, xi_x=xi_x, xi_y=np.asarray(xi_y), xi_sp=np.asarray(xi_sp), Fx=Fx,
                                    Fy=Fy, Mz=Mz, N=N, Q=Ftot_z, Y=Ftot_y, forces=gen)

    def generalized_forces(self, y, yaw, dy, droll, dyaw, du, dpitch, speed: float) -> np.ndarray:
        """Generalised forces (5, K) on the rows :data:`FORCE_ROWS` (N, N·m); arguments as :meth:`evaluate`."""
        return self.evaluate(y, yaw, dy, droll, dyaw, du, dpitch, speed).forces


def linear_model_forces(wr: WheelRail) -> WheelsetForces:
    """The nonlinear forces whose linearisation at y = 0 is the linear model's contact (4.9)–(4.48).

    :class:`ConicalGeometry` of the vehicle's contact parameters, the linear creep law with the vehicle's
    coefficients (f23, f33 zero when ``spin`` is off) and the track-plane conventions of (4.11)–(4.18).

    Raises
    ------
    ValueError
        ``gravity_stiffness = false`` with a non-zero θ0 or ε: the linear model then drops the normal
        forces' lateral components, which a force model with normal loads cannot do.
    """
    if not wr.gravity_stiffness and (wr.theta0 != 0.0 or wr.epsilon != 0.0):
        raise ValueError("contact: gravity_stiffness = false with theta0 or epsilon non-zero has no nonlinear "
                         "counterpart (the normal forces' lateral components are the gravity stiffness)")
    creep = wr.creep if wr.spin else Creep(wr.creep.f11, wr.creep.f22)
    return WheelsetForces(ConicalGeometry.from_wheel_rail(wr), creep, wr.axle_load, LinearCreepLaw(), plane="track")



def profile_forces(wr: WheelRail, table: object, creep_law: CreepLaw | None = None, *, kind: str = "pchip",
                   plane: Plane = "contact", flange: FlangeSpring | None = None) -> WheelsetForces:
    """The forces of a vehicle's wheelset on a rigid contact table of real profiles.

    Parameters
    ----------
    wr : WheelRail
        The vehicle's contact (``vehicle.wheel_rail()``): creep coefficients (f23, f33 zero when ``spin`` is
        off) and axle load.
    table : ContactTable
        Rigid contact geometry (e.g. ``vehicle.contact_table()`` or
        :func:`railopt.models.contact.rigid_contact.rigid_contact_table`), with ``table.r0`` = ``wr.r0``.
    creep_law : CreepLaw, optional
        Default the linear law.
    kind, plane, flange
        As :class:`TabulatedGeometry` and :class:`WheelsetForces`.

    Raises
    ------
    ValueError
        The table's nominal rolling radius differs from the vehicle's (the creepages' r0 and the creep
        coefficients would disagree).
    """
    if abs(float(table.r0) - wr.r0) > 1e-9:
        raise ValueError(f"table: nominal rolling radius r0 = {float(table.r0):.6g} m differs from the vehicle's "
                         f"[contact] wheel radius {wr.r0:.6g} m; build the table with the vehicle's r0")
    creep = wr.creep if wr.spin else Creep(wr.creep.f11, wr.creep.f22)
    geometry = TabulatedGeometry.from_table(table, kind=kind)
    return WheelsetForces(geometry, creep, wr.axle_load, creep_law or LinearCreepLaw(), plane=plane, flange=flange)

__all__ = [
    "FORCE_ROWS",
    "ConicalGeometry",
    "ContactGeometry",
    "ContactPoints",
    "CreepLaw",
    "FlangeSpring",
    "LinearCreepLaw",
    "SaturatedCreepLaw",
    "TabulatedGeometry",
    "WheelLift",
    "WheelsetContactState",
    "WheelsetForces",
    "linear_model_forces",
    "profile_forces",
]
