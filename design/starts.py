"""Start points for multi-start campaigns: scrambled Sobol or Latin hypercube, plus user points."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.stats import qmc

from railopt.design.variables import Space

SAMPLERS = ("sobol", "lhs")


@dataclass(frozen=True)
class Start:
    """One start: its id (row key in the store), where it came from and the design x0."""

    start_id: int
    origin: str  # "user", "sobol" or "lhs"
    x0: np.ndarray


def start_points(
    space: Space,
    n_starts: int,
    sampler: str = "sobol",
    seed: int = 0,
    points: Sequence[Sequence[float]] | None = None,
) -> list[Start]:
    """User ``points`` first (ids 0..), then ``n_starts`` quasi-random points (same seed → same starts)."""
    if not isinstance(n_starts, int | np.integer) or isinstance(n_starts, bool) or n_starts <= 0:
        raise ValueError(f"n_starts: must be a positive integer, got {n_starts!r}")
    if sampler not in SAMPLERS:
        raise ValueError(f"sampler: must be one of {SAMPLERS}, got {sampler!r}")
    if not isinstance(seed, int | np.integer) or isinstance(seed, bool) or seed < 0:
        raise ValueError(f"seed: must be a non-negative integer, got {seed!r}")
    starts = [Start(i, "user", space.check_point(p, field=f"points[{i}]")) for i, p in enumerate(points or [])]
    rng = np.random.default_rng(seed)
    if sampler == "sobol":
        engine = qmc.Sobol(space.dim, scramble=True, rng=rng)
        with warnings.catch_warnings():  # balance warning for non powers of two is harmless here
            warnings.simplefilter("ignore", UserWarning)
            u = engine.random(n_starts)
    else:
        u = qmc.LatinHypercube(space.dim, rng=rng).random(n_starts)
    base = len(starts)
    starts += [Start(base + i, sampler, space.to_x(ui)) for i, ui in enumerate(u)]
    return starts
