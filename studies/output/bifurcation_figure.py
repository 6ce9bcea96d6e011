"""The bifurcation diagram figure: hunting-cycle amplitude against forward speed, stable and unstable branches,
the fold (the nonlinear critical speed), the linear critical speed and the descending ramp's verdicts."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from railopt.studies.output.figures import wrap_title

__all__ = ["plot_bifurcation_diagram"]

RAMP_STYLES = {"steady": ("C2", "o"), "decaying": ("C0", "v"), "growing": ("C3", "^"), "rest": ("0.5", "s"),
               "undetermined": ("C4", "x")}


def _segments(table: pd.DataFrame):
    """Consecutive runs of equal stability along the branch (arclength order), each with its neighbour's point
    so that the drawn curve has no gap where the stability changes."""
    stable = table["stable"].to_numpy(bool)
    start = 0
    for k in range(1, len(table) + 1):
        if k == len(table) or stable[k] != stable[start]:
            yield bool(stable[start]), table.iloc[start:min(k + 1, len(table))]
            start = k


def plot_bifurcation_diagram(diagram: pd.DataFrame, title: str, amplitude_label: str,
                             ramp: pd.DataFrame | None = None, scale: float = 1.0) -> Figure:
    """Amplitude of the periodic orbits against speed (m/s): stable branches solid, unstable dashed, each fold
    (``diagram.attrs["fold_speeds_m_s"]``) a vertical dotted line with its speed, the linear critical speed
    (``attrs["linear_critical_speed_m_s"]``) a dash-dot line, and the ramp's verdict at each speed
    (``ramp``: :meth:`RampResult.to_pandas` columns ``speed_m_s``, ``amplitude``, ``classification``) as markers.

    ``diagram`` has the columns of :meth:`BifurcationDiagram.to_pandas` (``speed_m_s``, ``amplitude``, ``stable``,
    in arclength order); amplitudes are multiplied by ``scale`` for the axis (1e3: m → mm), whose label is
    ``amplitude_label`` (name it with its unit)."""
    fig = Figure(figsize=(7.4, 4.6), layout="constrained")
    ax = fig.subplots()
    shown = set()
    for stable, part in _segments(diagram):
        label = "stable cycles" if stable else "unstable cycles (the basin's edge)"
        ax.plot(part["speed_m_s"], part["amplitude"] * scale, color="C3" if stable else "C0",
                ls="-" if stable else "--", lw=1.8 if stable else 1.4,
                label=None if label in shown else label)
        shown.add(label)
    for k, fold in enumerate(diagram.attrs.get("fold_speeds_m_s", [])):
        ax.axvline(fold, color="k", ls=":", lw=1.1, label=f"fold {fold:.4g} m/s" + (" (nonlinear critical speed)"
                                                                                   if k == 0 else ""))
    linear = diagram.attrs.get("linear_critical_speed_m_s", math.nan)
    if linear is not None and np.isfinite(linear):
        ax.axvline(linear, color="C1", ls="-.", lw=1.2, label=f"linear critical speed {linear:.4g} m/s")
    if ramp is not None and len(ramp):
        for state, (color, marker) in RAMP_STYLES.items():
            r = ramp[ramp["classification"] == state]
            if len(r):
                ax.plot(r["speed_m_s"], r["amplitude"] * scale, ls="none", marker=marker, ms=5, color=color,
                        markerfacecolor="none", label=f"ramp: {state}")
    ax.set_xlabel("forward speed (m/s)")
    ax.set_ylabel(wrap_title(amplitude_label, 3.8, 9), fontsize=9)
    ax.set_ylim(bottom=0.0)
    ax.set_title(wrap_title(title, 4.6, 10), fontsize=10)  # the axes' width: the legend sits beside them
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return fig
