"""Plausibility of a vehicle's bodies and suspension against each other: gyration radii against the bodies' size
and each other, bogie frames against their car body, stiffnesses against the role an element plays, directions
against the element's name, and the running gear of one vehicle against itself.

Checks (bands are module constants, sources in the comments):

* **gyration against size**: a radius of gyration √(I/m) far below the spread of the body's attachment points
  (Iyy of a 20 m car body in t·m²) or beyond it (a bogie frame's mass ÷10), a roll gyration larger than any
  cross-section allows (Ixx ↔ Izz swapped: 7.85 m on the coach's body), a pitch or yaw gyration longer than the
  vehicle;
* **gyration against each other**: any rigid body has I₁ ≤ I₂ + I₃; a body flat in z (attachment points spread in
  x and y, not in z: car bodies, bogie frames) has its largest moment about z; a body long in x its smallest about
  x; a wheelset its smallest about its axle (Iyy);
* **masses against each other**: a bogie frame heavier than half the car body it carries;
* **role**: the primary suspension's stiffness per wheelset and direction (wheelset to frame) and the
  secondary's per bogie, below what any running gear has (a stiffness in kN/m); the primary damping above what
  any axlebox damper set has (×1000);
* **restraint**: a wheelset that no spring or constraint holds laterally or in yaw to its frame;
* **consistency**: one wheelset's primary (or one bogie's secondary) unlike the others' (an element deleted, a
  value slipped on one copy);
* **direction**: an element whose id or alias names an axis (``longitudinal``, ``kpy``, ``yaw`` ...) but whose
  direction points along another.
"""

from __future__ import annotations

import math

import numpy as np

from railopt.models.vehicle.elements import GROUND, Element
from railopt.models.vehicle.plausibility_warning import (
    PlausibilityWarning,
    body_label,
    element_label,
    suffix,
    value_key,
)
from railopt.models.vehicle.running_gear import AXES, RunningGear, acting_axis, inside_envelope, named_axis
from railopt.models.vehicle.slips import INERTIA_UNITS, MASS_UNITS, STIFFNESS_UNITS, likely_slip, rescalings
from railopt.models.vehicle.vehicle import Vehicle

GYRATION_SPAN_MIN = 0.1  # √(I/m) at least this fraction of the attachment points' spread (uniform bar: 0.29)
GYRATION_SPAN_MAX = 1.0  # √(I/m) at most the spread plus GYRATION_SLACK_M (bodies reach ~20 % past their mounts)
GYRATION_SLACK_M = 0.5
ROLL_SLACK_M = 1.5  # roll: a body's cross-section (~3 x 3.5 m) reaches well past mounts near its centre line
SPAN_MIN_M = 0.5  # spreads below this say nothing about a body's size
ROLL_GYRATION_MAX_M = 3.0  # √(Ixx/m) of a body inside a loading gauge (≤ 3.75 m wide, ≤ ~5.5 m above rail)
OVERHANG_M = 6.0  # a vehicle's half-length: its outermost wheelset plus this
FLAT_RATIO = 0.5  # a body is flat in z when its z-spread is below this fraction of its x- and y-spreads
LONG_RATIO = 2.0  # a body is long in x when its x-spread is this many times its y-spread
ORDER_TOL = 0.9  # a moment that should be the largest may fall 10 % short of another (equal moments are usual)
WHEELSET_INERTIA_RATIO = 2.0  # Ixx and Izz of a wheelset agree within this factor
FRAME_MASS_FRACTION = 0.5  # a bogie frame weighs less than this fraction of the car body it carries
# Primary stiffness per wheelset (both sides together), N/m, lower bounds below any running gear: Manchester
# coach 62.8 / 7.8 / 2.4 MN/m (x / y / z), soft "radial" bogies ~5 / 2 MN/m (x / y); freight primaries are stiffer;
# Iwnicki (ed.) 2006 ch. 3.  Upper ends of the usual band only place a rescaled value.
PRIMARY_MIN_N_PER_M = (1.0e6, 3.0e5, 3.0e5)
PRIMARY_USUAL_N_PER_M = ((2.0e6, 2.0e8), (1.0e6, 5.0e7), (5.0e5, 2.0e7))
# Secondary stiffness per bogie (all its secondary elements), N/m: air springs ~0.12-0.2 MN/m in shear each,
# 0.3-1 MN/m vertically; coil secondaries stiffer.  Manchester coach 0.32 / 0.32 / 0.86 MN/m.
SECONDARY_MIN_N_PER_M = (3.0e4, 5.0e4, 1.0e5)
SECONDARY_USUAL_N_PER_M = ((1.0e5, 5.0e7), (1.0e5, 1.0e7), (3.0e5, 2.0e7))
# Primary damping per wheelset and direction, N s/m: axlebox dampers are 2-30 kN s/m each (Manchester coach 8 kN s/m
# vertically per wheelset, sd40-2 30 kN s/m); above 0.5 MN s/m the wheelset is locked to its frame.
PRIMARY_DAMPING_MAX_N_S_PER_M = 5.0e5
MISMATCH_RATIO = 1.5  # one wheelset's (bogie's) total against the median of the others
DIRECTION_MIN = 0.8  # |component| along the named axis (cos 37°: an inclined damper keeps its name's axis)


