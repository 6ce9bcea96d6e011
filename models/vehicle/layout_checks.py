"""Plausibility of a vehicle's layout: positions and lengths against its own extent and wheelbase, the bogies,
element point pairs, and the symmetry of its elements.

Values that load but describe no vehicle: a semi-wheelbase or a lateral offset in mm, a bogie semi-spacing that
puts wheels on top of each other, a bogie left with one wheelset (a wheelset deleted with its elements: the
vehicle's CG is then off the middle of its wheelsets), an element whose two ends are far apart or off its line of
action (a point written absolute instead of relative to its body's CG, a sign slip), a ``mirror_y`` forgotten or
an element listed twice.  Each check and its band is a module constant (sources in the comments; loading gauges
EN 15273 / UIC 505-1, running gear S. Iwnicki (ed.), Handbook of Railway Vehicle Dynamics, CRC 2006, ch. 3);
the gyration, mass-ratio, suspension-role and direction checks live in
:mod:`railopt.models.vehicle.suspension_checks`.  The running-gear layout (frames, bogies) is read from the links by
:func:`railopt.models.vehicle.running_gear.running_gear`.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from railopt.models.vehicle.elements import GROUND, Element
from railopt.models.vehicle.plausibility_warning import (
    PlausibilityWarning,
    body_label,
    element_label,
    suffix,
)
from railopt.models.vehicle.running_gear import (
    HALF_WIDTH_M,
    MAX_HALF_LENGTH_M,
    POINT_HEIGHT_M,
    RunningGear,
    running_gear,
)
from railopt.models.vehicle.slips import LENGTH_UNITS, likely_slip
from railopt.models.vehicle.suspension_checks import suspension_checks
from railopt.models.vehicle.vehicle import Vehicle

MAX_LENGTH_M = 30.0  # a [lengths] value: the longest rail vehicle bodies are ~27.5 m (UIC-Z coaches 26.4 m)
OVERHANG_M = 6.0  # beyond the outermost wheelset (coaches ~2.4 m, locomotives 3-4 m)
POSITION_USUAL_M = 0.3  # a body or mount off the vehicle centre in x lies at least this far from it (or at 0)
LATERAL_USUAL_M = 0.15  # off-centre attachments (springs, dampers, axleboxes) lie 0.15-2 m from the centre line
CG_LATERAL_M = 0.3  # |y| of a body's CG: bodies are laterally near-symmetric (load offsets are limited to ~0.1 m)
AXLE_SPACING_BOGIE_M = (1.4, 3.2)  # adjacent axles of a bogie: 1.8 m (Y25 freight), 2.5-2.8 m (passenger),
# 2.6-3.0 m (locomotive two-axle), 1.9-2.2 m (three-axle locomotive bogies, e.g. HT-C 2 x 2.07 m)
AXLE_SPACING_BOGIE_USUAL_M = (1.8, 3.0)  # where a rescaled bogie wheelbase may land
AXLE_SPACING_CARRIED_M = (1.4, 14.0)  # adjacent axles carried by the car body: two-axle wagons 4-10 m
WHEEL_GAP_M = 0.05  # adjacent axles at least a wheel diameter plus this apart
BOGIE_CG_TOL_M = 0.25  # a bogie frame's CG from the middle of its wheelsets (unequal axle spacings ~0.1 m)
VEHICLE_CG_FRACTION = 0.1  # the vehicle's CG from the middle of its wheelsets, fraction of their spread
AXLEBOX_Y_M = (0.4, 1.4)  # |y| of a primary element's wheelset end off the centre line: inboard bearings ~0.6 m,
# outboard axleboxes ~1.0 m (standard gauge)
PAIR_OFF_LINE_M = 0.3  # an element's ends off its line of action (a real element: 0; estimates: < 0.25 m)
PAIR_GAP_M = 3.0  # an element's ends apart: dampers 0.3-1 m, traction rods ~2 m
SAME_POINT_M = 0.05  # ends this close coincide (for the likely slip)
AXES = "xyz"


def layout_checks(v: Vehicle) -> list[PlausibilityWarning]:
    """Warnings on the layout of ``v``: lengths, positions, wheelsets and bogies, point pairs, symmetry; then
    :func:`~railopt.models.vehicle.suspension_checks.suspension_checks`.

    Returns
    -------
    list of PlausibilityWarning
        Each with the key (``lengths.<name>``, ``bodies[i] (name).cg_m[k]``, ``elements (id: a-b).point_b_m``,
        ``cab.point_m[k]``) and the likely slip where one rescaling explains the value (``file`` is set by
        :func:`railopt.models.vehicle.plausibility.plausibility`).
    """
    gear = running_gear(v)
    out = _lengths(v)
    out += _positions(v)
    out += _wheelsets(v, gear)
    out += _point_pairs(v)
    out += _symmetry(v)
    out += suspension_checks(v, gear)
    return out


# ---------------------------------------------------------------------------------------------- helpers
def named_lengths(v: Vehicle, *values: float) -> str:
    """``" (lengths.semi_wheelbase = 1280)"``: the ``[lengths]`` names whose value is one of ``values`` (in
    magnitude), the likely source of a slipped position; ``""`` when none."""
    names = [k for k, x in v.lengths.values.items() if x != 0.0
             and any(math.isclose(abs(x), abs(y), rel_tol=1e-9) for y in values if y != 0.0)]
    return f" ({', '.join(f'lengths.{k} = {v.lengths.values[k]:g}' for k in names)})" if names else ""


def _ends(v: Vehicle, e: Element) -> tuple[np.ndarray, np.ndarray]:
    """Absolute positions of an element's two ends (a ground end is absolute already)."""
    cg = {b.name: np.asarray(b.cg) for b in v.bodies}
    a = cg[e.body_a] + np.asarray(e.point_a)
    b = np.asarray(e.point_b) + (cg[e.body_b] if e.body_b != GROUND else 0.0)
    return a, b


