"""Issue 27 R1 and R5: ``--resume`` never mixes starts of different inputs, and a failed run leaves nothing that
blocks the next.

A campaign's store records the SHA-256 of the contents of every file its config names (a vehicle file, a measured
spectrum's CSV); a resume after any of them changed is refused naming the file, and the same resume with the file
restored goes on (so the refusal is the file's contents, not the resume).  A resume whose stored starts are not the
first starts of the config (a lowered ``n_starts``, ``lhs`` drawing anew) is refused naming the field; a lowered
``n_starts`` that the store still covers publishes exactly what a fresh run publishes.  Real ``railopt`` processes
(``faults_cli``), but for the injected run-time failures (in-process, the study's multistart replaced).
"""

from __future__ import annotations

import hashlib
import sqlite3
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from faults_cli import (
    INPUTS,
    INPUTS_LABEL,
    STUDY,
    assert_refused,
    cli,
    run_args,
    snapshot,
    start_rows,
    store_path,
    study_file,
)
from faults_cli import inputs_study as _inputs_study

from railopt.models.vehicle.loader import bundled_path
from railopt.studies.cli import STUDIES_DIR, main
from railopt.studies.config import load_study
from railopt.studies.kinds.campaign import stores as stores_module
from railopt.studies.kinds.campaign.stores import input_digests, input_files


def _published(folder: Path) -> dict[str, bytes]:
    """The published files without the campaign stores (opening a store for writing bumps its change counter;
    its rows are compared with ``start_rows``)."""
    return {k: v for k, v in snapshot(folder).items() if not k.startswith("campaigns/")}


def _with_starts(study: Path, n_starts: int) -> Path:
    text = study.read_text()
    old = next(line for line in text.splitlines() if line.startswith("n_starts = "))
    out = study.with_name(f"study_{n_starts}.toml")
    out.write_text(text.replace(old, f"n_starts = {n_starts}"))
    return out


def _scale_psd(path: Path, factor: float, rows: slice = slice(None)) -> None:
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    table[rows, 1] *= factor
    np.savetxt(path, table, delimiter=",", header="wavenumber_rad_per_m,psd_m2_per_rad_per_m", comments="")


EDITS = {
    # the slips: the body mass in the vehicle file, the spectrum's PSD scaled
    "vehicle body mass": ("coach.toml", "models[0].options.vehicle",
                          lambda p: p.write_text(p.read_text().replace("mass_kg = 32000.0", "mass_kg = 33000.0", 1))),
    "spectrum scaled": ("psd.csv", "objective.spectrum.path", lambda p: _scale_psd(p, 2.0)),
    # the same kinds the issue does not name: a damper of the vehicle file, one row of the spectrum
    "vehicle damper": ("coach.toml", "models[0].options.vehicle",
                       lambda p: p.write_text(p.read_text().replace("damping_N_s_per_m = 25000.0",
                                                                    "damping_N_s_per_m = 26000.0"))),
    "one spectrum row": ("psd.csv", "objective.spectrum.path", lambda p: _scale_psd(p, 1.01, slice(30, 31))),
}


@pytest.mark.slow
@pytest.mark.parametrize("edit", list(EDITS))
def test_resume_after_an_input_file_changed_is_refused_naming_it(edit, tmp_path):
    name, field, change = EDITS[edit]
    study = _inputs_study(tmp_path / "in", n_starts=1)
    results = tmp_path / "results"
    first = cli(*run_args(study, results))
    assert first.returncode == 0, first.stderr
    store = store_path(results, INPUTS).with_name(f"{INPUTS_LABEL}.sqlite")
    before, rows = _published(results / INPUTS), start_rows(store)
    original = (tmp_path / "in" / name).read_bytes()
    change(tmp_path / "in" / name)
    assert (tmp_path / "in" / name).read_bytes() != original
    more = _with_starts(study, 2)
    refused = cli(*run_args(more, results, "--resume"))
    line = assert_refused(refused, tmp_path / "in" / name, field, "contents changed")
    assert "--fresh" in line
    assert _published(results / INPUTS) == before and start_rows(store) == rows  # nothing mixed, nothing published
    (tmp_path / "in" / name).write_bytes(original)  # the same inputs again: the resume goes on and extends the store
    resumed = cli(*run_args(more, results, "--resume"))
    assert resumed.returncode == 0, resumed.stderr
    assert [r[0] for r in start_rows(store)] == [0, 1] and start_rows(store)[0] == rows[0]  # start 0 not redone


def test_the_store_identity_names_every_input_file_with_its_contents(tmp_path):
    """Bundled vehicles are files too (a new railopt may change them): their files are hashed like a user's."""
    _, flagship, _ = load_study(STUDIES_DIR / "cab_lateral_minimax.toml")
    files = input_files(flagship)
    assert files == {"models[0].options.vehicle": bundled_path("sd40-2")}
    study = _inputs_study(tmp_path / "in")
    _, config, _ = load_study(study)
    digests = input_digests(config)
    assert set(digests) == {"models[0].options.vehicle", "objective.spectrum.path"}
    for entry in digests.values():  # the digest is of the file's bytes (a second implementation: hashlib here)
        assert entry["sha256"] == hashlib.sha256(Path(entry["file"]).read_bytes()).hexdigest()


