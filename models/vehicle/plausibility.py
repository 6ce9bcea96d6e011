"""Plausibility of a loaded vehicle: warnings (not errors) about values that load but look wrong.

A vehicle file can be valid and still wrong by a unit, a sign, a swap or a missing part: a stiffness in kN/m,
a semi-wheelbase in mm, Ixx and Izz swapped, a wheelset deleted with its elements.  :func:`plausibility` returns
one :class:`~railopt.models.vehicle.plausibility_warning.PlausibilityWarning` per suspicious value, naming the
file, the key and the likely slip (``looks like mm: 1280 → 1.28 m?``, :mod:`railopt.models.vehicle.slips`).
``railopt validate car.toml`` and ``railopt vehicle car.toml`` print them.  This module checks values against
published ranges (the bands below, each with its source); :mod:`railopt.models.vehicle.layout_checks` checks the
layout (positions against the vehicle's own extent and wheelbase, bogies, point pairs, gyration against the
bodies' size, element roles and directions, symmetry); the lateral and bounce frequencies of the sprung bodies
are checked here from one eigen-solve each.  Every check and the slips it catches: ``docs/vehicle.md``.
"""

from __future__ import annotations

import math
import re

import numpy as np

from railopt.models.units import GRAVITY, INCH, rad_s_to_hz
from railopt.models.vehicle.elements import GROUND
from railopt.models.vehicle.layout_checks import layout_checks
from railopt.models.vehicle.plausibility_warning import PlausibilityWarning, body_label, suffix, value_key
from railopt.models.vehicle.running_gear import link_counts
from railopt.models.vehicle.slips import (
    ANGLE_UNITS,
    BENDING_UNITS,
    DAMPING_UNITS,
    FORCE_UNITS,
    INERTIA_UNITS,
    LENGTH_UNITS,
    MASS_PER_LENGTH_UNITS,
    MASS_UNITS,
    MODULUS_UNITS,
    RATIO_UNITS,
    ROTATIONAL_DAMPING_UNITS,
    ROTATIONAL_STIFFNESS_UNITS,
    STIFFNESS_UNITS,
    likely_slip,
)
from railopt.models.vehicle.vehicle import Vehicle

