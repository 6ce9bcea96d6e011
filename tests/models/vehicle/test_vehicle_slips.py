"""A slip set: deliberate mistakes in authored vehicle files (the bundled coach, locomotive and wheelset edited as
TOML text), each caught — a plausibility warning or a load error naming the file, the key and the likely slip — or
shown harmless (the same matrices and critical speed).  Units, typos, signs, swaps, missing parts, and every kind of
issue 27 item 3: positions and lengths against the vehicle's extent and wheelbase, gyration radii against the
bodies' size and each other, point pairs, bogies short of a wheelset, primary stiffnesses, track data, directions
against an element's role.  The table "Slips the checks catch" in docs/vehicle.md lists the same slips."""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from railopt.models.stability import critical_speed
from railopt.models.vehicle import VehicleFileError, load_vehicle
from railopt.models.vehicle.loader import bundled_path
from railopt.models.vehicle.plausibility import plausibility

BASES = {name: bundled_path(name).read_text() for name in ("manchester-coach", "sd40-2", "single-wheelset")}
DOC = Path(__file__).parents[3] / "docs" / "vehicle.md"


# ---------------------------------------------------------------------------------------------- TOML edits
def _blocks(text: str) -> list[str]:
    return re.split(r"(?m)^(?=\[)", text)


def _hits(parts: list[str], where: tuple[str, ...]) -> list[int]:
    return [i for i, p in enumerate(parts) if all(w in p for w in where)]


def sub(old: str, new: str, *where: str) -> Callable[[str], str]:
    """Replace ``old`` by ``new`` in the one table (block) that contains every string of ``where``
    (the whole file when ``where`` is empty: the first occurrence)."""

    def edit(text: str) -> str:
        if not where:
            assert old in text, old
            return text.replace(old, new, 1)
        parts = _blocks(text)
        (i,) = _hits(parts, where)
        assert old in parts[i], (old, where)
        parts[i] = parts[i].replace(old, new, 1)
        return "".join(parts)

    return edit


def length(name: str, old: str, new: str) -> Callable[[str], str]:
    """Set the ``[lengths]`` entry ``name`` from ``old`` to ``new`` (as written)."""
    return sub(f"{name} = {{ value = {old},", f"{name} = {{ value = {new},")


def drop(*where: str) -> Callable[[str], str]:
    """Delete every table (block) containing every string of ``where``."""

    def edit(text: str) -> str:
        parts = _blocks(text)
        hits = _hits(parts, where)
        assert hits, where
        return "".join(p for i, p in enumerate(parts) if i not in hits)

    return edit


def copy(*where: str) -> Callable[[str], str]:
    """List the one table containing every string of ``where`` twice (a copy-paste left over)."""

    def edit(text: str) -> str:
        parts = _blocks(text)
        (i,) = _hits(parts, where)
        return "".join(parts[: i + 1] + [parts[i]] + parts[i + 1:])

    return edit


def both(*edits: Callable[[str], str]) -> Callable[[str], str]:
    """Apply ``edits`` in turn."""

    def edit(text: str) -> str:
        for e in edits:
            text = e(text)
        return text

    return edit


def swap_blocks(first: tuple[str, ...], second: tuple[str, ...]) -> Callable[[str], str]:
    """Exchange two tables (block order)."""

    def edit(text: str) -> str:
        parts = _blocks(text)
        (i,) = _hits(parts, first)
        (j,) = _hits(parts, second)
        parts[i], parts[j] = parts[j], parts[i]
        return "".join(parts)

    return edit


# ---------------------------------------------------------------------------------------------- the slips
@dataclass(frozen=True)
class Slip:
    """One deliberate mistake: ``edit`` applied to the bundled ``base``; caught by ``check`` (a warning whose key
    contains ``key`` and whose message contains ``hint``) or, with ``check = "error"``, by a load error naming the
    file and matching ``key``."""

    name: str
    kind: str
    base: str
    edit: Callable[[str], str]
    check: str
    key: str
    hint: str = ""


