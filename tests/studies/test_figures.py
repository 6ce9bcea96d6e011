"""Figures a user can read (issue 15 finding 13): titles inside the figure, y axes with unit and input amplitude,
distinct styles per curve, root loci as damping ratio and frequency against speed with the roots off the chart
counted; and the readable tables beside them (the forced-response modes named by kinetic-energy shares).
Issue 27 item 11: Pareto axes named with output and unit, the recommended design marked (above the data, legends
off it), no segment across a front's gap, root loci of every stability track with the required speed on a damping
axis that shows 0.1 %, titles naming the vehicle once; item 8: the sensitivity table in the study's order.

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
    plot_tradeoff,
    title_once,
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
    """No two labelled curves share colour, line style, marker and marker fill."""
    styles = [(*style, str(line.get_markerfacecolor()) == "none") for style, line in
              zip(curve_styles(ax), [x for x in ax.get_lines() if not x.get_label().startswith("_")], strict=True)]
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


# ---------------------------------------------------------------------------------------------- issue 27 item 11
def no_overlap(fig: Figure, ax) -> None:
    """The axes' legend lies outside the data area (beside or below the axes), so no point is hidden under it."""
    renderer = rendered(fig)
    legend = ax.get_legend().get_window_extent(renderer)
    area = ax.get_window_extent(renderer)
    assert legend.x0 >= area.x1 - 0.5 or legend.y1 <= area.y0 + 0.5, (legend, area)


def tradeoff_table(quantity: str, points: list[tuple[float, float]], feasible=None) -> pd.DataFrame:
    """A trade-off table: one design per point (variables a, b), all on the front unless said."""
    rows = [{"a": 1.0 + k, "b": 10.0 * (k + 1), "source": "sweep", "count": 1, "U": u, quantity: q,
             "feasible": True, "nondominated": True} for k, (q, u) in enumerate(points)]
    table = pd.DataFrame(rows)
    if feasible is not None:
        table["feasible"] = feasible
        table["nondominated"] = feasible
    return table


@pytest.mark.parametrize(("quantity", "unit"), [("critical_speed_m_s", "(m/s)"),
                                                ("least_damping_ratio", "dimensionless"),
                                                ("secondary_stroke_frame_front", "(m)")])
def test_pareto_axes_name_the_output_and_unit_and_mark_the_recommended_design(quantity, unit):
    table = tradeoff_table(quantity, [(1.0, 3.0), (2.0, 2.0), (3.0, 1.0)])
    u_label = "U: certified peak |cab_acceleration| (m/s² per 6.35 mm (0.25 in) lateral irregularity)"
    fig = plot_tradeoff(table, quantity, "sd40-2 (sd40-2.toml): U against " + quantity, required=2.5,
                        u_label=u_label, recommended={"a": 2.0, "b": 20.0})
    ax = fig.axes[0]
    assert ax.get_ylabel().replace("\n", " ") == u_label and "m/s²" in ax.get_ylabel()
    assert ax.get_xlabel().startswith(quantity) and unit in ax.get_xlabel()
    star = [line for line in ax.get_lines() if line.get_label().startswith("recommended design")]
    assert len(star) == 1 and (star[0].get_xdata()[0], star[0].get_ydata()[0]) == (2.0, 2.0)  # the row a=2, b=20
    assert star[0].get_zorder() > max(c.get_zorder() for c in ax.collections) and not star[0].get_clip_on()
    no_overlap(fig, ax)
    texts_inside(fig)
    # a recommended design that is not among the designs is said so, not drawn somewhere
    other = plot_tradeoff(table, quantity, "t", recommended={"a": 7.0, "b": 70.0}).axes[0]
    assert not [line for line in other.get_lines() if line.get_label().startswith("recommended")]
    assert [t.get_text() for t in other.texts] == ["the recommended design is not among these designs"]


def front_line(ax):
    return next(line for line in ax.get_lines() if line.get_label().startswith("non-dominated"))


