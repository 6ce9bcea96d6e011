"""Markdown for study summaries: tables of DataFrames, and the words an infinite critical speed prints as."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import pandas as pd

__all__ = ["markdown_table", "stable_over"]


def stable_over(search_m_s: Sequence[float]) -> str:
    """What an infinite critical speed means, in words: ``"stable over the range (2–134 m/s)"`` for the speed range
    (m/s) the critical speed was searched over (no root crosses into Re s > 0 there; above it nothing is known)."""
    lo, hi = search_m_s
    return f"stable over the range ({lo:.4g}–{hi:.4g} m/s)"


def _cell(v: object, digits: int, infinite: str | None = None) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        if math.isnan(v):
            return ""
        if math.isinf(v):
            return infinite if v > 0 and infinite is not None else ("inf" if v > 0 else "-inf")
        return f"{v:.{digits}g}"
    return str(v).replace("|", "\\|")  # a literal bar (|H|) would end the cell


def markdown_table(df: pd.DataFrame, digits: int = 7, infinite: Mapping[str, str] | None = None) -> str:
    """A GitHub-flavoured markdown table of ``df`` (no index), floats to ``digits`` significant figures.

    ``infinite`` maps a column to the text its +inf cells print as (a critical speed: :func:`stable_over`);
    elsewhere ±inf print as ``inf``/``-inf``, NaN and None as an empty cell; a ``|`` in a text is escaped."""
    infinite = dict(infinite or {})
    header = "| " + " | ".join(_cell(str(c), digits) for c in df.columns) + " |"
    rule = "|" + "|".join("---" for _ in df.columns) + "|"
    texts = [infinite.get(str(c)) for c in df.columns]
    rows = ["| " + " | ".join(_cell(v, digits, t) for v, t in zip(row, texts, strict=True)) + " |"
            for row in df.itertuples(index=False)]
    return "\n".join([header, rule, *rows])
