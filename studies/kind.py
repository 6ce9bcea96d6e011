"""The contract between the CLI and a study kind.

A study is a TOML file whose ``[study]`` table names a ``kind``.  A kind is its config model (the whole
file, ``extra="forbid"``), ``compute(config, context) -> result`` (data only: tables, arrays, numbers;
writes no files) and ``report(result, writer) -> markdown`` (writes the tables and figures through the
one :class:`~railopt.studies.output.writer.Writer` and returns the summary).  A result has a ``table``:
the short table the CLI prints.  Kinds register themselves with :func:`register_kind` when their module
in ``railopt.studies.kinds`` is imported; :func:`discover_kinds` imports every kind module (``pkgutil``).

The CLI calls compute, then report into a staging folder that it publishes to ``results/<name>/`` only
when the run succeeds, so a failed run leaves nothing half-written.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import pandas as pd
from pydantic import BaseModel

if TYPE_CHECKING:
    from railopt.studies.output.writer import Writer

__all__ = ["KINDS", "StudyContext", "StudyKind", "StudyResult", "dask_context", "discover_kinds", "register_kind"]


@dataclass
class StudyContext:
    """What the CLI hands a study's compute."""

    store_dir: Path  # campaign stores: the study folder (resumable), or the staging folder under --fresh
    workers: int | None = None
    scheduler: str | None = None
    scheduler_timeout: float | None = None  # s; None: $RAILOPT_SCHEDULER_TIMEOUT or the default
    resume: bool = False
    retry_failed: bool = False  # --resume also re-runs the starts stored as worker_lost
    show_progress: bool = True
    executed_on: list[str] = field(default_factory=list)  # what dask_context opened: "serial", a cluster, an address
    clusters: list[Any] = field(default_factory=list)  # the ClusterRecord of each cluster used (workers, losses)


class StudyResult(Protocol):
    """What compute returns: any data object with the table the CLI prints."""

    table: pd.DataFrame


@dataclass(frozen=True)
class StudyKind:
    """A registered kind: config model, compute (data) and report (files and summary markdown)."""

    name: str
    config_model: type[BaseModel]
    compute: Callable[[Any, StudyContext], StudyResult]
    report: Callable[[Any, Writer], str]
    summary: str = ""
    warnings: Callable[[Any], list[str]] | None = None
    """``config -> [message, ...]``: things a run does not refuse but a user must hear of (e.g. an existing
    design that hunts below its required speed); ``railopt validate`` and ``run`` print them as warnings."""


KINDS: dict[str, StudyKind] = {}


def register_kind(kind: StudyKind) -> StudyKind:
    """Kinds register themselves when their module (in ``railopt.studies.kinds``) is imported."""
    if kind.name in KINDS and KINDS[kind.name] is not kind:
        raise ValueError(f"study.kind: {kind.name!r} is registered twice")
    KINDS[kind.name] = kind
    return kind


def discover_kinds() -> dict[str, StudyKind]:
    """Import every module and package of ``railopt.studies.kinds`` (each registers its kind); returns KINDS."""
    package = importlib.import_module("railopt.studies.kinds")
    for info in pkgutil.iter_modules(package.__path__):
        importlib.import_module(f"{package.__name__}.{info.name}")
    return KINDS


def dask_context(context: StudyContext):
    """The dask client for a study run (``None`` = serial when ``workers == 0``).  Before any cluster starts the
    driver compiles (or loads) the numerical kernels once, so that cold workers do not each compile them
    (:mod:`railopt.studies.kernel_warmup`)."""
    from railopt.design.parallel import cluster_record, dask_client

    @contextmanager
    def recorded():
        if context.workers != 0:
            from railopt.studies.kernel_warmup import warm_kernels

            warm_kernels(context.show_progress)
        with dask_client(context.workers, context.scheduler, timeout=context.scheduler_timeout) as client:
            where = "serial" if client is None else _where(client)
            if where not in context.executed_on:
                context.executed_on.append(where)
            record = cluster_record(client)
            if record is not None:
                context.clusters.append(record)  # filled in as the run goes: workers at the end, lost workers
            yield client

    return recorded()


def _where(client) -> str:
    """A client's cluster in words: the embedded LocalCluster and its workers, or the scheduler's address."""
    try:
        n = len(client.scheduler_info().get("workers", {}))
    except Exception:  # noqa: BLE001  (only a label)
        n = None
    cluster = getattr(client, "cluster", None)
    if cluster is not None and type(cluster).__name__ == "LocalCluster":
        return f"LocalCluster, {n} workers"
    return f"scheduler {client.scheduler.address}" + (f", {n} workers" if n is not None else "")
