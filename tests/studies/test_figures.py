"""Figures a user can read (issue 15 finding 13): titles inside the figure, y axes with unit and input amplitude,
distinct styles per curve, root loci as damping ratio and frequency against speed with the roots off the chart
counted; and the readable tables beside them (the forced-response modes named by kinetic-energy shares).

Figures are rendered with Agg and inspected through their artists.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure

from railopt.models.stability import root_locus
from railopt.models.vehicle import load_vehicle
from railopt.studies.catalog import ModelRef
from railopt.studies.output.figures import (
    plot_before_after,
    plot_forced_response,
    plot_frf_panels,
    plot_root_loci_before_after,
    plot_root_locus,
    plot_surfaces,
)

LONG = ("sd40-2: sd40-2 cab model, ±0.25 in lateral irregularity, λ = 22.35 m, constrained and unconstrained "
        "optima of every method and objective against the existing suspension")


def rendered(fig: Figure):
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return canvas.get_renderer()


def texts_inside(fig: Figure) -> None:
    """Every title, axis label and figure text lies inside the figure."""
    renderer = rendered(fig)
    box = fig.bbox
    texts = list(fig.texts)
    for ax in fig.axes:
        if ax.get_visible():
            texts += [ax.title, ax.xaxis.label, ax.yaxis.label]
    for t in texts:
        if not t.get_text():
            continue
        e = t.get_window_extent(renderer)
        assert e.x0 >= box.x0 - 0.5 and e.x1 <= box.x1 + 0.5, (t.get_text(), e, box)
        assert e.y0 >= box.y0 - 0.5 and e.y1 <= box.y1 + 0.5, (t.get_text(), e, box)


def curve_styles(ax) -> list[tuple[tuple[float, ...], str, str]]:
    """(colour, line style, marker) of each labelled curve of a panel."""
    return [(to_rgba(line.get_color()), line.get_linestyle(), str(line.get_marker())) for line in ax.get_lines()
            if not line.get_label().startswith("_")]


def distinct(ax) -> None:
    styles = curve_styles(ax)
    assert len(styles) == len(set(styles)), styles


# ---------------------------------------------------------------------------------------------- FRF panels
def frf_panel(keys: list[str], ylabel: str = "|cab_acceleration| (m/s² per 6.35 mm (0.25 in) lateral irregularity)"):
    f = np.linspace(0.0, 3.0, 50)
    curves = [(f"curve {i} ({k})", f, (i + 1) * np.ones_like(f), k) for i, k in enumerate(keys)]
    return plot_frf_panels([(LONG, ylabel, curves)])


def test_frf_title_is_wrapped_inside_the_figure():
    fig = frf_panel(["ref", "exact"])
    ax = fig.axes[0]
    assert "\n" in ax.get_title()
    assert ax.get_title().replace("\n", " ") == LONG.removeprefix("sd40-2: ")  # the vehicle named once
    texts_inside(fig)


@pytest.mark.parametrize("keys", [["ref", "ref", "exact", "exact", "thesis", "thesis"],
                                  ["ref", "exact", "thesis", "exact", "exact"], ["C0", "C1", "C2", "C3", "C4"]])
def test_frf_curves_never_share_colour_and_style(keys):
    fig = frf_panel(keys)
    ax = fig.axes[0]
    assert len(curve_styles(ax)) == len(keys)
    distinct(ax)


def test_frf_repeated_key_keeps_its_colour_with_the_next_line_style():
    ax = frf_panel(["ref", "exact", "exact"]).axes[0]
    (c0, s0, _), (c1, s1, _), (c2, s2, _) = curve_styles(ax)
    assert (c0, s0) == (to_rgba("k"), "-")
    assert (c1, s1) == (to_rgba("C0"), "-")
    assert (c2, s2) == (to_rgba("C0"), "--")


def test_cab_axis_label_names_unit_and_input_amplitude():
    setup = ModelRef(label="sd40-2", model="cab_lateral", options={"vehicle": "sd40-2"}).setup("models[0]")
    assert setup.axis_label("cab_acceleration") == \
        "|cab_acceleration| (m/s² per 6.35 mm (0.25 in) lateral irregularity)"
    assert setup.axis_label("cab_displacement", inch=True) == \
        "|cab_displacement| (in per 6.35 mm (0.25 in) lateral irregularity)"
    assert setup.axis_label("body_roll") == "|body_roll| (rad per 6.35 mm (0.25 in) lateral irregularity)"
    fig = frf_panel(["ref", "exact"], setup.axis_label("cab_acceleration"))
    assert fig.axes[0].get_ylabel().replace("\n", " ") == \
        "|cab_acceleration| (m/s² per 6.35 mm (0.25 in) lateral irregularity)"
    texts_inside(fig)


def test_vehicle_forced_and_tmd_axis_labels():
    forced = ModelRef(label="m", model="vehicle_forced", options={
        "vehicle": "sd40-2", "view": "lateral", "input": {"kind": "alignment", "amplitude_m": 0.00635},
        "outputs": ["body.v", "body.alpha"],
        "quantity": "acceleration"}).setup("models[0]")
    assert forced.axis_label("body.v") == "|body.v| (m/s² per 6.35 mm alignment irregularity)"
    assert forced.axis_label("body.alpha") == "|body.alpha| (rad/s² per 6.35 mm alignment irregularity)"
    tmd = ModelRef(label="m", model="tmd", options={"mass_ratio": 0.05}).setup("models[0]")
    assert tmd.axis_label("amplification") == "|amplification| (k1·x1 / F, dimensionless)"


def test_design_variables_have_their_si_unit_and_the_surface_axes_show_it():
    """A variable's unit follows from what its element is (vehicle file type) or what the TMD parameter is; the
    objective-surface axes read ``log10 <name> (<unit>)`` and U in the objective output's unit."""
    cab = ModelRef(label="sd40-2", model="cab_lateral", options={"vehicle": "sd40-2"}).setup("models[0]")
    pm = cab.parameter_map
    vehicle = load_vehicle("sd40-2")
    units = {"spring": "N/m", "damper": "N·s/m", "rotational_spring": "N·m/rad", "rotational_damper": "N·m·s/rad"}
    for element in vehicle.elements:
        if element.id in pm.parameters:
            assert pm.unit(element.id) == units[element.type]
            assert pm.unit(element.alias) == units[element.type]
    assert pm.unit("secondary_lateral_stiffness") == "N/m"
    assert pm.unit("lateral_shock_absorber_damping") == "N·s/m"
    assert pm.unit("no_such_parameter") == ""
    tmd = ModelRef(label="m", model="tmd", options={"mass_ratio": 0.05}).setup("models[0]").parameter_map
    assert (tmd.unit("k2"), tmd.unit("c2"), tmd.unit("tuning"), tmd.unit("damping_ratio")) == ("N/m", "N·s/m", "–", "–")

    from railopt.design.surface import Surface

    xi, xj = np.geomspace(1e5, 1e6, 4), np.geomspace(1e7, 1e8, 3)
    grid = Surface(("K2", "K3"), xi, xj, np.outer(xj, xi) * 1e-12, np.ones((3, 4), dtype=bool))
    fig = plot_surfaces(grid, grid, "U over K2 × K3", units=("N/m", "N/m", "m/s²"))
    labels = [(ax.get_xlabel(), ax.get_ylabel()) for ax in fig.axes if ax.get_xlabel()]
    assert ("log10 K2 (N/m)", "log10 K3 (N/m)") in labels
    assert {ax.get_zlabel() for ax in fig.axes if hasattr(ax, "get_zlabel")} == {"log10 U (m/s²)"}
    assert "log10 U (m/s²)" in [ax.get_ylabel() for ax in fig.axes]  # the colour bars
    for bad in (("N/m", "N/m"), None, "N/m"):
        with pytest.raises(ValueError, match=r"units: \(unit of K2, of K3, of U\)"):
            plot_surfaces(grid, grid, "U over K2 × K3", units=bad)
    bare = plot_surfaces(grid, grid, "U over K2 × K3", units=("–", "", ""))
    assert ("log10 K2", "log10 K3") in [(ax.get_xlabel(), ax.get_ylabel()) for ax in bare.axes]
    texts_inside(fig)


