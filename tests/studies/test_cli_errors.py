"""The one error line ``railopt: error: FILE: field.path: message``, numbers the config layer refuses, full disks,
warnings of a kind and progress in logs: each through the real CLI (in-process ``main`` or a subprocess)."""

from __future__ import annotations

import io
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import pytest
from faults_cli import study_file

from railopt.studies.cli import main
from railopt.studies.config import ConfigError, StrictModel, StudyHeader, field_errors, load_study
from railopt.studies.kind import KINDS, StudyKind, register_kind
from railopt.studies.output.progress import Progress
from railopt.studies.output.writer import Writer

CLI = [sys.executable, "-m", "railopt.studies.cli"]
FAULTS = Path("/work/shared/faults")
WHEELSET = Path(__file__).resolve().parents[2] / "models" / "vehicle" / "data" / "single-wheelset.toml"

SWEEP = """[study]
name = "ws"
kind = "speed_sweep"

[[models]]
label = "car"
model = "vehicle_lateral"
options = {{ vehicle = "{vehicle}", track = "rigid"{extra} }}

[speeds]
range_m_s = [5.0, 120.0]
points = {points}

[critical]
range_m_s = [5.0, 300.0]
points = 16
"""


def sweep(folder: Path, vehicle: str = "car.toml", extra: str = "", points: str = "12", name="ws.toml") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(SWEEP.format(vehicle=vehicle, extra=extra, points=points))
    return path


def run_cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([*CLI, *args], capture_output=True, text=True, cwd=cwd, timeout=300)


def one_error(err: str) -> str:
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("railopt: error: "), err
    assert "(top level)" not in err and "Traceback" not in err, err
    return lines[0]


# ---------------------------------------------------------------------------------------------- the error line
def test_option_error_names_file_and_field_once(tmp_path, capsys):
    """Was `railopt: error: (top level): models[0].options: models[0].options.speed_m_s: ...`."""
    (tmp_path / "car.toml").write_text(WHEELSET.read_text())
    path = sweep(tmp_path, extra=", speed_m_s = -3.0")
    assert main(["validate", str(path)]) == 2
    line = one_error(capsys.readouterr().err)
    assert line == f"railopt: error: {path}: models[0].options.speed_m_s: Input should be greater than 0 (got -3.0)"


def test_field_errors_drop_a_repeated_or_empty_path():
    assert field_errors(ValueError("models[0].options: models[0].options.speed_m_s: too low")) == \
        "models[0].options.speed_m_s: too low"
    assert field_errors(ValueError("a.b: a.b: x"), "") == "a.b: x"
    assert field_errors(ValueError("no field here"), "") == "no field here"


def test_study_field_error_line_is_exact(tmp_path, capsys):
    path = study_file(tmp_path, 4)
    path.write_text(path.read_text().replace("n_starts = 4", "n_starts = 0"))
    assert main(["validate", str(path)]) == 2
    line = one_error(capsys.readouterr().err)
    assert line == f"railopt: error: {path}: design.n_starts: Input should be greater than 0 (got 0)"


def test_unknown_kind_and_missing_kind_name_the_file(tmp_path, capsys):
    path = study_file(tmp_path, 4)
    path.write_text(path.read_text().replace('kind = "campaign"', 'kind = "campain"'))
    assert main(["validate", str(path)]) == 2
    assert one_error(capsys.readouterr().err).startswith(
        f"railopt: error: {path}: study.kind: unknown kind 'campain'; did you mean 'campaign'?")
    path.write_text('[study]\nname = "x"\n')
    assert main(["validate", str(path)]) == 2
    assert one_error(capsys.readouterr().err) == (
        f"railopt: error: {path}: study.kind: missing; every study file needs a [study] table with name and kind")


def test_bad_vehicle_file_in_a_study_names_study_field_and_vehicle_file(tmp_path, capsys):
    (tmp_path / "car.toml").write_text(WHEELSET.read_text() + "\n[trak]\n")
    path = sweep(tmp_path)
    assert main(["validate", str(path)]) == 2
    line = one_error(capsys.readouterr().err)
    assert line.startswith(f"railopt: error: {path}: models[0].options: {tmp_path / 'car.toml'}: "), line
    assert "trak: unknown table or key at the top level; did you mean 'track'?" in line