# Bands.  "usual" bands enclose the running gear of the sources with a margin of 2-10x; a value outside is not
# impossible, only worth a second look.  Sources: S. Iwnicki (ed.), Handbook of Railway Vehicle Dynamics, CRC
# 2006 (ch. 3, the anatomy of running gear) and the Manchester benchmark vehicles (Iwnicki 1998, VSD 30:295);
# wheels EN 13979-1 (new diameters 0.63-1.25 m); loading gauges EN 15273 / UIC 505-1; equivalent conicity
# EN 15302 and UIC 518 (0.05-0.4 in service); track modulus AREMA Manual ch. 16 and Selig & Waters, Track
# Geotechnology (1994): 1,000-10,000 lb/in/in (7-70 MN/m^2) with slab track above; rails EN 13674-1 (49E1 ...
# 60E1: EI 3.8-6.5 MN m^2) and AREMA 115-141 RE (EI 6-8.5 MN m^2).
AXLE_LOAD_T = (3.0, 40.0)  # static load per wheelset, t: light rail ~5 t, heavy haul 35-40 t (EN 15528 up to 25 t)
MIN_MASS_KG = 50.0  # a rigid body of a rail vehicle weighs more
WHEELSET_MASS_KG = (300.0, 5000.0)  # tram wheelset ~0.5 t ... locomotive wheelset with gear wheel ~3.5 t
GYRATION_M = (0.05, 15.0)  # radius of gyration sqrt(I/m), any body, m
CG_HEIGHT_M = (0.0, 5.0)  # CG z above rail, m
WHEELSET_CG_TOL_M = 0.1  # |z_cg − r0| of a wheelset, m
WHEEL_RADIUS_M = (0.3, 0.65)  # EN 13979-1: new wheels 0.63-1.25 m in diameter (worn to ~0.58 m)
SEMI_GAUGE_M = (0.5, 0.9)  # half the contact-point spacing: metre gauge 0.5 ... broad gauge 1,676 mm (0.84)
CONICITY_MAX = 0.5  # above: not a tread conicity (EN 15302 / UIC 518 limits are 0.15-0.4)
CONICITY_USUAL = (0.02, 0.5)  # where a rescaled conicity may land (new 1:40 wheels ~0.02-0.05, worn ~0.4)
THETA0_MAX_RAD = 0.3  # contact angle of a tread contact (1:20 cone: 0.05 rad); flange contacts are ~1.2 rad
CREEP_COEFFICIENT_N = (5.0e5, 1.0e8)  # Kalker f11, f22 per wheel: ~4 MN (5 t axle) ... ~25 MN (40 t axle)
CREEP_FACTOR_MAX = 2.0  # a reduction factor of Kalker's coefficients (0.3-1 usual)
YOUNGS_MODULUS_PA = (1.5e11, 2.6e11)  # wheel and rail steel: 205-215 GPa
POISSON_RATIO = (0.2, 0.35)  # steel: 0.28-0.30
RAIL_HEAD_RADIUS_M = (0.08, 1.0)  # crown radii of rail heads: 80 mm (shoulder) ... 300-600 mm (crown)
TRACK_MODULUS_N_M2 = (3.0e6, 3.0e8)  # per rail: AREMA/Selig & Waters 7-70 MN/m^2, slab track to ~200
RAIL_EI_N_M2 = (1.0e6, 1.5e7)  # one rail: light 30 kg/m rail ~1.3 MN m^2 ... 141 RE ~8.5 MN m^2
TRACK_MASS_KG_M = (30.0, 600.0)  # rail (30-70 kg/m) plus participating sleeper mass, per rail
TRACK_DAMPING_MAX = 1.0  # a damping ratio (0.05-0.3 usual); above 1: per cent?
CLEARANCE_M = (1e-3, 0.5)  # free travels before a stop: lateral bump stops 20-60 mm, vertical up to ~0.1 m
SPRING_N_PER_M = (2.0e4, 2.0e9)  # softest air-spring shear ~0.1 MN/m; a 50 mm steel rod 1 m long ~0.4 GN/m
DAMPER_N_S_PER_M = (1.0e3, 1.0e7)  # smallest hydraulic dampers of running gear ~2 kN s/m; yaw dampers <~2 MN s/m
ROTATIONAL_SPRING_N_M_PER_RAD = (1.0e3, 1.0e8)  # air-spring yaw ~10 kN m/rad ... anti-roll bars 0.5-3 MN m/rad
ROTATIONAL_DAMPER_N_M_S_PER_RAD = (100.0, 1.0e8)
BODY_FREQUENCY_HZ = (0.3, 3.0)  # lateral and bounce of a body on the secondary suspension (ride: ~0.5-1.5 Hz)
NOMINAL_SPEED = 20.0  # m/s, for the eigen-solves
WHEELSET_NAME = re.compile(r"(wheel|axle|^ws\d)", re.IGNORECASE)
ELEMENT_BANDS = {
    "spring": (SPRING_N_PER_M, STIFFNESS_UNITS, "N/m", "a spring"),
    "damper": (DAMPER_N_S_PER_M, DAMPING_UNITS, "N·s/m", "a damper"),
    "rotational_spring": (ROTATIONAL_SPRING_N_M_PER_RAD, ROTATIONAL_STIFFNESS_UNITS, "N·m/rad", "a rotational spring"),
    "rotational_damper": (ROTATIONAL_DAMPER_N_M_S_PER_RAD, ROTATIONAL_DAMPING_UNITS, "N·m·s/rad",
                          "a rotational damper"),
}
"""Element type -> (usual band, units a slip is written in, SI unit, what it is)."""


