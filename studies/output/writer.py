"""The one writer of study files: tables (CSV, optionally Parquet) and figures, into the staging folder.

Every failed write (a full disk, a folder made read-only) is one :class:`~railopt.studies.output.publish.ResultsError`
naming the file (``results: cannot write <path>: No space left on device; ...``).

Tables are written at full precision (pandas' default float repr, which round-trips every float), so a
table read back compares with the computed one to the last bit; there is no second float format.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from railopt.studies.output.publish import writing

__all__ = ["Writer"]


class Writer:
    """Writes a study's tables and figures into ``outdir`` and records the file names in ``files``."""

    def __init__(self, outdir: Path, dpi: int = 110) -> None:
        self.outdir = Path(outdir)
        self.dpi = dpi
        self.files: list[str] = []

    def table(self, df: pd.DataFrame, stem: str, parquet: bool = False) -> list[str]:
        """Write ``stem.csv`` (and ``stem.parquet``); returns the names written."""
        with writing(self.outdir):
            self.outdir.mkdir(parents=True, exist_ok=True)
        with writing(self.outdir / f"{stem}.csv"):
            df.to_csv(self.outdir / f"{stem}.csv", index=False)
        names = [f"{stem}.csv"]
        if parquet:
            with writing(self.outdir / f"{stem}.parquet"):
                df.to_parquet(self.outdir / f"{stem}.parquet", index=False)
            names.append(f"{stem}.parquet")
        self.files += names
        return names

    def figure(self, fig, stem: str, dpi: int | None = None) -> str:
        """Save a matplotlib figure as ``stem.png`` (at ``dpi``, default the writer's); returns the name."""
        with writing(self.outdir):
            self.outdir.mkdir(parents=True, exist_ok=True)
        name = f"{stem}.png"
        with writing(self.outdir / name):
            fig.savefig(self.outdir / name, dpi=dpi or self.dpi)
        self.files.append(name)
        return name

    def text(self, text: str, name: str) -> str:
        """Write ``text`` as ``name`` (e.g. ``summary.md``); returns the name (not listed in ``files``)."""
        with writing(self.outdir / name):
            (self.outdir / name).write_text(text)
        return name

    def copy(self, source: Path, name: str) -> str:
        """Copy ``source`` to ``name`` in the folder (e.g. the study file as ``study.toml``); returns the name."""
        import shutil

        with writing(self.outdir / name):
            shutil.copyfile(source, self.outdir / name)
        return name
