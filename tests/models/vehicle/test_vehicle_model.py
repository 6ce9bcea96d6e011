"""Vehicle models: DOF counts, exact lateral/vertical decoupling, masses, parameters, parametric parts."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.models import ParametricSystem
from railopt.models.vehicle import BUNDLED, LATERAL_DOFS, load_vehicle
from railopt.models.vehicle.geometry import split

LB = 0.45359237  # kg
GRAVITY = 9.80665


@pytest.mark.parametrize(
    ("name", "track", "lateral", "vertical"),
    [
        ("sd40-2", "rigid", 9, 21),  # thesis §4.1: 9 + 21 = 30 on rigid track
        ("sd40-2", "flexible", 15, 27),  # 15 + 27 = 42 with the lumped track
        ("manchester-coach", "rigid", 17, 17),  # 3 + 2×3 + 4×(v, γ) | 3 + 2×3 + 4×(u, β)
        ("manchester-coach", "flexible", 21, 21),
        ("single-wheelset", "rigid", 2, 2),
    ],
)
def test_dof_counts(name: str, track: str, lateral: int, vertical: int) -> None:
    v = load_vehicle(name)
    assert v.lateral(track).n_dof == lateral
    assert v.vertical(track).n_dof == vertical


def test_sd40_coordinates(sd40) -> None:
    frames = [f"{b}.{d}" for b in ("body", "frame_rear", "frame_front") for d in LATERAL_DOFS]
    assert sd40.lateral("rigid").coordinates == tuple(frames)
    track = tuple(f"wheelset{i}_track.alpha" for i in range(1, 7))
    assert sd40.lateral("flexible").coordinates == tuple(frames) + track


@pytest.mark.parametrize("name", ["sd40-2", "manchester-coach"])
@pytest.mark.parametrize("track", ["rigid", "flexible"])
def test_lateral_vertical_decoupling_exact(name: str, track: str) -> None:
    """All coordinates assembled: the (v, α, γ) × (u, w, β) blocks are exactly zero."""
    a = load_vehicle(name).assembly(track)
    lat = np.array([split(c)[1] in LATERAL_DOFS for c in a.coordinates])
    for mat in (a.M, a.K(), a.C(25.0), a.C_creep):
        assert np.all(mat[np.ix_(lat, ~lat)] == 0.0)
        assert np.all(mat[np.ix_(~lat, lat)] == 0.0)
        assert np.any(mat[np.ix_(lat, lat)] != 0.0)
    ind_lat = np.array([split(c)[1] in LATERAL_DOFS for c in a.independent])
    assert np.all(a.T[np.ix_(lat, ~ind_lat)] == 0.0) and np.all(a.T[np.ix_(~lat, ind_lat)] == 0.0)


def test_sd40_masses_add_up_to_total(sd40) -> None:
    """368,000 lb total (SPEC §2.3); about 27.8 t per axle."""
    assert sd40.total_mass == pytest.approx(368_000 * LB, abs=1.0)
    parts = sum(b.mass for b in sd40.bodies if b.name != "body")
    assert sd40.body("body").mass == pytest.approx(368_000 * LB - parts, abs=1.0)
    assert sd40.axle_load() / GRAVITY == pytest.approx(27_820, rel=1e-3)
    assert len(sd40.wheelsets) == 6 and sum(b.name.startswith("motor") for b in sd40.bodies) == 6


def test_sd40_public_geometry(sd40) -> None:
    """Truck centres 13.26 m, axle spacing 2.07 m, r0 = 0.508 m, conicity 0.05."""
    x = {b.name: b.cg[0] for b in sd40.bodies}
    assert x["frame_front"] - x["frame_rear"] == pytest.approx(13.26, abs=0.005)
    assert x["wheelset6"] - x["wheelset4"] == pytest.approx(4.14, abs=1e-9)
    assert x["wheelset5"] - x["wheelset4"] == pytest.approx(2.07, abs=1e-9)
    assert sd40.parameter("wheel_radius") == 0.508 and sd40.parameter("conicity") == 0.05


def test_reduced_matrices_are_projections(sd40) -> None:
    """M_r = Tᵀ M T etc. (B.1.49); reactions vanish since ψ = θ0/(e0 − r0θ0) (4.8)."""
    a = sd40.assembly("rigid")
    model = sd40.lateral("rigid", speed=30.0)
    cols = [a.independent.index(c) for c in model.coordinates]
    T = a.T[:, cols]
    assert np.allclose(model.M, T.T @ a.M @ T, rtol=0, atol=1e-9)
    assert np.allclose(model.K, T.T @ a.K() @ T, rtol=1e-12, atol=1e-6)
    assert np.allclose(model.C, T.T @ a.C(30.0) @ T, rtol=1e-12, atol=1e-6)
    wr = sd40.wheel_rail()
    # the normal-load difference enters the lateral row with θ0 and the roll row with (e0 − r0θ0)
    i_v, i_a = a.coordinates.index("wheelset1.v"), a.coordinates.index("wheelset1.alpha")
    reaction = np.zeros(len(a.coordinates))
    reaction[i_v], reaction[i_a] = -wr.theta0, wr.e0 - wr.r0 * wr.theta0  # our axes: v_th = −v
    assert np.allclose(a.T.T @ reaction, 0.0, atol=1e-15)


def test_speed_scaling_of_creep(sd40) -> None:
    m = sd40.lateral("rigid")
    c10, c20 = m.at_speed(10.0).C, m.at_speed(20.0).C
    assert np.allclose(c10 - m.C_const, 2.0 * (c20 - m.C_const))
    assert np.array_equal(m.at_speed(10.0).K, m.at_speed(20.0).K)


def test_with_parameters_and_parametric(sd40) -> None:
    names = ["K2", "C13", "secondary_lateral_damping"]
    ids = ["K2", "C13", "C2"]
    values = [0.8e6, 200e3, 30e3]
    changed = sd40.with_parameters(dict(zip(names, values, strict=True)))
    assert changed.parameter("K2") == 0.8e6 and sd40.parameter("K2") == 0.5e6  # a copy
    expected = changed.lateral("rigid", speed=25.0)
    base = sd40.lateral("rigid", speed=25.0)
    fast = base.with_values(dict(zip(ids, values, strict=True)))  # no re-assembly
    for attr in ("M", "C", "K"):
        assert np.allclose(getattr(fast, attr), getattr(expected, attr), rtol=1e-12, atol=1e-6)
    ps = base.family(names, outputs=["cab.lateral"])
    assert isinstance(ps, ParametricSystem)
    sys = ps.at(values)
    for attr in ("M", "C", "K"):
        assert np.allclose(getattr(sys, attr), getattr(expected, attr), rtol=1e-12, atol=1e-6)
    assert np.allclose(np.sort_complex(sys.eigenvalues()), np.sort_complex(expected.eigenvalues()))


def test_with_parameters_names_and_errors() -> None:
    sw = load_vehicle("single-wheelset")
    new = sw.with_parameters({"mass": 1800.0, "yaw_inertia": 900.0, "semi_gauge": 0.7, "wheel_radius": 0.5,
                              "conicity": 0.2, "f11": 5e6, "f22": 6e6, "lateral_stiffness": 3e5,
                              "yaw_stiffness": 4e5})
    m = new.lateral(speed=10.0)
    assert np.allclose(np.diag(m.M), [1800.0, 900.0])
    assert m.K[0, 0] == 3e5 and m.K[1, 1] == 4e5
    assert m.K[1, 0] == pytest.approx(2 * 0.7 * 0.2 * 5e6 / 0.5)  # 2 e0 λ f11 / r0
    assert m.C[0, 0] == pytest.approx(2 * 6e6 / 10.0)
    with pytest.raises(ValueError, match="unknown parameter 'stiffnes'.*lateral_stiffness"):
        sw.with_parameters({"stiffnes": 1.0})
    with pytest.raises(ValueError, match="mass"):
        sw.with_parameters({"mass": float("nan")})
    with pytest.raises(ValueError, match="ky"):
        sw.with_parameters({"ky": -1.0})
    with pytest.raises(ValueError, match="unknown parameters"):
        sw.lateral().with_values({"nope": 1.0})


def test_sd40_parameter_names(sd40) -> None:
    names = sd40.parameter_names()
    for n in ("K2", "C17", "secondary_lateral_stiffness", "body.mass", "frame_front.Izz", "conicity",
              "creep_factor", "track_modulus"):
        assert n in names
    soft = sd40.with_parameters({"track_modulus": 10e6})
    assert soft.lumped_track().K_e < sd40.lumped_track().K_e


def test_bundled_names() -> None:
    assert set(BUNDLED) == {"sd40-2", "single-wheelset", "manchester-coach"}
    coach = load_vehicle("manchester-coach")
    assert coach.total_mass == pytest.approx(32_000 + 2 * 2_615 + 4 * 1_813)
    assert coach.parameter("conicity") == 0.15


@pytest.mark.parametrize("name", ["sd40-2", "manchester-coach"])
def test_rail_alignment_input_static_shift(name: str) -> None:
    """Shifting every rail and the whole vehicle laterally by the same amount loads nothing:
    K x + K_in u = 0 with x = unit lateral translation (no spring connects the vehicle to ground)."""
    v = load_vehicle(name)
    m = v.lateral("rigid", speed=20.0)
    M_in, C_in, K_in = m.input_matrices()
    assert K_in.shape == (m.n_dof, len(m.inputs)) and M_in.shape == C_in.shape == K_in.shape
    x = np.array([1.0 if c.endswith(".v") else 0.0 for c in m.coordinates])
    u = np.array([1.0 if c.endswith("_rail.v") else 0.0 for c in m.inputs])
    assert np.any(K_in != 0.0)
    assert np.allclose(m.K @ x + K_in @ u, 0.0, atol=1e-6 * np.abs(m.K).max())


def test_massless_free_coordinate_is_an_error() -> None:
    v = load_vehicle("single-wheelset").with_parameters({"yaw_inertia": 0.0})
    with pytest.raises(ValueError, match="massless independent coordinates \\['wheelset.gamma'\\]"):
        v.lateral()


def test_with_parameters_of_elements_keeps_the_assembly(sd40) -> None:
    base = sd40.assembly("rigid")
    changed = sd40.with_parameters({"K2": 0.9e6, "C15": 3e5})
    a = changed.assembly("rigid")
    assert a.parts["K2"][1] is base.parts["K2"][1]  # no re-assembly
    assert a.values["K2"] == 0.9e6 and base.values["K2"] == 0.5e6
    fresh = load_vehicle("sd40-2").with_parameters({"K2": 0.9e6, "C15": 3e5})
    assert np.allclose(changed.lateral(speed=20.0).K, fresh.lateral(speed=20.0).K)
    assert np.allclose(changed.lateral(speed=20.0).C, fresh.lateral(speed=20.0).C)