def test_the_front_is_broken_where_the_sweep_found_no_design():
    """The issue's front: 25.2 m/s (an unconstrained start) then 37.0 m/s, the targets 26–36 m/s between them all
    answered beyond 36.98: a NaN between the two, none elsewhere; a second front of the same kind, damping ratios
    with the 0.03 target failed (its point missing), keeps the 0.0099992 point joined to the 0.01 target's."""
    table = tradeoff_table("critical_speed_m_s", [(25.17, 0.70), (36.99, 1.23), (37.38, 2.22), (40.35, 2.50)])
    ax = plot_tradeoff(table, "critical_speed_m_s", "t", targets=[26.0, 28.0, 30.0, 32.0, 34.0, 36.0]).axes[0]
    x = front_line(ax).get_xdata()
    np.testing.assert_array_equal(np.isnan(x), [False, True, False, False, False])
    assert list(x[~np.isnan(x)]) == [25.17, 36.99, 37.38, 40.35]
    table = tradeoff_table("least_damping_ratio", [(0.005, 0.95), (0.0099992, 1.07), (0.02, 1.36), (0.04, 2.46)])
    ax = plot_tradeoff(table, "least_damping_ratio", "t", targets=[0.005, 0.01, 0.02, 0.03, 0.04]).axes[0]
    np.testing.assert_array_equal(np.isnan(front_line(ax).get_xdata()), [False, False, False, True, False])
    # no targets: nothing to break on
    assert not np.isnan(front_line(plot_tradeoff(table, "least_damping_ratio", "t").axes[0]).get_xdata()).any()


def test_surface_marks_sit_above_the_contours_and_the_legends_off_them():
    from railopt.design.surface import Surface

    xi, xj = np.geomspace(1e5, 1e6, 6), np.geomspace(1e7, 1e8, 5)
    grid = Surface(("K2", "K3"), xi, xj, np.outer(xj, xi) * 1e-12, np.ones((5, 6), dtype=bool))
    corner = {"K2": 1e6, "K3": 1e7}  # the lower right corner, where the legend used to be
    fig = plot_surfaces(grid, grid, "sd40-2 (sd40-2.toml): U over K2 × K3", units=("N/m", "N/m", "m/s²"),
                        marks={"recommended": corner, "unconstrained optimum": {"K2": 1e5, "K3": 1e8}})
    contours = [ax for ax in fig.axes if ax.get_legend() is not None]
    assert len(contours) == 2
    for ax in contours:
        mark = next(line for line in ax.get_lines() if line.get_label() == "recommended")
        assert (mark.get_xdata()[0], mark.get_ydata()[0]) == (6.0, 7.0)
        assert mark.get_zorder() >= 10 and not mark.get_clip_on()
        others = [line for line in ax.get_lines() if line.get_label() == "unconstrained optimum"]
        assert all(mark.get_zorder() > o.get_zorder() for o in others)  # never hidden under another mark
        no_overlap(fig, ax)


@pytest.fixture(scope="module")
def coach_loci() -> dict[str, pd.DataFrame]:
    coach = load_vehicle("manchester-coach")
    speeds = np.linspace(60.0, 90.0, 7)
    return {label: pd.concat([root_locus(v.lateral(track), speeds).to_pandas().assign(track=track)
                              for track in ("rigid", "flexible")])
            for label, v in (("before", coach), ("after", coach.with_parameters({"conicity": 0.1})))}


def test_root_loci_show_both_tracks_the_required_speed_and_a_tenth_of_a_per_cent(coach_loci):
    fig = plot_root_loci_before_after(coach_loci, "coach (manchester-coach.toml): root loci", required_speed=75.0)
    ax_z, ax_f = fig.axes
    labels = [line.get_label() for line in ax_z.get_lines()]
    assert {"before, rigid track", "before, flexible track", "after, rigid track", "after, flexible track"} <= \
        set(labels)
    flexible = next(line for line in ax_z.get_lines() if line.get_label() == "after, flexible track")
    assert flexible.get_markerfacecolor() == "none"  # the second track: open markers, same colour
    required = [line for line in ax_z.get_lines() if line.get_label().startswith("required speed")]
    assert len(required) == 1 and list(required[0].get_xdata()) == [75.0, 75.0]
    assert any(list(line.get_xdata()) == [75.0] for line in ax_z.get_lines())  # the marker on ζ = 0
    assert ax_z.get_yscale() == "symlog"
    # 0.1 % stands apart from 0 and from 1 %: at least 5 % of the axis height each
    to_axes = ax_z.transScale + ax_z.transLimits
    y0, y1, y10 = (to_axes.transform((0.0, z))[1] for z in (0.0, 1e-3, 1e-2))
    assert y1 - y0 > 0.05 and y10 - y1 > 0.05
    distinct(ax_z)
    texts_inside(fig)


