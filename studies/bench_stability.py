"""``railopt bench`` rows of the certified stability analyses: the critical speed from the bialternate pencil
against the sampled search it replaced and a dense scan (time and eigen-solves, one run)."""

from __future__ import annotations

import time

import numpy as np

from railopt.models.crossings import speed_pencil
from railopt.models.stability import critical_speed, first_crossing
from railopt.models.stability_map import CountedFamily
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


__all__ = ["ISSUE_CASE", "SCAN_STEP", "critical_speed_rows"]
