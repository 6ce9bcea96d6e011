"""Dynamic amplification of the moving-load deflection over speed, damping and axial force (§3.3)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd

from railopt.models.track.beam import Beam
from railopt.models.track.moving_load import closed_form_solution, moving_load


def dynamic_amplification(
    EI: float,
    m: float,
    k: float,
    P: float,
    speed_ratios: Sequence[float],
    damping_ratios: Sequence[float],
    axial_ratios: Sequence[float],
) -> pd.DataFrame:
    """Maximum deflection and its lag over a grid of v/v_cr, c/c_cr and N/N_cr (closed form).

    Parameters
    ----------
    EI, m, k : float
        Beam constants, N·m², kg/m, N/m².
    P : float
        Load, N.
    speed_ratios : sequence of float
        v / v_cr (v_cr of the beam with its axial force), >= 0.
    damping_ratios : sequence of float
        c / 2√(km), >= 0.
    axial_ratios : sequence of float
        N / N_cr, < 1 (negative: tension).

    Returns
    -------
    pandas.DataFrame
        One row per combination: ratios, ``v_m_s``, ``N_N``, ``y_max_m``, ``x_max_m`` (negative =
        behind the load), ``y_static_m`` (same N, v = 0), ``y_static_N0_m`` (Hetényi),
        ``amplification`` = y_max / y_static_N0 and ``speed_amplification`` = y_max / y_static.
        An undamped beam at v = v_cr is resonant: y_max = +inf and x_max = 0 there (never NaN).
    """
    base = Beam(EI=EI, m=m, k=k)
    y_static_n0 = P * base.beta / (2.0 * k)
    rows = []
    for nu in axial_ratios:
        for zeta in damping_ratios:
            beam = Beam.from_ratios(EI, m, k, damping_ratio=zeta, axial_ratio=nu)
            y_static = float(closed_form_solution(beam, P, 0.0).evaluate(np.array([0.0]))[0])
            for theta in speed_ratios:
                theta = float(theta)
                if not math.isfinite(theta) or theta < 0.0:
                    raise ValueError(f"speed_ratios: must be finite and non-negative, got {theta!r}")
                v = theta * beam.critical_velocity()
                if zeta == 0.0 and abs(theta - 1.0) <= 1e-6:
                    y_max, x_max = math.inf, 0.0
                else:
                    sol = moving_load(beam, np.array([0.0]), P, v)
                    y_max, x_max = sol.y_max, sol.x_max
                rows.append(
                    {
                        "speed_ratio": theta,
                        "damping_ratio": float(zeta),
                        "axial_ratio": float(nu),
                        "v_m_s": v,
                        "N_N": beam.N,
                        "y_max_m": y_max,
                        "x_max_m": x_max,
                        "y_static_m": y_static,
                        "y_static_N0_m": y_static_n0,
                        "amplification": y_max / y_static_n0,
                        "speed_amplification": y_max / y_static,
                    }
                )
    return pd.DataFrame(rows)


__all__ = ["dynamic_amplification"]