def _extent(v: Vehicle) -> tuple[float, float] | None:
    """x-range a vehicle's points may lie in: its outermost wheelsets ± :data:`OVERHANG_M`, at most
    ±:data:`MAX_HALF_LENGTH_M`; ``None`` without wheelsets."""
    xs = [b.cg[0] for b in v.wheelsets]
    if not xs:
        return None
    return max(min(xs) - OVERHANG_M, -MAX_HALF_LENGTH_M), min(max(xs) + OVERHANG_M, MAX_HALF_LENGTH_M)


def _off(x: float, band: tuple[float, float]) -> bool:
    return not (band[0] <= x <= band[1])


# ---------------------------------------------------------------------------------------------- lengths, positions
def _lengths(v: Vehicle) -> list[PlausibilityWarning]:
    out = []
    for k, x in v.lengths.values.items():
        if abs(x) > MAX_LENGTH_M:
            slip = likely_slip(x, (0.01, MAX_HALF_LENGTH_M), LENGTH_UNITS, "m")
            out.append(PlausibilityWarning(f"lengths.{k}", f"{x:g} m is longer than any rail vehicle (the unit is m)"
                                           f"{suffix(slip)}", x, "length"))
    return out


def _coordinate(v: Vehicle, path: str, what: str, p: np.ndarray, extent, rel: np.ndarray | None = None,
                lateral: float = HALF_WIDTH_M) -> Iterator[PlausibilityWarning]:
    """Warnings on one absolute position ``p`` (x against the extent, |y|, z); ``rel`` is what the file wrote."""
    rel = p if rel is None else rel
    x, y, z = (float(c) for c in p)
    band = extent or (-MAX_HALF_LENGTH_M, MAX_HALF_LENGTH_M)
    if _off(x, band):
        slip = likely_slip(rel[0], (POSITION_USUAL_M, max(abs(band[0]), abs(band[1]))), LENGTH_UNITS, "m")
        where = "the vehicle's extent (its outermost wheelsets ± 6 m)" if extent else "any rail vehicle"
        yield PlausibilityWarning(f"{path}[0]", f"{what} at x = {x:g} m lies outside {where}, "
                                  f"{band[0]:.4g} to {band[1]:.4g} m{suffix(slip)}{named_lengths(v, rel[0])}",
                                  x, "extent")
    if abs(y) > lateral:
        slip = likely_slip(rel[1], (LATERAL_USUAL_M, lateral), LENGTH_UNITS, "m")
        yield PlausibilityWarning(f"{path}[1]", f"{what} at y = {y:g} m is wider than {lateral:g} m off the centre "
                                  f"line{suffix(slip)}{named_lengths(v, rel[1])}", y, "lateral_offset")
    if _off(z, POINT_HEIGHT_M):
        slip = likely_slip(rel[2], (0.1, POINT_HEIGHT_M[1]), LENGTH_UNITS, "m")
        yield PlausibilityWarning(f"{path}[2]", f"{what} at z = {z:g} m above rail is outside "
                                  f"{POINT_HEIGHT_M[0]:g} to {POINT_HEIGHT_M[1]:g} m{suffix(slip)}"
                                  f"{named_lengths(v, rel[2])}", z, "height")


