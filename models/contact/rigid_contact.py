"""Rigid wheel/rail contact geometry of a wheelset on straight track, tabulated against the lateral shift y.

Frames and signs (the same as :mod:`.conicity`)
-----------------------------------------------
Track frame: Y lateral, positive towards the **left** rail; Z up.  The wheelset's axle centre sits at (y, h) and
is rolled by φ about the track's x axis (x forward, right-handed: φ > 0 lifts the LEFT wheel).  So a
restoring pair has Δr = r_l − r_r > 0 and φ > 0 for y > 0, and ``equivalent_conicity(table.y, table.delta_r,
amplitude)`` works directly.  Profiles (:mod:`.profiles`) are given for the left side (y towards the field,
z up); the right wheel and rail are their mirror images in Y.

Placement
---------
* Rails: the gauge point of each (inclined) rail — the gauge-side point ``gauge_height`` (14 mm) below the
  rail's highest point — lies at Y = ±gauge/2.
* Wheels: the flange backs lie at ±flange_back_distance/2 in the wheelset frame, so a profile point y_w of the
  left wheel lies at u = flange_back_distance/2 − flange_back + y_w; its height in the wheelset frame is
  v = z_w(y_w) − z_w(taping_line) − r0, i.e. the rolling radius at y_w is r0 − (z_w(y_w) − z_w(taping_line)).
  r0 may differ left/right (EN 15302 case E5: 920/918 mm wheels).

Method
------
With zero yaw both bodies are sections in the plane x = 0 (a wheel is a body of revolution whose axis stays in
that plane, a rail a prism along x), so the contact is planar.  For a roll φ and h = 0 the least vertical gap
between each wheel and its rail is d(φ) = min_w [Z_wheel(w) − Z_rail(Y(w))]: found on a grid of wheel points
(``grid_step``) and refined by Newton's method on the continuous (cubic-spline) profiles, where the gap's
derivative along the wheel profile vanishes (the two surfaces are parallel: common tangent).  Both wheels touch
(min gap 0 on both sides) when d_l(φ) = d_r(φ); then h = −d_l.  H(φ) = d_l − d_r increases monotonically with φ
(its slope ≈ the contact-point spacing 2e0); it is solved by safeguarded Newton (dH/dφ from the envelope
theorem, bisection inside a bracket when Newton leaves it) for all y at once, to |H| < 1e-13 m.

Outputs per y: roll φ, axle height h, rolling radii, Δr, contact angles δ (angle of the common tangent in the
track frame, positive when the surface rises towards the field side: both ≈ the cone angle on the tread,
≈ 70° on the flange), contact positions on the wheel and the rail (lateral, each in its own profile's
coordinates; the rail's as given, before the track's inclination), transverse curvatures (convex towards the
other body positive), and flags: a second local minimum of the gap within ``two_point_gap`` more than
``separation`` away from the contact (two-point contact), and a jump of the wheel contact position between
neighbouring y larger than ``jump_threshold``.

Yaw is left out: it moves the contact points ahead of or behind the axle plane (by ≈ r tan δ ψ) and changes
the lateral geometry only to second order in ψ (≈ r tan δ ψ²/2: under 0.1 mm for ψ < 10 mrad off the flange),
which a hunting model of small yaw neglects in the same way as the EN 15302 equivalent conicity does.

Limits: rigid bodies (no penetration, so no contact-patch spread: elastic codes place the patch centre up to
half a patch width, several mm in conformal tread contact, from the rigid point), profiles single-valued in y
(a flank beyond vertical is cut), straight track, zero yaw.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq

from railopt.models.contact.hertz import HertzEllipse, hertz_ellipse
from railopt.models.contact.profiles import Profile, incline
from railopt.models.validation import number as finite
from railopt.models.validation import positive

# ---------------------------------------------------------------------------------------------------------------
# the wheelset on its track


@dataclass(frozen=True)
class WheelsetTrack:
    """Two wheels on two rails: profiles and the dimensions that place them (SI, m).

    Attributes
    ----------
    wheel_left, wheel_right : Profile
        Wheel profiles (kind "wheel", with ``flange_back``), each in the left-side convention of
        :mod:`.profiles` (the right one is mirrored here).
    rail_left, rail_right : Profile
        Rail profiles (kind "rail"), as given (already inclined or not).
    gauge : float
        Track gauge between the gauge points, m (1.435).
    flange_back_distance : float
        Distance between the flange backs (back-to-back), m (1.360).
    r0_left, r0_right : float
        Rolling radius of each wheel at its profile's taping line, m.
    inclination : float
        Rail inclination applied here to both rails (tan of the angle: 1/40, 1/20; 0 when the rail data are
        already inclined), about ``inclination_about`` (rail profile coordinates, m).
    gauge_height : float
        Depth of the gauge point below the highest point of the (inclined) rail, m (14 mm, EN 13848-1).

    Raises
    ------
    ValueError
        Naming the field: wrong profile kinds, a wheel without ``flange_back``, non-positive dimensions, or a
        rail that does not reach ``gauge_height`` on its gauge side.
    """

    wheel_left: Profile
    wheel_right: Profile
    rail_left: Profile
    rail_right: Profile
    gauge: float = 1.435
    flange_back_distance: float = 1.360
    r0_left: float = 0.46
    r0_right: float = 0.46
    inclination: float = 0.0
    inclination_about: tuple[float, float] = (0.0, 0.0)
    gauge_height: float = 0.014

    def __post_init__(self) -> None:
        for name in ("wheel_left", "wheel_right"):
            p = getattr(self, name)
            if not isinstance(p, Profile) or p.kind != "wheel":
                raise ValueError(f"{name}: must be a wheel Profile")
            if p.flange_back is None:
                raise ValueError(f"{name}: the wheel profile needs flange_back (y of the flange back, m)")
        for name in ("rail_left", "rail_right"):
            p = getattr(self, name)
            if not isinstance(p, Profile) or p.kind != "rail":
                raise ValueError(f"{name}: must be a rail Profile")
        for name in ("gauge", "flange_back_distance", "r0_left", "r0_right", "gauge_height"):
            object.__setattr__(self, name, positive(name, getattr(self, name)))
        object.__setattr__(self, "inclination", finite("inclination", self.inclination))
        if self.flange_back_distance >= self.gauge:
            raise ValueError(f"flange_back_distance: {self.flange_back_distance} m must be less than the gauge")
        for side in ("left", "right"):
            self.gauge_point(side)  # raises when the rail is too shallow

    @classmethod
    def symmetric(cls, wheel: Profile, rail: Profile, **kw: float) -> WheelsetTrack:
        """The same wheel and rail profile on both sides (``r0`` sets both radii)."""
        r0 = kw.pop("r0", None)
        if r0 is not None:
            kw.setdefault("r0_left", r0)
            kw.setdefault("r0_right", r0)
        return cls(wheel_left=wheel, wheel_right=wheel, rail_left=rail, rail_right=rail, **kw)

    def placed_rail(self, side: str) -> Profile:
        """The rail of ``side`` ("left"/"right") after this track's inclination (its own left-side frame)."""
        rail = self.rail_left if side == "left" else self.rail_right
        return incline(rail, self.inclination, self.inclination_about) if self.inclination else rail

    def gauge_point(self, side: str) -> tuple[float, float]:
        """(y, z), m, of the gauge point of the placed rail of ``side``, in its profile coordinates."""
        rail = self.placed_rail(side)
        i_top = int(np.argmax(rail.z))
        z_g = float(rail.z[i_top]) - self.gauge_height
        below = np.nonzero(rail.z[: i_top + 1] <= z_g)[0]
        if below.size == 0:
            raise ValueError(f"rail_{side}: the profile does not reach {self.gauge_height * 1e3:.3g} mm below its top "
                             "on the gauge side (gauge_height)")
        j = int(below[-1])
        if rail.z[j] == z_g:
            return float(rail.y[j]), z_g
        y_g = brentq(lambda t: float(rail.height(t)) - z_g, float(rail.y[j]), float(rail.y[j + 1]), xtol=1e-15)
        return float(y_g), z_g

    @property
    def e0(self) -> float:
        """Half the lateral spacing of the two taping lines, m (0.75 for S1002 at 1360 mm back-to-back)."""
        wl, wr = self.wheel_left, self.wheel_right
        return 0.5 * (self.flange_back_distance - wl.flange_back + wl.taping_line
                      - wr.flange_back + wr.taping_line)


