"""The bifurcation-diagram figure, drawn from a real diagram of the subcritical Hopf normal form (closed forms in
tests/models/test_bifurcation_normal_form.py: Hopf at 30 m/s, fold at 25 m/s, stable outer and unstable inner
cycles): branch styles by stability, the fold and the linear critical speed marked at their closed-form speeds,
the ramp's verdicts as markers, axes with units."""

from __future__ import annotations

import numpy as np
import pytest

from railopt.models.bifurcation import (
    ContinuationOptions,
    Dwell,
    IntegrationSettings,
    ShootingOptions,
    bifurcation_diagram,
)
from railopt.studies.output.bifurcation_figure import plot_bifurcation_diagram
from tests.models.test_bifurcation_normal_form import SECTION, V_C, V_FOLD, V_REF, radius, rhs


@pytest.fixture(scope="module")
def diagram():
    return bifurcation_diagram(rhs, np.array([0.05, 0.0]), np.arange(31.3, 22.5, -0.5),
                               Dwell(wavelengths=60, wavelength_m=20.0), 0, SECTION, sample_rate_hz=40.0,
                               speed_range=(20.0, 34.0), settings=IntegrationSettings(rtol=1e-10, atol=1e-12),
                               continuation=ContinuationOptions(speed_scale=V_REF),
                               shooting=ShootingOptions(min_amplitude=0.05), linear_critical_speed=V_C)


def test_branches_folds_and_ramp_are_drawn_as_the_diagram_says(diagram):
    table = diagram.to_pandas()
    fig = plot_bifurcation_diagram(table, "normal form: hunting cycles", "amplitude of x (mm)",
                                   ramp=diagram.ramp.to_pandas(), scale=1e3)
    ax = fig.axes[0]
    lines = {line.get_label(): line for line in ax.get_lines()}
    stable = [line for line in ax.get_lines() if line.get_color() == "C3" and line.get_linestyle() == "-"]
    unstable = [line for line in ax.get_lines() if line.get_color() == "C0" and line.get_linestyle() == "--"]
    assert stable and unstable
    # every drawn point lies on the closed-form branch of its style (amplitude in mm: × 1e3)
    for group, sign in ((stable, +1), (unstable, -1)):
        for line in group:
            # the last point of a segment may be the next segment's first (drawn joined, no gap at the fold)
            v, a = np.asarray(line.get_xdata(), float)[:-1], np.asarray(line.get_ydata(), float)[:-1] / 1e3
            np.testing.assert_allclose(a, radius(v, sign), rtol=1e-6)
    fold = next(line for label, line in lines.items() if label.startswith("fold"))
    assert fold.get_xdata()[0] == pytest.approx(V_FOLD, rel=1e-6) and "nonlinear critical speed" in fold.get_label()
    linear = next(line for label, line in lines.items() if label.startswith("linear critical speed"))
    assert linear.get_xdata()[0] == V_C and linear.get_linestyle() == "-."
    assert any(label.startswith("ramp: steady") for label in lines) and any(
        label.startswith("ramp: decaying") or label.startswith("ramp: rest") for label in lines)
    assert ax.get_xlabel() == "forward speed (m/s)" and "(mm)" in ax.get_ylabel()
    styles = {(line.get_color(), line.get_linestyle(), line.get_marker()) for line in ax.get_lines()
              if line.get_label() and not line.get_label().startswith("_")}
    assert len(styles) == len([x for x in lines if not x.startswith("_")])  # no two legend entries look alike