C, L, W = "manchester-coach", "sd40-2", "single-wheelset"
PKY3 = ('id = "kpy"', 'body_a = "wheelset3"')
CSY_F = ('id = "csy"', 'body_b = "bogie_front"')
KSZ_F = ('id = "ksz"', 'body_b = "bogie_front"')
KSX_R = ('id = "ksx"', 'body_b = "bogie_rear"')
WS1 = ('name = "wheelset1"',)

SLIPS: list[Slip] = [
    # lengths and positions, against the vehicle's extent and wheelbase (units, typos)
    Slip("semi-wheelbase in cm (128)", "units", C,
         length("semi_wheelbase", "1.28", "128.0"), "length", "lengths.semi_wheelbase", "cm"),
    Slip("semi-wheelbase 10x (12.8, a typo)", "typos", C,
         length("semi_wheelbase", "1.28", "12.8"), "wheelbase", "(wheelset2).cg_m[0]",
         "25.6 → 2.56 m"),
    Slip("semi-wheelbase in feet (4.2)", "units", C,
         length("semi_wheelbase", "1.28", "4.2"), "wheelbase", "(wheelset4).cg_m[0]", "feet"),
    Slip("bogie semi-spacing in dm (0.95)", "units", C,
         length("bogie_semi_spacing", "9.5", "0.95"), "wheel_overlap", ".cg_m[0]", "overlap"),
    Slip("bogie semi-spacing in cm (950)", "units", C,
         length("bogie_semi_spacing", "9.5", "950.0"), "length", "lengths.bogie_semi_spacing", "→ 9.5 m"),
    Slip("body CG height in mm (1800)", "units", C,
         length("h_body", "1.8", "1800.0"), "length", "lengths.h_body", "mm"),
    Slip("secondary attachment height in cm (100)", "units", C,
         length("h_secondary", "1.0", "100.0"), "length", "lengths.h_secondary",
         "cm (→ 1 m)"),
    Slip("primary spring's bogie end height in mm", "units", C,
         sub('"primary_semi_spacing", "r0 - h_bogie"]', '"primary_semi_spacing", -140.0]', 'id = "kpz"',
             'body_a = "wheelset2"'), "height", "(kpz: wheelset2-bogie_rear).point_b_m[2]", "mm"),
    Slip("secondary lateral semi-spacing 10x (10.0)", "typos", C,
         length("secondary_semi_spacing", "1.0", "10.0"), "lateral_offset", "body-bogie_rear).point_a_m[1]",
         "10× too large (10 → 1 m)"),
    Slip("primary lateral semi-spacing in dm (0.1)", "units", C,
         length("primary_semi_spacing", "1.0", "0.1"), "axlebox_offset", "point_a_m[1]",
         "10× too small"),
    Slip("lateral damper offset in mm (l13 = 200)", "units", L,
         length("l13", "0.20", "200.0"), "length", "lengths.l13", "mm"),
    Slip("cab point in mm", "units", C,
         sub("point_m = [9.5, 0.0, 2.5]", "point_m = [9500.0, 0.0, 2500.0]"), "extent", "cab.point_m[0]",
         "mm: 9500 → 9.5 m"),
    Slip("wheelset CG height in mm (460)", "units", C,
         sub('"r0"]', "460.0]", 'name = "wheelset3"'), "cg_height", "(wheelset3).cg_m[2]", "mm"),
    Slip("body CG y and z swapped", "swaps", C,
         sub('cg_m = [0.0, 0.0, "h_body"]', 'cg_m = [0.0, "h_body", 0.0]'), "lateral_offset", "(body).cg_m[1]",
         "y and z swapped"),
    Slip("semi-gauge 10x (7.5)", "typos", C,
         sub("semi_gauge_m = 0.75", "semi_gauge_m = 7.5"), "semi_gauge", "contact.semi_gauge_m", "→ 0.75 m"),
    # signs
    Slip("front bogie CG at -x (sign)", "signs", C,
         sub('cg_m = ["bogie_semi_spacing",', 'cg_m = ["-bogie_semi_spacing",', 'name = "bogie_front"'),
         "bogie_wheelsets", "(bogie_front).cg_m[0]", "from the middle"),
    Slip("wheelset at the other end (sign of x)", "signs", C,
         sub('cg_m = ["bogie_semi_spacing + semi_wheelbase",', 'cg_m = ["-(bogie_semi_spacing + semi_wheelbase)",',
             'name = "wheelset4"'), "wheel_overlap", "cg_m[0]", "overlap"),
    Slip("primary lateral spring's bogie end at -x (sign)", "signs", C,
         sub('point_b_m = ["semi_wheelbase",', 'point_b_m = ["-semi_wheelbase",', 'id = "kpy"',
             'body_a = "wheelset2"'), "point_pair", "(kpy: wheelset2-bogie_rear)", "sign slip in point_b_m[0]"),
    Slip("negative secondary vertical stiffness", "signs", L,
         sub("stiffness_N_per_m = 60000000.0", "stiffness_N_per_m = -60000000.0", 'id = "K3"', 'body_b = "frame_rear"'),
         "error", r"elements\[\d+\] \(K3\)\.stiffness_N_per_m: must be >= 0"),
    Slip("negative conicity", "signs", C, sub("conicity = 0.15", "conicity = -0.15"), "error",
         r"contact\.conicity: must be >= 0"),
    Slip("negative clearance", "signs", L,
         length("secondary_lateral_m", "0.0254", "-0.0254"), "error",
         r"clearances\.secondary_lateral_m: must be positive"),
    # swaps
    Slip("body Ixx and Iyy swapped", "swaps", C,
         sub("inertia_kg_m2 = [56800.0, 1970000.0, 1970000.0]", "inertia_kg_m2 = [1970000.0, 56800.0, 1970000.0]"),
         "gyration_size", "(body).inertia_kg_m2[0]", "Ixx and Iyy swapped"),
    Slip("bogie Ixx and Izz swapped", "swaps", C,
         sub("inertia_kg_m2 = [1722.0, 1476.0, 3067.0]", "inertia_kg_m2 = [3067.0, 1476.0, 1722.0]",
             'name = "bogie_rear"'), "inertia_order", "(bogie_rear).inertia_kg_m2", "Ixx and Izz swapped"),
    Slip("locomotive frame Iyy and Izz swapped", "swaps", L,
         sub("inertia_kg_m2 = [4200.0, 15000.0, 19000.0]", "inertia_kg_m2 = [4200.0, 19000.0, 15000.0]",
             'name = "frame_front"'), "inertia_order", "(frame_front).inertia_kg_m2", "Iyy and Izz swapped"),
    Slip("wheelset Ixx and Iyy swapped", "swaps", C,
         sub("inertia_kg_m2 = [1120.0, 112.0, 1120.0]", "inertia_kg_m2 = [112.0, 1120.0, 1120.0]", *WS1),
         "inertia_order", "(wheelset1).inertia_kg_m2", "spin about the axle"),
    Slip("point_a_m and point_b_m swapped", "swaps", C,
         both(sub('point_a_m = ["bogie_semi_spacing", "secondary_semi_spacing", "h_secondary - h_body"]',
                  'point_a_m = [0.0, "secondary_semi_spacing", "h_secondary - h_bogie"]', *KSZ_F),
              sub('point_b_m = [0.0, "secondary_semi_spacing", "h_secondary - h_bogie"]',
                  'point_b_m = ["bogie_semi_spacing", "secondary_semi_spacing", "h_secondary - h_body"]', *KSZ_F)),
         "point_pair", "(ksz: body-bogie_front)", "swapped"),
    Slip("body_a and body_b swapped (points kept)", "swaps", C,
         both(sub('body_a = "body"', 'body_a = "bogie_rear"', *KSX_R),
              sub('body_b = "bogie_rear"', 'body_b = "body"', 'id = "ksx"', 'body_a = "bogie_rear"')),
         "point_pair", "(ksx: bogie_rear-body)", "swapped"),
    Slip("secondary point written absolute", "typos", C,
         sub('point_b_m = [0.0, "secondary_semi_spacing", "h_secondary - h_bogie"]',
             'point_b_m = ["bogie_semi_spacing", "secondary_semi_spacing", "h_secondary"]', *CSY_F),
         "point_pair", "(csy: body-bogie_front)", "looks absolute"),
    # stiffness, damping and mass units
    Slip("primary lateral stiffness in kN/m", "units", C,
         lambda t: t.replace("stiffness_N_per_m = 3884000.0", "stiffness_N_per_m = 3884.0"), "primary_stiffness",
         "elements (kpy)", "kN/m"),
    Slip("primary longitudinal stiffness in N/mm", "units", C,
         lambda t: t.replace("stiffness_N_per_m = 31391000.0", "stiffness_N_per_m = 31391.0"), "primary_stiffness",
         "elements (kpx)", "N/mm"),
    Slip("primary vertical stiffness in MN/m", "units", C,
         lambda t: t.replace("stiffness_N_per_m = 1220000.0", "stiffness_N_per_m = 1.22"), "stiffness",
         "elements (kpz).stiffness_N_per_m", "MN/m"),
    Slip("locomotive primary vertical stiffness in kN/m", "units", L,
         lambda t: t.replace("stiffness_N_per_m = 2700000.0", "stiffness_N_per_m = 2700.0"), "stiffness",
         "elements (K9).stiffness_N_per_m", "kN/m"),
    Slip("secondary vertical stiffness in kN/m", "units", C,
         lambda t: t.replace("stiffness_N_per_m = 430000.0", "stiffness_N_per_m = 430.0"), "stiffness",
         "elements (ksz).stiffness_N_per_m", "kN/m"),
    Slip("secondary lateral stiffness 1000x (1.6e8)", "typos", C,
         lambda t: re.sub(r'(id = "ksy"\n(?:.*\n)*?stiffness_N_per_m = )160000.0', r"\g<1>1.6e8", t),
         "body_frequency", "(body): lateral frequency", "Hz"),
    Slip("secondary lateral damping in kN s/m", "units", C,
         lambda t: t.replace("damping_N_s_per_m = 32000.0", "damping_N_s_per_m = 32.0"), "damping",
         "elements (csy).damping_N_s_per_m", "kN·s/m"),
    Slip("yaw damper in kN s/m (400)", "units", L,
         lambda t: t.replace("damping_N_s_per_m = 400000.0", "damping_N_s_per_m = 400.0"), "damping",
         "elements (C15).damping_N_s_per_m", "kN·s/m"),
    Slip("secondary vertical damping 1000x", "typos", C,
         lambda t: t.replace("damping_N_s_per_m = 20000.0", "damping_N_s_per_m = 2.0e7"), "damping",
         "elements (csz).damping_N_s_per_m", "too large"),
    Slip("primary lateral damping 1000x", "typos", C,
         lambda t: t.replace("damping_N_s_per_m = 2000.0", "damping_N_s_per_m = 2.0e6"), "primary_damping",
         "elements (cpy).damping_N_s_per_m", "above the 5e+05 N·s/m"),
    Slip("anti-roll bar 1000x", "typos", C,
         lambda t: t.replace("stiffness_N_m_per_rad = 940000.0", "stiffness_N_m_per_rad = 9.4e8"), "stiffness",
         "elements (karb).stiffness_N_m_per_rad", "10× too large"),
    Slip("bogie frame mass 10x too small", "typos", C,
         sub("mass_kg = 2615.0", "mass_kg = 261.5", 'name = "bogie_rear"'), "gyration_size",
         "(bogie_rear).inertia_kg_m2[2]", "mass would lie beyond them"),
    Slip("anti-roll bar in kN m/rad", "units", C,
         lambda t: t.replace("stiffness_N_m_per_rad = 940000.0", "stiffness_N_m_per_rad = 940.0"), "stiffness",
         "elements (karb).stiffness_N_m_per_rad", "kN·m/rad"),
    Slip("bogie frame mass 10x", "typos", C,
         sub("mass_kg = 2615.0", "mass_kg = 26150.0", 'name = "bogie_front"'), "frame_mass",
         "(bogie_front).mass_kg", "10× too large"),
    Slip("car body mass 10x too small", "typos", C, sub("mass_kg = 32000.0", "mass_kg = 3200.0"), "frame_mass",
         "(bogie_rear).mass_kg", "(body).mass_kg = 3200"),
    Slip("wheelset mass 10x", "typos", C, sub("mass_kg = 1813.0", "mass_kg = 18130.0", *WS1), "mass",
         "(wheelset1).mass_kg", "10× too large"),
    Slip("motor mass in tonnes", "units", L, sub("mass_kg = 2900.0", "mass_kg = 2.9", 'name = "motor4"'), "mass",
         "(motor4).mass_kg", "tonnes"),
    Slip("body yaw inertia in t m2", "units", C,
         sub("inertia_kg_m2 = [56800.0, 1970000.0, 1970000.0]", "inertia_kg_m2 = [56800.0, 1970000.0, 1970.0]"),
         "gyration_size", "(body).inertia_kg_m2[2]", "t·m²"),
    # contact and track data
    Slip("wheel diameter for the radius", "units", C,
         sub('r0 = { value = 0.46,', 'r0 = { value = 0.92,'), "wheel_radius", "contact.wheel_radius_m", "diameter"),
    Slip("gauge for the semi-gauge", "units", C, sub("semi_gauge_m = 0.75", "semi_gauge_m = 1.435"), "semi_gauge",
         "contact.semi_gauge_m", "the gauge"),
    Slip("conicity 10x (1.5)", "typos", C, sub("conicity = 0.15", "conicity = 1.5"), "conicity", "contact.conicity",
         "10× too large: 1.5 → 0.15"),
    Slip("contact angle in degrees", "units", L, sub("theta0 = 0.05", "theta0 = 1.0"), "contact_angle",
         "contact.theta0", "degrees"),
    Slip("given creep coefficient in kN", "units", W, sub("f11_N = 10.0e6", "f11_N = 10.0e3"), "creep",
         "contact.f11_N", "kN"),
    Slip("Young's modulus in GPa", "units", C, sub("youngs_modulus_Pa = 2.1e11", "youngs_modulus_Pa = 210.0"),
         "material", "contact.youngs_modulus_Pa", "GPa"),
    Slip("rail EI in MN m2", "units", C, sub("rail_EI_N_m2 = 6.42e6", "rail_EI_N_m2 = 6.42"), "track",
         "track.rail_EI_N_m2", "MN·m²"),
    Slip("track mass in t/m", "units", C, sub("mass_per_length_kg_m = 150.0", "mass_per_length_kg_m = 0.15"), "track",
         "track.mass_per_length_kg_m", "t/m"),
    Slip("track modulus in lb/in2", "units", L, sub("track_modulus_N_m2 = 20.684e6", "track_modulus_N_m2 = 3000.0"),
         "track", "track.track_modulus_N_m2", "lb/in²"),
    Slip("track damping ratio in per cent", "units", C, sub("damping_ratio = 0.1", "damping_ratio = 10.0", "[track]"),
         "track", "track.damping_ratio", "per cent"),
    Slip("clearance in mm", "units", L, sub("secondary_lateral_m = { value = 0.0254,",
                                            "secondary_lateral_m = { value = 25.4,"), "clearance",
         "clearances.secondary_lateral_m", "mm"),
    # directions against the element's role
    Slip("primary vertical spring acting laterally", "directions", C,
         sub("direction = [0.0, 0.0, 1.0]", "direction = [0.0, 1.0, 0.0]", 'id = "kpz"', 'body_a = "wheelset3"'),
         "direction", "(kpz: wheelset3-bogie_front).direction", "named for z"),
    Slip("secondary yaw stiffness about x", "directions", C,
         sub("direction = [0.0, 0.0, 1.0]", "direction = [1.0, 0.0, 0.0]", 'id = "ksyaw"', 'body_b = "bogie_front"'),
         "direction", "(ksyaw: body-bogie_front).direction", "turns about x"),
    Slip("longitudinal spring at 45 degrees (direction typo)", "directions", C,
         sub("direction = [1.0, 0.0, 0.0]", "direction = [1.0, 1.0, 0.0]", 'id = "kpx"', 'body_a = "wheelset2"'),
         "direction", "(kpx: wheelset2-bogie_rear).direction", "named for x"),
    Slip("locomotive sidebearer lateral spring acting vertically", "directions", L,
         sub("direction = [0.0, 1.0, 0.0]", "direction = [0.0, 0.0, 1.0]", 'id = "K5"', 'body_b = "frame_front"'),
         "direction", "(K5: body-frame_front).direction", "named for y"),
    # missing parts and copies
    Slip("a wheelset deleted with its elements (wheelset1)", "missing parts", C,
         both(drop(*WS1), drop('body_a = "wheelset1"')), "bogie_wheelsets", "(bogie_rear)", "wheelset deleted"),
    Slip("one wheelset's primary lateral springs deleted", "missing parts", C, drop(*PKY3), "suspension_mismatch",
         "(wheelset3): primary stiffness along y", "missing"),
    Slip("mirror_y forgotten on a primary damper", "missing parts", C,
         sub("mirror_y = true\n", "", 'id = "cpz"', 'body_a = "wheelset4"'), "mirror", "(cpz: wheelset4-bogie_front)",
         "mirror_y = true forgotten"),
    Slip("one bogie's secondary lateral springs deleted", "missing parts", C,
         drop('id = "ksy"', 'body_b = "bogie_front"'), "suspension_mismatch",
         "(bogie_front): secondary stiffness along y", "missing"),
    Slip("a wheelset's rigid constraint deleted", "missing parts", L,
         drop("[[constraints]]", 'body = "wheelset5"', 'type = "rigid"'), "wheelset_restraint", "(wheelset5)",
         "deleted"),
    Slip("secondary damper listed twice", "missing parts", C, copy(*CSY_F), "duplicate", "(csy: body-bogie_front)",
         "listed 2 times"),
    Slip("[contact] table deleted", "missing parts", C, drop("[contact]"), "error", r"missing \[contact\] table"),
    Slip("a body's kind line forgotten", "missing parts", C, sub('kind = "wheelset"\n', "", 'name = "wheelset2"'),
         "error", r"bodies\[3\] \(wheelset2\): missing kind"),
    # typos refused by the schema or the loader
    Slip("misspelt value key", "typos", C, sub("stiffness_N_per_m = 160000.0", "stiffnes_N_per_m = 160000.0", *KSX_R),
         "error", r"stiffnes_N_per_m: unknown key; did you mean 'stiffness_N_per_m'"),
    Slip("misspelt body name", "typos", C, sub('body_b = "bogie_rear"', 'body_b = "bogie_raer"', *KSX_R), "error",
         r"body_b 'bogie_raer' is not a body; did you mean 'bogie_rear'"),
    Slip("misspelt element id (twin of kpy)", "typos", C, sub('id = "kpy"', 'id = "kyp"', *PKY3), "error",
         r"alias: 'primary_lateral_stiffness' already names element 'kpy'"),
    Slip("dropped digit on one copy of a value", "typos", C,
         sub("stiffness_N_per_m = 3884000.0", "stiffness_N_per_m = 388400.0", *PKY3), "error",
         r"id 'kpy' given two values"),
    Slip("wheelset mass 1e-30 (R6)", "units", C, sub("mass_kg = 1813.0", "mass_kg = 1e-30", *WS1), "error",
         r"bodies\[2\] \(wheelset1\)\.mass_kg: 1e-30 kg"),
    Slip("zero clearance (R6)", "signs", L, sub("secondary_lateral_m = { value = 0.0254,",
                                                "secondary_lateral_m = { value = 0.0,"), "error",
         r"clearances\.secondary_lateral_m: must be positive"),
]

