"""Stores and resume of the ``campaign`` kind: where each campaign's SQLite store lives, the refusal of an existing
store without ``--resume`` or of one made from another config, one campaign run (or resumed) into its store and
the checks of its distinct optima (results in the same store)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from railopt.design import CampaignStore, MinimaxProblem, check_designs, distinct_optima, multistart
from railopt.studies.catalog import Check, ModelSetup
from railopt.studies.kind import StudyContext
from railopt.studies.kinds.campaign.config import CampaignStudyConfig
from railopt.studies.kinds.campaign.problems import _starts, campaign_label, campaign_problem
from railopt.studies.specs import CampaignSettings

__all__ = ["check_optima", "check_stores", "run_campaign", "store_path"]


def store_path(context: StudyContext, label: str) -> Path:
    """The SQLite store of campaign ``label``: ``<store_dir>/campaigns/<label>.sqlite``."""
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


def _store_config(cfg: CampaignStudyConfig, key: tuple[str, str, str, str]) -> dict:
    """What a campaign's store is made from: the whole config but the number of starts (a resume may extend a
    campaign: the same seed and sampler give the same first starts, so only the new ones run)."""
    model, kind, objective, method = key
    dumped = cfg.model_dump(mode="json")
    dumped["design"] = {k: v for k, v in dumped["design"].items() if k != "n_starts"}
    return {**dumped, "campaign": {"model": model, "objective": objective, "method": method, "problem": kind}}


def _flat(value: object, prefix: str = "") -> dict[str, object]:
    if isinstance(value, dict):
        out: dict[str, object] = {}
        for k, v in value.items():
            out |= _flat(v, f"{prefix}.{k}" if prefix else str(k))
        return out
    return {prefix: value}


def _check_resumable(path: Path, config: dict) -> None:
    """A store made from another config is refused naming the fields that differ (``n_starts`` may grow)."""
    if not path.exists():
        return
    with CampaignStore.open(path) as store:
        stored = store.config()
    old, new = _flat(stored), _flat(json.loads(json.dumps(config, sort_keys=True, default=str)))
    changed = sorted(k for k in old.keys() | new.keys() if old.get(k, "<absent>") != new.get(k, "<absent>"))
    if changed:
        shown = ", ".join(f"{k} ({old.get(k, '<absent>')!r} → {new.get(k, '<absent>')!r})" for k in changed[:6])
        more = f" and {len(changed) - 6} more" if len(changed) > 6 else ""
        raise ValueError(f"store: {path} was made from a different config: {shown}{more}; only design.n_starts may "
                         "change on --resume (run with --fresh to discard the store)")


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
    from railopt.studies.output.progress import Progress  # a bar on a terminal, plain periodic lines in a log

    bar = Progress(label, unit="start", enabled=context.show_progress)
    try:
        return multistart(problem, settings.n_starts, method=settings.method, seed=settings.seed,
                          sampler=settings.sampler, points=points, client=client, store=store,
                          options=settings.solver_options(), progress=bar.update,
                          retry_failed=context.retry_failed)
    finally:
        bar.close()
        store.close()


def _design_check(setup: ModelSetup, names: list[str], check: Check):
    """A check of the design x through the setup's parameter map, as the design layer runs it (a task):
    ``x -> (value, payload)``."""

    def on_design(x: np.ndarray) -> tuple[float, dict]:
        p, _ = setup.parameters(names, x)
        result = check(p)
        return result.value, result.payload()

    return on_design


def check_optima(optima: pd.DataFrame, setup: ModelSetup, names: list[str], label: str, context: StudyContext,
                 name: str, client: Any = None) -> tuple[pd.DataFrame, list[str]]:
    """Run check ``name`` of ``setup`` on each distinct optimum as tasks (results go to the campaign's store).

    Returns ``optima`` with a column ``name`` (the check's value) and the check's payload (a column already in
    ``optima`` is prefixed ``name.``), and the columns of the check's flags."""
    check = setup.checks[name]
    with CampaignStore.open(store_path(context, label)) as store:
        checks = check_designs(_design_check(setup, names, check), optima, names, name, client=client, store=store)
    checks = checks.drop(columns="name").rename(columns={"value": name})
    renamed = {c: f"{name}.{c}" for c in checks.columns if c not in ("start_id", name) and c in optima.columns}
    checks = checks.rename(columns=renamed)
    return optima.merge(checks, on="start_id", how="left"), [renamed.get(f, f) for f in check.flag_names]


def _campaign(cfg: CampaignStudyConfig, setup: ModelSetup, key: tuple[str, str, str, str], context: StudyContext,
              client) -> tuple[pd.DataFrame, pd.DataFrame, list[str]]:
    """One campaign (model, problem, objective, method): its starts, its checked distinct optima and their flags."""
    model, kind, objective, method = key
    names = [v.name for v in cfg.design.variables]
    problem = campaign_problem(cfg, setup, objective, kind)
    label = campaign_label(model, objective, method, kind)
    settings = cfg.design.model_copy(update={"method": method})
    store_config = _store_config(cfg, key)
    _check_resumable(store_path(context, label), store_config)
    table = run_campaign(problem, label, settings, context, store_config, client, _starts(cfg, setup))
    found = distinct_optima(table, problem).rename(columns={"best_start": "start_id"})
    flags: list[str] = []
    for check in cfg.design.checks:
        found, check_flags = check_optima(found, setup, names, label, context, check, client)
        flags += check_flags
    return table, found, flags
