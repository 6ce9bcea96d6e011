"""Markdown for study summaries: tables of DataFrames."""

from __future__ import annotations

import math

import pandas as pd

__all__ = ["markdown_table"]


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