def _misplaced(v: Vehicle, extent) -> set[str]:
    """Bodies whose CG is outside the vehicle (x beyond the extent, |y| beyond the half-width, z outside 0-5 m):
    their element ends and point pairs are not checked again (the CG's warning names the slip)."""
    band = extent or (-MAX_HALF_LENGTH_M, MAX_HALF_LENGTH_M)
    return {b.name for b in v.bodies if _off(b.cg[0], band) or abs(b.cg[1]) > HALF_WIDTH_M
            or _off(b.cg[2], (0.0, 5.0))}


def _positions(v: Vehicle) -> list[PlausibilityWarning]:
    """CGs, element ends and the cab point inside the vehicle's extent, its width and its height."""
    extent = _extent(v)
    out = []
    for b in v.bodies:
        label = body_label(v, b.name)
        cg = np.asarray(b.cg)
        out += [w for w in _coordinate(v, f"{label}.cg_m", "the CG", cg, extent) if w.check != "height"]
        if abs(cg[1]) > CG_LATERAL_M and abs(cg[1]) <= HALF_WIDTH_M:
            out.append(PlausibilityWarning(f"{label}.cg_m[1]", f"the CG is {cg[1]:g} m off the centre line "
                                           f"(bodies are laterally near-symmetric; > {CG_LATERAL_M:g} m is "
                                           "unusual): y and z swapped? (z is the height)", float(cg[1]),
                                           "lateral_offset"))
    skip = _misplaced(v, extent)
    slipped = [x for x in v.lengths.values.values() if abs(x) > MAX_LENGTH_M]  # said by the "length" check
    groups: dict[tuple, tuple[Element, str, PlausibilityWarning, list[str]]] = {}
    for e in v.elements:
        a, b = _ends(v, e)
        for key, body, p, rel in (("point_a_m", e.body_a, a, e.point_a), ("point_b_m", e.body_b, b, e.point_b)):
            if body in skip:
                continue
            for w in _coordinate(v, "", "an end", p, extent, np.asarray(rel)):
                c = abs(float(rel[_AXIS[w.check]]))
                if any(math.isclose(c, abs(x), rel_tol=1e-9) for x in slipped):
                    continue
                tag = (e.body_a, e.body_b, w.check, round(c, 6))  # both ends and the mirror image: one warning
                groups.setdefault(tag, (e, key + w.path, w, []))[3].append(e.id)
    for e, key, w, ids in groups.values():
        out.append(PlausibilityWarning(element_label(e, key, ids), w.message, w.value, w.check))
    if v.cab_point is not None:
        out += list(_coordinate(v, "cab.point_m", "the cab point", np.asarray(v.cab_point), extent))
    return out


_AXIS = {"extent": 0, "lateral_offset": 1, "height": 2}


