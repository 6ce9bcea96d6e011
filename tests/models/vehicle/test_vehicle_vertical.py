"""The longitudinal–vertical (u, w, β) block against App. B.2 of the thesis, term by term.

Independent source: the printed equations, re-typed below from the OCR (thesis axes and names; our
matrices are mapped with THESIS_SIGNS, so the thesis's pitch is −β).  The layout is the bundled
sd40-2 file with every length, suspension value and contact number replaced by random numbers, on
flexible track, so no coefficient can agree by accident of the data.

Thesis lengths of the motor noses (they do not occur in App. B.1), read off (B.2.10), (B.2.15),
(B.2.25), (B.2.35) for our layout (motor CG l34 from its axle towards the vehicle centre, nose l22
— ours — beyond the motor CG):  ``l35 = l22`` (nose from the motor CG);  motors 1, 6:
``l22_th = l24 − l34 − l22`` (nose on the frame, towards the truck end);  motors 2, 5:
``l27 = l34 + l22 − l26``;  motors 3, 4: ``l25 = l23 + l34 + l22``.
"""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
from printed_matrices import PrintedMatrices

from railopt.models.vehicle import THESIS_SIGNS, load_vehicle
from railopt.models.vehicle.geometry import split
from railopt.models.vehicle.loader import bundled_path

S = 31.7  # forward speed, m/s


class Printed(PrintedMatrices):
    """Our assembled (all-coordinate) matrices in thesis signs, sums of coordinates for merged ones."""

    speed = S

    def customise(self, rng: np.random.Generator, data: dict) -> None:
        f = {"f11_N": float(rng.uniform(1e6, 2e7)), "f22_N": float(rng.uniform(1e6, 2e7)),
             "f23_N_m": float(rng.uniform(1e3, 1e5)), "f33_N_m2": float(rng.uniform(10.0, 1e3))}
        data["contact"] = {"wheel_radius_m": "l20", "semi_gauge_m": "l18 / 2", "creep": "given", "spin": True,
                           "gravity_stiffness": True, "conicity": 0.07, "theta0": 0.03, "epsilon": 0.05,
                           "eta": 0.01, "axle_load_N": 2.5e5, **f}
        self.f1 = f["f11_N"]
        L = self.l
        self.l35 = L["l22"]
        self.nose = {1: L["l24"] - L["l34"] - L["l22"], 2: L["l34"] + L["l22"] - L["l26"],
                     3: L["l23"] + L["l34"] + L["l22"]}
        self.nose.update({4: self.nose[3], 5: self.nose[2], 6: self.nose[1]})


@pytest.fixture(scope="module", params=[21, 22])
def th(request: pytest.FixtureRequest) -> Printed:
    return Printed(request.param)


def check(th: Printed, row: str, expected: dict[tuple[str, str], float]) -> None:
    scale = max(abs(v) for v in expected.values())
    for (mat, col), value in expected.items():
        got = th(mat, row, col)
        assert got == pytest.approx(value, rel=1e-9, abs=1e-12 * scale), (mat, row, col)


def test_b22_body_vertical(th: Printed) -> None:
    """(B.2.2) Vertical - Body, every printed term (and no β_a term: the sidebearers are symmetric)."""
    L, p = th.l, th.p
    expected = {("M", "body.w"): th.body["body"].mass}
    for X, k3, k6 in (("K", p["K3"], p["K6"]), ("C", p["C3"], p["C6"])):
        expected.update({
            (X, "body.w"): 4 * k3 + 4 * k6,
            (X, "frame_front.w"): -2 * k3 - 2 * k6,
            (X, "frame_rear.w"): -2 * k3 - 2 * k6,
            (X, "frame_front.beta"): -2 * L["l4"] * k3 + 2 * L["l5"] * k6,
            (X, "frame_rear.beta"): 2 * L["l4"] * k3 - 2 * L["l5"] * k6,
            (X, "body.beta"): 0.0,
            (X, "body.u"): 0.0,
        })
    check(th, "body.w", expected)


def _motor_vertical(th: Printed, i: int, frame: str, nose_coef: float, motor_coef: float) -> dict:
    """(B.2.10)/(B.2.15)/(B.2.25)/(B.2.35): m_c ẅ_c + (−K10) w_b + K10 w_c + (nose) β_b + (±l35 K10) β_c, C alike."""
    p = th.p
    out = {("M", f"motor{i}.w"): th.body[f"motor{i}"].mass}
    for X, k in (("K", p["K10"]), ("C", p["C10"])):
        out.update({(X, f"{frame}.w"): -k, (X, f"motor{i}.w"): k, (X, f"{frame}.beta"): nose_coef * k,
                    (X, f"motor{i}.beta"): motor_coef * k})
    return out


