"""The track study kind: config validation and a small end-to-end run."""

import tomllib
from pathlib import Path

import pandas as pd
import pytest
from pydantic import ValidationError

from railopt.studies.kind import StudyContext
from railopt.studies.kinds.track import KIND, TrackStudyConfig
from railopt.studies.output.writer import Writer

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("name", ["track_moving_load", "track_transient"])
def test_shipped_configs_validate(name):
    cfg = KIND.config_model.model_validate(tomllib.loads((ROOT / "studies" / f"{name}.toml").read_text()))
    assert cfg.study.kind == "track"
    assert cfg.figures.make


def test_bad_config_names_the_field():
    with pytest.raises(ValidationError, match="k_N_m2"):
        TrackStudyConfig.model_validate({"study": {"name": "x", "kind": "track"}, "track": {"k_N_m2": -1.0}})
    with pytest.raises(ValidationError, match="unknown_key"):
        TrackStudyConfig.model_validate(
            {"study": {"name": "x", "kind": "track"}, "track": {"unknown_key": 1}}
        )
    with pytest.raises(ValidationError, match="make"):
        TrackStudyConfig.model_validate(
            {"study": {"name": "x", "kind": "track"}, "figures": {"make": ["fig9"]}}
        )


def test_run_writes_figures_tables_and_summary(tmp_path):
    cfg = TrackStudyConfig.model_validate(
        {
            "study": {"name": "t", "kind": "track"},
            "figures": {"make": ["fig3_5_damping", "fig3_4_step"], "points": 101},
            "amplification": {
                "speed_ratios": [0.0, 0.5, 1.0],
                "damping_ratios": [0.0, 0.1],
                "axial_ratios": [0.0],
            },
        }
    )
    result = KIND.compute(cfg, StudyContext(store_dir=tmp_path))
    markdown = KIND.report(result, Writer(tmp_path))
    for f in ("fig3_5_damping.png", "fig3_4_step.png", "amplification.csv", "maxima.csv"):
        assert (tmp_path / f).exists()
    summary = dict(zip(result.table["quantity"], result.table["value"], strict=True))
    assert float(summary["f0_Hz"]) == pytest.approx(62.0, rel=1e-4)
    assert "f0" in markdown
    amp = pd.read_csv(tmp_path / "amplification.csv")
    resonant = amp[(amp.damping_ratio == 0.0) & (amp.speed_ratio == 1.0)]
    assert resonant["y_max_m"].iloc[0] == float("inf")
    assert not amp["y_max_m"].isna().any()
    maxima = pd.read_csv(tmp_path / "maxima.csv")
    assert (maxima.loc[maxima.damping_ratio > 0, "x_max_m"] < 0).all()