def test_neither_study_nor_vehicle_is_named(tmp_path, capsys):
    path = tmp_path / "x.toml"
    path.write_text("a = 1\n")
    assert main(["validate", str(path)]) == 2
    assert one_error(capsys.readouterr().err) == (
        f"railopt: error: {path}: neither a study file (no [study] table with name and kind) nor a vehicle file "
        "(no [vehicle] table)")


# ---------------------------------------------------------------------------------------------- paths in a study
def test_relative_vehicle_path_resolves_from_the_study_folder_from_any_cwd(tmp_path):
    project = tmp_path / "project"
    folder = project / "studies"
    folder.mkdir(parents=True)
    (folder / "car.toml").write_text(WHEELSET.read_text())
    path = sweep(folder)
    from_root = run_cli("validate", "studies/ws.toml", cwd=project)
    from_folder = run_cli("validate", "ws.toml", cwd=folder)
    assert (from_root.returncode, from_root.stdout) == (0, "studies/ws.toml: valid speed_sweep study 'ws'\n"), \
        from_root.stderr
    assert (from_folder.returncode, from_folder.stdout) == (0, "ws.toml: valid speed_sweep study 'ws'\n"), \
        from_folder.stderr
    _, config, raw = load_study(path)
    assert config.models[0].options["vehicle"] == str(folder / "car.toml")
    # the same study from elsewhere, and with an absolute path, and with a bundled name
    assert run_cli("validate", str(path), cwd=tmp_path).returncode == 0
    absolute = sweep(tmp_path / "elsewhere", vehicle=str(folder / "car.toml"))
    assert run_cli("validate", str(absolute), cwd=project).returncode == 0
    bundled = sweep(tmp_path / "bundled", vehicle="single-wheelset")
    _, config, _ = load_study(bundled)
    assert config.models[0].options["vehicle"] == "single-wheelset"


def test_relative_path_missing_from_the_study_folder_is_refused_naming_it(tmp_path):
    (tmp_path / "car.toml").write_text(WHEELSET.read_text())  # in the cwd, not beside the study
    path = sweep(tmp_path / "sub")
    done = run_cli("validate", "sub/ws.toml", cwd=tmp_path)
    assert done.returncode == 2
    line = one_error(done.stderr)
    assert line.startswith(f"railopt: error: sub/ws.toml: models[0].options: {path.parent / 'car.toml'}: "
                           "no such vehicle file"), line


def test_run_of_a_study_with_a_relative_vehicle_from_the_project_root(tmp_path):
    """Same numbers from either folder: the wheelset's critical speed (Routh-Hurwitz case of the model layer)."""
    from railopt.models.stability import critical_speed
    from railopt.models.vehicle import load_vehicle

    folder = tmp_path / "studies"
    folder.mkdir()
    (folder / "car.toml").write_text(WHEELSET.read_text())
    sweep(folder)
    speeds = []
    for cwd, arg in ((tmp_path, "studies/ws.toml"), (folder, "ws.toml")):
        done = run_cli("run", arg, "--workers", "0", "--no-progress", "--results", str(tmp_path / f"r{len(speeds)}"),
                       cwd=cwd)
        assert done.returncode == 0, done.stderr
        table = pd.read_csv(tmp_path / f"r{len(speeds)}" / "ws" / "critical_speeds.csv")
        speeds.append(float(table["critical_speed_m_s"].iloc[0]))
    model = load_vehicle(str(folder / "car.toml")).lateral(track="rigid")
    expected = critical_speed(model, speed_range=(5.0, 300.0), tol=0.01, grid=16).speed
    assert speeds[0] == speeds[1] == pytest.approx(expected, abs=1e-9)