def _outside(x: float, band: tuple[float, float]) -> bool:
    return not (band[0] <= x <= band[1])


def _band(band: tuple[float, float], unit: str = "") -> str:
    u = f" {unit}" if unit else ""
    return f"{band[0]:g}-{band[1]:g}{u}"


def plausibility(vehicle: Vehicle, speed: float = NOMINAL_SPEED) -> list[PlausibilityWarning]:
    """Warnings about values of ``vehicle`` that look wrong (units, magnitudes, swaps, missing parts, links).

    Parameters
    ----------
    vehicle : Vehicle
        A loaded vehicle.
    speed : float
        Forward speed of the eigen-solves (m/s).

    Returns
    -------
    list of PlausibilityWarning
        Empty when nothing looks wrong; each names the file (``vehicle.path``), the key and the likely slip; in
        the order masses, heights, contact, track, clearances, elements, layout, links, frequencies.
    """
    out: list[PlausibilityWarning] = []
    out += _masses(vehicle)
    out += _geometry(vehicle)
    out += _contact(vehicle)
    out += _track(vehicle)
    out += _clearances(vehicle)
    out += _elements(vehicle)
    out += layout_checks(vehicle)
    out += _links(vehicle)
    out += _frequencies(vehicle, speed)
    return [PlausibilityWarning(w.path, w.message, w.value, w.check, vehicle.path) for w in out]


def _masses(v: Vehicle) -> list[PlausibilityWarning]:
    out = []
    for b in v.bodies:
        label = body_label(v, b.name)
        if b.mass < MIN_MASS_KG:
            slip = likely_slip(b.mass, (MIN_MASS_KG, 2.0e5), MASS_UNITS, "kg")
            out.append(PlausibilityWarning(f"{label}.mass_kg", f"{b.mass:g} kg is below {MIN_MASS_KG:g} kg for a "
                                           f"rigid body of a rail vehicle (the unit is kg){suffix(slip)}",
                                           b.mass, "mass"))
        elif b.kind == "wheelset" and _outside(b.mass, WHEELSET_MASS_KG):
            slip = likely_slip(b.mass, WHEELSET_MASS_KG, MASS_UNITS, "kg")
            out.append(PlausibilityWarning(f"{label}.mass_kg", f"a wheelset of {b.mass:g} kg is outside the usual "
                                           f"{_band(WHEELSET_MASS_KG, 'kg')}{suffix(slip)}", b.mass, "mass"))
        for k, axis in enumerate(("Ixx", "Iyy", "Izz")):
            r = math.sqrt(b.inertia[k][k] / b.mass)
            if _outside(r, GYRATION_M):
                slip = likely_slip(b.inertia[k][k], (b.mass * GYRATION_M[0] ** 2, b.mass * GYRATION_M[1] ** 2),
                                   INERTIA_UNITS, "kg·m²")
                out.append(PlausibilityWarning(
                    f"{label}.inertia_kg_m2[{k}]", f"radius of gyration sqrt({axis}/m) = {r:.3g} m is outside "
                    f"{_band(GYRATION_M, 'm')}: mass or inertia in the wrong unit?{suffix(slip)}", r, "gyration"))
    n = len(v.wheelsets)
    if n:
        load_t = v.total_mass / n / 1000.0
        path = "bodies (total mass / wheelsets)"
        if v.contact is not None and v.contact.axle_load is not None:
            load_t = v.contact.axle_load / GRAVITY / 1000.0
            path = "contact.axle_load_N"
        if _outside(load_t, AXLE_LOAD_T):
            slip = likely_slip(v.contact.axle_load, (AXLE_LOAD_T[0] * 1e3 * GRAVITY, AXLE_LOAD_T[1] * 1e3 * GRAVITY),
                               FORCE_UNITS, "N") if path == "contact.axle_load_N" else ""
            out.append(PlausibilityWarning(
                path, f"axle load {load_t:.3g} t (total mass {v.total_mass:,.0f} kg on {n} wheelsets) is outside "
                f"{_band(AXLE_LOAD_T, 't')}{suffix(slip)}", load_t, "axle_load"))
    return out