# ---------------------------------------------------------------------------------------------------------------
# the table


_FLOAT_FIELDS = (
    "roll", "axle_height", "r_left", "r_right", "delta_r", "contact_angle_left", "contact_angle_right",
    "wheel_contact_left", "wheel_contact_right", "rail_contact_left", "rail_contact_right", "track_contact_left",
    "track_contact_right", "wheel_curvature_left", "wheel_curvature_right", "rail_curvature_left",
    "rail_curvature_right", "secondary_gap_left", "secondary_gap_right",
)
_BOOL_FIELDS = ("two_point_left", "two_point_right", "jump_left", "jump_right")


@dataclass(frozen=True, eq=False)
class ContactTable:
    """Rigid contact geometry against the wheelset's lateral shift (arrays of shape (n,), SI units).

    Attributes
    ----------
    y : lateral shift of the axle centre, m, positive to the left, strictly increasing.
    roll : wheelset roll φ, rad (positive: left wheel up).
    axle_height : height of the axle centre above the rails' reference level, m (≈ r0 + rail top).
    r_left, r_right : rolling radii, m;  delta_r = r_left − r_right, m.
    contact_angle_left, contact_angle_right : δ, rad, of the common tangent in the track frame, positive when
        the surface rises towards that side's field side (tread ≈ cone angle, flange ≈ 70°).
    wheel_contact_left/right : contact position on the wheel profile, m (its y coordinate: 0 = taping line).
    rail_contact_left/right : contact position on the rail profile as given to the track (before the track's
        own inclination), m.
    track_contact_left/right : lateral position of the contact point in the track frame, m (left > 0).
    wheel_curvature_left/right, rail_curvature_left/right : transverse curvature of the profile at the contact,
        1/m, positive when convex towards the other body (a rail crown R300: +3.33; a hollow tread: < 0).
    secondary_gap_left/right : least gap, m, at another local minimum of the gap more than ``separation`` away
        (inf if none): small values mean a second contact is near.
    two_point_left/right : secondary gap below ``two_point_gap`` (two-point contact).
    jump_left/right : True at i when the wheel contact position moved by more than ``jump_threshold`` between
        y[i−1] and y[i] (False at i = 0).
    r0, e0 : nominal rolling radius and half contact spacing, m (scalars, for :func:`.equivalent_conicity`).
    """

    y: np.ndarray
    roll: np.ndarray
    axle_height: np.ndarray
    r_left: np.ndarray
    r_right: np.ndarray
    delta_r: np.ndarray
    contact_angle_left: np.ndarray
    contact_angle_right: np.ndarray
    wheel_contact_left: np.ndarray
    wheel_contact_right: np.ndarray
    rail_contact_left: np.ndarray
    rail_contact_right: np.ndarray
    track_contact_left: np.ndarray
    track_contact_right: np.ndarray
    wheel_curvature_left: np.ndarray
    wheel_curvature_right: np.ndarray
    rail_curvature_left: np.ndarray
    rail_curvature_right: np.ndarray
    secondary_gap_left: np.ndarray
    secondary_gap_right: np.ndarray
    two_point_left: np.ndarray
    two_point_right: np.ndarray
    jump_left: np.ndarray
    jump_right: np.ndarray
    r0: float = 0.46
    e0: float = 0.75

    def __post_init__(self) -> None:
        y = np.array(self.y, dtype=float)
        if y.ndim != 1 or y.size < 1 or not np.all(np.isfinite(y)) or not np.all(np.diff(y) > 0.0):
            raise ValueError("y: must be a 1-D, finite, strictly increasing array")
        y.setflags(write=False)
        object.__setattr__(self, "y", y)
        for name in _FLOAT_FIELDS + _BOOL_FIELDS:
            a = np.array(getattr(self, name), dtype=bool if name in _BOOL_FIELDS else float)
            if a.shape != y.shape:
                raise ValueError(f"{name}: shape {a.shape} does not match y {y.shape}")
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        object.__setattr__(self, "r0", positive("r0", self.r0))
        object.__setattr__(self, "e0", positive("e0", self.e0))

    @property
    def jumps(self) -> np.ndarray:
        """Indices i where either contact jumps between y[i−1] and y[i], or either side has two-point contact."""
        return np.nonzero(self.jump_left | self.jump_right | self.two_point_left | self.two_point_right)[0]

    def flange_onset(self, angle_deg: float = 45.0) -> float:
        """The smallest shift y > 0 (m) at which the left wheel's contact angle exceeds ``angle_deg``: where the
        contact moves onto the flange (the flangeway clearance the wheelset can use); inf beyond the table."""
        steep = (self.y > 0) & (np.abs(self.contact_angle_left) > np.radians(angle_deg))
        return float(self.y[steep][0]) if np.any(steep) else math.inf

    def at(self, y: np.ndarray | float, kind: str = "linear") -> ContactTable:
        """The table interpolated at ``y`` (m, within [y[0], y[-1]]).

        ``kind="linear"``: piecewise linear between the nodes (keeps jumps sharp: use it for tables with
        flange contact); ``"cubic"``: not-a-knot cubic spline through the nodes (smooth tables only: a spline
        rings across a jump).  The boolean flags and the secondary gaps (which may be inf) are taken from the
        nearest node.  The result is tabulated at the sorted, distinct values of ``y``.

        Raises
        ------
        ValueError
            ``y`` outside the table, not finite, or ``kind`` unknown; ``"cubic"`` with fewer than 4 nodes.
        """
        q = np.atleast_1d(np.asarray(y, dtype=float))
        if q.ndim != 1 or not np.all(np.isfinite(q)):
            raise ValueError("y: must be finite numbers")
        if q.size and (q.min() < self.y[0] - 1e-15 or q.max() > self.y[-1] + 1e-15):
            raise ValueError(f"y: outside the table [{self.y[0]:.6g}, {self.y[-1]:.6g}] m")
        if kind not in ("linear", "cubic"):
            raise ValueError(f"kind: 'linear' or 'cubic', got {kind!r}")
        if kind == "cubic" and self.y.size < 4:
            raise ValueError("kind: 'cubic' needs at least 4 table nodes")
        order = np.argsort(q)
        qs = q[order]
        out: dict[str, np.ndarray] = {}
        nearest = np.clip(np.searchsorted(self.y, qs), 0, self.y.size - 1)
        left = np.clip(nearest - 1, 0, self.y.size - 1)
        nearest = np.where(np.abs(self.y[left] - qs) <= np.abs(self.y[nearest] - qs), left, nearest)
        by_node = _BOOL_FIELDS + ("secondary_gap_left", "secondary_gap_right")
        for name in _FLOAT_FIELDS + _BOOL_FIELDS:
            v = getattr(self, name)
            if name in by_node or not np.all(np.isfinite(v)):
                out[name] = v[nearest]
            elif kind == "linear":
                out[name] = np.interp(qs, self.y, v)
            else:
                out[name] = CubicSpline(self.y, v)(qs)
        qs_unique, first = np.unique(qs, return_index=True)
        picked = {k: v[first] for k, v in out.items()}
        return ContactTable(y=qs_unique, r0=self.r0, e0=self.e0, **picked)

    @classmethod
    def conical(cls, conicity: float, y: np.ndarray, r0: float = 0.46, e0: float = 0.75) -> ContactTable:
        """The ideal table of coned wheels (cone slope λ) on knife-edge rails, linear in y.

        r_l = r0 + λy, r_r = r0 − λy (Δr = 2λy), contact angles atan λ on both sides, roll φ = ψy with
        ψ = λ/(e0 − r0λ) (thesis (4.8) with θ0 = λ), contact positions on the wheels ∓y (the rail point fixed:
        rail positions 0, track positions ±e0), rail curvature inf (knife edge: no Hertz ellipse), wheel 0.
        For checking the nonlinear model against the linear one (``WheelRailGeometry.coned``).
        """
        lam = finite("conicity", conicity)
        r0 = positive("r0", r0)
        e0 = positive("e0", e0)
        y = np.asarray(y, dtype=float)
        n = y.shape
        psi = lam / (e0 - r0 * lam)
        zeros, ones = np.zeros(n), np.ones(n)
        return cls(
            y=y, roll=psi * y, axle_height=r0 * ones, r_left=r0 + lam * y, r_right=r0 - lam * y,
            delta_r=2.0 * lam * y, contact_angle_left=math.atan(lam) * ones, contact_angle_right=math.atan(lam) * ones,
            wheel_contact_left=-y, wheel_contact_right=y.copy(), rail_contact_left=zeros, rail_contact_right=zeros,
            track_contact_left=e0 * ones, track_contact_right=-e0 * ones, wheel_curvature_left=zeros,
            wheel_curvature_right=zeros, rail_curvature_left=np.full(n, np.inf),
            rail_curvature_right=np.full(n, np.inf), secondary_gap_left=np.full(n, np.inf),
            secondary_gap_right=np.full(n, np.inf), two_point_left=np.zeros(n, bool), two_point_right=np.zeros(n, bool),
            jump_left=np.zeros(n, bool), jump_right=np.zeros(n, bool), r0=r0, e0=e0,
        )

    def hertz_curvatures(self, side: str) -> tuple[np.ndarray, np.ndarray]:
        """Relative curvatures (A, B), 1/m, shape (n,), of the contact on ``side`` for :func:`.hertz_ellipse`.

        A = cos δ_w / (2 r): the wheel's principal curvature along the rolling direction at a point whose
        normal makes the angle δ_w with the wheel's radius (δ_w = δ ∓ φ, the profile slope angle in the
        wheelset frame; Meusnier), the rail being straight.  B = ½ (κ_wheel + κ_rail), the transverse
        curvatures convex-positive — the same as ``wheel_rail_curvatures``: B = ½(1/R_rail − 1/R_wheel,concave).
        """
        if side not in ("left", "right"):
            raise ValueError(f"side: 'left' or 'right', got {side!r}")
        sigma = 1.0 if side == "left" else -1.0
        delta_w = getattr(self, f"contact_angle_{side}") - sigma * self.roll
        A = 0.5 * np.cos(delta_w) / getattr(self, f"r_{side}")
        B = 0.5 * (getattr(self, f"wheel_curvature_{side}") + getattr(self, f"rail_curvature_{side}"))
        return A, B