# ---------------------------------------------------------------------------------------------- wheelsets and bogies
def _wheelsets(v: Vehicle, gear: RunningGear) -> list[PlausibilityWarning]:
    out: list[PlausibilityWarning] = []
    ws = sorted(v.wheelsets, key=lambda b: b.cg[0])
    if not ws:
        return out
    x = {b.name: b.cg[0] for b in v.bodies}
    r0 = v.contact.r0 if v.contact is not None else 0.45
    for w1, w2 in zip(ws, ws[1:], strict=False):
        gap = w2.cg[0] - w1.cg[0]
        if gap < 2.0 * r0 + WHEEL_GAP_M:
            out.append(PlausibilityWarning(
                f"{body_label(v, w2.name)}.cg_m[0]", f"{w1.name} and {w2.name} are {gap:.4g} m apart, less than a "
                f"wheel diameter ({2 * r0:g} m): their wheels overlap; a bogie semi-spacing or semi-wheelbase too "
                f"short, or a sign slip?{named_lengths(v, w1.cg[0], w2.cg[0])}", gap, "wheel_overlap"))
    counts = {f: len(w) for f, w in gear.bogies.items()}
    most = max(counts.values(), default=0)
    for f, wheelsets in gear.bogies.items():
        label = body_label(v, f)
        if counts[f] < most:
            fuller = next(g for g, n in counts.items() if n == most)
            out.append(PlausibilityWarning(label, f"carries {counts[f]} wheelset(s), {fuller} carries {most}: a "
                                           "wheelset deleted (with its elements)?", counts[f], "bogie_wheelsets"))
        middle = float(np.mean([x[w] for w in wheelsets]))
        if abs(x[f] - middle) > BOGIE_CG_TOL_M:
            out.append(PlausibilityWarning(
                f"{label}.cg_m[0]", f"the bogie's CG (x = {x[f]:g} m) is {x[f] - middle:+.3g} m from the middle of "
                f"its {len(wheelsets)} wheelset(s) ({', '.join(wheelsets)}): a wheelset deleted, or a position "
                f"slipped?{named_lengths(v, x[f], x[f] - middle)}", x[f] - middle, "bogie_wheelsets"))
        out += _spacings(v, wheelsets, AXLE_SPACING_BOGIE_M, f"axles of bogie {f}")
    carried: dict[str, list[str]] = {}
    for w, f in gear.frames.items():
        if f and f != GROUND and f not in gear.bogies:
            carried.setdefault(f, []).append(w)
    for f, wheelsets in carried.items():
        out += _spacings(v, sorted(wheelsets, key=lambda w: x[w]), AXLE_SPACING_CARRIED_M,
                         f"axles carried by {f}")
    if len(ws) >= 2:
        spread = ws[-1].cg[0] - ws[0].cg[0]
        middle = float(np.mean([b.cg[0] for b in ws]))
        masses = np.array([b.mass for b in v.bodies])
        cg = float(masses @ np.array([b.cg[0] for b in v.bodies]) / masses.sum())
        if spread > 0 and abs(cg - middle) > VEHICLE_CG_FRACTION * spread:
            out.append(PlausibilityWarning(
                "bodies (vehicle CG)", f"the vehicle's CG (x = {cg:.3g} m) is {cg - middle:+.3g} m from the middle "
                f"of its {len(ws)} wheelsets (spread {spread:.3g} m): the static axle loads are far from equal (the "
                "model shares the weight equally); a wheelset deleted, or a body's position slipped?", cg - middle,
                "vehicle_cg"))
    out += _axleboxes(v, gear)
    return out


def _spacings(v: Vehicle, wheelsets, band: tuple[float, float], what: str) -> list[PlausibilityWarning]:
    x = {b.name: b.cg[0] for b in v.bodies}
    out = []
    for w1, w2 in zip(wheelsets, wheelsets[1:], strict=False):
        d = x[w2] - x[w1]
        if _off(d, band):
            usual = AXLE_SPACING_BOGIE_USUAL_M if band == AXLE_SPACING_BOGIE_M else band
            slip = likely_slip(d, usual, LENGTH_UNITS, "m")
            out.append(PlausibilityWarning(
                f"{body_label(v, w2)}.cg_m[0]", f"{w1} and {w2} ({what}) are {d:.4g} m apart, outside the usual "
                f"{band[0]:g}-{band[1]:g} m{suffix(slip)}{named_lengths(v, d, d / 2)}", d, "wheelbase"))
    return out


