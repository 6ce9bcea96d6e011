"""Run a study from Python: ``run_study(path) -> StudyRun``, the study's tables as pandas DataFrames.

The one run path of a study, shared by ``railopt run`` (:func:`railopt.studies.cli.cmd_run`) and
:func:`run_study`: :func:`execute_study` takes the study's lock, computes (``kind.compute``), reports into
a staging folder (``kind.report`` through the one :class:`~railopt.studies.output.writer.Writer`) and
publishes the folder as ``<results>/<study name>/`` only when everything succeeded
(:mod:`railopt.studies.output.publish`).  So a study run from Python writes the same files, bit for bit,
as the command, and hands back what it wrote: every table as a DataFrame (the frames that were written,
so ``run.tables["peaks"]`` equals ``peaks.csv`` read back), the figures' paths, the summary.

Example (a script needs the ``__main__`` guard only when ``workers`` > 0 starts a local dask cluster)::

    from railopt.studies import run_study

    run = run_study("tmd_frf")                  # a bundled study, or a path to a study TOML
    run.tables["peaks"]                         # DataFrame: model, design, output, peak, frequency_hz, ...
    run.figures["frf"]                          # Path of frf.png
    run.folder                                  # where it was published (a new temporary folder by default)
"""

from __future__ import annotations

import numbers
import os
import platform
import tempfile
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from railopt.studies.config import ConfigError, load_study
from railopt.studies.kind import StudyContext, StudyKind
from railopt.studies.output.publish import publication
from railopt.studies.output.writer import Writer

__all__ = ["STUDIES_DIR", "StudyRun", "execute_study", "resolve_study", "run_study", "run_timing", "study_warnings"]

STUDIES_DIR = Path(__file__).resolve().parent
"""The bundled studies' folder (``railopt list``)."""


def study_warnings(kind: StudyKind, config: object) -> list[str]:
    """Everything a study does not refuse but its user must hear of: the plausibility warnings of its vehicles
    (each naming the file, the key and the likely slip), then the kind's own (an existing design that hunts)."""
    from railopt.studies.catalog.vehicle import vehicle_warnings

    return vehicle_warnings(config) + (list(kind.warnings(config)) if kind.warnings is not None else [])


def resolve_study(arg: str) -> Path:
    """A path as given, else ``<name>.toml`` among the bundled studies; a :class:`ConfigError` naming ``arg``."""
    path = Path(arg)
    if path.is_file():
        return path
    for candidate in (STUDIES_DIR / arg, STUDIES_DIR / f"{arg}.toml"):
        if candidate.is_file():
            return candidate
    raise ConfigError(f"{arg}: study: no such file (and no bundled study of that name; see `railopt list`)")


def run_timing(compute_s: float, report_s: float, context: StudyContext) -> pd.DataFrame:
    """One row: how long the run's compute and report took (s), whether it resumed stored work, where it ran, and
    what the cluster did meanwhile (workers at the start and end, lost workers, re-run tasks: ``timing.csv`` of every
    study)."""
    from railopt.design.parallel import cluster_summary

    where = "; ".join(context.executed_on) or "serial"  # what the run really used (kinds without dask: serial)
    return pd.DataFrame([{"compute_s": compute_s, "report_s": report_s, "total_s": compute_s + report_s,
                          "resumed": bool(context.resume), "cpus": os.cpu_count(), "workers": where,
                          # the workers at the start, at the end and the most seen; lost workers, re-run tasks
                          **cluster_summary(context.clusters),
                          "machine": platform.machine(), "python": platform.python_version()}])


