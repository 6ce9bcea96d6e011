"""Stores and resume of the ``campaign`` kind: where each campaign's SQLite store lives, the refusal of an existing
store without ``--resume`` or of one made from other inputs, one campaign run (or resumed) into its store and
the checks of its distinct optima (results in the same store).

A store's identity is the validated config (all of it but ``design.n_starts``) and the SHA-256 of the contents of
every file the config names (:func:`input_files`: a vehicle file, bundled or not, a measured-spectrum CSV): a
resume after any of them changed is refused naming the file, never a table that mixes starts of two inputs.  A
resume may add starts (a larger ``n_starts``: the same seed and sampler give the same first starts, so only the
new ones run); it is refused when the stored starts are not exactly the first starts of this config — fewer
starts than stored (a lowered ``n_starts`` would publish more starts than a fresh run), or starts drawn
differently (``sampler = "lhs"`` draws every start anew when ``n_starts`` changes).  A run that fails before its
first start is stored removes the store it created, so nothing blocks the corrected rerun.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from railopt.design import CampaignStore, MinimaxProblem, check_designs, distinct_optima, multistart, start_points
from railopt.design.parallel import reporting_progress
from railopt.studies.catalog import Check, ModelSetup
from railopt.studies.kind import StudyContext
from railopt.studies.kinds.campaign.config import CampaignStudyConfig
from railopt.studies.kinds.campaign.problems import _starts, campaign_label, campaign_problem
from railopt.studies.output.progress import Progress  # a bar on a terminal, plain periodic lines in a log
from railopt.studies.specs import CampaignSettings

__all__ = ["check_optima", "check_stores", "input_digests", "input_files", "run_campaign", "store_path"]

PATH_KEYS = ("vehicle", "path")  # config keys that name a file (as do keys ending in _file or _path)


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


def _named_file(key: str, value: str) -> Path:
    """The file a config value names: a bundled vehicle's file for its name, else the path as given."""
    if key == "vehicle":
        from railopt.models.vehicle.loader import BUNDLED, bundled_path

        if value in BUNDLED:
            return bundled_path(value)
    return Path(value)


def input_files(config: object, prefix: str = "") -> dict[str, Path]:
    """Every file a validated config names, by its dotted field path (``models[0].options.vehicle`` →
    the vehicle file, ``objective.spectrum.path`` → the measured spectrum's CSV): the values of the keys
    :data:`PATH_KEYS` and of keys ending in ``_file`` or ``_path``, at any depth (``config`` a pydantic model or
    its JSON dump)."""
    if hasattr(config, "model_dump"):
        config = config.model_dump(mode="json")
    out: dict[str, Path] = {}
    if isinstance(config, dict):
        for k, v in config.items():
            where = f"{prefix}.{k}" if prefix else str(k)
            if isinstance(v, str) and v and (k in PATH_KEYS or str(k).endswith(("_file", "_path"))):
                out[where] = _named_file(str(k), v)
            else:
                out |= input_files(v, where)
    elif isinstance(config, list):
        for i, v in enumerate(config):
            out |= input_files(v, f"{prefix}[{i}]")
    return out


def input_digests(config: object) -> dict[str, dict[str, str]]:
    """``{field path: {"file": path, "sha256": digest of its contents}}`` of :func:`input_files` (a file that cannot
    be read has the digest ``"unreadable: <why>"``): what a store records so that a resume with a changed input
    file is refused, naming it."""
    out = {}
    for where, path in input_files(config).items():
        try:
            digest = hashlib.sha256(path.read_bytes()).hexdigest()
        except OSError as exc:
            digest = f"unreadable: {exc.strerror or exc}"
        out[where] = {"file": str(path), "sha256": digest}
    return out


