"""Plausibility of a loaded vehicle: warnings (not errors) about values that load but look wrong.

A vehicle file can be valid and still wrong by a unit: a stiffness in kN/m, a mass in tonnes, a
semi-gauge or a CG height in mm, a conicity in per cent.  :func:`plausibility` returns one
:class:`PlausibilityWarning` per suspicious value, with the key path, the value (SI, as loaded) and
what is usual.  The checks and their bands (module constants) are listed in ``docs/vehicle.md``:

* total mass and axle load (weight shared by the wheelsets, or the file's ``axle_load_N``): 3–40 t per axle;
* masses below 50 kg and radii of gyration √(I/m) outside 0.05–15 m (a mass in tonnes);
* CG heights outside 0–5 m above rail, a wheelset CG more than 0.1 m from the rolling radius;
* wheel radius 0.3–0.65 m, semi-gauge 0.5–0.9 m, conicity above 0.5 (per cent?);
* translational springs below 10 kN/m, translational dampers below 100 N·s/m (kN/m, kN·s/m?);
* the lateral and bounce frequencies of each body carried by the secondary suspension (a body of kind
  "body" not connected to a wheelset) outside 0.3–3 Hz, from one eigen-solve of the lateral and one of the
  vertical view on rigid track at :data:`NOMINAL_SPEED`: the mode with the largest share of the body's
  kinetic energy in its lateral (bounce) coordinate, ``|s|/2π``;
* bodies named like wheelsets but of kind "body" (no wheel/rail contact), a ``[contact]`` table without
  wheelsets, bodies that carry no load (no element or constraint connects them).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from railopt.models.units import GRAVITY, rad_s_to_hz
from railopt.models.vehicle.elements import GROUND
from railopt.models.vehicle.vehicle import Vehicle

AXLE_LOAD_T = (3.0, 40.0)  # static load per wheelset, tonnes
MIN_MASS_KG = 50.0  # a rigid body of a rail vehicle weighs more
GYRATION_M = (0.05, 15.0)  # radius of gyration sqrt(I/m), m
CG_HEIGHT_M = (0.0, 5.0)  # CG z above rail, m
WHEELSET_CG_TOL_M = 0.1  # |z_cg − r0| of a wheelset, m
WHEEL_RADIUS_M = (0.3, 0.65)
SEMI_GAUGE_M = (0.5, 0.9)
CONICITY_MAX = 0.5  # above: almost surely per cent
MIN_SPRING_N_PER_M = 1.0e4
MIN_DAMPER_N_S_PER_M = 100.0
BODY_FREQUENCY_HZ = (0.3, 3.0)  # lateral and bounce of a body on the secondary suspension
NOMINAL_SPEED = 20.0  # m/s, for the eigen-solves
WHEELSET_NAME = re.compile(r"(wheel|axle|^ws\d)", re.IGNORECASE)


@dataclass(frozen=True)
class PlausibilityWarning:
    """One suspicious value.

    Attributes
    ----------
    path : str
        Key path in the file (``contact.semi_gauge_m``, ``bodies[0] (body).mass_kg``,
        ``elements (ksy).stiffness_N_per_m``) or a derived quantity (``bodies[0] (body): lateral frequency``).
    message : str
        What is unusual and what is usual.
    value : float
        The value as loaded (SI: kg, m, N/m, Hz for frequencies, t for axle loads).
    check : str
        Short name of the check (``"axle_load"``, ``"wheel_radius"``, ``"body_frequency"``, ...).
    """

    path: str
    message: str
    value: float
    check: str

    def __str__(self) -> str:
        return f"{self.path}: {self.message}"


def _outside(x: float, band: tuple[float, float]) -> bool:
    return not (band[0] <= x <= band[1])


def plausibility(vehicle: Vehicle, speed: float = NOMINAL_SPEED) -> list[PlausibilityWarning]:
    """Warnings about values of ``vehicle`` that look wrong (units, magnitudes, missing links).

    Parameters
    ----------
    vehicle : Vehicle
        A loaded vehicle.
    speed : float
        Forward speed of the eigen-solves (m/s).

    Returns
    -------
    list of PlausibilityWarning
        Empty when nothing looks wrong; in the order mass, geometry, contact, elements, frequencies, links.
    """
    out: list[PlausibilityWarning] = []
    out += _masses(vehicle)
    out += _geometry(vehicle)
    out += _contact(vehicle)
    out += _elements(vehicle)
    out += _links(vehicle)
    out += _frequencies(vehicle, speed)
    return out


def _label(vehicle: Vehicle, name: str) -> str:
    i = next(k for k, b in enumerate(vehicle.bodies) if b.name == name)
    return f"bodies[{i}] ({name})"


def _masses(v: Vehicle) -> list[PlausibilityWarning]:
    out = []
    for b in v.bodies:
        label = _label(v, b.name)
        if b.mass < MIN_MASS_KG:
            out.append(PlausibilityWarning(f"{label}.mass_kg", f"{b.mass:g} kg is below {MIN_MASS_KG:g} kg for a "
                                           "rigid body of a rail vehicle: is it in tonnes? the unit is kg",
                                           b.mass, "mass"))
        for k, axis in enumerate(("Ixx", "Iyy", "Izz")):
            r = math.sqrt(b.inertia[k][k] / b.mass)
            if _outside(r, GYRATION_M):
                out.append(PlausibilityWarning(
                    f"{label}.inertia_kg_m2", f"radius of gyration sqrt({axis}/m) = {r:.3g} m is outside "
                    f"{GYRATION_M[0]:g}-{GYRATION_M[1]:g} m: mass or inertia in the wrong unit?", r, "gyration"))
    n = len(v.wheelsets)
    if n:
        load_t = v.total_mass / n / 1000.0
        path = "bodies (total mass / wheelsets)"
        if v.contact is not None and v.contact.axle_load is not None:
            load_t = v.contact.axle_load / GRAVITY / 1000.0
            path = "contact.axle_load_N"
        if _outside(load_t, AXLE_LOAD_T):
            out.append(PlausibilityWarning(
                path, f"axle load {load_t:.3g} t (total mass {v.total_mass:,.0f} kg on {n} wheelsets) is outside "
                f"{AXLE_LOAD_T[0]:g}-{AXLE_LOAD_T[1]:g} t", load_t, "axle_load"))
    return out


def _geometry(v: Vehicle) -> list[PlausibilityWarning]:
    out = []
    for b in v.bodies:
        label = _label(v, b.name)
        z = b.cg[2]
        if _outside(z, CG_HEIGHT_M):
            out.append(PlausibilityWarning(f"{label}.cg_m[2]", f"CG {z:g} m above rail is outside "
                                           f"{CG_HEIGHT_M[0]:g}-{CG_HEIGHT_M[1]:g} m: is it in mm? the unit is m",
                                           z, "cg_height"))
        elif b.kind == "wheelset" and v.contact is not None and abs(z - v.contact.r0) > WHEELSET_CG_TOL_M:
            out.append(PlausibilityWarning(f"{label}.cg_m[2]", f"a wheelset's CG (its axle) is at the rolling radius "
                                           f"{v.contact.r0:g} m, not {z:g} m", z, "cg_height"))
    return out


def _contact(v: Vehicle) -> list[PlausibilityWarning]:
    c = v.contact
    if c is None:
        return []
    out = []
    if _outside(c.r0, WHEEL_RADIUS_M):
        out.append(PlausibilityWarning("contact.wheel_radius_m", f"wheel radius {c.r0:g} m is outside the usual "
                                       f"{WHEEL_RADIUS_M[0]:g}-{WHEEL_RADIUS_M[1]:g} m (a radius, in m)",
                                       c.r0, "wheel_radius"))
    if _outside(c.e0, SEMI_GAUGE_M):
        out.append(PlausibilityWarning("contact.semi_gauge_m", f"semi-gauge {c.e0:g} m is outside "
                                       f"{SEMI_GAUGE_M[0]:g}-{SEMI_GAUGE_M[1]:g} m (half the contact-point spacing, "
                                       "in m; standard gauge: 0.75)", c.e0, "semi_gauge"))
    if c.conicity > CONICITY_MAX:
        out.append(PlausibilityWarning("contact.conicity", f"conicity {c.conicity:g} is above {CONICITY_MAX:g}: "
                                       f"almost surely per cent (write {c.conicity / 100:g})", c.conicity,
                                       "conicity"))
    if not v.wheelsets:
        out.append(PlausibilityWarning("contact", "a [contact] table but no body of kind \"wheelset\": nothing "
                                       "touches the rail", 0.0, "wheelsets"))
    return out


def _elements(v: Vehicle) -> list[PlausibilityWarning]:
    out, seen = [], set()
    for e in v.elements:
        if e.id in seen or e.rotational or e.value == 0.0:
            continue
        seen.add(e.id)
        if e.matrix == "K" and e.value < MIN_SPRING_N_PER_M:
            out.append(PlausibilityWarning(f"elements ({e.id}).stiffness_N_per_m",
                                           f"{e.value:g} N/m is below {MIN_SPRING_N_PER_M:g} N/m for a suspension "
                                           "spring: is it in kN/m? the unit is N/m", e.value, "stiffness"))
        if e.matrix == "C" and e.value < MIN_DAMPER_N_S_PER_M:
            out.append(PlausibilityWarning(f"elements ({e.id}).damping_N_s_per_m",
                                           f"{e.value:g} N·s/m is below {MIN_DAMPER_N_S_PER_M:g} N·s/m for a damper: "
                                           "is it in kN·s/m? the unit is N·s/m", e.value, "damping"))
    return out


def _connected(v: Vehicle) -> dict[str, set[str]]:
    """Body -> the bodies (or ground) an element or constraint links it to."""
    links: dict[str, set[str]] = {b.name: set() for b in v.bodies}
    for e in v.elements:
        links[e.body_a].add(e.body_b)
        if e.body_b != GROUND:
            links[e.body_b].add(e.body_a)
    for c in v.constraints:
        if c.to:
            links[c.body].add(c.to)
            links[c.to].add(c.body)
        else:
            links[c.body].add(GROUND)
    return links


def _links(v: Vehicle) -> list[PlausibilityWarning]:
    out = []
    links = _connected(v)
    for b in v.bodies:
        label = _label(v, b.name)
        if b.kind == "body" and WHEELSET_NAME.search(b.name):
            out.append(PlausibilityWarning(f"{label}.kind", "named like a wheelset but kind = \"body\": it gets no "
                                           "wheel/rail contact (write kind = \"wheelset\")", 0.0, "wheelsets"))
        if b.kind == "body" and not links[b.name]:
            out.append(PlausibilityWarning(label, "carries no load: no element or constraint connects it to "
                                           "another body or ground", b.mass, "unconnected"))
    return out


def sprung_bodies(v: Vehicle) -> tuple[str, ...]:
    """Bodies of kind "body" carried by the secondary: linked to something, but to no wheelset or ground."""
    links = _connected(v)
    wheelsets = {b.name for b in v.wheelsets}
    return tuple(b.name for b in v.bodies if b.kind == "body" and links[b.name]
                 and not links[b.name] & (wheelsets | {GROUND}))


def body_frequencies(v: Vehicle, speed: float = NOMINAL_SPEED) -> dict[tuple[str, str], float]:
    """``{(body, "lateral" | "bounce"): Hz}`` of each sprung body: ``|s|/2π`` of the mode with the largest share of
    the body's kinetic energy in ``v`` (lateral view) or ``w`` (vertical view), rigid track, ``speed`` m/s."""
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
    out = []
    for (name, kind), f in body_frequencies(v, speed).items():
        if _outside(f, BODY_FREQUENCY_HZ):
            out.append(PlausibilityWarning(
                f"{_label(v, name)}: {kind} frequency",
                f"{kind} mode of the body on its suspension at {f:.3g} Hz is outside the usual "
                f"{BODY_FREQUENCY_HZ[0]:g}-{BODY_FREQUENCY_HZ[1]:g} Hz: a stiffness in kN/m or a mass in tonnes?",
                f, "body_frequency"))
    return out


__all__ = [
    "AXLE_LOAD_T", "BODY_FREQUENCY_HZ", "CG_HEIGHT_M", "CONICITY_MAX", "GYRATION_M", "MIN_DAMPER_N_S_PER_M",
    "MIN_MASS_KG", "MIN_SPRING_N_PER_M", "NOMINAL_SPEED", "PlausibilityWarning", "SEMI_GAUGE_M",
    "WHEELSET_CG_TOL_M", "WHEELSET_NAME", "WHEEL_RADIUS_M", "body_frequencies", "plausibility", "sprung_bodies",
]
