"""The one writer of study files: tables (CSV, optionally Parquet) and figures, into the staging folder.

Tables are written at full precision (pandas' default float repr, which round-trips every float), so a
table read back compares with the computed one to the last bit; there is no second float format.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

__all__ = ["Writer"]


class Writer:
    """Writes a study's tables and figures into ``outdir`` and records the file names in ``files``."""

    def __init__(self, outdir: Path, dpi: int = 110) -> None:
        self.outdir = Path(outdir)
        self.dpi = dpi
        self.files: list[str] = []

    def table(self, df: pd.DataFrame, stem: str, parquet: bool = False) -> list[str]:
        """Write ``stem.csv`` (and ``stem.parquet``); returns the names written."""
        self.outdir.mkdir(parents=True, exist_ok=True)
        df.to_csv(self.outdir / f"{stem}.csv", index=False)
        names = [f"{stem}.csv"]
        if parquet:
            df.to_parquet(self.outdir / f"{stem}.parquet", index=False)
            names.append(f"{stem}.parquet")
        self.files += names
        return names

    def figure(self, fig, stem: str, dpi: int | None = None) -> str:
        """Save a matplotlib figure as ``stem.png`` (at ``dpi``, default the writer's); returns the name."""
        self.outdir.mkdir(parents=True, exist_ok=True)
        name = f"{stem}.png"
        fig.savefig(self.outdir / name, dpi=dpi or self.dpi)
        self.files.append(name)
        return name
