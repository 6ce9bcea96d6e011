"""Running a multi-start campaign from a study: settings, store handling, progress bar."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any, Literal

import pandas as pd
from pydantic import Field, field_validator
from tqdm import tqdm

from railopt.design import CampaignStore, MinimaxProblem, check_designs, multistart
from railopt.design.checks import Check
from railopt.design.solve import method_options
from railopt.studies.base import StrictModel, StudyContext


class SolverOptions(StrictModel):
    xtol: float = Field(1e-10, gt=0, strict=True)  # strict: `true` is not a number
    ftol: float = Field(1e-12, gt=0, strict=True)
    maxeval: int = Field(3000, gt=0, strict=True)
    maxtime: float = Field(120.0, gt=0, strict=True)


class CampaignSettings(StrictModel):
    """The ``[design]`` table shared by campaign studies."""

    method: Literal["slsqp", "cobyla", "slp"] = "slsqp"
    n_starts: int = Field(16, gt=0, strict=True)  # strict: `true` or 16.0 is not a count
    sampler: Literal["sobol", "lhs"] = "sobol"
    seed: int = Field(0, ge=0, strict=True)
    options: SolverOptions = SolverOptions()

    @field_validator("method")
    @classmethod
    def _registered(cls, v: str) -> str:
        method_options(v)  # raises naming the method if it is not registered
        return v

    def solver_options(self) -> dict[str, Any]:
        return self.options.model_dump()


def store_path(context: StudyContext, label: str) -> Path:
    return context.store_dir / "campaigns" / f"{label}.sqlite"


def check_stores(context: StudyContext, labels: list[str]) -> None:
    """Before any work: an existing store without --resume is an error naming the file."""
    if context.resume:
        return
    existing = [str(store_path(context, lb)) for lb in labels if store_path(context, lb).exists()]
    if existing:
        raise FileExistsError(
            f"store: {', '.join(existing)} already exist(s); pass --resume to finish or reuse them, "
            "or --fresh to discard them"
        )


def run_campaign(
    problem: MinimaxProblem,
    label: str,
    settings: CampaignSettings,
    context: StudyContext,
    config: dict[str, Any],
    client: Any = None,
    points: list[list[float]] | None = None,
) -> pd.DataFrame:
    """Run (or resume) one campaign into ``<store_dir>/campaigns/<label>.sqlite``; returns its table."""
    path = store_path(context, label)
    if path.exists():
        store = CampaignStore.open(path, expect_config=config)
    else:
        store = CampaignStore.create(path, label, config, list(problem.space.names))
    bar = tqdm(desc=label, unit="start", file=sys.stderr, disable=not context.show_progress, mininterval=0.5)

    def progress(done: int, total: int) -> None:
        bar.total = total
        bar.n = done
        bar.refresh()

    try:
        return multistart(
            problem,
            settings.n_starts,
            method=settings.method,
            seed=settings.seed,
            sampler=settings.sampler,
            points=points,
            client=client,
            store=store,
            options=settings.solver_options(),
            progress=progress,
        )
    finally:
        bar.close()
        store.close()


def check_optima(
    optima: pd.DataFrame,
    variables: list[str],
    label: str,
    context: StudyContext,
    name: str,
    check: Check,
    client: Any = None,
) -> pd.DataFrame:
    """Run ``check`` on each distinct optimum (rows with ``start_id`` and the variables) as tasks;
    results go to the campaign's store.  Returns ``optima`` with a column ``name`` (the check's
    value) and the check's flags (prefixed ``name.`` if a column of that name exists)."""
    with CampaignStore.open(store_path(context, label)) as store:
        checks = check_designs(check, optima, variables, name, client=client, store=store)
    checks = checks.drop(columns="name").rename(columns={"value": name})
    checks = checks.rename(columns={c: f"{name}.{c}" for c in checks.columns
                                    if c not in ("start_id", name) and c in optima.columns})
    return optima.merge(checks, on="start_id", how="left")
