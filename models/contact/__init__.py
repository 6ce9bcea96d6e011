"""Wheel/rail contact: geometry, Hertz ellipse, creep coefficients, gravity stiffness, conicity.

Thesis §4.2.1–4.2.2, equations (4.1)–(4.32) and (4.43)–(4.49); SI units throughout (m, N, rad, Pa).
Details, sources, sign conventions and the garbled-OCR notes: ``docs/contact.md``.

Public API
----------
Geometry (4.1)–(4.8) — :mod:`.geometry`

* ``WheelRailGeometry(r0, e0, conicity, theta0, epsilon, eta=0.0)`` — frozen; ``.psi`` (4.8), ``.l18`` = 2 e0,
  ``.l20`` = r0, ``.contact_angles(v, alpha_de=0.0)``, ``.contact_distances(v)``, ``.rolling_radii(v)``,
  ``.roll(v)``; constructors ``WheelRailGeometry.coned(r0, e0, conicity)`` and
  ``WheelRailGeometry.from_circular_profiles(r0, e0, delta0, R_wheel, R_rail)``.
  ``v`` is positive towards the right rail (the thesis's convention).

Hertz (4.19)–(4.20) — :mod:`.hertz`

* ``hertz_ellipse(N, E, nu, A, B) -> HertzEllipse(a, b, m, n, p0)`` (``.c`` = √(ab), ``.aspect`` = a/b);
  a along the rolling direction, A, B the relative curvatures along x (rolling) and y (lateral).
* ``hertz_coefficients(curvature_ratio) -> (m, n, g)``;
  ``wheel_rail_curvatures(r_wheel, R_rail, R_wheel_transverse=inf) -> (A, B)``.

Creep (4.9)–(4.32) — :mod:`.creep`

* ``creep_coefficients(a, b, G, nu, theory="vermeulen-johnson" | "kalker" | "carter", factor=1.0, *, r0=None,
  N=None) -> CreepCoefficients``
* ``CreepCoefficients(f11, f22, f23=0.0, f33=0.0, f32=None)`` — per wheel; f11, f22 in N, f23, f32 in N·m,
  f33 in N·m²; f32 defaults to −f23; ``.scaled(factor)``, ``.forces(xi_x, xi_y, xi_sp)``.
* ``kalker_coefficients(a_over_b, nu) -> array([C11, C22, C23, C33])``,
  ``vermeulen_johnson_phi_psi(a_over_b, nu) -> (Phi, Psi1)``, ``carter_coefficient(r0, N)`` (N).

Gravity and track roll (4.43)–(4.49) — :mod:`.gravity` (coefficients on the equations' left-hand sides)

* ``lateral_gravity_stiffness(W, geometry)`` = Wε/e0 (N/m); ``lateral_track_roll_coupling(W)`` = −W;
  ``roll_gravity_stiffness(W, geometry)`` = −W(η + r0ε/e0); ``roll_track_roll_coupling(W, geometry)`` = r0 W;
  ``roll_load_transfer_arm(geometry)`` = e0 − r0θ0; ``yaw_gravity_stiffness(W, geometry)`` = −e0θ0W;
  ``track_roll_terms(W, e0, K_e_roll, C_e_roll, m_e) -> TrackRollTerms``.

Equivalent conicity (EN 15302 integral method) — :mod:`.conicity`

* ``equivalent_conicity(y, delta_r, amplitude, r0=0.46, e0=0.75) -> float`` (tan γe); Δr = r_l − r_r,
  y positive to the left; ``kinematic_wavelength(...)`` (m), ``turning_points(y, delta_r, amplitude)``,
  ``linear_delta_r_table(conicity, y_max=0.012, n=241) -> (y, delta_r)``.

Creep saturation (nonlinear creep forces) — :mod:`.saturation`, :mod:`.fastsim`; ``docs/creep_saturation.md``

* ``shen_hedrick_elkins(coefficients, xi_x, xi_y, xi_sp, N, mu, spin_moment="scaled") -> SaturatedCreepForces``
  (``.Tx``, ``.Ty`` N, ``.Mz`` N·m, ``.epsilon``, ``.ratio``; arrays broadcast); ``shen_hedrick_elkins_jacobian(...)``
  -> ∂(Tx, Ty, Mz)/∂(ξx, ξy, ξsp), shape ``S + (3, 3)``, equal to the linear law at zero creep;
  ``she_force_ratio(r)`` (the Vermeulen–Johnson cubic).
* ``fastsim(xi_x, xi_y, xi_sp, a, b, N, mu, G, nu, *, flexibilities=None, n_x=64, n_y=64, bound="parabolic",
  tractions=False) -> FastsimResult`` (``.Fx``, ``.Fy`` N, ``.Mz`` N·m; optional ``.x``, ``.y``, ``.px``, ``.py``,
  ``.slip``, ``.slip_fraction``); ``fastsim_flexibilities(a, b, G, nu) -> (L1, L2, L3)`` (m³/N).

Profiles — :mod:`.profiles`; ``docs/contact_geometry.md``

* ``Profile(y, z, kind, name="", flange_back=None, taping_line=0.0, source="")`` — frozen; one wheel or rail
  section seen as the LEFT one: y (m) towards the field side, z (m) UP; ``.height/.slope/.curvature(y)``,
  ``.rolling_radius(y, r0)``, ``.inclined(t)``; ``load_profile(name_or_path)`` (``PROFILE_NAMES``: "s1002",
  "60e1" = "uic60", "mbench_s1002", "mbench_uic60", "r_uic519_a/b/h/i", "s_uic519_a"; or a .prw/.prr/CSV path),
  ``read_simpack_profile(path)``, ``read_profile_csv(path, kind)`` (mm), ``s1002()``, ``rail_60e1()``,
  ``incline(rail, 1/40, about=(0, 0))``.

Rigid contact geometry tables — :mod:`.rigid_contact`; ``docs/contact_geometry.md``

* ``WheelsetTrack(wheel_left, wheel_right, rail_left, rail_right, gauge=1.435, flange_back_distance=1.360,
  r0_left=0.46, r0_right=0.46, inclination=0.0, gauge_height=0.014)``, ``WheelsetTrack.symmetric(wheel, rail,
  r0=..., ...)``.
* ``rigid_contact_table(track, y, roll=True, ...) -> ContactTable`` — frozen, arrays (n,): ``roll``, ``r_left``,
  ``r_right``, ``delta_r`` (= r_l − r_r, y positive to the left: feeds ``equivalent_conicity`` directly), contact
  angles, contact positions on wheel/rail/track, transverse curvatures, ``two_point_*``/``jump_*`` flags;
  ``.at(y, kind="linear"|"cubic")``, ``ContactTable.conical(λ, y, r0, e0)``; ``hertz_ellipses(table, N_left,
  N_right=None, E, nu) -> (left, right)`` lists of ``HertzEllipse``.
"""

