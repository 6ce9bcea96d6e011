"""``railopt.studies.run_study``: a study from Python returns the tables ``railopt run`` writes, as DataFrames."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import pandas as pd
import pytest

from railopt.models.tmd import den_hartog, den_hartog_fixed_point_height, nishihara_asami
from railopt.studies import StudyRun, run_study
from railopt.studies.cli import STUDIES_DIR, main
from railopt.studies.config import ConfigError

WALL_TIMES = ["compute_s", "report_s", "total_s"]


def cli_run(study: str, results: Path) -> Path:
    assert main(["run", str(STUDIES_DIR / f"{study}.toml"), "--workers", "0", "--results", str(results),
                 "--no-progress"]) == 0
    return results / study


def assert_same_tables_as_the_cli(run: StudyRun, cli_folder: Path) -> None:
    """Every table of ``run`` is the CLI's CSV: the same text (wall times aside) and, read back, the same numbers to
    the last bit; the files are the same set."""
    assert sorted(f"{stem}.csv" for stem in run.tables) == sorted(p.name for p in cli_folder.glob("*.csv"))
    assert sorted(f"{stem}.png" for stem in run.figures) == sorted(p.name for p in cli_folder.glob("*.png"))
    for stem, frame in run.tables.items():
        written = pd.read_csv(cli_folder / f"{stem}.csv")
        if stem == "timing":
            frame, written = frame.drop(columns=WALL_TIMES), written.drop(columns=WALL_TIMES)
        else:
            assert frame.to_csv(index=False) == (cli_folder / f"{stem}.csv").read_text(), stem
        assert list(frame.columns) == list(written.columns) and len(frame) == len(written), stem
        numeric = [c for c in frame.columns if pd.api.types.is_numeric_dtype(frame[c])]
        pd.testing.assert_frame_equal(frame[numeric], written[numeric], check_exact=True, obj=f"{stem}.csv")
    assert all(path.is_file() and path.parent == run.folder for path in run.figures.values())
    assert run.summary == (run.folder / "summary.md").read_text()


def test_tmd_frf_tables_equal_the_cli_csv_and_den_hartog(tmp_path):
    run = run_study(STUDIES_DIR / "tmd_frf.toml", results=tmp_path / "api")
    assert (run.name, run.kind, run.folder) == ("tmd_frf", "frf", tmp_path / "api" / "tmd_frf")
    assert_same_tables_as_the_cli(run, cli_run("tmd_frf", tmp_path / "cli"))
    peaks = run["peaks"].set_index("design")
    # the certified band maximum (pole-residue grid + Brent) against the maximum of the closed-form |X1 k1/F|
    assert peaks.loc["den_hartog", "peak"] == pytest.approx(den_hartog(0.05).peak, rel=1e-10)
    assert peaks.loc["nishihara_asami", "peak"] == pytest.approx(nishihara_asami(0.05).peak, rel=1e-10)
    # Den Hartog's fixed points lie on every curve: no design peaks below sqrt(1 + 2/μ) = sqrt(41)
    assert peaks["peak"].min() >= den_hartog_fixed_point_height(0.05) == pytest.approx(math.sqrt(41), rel=1e-15)
    assert peaks["certified"].all()


def test_track_moving_load_tables_equal_the_cli_csv_and_the_winkler_deflection(tmp_path):
    run = run_study("track_moving_load", results=tmp_path / "api")  # a bundled study by name
    assert_same_tables_as_the_cli(run, cli_run("track_moving_load", tmp_path / "cli"))
    amp = run["amplification"]
    static = amp[(amp["speed_ratio"] == 0) & (amp["damping_ratio"] == 0) & (amp["axial_ratio"] == 0)]
    EI, k, P = 7.5935296e6, 2.0684272e7, 133446.65  # studies/track_moving_load.toml
    beta = (k / (4 * EI)) ** 0.25
    assert static["y_max_m"].iloc[0] == pytest.approx(P * beta / (2 * k), rel=1e-12)  # Hetényi: y0 = Pβ/2k


def test_default_results_folder_is_a_new_temporary_folder():
    first, second = run_study("tmd_frf"), run_study("tmd_frf")
    assert first.folder != second.folder
    for run in (first, second):
        assert run.folder.name == "tmd_frf" and (run.folder / "peaks.csv").is_file()
        assert run.folder.parent.name.startswith("railopt-")
    pd.testing.assert_frame_equal(first["peaks"], second["peaks"], check_exact=True)
    for run in (first, second):
        shutil.rmtree(run.folder.parent)


def test_a_second_run_into_the_same_folder_replaces_the_published_one(tmp_path):
    run_study("tmd_frf", results=tmp_path)
    (tmp_path / "tmd_frf" / "stale.csv").write_text("a\n1\n")
    again = run_study("tmd_frf", results=tmp_path)
    assert not (again.folder / "stale.csv").exists()  # the whole folder is swapped in, as by `railopt run`


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"workers": -1}, "workers"),
    ({"workers": 1.5}, "workers"),
    ({"workers": 2, "scheduler": "tcp://127.0.0.1:1"}, "workers, scheduler"),
    ({"resume": True, "fresh": True}, "resume, fresh"),
    ({"workers": None, "scheduler": "tcp://127.0.0.1:1", "scheduler_timeout": -1.0}, "scheduler_timeout"),
])
def test_bad_arguments_are_refused_naming_them_before_anything_is_written(tmp_path, kwargs, field):
    with pytest.raises(ValueError, match=f"^{field}:"):
        run_study("tmd_frf", results=tmp_path, **kwargs)
    assert list(tmp_path.iterdir()) == []


def test_a_bad_study_file_is_refused_naming_file_and_field(tmp_path):
    study = tmp_path / "bad.toml"
    study.write_text((STUDIES_DIR / "tmd_frf.toml").read_text().replace("points = 2000", "points = -3"))
    with pytest.raises(ConfigError, match=r"bad\.toml.*grid\.points"):
        run_study(study, results=tmp_path / "out")
    assert not (tmp_path / "out").exists()
    with pytest.raises(ConfigError, match="no_such_study"):
        run_study("no_such_study", results=tmp_path / "out")


def test_an_unknown_table_names_the_tables_there_are(tmp_path):
    run = run_study("tmd_frf", results=tmp_path)
    with pytest.raises(KeyError, match=r"'peak'.*\['frf', 'peaks', 'timing'\]"):
        run["peak"]
