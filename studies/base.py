"""The contract between the CLI and a study kind.

A study is a TOML file whose ``[study]`` table names a ``kind``; each kind registers a pydantic
config model (the whole file, ``extra="forbid"``) and a ``run`` function.  ``run`` writes its
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
    store_dir: Path  # persistent folder for resumable state (campaign stores)
    workers: int | None = None
    scheduler: str | None = None
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


def dask_context(context: StudyContext):
    """The dask client for a study run (``None`` = serial when ``workers == 0``)."""
    from railopt.design.parallel import dask_client

    return dask_client(context.workers, context.scheduler)