def _geometry(v: Vehicle) -> list[PlausibilityWarning]:
    out = []
    for b in v.bodies:
        label = body_label(v, b.name)
        z = b.cg[2]
        if _outside(z, CG_HEIGHT_M):
            usual = WHEEL_RADIUS_M if b.kind == "wheelset" else (0.3, CG_HEIGHT_M[1])
            slip = likely_slip(z, usual, LENGTH_UNITS, "m")
            out.append(PlausibilityWarning(f"{label}.cg_m[2]", f"CG {z:g} m above rail is outside "
                                           f"{_band(CG_HEIGHT_M, 'm')} (the unit is m){suffix(slip)}",
                                           z, "cg_height"))
        elif b.kind == "wheelset" and v.contact is not None and abs(z - v.contact.r0) > WHEELSET_CG_TOL_M:
            out.append(PlausibilityWarning(f"{label}.cg_m[2]", f"a wheelset's CG (its axle) is at the rolling radius "
                                           f"{v.contact.r0:g} m, not {z:g} m", z, "cg_height"))
    return out


def _range(path: str, x: float, band: tuple[float, float], what: str, unit: str, units, check: str,
           usual: tuple[float, float] | None = None) -> list[PlausibilityWarning]:
    """One warning when ``x`` is outside ``band``, with the rescaling that lands it in ``usual`` (default ``band``)."""
    if not _outside(x, band):
        return []
    slip = likely_slip(x, usual or band, units, unit)
    u = f" {unit}" if unit else ""
    return [PlausibilityWarning(path, f"{what} {x:g}{u} is outside the usual {_band(band, unit)}{suffix(slip)}", x,
                                check)]


def _contact(v: Vehicle) -> list[PlausibilityWarning]:
    c = v.contact
    if c is None:
        return []
    out = []
    out += _range("contact.wheel_radius_m", c.r0, WHEEL_RADIUS_M, "wheel radius", "m",
                  (("mm", 1e-3), ("the diameter (a radius is half)", 0.5), ("inches", INCH)), "wheel_radius")
    out += _range("contact.semi_gauge_m", c.e0, SEMI_GAUGE_M, "semi-gauge (half the contact-point spacing)", "m",
                  (("mm", 1e-3), ("the gauge (the semi-gauge is half)", 0.5)), "semi_gauge")
    if c.conicity > CONICITY_MAX:
        slip = likely_slip(c.conicity, CONICITY_USUAL, RATIO_UNITS)
        out.append(PlausibilityWarning("contact.conicity", f"conicity {c.conicity:g} is above {CONICITY_MAX:g}"
                                       f"{suffix(slip or 'out of the range of tread conicities (0.02-0.5)')}",
                                       c.conicity, "conicity"))
    if abs(c.theta0) > THETA0_MAX_RAD:
        slip = likely_slip(c.theta0, (1e-3, THETA0_MAX_RAD), ANGLE_UNITS, "rad")
        out.append(PlausibilityWarning("contact.theta0", f"contact angle {c.theta0:g} rad is above "
                                       f"{THETA0_MAX_RAD:g} rad for a tread contact (the unit is rad){suffix(slip)}",
                                       c.theta0, "contact_angle"))
    if c.coefficients is not None:
        for key, f in (("f11_N", c.coefficients.f11), ("f22_N", c.coefficients.f22)):
            out += _range(f"contact.{key}", f, CREEP_COEFFICIENT_N, "creep coefficient", "N", FORCE_UNITS, "creep")
    if c.creep_factor > CREEP_FACTOR_MAX:
        slip = likely_slip(c.creep_factor, (0.05, 1.0), RATIO_UNITS)
        out.append(PlausibilityWarning("contact.creep_factor", f"creep factor {c.creep_factor:g} is above "
                                       f"{CREEP_FACTOR_MAX:g} (it reduces Kalker's coefficients){suffix(slip)}",
                                       c.creep_factor, "creep"))
    if c.creep == "hertz":
        out += _range("contact.youngs_modulus_Pa", c.youngs_modulus, YOUNGS_MODULUS_PA, "Young's modulus", "Pa",
                      MODULUS_UNITS, "material")
        out += _range("contact.poisson_ratio", c.poisson_ratio, POISSON_RATIO, "Poisson's ratio", "", (),
                      "material")
        out += _range("contact.rail_head_radius_m", c.rail_head_radius, RAIL_HEAD_RADIUS_M, "rail head radius",
                      "m", (("mm", 1e-3), ("inches", INCH)), "contact_radius")
    if not v.wheelsets:
        out.append(PlausibilityWarning("contact", "a [contact] table but no body of kind \"wheelset\": nothing "
                                       "touches the rail", 0.0, "wheelsets"))
    return out