def hertz_ellipses(table: ContactTable, normal_load_left: np.ndarray | float,
                   normal_load_right: np.ndarray | float | None = None, E: float = 2.1e11,
                   nu: float = 0.28) -> tuple[list[HertzEllipse], list[HertzEllipse]]:
    """Hertz ellipse of every contact point of ``table`` (:func:`.hertz_ellipse`, thesis (4.19)–(4.20)).

    Parameters
    ----------
    normal_load_left, normal_load_right : float or array of shape (n,)
        Normal contact loads, N (right defaults to left).
    E, nu : float
        Young's modulus (Pa) and Poisson's ratio of wheel and rail (one material).

    Returns
    -------
    (left, right) : two lists of n :class:`.HertzEllipse` (a along the rolling direction, b lateral).

    Raises
    ------
    ValueError
        Naming the side and y where B ≤ 0 (conformal contact: no Hertz ellipse) or the curvature is infinite
        (knife edge), and the loads' shapes.
    """
    loads = {}
    for side, value in (("left", normal_load_left),
                        ("right", normal_load_left if normal_load_right is None else normal_load_right)):
        arr = np.broadcast_to(np.asarray(value, dtype=float), table.y.shape) if np.ndim(value) == 0 \
            else np.asarray(value, dtype=float)
        if arr.shape != table.y.shape:
            raise ValueError(f"normal_load_{side}: shape {arr.shape} does not match the table {table.y.shape}")
        loads[side] = arr
    result: dict[str, list[HertzEllipse]] = {}
    for side in ("left", "right"):
        A, B = table.hertz_curvatures(side)
        ellipses = []
        for i in range(table.y.size):
            if not (np.isfinite(A[i]) and np.isfinite(B[i]) and B[i] > 0.0):
                raise ValueError(f"table: the {side} contact at y = {table.y[i]:.6g} m has B = {B[i]:.6g} 1/m "
                                 "(conformal or knife-edge contact: no Hertz ellipse)")
            ellipses.append(hertz_ellipse(float(loads[side][i]), E, nu, float(A[i]), float(B[i])))
        result[side] = ellipses
    return result["left"], result["right"]