def _store_config(cfg: CampaignStudyConfig, key: tuple[str, str, str, str]) -> dict:
    """What a campaign's store is made from: the whole config but the number of starts (a resume may extend a
    campaign: the same seed and sampler give the same first starts, so only the new ones run), and the contents
    of every file it names (:func:`input_digests`)."""
    model, kind, objective, method = key
    dumped = cfg.model_dump(mode="json")
    dumped["design"] = {k: v for k, v in dumped["design"].items() if k != "n_starts"}
    return {**dumped, "campaign": {"model": model, "objective": objective, "method": method, "problem": kind},
            "inputs": input_digests(cfg)}


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
    if "inputs" not in stored:
        raise ValueError(f"store: {path} was made by an earlier railopt that did not record the contents of its input "
                         "files, so a resume could mix starts of other inputs; run with --fresh to discard the store")
    old, new = _flat(stored), _flat(json.loads(json.dumps(config, sort_keys=True, default=str)))
    changed = sorted(k for k in old.keys() | new.keys() if old.get(k, "<absent>") != new.get(k, "<absent>"))
    files = sorted({k.rsplit(".", 1)[0] for k in changed if k.startswith("inputs.") and k.endswith(".sha256")})
    for field in files:  # the same file named by the same field, with other contents
        if f"{field}.file" not in changed:
            name = new.get(f"{field}.file", old.get(f"{field}.file"))
            raise ValueError(f"store: {path} was made from another version of {name} ({field.removeprefix('inputs.')}):"
                             " its contents changed since, and a resume would mix starts of both; restore the file, "
                             "or run with --fresh to discard the store")
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
    """Run (or resume) one campaign into ``<store_dir>/campaigns/<label>.sqlite``; returns its table.

    A resumed store must hold exactly the first starts of this config (:func:`_check_plan`, ``ValueError`` naming
    ``design.n_starts`` or ``design.sampler``).  When the run fails before any start is stored, a store this call
    created is removed (with its ``-wal``/``-shm`` files): it holds nothing, and would block the next run."""
    path = store_path(context, label)
    created = not path.exists()
    if created:
        store = CampaignStore.create(path, label, config, list(problem.space.names))
    else:
        store = CampaignStore.open(path, expect_config=config)
    bar = Progress(label, unit="start", enabled=context.show_progress)
    discard = False
    try:
        if not created:
            _check_plan(store, problem, settings, points)
        return multistart(problem, settings.n_starts, method=settings.method, seed=settings.seed,
                          sampler=settings.sampler, points=points, client=client, store=store,
                          options=settings.solver_options(), progress=bar.update,
                          retry_failed=context.retry_failed)
    except BaseException:
        discard = created and _holds_nothing(store)
        raise
    finally:
        bar.close()
        store.close()
        if discard:
            for extra in ("", "-wal", "-shm", "-journal"):
                Path(f"{path}{extra}").unlink(missing_ok=True)


def _holds_nothing(store: CampaignStore) -> bool:
    try:
        return not store.finished_ids()
    except ValueError:  # unreadable: kept, and named by the next open
        return False


def _check_plan(store: CampaignStore, problem: MinimaxProblem, settings: CampaignSettings,
                points: list[list[float]] | None) -> None:
    """Refuse a resume whose stored starts are not the first starts of this config: starts beyond it (a lowered
    ``n_starts``: a resume would publish more starts than a fresh run) or starts drawn elsewhere (the sampler
    ``lhs`` draws every start anew when ``n_starts`` changes)."""
    plan = {s.start_id: s for s in start_points(problem.space, settings.n_starts, sampler=settings.sampler,
                                                 seed=settings.seed, points=points)}
    stored = store.starts()
    names = list(problem.space.names)
    beyond = sorted(int(i) for i in stored["start_id"] if int(i) not in plan)
    if beyond:
        need = max(beyond) + 1 - (len(points) if points else 0)
        raise ValueError(f"design.n_starts: {settings.n_starts} is fewer than the starts in {store.path} (up to start "
                         f"{max(beyond)}, {len(beyond)} beyond this config's {len(plan)}): a resume would publish more "
                         f"starts than a fresh run; set n_starts to {need} or more, or run with --fresh")
    x0s = stored[[f"x0_{n}" for n in names]].to_numpy(dtype=float)
    for start_id, x0 in zip(stored["start_id"].astype(int), x0s, strict=True):
        start = plan[start_id]
        if not np.array_equal(x0, start.x0):
            why = ("sampler 'lhs' draws every start anew when n_starts changes: keep n_starts, or use 'sobol'"
                   if settings.sampler == "lhs" else "the starts were drawn or given differently")
            raise ValueError(f"design.sampler: start {start_id} in {store.path} began at {x0.tolist()}, this config's "
                             f"start {start_id} begins at {start.x0.tolist()} ({why}); a resume would mix the two; "
                             "run with --fresh")


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
    for check in cfg.design.checks:  # a check of each distinct optimum (a critical-speed search: seconds each)
        bar = Progress(f"{label} ({check} check of its optima)", unit="design", enabled=context.show_progress)
        with reporting_progress(bar.update):
            found, check_flags = check_optima(found, setup, names, label, context, check, client)
        bar.close()
        flags += check_flags
    return table, found, flags
