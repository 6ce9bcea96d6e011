"""The reference rule (tests/reference_rule.py) itself: each tolerance lets through what it states and no more."""

from __future__ import annotations

import pandas as pd
from reference_rule import differences


def _table(**changes) -> pd.DataFrame:
    row = {"cluster": 0, "value": 0.25, "count": 3, "stiffness": 1.5e6, "status": "converged", "stable": True}
    row.update(changes)
    return pd.DataFrame([row])


def test_u_holds_to_1e9_designs_to_1e6_and_labels_counts_flags_exactly():
    base = _table()
    assert differences(_table(value=0.25 * (1 + 5e-10), stiffness=1.5e6 * (1 + 5e-7)), base) == []
    assert [d.split("[")[0] for d in differences(_table(value=0.25 * (1 + 2e-9)), base)] == ["value"]
    assert [d.split("[")[0] for d in differences(_table(stiffness=1.5e6 * (1 + 2e-6)), base)] == ["stiffness"]
    for column, other in (("count", 4), ("status", "failed"), ("stable", False)):
        found = differences(_table(**{column: other}), base)
        assert len(found) == 1 and found[0].startswith(column) and "exact" in found[0]


def test_a_missing_row_or_column_is_a_difference():
    base = _table()
    assert "shape or columns" in differences(pd.concat([base, base]), base)[0]
    assert "shape or columns" in differences(base.drop(columns="status"), base)[0]


def test_changes_are_absolute_the_grid_size_within_5_percent_and_representative_starts_left_out(tmp_path):
    from reference_rule import tables

    base = _table(change_vs_existing=-1.4e-15, grid_points=90)
    assert differences(_table(change_vs_existing=4e-16, grid_points=91), base) == []  # round-off of a zero change
    assert [d.split("[")[0] for d in differences(_table(change_vs_existing=2e-6, grid_points=90), base)] == [
        "change_vs_existing"]
    assert [d.split("[")[0] for d in differences(_table(change_vs_existing=-1.4e-15, grid_points=96), base)] == [
        "grid_points"]
    for name in ("optima", "starts"):
        _table(start_id=3).to_csv(tmp_path / f"{name}.csv", index=False)
    read = tables(tmp_path)
    assert "start_id" not in read["optima"] and "start_id" in read["starts"]


def test_a_text_where_the_reference_had_none_is_a_difference():
    base = pd.DataFrame({"message": [float("nan"), float("nan")]})  # an all-empty column reads as float
    found = differences(pd.DataFrame({"message": [float("nan"), "maxeval=2000 reached"]}), base)
    assert len(found) == 1 and found[0].startswith("message[1]")


def test_a_peak_is_held_to_1e9_the_epigraph_variable_to_1e6_and_a_violation_to_1e9_absolute():
    base = pd.DataFrame({"den_hartog_peak": [2.5], "t": [0.25], "constraint_violation": [0.0]})
    assert differences(pd.DataFrame({"den_hartog_peak": [2.5], "t": [0.25 * (1 + 5e-7)],
                                     "constraint_violation": [1e-20]}), base) == []
    found = differences(pd.DataFrame({"den_hartog_peak": [2.5 * (1 + 5e-9)], "t": [0.25],
                                      "constraint_violation": [2e-9]}), base)
    assert [d.split("[")[0] for d in found] == ["den_hartog_peak", "constraint_violation"]
