"""Compile (or load) the numerical kernels in the driver before a dask cluster's workers start.

numba caches each compiled kernel on disk (``models/kernels.py``: ``cache=True``; the folder is
``NUMBA_CACHE_DIR`` when set).  Worker processes load a written cache in about a second, but with a cold cache
each worker compiles the kernels itself on its first task — measured 45–48 s per worker with two workers
compiling at once on two cores (docs/models.md).  One small certified band maximum in the driver, before the
cluster starts, writes the cache once; the workers then load it.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from railopt.models import LinearSystem

__all__ = ["warm_kernels"]


def warm_kernels(show_progress: bool = True) -> float:
    """Run the certified and the thesis-method band maximum of a 2-DOF system once (compiles or loads every
    kernel of those paths); returns the seconds it took.  Prints one line to stderr when it took over 2 s
    (a cold cache) and ``show_progress``."""
    t = time.perf_counter()
    system = LinearSystem(np.diag([1.0, 2.0]), np.array([[0.3, -0.1], [-0.1, 0.2]]),
                          np.array([[3.0, -1.0], [-1.0, 2.0]]), np.array([1.0, 0.0]), np.array([0.0, 1.0]))
    system.response_maxima(band_rad_s=(0.0, 4.0), exact=True)
    system.response_maxima(band_rad_s=(0.0, 4.0))
    seconds = time.perf_counter() - t
    if show_progress and seconds > 2.0:
        print(f"compiled the numerical kernels in {seconds:.0f} s (cached on disk for the workers and later runs)",
              file=sys.stderr, flush=True)
    return seconds