HARMLESS: list[Slip] = [
    Slip("spring direction written negative", "signs", C,
         sub("direction = [1.0, 0.0, 0.0]", "direction = [-1.0, 0.0, 0.0]", *KSX_R), "harmless", ""),
    Slip("mirrored damper written on the other side", "signs", C,
         both(sub('"secondary_semi_spacing", "h_secondary - h_body"]',
                  '"-secondary_semi_spacing", "h_secondary - h_body"]', *CSY_F),
              sub('"secondary_semi_spacing", "h_secondary - h_bogie"]',
                  '"-secondary_semi_spacing", "h_secondary - h_bogie"]', *CSY_F)), "harmless", ""),
    Slip("element written from its other end", "swaps", C,
         both(sub('body_a = "body"', 'body_a = "bogie_front"', *KSZ_F),
              sub('body_b = "bogie_front"', 'body_b = "body"', 'id = "ksz"', 'body_a = "bogie_front"'),
              sub('point_a_m = ["bogie_semi_spacing", "secondary_semi_spacing", "h_secondary - h_body"]',
                  'point_a_m = [0.0, "secondary_semi_spacing", "h_secondary - h_bogie"]', 'id = "ksz"',
                  'body_a = "bogie_front"'),
              sub('point_b_m = [0.0, "secondary_semi_spacing", "h_secondary - h_bogie"]',
                  'point_b_m = ["bogie_semi_spacing", "secondary_semi_spacing", "h_secondary - h_body"]', 'id = "ksz"',
                  'body_a = "bogie_front"')), "harmless", ""),
    Slip("element tables in another order", "swaps", C, swap_blocks(KSX_R, PKY3), "harmless", ""),
]