def _motor_pitch(th: Printed, i: int, frame: str, sign: float, nose_coef: float) -> dict:
    """(B.2.11)/(B.2.26)/(B.2.36): I_cβ β̈_c + (∓l35 K10) w_b + (±l35 K10) w_c + (…) β_b + (l35² K10) β_c."""
    p, l35 = th.p, th.l35
    out = {("M", f"motor{i}.beta"): th.body[f"motor{i}"].inertia[1][1]}
    for X, k in (("K", p["K10"]), ("C", p["C10"])):
        out.update({(X, f"{frame}.w"): -sign * l35 * k, (X, f"motor{i}.w"): sign * l35 * k,
                    (X, f"{frame}.beta"): nose_coef * k, (X, f"motor{i}.beta"): l35**2 * k})
    return out


def test_b210_b211_motor1(th: Printed) -> None:
    """(B.2.10) Vertical - Motor 1 and (B.2.11) Pitch - Motor 1: (l22 K10) β_br, (l35 K10) β_c1;
    (−l35 K10) w_br, (l35 K10) w_c1, (l22 l35 K10) β_br, (l35² K10) β_c1 (damping alike with C10)."""
    l22 = th.nose[1]
    check(th, "motor1.w", _motor_vertical(th, 1, "frame_rear", l22, th.l35))
    check(th, "motor1.beta", _motor_pitch(th, 1, "frame_rear", 1.0, l22 * th.l35))


def test_b215_motor2_b225_b226_motor4_b235_b236_motor6(th: Printed) -> None:
    """(B.2.15) (−l27 K10) β_br; (B.2.25) (l25 K10) β_bf, (−l35 K10) β_c4; (B.2.26) (l35 K10) w_bf,
    (−l35 l25 K10) β_bf; (B.2.35) (−l22 K10) β_bf, (−l35 K10) β_c6; (B.2.36) (l35 l22 K10) β_bf."""
    l35 = th.l35
    check(th, "motor2.w", _motor_vertical(th, 2, "frame_rear", -th.nose[2], l35))
    check(th, "motor4.w", _motor_vertical(th, 4, "frame_front", th.nose[4], -l35))
    check(th, "motor4.beta", _motor_pitch(th, 4, "frame_front", -1.0, -l35 * th.nose[4]))
    check(th, "motor6.w", _motor_vertical(th, 6, "frame_front", -th.nose[6], -l35))
    check(th, "motor6.beta", _motor_pitch(th, 6, "frame_front", -1.0, l35 * th.nose[6]))


def test_b212_longitudinal_motor_wheelset(th: Printed) -> None:
    """(B.2.12) (m_c + m_d) ü_d1 + (2f1/S) u̇_d1 + (2 l20 f1/S) β̇_d1 — the f1 that (4.40) lost is printed
    here; no spring acts in u on the motor/wheelset (the reaction RA1 ties it to the frame)."""
    u_d = "wheelset1.u + motor1.u"
    f1, l20 = th.f1, th.l["l20"]
    check(th, u_d, {("M", u_d): th.body["wheelset1"].mass + th.body["motor1"].mass,
                    ("C", u_d): 2 * f1 / S, ("C", "wheelset1.beta"): 2 * l20 * f1 / S,
                    ("K", u_d): 0.0, ("K", "frame_rear.beta"): 0.0, ("K", "frame_rear.u"): 0.0})
    assert np.all(th.vec(u_d) @ th.mats["K"] == 0.0)


def _track_wheelset(th: Printed, i: int, frame: str, x: float) -> dict:
    """(B.2.13)/(B.2.23)/(B.2.38): (m_d + m_e) ẅ_d + (−2K9) w_b + (2K9 + K_e) w_d + (−2 x K9) β_b + C alike,
    x = the axle's position from the frame CG (thesis: −l24 for wheelset 1, +l23 for 3, +l24 for 6)."""
    p, lt = th.p, th.lt
    damp = p["C17"] + p["C18"] if i not in (2, 5) else 2 * p["C18"]
    w_d = f"wheelset{i}.w + wheelset{i}_track.w"
    return {
        ("M", w_d): th.body[f"wheelset{i}"].mass + lt.m_e_pair,
        ("K", f"{frame}.w"): -2 * p["K9"], ("K", w_d): 2 * p["K9"] + lt.K_e_pair,
        ("K", f"{frame}.beta"): -2 * x * p["K9"],
        ("C", f"{frame}.w"): -damp, ("C", w_d): damp + lt.C_e_pair, ("C", f"{frame}.beta"): -x * damp,
    }


