"""The contract between the CLI and a study kind.

A study is a TOML file whose ``[study]`` table names a ``kind``; each kind registers a pydantic
config model (the whole file, ``extra="forbid"``) and a ``run`` function with :func:`register_kind`
when its module in ``railopt.studies.kinds`` is imported.  ``run`` writes its
files into ``context.outdir`` — a staging folder that the CLI publishes to ``results/<name>/``
only when the run succeeds, so a failed run leaves nothing half-written.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated

import pandas as pd
from pydantic import AfterValidator, BaseModel, ConfigDict, Field


def _ordered_interval(v: tuple[float, float]) -> tuple[float, float]:
    lo, hi = v
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ValueError(f"must be finite, got ({lo}, {hi})")
    if not lo < hi:
        raise ValueError(f"inverted or empty: lower {lo} ≥ upper {hi}")
    return v


Interval = Annotated[tuple[float, float], AfterValidator(_ordered_interval)]
"""A (lower, upper) pair with lower < upper, both finite: bounds and frequency bands in configs."""


def _non_negative_lower(v: tuple[float, float]) -> tuple[float, float]:
    if v[0] < 0:
        raise ValueError(f"lower edge must be ≥ 0 Hz, got {v[0]}")
    return v


BandHz = Annotated[tuple[float, float], AfterValidator(_ordered_interval), AfterValidator(_non_negative_lower)]
"""A frequency band in Hz: finite, 0 ≤ lower < upper."""


class StrictModel(BaseModel):
    """Base for config tables: unknown keys and wrong types are errors that name the field."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class StudyHeader(StrictModel):
    name: str = Field(pattern=r"^[A-Za-z0-9_\-]+$")
    kind: str
    description: str = ""


@dataclass
class StudyContext:
    """What the CLI hands a study run."""

    outdir: Path  # staging folder; published atomically on success
    store_dir: Path  # campaign stores: the study folder (resumable), or the staging folder under --fresh
    workers: int | None = None
    scheduler: str | None = None
    scheduler_timeout: float | None = None  # s; None: $RAILOPT_SCHEDULER_TIMEOUT or the default
    resume: bool = False
    show_progress: bool = True


@dataclass
class StudyOutcome:
    """What a study run returns: a table printed by the CLI and a markdown summary."""

    table: pd.DataFrame
    markdown: str
    files: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class StudyKind:
    name: str
    config_model: type[BaseModel]
    run: Callable[[BaseModel, StudyContext], StudyOutcome]
    summary: str = ""


KINDS: dict[str, StudyKind] = {}


def register_kind(kind: StudyKind) -> StudyKind:
    """Kinds register themselves when their module (in ``railopt.studies.kinds``) is imported."""
    if kind.name in KINDS and KINDS[kind.name] is not kind:
        raise ValueError(f"study.kind: {kind.name!r} is registered twice")
    KINDS[kind.name] = kind
    return kind


class FiniteModel(StrictModel):
    """A config table whose floats must be finite (NaN and inf are refused naming the field)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


def dask_context(context: StudyContext):
    """The dask client for a study run (``None`` = serial when ``workers == 0``)."""
    from railopt.design.parallel import dask_client

    return dask_client(context.workers, context.scheduler, timeout=context.scheduler_timeout)