def suspension_checks(v: Vehicle, gear: RunningGear) -> list[PlausibilityWarning]:
    """Warnings on the bodies' inertia and the suspension of ``v`` (module docstring); ``gear`` is its running
    gear (:func:`railopt.models.vehicle.running_gear.running_gear`)."""
    out = _inertias(v)
    out += _frame_masses(v, gear)
    out += _restraints(v, gear)
    out += _roles(v, gear)
    out += _directions(v)
    return out


# ---------------------------------------------------------------------------------------------- inertia
def spans(v: Vehicle) -> dict[str, np.ndarray]:
    """Body -> spread (x, y, z) of its attachment points about its CG, m: the CG and the element ends on it that lie
    inside the envelope of any vehicle (an end slipped far out is another check's warning, not a size)."""
    pts: dict[str, list] = {b.name: [np.zeros(3)] for b in v.bodies}
    cg = {b.name: np.asarray(b.cg) for b in v.bodies}
    for e in v.elements:
        for body, p in ((e.body_a, e.point_a), (e.body_b, e.point_b)):
            if body != GROUND and inside_envelope(cg[body] + p):
                pts[body].append(np.asarray(p))
    return {n: np.ptp(np.array(p), axis=0) for n, p in pts.items()}


def _inertias(v: Vehicle) -> list[PlausibilityWarning]:
    out = []
    size = spans(v)
    xs = [b.cg[0] for b in v.wheelsets]
    half_length = (max(xs) - min(xs)) / 2.0 + OVERHANG_M if xs else math.inf
    for b in v.bodies:
        label = body_label(v, b.name)
        moments = np.diag(np.asarray(b.inertia))
        r = np.sqrt(moments / b.mass)
        s = size[b.name]
        principal = np.linalg.eigvalsh(np.asarray(b.inertia))
        if principal[2] > (principal[0] + principal[1]) * (1.0 + 1e-6):
            out.append(PlausibilityWarning(
                f"{label}.inertia_kg_m2", f"principal moments {_fmt(principal)} kg·m²: the largest exceeds the sum "
                "of the other two, which no rigid body can (I₁ ≤ I₂ + I₃); one entry swapped or in the wrong unit?",
                float(principal[2]), "inertia_order"))
        for k in range(3):
            others = [i for i in range(3) if i != k]
            spread = float(max(s[others]))
            if spread >= SPAN_MIN_M and r[k] < GYRATION_SPAN_MIN * spread:
                lo = b.mass * (GYRATION_SPAN_MIN * spread) ** 2
                slip = likely_slip(moments[k], (lo, b.mass * spread ** 2), INERTIA_UNITS, "kg·m²")
                out.append(PlausibilityWarning(
                    f"{label}.inertia_kg_m2[{k}]", f"radius of gyration about {AXES[k]} √(I/m) = {r[k]:.3g} m on a "
                    f"body whose attachment points spread {spread:.3g} m: below {GYRATION_SPAN_MIN:g} of its size"
                    f"{suffix(slip)}", float(r[k]), "gyration_size"))
        for k in range(3):
            spread = float(max(s[[i for i in range(3) if i != k]]))
            slack = ROLL_SLACK_M if k == 0 else GYRATION_SLACK_M
            beyond = r[k] > GYRATION_SPAN_MAX * spread + slack and not (k == 0 and r[0] > ROLL_GYRATION_MAX_M)
            if spread >= SPAN_MIN_M and beyond:  # (a roll beyond any cross-section is said below)
                out.append(PlausibilityWarning(
                    f"{label}.inertia_kg_m2[{k}]", f"radius of gyration about {AXES[k]} √(I/m) = {r[k]:.3g} m on a "
                    f"body whose attachment points spread {spread:.3g} m: its mass would lie beyond them; the mass "
                    f"({b.mass:g} kg) too small or the inertia too large?", float(r[k]), "gyration_size"))
        if r[0] > ROLL_GYRATION_MAX_M:
            out.append(PlausibilityWarning(
                f"{label}.inertia_kg_m2[0]", f"roll radius of gyration √(Ixx/m) = {r[0]:.3g} m: no body inside a "
                f"loading gauge reaches {ROLL_GYRATION_MAX_M:g} m{_swap_hint(moments, 0)}", float(r[0]),
                "gyration_size"))
        for k in (1, 2):
            if r[k] > half_length:
                out.append(PlausibilityWarning(
                    f"{label}.inertia_kg_m2[{k}]", f"radius of gyration about {AXES[k]} √(I/m) = {r[k]:.3g} m is "
                    f"longer than half the vehicle ({half_length:.3g} m): inertia in the wrong unit or mass in "
                    "tonnes?", float(r[k]), "gyration_size"))
        out += _order(label, b.kind, moments, s)
    return out