def _axleboxes(v: Vehicle, gear: RunningGear) -> list[PlausibilityWarning]:
    """The lateral offset of the primary suspension's wheelset ends (primary lateral semi-spacing)."""
    wheelsets = {b.name for b in v.wheelsets}
    out, seen = [], set()
    for e in v.elements:
        if gear.role(e, wheelsets) != "primary" or e.body_b == GROUND:
            continue
        key, p = ("point_a_m", e.point_a) if e.body_a in wheelsets else ("point_b_m", e.point_b)
        y = abs(p[1])
        if y > 0.05 and _off(y, AXLEBOX_Y_M) and y <= HALF_WIDTH_M and (e.id, key) not in seen:
            seen.add((e.id, key))
            slip = likely_slip(y, (0.5, 1.2), LENGTH_UNITS, "m")
            out.append(PlausibilityWarning(
                element_label(e, f"{key}[1]"), f"the primary suspension acts {y:g} m off the wheelset's centre "
                f"line, outside the usual {AXLEBOX_Y_M[0]:g}-{AXLEBOX_Y_M[1]:g} m (axleboxes){suffix(slip)}"
                f"{named_lengths(v, y)}", y, "axlebox_offset"))
    return out


# ---------------------------------------------------------------------------------------------- point pairs
def _off_line(e: Element, a: np.ndarray, b: np.ndarray) -> float:
    gap = b - a
    if e.rotational:
        return 0.0
    d = np.asarray(e.direction)
    return float(np.linalg.norm(gap - (gap @ d) * d))


def _pair_slip(v: Vehicle, e: Element) -> str:
    """The edit of one point that brings the element's ends together, in words; ``""`` when none does."""
    cg = {b.name: np.asarray(b.cg) for b in v.bodies}
    cg[GROUND] = np.zeros(3)
    pa, pb = np.asarray(e.point_a), np.asarray(e.point_b)
    ca, cb = cg[e.body_a], cg[e.body_b]

    def meet(a, b) -> bool:
        return float(np.linalg.norm(np.asarray(b) - np.asarray(a))) < SAME_POINT_M

    if e.body_b != GROUND and meet(ca + pa, pb):
        return "point_b_m looks absolute: it is measured from body_b's CG"
    if meet(pa, cb + pb):
        return "point_a_m looks absolute: it is measured from body_a's CG"
    if meet(ca + pb, cb + pa):
        return "point_a_m and point_b_m swapped?"
    for key, p, other, c_own in (("point_a_m", pa, cb + pb, ca), ("point_b_m", pb, ca + pa, cb)):
        for k in range(3):
            q = p.copy()
            q[k] = -q[k]
            if q[k] != p[k] and meet(c_own + q, other):
                return f"sign slip in {key}[{k}]?"
            for label, factor in LENGTH_UNITS[:2]:
                q = p.copy()
                q[k] = q[k] * factor
                if q[k] != p[k] and meet(c_own + q, other):
                    return f"{key}[{k}] looks like {label}: {p[k]:g} → {q[k]:.4g} m?"
    return ""


