"""Forced response to rail irregularities (4.60)–(4.70): closed forms, invariants and a second method.

Independent sources: the base-excited SDOF transmissibility and a quarter-car's invariant points
(derived in the docstrings below), a two-axle vehicle's wheelbase filter, exact symmetry of the
locomotive about its centre, the static limit, the full unreduced system solved with Lagrange
multipliers, and a brute-force frequency sweep for the certified band maximum.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from railopt.models import LinearSystem, ParametricSystem
from railopt.models.sensitivity import maxima_jacobians
from railopt.models.vehicle import (
    PointOutput,
    forced_parametric,
    forced_system,
    frequency_response,
    parse_vehicle,
)
from railopt.models.vehicle.irregularity import Irregularity, RailInput, frequency_hz, wavelength_m

S = 40.0  # m/s
HZ = 2 * np.pi
VERTICAL = Irregularity("vertical", 1.0)
FIGURE_OUTPUTS = ["body.u", "body.w", "body.beta", "frame_rear.w", "frame_front.beta", "motor3.beta",
                  "wheelset3.beta", "wheelset3_track.w"]


def small_vehicle(bodies: list[dict], elements: list[dict]) -> dict:
    """A vehicle file (as a dict) on one or more wheelsets; creep given, no gravity stiffness."""
    return {
        "vehicle": {"name": "test"},
        "bodies": bodies,
        "elements": elements,
        "contact": {"conicity": 0.1, "wheel_radius_m": 0.45, "semi_gauge_m": 0.75, "theta0": 0.0, "creep": "given",
                    "f11_N": 1.0e7, "f22_N": 9.0e6, "spin": False, "gravity_stiffness": False},
    }


def body(name: str, mass: float, x: float = 0.0, z: float = 1.5, kind: str = "body") -> dict:
    return {"name": name, "kind": kind, "mass_kg": mass, "inertia_kg_m2": [0.3 * mass, 0.5 * mass, 0.5 * mass],
            "cg_m": [x, 0.0, z]}


def link(eid: str, kind: str, a: str, b: str, value: float, xa: float = 0.0, xb: float = 0.0) -> dict:
    key = "stiffness_N_per_m" if kind == "spring" else "damping_N_s_per_m"
    return {"id": eid, "type": kind, "body_a": a, "point_a_m": [xa, 0.0, 0.0], "body_b": b,
            "point_b_m": [xb, 0.0, 0.0], "direction": [0.0, 0.0, 1.0], key: value}


# ---------------------------------------------------------------------------------------------- closed forms
def test_sdof_base_excited_transmissibility() -> None:
    """Mass m on k, c over a wheelset that follows the profile: m ẅ + c(ẇ − ε̇) + k(w − ε) = 0 ⇒
    w/ε = (k + iΩc)/(k − mΩ² + iΩc) (displacement); velocity and acceleration outputs are (iΩ)^q times
    it (per metre of profile)."""
    m, k, c = 2000.0, 8.0e5, 6.0e3
    v = parse_vehicle(small_vehicle([body("body", m), body("wheelset", 1000.0, z=0.45, kind="wheelset")],
                                    [link("k", "spring", "body", "wheelset", k), link("c", "damper", "body",
                                                                                      "wheelset", c)]))
    model = v.vertical("rigid", speed=S)
    f = np.array([0.05, 0.5, 1.0, np.sqrt(k / m) / HZ, 3.0, 7.5, 30.0])
    w = HZ * f
    T = (k + 1j * w * c) / (k - m * w**2 + 1j * w * c)
    for q, quantity in enumerate(("displacement", "velocity", "acceleration")):
        df = model.frequency_response(f, VERTICAL, ["body.w"], quantity=quantity)
        H = df["real"].to_numpy() + 1j * df["imag"].to_numpy()
        assert np.max(np.abs(H - (1j * w) ** q * T) / np.abs((1j * w) ** q * T)) < 1e-12
    sys = model.forced_system(VERTICAL, ["body.w"])
    peak = sys.response_maxima(band_rad_s=(0.1 * HZ, 10 * HZ), exact=True)
    zeta = c / (2 * np.sqrt(k * m))  # closed-form peak of |T|: at r² = (√(1 + 8ζ²) − 1)/(4ζ²)
    r2 = (np.sqrt(1 + 8 * zeta**2) - 1) / (4 * zeta**2)
    t_peak = np.sqrt((1 + 4 * zeta**2 * r2) / ((1 - r2) ** 2 + 4 * zeta**2 * r2))
    assert peak.certified and peak.value == pytest.approx(t_peak, rel=1e-9)


def quarter_car(ms: float, mu: float, ks: float, c: float, kt: float):
    """Sprung mass ms on (ks, c) over an unsprung frame mu on a spring kt over the wheelset."""
    return parse_vehicle(small_vehicle(
        [body("body", ms, z=2.0), body("frame", mu, z=1.0), body("wheelset", 1000.0, z=0.45, kind="wheelset")],
        [link("ks", "spring", "body", "frame", ks), link("cs", "damper", "body", "frame", c),
         link("kt", "spring", "frame", "wheelset", kt)]))


def test_quarter_car_invariant_points() -> None:
    """H = z_s/ε = kt g / [g (kt − MΩ²) − msΩ² (kt − muΩ²)], g = ks + iΩc, M = ms + mu (derived from
    the two equations of motion).  H = (A + iΩcB)/(P + iΩcQ) with A, B, P, Q real, so |H| is independent
    of c exactly where |A/P| = |B/Q|, i.e. |H(c = 0)| = |H(c = ∞)| = |kt/(kt − MΩ²)|:
    H0 = −H∞ ⇔ ms mu Ω⁴ − (ms kt + 2 ks M) Ω² + 2 ks kt = 0 (two points), and H0 = H∞ at Ω² = kt/mu
    (|H| = mu/ms).  Every damping passes through these three points."""
    ms, mu, ks, kt = 8000.0, 1200.0, 3.0e5, 4.0e6
    M = ms + mu
    roots = np.sort(np.roots([ms * mu, -(ms * kt + 2 * ks * M), 2 * ks * kt]).real)
    omegas = np.r_[np.sqrt(roots), np.sqrt(kt / mu)]
    expected = np.abs(kt / (kt - M * omegas**2))
    assert expected[2] == pytest.approx(mu / ms, rel=1e-12)
    values = []
    for c in (2e3, 1.5e4, 6e4, 3e5):
        model = quarter_car(ms, mu, ks, c, kt).vertical("rigid", speed=S)
        df = model.frequency_response(omegas / HZ, VERTICAL, ["body.w"])
        values.append(df["amplitude"].to_numpy())
        g = ks + 1j * omegas * c  # the closed form at this c too
        H = kt * g / (g * (kt - M * omegas**2) - ms * omegas**2 * (kt - mu * omegas**2))
        assert np.allclose(df["amplitude"], np.abs(H), rtol=1e-11)
    assert np.max(np.abs(np.array(values) / expected - 1.0)) < 1e-10


def test_two_axle_wheelbase_filter() -> None:
    """A body (m, I) on springs and dampers (k, c) at x = ±b over two wheelsets at ±b, running at S: the
    front axle sees ε, the rear ε e^{−iΩτ}, τ = 2b/S.  Split into ε_s = (1 + e^{−iΩτ})/2 (both axles alike)
    and ε_a = (1 − e^{−iΩτ})/2 (front up, rear down).  Bounce: w = T_b ε_s, T_b = (2k + 2iΩc)/(2k − mΩ² +
    2iΩc).  Pitch: the front point moves w − bβ (our β, nose down positive), so −bβ = T_p ε_a with
    T_p = (2kb² + 2iΩcb²)/(2kb² − IΩ² + 2iΩcb²)."""
    m, inertia, k, c, b = 20000.0, 0.5 * 20000.0, 1.0e6, 1.2e4, 4.0
    bodies = [body("body", m), body("ws_rear", 1000.0, x=-b, z=0.45, kind="wheelset"),
              body("ws_front", 1000.0, x=b, z=0.45, kind="wheelset")]
    elements = [link("k", "spring", "body", "ws_rear", k, xa=-b), link("c", "damper", "body", "ws_rear", c, xa=-b),
                link("k", "spring", "body", "ws_front", k, xa=b), link("c", "damper", "body", "ws_front", c, xa=b)]
    model = parse_vehicle(small_vehicle(bodies, elements)).vertical("rigid", speed=S)
    f = np.linspace(0.2, 12.0, 37)
    w = HZ * f
    tau = 2 * b / S
    df = model.frequency_response(f, VERTICAL, ["body.w", "body.beta"])
    H = (df["real"] + 1j * df["imag"]).to_numpy().reshape(2, -1)
    Tb = (2 * k + 2j * w * c) / (2 * k - m * w**2 + 2j * w * c)
    Tp = (2 * k * b**2 + 2j * w * c * b**2) / (2 * k * b**2 - inertia * w**2 + 2j * w * c * b**2)
    eps_s, eps_a = (1 + np.exp(-1j * w * tau)) / 2, (1 - np.exp(-1j * w * tau)) / 2
    assert np.allclose(H[0], Tb * eps_s, rtol=1e-11, atol=1e-14)
    assert np.allclose(-b * H[1], Tp * eps_a, rtol=1e-11, atol=1e-14)
    # the wavelength filter: no bounce where the wheelbase 2b is an odd number of half wavelengths
    f_null = S / (2 * (2 * b))  # L = 2·(2b)
    null = model.frequency_response([f_null], VERTICAL, ["body.w"])["amplitude"].iloc[0]
    assert null < 1e-12
    assert wavelength_m(f_null, S) == pytest.approx(4 * b) and frequency_hz(4 * b, S) == pytest.approx(f_null)


# ---------------------------------------------------------------------------------------------- locomotive physics
@pytest.mark.parametrize("track", ["rigid", "flexible"])
def test_long_wavelength_moves_the_whole_vehicle(sd40, track: str) -> None:
    """In-phase vertical profile, wavelength L = S/f → ∞: body and frames follow it (transmissibility → 1,
    phase → −Ω x_lead/S, the profile's phase at the body centre); pitches follow the profile's slope,
    |β| → k = 2π/L → 0; the lumped track does not deflect (the irregularity sits on the rail head)."""
    model = sd40.vertical(track, speed=S)
    outs = ["body.w", "frame_rear.w", "frame_front.w", "body.beta", "frame_front.beta", "body.u"]
    if track == "flexible":
        outs.append("wheelset3_track.w")
    lead = sd40.body("wheelset6").cg[0]
    for f, tol, rel in ((1e-3, 1e-5, 1e-2), (1e-5, 1e-9, 1e-6)):
        df = model.frequency_response([f], VERTICAL, outs).set_index("output")
        k = HZ * f / S
        centre = np.exp(-1j * HZ * f * lead / S)
        for o in ("body.w",):
            got = df.loc[o, "real"] + 1j * df.loc[o, "imag"]
            assert abs(got - centre) < tol
        for o in ("frame_rear.w", "frame_front.w"):
            assert abs(df.loc[o, "amplitude"] - 1.0) < tol
        for o in ("body.beta", "frame_front.beta"):
            assert df.loc[o, "amplitude"] == pytest.approx(k, rel=rel)
        assert df.loc["body.u", "amplitude"] < k
        if track == "flexible":
            assert df.loc["wheelset3_track.w", "amplitude"] < tol


def _axle_terms(model, amplitudes: np.ndarray) -> RailInput:
    inputs = model.inputs
    terms = []
    for j, a in enumerate(amplitudes, start=1):
        u = np.zeros(len(inputs))
        u[inputs.index(f"wheelset{j}_rail.w")] = a
        terms.append((u, 0.0))
    return RailInput(inputs, tuple(terms), "synchronous axles")


@pytest.mark.parametrize("track", ["rigid", "flexible"])
def test_symmetric_input_no_pitch_antisymmetric_no_bounce(sd40, track: str) -> None:
    """The locomotive is mirror-symmetric about x = 0 (x → −x: u, β odd; w even).  Axle inputs with
    a_i = a_{7−i} excite no body pitch and no body fore-aft motion; a_i = −a_{7−i} no body bounce."""
    model = sd40.vertical(track, speed=S)
    rng = np.random.default_rng(5)
    half = rng.uniform(0.3, 1.0, 3)
    f = np.linspace(0.1, 80.0, 60)
    sym = model.frequency_response(f, _axle_terms(model, np.r_[half, half[::-1]]), ["body.w", "body.beta", "body.u"])
    anti = model.frequency_response(f, _axle_terms(model, np.r_[half, -half[::-1]]), ["body.w", "body.beta"])
    a = {o: g["amplitude"].to_numpy() for o, g in sym.groupby("output")}
    b = {o: g["amplitude"].to_numpy() for o, g in anti.groupby("output")}
    assert np.max(a["body.beta"] / a["body.w"]) < 1e-12 and np.max(a["body.u"] / a["body.w"]) < 1e-12
    assert np.max(b["body.w"] / b["body.beta"]) < 1e-10  # β in rad/m vs w in m/m: ratio of scales ~10
    assert np.min(a["body.w"][:10]) > 1e-3 and np.min(b["body.beta"][:10]) > 1e-4


def test_flexible_converges_to_rigid(sd40) -> None:
    """Track modulus ×10^2, 10^4, 10^6: the flexible-track FRFs approach the rigid-track ones."""
    f = np.geomspace(0.1, 30.0, 80)
    outs = ["body.w", "body.beta", "frame_front.beta", "motor3.beta", "wheelset3.beta"]
    rigid = sd40.vertical("rigid", speed=S).frequency_response(f, VERTICAL, outs)
    H0 = (rigid["real"] + 1j * rigid["imag"]).to_numpy()
    errors = []
    for factor in (1.0, 1e2, 1e4, 1e6):
        stiff = sd40.with_parameters({"track_modulus": sd40.parameter("track_modulus") * factor})
        flex = stiff.vertical("flexible", speed=S).frequency_response(f, VERTICAL, outs)
        H = (flex["real"] + 1j * flex["imag"]).to_numpy()
        errors.append(np.max(np.abs(H - H0)) / np.max(np.abs(H0)))
    assert errors[0] > 1e-2  # the real track matters (motors and wheelsets)
    assert all(e1 < 0.2 * e0 for e0, e1 in zip(errors, errors[1:], strict=False))
    assert errors[-1] < 1e-4


@pytest.mark.parametrize("track", ["rigid", "flexible"])
def test_residual_below_1e_10(sd40, track: str) -> None:
    """‖Z X − F‖∞/‖F‖∞ at every frequency computed (vertical 0.02–80 Hz, lateral alignment 0.02–20 Hz)."""
    f = np.linspace(0.02, 80.0, 800)
    df = sd40.vertical(track, speed=S).frequency_response(f, VERTICAL, FIGURE_OUTPUTS)
    assert df["residual"].max() < 1e-10
    lat = sd40.lateral(track, speed=S).frequency_response(f[:200], Irregularity("alignment", 0.01),
                                                         ["body.v", "body.alpha", "body.gamma", "cab.lateral"])
    assert lat["residual"].max() < 1e-10


@pytest.mark.parametrize("track", ["rigid", "flexible"])
def test_unreduced_system_with_multipliers(sd40, track: str) -> None:
    """Second method: all 6-per-body coordinates z (both blocks, inputs included) with Lagrange
    multipliers — [Z_z Gᵀ E; G 0 0; Eᵀ 0 0] [z; λ; μ] = [0; 0; u] with G spanning the constraints
    (G [T T_in] = 0) and E selecting the prescribed rail coordinates — against the reduced solve."""
    a = sd40.assembly(track)
    model = sd40.vertical(track, speed=S)
    nz = len(a.coordinates)
    TT = np.hstack([a.T, a.T_in])
    _, sv, vt = np.linalg.svd(TT.T)
    G = vt[np.sum(sv > 1e-10 * sv[0]):]  # rows orthogonal to the admissible motions
    E = np.zeros((nz, len(a.inputs)))
    for j, name in enumerate(a.inputs):
        E[a.coordinates.index(name), j] = 1.0
    K, C = a.K(), a.C(S)
    outs = ["body.w", "body.beta", "body.u", "motor3.beta", "wheelset3.w", "frame_front.beta"]
    for f in (0.3, 2.0, 7.0, 62.0):
        w = HZ * f
        Zz = K - w**2 * a.M + 1j * w * C
        # profile delayed at each axle: u_j = e^{−iΩτ_j} on <ws>_rail.w
        xs = {b.name: b.cg[0] for b in sd40.wheelsets}
        lead = max(xs.values())
        u = np.zeros(len(a.inputs), dtype=complex)
        for name, x in xs.items():
            u[a.inputs.index(f"{name}_rail.w")] = np.exp(-1j * w * (lead - x) / S)
        ng, nu = G.shape[0], len(a.inputs)
        A = np.block([[Zz, G.T, E], [G, np.zeros((ng, ng + nu))], [E.T, np.zeros((nu, ng + nu))]])
        rhs = np.r_[np.zeros(nz + ng), u]
        z = np.linalg.solve(A, rhs)[:nz]
        df = model.frequency_response([f], VERTICAL, outs).set_index("output")
        for o in outs:
            got = df.loc[o, "real"] + 1j * df.loc[o, "imag"]
            assert abs(got - z[a.coordinates.index(o)]) <= 1e-9 * max(abs(got), 1e-6), (track, f, o)


def brute_force_peak(sys: LinearSystem, band: tuple[float, float], output: str, points: int = 20_001) -> float:
    """A uniform sweep by direct solves (chunked), every local maximum refined by scipy's bounded Brent."""
    w = np.linspace(*band, points)
    a = np.concatenate([np.abs(sys.frf(omega_rad_s=w[i:i + 2000], output=output)) for i in range(0, points, 2000)])
    best = max(a[0], a[-1])
    for k in np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1:
        r = minimize_scalar(lambda x: -abs(sys.frf(omega_rad_s=x, output=output)), bounds=(w[k - 1], w[k + 1]),
                            method="bounded",
                            options={"xatol": 1e-12})
        best = max(best, -r.fun, a[k])
    return float(best)


@pytest.mark.parametrize("track", ["rigid", "flexible"])
def test_certified_peak_equals_brute_force(sd40, track: str) -> None:
    """The forcing declares one delay per axle, so the exact band maximum is certified and equals a
    brute-force sweep (the wheelbase filter makes more local maxima than modes)."""
    sys = sd40.vertical(track, speed=S).forced_system(VERTICAL, ["body.w", "motor3.beta"])
    assert sys.forcing.declared and sys.forcing.max_delay == pytest.approx(2 * (6.629 + 2.07) / S)
    band = (0.1 * HZ, 8.0 * HZ)
    for out in ("body.w", "motor3.beta"):
        rm = sys.response_maxima(band_rad_s=band, exact=True, output=out)
        assert rm.certified
        assert rm.value == pytest.approx(brute_force_peak(sys, band, out), rel=1e-8)


# ---------------------------------------------------------------------------------------------- API
def test_outputs_points_dependent_and_rigid_track(sd40) -> None:
    """Body points by offset (the cab point), dependent coordinates with the direct input term
    (wheelset 3 follows the profile exactly on rigid track, phase −Ωτ3), the rigid track's zero row."""
    f = np.array([0.7, 3.0, 11.0])
    rigid = sd40.vertical("rigid", speed=S)
    df = rigid.frequency_response(f, VERTICAL, ["cab.vertical", "body[8.5,-0.7,1.2].z", "wheelset3.w",
                                                "wheelset3_track.w",
                                                PointOutput("body", (8.5, -0.7, 1.2), (0.0, 0.0, 2.0), "p")])
    g = {o: (x["real"] + 1j * x["imag"]).to_numpy() for o, x in df.groupby("output")}
    same = frequency_response(rigid, f, VERTICAL, "cab.vertical")  # the free function behind the method
    assert np.array_equal(same["amplitude"], df[df["output"] == "cab.vertical"]["amplitude"])
    assert np.allclose(g["cab.vertical"], g["body[8.5,-0.7,1.2].z"], rtol=1e-14, atol=0)
    assert np.allclose(g["cab.vertical"], g["p"], rtol=1e-14, atol=0)
    tau3 = (sd40.body("wheelset6").cg[0] - sd40.body("wheelset3").cg[0]) / S
    assert np.allclose(g["wheelset3.w"], np.exp(-1j * HZ * f * tau3), rtol=1e-13)
    assert np.all(g["wheelset3_track.w"] == 0.0)
    flex = sd40.vertical("flexible", speed=S).frequency_response(f, VERTICAL, ["wheelset3.w", "wheelset3_track.w"])
    h = {o: (x["real"] + 1j * x["imag"]).to_numpy() for o, x in flex.groupby("output")}
    assert np.allclose(h["wheelset3.w"], h["wheelset3_track.w"] + np.exp(-1j * HZ * f * tau3), rtol=1e-13)  # (4.66)
    assert set(df.columns) >= {"frequency_hz", "output", "amplitude", "phase_deg", "track", "speed_m_s"}
    assert (df["track"] == "rigid").all() and (df["speed_m_s"] == S).all()


def test_lateral_alignment_long_wavelength(sd40) -> None:
    """In-phase alignment of long wavelength shifts the whole vehicle sideways (lateral → 1, roll and yaw → 0);
    the cab's lateral acceleration is the profile's −Ω² at low frequency."""
    for track in ("rigid", "flexible"):
        model = sd40.lateral(track, speed=S)
        df = model.frequency_response([1e-4], Irregularity("alignment", 1.0),
                                      ["body.v", "cab.lateral", "body.alpha", "body.gamma"]).set_index("output")
        assert df.loc["body.v", "real"] == pytest.approx(1.0, abs=1e-5)
        assert df.loc["cab.lateral", "real"] == pytest.approx(1.0, abs=1e-5)
        assert df.loc["body.alpha", "amplitude"] < 1e-7  # roll → 0
        assert df.loc["body.gamma", "amplitude"] == pytest.approx(HZ * 1e-4 / S, rel=1e-3)  # yaw = slope k → 0
    acc = sd40.lateral("rigid", speed=S).frequency_response([1e-3], Irregularity("alignment", 0.00635),
                                                            ["cab.lateral"], quantity="acceleration")
    assert acc["amplitude"].iloc[0] == pytest.approx(0.00635 * (HZ * 1e-3) ** 2, rel=1e-3)
    cross = sd40.lateral("rigid", speed=S).frequency_response([1e-4], Irregularity("cross_level", 0.01),
                                                              ["body.alpha"])
    assert cross["amplitude"].iloc[0] > 0  # the rail roll a/e0 tilts the vehicle


def test_parametric_matches_forced_system(sd40) -> None:
    """forced_parametric(...).at(p) is forced_system at those values (stiffness, damping and their share of
    the input matrices), and its peak Jacobian agrees with central differences."""
    model = sd40.vertical("flexible", speed=S)
    names = ["primary_vertical_stiffness", "C17", "C18", "K10"]
    ps = forced_parametric(model, VERTICAL, names, ["body.w", "motor3.beta"])
    assert isinstance(ps, ParametricSystem)
    p = np.array([3.1e6, 2.0e4, 2.0e4, 4.0e6])
    ref = forced_system(model.with_values(dict(zip(names, p, strict=True))), VERTICAL, ["body.w", "motor3.beta"])
    w = HZ * np.linspace(0.2, 70.0, 50)
    assert np.allclose(ps.at(p).frf_outputs(omega_rad_s=w), ref.frf_outputs(omega_rad_s=w), rtol=1e-11, atol=1e-15)
    band = (0.2 * HZ, 8.0 * HZ)
    sys = ps.at(p)
    (rm, J), = maxima_jacobians(sys, band_rad_s=band, exact=True, outputs=["body.w"]).values()
    k = int(np.argmax(rm.values))
    for i in range(len(names)):
        h = 1e-4 * p[i]
        up, dn = p.copy(), p.copy()
        up[i] += h
        dn[i] -= h
        fd = ps.at(up).peak(band_rad_s=band, output="body.w") - ps.at(dn).peak(band_rad_s=band, output="body.w")
        fd /= 2 * h
        assert J[k, i] == pytest.approx(fd, rel=2e-4, abs=1e-6 * rm.value / p[i])


def test_errors_name_the_item(sd40) -> None:
    model = sd40.vertical("rigid", speed=S)
    with pytest.raises(ValueError, match="outputs: unknown output 'body.wiggle'"):
        model.frequency_response([1.0], VERTICAL, ["body.wiggle"])
    with pytest.raises(ValueError, match="outputs: 'body.v' is not a coordinate of this block"):
        model.frequency_response([1.0], VERTICAL, ["body.v"])
    with pytest.raises(ValueError, match="frequencies_hz: empty"):
        model.frequency_response([], VERTICAL, ["body.w"])
    with pytest.raises(ValueError, match="frequencies_hz: must be finite and > 0"):
        model.frequency_response([0.0, 1.0], VERTICAL, ["body.w"])
    with pytest.raises(ValueError, match="speed"):
        sd40.vertical("rigid", speed=-3.0)
    with pytest.raises(ValueError, match="speed"):
        sd40.vertical("rigid").frequency_response([1.0], VERTICAL, ["body.w"])
    with pytest.raises(ValueError, match="speed"):
        Irregularity("vertical").rail_input(model.inputs, [("wheelset1", 0.0)], 0.0, 0.75)
    with pytest.raises(ValueError, match="input: a alignment in_phase irregularity needs the input"):
        model.frequency_response([1.0], Irregularity("alignment"), ["body.w"])
    with pytest.raises(ValueError, match="input.amplitude_m"):
        Irregularity("vertical", -1.0)
    with pytest.raises(ValueError, match="input.kind"):
        Irregularity("twist")
    with pytest.raises(ValueError, match="input.rails"):
        Irregularity("alignment", rails="out_of_phase")
    with pytest.raises(ValueError, match="input.rails: lateral rail motion is modelled in phase"):
        Irregularity("lateral", rails="out_of_phase")
    with pytest.raises(ValueError, match="input: a cross_level out_of_phase irregularity needs the input"):
        sd40.lateral("flexible", speed=S).frequency_response([1.0], Irregularity("cross_level"), ["body.v"])
    with pytest.raises(ValueError, match="subtracts rad from m"):
        model.frequency_response([1.0], VERTICAL, ["body.w - body.beta"])
    with pytest.raises(ValueError, match="quantity"):
        model.frequency_response([1.0], VERTICAL, ["body.w"], quantity="jerk")
    with pytest.raises(ValueError, match="outputs: at least one"):
        model.frequency_response([1.0], VERTICAL, [])
    with pytest.raises(ValueError, match="unknown body 'cab'"):
        model.frequency_response([1.0], VERTICAL, ["cab[0,0,0].z"])


def test_fixed_wavelength_sweep_runs_each_frequency_at_its_speed(sd40) -> None:
    """The thesis's sweep: a fixed wavelength L (11.89 m, 39 ft rails), f = S/L reached by the speed; each row
    equals the fixed-speed solve at S = f L (creep damping C_creep/S and delays d/S change, phases 2πd/L don't)."""
    L = 39 * 0.3048
    f = np.array([0.5, 2.2, 6.0])
    thesis = Irregularity("vertical", 0.00635, wavelength_m=L)
    model = sd40.vertical("flexible")  # no speed needed: each frequency sets its own
    df = model.frequency_response(f, thesis, ["body.w", "motor3.beta"])
    assert np.allclose(df["speed_m_s"], np.tile(f * L, 2)) and np.allclose(df["wavelength_m"], L)
    for fi in f:
        ref = sd40.vertical("flexible", speed=fi * L).frequency_response([fi], Irregularity("vertical", 0.00635),
                                                                         ["body.w", "motor3.beta"])
        got = df[df["frequency_hz"] == fi]
        assert np.allclose(got["real"].to_numpy(), ref["real"].to_numpy(), rtol=1e-13, atol=0)
        assert np.allclose(got["imag"].to_numpy(), ref["imag"].to_numpy(), rtol=1e-13, atol=0)
    with pytest.raises(ValueError, match="input.wavelength_m: a fixed wavelength"):
        sd40.vertical("flexible", speed=S).forced_system(thesis, ["body.w"])


@pytest.mark.parametrize("track", ["rigid", "flexible"])
def test_outputs_with_the_input_itself_feedthrough(sd40, track: str) -> None:
    """Outputs containing the rail input (a wheelset on the profile, a primary-suspension stroke) become
    LinearSystem outputs with a delayed feedthrough d(Ω): the system's FRF equals the table's, and on rigid
    track wheelset 3 follows the profile exactly (|H| = 1, certified peak 1)."""
    model = sd40.vertical(track, speed=S)
    stroke = "frame_rear[2.07,1.0,-0.25].z - wheelset3.w"  # primary spring of wheelset 3, left side
    outs = ["wheelset3.w", stroke, "body.w"]
    sys = model.forced_system(VERTICAL, outs)
    f = np.linspace(0.1, 70.0, 200)
    H = sys.frf_outputs(omega_rad_s=HZ * f)
    df = model.frequency_response(f, VERTICAL, outs)
    for j, o in enumerate(outs):
        d = df[df["output"] == o]
        assert np.allclose(H[:, j], d["real"] + 1j * d["imag"], rtol=1e-12, atol=1e-15)
    # the stroke is the frame point minus the wheelset: (frame.w − 2.07·β_frame) − wheelset3.w (our β)
    parts = model.frequency_response(f, VERTICAL, ["frame_rear.w", "frame_rear.beta", "wheelset3.w"])
    p = {o: (g["real"] + 1j * g["imag"]).to_numpy() for o, g in parts.groupby("output")}
    assert np.allclose(H[:, 1], p["frame_rear.w"] - 2.07 * p["frame_rear.beta"] - p["wheelset3.w"], rtol=1e-12)
    rm = sys.response_maxima(band_rad_s=(0.1 * HZ, 8 * HZ), exact=True, output="wheelset3.w")
    assert rm.certified
    if track == "rigid":
        assert np.allclose(np.abs(H[:, 0]), 1.0, rtol=1e-14) and rm.value == pytest.approx(1.0, rel=1e-14)
