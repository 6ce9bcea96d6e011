"""Vehicle models against closed forms: Klingel, rigid-truck kinematic wavelength, Routh–Hurwitz
critical speed of the restrained wheelset, flexible → rigid track.

Closed forms (our axes, per wheel creep coefficients f11, f22; derivations in docs/vehicle.md):

* free wheelset, rigid creep: ω = S sqrt(λ/(e0 r0)) (Klingel);
* rigid truck, axles at x_i (Σ x_i = 0), rigid creep: L = 2π sqrt(e0 r0/λ · (1 + (f22/f11) <x²>/e0²)),
  <x²> = mean x_i², i.e. 1 + b²/e0² for two axles at ±b and 1 + (2/3) b²/e0² for three at −b, 0, b
  (f11 = f22);
* elastically restrained wheelset: the quartic det[[m s² + a s + k_y, −2 f22], [b, I s² + c s + k_ψ]]
  with a = 2 f22/S, c = 2 e0² f11/S, b = 2 e0 λ f11/r0 is Hurwitz-stable while
  a3 a2 a1 − a4 a1² − a3² a0 > 0; with x = 1/S this boundary gives S_cr and ω_cr² = a1/a3.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from railopt.models.stability import critical_speed
from railopt.models.vehicle import load_vehicle, parse_vehicle

from conftest import routh_hurwitz


def kinematic_root(model, speed: float) -> complex:
    """The oscillatory root with the smallest |s| (the kinematic mode under large creep)."""
    s = model.at_speed(speed).eigenvalues()
    s = s[s.imag > 1e-9]
    return s[np.argmin(np.abs(s))]


def test_klingel_frequency_free_wheelset() -> None:
    v = load_vehicle("single-wheelset").with_parameters({"lateral_stiffness": 0.0, "yaw_stiffness": 0.0})
    lam, r0, e0 = v.parameter("conicity"), v.parameter("wheel_radius"), v.parameter("semi_gauge")
    speed = 30.0
    exact = speed * math.sqrt(lam / (e0 * r0))
    errors = []
    for factor in (1.0, 10.0, 100.0, 1000.0):
        model = v.with_parameters({"creep_factor": factor}).lateral()
        errors.append(abs(kinematic_root(model, speed).imag - exact) / exact)
    assert errors == sorted(errors, reverse=True)  # converges as the creep coefficients grow
    assert errors[-1] < 1e-5
    assert errors[0] < 0.05


def truck_file(n_axles: int, b: float, f11: float, f22: float) -> dict:
    """A rigid truck: frame plus ``n_axles`` wheelsets tied in u, v, γ; no springs; all at one height."""
    xs = np.linspace(-b, b, n_axles) if n_axles > 1 else np.zeros(1)
    bodies = [{"name": "frame", "kind": "body", "mass_kg": 5000.0, "inertia_kg_m2": [3000.0, 8000.0, 9000.0],
               "cg_m": [0, 0, 0.5]}]
    constraints = []
    for i, x in enumerate(xs):
        bodies.append({"name": f"ws{i}", "kind": "wheelset", "mass_kg": 2000.0,
                       "inertia_kg_m2": [1000.0, 200.0, 1000.0], "cg_m": [float(x), 0.0, 0.5]})
        constraints.append({"type": "rigid", "body": f"ws{i}", "to": "frame", "dofs": ["u", "v", "gamma"]})
    return {"vehicle": {"name": "truck"}, "bodies": bodies, "constraints": constraints,
            "contact": {"conicity": 0.05, "wheel_radius_m": 0.5, "semi_gauge_m": 0.75, "f11_N": f11, "f22_N": f22,
                        "spin": False, "gravity_stiffness": False}}


@pytest.mark.parametrize(
    ("n_axles", "b", "f11", "f22"), [(2, 1.25, 1e7, 1e7), (3, 2.07, 1e7, 1e7), (3, 2.07, 1.2e7, 0.9e7)]
)
def test_rigid_truck_kinematic_wavelength(n_axles: int, b: float, f11: float, f22: float) -> None:
    xs = np.linspace(-b, b, n_axles)
    e0, r0, lam = 0.75, 0.5, 0.05
    exact = 2 * math.pi * math.sqrt(e0 * r0 / lam * (1 + (f22 / f11) * np.mean(xs**2) / e0**2))
    if n_axles == 2 and f11 == f22:  # the textbook two-axle form
        assert exact == pytest.approx(2 * math.pi * math.sqrt(r0 * e0 / lam * (1 + b**2 / e0**2)), rel=1e-12)
    speed = 20.0
    truck = parse_vehicle(truck_file(n_axles, b, f11, f22))
    model = truck.with_parameters({"creep_factor": 1e4}).lateral()
    wavelength = 2 * math.pi * speed / kinematic_root(model, speed).imag
    assert wavelength == pytest.approx(exact, rel=1e-4)


@pytest.mark.parametrize(
    "params",
    [
        {},
        {"mass": 1200.0, "yaw_inertia": 500.0, "lateral_stiffness": 2e6, "yaw_stiffness": 5e6, "conicity": 0.2},
        {"mass": 2000.0, "yaw_inertia": 1100.0, "lateral_stiffness": 0.4e6, "yaw_stiffness": 1e6, "f11": 6e6,
         "f22": 7e6, "semi_gauge": 0.7465, "wheel_radius": 0.5},
        {"conicity": 0.05, "f22": 12e6, "yaw_stiffness": 8e6},
    ],
)
def test_single_wheelset_critical_speed_routh_hurwitz(params: dict) -> None:
    v = load_vehicle("single-wheelset").with_parameters(params)
    names = ("mass", "yaw_inertia", "lateral_stiffness", "yaw_stiffness", "f11", "f22", "conicity", "semi_gauge",
             "wheel_radius")
    exact_speed, exact_freq = routh_hurwitz(*(v.parameter(n) for n in names))
    cs = critical_speed(v, "rigid", (1.0, 3.0 * exact_speed), tol=1e-7)
    assert not cs.unstable_at_lower_end
    assert abs(cs.speed - exact_speed) / exact_speed < 1e-6
    assert abs(cs.frequency - exact_freq) / exact_freq < 1e-6
    assert cs.coordinate in ("wheelset.v", "wheelset.gamma")
    assert cs.mode == "wheelset hunting"


def test_flexible_track_converges_to_rigid() -> None:
    v = load_vehicle("sd40-2")
    rigid = v.lateral("rigid", speed=30.0).eigenvalues()
    k0 = v.parameter("track_modulus")
    diffs = []
    for factor in (1e2, 1e4, 1e6):
        flex = v.with_parameters({"track_modulus": k0 * factor}).lateral("flexible", speed=30.0).eigenvalues()
        # every rigid-track root has a flexible-track partner; the 12 extra track roots run away
        diffs.append(max(np.min(np.abs(flex - s)) / abs(s) for s in rigid))
    assert np.sort(np.abs(flex))[-12:].min() > 10 * np.abs(rigid).max()
    assert diffs == sorted(diffs, reverse=True)
    assert diffs[-1] < 1e-5