# ---------------------------------------------------------------------------------------------- numbers
def _cases(path: Path) -> dict[str, tuple[str, str, str]]:
    return {
        "seed beyond int64": ("seed = 2002", f"seed = {2**63}", "design.seed: must be at most 9223372036854775807"),
        "seed 2**70": ("seed = 2002", f"seed = {2**70}", "design.seed: must be at most 9223372036854775807"),
        "maxeval 2**40": ("maxeval = 3000", f"maxeval = {2**40}", "design.options.maxeval: must be at most 2147483647"),
        "maxeval 2**31": ("maxeval = 3000", f"maxeval = {2**31}", "design.options.maxeval: must be at most 2147483647"),
        "maxeval 1e10": ("maxeval = 3000", "maxeval = 1e10", "design.options.maxeval: Input should be a valid integer"),
        "n_starts 1e20": ("n_starts = 4", "n_starts = 1e20", "design.n_starts: Input should be a valid integer"),
        "n_starts 10**7+1": ("n_starts = 4", f"n_starts = {10**7 + 1}", "design.n_starts: must be at most 10000000"),
        "lower as string": ("lower = 0.5", 'lower = "1e5"',
                            "design.variables.0.lower: must be a number, not a string (got '1e5')"),
        "band as strings": ("band_hz = [1.0, 3.0]", 'band_hz = ["1", "3"]',
                            "objective.band_hz: [0]: must be a number, not a string (got '1')"),
        "option as string": ("mass_ratio = 0.05,", 'mass_ratio = "0.05",',
                             "models[0].options.mass_ratio: must be a number, not a string (got '0.05')"),
        "xtol as string": ("xtol = 1e-10", 'xtol = "1e-10"',
                           "design.options.xtol: must be a number, not a string (got '1e-10')"),
        "4301-digit seed": ("seed = 2002", "seed = " + "9" * 4301,
                            "design.seed: integer too long to read (Exceeds the limit (4300 digits)"),
        "4400-digit option": ("primary_mass_kg = 1000.0", "primary_mass_kg = 1" + "0" * 4400,
                              "models.options.primary_mass_kg: integer too long to read"),
    }


@pytest.mark.parametrize("case", sorted(_cases(Path())))
def test_oversized_and_mistyped_numbers_are_refused_naming_the_field(case, tmp_path, capsys):
    old, new, message = _cases(tmp_path)[case]
    path = study_file(tmp_path, 4)
    text = path.read_text()
    assert old in text, old
    path.write_text(text.replace(old, new, 1))
    results = tmp_path / "results"
    for command in (["validate", str(path)], ["run", str(path), "--workers", "0", "--results", str(results)]):
        assert main(command) == 2
        line = one_error(capsys.readouterr().err)
        assert line.startswith(f"railopt: error: {path}: {message}"), line
    assert not results.exists()


@pytest.mark.parametrize("old, new", [("seed = 2002", f"seed = {2**63 - 1}"),
                                      ("maxeval = 3000", f"maxeval = {2**31 - 1}"),
                                      ("n_starts = 4", f"n_starts = {10**7}")])
def test_numbers_at_their_limit_validate(old, new, tmp_path, capsys):
    path = study_file(tmp_path, 4)
    path.write_text(path.read_text().replace(old, new, 1))
    assert main(["validate", str(path)]) == 0, capsys.readouterr().err


def test_strings_for_numbers_refused_in_other_kinds(tmp_path, capsys):
    (tmp_path / "car.toml").write_text(WHEELSET.read_text())
    path = sweep(tmp_path, points='"12"')
    assert main(["validate", str(path)]) == 2
    assert one_error(capsys.readouterr().err) == (
        f"railopt: error: {path}: speeds.points: must be a number, not a string (got '12')")
    path = sweep(tmp_path, extra=', speed_m_s = "30"', name="ws2.toml")
    assert main(["validate", str(path)]) == 2
    assert one_error(capsys.readouterr().err) == (
        f"railopt: error: {path}: models[0].options.speed_m_s: must be a number, not a string (got '30')")
    path = sweep(tmp_path, extra=', parameters = { yaw_stiffness = "5e5" }', name="ws3.toml")
    assert main(["validate", str(path)]) == 2
    assert one_error(capsys.readouterr().err) == (
        f"railopt: error: {path}: models[0].options.parameters: yaw_stiffness: must be a number, not a string "
        "(got '5e5')")