def _fmt(x) -> str:
    return "[" + ", ".join(f"{c:.4g}" for c in x) + "]"


def _swap_hint(moments: np.ndarray, k: int) -> str:
    """``": Ixx and Izz swapped?"`` when swapping entry ``k`` with another gives the order a long body has."""
    names = ("Ixx", "Iyy", "Izz")
    j = int(np.argmin(moments))
    return f": {names[k]} and {names[j]} swapped? (roll, about x, is the smallest moment of a long body)" \
        if j != k else ": inertia in the wrong unit?"


def _order(label: str, kind: str, moments: np.ndarray, s: np.ndarray) -> list[PlausibilityWarning]:
    """The order of the moments a body's shape implies."""
    names = ("Ixx", "Iyy", "Izz")
    out = []
    if kind == "wheelset":
        if moments[1] >= min(moments[0], moments[2]) or not (
                1.0 / WHEELSET_INERTIA_RATIO <= moments[0] / moments[2] <= WHEELSET_INERTIA_RATIO):
            out.append(PlausibilityWarning(
                f"{label}.inertia_kg_m2", f"a wheelset's moments {_fmt(moments)} kg·m²: Iyy (spin about the axle) is "
                "the smallest and Ixx ≈ Izz (roll and yaw of the axle); axes swapped or one in the wrong unit?",
                float(moments[1]), "inertia_order"))
        return out
    flat = s[2] < FLAT_RATIO * min(s[0], s[1]) and min(s[0], s[1]) >= SPAN_MIN_M
    if flat and moments[2] < ORDER_TOL * max(moments[0], moments[1]):
        j = int(np.argmax(moments[:2]))
        out.append(PlausibilityWarning(
            f"{label}.inertia_kg_m2", f"moments {_fmt(moments)} kg·m² on a body spread in x and y ({s[0]:.3g} m, "
            f"{s[1]:.3g} m) but not in z ({s[2]:.3g} m): yaw (Izz) is its largest moment; {names[j]} and Izz "
            "swapped?", float(moments[2]), "inertia_order"))
    long = s[0] >= LONG_RATIO * s[1] and s[0] >= SPAN_MIN_M
    if long and moments[0] > min(moments[1], moments[2]) / ORDER_TOL:
        j = 1 + int(np.argmin(moments[1:]))
        out.append(PlausibilityWarning(
            f"{label}.inertia_kg_m2", f"moments {_fmt(moments)} kg·m² on a body long in x ({s[0]:.3g} m against "
            f"{s[1]:.3g} m across): roll (Ixx) is its smallest moment; Ixx and {names[j]} swapped?",
            float(moments[0]), "inertia_order"))
    return out


def _frame_masses(v: Vehicle, gear: RunningGear) -> list[PlausibilityWarning]:
    out = []
    mass = {b.name: b.mass for b in v.bodies}
    for f, car in gear.car_bodies.items():
        if mass[f] > FRAME_MASS_FRACTION * mass[car]:
            slip = likely_slip(mass[f], (300.0, FRAME_MASS_FRACTION * mass[car]), MASS_UNITS, "kg")
            out.append(PlausibilityWarning(
                f"{body_label(v, f)}.mass_kg", f"the bogie weighs {mass[f]:g} kg, {mass[f] / mass[car]:.2g} of the "
                f"car body it carries ({body_label(v, car)}.mass_kg = {mass[car]:g} kg; bogie frames weigh < "
                f"{FRAME_MASS_FRACTION:g} of it): one of the two in the wrong unit?{suffix(slip)}", mass[f],
                "frame_mass"))
    return out


