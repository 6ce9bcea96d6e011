"""label_clusters against the rule written out by hand: the successful starts taken from the best U (ties: the lower
start id), each joining the first representative within xtol (∞-norm in unit-cube coordinates) or becoming the next."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from railopt.design import DesignVariable, MinimaxProblem
from railopt.design.multistart import label_clusters


def _problem() -> MinimaxProblem:
    variables = [DesignVariable("k", 1e3, 1e7, scale="log"), DesignVariable("c", 0.0, 2.0)]
    return MinimaxProblem(variables, lambda x: np.array([x[1]]))


def _by_hand(rows: list[dict], xtol: float) -> dict[int, int]:
    """start_id → cluster, in plain Python (log10 for the log variable, as the unit cube maps it)."""
    def u(r):
        return ((math.log10(r["k"]) - 3.0) / 4.0, r["c"] / 2.0)

    ok = [r for r in rows if r["status"] == "converged" and r["constraint_violation"] <= 1e-6
          and r["bound_violation"] <= 1e-6 and math.isfinite(r["value"])]
    reps, out = [], {r["start_id"]: -1 for r in rows}
    for r in sorted(ok, key=lambda r: (r["value"], r["start_id"])):
        for j, rep in enumerate(reps):
            if max(abs(a - b) for a, b in zip(u(r), rep, strict=True)) <= xtol:
                out[r["start_id"]] = j
                break
        else:
            reps.append(u(r))
            out[r["start_id"]] = len(reps) - 1
    return out


def test_clusters_equal_the_rule_by_hand_on_random_tables() -> None:
    rng = np.random.default_rng(7)
    problem = _problem()
    for trial in range(20):
        n = int(rng.integers(1, 120))
        centres = rng.uniform(0.0, 1.0, (int(rng.integers(1, 6)), 2))
        which = rng.integers(0, len(centres), n)
        uu = np.clip(centres[which] + rng.normal(0.0, 4e-4, (n, 2)), 0.0, 1.0)
        rows = []
        for i in range(n):
            value = float(np.round(rng.uniform(0.0, 3.0), 1))  # rounded: many ties in U, broken by the start id
            rows.append({"start_id": int(1000 - 3 * i), "k": 10 ** (3.0 + 4.0 * uu[i, 0]), "c": 2.0 * uu[i, 1],
                         "value": [value, math.inf, math.nan][int(rng.choice(3, p=[0.85, 0.1, 0.05]))],
                         "status": str(rng.choice(["converged", "maxeval"], p=[0.9, 0.1])),
                         "constraint_violation": float(rng.choice([0.0, 1e-3], p=[0.9, 0.1])),
                         "bound_violation": 0.0})
        table = pd.DataFrame(rows, index=rng.permutation(n) + 50)  # an index that is not 0..n−1
        got = label_clusters(table, problem, xtol=1e-3)
        want = _by_hand(rows, 1e-3)
        assert dict(zip(got["start_id"], got["cluster"], strict=True)) == want, trial
        assert list(got.index) == list(table.index)
        # clusters are numbered by their best U
        best = got[got["cluster"] >= 0].groupby("cluster")["value"].min()
        assert list(best.index) == sorted(best.index) and best.is_monotonic_increasing
