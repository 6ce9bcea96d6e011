"""``railopt bench`` rows of the certified stability analyses: the critical speed from the bialternate pencil
against the sampled search it replaced and a dense scan (time and eigen-solves, one run); the stability rows and
their derivatives at all speeds of one design in one stacked call against the per-speed loop."""

from __future__ import annotations

import time
import timeit

import numpy as np

from railopt.models.crossings import speed_pencil
from railopt.models.modal import mode_order
from railopt.models.sensitivity import eigenvalue_derivatives
from railopt.models.stability import critical_speed, first_crossing
from railopt.models.stability_map import CountedFamily
from railopt.models.stability_rows import StabilityRows
from railopt.models.vehicle import load_vehicle

ISSUE_CASE = {"secondary_lateral_stiffness": 1e5, "sidebearer1_vertical_stiffness": 1.99e8,
              "lateral_shock_absorber_damping": 3.67e4, "rotational_shock_absorber_damping": 8.11e4}
SCAN_STEP = 0.05  # m/s, the dense scan's step


def _scan(view, lo: float, hi: float) -> tuple[float, int]:
    """First up-crossing of the spectral abscissa on a SCAN_STEP grid (the whole range is scanned: a scan cannot
    know that a later window does not come back) and the eigen-solves it took."""
    speeds = np.arange(lo, hi + 1e-9, SCAN_STEP)
    first = np.inf
    for S in speeds:
        s = view.at(speed=float(S)).eigenvalues()
        live = s[np.abs(s) > 1e-8 * np.max(np.abs(s))]
        if np.isinf(first) and np.max(live.real) > 0.0:
            first = float(S)
    return first, len(speeds)


def critical_speed_rows(tol: float = 0.01, speed_range: tuple[float, float] = (1.0, 120.0)) -> list[dict]:
    """One row per case: certified critical speed (pencil + map) vs the sampled search (8-point grid, local-maximum
    search, Brent) and vs a dense 0.05 m/s scan of the whole range; ratios of time, with the answers and solves."""
    rows = []
    sd40 = load_vehicle("sd40-2")
    cases = [("sd40-2 rigid", sd40.lateral(track="rigid")), ("sd40-2 flexible", sd40.lateral(track="flexible")),
             ("sd40-2 rigid, the issue's window design", sd40.with_parameters(ISSUE_CASE).lateral(track="rigid"))]
    lo, hi = speed_range
    for label, view in cases:
        t = time.perf_counter()
        cs = critical_speed(view, speed_range=speed_range, tol=tol)
        t_cert = time.perf_counter() - t
        counted = CountedFamily(view, None)
        t = time.perf_counter()
        sampled, _ = first_crossing(counted, lo, hi, tol, 8)
        t_sampled = time.perf_counter() - t
        t = time.perf_counter()
        scanned, scan_solves = _scan(view, lo, hi)
        t_scan = time.perf_counter() - t
        size = speed_pencil(view.at(speed=0.5 * (lo + hi))).bialternate_size
        rows.append({"benchmark": f"critical speed {label}, {lo:g}–{hi:g} m/s, tol {tol} m/s: certified "
                                  f"{cs.speed:.3f} m/s (pencil m={size}, {cs.eigen_solves} eigen-solves)",
                     "ours_s": t_cert, "reference_s": t_scan,
                     "reference": f"dense {SCAN_STEP} m/s scan ({scan_solves} eigen-solves): {scanned:.2f} m/s",
                     "ratio": t_cert / t_scan,
                     "note": f"sampled search (8-point grid + Brent, the former method): {sampled:.3f} m/s in "
                             f"{counted.solves} eigen-solves, {t_sampled:.4f} s; certified / sampled "
                             f"{t_cert / t_sampled:.2f}"})
    return rows


ROW_SPEEDS = tuple(np.linspace(15.0, 31.29, 12))  # the flagship's row speeds (15 m/s to 70 mph), m/s
DESIGNED = ["K2", "K3", "C13", "C15"]  # the flagship's designed parameters


def _per_speed(families: list, speeds: tuple[float, ...]) -> list[tuple[np.ndarray, np.ndarray]]:
    """The reference: per track and speed one member through the public API, its eigen-decomposition, the roots one
    per mode and their derivatives (no kept-mode mask: a floor for the former loop, which also worked one out)."""
    out = []
    for family in families:
        for S in speeds:
            system = family.at(None, speed=float(S))
            s = system.modal().s
            idx = mode_order(s)[1::2]
            t = system.tangent
            out.append((s[idx], eigenvalue_derivatives(system, t.dM, t.dC, t.dK)[idx]))
    return out


def stacked_rows_row(reps: int = 20) -> dict:
    """Stability rows + derivatives of one flagship design (sd40-2 lateral, rigid and flexible track, the 12 row
    speeds, the 4 designed parameters): :class:`StabilityRows` (one stacked eigen-decomposition and one stacked
    derivative call per track) against the per-speed loop through the public LinearSystem API; median of
    ``reps``, with the largest difference of roots and derivatives between the two."""
    vehicle = load_vehicle("sd40-2")
    families = [vehicle.lateral(track).family(DESIGNED) for track in ("rigid", "flexible")]

    def stacked() -> list[StabilityRows]:
        out = []
        for family in families:
            rows = StabilityRows(family, None, ROW_SPEEDS)
            rows.roots_jacobian()
            out.append(rows)
        return out

    t_stacked = float(np.median(timeit.repeat(stacked, number=1, repeat=reps)))
    t_loop = float(np.median(timeit.repeat(lambda: _per_speed(families, ROW_SPEEDS), number=1, repeat=reps)))
    reference = iter(_per_speed(families, ROW_SPEEDS))  # track by track, speed by speed
    d_roots = d_ds = 0.0  # Re s and |Im s| (a pair's two roots are one mode), Re ds/dp of the kept rows
    for r in stacked():
        kept = (r.roots() != -1.0).reshape(len(ROW_SPEEDS), -1)
        jac = r.roots_jacobian().reshape(len(ROW_SPEEDS), -1, len(DESIGNED))
        for k, s in enumerate(r.mode_roots):
            s_ref, ds_ref = next(reference)
            gap = np.abs(s.real - s_ref.real) + np.abs(np.abs(s.imag) - np.abs(s_ref.imag))
            d_roots = max(d_roots, float(np.max(gap) / np.max(np.abs(s_ref))))
            slope = ds_ref.real[kept[k]]
            d_ds = max(d_ds, float(np.max(np.abs(jac[k][kept[k]] - slope)) / np.max(np.abs(slope))))
    sizes = "/".join(str(f.n) for f in families)
    return {"benchmark": f"stability rows + derivatives, all speeds of one design: stacked vs per-speed loop "
                         f"(sd40-2 lateral rigid + flexible, n = {sizes}, {len(ROW_SPEEDS)} speeds, "
                         f"{len(DESIGNED)} parameters)",
            "ours_s": t_stacked, "reference_s": t_loop,
            "reference": "per-speed loop: family.at(S), eig, mode_order, eigenvalue_derivatives (public API)",
            "ratio": t_stacked / t_loop,
            "note": f"roots agree to {d_roots:.1e}·max|s|, Re ds/dp of the kept rows to {d_ds:.1e}·max"}


__all__ = ["DESIGNED", "ISSUE_CASE", "ROW_SPEEDS", "SCAN_STEP", "critical_speed_rows", "stacked_rows_row"]
