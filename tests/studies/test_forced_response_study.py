"""Study kind ``forced_response`` on a small config: its tables against the model layer, and config errors."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from railopt.models.vehicle import load_vehicle
from railopt.models.vehicle.irregularity import Irregularity
from railopt.studies.cli import STUDIES_DIR, main
from railopt.studies.config import ConfigError, load_study

HZ = 2 * np.pi

SMALL = """
[study]
name = "small_forced"
kind = "forced_response"
description = "two outputs, one band"

[[models]]
label = "r"
model = "vehicle_forced"
options = {{ vehicle = "sd40-2", track = "rigid", speed_m_s = {speed}, input = {{ amplitude_m = 0.01 }} }}

[[models]]
label = "f"
model = "vehicle_forced"
options = {{ vehicle = "sd40-2", track = "flexible", speed_m_s = 25.0, input = {{ amplitude_m = 0.01 }} }}

[[groups]]
label = "v"
rigid = "r"
flexible = "f"
panels = [
  {{ figure = "Fig 4.6", title = "Body vertical", output = "{output}" }},
  {{ figure = "Fig 4.10", title = "Motor 3 pitch", output = "motor3.beta" }},
]
bands = [{{ label = "b", band_hz = [0.01, 6.0], points = 40 }}]

[[groups]]
label = "t"
rigid = "r"
flexible = "f"
wavelength_m = 11.8872
panels = [{{ figure = "Fig 4.6", title = "Body vertical, 39 ft", output = "body.w" }}]
bands = [{{ label = "b", band_hz = [0.5, 6.0], points = 30 }}]
"""


def test_small_study_tables_match_the_model(tmp_path):
    study = tmp_path / "small_forced.toml"
    study.write_text(SMALL.format(speed=25.0, output="body.w"))
    assert main(["run", str(study), "--results", str(tmp_path / "r"), "--no-progress"]) == 0
    out = tmp_path / "r" / "small_forced"
    all_peaks = pd.read_csv(out / "peaks.csv")
    peaks = all_peaks[all_peaks["group"] == "v"].set_index("output")
    v = load_vehicle("sd40-2")
    irr = Irregularity("vertical", 0.01)
    for track, col in (("rigid", "rigid_peak"), ("flexible", "flexible_peak")):
        sys = v.vertical(track, speed=25.0).forced_system(irr, ["body.w", "motor3.beta"])
        for o in ("body.w", "motor3.beta"):
            assert peaks.loc[o, col] == pytest.approx(sys.peak(band_rad_s=(0.01 * HZ, 6.0 * HZ), output=o), rel=1e-12)
    assert peaks["certified"].all()
    assert np.allclose(peaks["flexible_over_rigid"], peaks["flexible_peak"] / peaks["rigid_peak"])
    frf = pd.read_csv(out / "frf.csv")
    low = frf[(frf["output"] == "body.w") & (frf["frequency_hz"] == 0.01)].iloc[0]
    assert low["rigid_amplitude"] == pytest.approx(0.01, rel=1e-3)  # transmissibility → 1 (L = 2.5 km)
    assert low["flexible_amplitude"] == pytest.approx(0.01, rel=1e-3)
    assert (out / "v_body_w_b.png").is_file() and (out / "summary.md").is_file()
    assert "flexible/rigid peak ratio" in (out / "summary.md").read_text()
    # the thesis's sweep (fixed wavelength, S = f L): grid maximum refined by Brent = a dense sweep's maximum
    t = all_peaks[all_peaks["group"] == "t"].iloc[0]
    assert not t["certified"]
    f = np.linspace(0.5, 6.0, 4001)
    dense = v.vertical("flexible").frequency_response(f, Irregularity("vertical", 0.01, wavelength_m=11.8872),
                                                      ["body.w"])["amplitude"].max()
    assert t["flexible_peak"] == pytest.approx(dense, rel=1e-5) and t["flexible_peak"] >= dense * (1 - 1e-12)


def test_config_errors_name_the_field(tmp_path):
    study = tmp_path / "small_forced.toml"
    study.write_text(SMALL.format(speed=25.0, output="body.wobble"))
    with pytest.raises(ConfigError, match=r"groups\[0\].panels\[0\].output: outputs: unknown output 'body.wobble'"):
        load_study(study)
    study.write_text(SMALL.format(speed=-5.0, output="body.w"))
    with pytest.raises(ConfigError, match="speed_m_s"):
        load_study(study)
    study.write_text(SMALL.format(speed=25.0, output="body.w").replace("[0.01, 6.0]", "[6.0, 0.01]"))
    with pytest.raises(ConfigError, match="band_hz"):
        load_study(study)
    study.write_text(SMALL.format(speed=25.0, output="body.w").replace("[0.01, 6.0]", "[0.0, 6.0]"))
    with pytest.raises(ConfigError, match="band_hz: .*lower edge must be > 0"):
        load_study(study)


def test_bundled_config_validates():
    kind, config, _ = load_study(STUDIES_DIR / "locomotive_vertical_response.toml")
    assert kind.name == "forced_response"
    assert [g.label for g in config.groups] == ["vertical", "lateral", "thesis_sweep"]
