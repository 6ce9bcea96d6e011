"""Stability as a design quantity (issue 14, SPEC §2.4–2.5): no steady state for an unstable system,
root and critical-speed gradients against central differences and the Routh–Hurwitz closed form, mode names."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.models import ParameterPart, ParametricSystem
from railopt.models.sensitivity import root_jacobian, root_speed_derivative
from railopt.models.stability import critical_speed, critical_speed_gradient, modes, root_locus
from railopt.models.stability_rows import damping_constraints, root_constraints
from railopt.models.vehicle import Irregularity, load_vehicle

from conftest import routh_hurwitz

WHEELSET = dict(m=1500.0, iz=700.0, ky=1e6, kpsi=2e6, f11=10e6, f22=9e6, lam=0.1, e0=0.75, r0=0.45)


def wheelset_family(m, iz, ky, kpsi, f11, f22, lam, e0, r0) -> ParametricSystem:
    return ParametricSystem(
        np.diag([m, iz]), np.zeros((2, 2)), np.array([[0.0, -2 * f22], [2 * f11 * e0 * lam / r0, 0.0]]),
        parts={"ky": ParameterPart(K=np.diag([1.0, 0.0])), "kpsi": ParameterPart(K=np.diag([0.0, 1.0]))},
        C_speed=np.diag([2 * f22, 2 * f11 * e0**2]), values=[ky, kpsi], names=("wheelset.v", "wheelset.gamma"))


def matched(s_ref: np.ndarray, s: np.ndarray) -> np.ndarray:
    """``s`` reordered to the nearest root of ``s_ref`` (FD steps move roots a little)."""
    return np.array([s[np.argmin(np.abs(s - r))] for r in s_ref])


def test_an_unstable_system_has_no_certified_maximum() -> None:
    """The coach above its critical speed: no steady state, so no number is certified (issue 14 finding 2)."""
    system = load_vehicle("manchester-coach").lateral("rigid", 100.0).forced_system(
        Irregularity("alignment", amplitude_m=0.001), ["cab.lateral"], quantity="acceleration")
    for exact in (True, False):
        rm = system.response_maxima(band_rad_s=(1.2566, 62.83), exact=exact)
        assert not rm.certified
        assert rm.value == np.inf and np.all(np.isinf(rm.values))
        assert rm.reason.startswith("unstable: root s = 3.04") and "no steady-state response" in rm.reason
    assert system.peak(band_rad_s=(1.2566, 62.83)) == np.inf
    table = load_vehicle("manchester-coach").lateral("rigid", 100.0).frequency_response(
        [1.0, 2.0], Irregularity("alignment", amplitude_m=0.001), ["cab.lateral"])
    assert not table["steady_state"].any()
    stable = load_vehicle("manchester-coach").lateral("rigid", 50.0).frequency_response(
        [1.0, 2.0], Irregularity("alignment", amplitude_m=0.001), ["cab.lateral"])
    assert stable["steady_state"].all()


@pytest.mark.parametrize("vehicle", ["sd40-2", "single-wheelset"])
def test_root_and_speed_derivatives_equal_central_differences(vehicle: str) -> None:
    view = load_vehicle(vehicle).lateral("rigid")
    names = list(view.parts)
    family = view.family(names)
    p0, S = family.values, 25.0
    system = family.at(p0, speed=S)
    s0 = system.modal().s
    keep = np.abs(s0) > 1e-6 * np.max(np.abs(s0))
    J = root_jacobian(system)
    for i in range(len(names)):
        h = 1e-4 * max(abs(p0[i]), 1.0)  # central differences: truncation ~1e-8, rounding of the roots ~1e-12
        up, down = p0.copy(), p0.copy()
        up[i] += h
        down[i] -= h
        fd = (matched(s0, family.at(up, speed=S).eigenvalues()) - matched(s0, family.at(down, speed=S).eigenvalues()))
        fd /= 2 * h
        scale = np.max(np.abs(fd[keep])) + 1e-12
        assert np.max(np.abs(J[keep, i] - fd[keep])) <= 1e-6 * scale, names[i]
    dS = root_speed_derivative(system)
    h = 1e-5 * S
    fd = (matched(s0, family.at(p0, speed=S + h).eigenvalues()) - matched(s0, family.at(p0, speed=S - h).eigenvalues()))
    fd /= 2 * h
    assert np.max(np.abs(dS[keep] - fd[keep])) <= 1e-6 * np.max(np.abs(fd[keep]))


def test_critical_speed_gradient_equals_the_routh_hurwitz_derivative() -> None:
    family = wheelset_family(**WHEELSET)
    cs, grad = critical_speed_gradient(family, speed_range=(1.0, 200.0), tol=1e-9)
    assert cs.speed == pytest.approx(routh_hurwitz(**WHEELSET)[0], rel=1e-9)
    for i, name in enumerate(("ky", "kpsi")):
        h = 1e-5 * WHEELSET[name]
        exact = (routh_hurwitz(**(WHEELSET | {name: WHEELSET[name] + h}))[0]
                 - routh_hurwitz(**(WHEELSET | {name: WHEELSET[name] - h}))[0]) / (2 * h)
        assert grad[i] == pytest.approx(exact, rel=1e-6)


def test_critical_speed_gradient_of_the_locomotive_equals_central_differences() -> None:
    view = load_vehicle("sd40-2").lateral("rigid")
    names = ["K2", "K3", "C13", "C15"]
    family = view.family(names)
    p0 = family.values
    cs, grad = critical_speed_gradient(family, speed_range=(5.0, 60.0), tol=1e-10, grid=12)
    assert 30.0 < cs.speed < 40.0
    for i in range(len(names)):
        h = 1e-4 * p0[i]
        up, down = p0.copy(), p0.copy()
        up[i] += h
        down[i] -= h
        vu = critical_speed(family.with_values(up), speed_range=(5.0, 60.0), tol=1e-11, grid=12).speed
        vd = critical_speed(family.with_values(down), speed_range=(5.0, 60.0), tol=1e-11, grid=12).speed
        fd = (vu - vd) / (2 * h)
        assert grad[i] == pytest.approx(fd, rel=1e-6, abs=1e-6 * np.max(np.abs(grad))), names[i]


@pytest.mark.parametrize("rows", [root_constraints, damping_constraints])
def test_stability_constraint_rows_and_their_gradients(rows) -> None:
    family = load_vehicle("sd40-2").lateral("flexible").family(["K2", "C13"])
    speeds = [10.0, 25.0]
    kwargs = {"sigma_min": 0.05} if rows is root_constraints else {"zeta_min": 0.05}
    p0 = family.values
    g, J = rows(family, p0, speeds, **kwargs)
    assert len(g) == 2 * family.n  # one row per mode and speed: the count is fixed
    # track modes (lumped track bodies carry their energy) are excluded rows
    table = modes(family, speed=10.0)
    assert (table["group"] == "track").sum() >= 6  # "track", "track #2", ...
    assert np.sum(g[: family.n] == -1.0) >= (table["group"] == "track").sum()
    for i in range(2):
        h = 1e-6 * p0[i]
        up, down = p0.copy(), p0.copy()
        up[i] += h
        down[i] -= h
        fd = (rows(family, up, speeds, **kwargs)[0] - rows(family, down, speeds, **kwargs)[0]) / (2 * h)
        live = g != -1.0
        assert np.max(np.abs(J[live, i] - fd[live])) <= 1e-5 * np.max(np.abs(fd[live]))


@pytest.mark.parametrize("exclude", [(), ("body",), ("front truck",), ("frame_rear", "body hunting")])
@pytest.mark.parametrize("track", ["rigid", "flexible"])
def test_the_kept_rows_are_the_modes_named_by_modes(exclude, track: str) -> None:
    """The rows' mask (worked out from energy shares, names only when something is excluded) is the one
    :func:`modes` gives root by root: a row is −1 exactly for a rigid-body, track or excluded mode."""
    family = load_vehicle("sd40-2").lateral(track).family(["K2", "C13"])
    speeds = [12.0, 31.0]
    g, _ = root_constraints(family, family.values, speeds, sigma_min=1e-3, exclude=exclude)
    for k, S in enumerate(speeds):
        table = modes(family, speed=S)
        always = (table["group"] == "track") | table["name"].str.startswith("rigid body")
        dropped = (always | table["name"].map(lambda nm: any(nm == x or nm.startswith(x) for x in exclude))
                   | table["group"].isin(exclude))
        if exclude:
            assert dropped.sum() > always.sum()  # the exclusion bites
        rows = g[k * family.n:(k + 1) * family.n]
        assert np.array_equal(rows == -1.0, dropped.to_numpy())
        assert np.allclose(rows[~dropped.to_numpy()], table["real"][~dropped].to_numpy() + 1e-3, rtol=0, atol=1e-12)


@pytest.mark.parametrize(("vehicle", "conicity", "expected"), [
    ("manchester-coach", 0.025, "body hunting (bogies in phase)"),
    ("manchester-coach", 0.05, "bogie hunting (in phase)"),
    ("sd40-2", None, "body hunting (front truck)"),
])
@pytest.mark.parametrize("track", ["rigid", "flexible"])
def test_the_critical_mode_is_named_by_what_hunts(vehicle: str, conicity, expected: str, track: str) -> None:
    v = load_vehicle(vehicle)
    if conicity is not None:
        v = v.with_parameters({"conicity": conicity})
    cs = critical_speed(v, track, (1.0, 150.0), tol=0.01)
    assert cs.mode == expected
    table = modes(v.lateral(track), speed=cs.speed)
    critical = table.loc[table["real"].idxmax()]
    assert critical["name"] == expected
    assert critical["frequency_hz"] == pytest.approx(cs.frequency, rel=1e-3)
    if track == "flexible":
        assert (table["group"] == "track").sum() == len(v.wheelsets)  # one track roll per wheelset
        assert table.loc[table["group"] == "track", "track_share"].min() > 0.9


@pytest.mark.parametrize(("conicity", "expected"), [(0.025, "body hunting (bogies in phase)"),
                                                    (0.05, "bogie hunting (in phase)")])
def test_root_locus_names_its_roots_as_the_modes_table_does(conicity: float, expected: str) -> None:
    v = load_vehicle("manchester-coach").with_parameters({"conicity": conicity})
    cs = critical_speed(v, "rigid", (1.0, 150.0), tol=0.01)
    above = cs.speed * 1.005
    locus = root_locus(v.lateral("rigid"), [cs.speed * 0.9, above]).to_pandas()
    grows = locus[(locus["speed"] == above) & (locus["real"] > 0)]
    assert list(grows["name"]) == [expected]
    # the locus names each oscillatory root as modes() names the same root at the same speed
    table = modes(v.lateral("rigid"), speed=above)
    table = table[table["imag"] > 0].sort_values(["imag", "real"]).reset_index(drop=True)
    at = locus[(locus["speed"] == above) & (locus["imag"] > 0)].reset_index(drop=True)
    assert np.allclose(at["imag"], table["imag"], rtol=1e-9, atol=1e-9)
    assert list(at["name"]) == list(table["name"])


def test_stability_rows_solve_once_and_give_the_asked_columns() -> None:
    """:class:`StabilityRows`: the Jacobian of any ``wrt`` is the full Jacobian's columns (any order, repeats,
    negative indices, a numpy array or a generator), the damping rows share the root derivatives, and what is not
    a list of indices is refused by name (a mask, floats, an index out of range, a bare-string exclude)."""
    from railopt.models.stability_rows import StabilityRows

    family = load_vehicle("sd40-2").lateral("rigid").family(["K2", "K3", "C13", "C15"])
    rows = StabilityRows(family, None, [10.0, 20.0, 30.0])
    full_roots, full_damping = rows.roots_jacobian(), rows.damping_jacobian()
    assert full_roots.shape == (3 * family.n, 4)
    for wrt, cols in (([0, 2], [0, 2]), ((i for i in [3, 1]), [3, 1]), (np.array([2, 0]), [2, 0]),
                      ([1, 1], [1, 1]), ([-1], [3]), (range(4), [0, 1, 2, 3])):
        fresh = StabilityRows(family, None, [10.0, 20.0, 30.0])
        np.testing.assert_array_equal(fresh.roots_jacobian(wrt), full_roots[:, cols])
        np.testing.assert_array_equal(rows.damping_jacobian(list(cols)), full_damping[:, cols])
    assert rows.roots_jacobian([]).shape == (3 * family.n, 0)
    g, J = root_constraints(family, None, [10.0, 20.0, 30.0], wrt=[1, 3])
    np.testing.assert_array_equal(g, rows.roots())
    np.testing.assert_array_equal(J, full_roots[:, [1, 3]])
    for bad in (np.array([True, False, True, False]), [True, False], np.array([0.0, 2.0]), "01", 3):
        with pytest.raises(ValueError, match="wrt: parameter indices must be whole numbers"):
            rows.roots_jacobian(bad)
    with pytest.raises(ValueError, match=r"wrt: indices \[4\] are outside the family's 4 parameters"):
        rows.damping_jacobian([4])
    with pytest.raises(ValueError, match=r"exclude: .* got the string 'body lateral'; write \['body lateral'\]"):
        StabilityRows(family, None, [10.0], exclude="body lateral")