# ---------------------------------------------------------------------------------------------- before/after
def test_before_after_says_where_each_peak_lies():
    f = np.linspace(0.0, 3.0, 301)
    before = 1.0 + f ** 2  # still rising at the band edge
    after = 1.0 / ((1.0 - (f / 1.5) ** 2) ** 2 + 0.1)  # a resonance at 1.5 Hz
    fig = plot_before_after(f, before, after, LONG, "|cab_acceleration| (in/s² per 6.35 mm (0.25 in) lateral "
                                                    "irregularity)")
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["before (peak 10 at 3 Hz, band edge)", f"after (peak {np.max(after):.4g} at 1.5 Hz)"]
    distinct(ax)
    texts_inside(fig)


# ---------------------------------------------------------------------------------------------- forced response
def test_forced_response_axis_names_the_input_and_fits():
    f = np.linspace(0.5, 8.0, 40)
    series = {t: pd.DataFrame({"frequency_hz": f, "amplitude": k * np.ones_like(f), "unit": "m/s²",
                               "output": "body.w"}) for k, t in ((1.0, "rigid"), (1.2, "flexible"))}
    fig = plot_forced_response(series, title="Fig 4.6 " + LONG, peaks={"rigid": (1.0, 2.0), "flexible": (1.2, 2.1)},
                               note=LONG + "; " + LONG, input_label="6.35 mm vertical irregularity")
    ax = fig.axes[0]
    assert ax.get_ylabel().replace("\n", " ") == "|body.w| (m/s² per 6.35 mm vertical irregularity)"
    distinct(ax)
    texts_inside(fig)


# ---------------------------------------------------------------------------------------------- root loci
@pytest.fixture(scope="module")
def flexible_locus() -> pd.DataFrame:
    view = load_vehicle("sd40-2").lateral(track="flexible")
    return root_locus(view, np.linspace(5.0, 40.0, 8)).to_pandas()