def _track(v: Vehicle) -> list[PlausibilityWarning]:
    t = v.track
    if t is None:
        return []
    out = _range("track.track_modulus_N_m2", t.track_modulus, TRACK_MODULUS_N_M2, "track modulus (per rail)",
                 "N/m²", MODULUS_UNITS, "track", (7.0e6, 1.0e8))
    out += _range("track.rail_EI_N_m2", t.rail_EI, RAIL_EI_N_M2, "rail bending stiffness", "N·m²", BENDING_UNITS,
                  "track")
    out += _range("track.mass_per_length_kg_m", t.mass_per_length, TRACK_MASS_KG_M, "track mass per rail", "kg/m",
                  MASS_PER_LENGTH_UNITS, "track")
    if t.damping_ratio > TRACK_DAMPING_MAX:
        slip = likely_slip(t.damping_ratio, (0.01, TRACK_DAMPING_MAX), RATIO_UNITS)
        out.append(PlausibilityWarning("track.damping_ratio", f"damping ratio {t.damping_ratio:g} is above "
                                       f"{TRACK_DAMPING_MAX:g}{suffix(slip)}", t.damping_ratio, "track"))
    return out


def _clearances(v: Vehicle) -> list[PlausibilityWarning]:
    out = []
    for k, x in v.clearances.values.items():
        out += _range(f"clearances.{k}", x, CLEARANCE_M, "free travel", "m", LENGTH_UNITS, "clearance")
    return out


def _elements(v: Vehicle) -> list[PlausibilityWarning]:
    out, seen = [], set()
    for e in v.elements:
        if e.id in seen or e.value == 0.0:
            continue
        seen.add(e.id)
        band, units, unit, what = ELEMENT_BANDS[e.type]
        if _outside(e.value, band):
            slip = likely_slip(e.value, band, units, unit)
            where = "below" if e.value < band[0] else "above"
            out.append(PlausibilityWarning(
                f"elements ({e.id}).{value_key(e)}", f"{e.value:g} {unit} is {where} the usual "
                f"{_band(band, unit)} for {what} of running gear (the unit is {unit}){suffix(slip)}", e.value,
                "damping" if e.matrix == "C" else "stiffness"))
    return out


def _links(v: Vehicle) -> list[PlausibilityWarning]:
    out = []
    links = link_counts(v)
    for b in v.bodies:
        label = body_label(v, b.name)
        if b.kind == "body" and WHEELSET_NAME.search(b.name):
            out.append(PlausibilityWarning(f"{label}.kind", "named like a wheelset but kind = \"body\": it gets no "
                                           "wheel/rail contact (write kind = \"wheelset\")", 0.0, "wheelsets"))
        if b.kind == "body" and not links[b.name]:
            out.append(PlausibilityWarning(label, "carries no load: no element or constraint connects it to "
                                           "another body or ground", b.mass, "unconnected"))
    return out