@dataclass(frozen=True)
class StudyRun:
    """A finished, published study run.

    Attributes
    ----------
    name, kind : str
        The study's ``[study] name`` and ``kind``.
    folder : Path
        The published study folder (``<results>/<name>/``): tables (CSV), figures (PNG), ``summary.md``,
        ``study.toml`` and, for campaigns, ``campaigns/<label>.sqlite``.
    tables : dict of str to DataFrame
        Every table the study wrote, by file stem (``"peaks"`` for ``peaks.csv``; ``"timing"`` included): the
        frames as written: ``frame.to_csv(index=False)`` is the file, and its numeric columns read back equal
        to the last bit (a column mixing text and numbers keeps its numbers here, where the CSV has text).
    figures : dict of str to Path
        Every figure, by file stem (``"frf"`` → ``folder / "frf.png"``).
    summary : str
        The study's ``summary.md`` (Markdown).
    table : DataFrame
        The short table ``railopt run`` prints.
    result : object
        What the kind's ``compute`` returned (its data object; kind-specific).
    compute_s, report_s : float
        Wall time of compute and report, s (as in ``timing.csv``).
    files : list of str
        The names of the files written, in order (``summary.md`` and ``study.toml`` not listed).
    warnings : list of str
        The kind's warnings on the config (``railopt run`` prints them as ``railopt: warning:``).
    """

    name: str
    kind: str
    folder: Path
    tables: dict[str, pd.DataFrame]
    figures: dict[str, Path]
    summary: str
    table: pd.DataFrame
    result: Any
    compute_s: float
    report_s: float
    files: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def __getitem__(self, stem: str) -> pd.DataFrame:
        """``run["peaks"]`` is ``run.tables["peaks"]``; an unknown stem raises ``KeyError`` listing the tables."""
        try:
            return self.tables[stem]
        except KeyError:
            raise KeyError(f"{stem!r}: study {self.name!r} wrote no such table; its tables: "
                           f"{sorted(self.tables)}") from None

    def __repr__(self) -> str:
        return (f"StudyRun({self.name!r}, kind={self.kind!r}, folder={str(self.folder)!r}, "
                f"tables={sorted(self.tables)}, figures={sorted(self.figures)})")


class _KeepingWriter(Writer):
    """The study's writer, also keeping each table it writes (a copy) and each figure's path."""

    def __init__(self, outdir: Path) -> None:
        super().__init__(outdir)
        self.frames: dict[str, pd.DataFrame] = {}
        self.figure_stems: list[str] = []

    def table(self, df: pd.DataFrame, stem: str, parquet: bool = False) -> list[str]:  # noqa: D102
        names = super().table(df, stem, parquet)
        self.frames[stem] = df.copy()
        return names

    def figure(self, fig, stem: str, dpi: int | None = None) -> str:  # noqa: D102
        name = super().figure(fig, stem, dpi)
        self.figure_stems.append(stem)
        return name


def execute_study(study_file: Path, kind: StudyKind, config: Any, results: Path | str, *, fresh: bool = False,
                  resume: bool = False, workers: int | None = None, scheduler: str | None = None,
                  scheduler_timeout: float | None = None, retry_failed: bool = False,
                  show_progress: bool = True, warnings: list[str] | None = None) -> StudyRun:
    """Compute, report and publish one validated study as ``results/<name>/`` (what ``railopt run`` does).

    Parameters
    ----------
    study_file : Path
        The study TOML (copied into the folder as ``study.toml``).
    kind, config
        The study's kind and validated config (:func:`railopt.studies.config.load_study`).
    results : Path or str
        The results root; created if missing (an empty or blank string is refused: it would mean the working
        folder).
    fresh, resume, retry_failed : bool
        As ``--fresh``, ``--resume``, ``--retry-failed``: new campaign stores (the old ones replaced only when
        this run is published), or finish the stored ones.  Neither, with a store in place: the kind refuses.
    workers, scheduler, scheduler_timeout
        Where campaigns run: ``workers`` processes of a local dask cluster (0: serial, in-process; None: one
        per CPU), or the dask scheduler at ``scheduler`` (waiting ``scheduler_timeout`` s for it).
    show_progress : bool
        Progress bars or lines of long work on stderr.
    warnings : list of str, optional
        The config's warnings, kept in the returned run.

    Returns
    -------
    StudyRun
        The tables, figures and summary as published.

    Raises
    ------
    ResultsError
        ``results`` unusable (a file in the way, not writable), the study locked by another run, a write that
        failed; nothing is published and the staging folder is removed.
    ValueError
        A user error the kind detects while computing (a store that needs ``resume`` or ``fresh``, an
        unreachable scheduler, ...), naming the file or field.
    """
    name = config.study.name
    with publication(results, name) as folders:  # checks, the study lock, leftovers; staging removed at the end
        final, staging = folders.final, folders.staging
        context = StudyContext(
            store_dir=staging if fresh else final,  # --fresh: old stores go only when this run is published
            workers=workers,
            scheduler=scheduler,
            scheduler_timeout=scheduler_timeout,
            resume=resume,
            retry_failed=retry_failed,
            show_progress=show_progress,
        )
        started = time.perf_counter()
        result = kind.compute(config, context)
        computed = time.perf_counter()
        writer = _KeepingWriter(staging)
        summary = kind.report(result, writer)
        writer.text(summary, "summary.md")
        writer.copy(study_file, "study.toml")
        reported = time.perf_counter()
        writer.table(run_timing(computed - started, reported - computed, context), "timing")
        folders.publish(carry=not fresh)
    return StudyRun(name=name, kind=kind.name, folder=final, tables=writer.frames,
                    figures={stem: final / f"{stem}.png" for stem in writer.figure_stems}, summary=summary,
                    table=result.table, result=result, compute_s=computed - started,
                    report_s=reported - computed, files=list(writer.files),
                    warnings=list(warnings or []))


