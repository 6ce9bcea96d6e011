"""Profiles: S1002 and 60E1 against their definitions and the Manchester benchmark files; loaders; inclination.

Independent references:
* the Manchester Contact Benchmark v3 S1002 (CONTACT, examples/MBench_S1002_v3.prw, commit d431cdb — shipped
  unchanged under data/profiles/), read by our SIMPACK loader with its own flags (mirror.y = 1);
* EN 13715 S1002 "h28 e32.5": flange height 28 mm, flange thickness 32.5 mm at 10 mm above the running circle;
* 60E1 (EN 13674-1): head width 72 mm, R300/R80/R13 arcs tangent, 1:20 flank; points of the head sampled
  independently (../shared/profiles/uic60_60E1_head_analytic.csv) and the benchmark UIC60 de-canted (0.041 mm);
* geometry: a rotation by atan(1/40) moves an R300 crown's top by 300 sin(atan 1/40) mm.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from railopt.models.contact.profiles import (
    DATA_DIR,
    PROFILE_NAMES,
    RAIL_60E1,
    S1002_BREAKPOINTS_MM,
    Profile,
    incline,
    load_profile,
    rail_60e1,
    read_profile_csv,
    read_simpack_profile,
    s1002,
    s1002_depth_mm,
)

# --- S1002 ---------------------------------------------------------------------------------------------------


def test_s1002_analytic_equals_manchester_benchmark_file() -> None:
    bench = read_simpack_profile(DATA_DIR / "MBench_S1002_v3.prw", flange_back=-0.070)
    assert bench.kind == "wheel" and bench.y.size == 399
    # after mirror.y the flange lies at negative y: the file runs from -69.61 mm (flange back side) to +60 mm
    assert bench.y[0] == pytest.approx(-0.0696126280) and bench.y[-1] == pytest.approx(0.060)
    analytic = -s1002_depth_mm(bench.y * 1e3)  # mm, z up
    err = np.max(np.abs(bench.z * 1e3 - analytic))
    assert err < 1e-5  # measured 1.6e-6 mm (the file's 8 significant digits)


def test_s1002_standard_dimensions_and_section_joins() -> None:
    s = np.linspace(-70.0, 60.0, 1_300_001)
    F = s1002_depth_mm(s)
    i = int(np.argmax(F))
    assert F[i] == pytest.approx(28.0, abs=1e-6)  # flange height h = 28 mm (EN 13715 "S1002 h28")
    # flange thickness e = 32.5 mm, measured 10 mm above the running circle (F = 10 on the flange face)
    face = (s > s[i]) & (s < -30.0)
    s10 = s[face][np.argmin(np.abs(F[face] - 10.0))]
    assert s10 + 70.0 == pytest.approx(32.5, abs=2e-4)
    # sections join continuously: < 4e-5 mm except C/D at -35 mm (1.2e-4 mm, the published coefficients' rounding)
    for b in S1002_BREAKPOINTS_MM[1:-1]:
        jump = abs(float(s1002_depth_mm(b + 1e-9) - s1002_depth_mm(b - 1e-9)))
        assert jump < (1.3e-4 if b == -35.0 else 4e-5), b
    # and with continuous slope (tangent arcs and lines) to 5e-5
    for b in S1002_BREAKPOINTS_MM[1:-1]:
        left = float(s1002_depth_mm(b - 1e-6) - s1002_depth_mm(b - 2e-6)) / 1e-6
        right = float(s1002_depth_mm(b + 2e-6) - s1002_depth_mm(b + 1e-6)) / 1e-6
        assert abs(left - right) < 5e-5, b


def test_s1002_profile_convention() -> None:
    w = s1002()
    assert w.kind == "wheel" and w.flange_back == -0.070 and w.taping_line == 0.0
    assert float(w.height(0.0)) == 0.0
    # z up: the flange tip (larger radius) lies 28 mm below the taping line, at y = -55 mm
    assert float(w.height(-0.055)) == pytest.approx(-0.028, abs=1e-9)
    assert float(w.rolling_radius(-0.055, 0.46)) == pytest.approx(0.488, abs=1e-9)
    # the tread falls towards the field side at ~1:30 near the taping line (radius decreasing outwards)
    assert 0.02 < float(w.slope(0.0)) < 0.04


# --- 60E1 ----------------------------------------------------------------------------------------------------


def test_60e1_arcs_tangent_and_head_width() -> None:
    g = RAIL_60E1.geometry()
    R = RAIL_60E1.radii
    centres = [g["c1"], g["c2"], g["c3"]]
    joints = [RAIL_60E1.y12, RAIL_60E1.y23]
    for k, yj in enumerate(joints):
        zj = float(RAIL_60E1.depth(yj))
        slopes = []
        for c, r in ((centres[k], R[k]), (centres[k + 1], R[k + 1])):
            assert math.hypot(yj - c[0], zj - c[1]) == pytest.approx(r, abs=1e-12)  # the joint lies on both arcs
            slopes.append(-(yj - c[0]) / (zj - c[1]))  # slope of a circle (centre below) at (yj, zj)
        assert abs(slopes[0] - slopes[1]) < 1e-9
    # R13 / flank: the flank has dz/dy = -20 (1:20 from vertical) and is tangent to R13
    p3, c3 = g["p3"], centres[2]
    assert -(p3[0] - c3[0]) / (p3[1] - c3[1]) == pytest.approx(-20.0, abs=1e-9)
    assert 2.0 * p3[0] == pytest.approx(0.072, abs=1e-6)  # head width 72 mm
    assert p3[1] == pytest.approx(-0.0143, abs=1e-6)  # at 14.3 mm depth


def test_60e1_equals_independent_sampling() -> None:
    """Points of ../shared/profiles/uic60_60E1_head_analytic.csv (generated separately from the arc definition
    transcribed in rohrbecka/EN13674 P60E1.swift; y and depth in mm, depth positive down), copied here."""
    y_mm = np.array([-30.1, -24.1, -18.1, -12.1, -6.1, -0.1, 5.9, 11.9, 17.9, 23.9, 29.9, 35.9])
    depth_mm = np.array([4.0488087, 1.8689817, 0.8331845, 0.2602250, 0.0620231, 0.0000167, 0.0580223, 0.2489585,
                         0.8067068, 1.8268267, 3.9214110, 13.2161359])
    z = RAIL_60E1.depth(y_mm * 1e-3) * 1e3
    assert np.max(np.abs(z + depth_mm)) < 1e-6  # the file's 7 decimals


def test_60e1_against_manchester_benchmark_uic60_decanted() -> None:
    bench = load_profile("mbench_uic60")
    assert bench.kind == "rail"
    # the benchmark rail is canted 1:40 with its origin on the top: de-cant it about that origin
    flat = incline(bench, -1.0 / 40.0)
    yy = np.linspace(-0.030, 0.020, 50_001)
    zz = flat.height(yy)
    axis = float(yy[np.nanargmax(zz)])  # the crown top of the de-canted head is its symmetry axis
    assert axis == pytest.approx(-300e-3 * math.sin(math.atan(1 / 40)), abs=5e-5)  # -7.5 mm (header: -7.492)
    x = np.linspace(-0.035, 0.035, 7001)
    diff = (flat.height(axis + x) - float(np.nanmax(zz))) - RAIL_60E1.depth(x)
    assert np.max(np.abs(diff)) < 0.045e-3  # header: 0.041 mm (R300/R80 tangent point 0.27 mm further out)


def test_rail_60e1_profile_and_aliases() -> None:
    r = rail_60e1()
    assert r.kind == "rail" and r.top == (0.0, 0.0)
    assert load_profile("UIC60") is load_profile("60E1")
    assert float(r.curvature(0.0)) == pytest.approx(-1.0 / 0.300, rel=1e-6)  # crown R300, bulging up


# --- inclination ---------------------------------------------------------------------------------------------


def test_incline_moves_the_top_of_an_r300_crown() -> None:
    r = rail_60e1()
    t = incline(r, 1.0 / 40.0)
    yy = np.linspace(0.0, 0.012, 120_001)
    top = float(yy[np.nanargmax(t.height(yy))])
    assert top == pytest.approx(0.300 * math.sin(math.atan(1 / 40)), abs=2e-7)  # to the field side
    back = incline(t, -1.0 / 40.0)
    x = np.linspace(-0.030, 0.030, 601)
    assert np.max(np.abs(back.height(x) - r.height(x))) < 1e-12
    with pytest.raises(ValueError, match="inclination"):
        incline(r, 1.5)
    with pytest.raises(ValueError, match="profile"):
        incline(s1002(), 1 / 40)


def test_annex_d_rail_is_inclined_1_in_20() -> None:
    """S-UIC 519-A as tabulated: symmetric about an axis inclined 1:20, asymmetric otherwise."""
    rail = load_profile("S-UIC 519-A")

    def midpoints(p: Profile) -> np.ndarray:
        i = int(np.argmax(p.z))
        top = p.z[i]
        out = []
        for depth in (1e-3, 3e-3, 5e-3, 8e-3):
            left = np.interp(top - depth, p.z[:i], p.y[:i])
            right = np.interp(top - depth, p.z[i:][::-1], p.y[i:][::-1])
            out.append(0.5 * (left + right))
        return np.array(out)

    upright = midpoints(incline(rail, -1.0 / 20.0))
    assert np.ptp(upright) < 2e-5  # symmetric head: the chord midpoints agree to 0.02 mm at 1-8 mm depth
    for t in (0.0, -1.0 / 40.0):  # as given, or de-inclined 1:40 only: clearly asymmetric
        assert np.ptp(midpoints(incline(rail, t) if t else rail)) > 2e-3


# --- loaders -------------------------------------------------------------------------------------------------


def test_catalogue_names() -> None:
    for name in PROFILE_NAMES:
        p = load_profile(name)
        assert p.kind in ("wheel", "rail")
        assert (p.flange_back is not None) == (p.kind == "wheel")
    assert load_profile("R-UIC 519-A") is load_profile("r_uic519_a") is load_profile("RUIC519A")
    with pytest.raises(ValueError, match="neither a catalogue name"):
        load_profile("s1003")


def test_csv_loader_formats_and_errors(tmp_path: Path) -> None:
    f = tmp_path / "w.csv"
    f.write_text("\ufeff# a wheel\ny_mm;z_mm\n-1.0; 0.5\n0.0;0.0\n1.0;-0.5\n2.0;-1.0\n", encoding="utf-8")
    p = read_profile_csv(f, "wheel", z_down=True, flange_back=-0.07)
    np.testing.assert_allclose(p.y, [-1e-3, 0.0, 1e-3, 2e-3])
    np.testing.assert_allclose(p.z, [-0.5e-3, 0.0, 0.5e-3, 1e-3])
    g = tmp_path / "bad.csv"
    g.write_text("y,z\n0,0\n1,x\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"bad\.csv, line 3"):
        read_profile_csv(g, "rail")
    h = tmp_path / "three.csv"
    h.write_text("0,0,0\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"three\.csv, line 1: expected two columns"):
        read_profile_csv(h, "rail")
    d = tmp_path / "dup.csv"
    d.write_text("0,0\n1,0\n1,1\n2,0\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"dup\.csv.*strictly increasing"):
        read_profile_csv(d, "rail")
    with pytest.raises(ValueError, match="kind"):
        load_profile(str(f))


def test_simpack_loader_flags(tmp_path: Path) -> None:
    pts = [(0.003, 0.0002), (0.001, 0.0001), (-0.001, 0.0), (-0.003, -0.0002)]  # metres, z down
    body = "\n".join(f"{a:.7e} {b:.7e} 1.0" for a, b in pts)
    text = ("header.begin\n type = 1 ! wheel\nheader.end\nspline.begin\n type = 0\n mirror.y = 1\n"
            " inversion = 1\n units.len.f = +1.0e+00 ! metres\n bound.y.min = 1\n bound.y.max = 0\n"
            f" point.begin\n ! y z w\n{body}\n point.end\nspline.end\n")
    f = tmp_path / "t.prw"
    f.write_text(text, encoding="utf-8")
    p = read_simpack_profile(f, flange_back=-0.07)
    assert p.kind == "wheel"  # the header type, not the spline block's 'type'
    np.testing.assert_allclose(p.y, [-0.003, -0.001, 0.001, 0.003])  # mirrored, sorted
    np.testing.assert_allclose(p.z, [-0.0002, -0.0001, 0.0, 0.0002])  # z up
    bad = tmp_path / "s.prr"
    bad.write_text(text.replace("mirror.y = 1", "shift.y = 2.0"), encoding="utf-8")
    with pytest.raises(ValueError, match=r"s\.prr: shift\.y"):
        read_simpack_profile(bad)
    empty = tmp_path / "e.prr"
    empty.write_text("header.begin\nheader.end\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"e\.prr: no point list"):
        read_simpack_profile(empty)


def test_profile_validation() -> None:
    with pytest.raises(ValueError, match="strictly increasing"):
        Profile(y=[0, 1, 1, 2], z=[0, 0, 0, 0], kind="rail")
    with pytest.raises(ValueError, match="kind"):
        Profile(y=[0, 1, 2, 3], z=[0, 0, 0, 0], kind="axle")
    with pytest.raises(ValueError, match="flange_back"):
        Profile(y=[0, 1, 2, 3], z=[0, 0, 0, 0], kind="rail", flange_back=-0.07)
    p = Profile(y=[0, 1, 2, 3], z=[0, 0, 0, 0], kind="rail")
    assert np.isnan(p.height(4.0))  # no surface beyond the points