# ---------------------------------------------------------------------------------------------- the number of starts
def _published_tables(results: Path) -> dict[str, pd.DataFrame]:
    """The published tables a resumed and a fresh run must share (wall times and timing aside)."""
    out = {}
    for name in ("starts", "optima", "comparison"):
        df = pd.read_csv(results / STUDY / f"{name}.csv")
        out[name] = df.drop(columns=[c for c in df.columns if c.startswith("wall_time") or c == "finished_utc"])
    return out


def test_a_lowered_n_starts_is_refused_when_the_store_holds_more(tmp_path):
    study = study_file(tmp_path / "six", 6)
    results = tmp_path / "results"
    assert cli(*run_args(study, results)).returncode == 0
    rows = start_rows(store_path(results))
    assert [r[0] for r in rows] == list(range(7))  # the Den Hartog start + 6 Sobol starts
    fewer = study_file(tmp_path / "three", 3)
    refused = cli(*run_args(fewer, results, "--resume"))
    line = assert_refused(refused, "design.n_starts", store_path(results), "set n_starts to 6 or more")
    assert "more starts than a fresh run" in line
    assert start_rows(store_path(results)) == rows


def test_a_lowered_n_starts_the_store_still_covers_publishes_what_a_fresh_run_publishes(tmp_path):
    """A campaign killed after 3 of its starts, resumed with n_starts lowered to 3: exactly the fresh run's tables."""
    study = study_file(tmp_path / "six", 6)
    results = tmp_path / "results"
    assert cli(*run_args(study, results)).returncode == 0
    with sqlite3.connect(store_path(results)) as db:  # as if killed after starts 0-2
        db.execute("DELETE FROM starts WHERE start_id >= 3")
        db.execute("DELETE FROM checks")
    db.close()
    fewer = study_file(tmp_path / "three", 2)  # ids 0 (Den Hartog), 1, 2
    resumed = cli(*run_args(fewer, results, "--resume"))
    assert resumed.returncode == 0, resumed.stderr
    fresh_root = tmp_path / "fresh"
    assert cli(*run_args(fewer, fresh_root)).returncode == 0
    got, want = _published_tables(results), _published_tables(fresh_root)
    for name in want:
        pd.testing.assert_frame_equal(got[name], want[name], check_exact=True, obj=name)


def test_lhs_starts_drawn_anew_are_refused_naming_the_sampler(tmp_path):
    """The same kind: with ``sampler = "lhs"`` every start moves when n_starts changes, so a resume that extends
    the campaign would mix two samples."""
    study = study_file(tmp_path / "four", 4)
    study.write_text(study.read_text().replace('sampler = "sobol"', 'sampler = "lhs"'))
    assert 'sampler = "lhs"' in study.read_text()
    results = tmp_path / "results"
    assert cli(*run_args(study, results)).returncode == 0
    rows = start_rows(store_path(results))
    more = study_file(tmp_path / "six", 6)
    more.write_text(more.read_text().replace('sampler = "sobol"', 'sampler = "lhs"'))
    refused = cli(*run_args(more, results, "--resume"))
    assert_refused(refused, "design.sampler", "start 1", "lhs", "--fresh")
    assert start_rows(store_path(results)) == rows


# ---------------------------------------------------------------------------------------------- failed runs (R5)
def _failing_multistart(store_first: bool, exc: BaseException):
    """The study's multistart, failing with ``exc`` (after storing the first starts of the plan, ids 0 and 1:
    the Den Hartog start and the first Sobol start, when ``store_first``)."""
    real = stores_module.multistart

    def multistart(problem, n_starts, **kwargs):
        if store_first:
            real(problem, 1, **kwargs)
        raise exc

    return multistart


@pytest.mark.parametrize("exc", [ValueError("options.xtol: a run-time refusal"), KeyboardInterrupt()],
                         ids=["error", "ctrl-c"])
def test_a_run_that_fails_before_its_first_start_leaves_nothing_that_blocks_the_next(exc, tmp_path, monkeypatch,
                                                                                       capsys):
    """The issue's run-time failure (an option refused when the campaign starts) left an empty store, and the
    corrected rerun was refused ("already exists; pass --resume"); Ctrl-C before the first start is the same kind."""
    study = study_file(tmp_path / "study", 3)
    results = tmp_path / "results"
    with monkeypatch.context() as patch:
        patch.setattr(stores_module, "multistart", _failing_multistart(False, exc))
        code = main(run_args(study, results))
    assert code == (2 if isinstance(exc, ValueError) else 130)
    assert not store_path(results).exists()
    assert sorted(p.name for p in results.iterdir()) == []  # no study folder, no staging, no lock
    capsys.readouterr()
    assert main(run_args(study, results)) == 0  # neither --resume nor --fresh needed
    assert [r[0] for r in start_rows(store_path(results))] == [0, 1, 2, 3]


def test_a_run_that_fails_after_a_start_keeps_its_store_for_resume(tmp_path, monkeypatch, capsys):
    """The converse: a store holding finished starts is the resumable state, kept."""
    study = study_file(tmp_path / "study", 3)
    results = tmp_path / "results"
    with monkeypatch.context() as patch:
        patch.setattr(stores_module, "multistart", _failing_multistart(True, ValueError("boom")))
        assert main(run_args(study, results)) == 2
    kept = start_rows(store_path(results))
    assert [r[0] for r in kept] == [0, 1]
    capsys.readouterr()
    assert main(run_args(study, results, "--resume")) == 0
    rows = start_rows(store_path(results))
    assert [r[0] for r in rows] == [0, 1, 2, 3] and rows[:2] == kept  # the kept starts were not redone