def test_root_locus_is_damping_and_frequency_against_speed(flexible_locus):
    loci = {"before": flexible_locus, "after": flexible_locus.assign(damping_ratio=flexible_locus["damping_ratio"])}
    fig = plot_root_loci_before_after(loci, LONG)
    ax_z, ax_f = fig.axes
    assert ax_z.get_ylabel().startswith("damping ratio ζ = −Re s / |s|")
    assert ax_f.get_ylabel() == "frequency |Im s| / 2π (Hz)"
    assert ax_f.get_xlabel() == "forward speed (m/s)"
    assert ax_z.get_shared_x_axes().joined(ax_z, ax_f)
    upper = flexible_locus[flexible_locus["imag"] >= 0]
    shown = upper[upper["frequency_hz"] <= 25.0]
    assert ax_f.get_ylim() == (0.0, min(25.0, 1.08 * shown["frequency_hz"].max()))
    before = [line for line in ax_f.get_lines() if line.get_label() == "before"][0]
    np.testing.assert_array_equal(before.get_xdata(), shown["speed"].to_numpy())
    np.testing.assert_array_equal(before.get_ydata(), shown["frequency_hz"].to_numpy())
    z_line = [line for line in ax_z.get_lines() if line.get_label() == "before"][0]
    np.testing.assert_array_equal(z_line.get_ydata(), shown["damping_ratio"].to_numpy())
    distinct(ax_z)
    distinct(ax_f)
    texts_inside(fig)


def test_roots_above_the_chart_are_counted(flexible_locus):
    upper = flexible_locus[flexible_locus["imag"] >= 0]
    hidden = int(upper[upper["frequency_hz"] > 25.0].groupby("speed").size().max())
    assert hidden > 0  # the flexible track's modes (about 25 Hz and above)
    fig = plot_root_loci_before_after({"before": flexible_locus}, "before")
    captions = [t.get_text() for t in fig.texts]
    assert captions == [f"before: {hidden} roots above 25 Hz not shown"]
    fig = plot_root_loci_before_after({"before": flexible_locus}, "before", max_hz=100.0)
    assert fig.texts == [] or [t.get_text() for t in fig.texts] == [""]


def test_speed_sweep_root_locus_marks_the_critical_speed_and_counts_hidden_roots(flexible_locus):
    locus = pd.concat([flexible_locus.assign(model="a"), flexible_locus.assign(model="b")], ignore_index=True)
    critical = pd.DataFrame({"model": ["a", "b"], "critical_speed_m_s": [33.168, np.inf],
                             "critical_speed_mph": [74.19, np.inf], "mode": ["body hunting", ""]})
    fig = plot_root_locus(locus, critical)
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert len(visible) == 4
    ax_z, ax_f = visible[0], visible[2]
    assert ax_z.get_title() == "a: critical speed 33.17 m/s (74.2 mph), body hunting"
    crit = [line for line in ax_z.get_lines() if line.get_label() == "critical speed"]
    assert len(crit) == 1 and list(crit[0].get_xdata()) == [33.168, 33.168]
    upper = flexible_locus[flexible_locus["imag"] >= 0]
    hidden = int(upper[upper["frequency_hz"] > 25.0].groupby("speed").size().max())
    assert [t.get_text() for t in ax_f.texts] == [f"{hidden} roots above 25 Hz not shown"]
    assert fig.texts[0].get_text().replace("\n", " ") == \
        f"a: {hidden} roots above 25 Hz not shown; b: {hidden} roots above 25 Hz not shown"
    for ax in visible:
        distinct(ax)
    texts_inside(fig)


# ---------------------------------------------------------------------------------------------- tables
def test_forced_response_modes_are_named_by_energy_shares():
    from railopt.studies.kinds.forced_response import _modes

    view = load_vehicle("sd40-2").vertical(track="flexible", speed=30.0)
    rows = pd.DataFrame(_modes("vertical", "vertical_flexible", view, 15.0))
    assert list(rows.columns) == ["group", "model", "frequency_hz", "damping_ratio", "name", "share", "track_share"]
    assert (rows["frequency_hz"] >= 15.0).all()
    assert rows["frequency_hz"].is_monotonic_increasing
    assert rows["name"].iloc[0] == "track"
    assert rows["frequency_hz"].iloc[0] == pytest.approx(22.107571, abs=1e-5)
    assert rows["name"].is_unique  # distinct modes, distinct names: "track", "track #2", ...
    assert set(rows["name"]) >= {"track", "track #2", "truck pitch (anti-phase)", "truck pitch (in phase)",
                                 "truck bounce (in phase)", "truck bounce (anti-phase)"}
    pitch = rows[rows["name"] == "truck pitch (anti-phase)"].iloc[0]
    assert pitch["frequency_hz"] == pytest.approx(24.431591, abs=1e-5)
    assert pitch["damping_ratio"] == pytest.approx(0.140275, abs=1e-5)