def sprung_bodies(v: Vehicle) -> tuple[str, ...]:
    """Bodies of kind "body" carried by the secondary: linked to something, but to no wheelset or ground."""
    links = link_counts(v)
    wheelsets = {b.name for b in v.wheelsets}
    return tuple(b.name for b in v.bodies if b.kind == "body" and links[b.name]
                 and not set(links[b.name]) & (wheelsets | {GROUND}))


def body_frequencies(v: Vehicle, speed: float = NOMINAL_SPEED) -> dict[tuple[str, str], float]:
    """``{(body, "lateral" | "bounce"): Hz}`` of each sprung body: ``|s|/2π`` of the mode with the largest share of
    the body's kinetic energy in ``v`` (lateral view) or ``w`` (vertical view), rigid track, ``speed`` m/s.

    Raises ``ValueError`` when a view cannot be built or solved (e.g. a singular mass matrix)."""
    out: dict[tuple[str, str], float] = {}
    bodies = sprung_bodies(v)
    if not bodies:
        return out
    for kind, dof, make in (("lateral", "v", v.lateral), ("bounce", "w", v.vertical)):
        try:
            view = make("rigid", speed=speed)
        except ValueError:
            view = v.full("rigid", speed=speed)
        m = view.at().modal()
        n, M = view.n_dof, view.M
        X = m.V[:n, :]
        total = np.real(np.einsum("ik,ij,jk->k", X.conj(), M, X))
        for name in bodies:
            coord = f"{name}.{dof}"
            if coord not in view.coordinates:
                continue
            j = view.coordinates.index(coord)
            share = M[j, j] * np.abs(X[j, :]) ** 2 / np.where(total > 0, total, np.inf)
            best = np.flatnonzero(share >= share.max() - 1e-9)
            k = best[np.argmin(np.abs(m.s[best]))]
            out[(name, kind)] = float(rad_s_to_hz(abs(m.s[k])))
    return out


def _frequencies(v: Vehicle, speed: float) -> list[PlausibilityWarning]:
    try:
        found = body_frequencies(v, speed)
    except ValueError as exc:
        return [PlausibilityWarning("bodies", f"the body frequencies could not be computed ({exc})", math.nan,
                                    "body_frequency")]
    out = []
    for (name, kind), f in found.items():
        if _outside(f, BODY_FREQUENCY_HZ):
            out.append(PlausibilityWarning(
                f"{body_label(v, name)}: {kind} frequency",
                f"{kind} mode of the body on its suspension at {f:.3g} Hz is outside the usual "
                f"{_band(BODY_FREQUENCY_HZ, 'Hz')}: a stiffness in kN/m or a mass in tonnes?",
                f, "body_frequency"))
    return out


__all__ = [
    "AXLE_LOAD_T", "BODY_FREQUENCY_HZ", "CG_HEIGHT_M", "CLEARANCE_M", "CONICITY_MAX", "CONICITY_USUAL",
    "CREEP_COEFFICIENT_N", "CREEP_FACTOR_MAX", "DAMPER_N_S_PER_M", "ELEMENT_BANDS", "GYRATION_M", "MIN_MASS_KG",
    "NOMINAL_SPEED", "POISSON_RATIO", "PlausibilityWarning", "RAIL_EI_N_M2", "RAIL_HEAD_RADIUS_M",
    "ROTATIONAL_DAMPER_N_M_S_PER_RAD", "ROTATIONAL_SPRING_N_M_PER_RAD", "SEMI_GAUGE_M", "SPRING_N_PER_M",
    "THETA0_MAX_RAD", "TRACK_DAMPING_MAX", "TRACK_MASS_KG_M", "TRACK_MODULUS_N_M2", "WHEELSET_CG_TOL_M",
    "WHEELSET_MASS_KG", "WHEELSET_NAME", "WHEEL_RADIUS_M", "YOUNGS_MODULUS_PA", "body_frequencies", "plausibility",
    "sprung_bodies",
]
