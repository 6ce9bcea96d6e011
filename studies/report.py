"""Small writers shared by the studies: markdown tables and files in the staging folder."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd


def _cell(v: object, digits: int) -> str:
    if isinstance(v, float):
        if math.isnan(v):
            return ""
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return f"{v:.{digits}g}"
    return str(v)


def markdown_table(df: pd.DataFrame, digits: int = 7) -> str:
    """A GitHub-flavoured markdown table of ``df`` (no index), floats to ``digits`` significant figures."""
    header = "| " + " | ".join(str(c) for c in df.columns) + " |"
    rule = "|" + "|".join("---" for _ in df.columns) + "|"
    rows = ["| " + " | ".join(_cell(v, digits) for v in row) + " |" for row in df.itertuples(index=False)]
    return "\n".join([header, rule, *rows])


def write_table(df: pd.DataFrame, outdir: Path, stem: str, parquet: bool = False) -> list[str]:
    """Write ``stem.csv`` (and ``stem.parquet``) into ``outdir``; returns the file names."""
    outdir.mkdir(parents=True, exist_ok=True)
    df.to_csv(outdir / f"{stem}.csv", index=False)
    names = [f"{stem}.csv"]
    if parquet:
        df.to_parquet(outdir / f"{stem}.parquet", index=False)
        names.append(f"{stem}.parquet")
    return names
