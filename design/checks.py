"""Checks of finished designs (e.g. the stability of each optimum), run as tasks like the starts.

A check is any function ``design -> (value, payload)``; results stream back (serially or on dask)
into the campaign store's ``checks`` table, keyed by the start that produced the design.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from railopt.design.parallel import call, map_unordered, resolve, shipping
from railopt.design.runner import Runner
from railopt.design.store import CampaignStore

Check = Callable[[np.ndarray], tuple[float, Mapping[str, Any]]]


@dataclass(frozen=True)
class _CheckTask:
    check: Check
    start_id: int
    x: np.ndarray

    def __call__(self) -> tuple[int, float, Mapping[str, Any]]:
        value, payload = resolve(self.check)(self.x)  # shipped once per check (a handle inside a dask task)
        return self.start_id, float(value), dict(payload)



def check_designs(
    check: Check,
    designs: pd.DataFrame,
    variables: list[str],
    name: str,
    client: Runner | None = None,
    store: CampaignStore | None = None,
) -> pd.DataFrame:
    """Run ``check`` on each row of ``designs`` (columns ``start_id`` and the variables).

    Returns ``start_id, name, value`` plus the payload's keys, sorted by ``start_id``; with a
    store, each result is committed under ``name`` as it arrives.
    """
    if "start_id" not in designs.columns:
        raise ValueError("designs: needs a start_id column")
    missing = [v for v in variables if v not in designs.columns]
    if missing:
        raise ValueError(f"designs: missing variable columns {missing}")
    rows = []
    with shipping(client, check, "check") as shipped:  # the check (and its model) goes to the workers once
        tasks = [_CheckTask(shipped, int(r["start_id"]), r[variables].to_numpy(dtype=float))
                 for _, r in designs.iterrows()]
        for start_id, value, payload in map_unordered(call, tasks, client=client):
            if store is not None:
                store.add_check(start_id, name, value, payload)
            rows.append({"start_id": start_id, "name": name, "value": value, **payload})
    return pd.DataFrame(rows).sort_values("start_id", ignore_index=True) if rows else pd.DataFrame(
        columns=["start_id", "name", "value"])


__all__ = ["Check", "check_designs"]