def run_study(path: str | Path, *, results: str | Path | None = None, workers: int | None = 0,
              scheduler: str | None = None, scheduler_timeout: float | None = None, resume: bool = False,
              fresh: bool = False, retry_failed: bool = False, show_progress: bool = False) -> StudyRun:
    """Validate, run and publish a study, as ``railopt run`` does, and return its tables as DataFrames.

    Parameters
    ----------
    path : str or Path
        A study TOML, or the name of a bundled study (``"tmd_frf"``; ``railopt list``).
    results : str or Path, optional
        The results root: the study is published as ``results/<name>/``.  Default: a new temporary folder
        (``tempfile.mkdtemp``, left in place for the files; ``StudyRun.folder`` says where).
    workers : int or None
        Worker processes of an embedded dask ``LocalCluster`` for campaigns; 0 (default) runs serially in this
        process; None: one per CPU.  A script that starts a cluster must guard its top level with
        ``if __name__ == "__main__":`` (the workers are new processes that import it).
    scheduler : str, optional
        Address of an existing dask scheduler instead (``workers`` must then be None).
    scheduler_timeout : float, optional
        How long to wait for the scheduler, s.
    resume, fresh, retry_failed : bool
        As ``railopt run --resume / --fresh / --retry-failed`` (needed when ``results`` already holds the
        study's campaign stores).
    show_progress : bool
        Progress of long work on stderr.

    Returns
    -------
    StudyRun
        ``tables`` (stem → DataFrame, as written to the CSV files), ``figures`` (stem → PNG path), ``summary``
        (Markdown), ``table`` (the printed short table), ``folder``, ``result`` (the kind's data object).

    Raises
    ------
    ValueError
        The study file is invalid (:class:`~railopt.studies.config.ConfigError`, naming the file and the
        field), an argument is (naming it: ``workers``, ``scheduler``, ``resume``), the store needs
        ``resume`` or ``fresh``, the scheduler cannot be reached.
    ResultsError
        The results folder cannot be used, or another run holds the study's lock.

    The config's warnings (what ``railopt run`` prints as ``railopt: warning:``) are issued as
    :class:`UserWarning` and kept in ``StudyRun.warnings``.
    """
    from railopt.design.parallel import scheduler_timeout as checked_timeout

    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, numbers.Integral)
                                or workers < 0):
        raise ValueError(f"workers: must be an integer ≥ 0 (0 = serial) or None, got {workers!r}")
    if workers is not None and scheduler:
        raise ValueError("workers, scheduler: give one of them (a local cluster or an existing scheduler); "
                         "pass workers=None with a scheduler")
    if resume and fresh:
        raise ValueError("resume, fresh: give one of them (finish the stored campaigns, or start new ones)")
    if scheduler_timeout is not None:
        checked_timeout(scheduler_timeout, "scheduler_timeout")
    study_file = resolve_study(str(path))
    kind, config, _ = load_study(study_file)
    messages = [" ".join(str(m).split()) for m in study_warnings(kind, config)]
    for message in messages:
        warnings.warn(f"{study_file}: {message}", UserWarning, stacklevel=2)
    root = Path(tempfile.mkdtemp(prefix="railopt-")) if results is None else results
    return execute_study(study_file, kind, config, root, fresh=fresh, resume=resume, workers=workers,
                         scheduler=scheduler, scheduler_timeout=scheduler_timeout, retry_failed=retry_failed,
                         show_progress=show_progress, warnings=messages)