def _write(tmp_path: Path, slip: Slip) -> Path:
    text = slip.edit(BASES[slip.base])
    assert text != BASES[slip.base], slip.name
    path = tmp_path / "car.toml"
    path.write_text(text)
    return path


def test_the_slip_set_covers_every_kind() -> None:
    assert len(SLIPS) + len(HARMLESS) >= 45
    assert len({s.name for s in SLIPS + HARMLESS}) == len(SLIPS) + len(HARMLESS)
    assert {s.kind for s in SLIPS} >= {"units", "typos", "signs", "swaps", "missing parts", "directions"}
    item3 = {"extent", "length", "wheelbase", "axlebox_offset", "lateral_offset", "height", "gyration_size",
             "inertia_order", "point_pair", "bogie_wheelsets", "primary_stiffness", "track", "direction"}
    assert item3 <= {s.check for s in SLIPS}


@pytest.mark.parametrize("slip", SLIPS, ids=[s.name for s in SLIPS])
def test_slip_is_caught_naming_file_key_and_slip(tmp_path: Path, slip: Slip) -> None:
    path = _write(tmp_path, slip)
    if slip.check == "error":
        with pytest.raises(VehicleFileError) as err:
            load_vehicle(path)
        message = str(err.value)
        assert message.startswith(f"{path}: ") and re.search(slip.key, message), message
        return
    warnings = plausibility(load_vehicle(path))
    found = [w for w in warnings if w.check == slip.check and slip.key in w.path]
    assert found, "\n".join(w.line() for w in warnings)
    assert any(slip.hint in w.message for w in found), "\n".join(w.line() for w in found)
    assert all(w.file == str(path) and w.line().startswith(f"{path}: ") for w in warnings)