from railopt.models.contact.conicity import (
    equivalent_conicity,
    kinematic_wavelength,
    linear_delta_r_table,
    turning_points,
)
from railopt.models.contact.creep import (
    CARTER_CONSTANT_SI,
    CARTER_CONSTANT_US,
    THEORIES,
    CreepCoefficients,
    carter_coefficient,
    creep_coefficients,
    johnson_spin,
    kalker_coefficients,
    vermeulen_johnson_phi_psi,
)
from railopt.models.contact.fastsim import FastsimResult, fastsim, fastsim_flexibilities
from railopt.models.contact.geometry import WheelRailGeometry
from railopt.models.contact.gravity import (
    TrackRollTerms,
    lateral_gravity_stiffness,
    lateral_track_roll_coupling,
    roll_gravity_stiffness,
    roll_load_transfer_arm,
    roll_track_roll_coupling,
    track_roll_terms,
    yaw_gravity_stiffness,
)
from railopt.models.contact.hertz import HertzEllipse, hertz_coefficients, hertz_ellipse, wheel_rail_curvatures
from railopt.models.contact.profiles import (
    PROFILE_NAMES,
    Profile,
    incline,
    load_profile,
    rail_60e1,
    read_profile_csv,
    read_simpack_profile,
    s1002,
)
from railopt.models.contact.rigid_contact import ContactTable, WheelsetTrack, hertz_ellipses, rigid_contact_table
from railopt.models.contact.saturation import (
    SaturatedCreepForces,
    she_force_ratio,
    shen_hedrick_elkins,
    shen_hedrick_elkins_jacobian,
)

__all__ = [
    "CARTER_CONSTANT_SI",
    "CARTER_CONSTANT_US",
    "THEORIES",
    "CreepCoefficients",
    "HertzEllipse",
    "TrackRollTerms",
    "WheelRailGeometry",
    "carter_coefficient",
    "creep_coefficients",
    "equivalent_conicity",
    "hertz_coefficients",
    "hertz_ellipse",
    "johnson_spin",
    "kalker_coefficients",
    "kinematic_wavelength",
    "lateral_gravity_stiffness",
    "lateral_track_roll_coupling",
    "linear_delta_r_table",
    "roll_gravity_stiffness",
    "roll_load_transfer_arm",
    "roll_track_roll_coupling",
    "track_roll_terms",
    "turning_points",
    "vermeulen_johnson_phi_psi",
    "wheel_rail_curvatures",
    "yaw_gravity_stiffness",
    "FastsimResult",
    "SaturatedCreepForces",
    "fastsim",
    "fastsim_flexibilities",
    "she_force_ratio",
    "shen_hedrick_elkins",
    "shen_hedrick_elkins_jacobian",
    "ContactTable",
    "PROFILE_NAMES",
    "Profile",
    "WheelsetTrack",
    "hertz_ellipses",
    "incline",
    "load_profile",
    "rail_60e1",
    "read_profile_csv",
    "read_simpack_profile",
    "rigid_contact_table",
    "s1002",
]