# ---------------------------------------------------------------------------------------------- suspension roles
def _totals(v: Vehicle, gear: RunningGear, role: str, owners: dict[str, str]) -> dict[tuple, dict[str, float]]:
    """``(matrix, rotational, axis) -> {owner: Σ value · d_axis²}`` over the elements of ``role``; ``owners`` maps
    an element end's body to the wheelset or bogie it is counted for."""
    wheelsets = {b.name for b in v.wheelsets}
    out: dict[tuple, dict[str, float]] = {}
    for e in v.elements:
        if gear.role(e, wheelsets) != role:
            continue
        owner = owners.get(e.body_a) or owners.get(e.body_b)
        if owner is None:
            continue
        d = np.asarray(e.direction) ** 2
        for k in range(3):
            if d[k] > 1e-12:
                group = out.setdefault((e.matrix, e.rotational, k), {})
                group[owner] = group.get(owner, 0.0) + e.value * d[k]
    return out


def _roles(v: Vehicle, gear: RunningGear) -> list[PlausibilityWarning]:
    out: list[PlausibilityWarning] = []
    framed = {w: w for w, f in gear.frames.items() if f}
    bogies = {b: b for b in gear.bogies}
    for role, owners, low, usual, per in (("primary", framed, PRIMARY_MIN_N_PER_M, PRIMARY_USUAL_N_PER_M, "wheelset"),
                                          ("secondary", bogies, SECONDARY_MIN_N_PER_M, SECONDARY_USUAL_N_PER_M,
                                           "bogie")):
        totals = _totals(v, gear, role, owners)
        for (matrix, rotational, k), group in totals.items():
            group = {o: group.get(o, 0.0) for o in owners}  # an owner without such an element: 0
            if matrix == "K" and not rotational:
                for owner, total in group.items():
                    if 0.0 < total < low[k]:
                        out.append(_low(v, gear, role, owner, k, total, low[k], usual[k]))
            if matrix == "C" and not rotational and role == "primary":
                out += _damping_high(v, gear, k, group)
            out += _mismatch(v, role, matrix, rotational, k, group, per)
    return out


def _restraints(v: Vehicle, gear: RunningGear) -> list[PlausibilityWarning]:
    """Each wheelset held laterally and in yaw to its frame (or ground) by a spring or a constraint: a wheelset held
    by creep alone is a deleted element or constraint (its hunting is then a different vehicle's)."""
    out = []
    for b in v.wheelsets:
        frame = gear.frames.get(b.name, "")
        if not frame:
            continue
        held = {"laterally": False, "in yaw": False}
        for e in v.elements:
            if {e.body_a, e.body_b} != {b.name, frame} or e.matrix != "K" or e.value == 0.0:
                continue
            d = np.asarray(e.direction)
            p = np.asarray(e.point_a if e.body_a == b.name else e.point_b)
            if e.rotational:
                held["in yaw"] |= abs(d[2]) > 0.1
            else:
                held["laterally"] |= abs(d[1]) > 0.1
                held["in yaw"] |= abs(np.cross(p, d)[2]) > 0.05  # a moment arm about z
        for c in v.constraints:
            if {c.body, c.to or GROUND} != {b.name, frame}:
                continue
            dofs = set(c.dofs) if c.type != "hinge" else {"u", "v", "w", "alpha", "beta", "gamma"} - {
                {"x": "alpha", "y": "beta", "z": "gamma"}[c.axis]}
            held["laterally"] |= "v" in dofs
            held["in yaw"] |= "gamma" in dofs
        for what, ok in held.items():
            if not ok:
                out.append(PlausibilityWarning(
                    body_label(v, b.name), f"no spring or constraint holds the wheelset {what} to {frame}: only "
                    f"the creep forces do; a primary element or constraint deleted?", 0.0, "wheelset_restraint"))
    return out


def _elements_of(v: Vehicle, gear: RunningGear, role: str, owner: str, k: int) -> list[Element]:
    wheelsets = {b.name for b in v.wheelsets}
    return [e for e in v.elements if gear.role(e, wheelsets) == role and owner in (e.body_a, e.body_b)
            and e.matrix == "K" and not e.rotational and abs(e.direction[k]) > 1e-6]


