"""Mode-shape figures (issue 27 item 9): every mode of a vehicle drawn on its plan view — from ``railopt vehicle ...
--modes`` and in the stability (speed_sweep) study.  Checked on the matplotlib objects: each body's displaced
rectangle against an independent reading of the eigenvector (numpy's eigenvectors of the state matrix built here,
phase set by the coordinate with the largest kinetic-energy share, constrained bodies moved by rigid-body
kinematics), never through the figure code.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.patches import Polygon

from railopt.models.vehicle import load_vehicle
from railopt.studies.cli import main, main_vehicle
from railopt.studies.output.mode_figure import plot_mode_shapes

DISPLACEMENT = 0.8


def eigenvector(system, root: complex) -> np.ndarray:
    """The displacement part of the state eigenvector nearest ``root`` (or its conjugate), scaled so the coordinate
    with the largest kinetic-energy share is 1: numpy on the state matrix built here."""
    n = system.n
    Minv = np.linalg.inv(system.M)
    G = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ system.K, -Minv @ system.C]])
    s, V = np.linalg.eig(G)
    k = int(np.argmin(np.abs(s - root)))
    v = V[:n, k] if s[k].imag >= 0 else np.conj(V[:n, k])
    e = np.real(np.conj(v) * (system.M @ v))
    return v / v[int(np.argmax(e))]


def patches(ax) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """body → (undisplaced corners, displaced corners) of one panel (each displaced rectangle, labelled with its
    body, follows its dashed undisplaced outline)."""
    polygons = [p for p in ax.patches if isinstance(p, Polygon)]
    out = {}
    for rest, moved in zip(polygons[::2], polygons[1::2], strict=True):
        assert not rest.get_label() or rest.get_label().startswith("_")
        out[moved.get_label()] = (rest.get_xy()[:4], moved.get_xy()[:4])
    return out


def panel(fig, name: str):
    axes = [ax for ax in fig.axes if ax.get_visible() and ax.get_title().split("\n")[0] == name]
    assert len(axes) == 1, [ax.get_title() for ax in fig.axes]
    return axes[0]


@pytest.fixture(scope="module")
def coach():
    vehicle = load_vehicle("manchester-coach")
    view = vehicle.lateral("rigid")
    system = view.at(speed=79.0)
    return view, system, plot_mode_shapes(view, system, "coach", displacement_m=DISPLACEMENT)


def test_one_panel_per_mode_titled_with_its_name(coach) -> None:
    view, system, fig = coach
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert len(visible) == system.n
    names = [ax.get_title().split("\n")[0] for ax in visible]
    assert len(set(names)) == len(names) and "bogie hunting (in phase)" in names
    assert fig.get_suptitle() == "coach"
    for ax in visible:
        assert ax.get_aspect() == 1.0  # a plan view: metres the same both ways
        assert "x (m" in ax.get_xlabel() and "y (m" in ax.get_ylabel()


@pytest.mark.parametrize("name", ["bogie hunting (in phase)", "bogie lateral (anti-phase)", "body yaw"])
def test_each_body_moves_by_the_modes_real_part(coach, name) -> None:
    """The bogie frames' drawn lateral displacements are, up to the one drawing scale, Re v of their coordinates
    (independent eigenvector): same sign for in phase, opposite for anti-phase; the largest corner excursion of a
    mode without roll is the drawing's 0.8 m."""
    view, system, fig = coach
    ax = panel(fig, name)
    moved = {b: m for b, (_, m) in patches(ax).items()}
    freq = float(ax.get_title().split("\n")[1].split(" Hz")[0])
    s = system.eigenvalues()
    root = s[np.argmin(np.abs(np.abs(s.imag) / (2 * np.pi) - freq) + (s.imag < 0))]
    v = eigenvector(system, root)
    places = {b.name: b.cg for b in view.bodies}
    drawn = {b: moved[b].mean(axis=0)[1] - places[b][1] for b in ("bogie_front", "bogie_rear", "body")}
    re = {b: np.real(v[system.names.index(f"{b}.v")]) for b in drawn}
    scale = drawn["bogie_front"] / re["bogie_front"]
    assert scale > 0
    for b in drawn:
        assert drawn[b] == pytest.approx(scale * re[b], abs=1e-9 + 1e-6 * DISPLACEMENT)
    if "in phase" in name:
        assert drawn["bogie_front"] * drawn["bogie_rear"] > 0
    if "anti-phase" in name:
        assert drawn["bogie_front"] * drawn["bogie_rear"] < 0
    if name == "body yaw":  # no roll: the largest drawn corner excursion is the drawing's displacement
        reach = max(float(np.max(np.linalg.norm(m - r, axis=1))) for r, m in patches(ax).values())
        assert reach == pytest.approx(DISPLACEMENT, rel=0.02)