@pytest.mark.parametrize("name, field", [("toml_seed_beyond_int64.toml", "design.seed"),
                                         ("toml_maxeval_beyond_c_int.toml", "design.options.maxeval"),
                                         ("toml_integer_over_4300_digits.toml", "design.seed"),
                                         ("F05_strings_accepted_as_numbers.toml", "models[0].options.amplitude_in")])
def test_shared_fault_files_are_refused_by_validate_and_run(name, field, tmp_path):
    fault = FAULTS / name
    if not fault.is_file():
        pytest.skip(f"{fault} not present")
    results = tmp_path / "results"
    for args in (["validate", str(fault)], ["run", str(fault), "--workers", "0", "--results", str(results)]):
        done = run_cli(*args)
        assert done.returncode == 2, done.stderr
        assert one_error(done.stderr).startswith(f"railopt: error: {fault}: {field}: "), done.stderr
    assert not results.exists()


# ---------------------------------------------------------------------------------------------- warnings of a kind
class _ProbeConfig(StrictModel):
    study: StudyHeader
    value: float


@dataclass
class _ProbeResult:
    table: pd.DataFrame


@pytest.fixture
def probe_kind():
    kind = register_kind(StudyKind(
        name="warning_probe", config_model=_ProbeConfig,
        compute=lambda cfg, ctx: _ProbeResult(pd.DataFrame({"value": [cfg.value * 2]})),
        report=lambda result, writer: (writer.table(result.table, "values"), "# probe\n")[1],
        summary="probe", warnings=lambda cfg: [f"value {cfg.value:g} is above 1"] * (cfg.value > 1)))
    yield kind
    KINDS.pop("warning_probe", None)


def test_kind_warnings_are_printed_by_validate_and_run_without_changing_the_exit_code(probe_kind, tmp_path, capsys):
    path = tmp_path / "probe.toml"
    path.write_text('value = 2.5\n[study]\nname = "probe"\nkind = "warning_probe"\n')
    assert main(["validate", str(path)]) == 0
    out = capsys.readouterr()
    assert out.err == f"railopt: warning: {path}: value 2.5 is above 1\n"
    assert out.out == f"{path}: valid warning_probe study 'probe'\n"
    assert main(["run", str(path), "--workers", "0", "--results", str(tmp_path / "r")]) == 0
    out = capsys.readouterr()
    assert out.err.splitlines()[0] == f"railopt: warning: {path}: value 2.5 is above 1"
    assert pd.read_csv(tmp_path / "r" / "probe" / "values.csv")["value"].tolist() == [5.0]
    path.write_text('value = 0.5\n[study]\nname = "probe"\nkind = "warning_probe"\n')
    assert main(["validate", str(path)]) == 0
    assert capsys.readouterr().err == ""