def test_b213_b223_b238_track_wheelset(th: Printed) -> None:
    """(B.2.13) 2(l24 K9) β_br, [l24(C17 + C18)] β̇_br; (B.2.23) (−2 l23 K9) β_br (K_e printed "K3");
    (B.2.38) (−2 l24 K9) β_bf, [l24(−C17 − C18)] β̇_bf."""
    L = th.l
    check(th, "wheelset1.w + wheelset1_track.w", _track_wheelset(th, 1, "frame_rear", -L["l24"]))
    check(th, "wheelset3.w + wheelset3_track.w", _track_wheelset(th, 3, "frame_rear", L["l23"]))
    check(th, "wheelset6.w + wheelset6_track.w", _track_wheelset(th, 6, "frame_front", L["l24"]))


def test_b214_pitch_wheelset(th: Printed) -> None:
    """(B.2.14) +I_dβ β̈_d1 + (2 l20 f1/S) u̇_d1 + (2 l20² f1/S) β̇_d1: the + sign (4.42) lost is printed here."""
    f1, l20 = th.f1, th.l["l20"]
    check(th, "wheelset1.beta", {("M", "wheelset1.beta"): th.body["wheelset1"].inertia[1][1],
                                 ("C", "wheelset1.u + motor1.u"): 2 * l20 * f1 / S,
                                 ("C", "wheelset1.beta"): 2 * l20**2 * f1 / S, ("K", "wheelset1.beta"): 0.0})


def test_elimination_motor_pitch_row() -> None:
    """After (B.2.40): reduced equation 10 = 11 + l34 (10) with w_c1 = w_d1 + l34 β_c1 (rigid track:
    w_d1 = rail profile).  Derived from the printed (B.2.10), (B.2.11): row β_c1 has
    (I_cβ + l34² m_c) β̈_c1, −(l35 + l34) K10 w_br, l22 (l35 + l34) K10 β_br, (l35 + l34)² K10 β_c1, and
    the rail input (l35 + l34) K10 w_rail1 (thesis signs).  Bundled data (random lengths would break
    the exact block decoupling by round-off)."""
    v = load_vehicle("sd40-2")
    L = {k: (t["value"] if isinstance(t, dict) else t)
         for k, t in tomllib.loads(bundled_path("sd40-2").read_text())["lengths"].items()}
    m = v.vertical("rigid", speed=S)
    d = np.array([THESIS_SIGNS[split(c)[1]] for c in m.coordinates])
    K = m.K * np.outer(d, d)
    M = m.M * np.outer(d, d)
    K_in = m.input_matrices()[2] * d[:, None]  # rail.w keeps its sign
    i = m.coordinates.index("motor1.beta")
    col = m.coordinates.index
    k10, lever, l22_th = v.parameter("K10"), L["l22"] + L["l34"], L["l24"] - L["l34"] - L["l22"]
    mc, Ic = v.body("motor1").mass, v.body("motor1").inertia[1][1]
    assert M[i, i] == pytest.approx(Ic + L["l34"] ** 2 * mc, rel=1e-12)
    assert K[i, col("frame_rear.w")] == pytest.approx(-lever * k10, rel=1e-12)
    assert K[i, col("frame_rear.beta")] == pytest.approx(l22_th * lever * k10, rel=1e-12)
    assert K[i, i] == pytest.approx(lever**2 * k10, rel=1e-12)
    assert K_in[i, m.inputs.index("wheelset1_rail.w")] == pytest.approx(lever * k10, rel=1e-12)


def test_dof_27_21_and_the_elimination_list() -> None:
    """The coordinates that remain after the eliminations printed after (B.2.40):
    u_a w_a β_a, u_br w_br β_br, u_bf w_bf β_bf, then per axle β_cj, w_dj, β_dj (27); rigid track drops
    the six w_dj (21).  w_dj is our lumped track body's w (the wheelset rides on it)."""
    v = load_vehicle("sd40-2")
    flex, rigid = v.vertical("flexible", speed=S), v.vertical("rigid", speed=S)
    assert (flex.n_dof, rigid.n_dof) == (27, 21)
    thesis = [f"{b}.{d}" for b in ("body", "frame_rear", "frame_front") for d in ("u", "w", "beta")]
    for j in range(1, 7):
        thesis += [f"motor{j}.beta", f"wheelset{j}_track.w", f"wheelset{j}.beta"]
    assert sorted(flex.coordinates) == sorted(thesis)
    assert sorted(rigid.coordinates) == sorted(c for c in thesis if not c.endswith("_track.w"))
    assert flex.track == "flexible" and rigid.track == "rigid"
