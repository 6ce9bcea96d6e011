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

Implementation: these formulas are computed once, by the compiled kernels of :mod:`.wheelset_kernel` (numba):
the geometry is a :class:`ConicalGeometry` or a :class:`TabulatedGeometry`, the law a :class:`LinearCreepLaw` or a
:class:`SaturatedCreepLaw` — the kinds those kernels know (other objects are refused when the forces are built).

Limits: the spin of the inclined contact takes δ in the track frame (the roll φ is left out of δ − σφ);
rigid track only (a flexible, lumped track needs the track roll and the rail's lateral motion in the
contact: not built, :func:`railopt.models.vehicle.nonlinear.nonlinear_vehicle` refuses it); small yaw
(γ, not sin γ, in the creepages); the contact point stays in the axle plane (the yaw shift r tan δ γ is left
out, as in the rigid tables); one contact point per wheel (two-point contact is the table's nearest point);
the creep coefficients scale with the normal load as a Hertz contact of fixed curvatures (ab ∝ N^(2/3)) under
the saturated law — the curvature change along the profile is not followed.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from scipy.interpolate import PchipInterpolator

from railopt.models.bifurcation.integration import ModelLimit
from railopt.models.contact.saturation import SPIN_MOMENT_CHOICES
from railopt.models.kernels import c_array
from railopt.models.validation import number
from railopt.models.vehicle import wheelset_kernel as kernel
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

    def parameters(self, params: np.ndarray) -> None:
        """Write the cone into the kernels' parameter vector (:mod:`.wheelset_kernel`)."""
        params[kernel.P_GEOMETRY] = 0.0
        params[kernel.P_CONICITY:kernel.P_ETA + 1] = (self.conicity, self.r0, self.e0, self.theta0, self.epsilon,
                                                      self.eta)

    def points(self, y: np.ndarray) -> ContactPoints:
        """The conical contact points at ``y`` (m, (K,)): exact in y, Δr = 2λy, tan δ = θ0 ± εy/e0."""
        y = _shifts(y)
        params = np.zeros(kernel.N_PARAMS)
        self.parameters(params)
        out = np.empty((4, 2, y.size))
        kernel.conical_points(y, params, out)
        return ContactPoints(*out)


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
        y = c_array(self.y)
        stacked = np.concatenate([self.radius, self.angle, self.lateral_arm, self.vertical_arm])  # (8, n)
        if self.kind == "pchip":  # scipy's coefficients (4, n - 1, 8); the kernel evaluates the cubics
            coef = PchipInterpolator(y, stacked, axis=1).c
        else:  # the straight lines as cubics with zero cubic and quadratic terms
            coef = np.zeros((4, y.size - 1, 8))
            coef[2] = (np.diff(stacked, axis=1) / np.diff(y)).T
            coef[3] = stacked[:, :-1].T
        object.__setattr__(self, "_breaks", y)
        object.__setattr__(self, "_coef", c_array(coef))

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

    def parameters(self, params: np.ndarray) -> None:
        """Mark a table in the kernels' parameter vector (its breakpoints and cubics travel as :meth:`table`)."""
        params[kernel.P_GEOMETRY] = 1.0

    def table(self) -> tuple[np.ndarray, np.ndarray]:
        """Breakpoints (n,) and cubic coefficients (4, n − 1, 8) of :func:`.wheelset_kernel.table_points`."""
        return self._breaks, self._coef

    def outside(self, y: float) -> ValueError:
        """The error for a shift ``y`` (m) outside the table."""
        return ValueError(f"{self.source}: lateral shift {y:.6g} m outside the table [{self.y[0]:.6g}, "
                          f"{self.y[-1]:.6g}] m (beyond the flange range)")

    def points(self, y: np.ndarray) -> ContactPoints:
        """The table's contact points interpolated at ``y`` (m, (K,)); ValueError naming the table outside it."""
        y = _shifts(y)
        if y.size and (np.min(y) < self.y[0] or np.max(y) > self.y[-1]):
            raise self.outside(float(np.max(np.abs(y))))
        out = np.empty((4, 2, y.size))
        kernel.table_points(y, self._breaks, self._coef, out)
        return ContactPoints(*out)


#: The contact geometries the compiled forces know: the cone of the linear model, or a rigid contact table.
ContactGeometry = ConicalGeometry | TabulatedGeometry


def _shifts(y: object, name: str = "y") -> np.ndarray:
    """One value per wheelset: a scalar or a 1-D array, as the kernels' writeable C array."""
    y = np.atleast_1d(np.asarray(y, dtype=float))
    if y.ndim != 1:
        raise ValueError(f"{name}: one value per wheelset (a scalar or a 1-D array), got shape {y.shape}")
    return c_array(y)


def forward_speed(speed: object) -> float:
    """The forward speed (m/s) as a float for the kernels (which check that it is positive and finite).

    Raises
    ------
    ValueError
        What is not a real number (a string, an array, a bool)."""
    if isinstance(speed, bool) or not isinstance(speed, int | float | np.integer | np.floating):
        raise ValueError(f"speed: forward speed must be a positive finite number of m/s, got {speed!r}")
    return float(speed)


# ---------------------------------------------------------------------------------------------------- creep laws
@dataclass(frozen=True)
class LinearCreepLaw:
    """Kalker's linear law (4.9) with the vehicle's constant coefficients (no load dependence): the linear
    model's law.  ``Fx = −f11 ξx``, ``Fy = −f22 ξy + f23 ξsp``, ``Mz = −f23 ξy − f33 ξsp``."""

    load_dependent: bool = field(default=False, init=False)

    def parameters(self, params: np.ndarray) -> None:
        """Write the law into the kernels' parameter vector (:mod:`.wheelset_kernel`)."""
        params[kernel.P_LAW] = 0.0

    def __call__(self, creep: Creep, xi_x, xi_y, xi_sp, N, N0):
        """Forces (Fx, Fy, Mz) (N, N·m) at creepages and normal loads N (arrays broadcast; N0 unused)."""
        return _creep_forces(self, creep, xi_x, xi_y, xi_sp, N, N0)


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

    def parameters(self, params: np.ndarray) -> None:
        """Write the law into the kernels' parameter vector (:mod:`.wheelset_kernel`)."""
        params[kernel.P_LAW] = 1.0
        params[kernel.P_MU] = self.mu
        params[kernel.P_SPIN_SCALED] = 1.0 if self.spin_moment == "scaled" else 0.0
        params[kernel.P_LOAD_SCALING] = 1.0 if self.load_scaling else 0.0

    def __call__(self, creep: Creep, xi_x, xi_y, xi_sp, N, N0):
        """Forces (Fx, Fy, Mz) (N, N·m) at creepages and normal loads N > 0 (arrays broadcast), nominal load N0.

        Raises :class:`WheelLift` for a load N ≤ 0."""
        N = np.asarray(N, dtype=float)
        if np.any(N <= 0.0):
            raise WheelLift(f"normal load: a wheel lifts (N = {float(np.min(N)):.4g} N <= 0): the wheelset "
                             "derails in this model; the rigid contact no longer applies")
        return _creep_forces(self, creep, xi_x, xi_y, xi_sp, N, N0)


#: The creep laws the compiled forces know: Kalker's linear law or the Shen–Hedrick–Elkins saturation.
CreepLaw = LinearCreepLaw | SaturatedCreepLaw


def _creep_forces(law: CreepLaw, creep: Creep, xi_x, xi_y, xi_sp, N, N0) -> tuple[np.ndarray, ...]:
    params = np.zeros(kernel.N_PARAMS)
    params[kernel.P_F11:kernel.P_F33 + 1] = (creep.f11, creep.f22, creep.f23, creep.f33)
    law.parameters(params)
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (xi_x, xi_y, xi_sp, N)))
    flat = [c_array(a.reshape(-1)) for a in arrays]
    out = np.empty((3, flat[0].size))
    kernel.creep_forces(params, *flat, float(N0), out)
    if arrays[0].ndim == 0:
        return tuple(float(out[i, 0]) for i in range(3))
    return tuple(out[i].reshape(arrays[0].shape) for i in range(3))


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
        if type(self.geometry) not in ContactGeometry.__args__:  # not a subclass either: its overrides go unread
            raise ValueError("geometry: a ConicalGeometry or TabulatedGeometry (the geometries the compiled forces "
                             f"know), got {type(self.geometry).__name__}")
        if not isinstance(self.creep, Creep):
            raise ValueError("creep: a wheelrail.Creep with the per-wheel linear coefficients")
        object.__setattr__(self, "axle_load", number("axle_load", self.axle_load, positive=True))
        if self.plane not in ("contact", "track"):
            raise ValueError(f"plane: 'contact' or 'track', got {self.plane!r}")
        if type(self.creep_law) not in CreepLaw.__args__:
            raise ValueError("creep_law: a LinearCreepLaw or SaturatedCreepLaw (the laws the compiled forces know), "
                             f"got {type(self.creep_law).__name__}")
        params = np.zeros(kernel.N_PARAMS)
        params[kernel.P_R0] = self.geometry.r0
        params[kernel.P_W] = self.axle_load
        params[kernel.P_F11:kernel.P_F33 + 1] = (self.creep.f11, self.creep.f22, self.creep.f23, self.creep.f33)
        self.creep_law.parameters(params)
        params[kernel.P_PLANE] = 0.0 if self.plane == "contact" else 1.0
        if self.flange is not None:
            params[kernel.P_FLANGE_K] = self.flange.stiffness
            params[kernel.P_FLANGE_D] = self.flange.clearance
        self.geometry.parameters(params)
        if isinstance(self.geometry, TabulatedGeometry):
            breaks, coef = self.geometry.table()
        else:  # a cone reads no table: placeholders of the kernels' one signature
            breaks, coef = np.zeros(2), np.zeros((4, 1, 8))
        object.__setattr__(self, "_kernel_args", (params, breaks, coef))

    @property
    def kernel_arguments(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(params, breakpoints, coefficients) of :func:`.wheelset_kernel.wheelset_forces` for these forces."""
        return self._kernel_args

    def raise_status(self, status: int, info: np.ndarray) -> None:
        """Raise the error of a kernel status (:mod:`.wheelset_kernel`); nothing for ``OK``.

        Raises
        ------
        ValueError
            A non-positive speed; a shift outside the table (naming it); a state or normal loads that are not finite;
        normal loads that do not converge.
        WheelLift
            A wheel's normal load reached zero (a ValueError too).
        """
        if status == kernel.OK:
            return
        if status == kernel.BAD_SPEED:
            raise ValueError(f"speed: forward speed must be a positive finite number of m/s, got {float(info[0])!r}")
        if status == kernel.NOT_FINITE:
            k = int(info[0])
            what = f"wheelset {k}'s state (y, yaw or a rate)" if k >= 0 else f"wheelset {-1 - k}'s normal loads"
            raise ValueError(f"state: {what} is not finite (NaN or infinite): the forces are not defined there")
        if status == kernel.OUTSIDE_TABLE:
            raise self.geometry.outside(float(info[0]))
        if status == kernel.WHEEL_LIFT:
            raise WheelLift(f"normal load: a wheel lifts (N = {info[0]:.4g} N <= 0) at y = {info[1]:.6g} m: the "
                            "rigid contact no longer applies (derailment)")
        raise ValueError(f"normal load: the normal loads and creep forces did not converge in {kernel.MAX_PASSES} "
                         "passes")

    def _run(self, y, yaw, dy, droll, dyaw, du, dpitch, speed: float) -> tuple[np.ndarray, np.ndarray]:
        names = ("y", "yaw", "dy", "droll", "dyaw", "du", "dpitch")
        values = [_shifts(a, n) for a, n in zip((y, yaw, dy, droll, dyaw, du, dpitch), names, strict=True)]
        try:
            args = [c_array(a) for a in np.broadcast_arrays(*values)]
        except ValueError:
            raise ValueError(f"{', '.join(names)}: one value per wheelset each (or one for all), sizes "
                             f"{[a.size for a in values]} differ") from None
        k = args[0].size
        state = np.empty((kernel.N_STATE, 2, k))
        gen = np.empty((len(FORCE_ROWS), k))
        info = np.zeros(2)
        status = kernel.wheelset_forces(*args, forward_speed(speed), *self._kernel_args, state, gen, info)
        self.raise_status(status, info)
        return state, gen

    def evaluate(self, y, yaw, dy, droll, dyaw, du, dpitch, speed: float) -> WheelsetContactState:
        """Contact state and generalised forces of K wheelsets (:func:`.wheelset_kernel.wheelset_forces`).

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
            A non-positive speed; inputs of different sizes; y outside a tabulated geometry; a wheel that lifts
            (N ≤ 0, :class:`WheelLift`); normal loads that do not converge.
        """
        s, gen = self._run(y, yaw, dy, droll, dyaw, du, dpitch, speed)
        k = kernel
        return WheelsetContactState(
            points=ContactPoints(s[k.S_RADIUS], s[k.S_ANGLE], s[k.S_LATERAL_ARM], s[k.S_VERTICAL_ARM]),
            xi_x=s[k.S_XI_X], xi_y=s[k.S_XI_Y], xi_sp=s[k.S_XI_SP], Fx=s[k.S_FX], Fy=s[k.S_FY], Mz=s[k.S_MZ],
            N=s[k.S_N], Q=s[k.S_Q], Y=s[k.S_Y], forces=gen)

    def generalized_forces(self, y, yaw, dy, droll, dyaw, du, dpitch, speed: float) -> np.ndarray:
        """Generalised forces (5, K) on the rows :data:`FORCE_ROWS` (N, N·m); arguments as :meth:`evaluate`."""
        return self._run(y, yaw, dy, droll, dyaw, du, dpitch, speed)[1]


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
    "forward_speed",
    "linear_model_forces",
    "profile_forces",
]