def _matrices(vehicle) -> list[np.ndarray]:
    out = []
    for view in (vehicle.lateral("rigid", speed=30.0), vehicle.vertical("rigid", speed=30.0)):
        out += [view.M, view.C, view.K]
    return out


@pytest.mark.parametrize("slip", HARMLESS, ids=[s.name for s in HARMLESS])
def test_harmless_slip_changes_no_number(tmp_path: Path, slip: Slip) -> None:
    """Same matrices (to rounding) and the same certified critical speed (< 1 %, in fact to the tolerance); and no
    warning — nothing to report."""
    base = load_vehicle(slip.base)
    slipped = load_vehicle(_write(tmp_path, slip))
    assert plausibility(slipped) == []
    for a, b in zip(_matrices(base), _matrices(slipped), strict=True):
        np.testing.assert_allclose(b, a, rtol=1e-12, atol=1e-9 * np.max(np.abs(a)))
    v0 = critical_speed(base, "rigid", (1.0, 150.0), tol=0.01).speed
    v1 = critical_speed(slipped, "rigid", (1.0, 150.0), tol=0.01).speed
    assert abs(v1 - v0) <= 0.01 * v0


def test_docs_list_every_slip_with_its_check() -> None:
    text = DOC.read_text()
    section = text[text.index("## Slips the checks catch"):]
    for s in SLIPS + HARMLESS:
        row = f"| {s.name} | {s.kind} | `{s.check}` |"
        assert row in section, row