def _point_pairs(v: Vehicle) -> list[PlausibilityWarning]:
    """Each element's two ends together on its line of action (elements on a misplaced body are skipped)."""
    skip = _misplaced(v, _extent(v))
    groups: dict[tuple, tuple[Element, PlausibilityWarning, list[str]]] = {}
    for e in v.elements:
        if e.body_a in skip or e.body_b in skip:
            continue
        a, b = _ends(v, e)
        gap = float(np.linalg.norm(b - a))
        off = _off_line(e, a, b)
        if off <= PAIR_OFF_LINE_M and gap <= PAIR_GAP_M:
            continue
        tag = (e.body_a, e.body_b, tuple(np.round(np.abs(a), 6)), tuple(np.round(np.abs(b), 6)))  # with its mirror
        if tag in groups:
            groups[tag][2].append(e.id)
            continue
        what = (f"{gap:.3g} m apart" if gap > PAIR_GAP_M else
                f"{off:.3g} m off its line of action (an element's ends lie on the line it acts along)")
        slip = _pair_slip(v, e) or "a position missing, slipped or in the wrong unit?"
        w = PlausibilityWarning("", f"the element's ends ({e.body_a} at {np.round(a, 3).tolist()}, {e.body_b} at "
                                f"{np.round(b, 3).tolist()} m) are {what}: {slip}", gap, "point_pair")
        groups[tag] = (e, w, [e.id])
    return [PlausibilityWarning(element_label(e, "point_b_m", ids), w.message, w.value, w.check)
            for e, w, ids in groups.values()]


# ---------------------------------------------------------------------------------------------- symmetry
def _canonical(e: Element, ndigits: int = 6) -> tuple:
    """An element's geometry as a hashable key (its direction up to sign; ends in either order)."""
    d = np.round(np.asarray(e.direction), ndigits) + 0.0
    if next((c for c in d if c != 0.0), 0.0) < 0.0:
        d = -d
    ends = sorted([(e.body_a, tuple(np.round(e.point_a, ndigits) + 0.0)),
                   (e.body_b, tuple(np.round(e.point_b, ndigits) + 0.0))])
    return (e.type, tuple(ends), tuple(d))


def _symmetry(v: Vehicle) -> list[PlausibilityWarning]:
    """Each element has its mirror image in y (same value), and none is listed twice."""
    out: list[PlausibilityWarning] = []
    keys: dict[tuple, list[Element]] = {}
    for e in v.elements:
        keys.setdefault(_canonical(e), []).append(e)
    reported = set()
    for key, group in keys.items():
        ids = [e.id for e in group]
        for i in sorted(set(ids)):
            if ids.count(i) > 1 and (i, key) not in reported:
                reported.add((i, key))
                e = group[ids.index(i)]
                out.append(PlausibilityWarning(element_label(e), f"listed {ids.count(i)} times at the same points "
                                               f"and direction ({e.body_a} {list(e.point_a)}, {e.body_b} "
                                               f"{list(e.point_b)}): its value counts {ids.count(i)} times; a copy "
                                               "left over, or mirror_y on an element already given on both sides?",
                                               float(ids.count(i)), "duplicate"))
    done = set()
    for e in v.elements:
        m = e.mirrored_y()
        mkey = _canonical(m)
        if mkey == _canonical(e) or (e.id, e.body_a, e.body_b) in done:
            continue
        partners = keys.get(mkey, [])
        if not any(math.isclose(p.value, e.value, rel_tol=1e-9) for p in partners):
            done.add((e.id, e.body_a, e.body_b))
            side = e.point_a[1] if e.point_a[1] != 0.0 else e.point_b[1]
            what = ("no element at the mirror image (y → −y)" if not partners else
                    f"its mirror image has another value ({partners[0].id} = {partners[0].value:g})")
            out.append(PlausibilityWarning(
                element_label(e, "mirror_y"), f"the element at y = {side:g} m ({e.id} = {e.value:g}) has {what}: "
                "mirror_y = true forgotten, or an element missing? (intended for an asymmetric vehicle: ignore)",
                e.value, "mirror"))
    return out


__all__ = [
    "AXES", "AXLEBOX_Y_M", "AXLE_SPACING_BOGIE_M", "AXLE_SPACING_BOGIE_USUAL_M", "AXLE_SPACING_CARRIED_M",
    "BOGIE_CG_TOL_M", "CG_LATERAL_M", "LATERAL_USUAL_M", "POSITION_USUAL_M", "MAX_LENGTH_M", "OVERHANG_M",
    "PAIR_GAP_M", "PAIR_OFF_LINE_M", "SAME_POINT_M", "VEHICLE_CG_FRACTION", "WHEEL_GAP_M",
    "layout_checks", "named_lengths",
]