# ---------------------------------------------------------------------------------------------------------------
# the solver


class _Side:
    """One wheel over its rail, in the track frame: vectorised gap evaluation (see the module doc)."""

    def __init__(self, track: WheelsetTrack, side: str, grid_step: float) -> None:
        self.sigma = 1.0 if side == "left" else -1.0
        self.wheel = track.wheel_left if side == "left" else track.wheel_right
        self.rail = track.placed_rail(side)
        self.r0 = track.r0_left if side == "left" else track.r0_right
        self.b = 0.5 * track.flange_back_distance - float(self.wheel.flange_back)
        self.z_tape = float(self.wheel.height(self.wheel.taping_line))
        y_g, _ = track.gauge_point(side)
        self.a = 0.5 * track.gauge - y_g  # rail profile coordinate p at track Y: p = σY − a
        w0, w1 = float(self.wheel.y[0]), float(self.wheel.y[-1])
        n = max(int(math.ceil((w1 - w0) / grid_step)) + 1, 8)
        self.w = np.linspace(w0, w1, n)
        self.u = self.sigma * (self.b + self.w)
        self.v = self.wheel.height(self.w) - self.z_tape - self.r0
        self.inclination = track.inclination
        self.about = track.inclination_about

    def grid_gap(self, y: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """Vertical gap (h = 0) at every wheel grid point, shape (n, m); inf where there is no rail below."""
        c, s = np.cos(phi)[:, None], np.sin(phi)[:, None]
        Y = y[:, None] + self.u[None, :] * c - self.v[None, :] * s
        Z = self.u[None, :] * s + self.v[None, :] * c
        g = Z - self.rail.height(self.sigma * Y - self.a)
        return np.where(np.isfinite(g), g, np.inf)

    def local(self, y: np.ndarray, phi: np.ndarray, w: np.ndarray) -> dict[str, np.ndarray]:
        """Gap and its derivatives along the wheel profile at wheel points ``w`` (continuous splines)."""
        sg = self.sigma
        c, s = np.cos(phi), np.sin(phi)
        zw, zw1, zw2 = self.wheel.height(w), self.wheel.slope(w), self.wheel.second_derivative(w)
        u, v = sg * (self.b + w), zw - self.z_tape - self.r0
        Y = y + u * c - v * s
        Z = u * s + v * c
        Y1, Y2 = sg * c - zw1 * s, -zw2 * s
        Z1, Z2 = sg * s + zw1 * c, zw2 * c
        p = sg * Y - self.a
        R0, R1, R2 = self.rail.height(p), self.rail.slope(p), self.rail.second_derivative(p)
        p1, p2 = sg * Y1, sg * Y2
        g = Z - R0
        g1 = Z1 - R1 * p1
        g2 = Z2 - (R2 * p1 * p1 + R1 * p2)
        dg_dphi = (Y - y) + sg * R1 * Z  # ∂g/∂φ at fixed w (envelope theorem: = dd/dφ at the minimum)
        return {"g": g, "g1": g1, "g2": g2, "dphi": dg_dphi, "Y": Y, "Z": Z, "p": p, "Y1": Y1, "Z1": Z1,
                "zw1": zw1, "zw2": zw2, "R1": R1, "R2": R2}

    def min_gap(self, y: np.ndarray, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(least gap d, its wheel point w*, dd/dφ, the grid gaps) for h = 0."""
        G = self.grid_gap(y, phi)
        k = np.argmin(G, axis=1)
        if not np.all(np.isfinite(G[np.arange(k.size), k])):
            bad = np.nonzero(~np.isfinite(G[np.arange(k.size), k]))[0][0]
            raise ValueError(f"y: at y = {y[bad]:.6g} m the wheel is not above its rail (no overlap)")
        h = self.w[1] - self.w[0]
        lo = self.w[np.maximum(k - 1, 0)]
        hi = self.w[np.minimum(k + 1, self.w.size - 1)]
        w = self.w[k].copy()
        for _ in range(4):
            loc = self.local(y, phi, w)
            ok = np.isfinite(loc["g2"]) & (loc["g2"] > 0.0) & np.isfinite(loc["g1"])
            step = np.where(ok, -loc["g1"] / np.where(ok, loc["g2"], 1.0), 0.0)
            w = np.clip(w + np.clip(step, -h, h), lo, hi)
        loc = self.local(y, phi, w)
        d = np.where(np.isfinite(loc["g"]), loc["g"], G[np.arange(k.size), k])
        d = np.minimum(d, G[np.arange(k.size), k])  # never above the grid value
        return d, w, loc["dphi"], G


def rigid_contact_table(track: WheelsetTrack, y: np.ndarray, *, grid_step: float = 5e-5,
                        two_point_gap: float = 2e-5, separation: float = 2e-3,
                        jump_threshold: float = 2e-3, roll_bracket: float = 0.02, roll: bool = True) -> ContactTable:
    """Rigid contact geometry of ``track`` at the lateral shifts ``y`` (m, strictly increasing); see the module doc.

    Parameters
    ----------
    grid_step : float
        Spacing, m, of the wheel points searched for the least gap before Newton refinement (0.05 mm).
    two_point_gap, separation : float
        A second local minimum of the gap more than ``separation`` (m) from the contact and less than
        ``two_point_gap`` (m) open flags two-point contact (0.02 mm: well inside the elastic approach of a
        loaded wheel, 0.05–0.1 mm, so such a point carries load in reality).
    jump_threshold : float
        A move of the wheel contact position larger than this (m) between neighbouring y flags a jump.
    roll_bracket : float
        The roll is sought in [−roll_bracket, roll_bracket], rad.
    roll : bool
        True (default): the rigid wheelset rolls (the physical solution above).  False: the roll's rotation
        of the profiles is neglected — each wheel is lowered vertically onto its rail with φ = 0 in the
        geometry, and ``roll`` reports the implied small angle (h_l − h_r)/(Y_l − Y_r).  This is how the
        EN 15302 Annex E reference Δr tables are computed (found by comparison: with roll the flange contact
        of case E1 starts 0.3–0.4 mm earlier than in the reference table, without roll it matches it to
        0.01 mm; see docs/contact_geometry.md); use it to reproduce those tables, not for dynamics.

    Returns
    -------
    ContactTable

    Raises
    ------
    ValueError
        ``y`` not 1-D strictly increasing finite; a wheel not above its rail; no roll in the bracket that makes
        both wheels touch (naming y).
    """
    y = np.asarray(y, dtype=float)
    if y.ndim != 1 or y.size < 1 or not np.all(np.isfinite(y)) or not np.all(np.diff(y) > 0.0):
        raise ValueError("y: must be a 1-D, finite, strictly increasing array of lateral shifts (m)")
    grid_step = positive("grid_step", grid_step)
    two_point_gap = positive("two_point_gap", two_point_gap)
    separation = positive("separation", separation)
    jump_threshold = positive("jump_threshold", jump_threshold)
    roll_bracket = positive("roll_bracket", roll_bracket)
    left, right = _Side(track, "left", grid_step), _Side(track, "right", grid_step)

    def H(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        dl, _, sl, _ = left.min_gap(y, phi)
        dr, _, sr, _ = right.min_gap(y, phi)
        return dl - dr, sl - sr

    if not roll:
        return _table_at(track, y, left, right, np.zeros(y.shape), two_point_gap, separation, jump_threshold,
                         rolled=False)
    lo = np.full(y.shape, -roll_bracket)
    hi = np.full(y.shape, roll_bracket)
    h_lo, _ = H(lo)
    h_hi, _ = H(hi)
    bad = ~((h_lo < 0.0) & (h_hi > 0.0))
    if bad.any():
        i = int(np.nonzero(bad)[0][0])
        raise ValueError(f"y: at y = {y[i]:.6g} m no roll within ±{roll_bracket} rad lets both wheels touch "
                         "(roll_bracket, or the wheelset is off the rails)")
    phi = np.zeros(y.shape)
    for _ in range(100):
        h, dh = H(phi)
        lo = np.where(h < 0.0, phi, lo)
        hi = np.where(h > 0.0, phi, hi)
        done = (np.abs(h) < 1e-13) | (hi - lo < 1e-15)
        if done.all():
            break
        newton = phi - h / np.where(dh > 0.0, dh, np.inf)
        inside = (dh > 0.0) & (newton > lo) & (newton < hi)
        phi = np.where(done, phi, np.where(inside, newton, 0.5 * (lo + hi)))
    else:  # pragma: no cover - the bracketed iteration halves the bracket at worst
        raise ValueError("y: the roll iteration did not converge")
    return _table_at(track, y, left, right, phi, two_point_gap, separation, jump_threshold, rolled=True)


def _table_at(track: WheelsetTrack, y: np.ndarray, left: _Side, right: _Side, phi: np.ndarray,
              two_point_gap: float, separation: float, jump_threshold: float, rolled: bool) -> ContactTable:
    """The contact quantities at the solved roll ``phi`` (or at φ = 0 with independent wheels: ``rolled=False``)."""
    out: dict[str, np.ndarray] = {"roll": phi}
    dl, wl, _, Gl = left.min_gap(y, phi)
    dr, wr, _, Gr = right.min_gap(y, phi)
    out["axle_height"] = -0.5 * (dl + dr)
    for name, side, d, w, G in (("left", left, dl, wl, Gl), ("right", right, dr, wr, Gr)):
        loc = side.local(y, phi, w)
        sg = side.sigma
        out[f"r_{name}"] = side.r0 - (side.wheel.height(w) - side.z_tape)
        out[f"contact_angle_{name}"] = np.arctan2(loc["Z1"], sg * loc["Y1"])
        out[f"wheel_contact_{name}"] = w
        p, zr = loc["p"], side.rail.height(loc["p"])
        if side.inclination:  # back to the rail profile as given: undo the track's inclination
            a = -math.atan(side.inclination)
            y0, z0 = side.about
            p = y0 + math.cos(a) * (p - y0) - math.sin(a) * (zr - z0)
        out[f"rail_contact_{name}"] = p
        out[f"track_contact_{name}"] = loc["Y"]
        out[f"wheel_curvature_{name}"] = side.wheel.curvature(w)
        out[f"rail_curvature_{name}"] = -side.rail.curvature(loc["p"])
        # second local minima of the gap, away from the contact
        gap = G - d[:, None]
        interior = np.full(gap.shape, False)
        interior[:, 1:-1] = (gap[:, 1:-1] <= gap[:, :-2]) & (gap[:, 1:-1] <= gap[:, 2:]) & np.isfinite(gap[:, 1:-1])
        far = np.abs(side.w[None, :] - w[:, None]) > separation
        cand = np.where(interior & far, gap, np.inf)
        sec = np.maximum(cand.min(axis=1), 0.0)
        out[f"secondary_gap_{name}"] = sec
        out[f"two_point_{name}"] = sec < two_point_gap
        jump = np.zeros(y.shape, bool)
        jump[1:] = np.abs(np.diff(w)) > jump_threshold
        out[f"jump_{name}"] = jump
    out["delta_r"] = out["r_left"] - out["r_right"]
    if not rolled:  # the small roll implied by the two wheels' different heights
        out["roll"] = (dr - dl) / (out["track_contact_left"] - out["track_contact_right"])
    return ContactTable(y=y, r0=0.5 * (track.r0_left + track.r0_right), e0=track.e0, **out)


def contact_table_fields() -> tuple[str, ...]:
    """Names of the (n,)-array fields of :class:`ContactTable`, in order."""
    return tuple(f.name for f in fields(ContactTable) if f.name not in ("r0", "e0"))


__all__ = ["ContactTable", "WheelsetTrack", "contact_table_fields", "hertz_ellipses", "rigid_contact_table"]
