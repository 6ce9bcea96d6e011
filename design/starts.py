"""Start points for multi-start campaigns: scrambled Sobol or Latin hypercube, plus user points."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.stats import qmc

from railopt.design.variables import Space

SAMPLERS = ("sobol", "lhs")
MAX_STARTS = 10**7  # starts per campaign (user points plus sampled ones): one store row and one task each
MAX_SEED = 2**63 - 1  # the seed is stored in the campaign store as a SQLite INTEGER (signed 64-bit)


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
    """User ``points`` first (ids 0..), then ``n_starts`` quasi-random points (same seed → same starts).

    Parameters
    ----------
    space : Space
        The design variables.
    n_starts : int
        Number of sampled starts, 1 ≤ n_starts and ``len(points) + n_starts`` ≤ :data:`MAX_STARTS` (10**7).
    sampler : {"sobol", "lhs"}
    seed : int
        0 ≤ seed ≤ :data:`MAX_SEED` (2**63 − 1, what the campaign store's INTEGER column holds).
    points : sequence of designs, optional
        User starts, each inside the bounds.

    Raises
    ------
    ValueError
        Naming the field (``n_starts``, ``sampler``, ``seed``, ``points[i]``), before any sampling.
    """
    check_count("n_starts", n_starts, MAX_STARTS - len(points or []))
    if sampler not in SAMPLERS:
        raise ValueError(f"sampler: must be one of {SAMPLERS}, got {sampler!r}")
    check_seed(seed)
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


def check_count(field: str, value: object, limit: int, lowest: int = 1) -> int:
    """``value`` as an int if it is an integer in [lowest, limit]; else a ``ValueError`` naming ``field``."""
    if not isinstance(value, int | np.integer) or isinstance(value, bool | np.bool_) or value < lowest:
        raise ValueError(f"{field}: must be an integer ≥ {lowest}, got {value!r}")
    if value > limit:
        raise ValueError(f"{field}: {value} is more than the limit {limit}")
    return int(value)


def check_seed(seed: object) -> int:
    """A seed as an int if 0 ≤ seed ≤ 2**63 − 1 (it is stored as a SQLite INTEGER); else ``ValueError`` naming it."""
    if not isinstance(seed, int | np.integer) or isinstance(seed, bool | np.bool_) or seed < 0:
        raise ValueError(f"seed: must be a non-negative integer, got {seed!r}")
    if seed > MAX_SEED:
        raise ValueError(f"seed: {seed} does not fit in a signed 64-bit integer (at most 2**63 - 1 = {MAX_SEED})")
    return int(seed)


__all__ = ["MAX_SEED", "MAX_STARTS", "SAMPLERS", "Start", "check_count", "check_seed", "start_points"]
