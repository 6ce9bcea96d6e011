"""The rule a fresh run of a bundled study is held to against its committed reference under ``results/``.

Since the compiled kernels (issue 25) the references are compared at the optimiser's tolerance, not bit for bit:

* U — every column that holds a band maximum (``U``, ``value``, ``…_U``, ``…_peak``, ``peak…``, ``before``/``after``):
  1e-9 relative;
* every other real number (design variables, speeds, damping ratios, the solver's epigraph variable ``t``, …):
  1e-6 relative — designs are what the optimiser fixes to its tolerance, and the quantities derived from a design
  inherit it;
* constraint and bound violations (zero when met): 1e-9 absolute;
* relative changes (columns named ``change…`` or ``…_change_…``, and ``objective_underestimate``): 1e-6
  absolute — they are differences of nearly equal numbers, fractions of a reference, and round-off of a zero
  change has no meaningful relative size;
* counts of distinct optima, start counts, statuses, flags, labels and every other non-real column: exactly;
* the certificate's grid size (``grid_points``, a diagnostic): within 5 % — a bisection sitting at its threshold
  or an exact duplicate adds or drops a point at round-off;
* wall times and timestamps (``wall_time…``, ``finished_utc``), evaluation counts (``evaluations``: the optimiser's
  path, which rounding may lengthen or shorten by a step) in every table, timing.csv, and which start represents
  an optimum (``start_id``/``best_start`` outside starts.csv: a tie between starts that reached the same design,
  broken at round-off) are left out; so are summary.md and the figures (they print these tables).

docs/reliability.md states the same rule for readers.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

U_COLUMNS = {"U", "value", "before", "after", "before_in", "after_in", "amplitude"}
U_RTOL = 1e-9
DESIGN_RTOL = 1e-6
CHANGE_ATOL = 1e-6
VIOLATION_ATOL = 1e-9
GRID_RTOL = 0.05
VOLATILE = {"timing.csv"}


def _volatile(column: str, table: str) -> bool:
    representative = table != "starts" and column in {"start_id", "best_start"}
    return column.startswith("wall_time") or column in {"finished_utc", "evaluations"} or representative


def _is_u(column: str) -> bool:
    """A band maximum: U, an optimum's value, a peak (``…_U``, ``…_peak``, ``peak…``), a before/after peak."""
    return column in U_COLUMNS or column.endswith(("_U", "_peak")) or column.startswith("peak")


def _is_violation(column: str) -> bool:
    return column in {"constraint_violation", "bound_violation"}


def _is_change(column: str) -> bool:
    return column.startswith("change") or "_change_" in column or column == "objective_underestimate"


def tables(folder: Path) -> dict[str, pd.DataFrame]:
    """Every CSV of a study folder but timing.csv, without wall times, timestamps and evaluation counts."""
    out = {}
    for path in sorted(folder.glob("*.csv")):
        if path.name not in VOLATILE:
            df = pd.read_csv(path)
            out[path.stem] = df.drop(columns=[c for c in df.columns if _volatile(c, path.stem)])
    return out


def differences(fresh: pd.DataFrame, committed: pd.DataFrame) -> list[str]:
    """Cells of ``fresh`` outside the rule against ``committed`` (same shape and columns), as readable lines."""
    if list(fresh.columns) != list(committed.columns) or len(fresh) != len(committed):
        return [f"shape or columns differ: {fresh.shape} {list(fresh.columns)} vs {committed.shape} "
                f"{list(committed.columns)}"]
    out = []
    for column in committed.columns:
        a, b = fresh[column], committed[column]
        numeric = all(pd.api.types.is_numeric_dtype(c) and not pd.api.types.is_bool_dtype(c) for c in (a, b))
        if numeric and (column == "grid_points" or pd.api.types.is_float_dtype(b) or pd.api.types.is_float_dtype(a)):
            x, y = a.to_numpy(float), b.to_numpy(float)
            rtol, atol = ((0.0, CHANGE_ATOL) if _is_change(column) else (0.0, VIOLATION_ATOL) if _is_violation(column)
                          else (GRID_RTOL, 0.0) if column == "grid_points"
                          else (U_RTOL if _is_u(column) else DESIGN_RTOL, 0.0))
            bad = ~np.isclose(x, y, rtol=rtol, atol=atol, equal_nan=True)
            out += [f"{column}[{i}]: {x[i]!r} vs {y[i]!r} (|Δ| {abs(x[i] - y[i]):.1e}, rel "
                    f"{abs(x[i] - y[i]) / max(abs(y[i]), 1e-300):.1e}; rtol {rtol:g}, atol {atol:g})"
                    for i in np.flatnonzero(bad)]
        elif not a.equals(b):
            both_empty = (a.isna() & b.isna()).to_numpy()
            unequal = (a.astype(str) != b.astype(str)).to_numpy() & ~both_empty
            out += [f"{column}[{i}]: {a.iloc[i]!r} vs {b.iloc[i]!r} (exact)" for i in np.flatnonzero(unequal)]
    return out


def assert_matches_reference(fresh_folder: Path, committed_folder: Path) -> None:
    """Assert that every table of a fresh run matches the committed reference under the rule."""
    fresh, committed = tables(fresh_folder), tables(committed_folder)
    assert sorted(fresh) == sorted(committed)
    problems = [f"{name}.{line}" for name in committed for line in differences(fresh[name], committed[name])]
    assert not problems, "\n".join(problems[:40])