def test_the_speed_sweep_locus_has_the_same_damping_axis_and_names_the_vehicle(flexible_locus):
    locus = flexible_locus.assign(model="a")
    critical = pd.DataFrame({"model": ["a"], "vehicle": ["sd40-2 (sd40-2.toml)"], "critical_speed_m_s": [33.168],
                             "critical_speed_mph": [74.19], "mode": ["body hunting (front truck)"]})
    fig = plot_root_locus(locus, critical)
    ax_z = fig.axes[0]
    assert ax_z.get_yscale() == "symlog"
    assert ax_z.get_title().replace("\n", " ") == \
        "a — sd40-2 (sd40-2.toml): critical speed 33.17 m/s (74.2 mph), body hunting (front truck)"


@pytest.mark.parametrize(("title", "expected"), [
    ("sd40-2: sd40-2 cab model, ±0.25 in lateral irregularity", "sd40-2 cab model, ±0.25 in lateral irregularity"),
    ("coach: coach (coach.toml), lateral, rigid track", "coach (coach.toml), lateral, rigid track"),
    ("a: sd40-2 cab model", "a: sd40-2 cab model"),
    ("sd40-2: sd40-2x model", "sd40-2: sd40-2x model"),
])
def test_titles_name_the_vehicle_once(title, expected):
    assert title_once(title) == expected
    f = np.linspace(0.0, 3.0, 5)
    fig = plot_frf_panels([(title, "|x| (m)", [("c", f, f, "ref")])])
    assert fig.axes[0].get_title().replace("\n", " ") == expected


def test_the_stability_map_names_each_vehicle(flexible_locus):
    from railopt.studies.output.map_figure import plot_stability_map

    damping = pd.DataFrame({"model": ["a"] * 3, "speed_m_s": [10.0, 20.0, 30.0],
                            "spectral_abscissa": [-1.0, -0.5, 0.2]})
    maps = pd.DataFrame({"model": ["a", "a"], "start_m_s": [1.0, 28.0], "end_m_s": [28.0, 40.0],
                         "state": ["stable", "unstable"]})
    fig = plot_stability_map(damping, maps, "study: stability map", vehicles={"a": "sd40-2 (sd40-2.toml)"})
    assert fig.axes[0].get_lines()[0].get_label() == "a (sd40-2 (sd40-2.toml)): max Re s"


# ---------------------------------------------------------------------------------------------- issue 27 item 8
@pytest.mark.parametrize("factors", [[2.0, 0.0, 0.5, 1.0], [0.0, 1.0], [1.0, 0.5, 0.25]])
def test_the_sensitivity_table_keeps_the_studys_order(factors):
    """Rows in the order the study lists the factors (a damper switched off, 0.0, included) for every model; the
    values are each model's own."""
    from railopt.studies.kinds.speed_sweep import sensitivity_pivot

    rows = [{"parameter": p, "factor": f, "model": m, "critical_speed_m_s": (np.inf if f == 0.0 else 10.0 * f + k)}
            for k, m in enumerate(["rigid", "flexible"]) for p, fs in (("csy", factors), ("conicity", [3.0, 1.0]))
            for f in fs]
    pivot = sensitivity_pivot(pd.DataFrame(rows))
    assert list(pivot.columns) == ["parameter", "factor", "rigid", "flexible"]
    assert list(zip(pivot["parameter"], pivot["factor"], strict=True)) == \
        [("csy", f) for f in factors] + [("conicity", 3.0), ("conicity", 1.0)]
    for _, r in pivot.iterrows():
        expected = np.inf if r["factor"] == 0.0 else 10.0 * r["factor"]
        assert (r["rigid"], r["flexible"]) == (expected, expected + 1)
