"""Fault tests of API and config input: errors name the field or file; numpy scalars count as numbers."""

from __future__ import annotations

import numpy as np
import pytest
from faults_cli import study_file

from railopt.design import DesignVariable, MinimaxProblem, multistart
from railopt.studies.cli import main


@pytest.mark.parametrize("lower, upper", [(np.float32(0.5), np.float32(2.0)), (np.int64(0), np.int64(3)),
                                          (np.float64(0.5), 2), (0, np.int32(1))])
def test_design_variable_takes_numpy_scalar_bounds(lower, upper):
    v = DesignVariable("k", lower, upper)
    assert (v.lower, v.upper) == (float(lower), float(upper))
    assert type(v.lower) is float and type(v.upper) is float


@pytest.mark.parametrize("lower, field", [(True, "k.lower"), ("0", "k.lower"), (np.float32("nan"), "k.lower")])
def test_design_variable_rejects_non_numbers_naming_the_field(lower, field):
    with pytest.raises(ValueError, match=f"^{field}: must be a finite number"):
        DesignVariable("k", lower, 1.0)


def test_multistart_takes_numpy_integer_counts_and_seeds():
    problem = MinimaxProblem([DesignVariable("x", np.float32(-1), np.int64(2))], lambda x: np.array([(x[0] - 1) ** 2]))
    table = multistart(problem, np.int64(3), seed=np.int64(4))
    assert list(table["start_id"]) == [0, 1, 2]
    assert np.allclose(table["x"], 1.0, atol=1e-4)


def test_finite_differences_of_a_function_whose_length_changes_name_the_function():
    """The issue: a `jacobian` shape error was reported although no Jacobian was given."""
    calls = []

    def functions(x):
        calls.append(x)
        return np.ones(2 if len(calls) == 1 else 3) * x[0]

    problem = MinimaxProblem([DesignVariable("x", 0, 1)], functions)
    with pytest.raises(ValueError, match=r"^functions: returned 3 values at a finite-difference step, 2 at x"):
        problem.evaluate([0.5], gradient=True)


def test_a_binary_study_file_is_named(tmp_path, capsys):
    path = tmp_path / "study.toml"
    path.write_bytes(b"\x00\x9f\x92\x96 [study]\n")
    for command in (["validate", str(path)], ["run", str(path), "--results", str(tmp_path / "r"), "--workers", "0"]):
        assert main(command) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"railopt: error: {path}: not a text file") and err.count("\n") == 1, err
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize(
    "old, new, field",
    [
        ("n_starts = 16", "n_starts = true", "design.n_starts"),
        ("n_starts = 16", "n_starts = 16.0", "design.n_starts"),
        ("seed = 2002", "seed = true", "design.seed"),
        ("maxeval = 3000", "maxeval = 3000.5", "design.options.maxeval"),
        ("xtol = 1e-10", "xtol = true", "design.options.xtol"),
    ],
)
def test_validate_rejects_what_is_not_a_count_naming_the_field(old, new, field, tmp_path, capsys):
    path = study_file(tmp_path, 16)
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"railopt: error: {path}: {field}:") and err.count("\n") == 1, err


def test_solver_options_accept_numpy_numbers_and_refuse_bools():
    import numpy as np

    from railopt.design.solve import method_options

    opts = method_options("slsqp", {"xtol": np.float32(1e-8), "maxeval": np.int64(50), "maxtime": np.int32(3)})
    assert opts["xtol"] == pytest.approx(1e-8) and opts["maxeval"] == 50 and type(opts["maxeval"]) is int
    for key, bad in (("xtol", True), ("maxeval", True), ("maxeval", 2.5), ("ftol", float("nan"))):
        with pytest.raises(ValueError, match=f"^options.{key}:"):
            method_options("slsqp", {key: bad})