def test_constrained_bodies_follow_their_frame_rigidly() -> None:
    """On the locomotive (wheelsets and motors are not coordinates: they ride on the truck frames) each wheelset's
    drawn lateral displacement is its frame's v − α Δz + γ Δx (small rigid-body motion, x forward, z up), read here
    from the frame's coordinates of the independent eigenvector."""
    vehicle = load_vehicle("sd40-2")
    view = vehicle.lateral("rigid")
    system = view.at(speed=33.88)
    fig = plot_mode_shapes(view, system, "sd40-2")
    ax = panel(fig, "body hunting (front truck)")
    moved = {b: m for b, (_, m) in patches(ax).items()}
    freq = float(ax.get_title().split("\n")[1].split(" Hz")[0])
    s = system.eigenvalues()
    root = s[np.argmin(np.abs(np.abs(s.imag) / (2 * np.pi) - freq) + (s.imag < 0))]
    v = np.real(eigenvector(system, root))
    places = {b.name: b.cg for b in view.bodies}
    frame = places["frame_front"]
    fv, fa, fg = (v[system.names.index(f"frame_front.{d}")] for d in ("v", "alpha", "gamma"))
    body_v = v[system.names.index("body.v")]
    scale = (moved["body"].mean(axis=0)[1] - places["body"][1]) / body_v
    for ws in ("wheelset4", "wheelset5", "wheelset6", "motor4"):
        x, _, z = places[ws]
        expected = fv - fa * (z - frame[2]) + fg * (x - frame[0])
        assert moved[ws].mean(axis=0)[1] - places[ws][1] == pytest.approx(scale * expected, abs=1e-9)
    assert {f"wheelset{i}" for i in range(1, 7)} <= set(moved)


def test_refuses_a_system_of_another_view() -> None:
    coach = load_vehicle("manchester-coach")
    with pytest.raises(ValueError, match="^system: coordinates"):
        plot_mode_shapes(coach.lateral("rigid"), coach.lateral("flexible").at(speed=20.0), "x")


def test_railopt_vehicle_modes_writes_the_figure(tmp_path: Path) -> None:
    png = tmp_path / "coach.png"
    text, code = main_vehicle(["manchester-coach", "--speed", "79", "--modes", str(png)])
    assert code == 0 and text.rstrip().endswith(f"Mode shapes: {png}")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    bad = tmp_path / "no" / "such" / "dir.png"
    text, code = main_vehicle(["sd40-2", "--modes", str(bad)])
    assert code == 2 and text.startswith(f"railopt: error: {bad}: cannot write the mode-shape figure")
    assert not bad.exists()


SWEEP = """{extra}
[study]
name = "modes_sweep"
kind = "speed_sweep"
description = "mode shapes of a speed sweep"

[[models]]
label = "wheelset"
model = "vehicle_lateral"
options = {{ vehicle = "single-wheelset", track = "rigid" }}

[speeds]
range_m_s = [5.0, 100.0]
points = 5

[critical]
range_m_s = [5.0, 300.0]
points = 8
tol_m_s = 0.05
"""


@pytest.mark.parametrize("extra", ["", "modes_speed_m_s = 40.0"])
def test_the_stability_study_draws_each_models_modes(tmp_path: Path, extra: str) -> None:
    study = tmp_path / "sweep.toml"
    study.write_text(SWEEP.format(extra=extra))
    assert main(["run", str(study), "--results", str(tmp_path / "r"), "--no-progress"]) == 0
    out = tmp_path / "r" / "modes_sweep"
    assert (out / "modes_wheelset.png").read_bytes()[:4] == b"\x89PNG"
    summary = (out / "summary.md").read_text()
    crit = pd.read_csv(out / "critical_speeds.csv")
    assert crit["vehicle"].iloc[0] == "single-wheelset (single-wheelset.toml)"
    speed = 40.0 if extra else crit["critical_speed_m_s"].iloc[0]
    assert f"![modes of wheelset at {speed:.4g} m/s](modes_wheelset.png)" in summary