# ---------------------------------------------------------------------------------------------- full disk
def test_a_failed_write_names_the_file_and_publishes_nothing(tmp_path, capsys, monkeypatch):
    import errno

    def full(self, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    study, results = study_file(tmp_path, 2), tmp_path / "results"
    monkeypatch.setattr(pd.DataFrame, "to_csv", full)
    assert main(["run", str(study), "--workers", "0", "--no-progress", "--results", str(results)]) == 2
    line = one_error(capsys.readouterr().err)
    assert re.fullmatch(rf"railopt: error: results: cannot write {re.escape(str(results))}/\.staging-tmd_hinf-\d+/"
                        r"comparison\.csv: No space left on device; free space or choose another --results "
                        r"\(the published results are unchanged\)", line), line
    assert sorted(p.name for p in results.iterdir()) == ["tmd_hinf"]  # the store only: no staging left
    assert sorted(p.name for p in (results / "tmd_hinf").iterdir()) == ["campaigns"]


def test_writer_names_the_file_it_cannot_write(tmp_path):
    from railopt.studies.output.publish import ResultsError

    blocked = tmp_path / "out"
    blocked.write_text("a file where a folder must be")
    with pytest.raises(ResultsError, match=rf"^results: cannot write {re.escape(str(blocked))}"):
        Writer(blocked).table(pd.DataFrame({"a": [1]}), "t")


@pytest.mark.skipif(not hasattr(__import__("os"), "geteuid") or __import__("os").geteuid() != 0
                    or not Path("/bin/mount").exists(), reason="needs root to mount a small tmpfs")
def test_full_tmpfs_names_the_staging_file(tmp_path):
    full = tmp_path / "full"
    full.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=100k", "tmpfs", str(full)]).returncode != 0:
        pytest.skip("cannot mount tmpfs here")
    try:
        study = study_file(tmp_path, 2)
        done = run_cli("run", str(study), "--workers", "0", "--no-progress", "--results", str(full))
        assert done.returncode == 2, done.stderr
        line = [x for x in done.stderr.splitlines() if x.startswith("railopt: error:")]
        assert len(line) == 1 and "No space left on device" in line[0] and str(full) in line[0], done.stderr
        assert not any(p.name.startswith(".staging") for p in full.iterdir())
    finally:
        subprocess.run(["umount", str(full)])


# ---------------------------------------------------------------------------------------------- progress
def test_progress_in_a_log_is_plain_periodic_lines():
    stream = io.StringIO()
    bar = Progress("mu0.05-exact-slsqp", stream=stream)
    assert not bar.terminal
    for done in range(1, 101):
        bar.update(done, 100)
    bar.close()
    text = stream.getvalue()
    assert "\r" not in text
    lines = text.splitlines()
    assert lines == [f"mu0.05-exact-slsqp: {k}/100 starts ({k} %)" for k in range(10, 101, 10)]


def test_progress_in_a_log_writes_after_the_interval_and_the_final_count(monkeypatch):
    import railopt.studies.output.progress as progress

    clock = iter([0.0, 1.0, 40.0, 41.0, 42.0, 43.0])
    monkeypatch.setattr(progress.time, "monotonic", lambda: next(clock))
    stream = io.StringIO()
    bar = Progress("c", stream=stream, steps=1)  # no lines by fraction before the end
    bar.update(1, 1000)  # t = 1: too early
    bar.update(2, 1000)  # t = 40: 30 s passed
    bar.update(3, 1000)  # t = 41
    bar.close()  # the final count
    assert stream.getvalue().splitlines() == ["c: 2/1000 starts (0 %)", "c: 3/1000 starts (0 %)"]


def test_progress_disabled_writes_nothing():
    stream = io.StringIO()
    with Progress("c", stream=stream, enabled=False) as bar:
        bar.update(5, 10)
    assert stream.getvalue() == ""


def test_run_with_stderr_a_pipe_writes_no_carriage_returns(tmp_path):
    study = study_file(tmp_path, 20)
    done = run_cli("run", str(study), "--workers", "0", "--results", str(tmp_path / "r"))
    assert done.returncode == 0, done.stderr
    assert "\r" not in done.stderr
    progress_lines = [x for x in done.stderr.splitlines() if x.startswith("mu0.05-exact-slsqp: ")]
    assert progress_lines[-1] == "mu0.05-exact-slsqp: 21/21 starts (100 %)"
    assert 2 <= len(progress_lines) <= 11
    table = pd.read_csv(tmp_path / "r" / "tmd_hinf" / "comparison.csv")
    assert table["U_objective"].iloc[0] == pytest.approx(6.407921, abs=1e-6)  # Nishihara-Asami, closed form


def test_load_study_error_is_a_config_error_naming_the_file(tmp_path):
    path = study_file(tmp_path, 4)
    path.write_text(path.read_text().replace("seed = 2002", f"seed = {2**64}"))
    with pytest.raises(ConfigError, match=rf"^{re.escape(str(path))}: design\.seed: must be at most"):
        load_study(path)


def test_progress_on_a_terminal_redraws_at_most_once_per_minimum_interval():
    """A redraw per finished start bypassed tqdm's minimum interval (112 redraws for 100 starts)."""
    stream = io.StringIO()
    bar = Progress("c", stream=stream, terminal=True, mininterval=60.0)
    for done in range(1, 101):
        bar.update(done, 100)
    bar.close()
    text = stream.getvalue()
    assert text.count("\r") <= 3, text
    assert "100%" in text.split("\r")[-1]
