"""``railopt bench`` rows of the nonlinear hunting analysis (issue 26): the cost of a simulated second of the
nonlinear vehicle on its profile table and of a whole bifurcation diagram, against the certified linear critical
speed of the same vehicle (what the linear check costs), in one run."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from railopt.models.stability import critical_speed
from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.hunting import HuntingAnalysis, leading_wheelset, nonlinear_hunting, profile_vehicle

WHEELSET = Path(__file__).resolve().parents[1] / "tests" / "models" / "vehicle" / "data" / "wheelset-s1002.toml"
"""The single wheelset on S1002/60E1 1:40 of the hunting tests (a source checkout; the row is skipped without it)."""


def _linear_time(vehicle) -> tuple[float, float]:
    t = time.perf_counter()
    speed = critical_speed(vehicle.lateral("rigid"), speed_range=(1.0, 150.0)).speed
    return time.perf_counter() - t, speed


def _per_simulated_second(vehicle, speed: float, seconds: float, method: str) -> float:
    nv = profile_vehicle(vehicle)
    x0 = np.zeros(2 * nv.n_dof)
    x0[nv.index(f"{leading_wheelset(vehicle)}.v")] = 1e-3
    t = time.perf_counter()
    solve_ivp(nv.rhs, (0.0, seconds), x0, args=(speed,), method=method, rtol=1e-6, atol=1e-9)
    return (time.perf_counter() - t) / seconds


def nonlinear_rows(quick: bool = False) -> list[dict]:
    """Seconds per simulated second (coach and single wheelset, RK45 and LSODA at rtol 1e-6) and per bifurcation
    diagram (the single wheelset: ramp, shooting, continuation to 3 points past the fold), each against the
    certified linear critical speed of the same vehicle; ``quick`` leaves the diagram out."""
    rows = []
    seconds = 0.5 if quick else 2.0
    coach = load_vehicle("manchester-coach")
    t_lin, v_lin = _linear_time(coach)
    for method in ("RK45", "LSODA"):
        per = _per_simulated_second(coach, 60.0, seconds, method)
        rows.append({"benchmark": f"nonlinear coach on S1002/60E1 (SHE), {method} rtol 1e-6, 60 m/s from 1 mm: "
                                  "seconds per simulated second",
                     "ours_s": per, "reference_s": t_lin,
                     "reference": f"certified linear critical speed of the coach ({v_lin:.2f} m/s)",
                     "ratio": per / t_lin, "note": f"{seconds:g} s simulated"})
    if not WHEELSET.is_file():  # an installed package without the tests: say so in the table
        rows.append({"benchmark": "nonlinear single wheelset rows", "note": f"skipped: {WHEELSET} is not in this "
                     "installation (run from a source checkout)"})
        return rows
    wheelset = load_vehicle(WHEELSET)
    t_lin, v_lin = _linear_time(wheelset)
    per = _per_simulated_second(wheelset, 45.0, seconds, "RK45")
    rows.append({"benchmark": "nonlinear single wheelset on S1002/60E1 (SHE), RK45 rtol 1e-6, 45 m/s: seconds per "
                              "simulated second", "ours_s": per, "reference_s": t_lin,
                 "reference": f"certified linear critical speed ({v_lin:.2f} m/s)", "ratio": per / t_lin})
    if quick:
        return rows
    analysis = HuntingAnalysis(top_speed=50.0, step=2.5, fine_step=0.5, lowest_speed=40.0, initial_amplitude=2e-3,
                               points_after_fold=3)
    t = time.perf_counter()
    r = nonlinear_hunting(wheelset, analysis)
    t_diagram = time.perf_counter() - t
    rows.append({"benchmark": "bifurcation diagram of the single wheelset on S1002/60E1: ramp 50→40 m/s "
                              "(2.5, then 0.5 m/s), shooting, continuation 3 points past the fold",
                 "ours_s": t_diagram, "reference_s": t_lin,
                 "reference": f"certified linear critical speed ({v_lin:.2f} m/s)", "ratio": t_diagram / t_lin,
                 "note": f"{r.critical.reason}; {len(r.diagram.speed) if r.diagram is not None else 0} points"})
    return rows


__all__ = ["nonlinear_rows"]
