"""Result objects: array-like where they are vectors, read-only arrays, value equality, compact reprs,
``to_pandas`` and ``to_dict`` holding the same numbers as the objects."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from railopt.design import DesignVariable, MinimaxProblem, objective_surface, solve
from railopt.models.track import Beam, ImpulseLoad, lumped, moving_load, transient

from conftest import random_system

ROOT = Path(__file__).resolve().parents[1]


def test_response_maxima_is_array_like_read_only_and_comparable():
    sys_ = random_system(3, 4)
    rm = sys_.response_maxima(band_rad_s=(0.1, 2.0), exact=True)
    arr = np.asarray(rm)
    assert arr.dtype == float and arr.shape == (5,)
    np.testing.assert_array_equal(arr, rm.values)
    assert len(rm) == 5 and rm[-1] == rm.values[-1] and list(rm) == list(rm.values)
    with pytest.raises(ValueError):
        rm.values[0] = 1.0  # read-only
    assert rm == sys_.response_maxima(band_rad_s=(0.1, 2.0), exact=True)
    assert rm != sys_.response_maxima(band_rad_s=(0.1, 2.0), exact=False)
    assert len(repr(rm)) < 200 and "U=" in repr(rm)
    df = rm.to_pandas()
    np.testing.assert_array_equal(df["value"], rm.values)
    np.testing.assert_allclose(df["frequency_hz"] * 2 * np.pi, rm.frequencies, rtol=1e-15)


def test_track_results_have_compact_reprs_and_tables():
    beam = Beam(EI=6.4e6, m=136.0, k=2.07e7, c=2e4)
    sol = moving_load(beam, np.linspace(-5, 5, 601), 1.3e5, 40.0)
    assert len(repr(sol)) < 400
    with pytest.raises(ValueError):
        sol.y[0] = 0.0
    df = sol.to_pandas()
    np.testing.assert_array_equal(df["y_m"], sol.y)
    assert df.attrs["y_max_m"] == sol.y_max >= df["y_m"].max()
    assert sol == moving_load(beam, np.linspace(-5, 5, 601), 1.3e5, 40.0)

    lt = lumped(beam, 0.1)
    row = lt.to_pandas()
    assert len(repr(lt)) < 400
    assert row.iloc[0]["K_e"] == pytest.approx(2 * beam.k / beam.beta, rel=1e-14)  # (4.33): K_e = 2k/β

    tr = transient(beam, [0.0, 1.0], [0.0, 0.01, 0.02], ImpulseLoad(100.0))
    table = tr.to_pandas()
    assert len(table) == 6 and len(repr(tr)) < 400
    assert table["y_m"].to_numpy().reshape(3, 2).tolist() == tr.y.tolist()


def test_surface_and_solve_result_round_trip():
    p = MinimaxProblem([DesignVariable("a", -1, 1), DesignVariable("b", -1, 1)],
                       lambda x: np.array([x[0] ** 2 + x[1] ** 2 + 1.0, (x[0] - 0.5) ** 2 + 1.0]))
    surf = objective_surface(p, ("a", "b"), np.linspace(-1, 1, 5), np.linspace(-1, 1, 5), [0.0, 0.0])
    df = surf.to_pandas()
    assert len(df) == 25 and len(repr(surf)) < 400
    for _, r in df.iterrows():
        assert r["U"] == pytest.approx(p.value([r["a"], r["b"]]), rel=1e-14)
    r = solve(p, [0.9, 0.9])
    d = r.to_dict()
    assert d["value"] == r.value and d["x"] == r.x.tolist() and d["status"] == r.status
    again = solve(p, [0.9, 0.9])
    assert dataclasses.replace(again, wall_time=r.wall_time) == r  # value equality: same solve, same fields
    assert dataclasses.replace(again, wall_time=r.wall_time, evaluations=r.evaluations + 1) != r
    with pytest.raises(ValueError):
        r.x[0] = 2.0


def test_solve_result_repr_shows_x_value_status_and_the_whole_message():
    """Like scipy's OptimizeResult: every field in full; the numbers in the repr round-trip to the result's own."""
    p = MinimaxProblem([DesignVariable("a", -1, 1), DesignVariable("b", -1, 1)],
                       lambda x: np.array([x[0] ** 2 + x[1] ** 2 + 1.0, (x[0] - 0.5) ** 2 + 1.0]))
    r = solve(p, [0.9, 0.9])
    long_message = "NLopt failure: " + " ".join(f"step {i} rejected" for i in range(40))  # > 500 characters
    r = dataclasses.replace(r, message=long_message)
    text = repr(r)
    fields = {line.split(":", 1)[0].strip(): line.split(":", 1)[1].strip()
              for line in text.splitlines()[1:-1] if ":" in line}
    assert fields["message"] == long_message
    assert fields["status"] == r.status and fields["success"] == str(r.success)
    assert float(fields["value"]) == r.value
    np.testing.assert_array_equal(np.array(eval(fields["x"])), r.x)  # the shortest digits that round-trip
    np.testing.assert_array_equal(np.array(eval(fields["functions"])), r.functions)
    assert max(r.functions) == r.value  # U = max_k f_k, as printed


@pytest.mark.slow
def test_non_editable_install_imports_from_the_repository_root(tmp_path):
    """`pip install .` (not editable), then Python started in the repository root: the local railopt/ folder
    must not shadow the installed subpackages."""
    target = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps",
                    "--target", str(target), str(ROOT)], check=True, capture_output=True, timeout=300)
    deps = [p for p in sys.path if p.endswith("site-packages")]
    env = {"PYTHONPATH": ":".join([str(target), *deps]), "PATH": "/usr/bin:/bin"}
    code = ("import railopt, railopt.models, railopt.design, railopt.studies.cli, railopt.records;"
            "print(railopt.models.__file__)")
    # -S: no site processing, so the editable finder of this test environment is not active
    out = subprocess.run([sys.executable, "-S", "-c", code], cwd=ROOT, env=env, capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().startswith(str(target))
