"""The stability map figure: the spectral abscissa against forward speed, the certified crossings marked."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from railopt.studies.output.figures import wrap_title

__all__ = ["plot_stability_map"]

STYLES = (("C0", "-"), ("C1", "--"), ("C2", "-."), ("C3", ":"), ("C4", "-"), ("C5", "--"))


def plot_stability_map(damping: pd.DataFrame, maps: pd.DataFrame, title: str,
                       vehicles: Mapping[str, str] | None = None) -> Figure:
    """One panel per model: max Re s (1/s) of the locus grid (``damping``: model, speed_m_s, spectral_abscissa)
    against speed (m/s), each unstable interval of the certified map (``maps``: model, start_m_s, end_m_s, state)
    shaded and every crossing speed marked by a vertical line with its value.  ``vehicles`` (model → the vehicle's
    name and file, :func:`~railopt.studies.output.figures.vehicle_label`) name each panel's vehicle."""
    models = list(dict.fromkeys(damping["model"]))
    fig = Figure(figsize=(7.0, 1.9 * len(models) + 0.9))
    axes = np.atleast_1d(fig.subplots(len(models), 1, sharex=True))
    for k, (ax, model) in enumerate(zip(axes, models, strict=True)):
        d = damping[damping["model"] == model]
        colour, style = STYLES[k % len(STYLES)]
        vehicle = (vehicles or {}).get(model, "")
        ax.plot(d["speed_m_s"], d["spectral_abscissa"], color=colour, ls=style, lw=1.3,
                label=f"{model}{f' ({vehicle})' if vehicle else ''}: max Re s")
        ax.axhline(0.0, color="k", lw=0.6)
        m = maps[maps["model"] == model]
        for _, iv in m[m["state"] == "unstable"].iterrows():
            ax.axvspan(iv["start_m_s"], iv["end_m_s"], color="C3", alpha=0.12, lw=0)
        for speed in m["start_m_s"].iloc[1:]:
            ax.axvline(speed, color="C3", ls="--", lw=0.9)
            ax.annotate(f"{speed:.2f}", (speed, 0.0), xytext=(3, 6), textcoords="offset points", fontsize=7,
                        color="C3")
        ax.set_ylabel("max Re s (1/s)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
    axes[-1].set_xlabel("forward speed (m/s)")
    axes[0].set_title(wrap_title(title, 6.6, 10), fontsize=10)
    fig.text(0.5, 0.005, "shaded: unstable (certified map); dashed: crossing speeds (bialternate pencil, confirmed by "
             "eigen-solves)", ha="center", va="bottom", fontsize=7, color="0.3")
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    return fig