def _low(v: Vehicle, gear: RunningGear, role: str, owner: str, k: int, total: float, low: float,
         usual: tuple[float, float]) -> PlausibilityWarning:
    direction = ("longitudinal", "lateral", "vertical")[k]
    elements = _elements_of(v, gear, role, owner, k)
    ids = sorted({e.id for e in elements})
    found = rescalings(total, usual, STIFFNESS_UNITS)
    slip = ""
    if found:
        label, corrected = found[0]
        values = ", ".join(f"{e.id} = {e.value:g} N/m" for e in {e.id: e for e in elements}.values())
        like = label if label.endswith(("too large", "too small")) else f"like {label}"
        slip = f"looks {like}: {values} → ×{corrected / total:g}?"
    key = f"elements ({', '.join(ids)}).{value_key(elements[0])}" if elements else f"{body_label(v, owner)}"
    return PlausibilityWarning(
        key, f"{role} {direction} stiffness of {owner} totals {total:.4g} N/m, below the {low:.3g} N/m of any "
        f"running gear (the unit is N/m){suffix(slip)}", total, f"{role}_stiffness")


def _damping_high(v: Vehicle, gear: RunningGear, k: int, group: dict[str, float]) -> list[PlausibilityWarning]:
    """Primary damping per wheelset and direction above :data:`PRIMARY_DAMPING_MAX_N_S_PER_M`."""
    wheelsets = {b.name for b in v.wheelsets}
    out = []
    for owner, total in group.items():
        if total > PRIMARY_DAMPING_MAX_N_S_PER_M:
            ids = sorted({e.id for e in v.elements if gear.role(e, wheelsets) == "primary" and e.matrix == "C"
                          and not e.rotational and owner in (e.body_a, e.body_b) and abs(e.direction[k]) > 1e-6})
            slip = likely_slip(total, (1.0e3, PRIMARY_DAMPING_MAX_N_S_PER_M), (), "N·s/m")
            out.append(PlausibilityWarning(
                f"elements ({', '.join(ids)}).damping_N_s_per_m", f"primary {AXES[k]} damping of {owner} totals "
                f"{total:.4g} N·s/m, above the {PRIMARY_DAMPING_MAX_N_S_PER_M:.3g} N·s/m of any axlebox damper set "
                f"(primary dampers: 2-30 kN·s/m each){suffix(slip)}", total, "primary_damping"))
    return out


def _mismatch(v: Vehicle, role: str, matrix: str, rotational: bool, k: int, group: dict[str, float],
              per: str) -> list[PlausibilityWarning]:
    if len(group) < 2:
        return []
    values = np.array(list(group.values()))
    median = float(np.median(values))
    if median <= 0.0:
        return []
    out = []
    what = ("damping" if matrix == "C" else "stiffness") + (" about " if rotational else " along ") + AXES[k]
    unit = {("K", False): "N/m", ("C", False): "N·s/m", ("K", True): "N·m/rad", ("C", True): "N·m·s/rad"}[
        (matrix, rotational)]
    for owner, total in group.items():
        if total > MISMATCH_RATIO * median or total < median / MISMATCH_RATIO:
            out.append(PlausibilityWarning(
                f"{body_label(v, owner)}: {role} {what}", f"the {role} {what} of {owner} totals {total:.4g} {unit}, "
                f"the median of the {len(group)} {per}s {median:.4g} {unit}: an element missing, listed twice, or its "
                "value slipped on one copy?", total, "suspension_mismatch"))
    return out


def _directions(v: Vehicle) -> list[PlausibilityWarning]:
    out, seen = [], set()
    for e in v.elements:
        k = named_axis(e)
        if k is None or abs(e.direction[k]) >= DIRECTION_MIN or (e.id, e.body_a, e.body_b) in seen:
            continue
        seen.add((e.id, e.body_a, e.body_b))
        acts = AXES[acting_axis(e)]
        verb = "turns about" if e.rotational else "acts along"
        name = e.id + (f" / {e.alias}" if e.alias else "")
        out.append(PlausibilityWarning(
            element_label(e, "direction"), f"named for {AXES[k]} ({name}) but {verb} {acts} (direction "
            f"{[round(float(c), 3) for c in e.direction]}): a direction typo, or the element's name?",
            abs(e.direction[k]),
            "direction"))
    return out


__all__ = [
    "DIRECTION_MIN", "FLAT_RATIO", "FRAME_MASS_FRACTION", "GYRATION_SLACK_M", "GYRATION_SPAN_MAX",
    "GYRATION_SPAN_MIN", "LONG_RATIO", "MISMATCH_RATIO", "ORDER_TOL", "OVERHANG_M", "PRIMARY_DAMPING_MAX_N_S_PER_M",
    "PRIMARY_MIN_N_PER_M", "PRIMARY_USUAL_N_PER_M", "ROLL_GYRATION_MAX_M", "ROLL_SLACK_M", "SECONDARY_MIN_N_PER_M",
    "SECONDARY_USUAL_N_PER_M", "SPAN_MIN_M", "WHEELSET_INERTIA_RATIO", "spans", "suspension_checks",
]
