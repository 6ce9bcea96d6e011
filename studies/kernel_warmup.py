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

from railopt.models import LinearSystem, ParameterPart, ParametricSystem
from railopt.models.response_maxima import batch_response_maxima
from railopt.models.sensitivity import maxima_jacobians

__all__ = ["warm_kernels", "warm_nonlinear_kernels"]


def warm_kernels(show_progress: bool = True) -> float:
    """Run what a campaign's tasks run on a 2-DOF system once — the certified and the thesis-method band maximum,
    a frequency response, the general path (a free rigid-body mode), the pole–residue sums, the maxima's
    gradients and a batch of designs (objective-surface rows) — so that every kernel of those paths is compiled
    or loaded; returns the seconds it took.  Prints one line to stderr when it took over 2 s (a cold cache) and
    ``show_progress``."""
    t = time.perf_counter()
    M, C, K = np.diag([1.0, 2.0]), np.array([[0.3, -0.1], [-0.1, 0.2]]), np.array([[3.0, -1.0], [-1.0, 2.0]])
    system = LinearSystem(M, C, K, np.array([1.0, 0.0]), np.array([0.0, 1.0]))
    system.response_maxima(band_rad_s=(0.0, 4.0), exact=True)
    system.response_maxima(band_rad_s=(0.0, 4.0))
    system.frf(omega_rad_s=np.linspace(0.1, 4.0, 5))
    free = np.array([[1.0, -1.0], [-1.0, 1.0]])  # a free rigid-body mode: the general path (the zero zone)
    LinearSystem(np.eye(2), 0.1 * free, free, np.array([1.0, 0.0]), np.array([0.0, 1.0]),
                 response="acceleration").response_maxima(band_rad_s=(0.0, 4.0), exact=True)
    family = ParametricSystem(M, C, K, np.array([1.0, 0.0]), np.array([0.0, 1.0]),
                              {"k": ParameterPart(K=np.diag([1.0, 0.0]))}, values=[0.5])
    batch_response_maxima(family.stack(np.array([[0.5], [1.0]])), band_rad_s=(0.0, 4.0))
    member = family.at([0.5])
    member.pole_residue().evaluate(np.linspace(0.1, 4.0, 5))
    for exact in (True, False):  # the gradients of a start
        maxima_jacobians(member, band_rad_s=(0.0, 4.0), exact=exact)
    seconds = time.perf_counter() - t
    if show_progress and seconds > 2.0:
        print(f"compiled the numerical kernels in {seconds:.0f} s (cached on disk for the workers and later runs)",
              file=sys.stderr, flush=True)
    return seconds


def warm_nonlinear_kernels(show_progress: bool = True) -> float:
    """Compile (or load) the nonlinear wheel/rail kernels (:mod:`railopt.models.vehicle.wheelset_kernel`) in the
    driver — the right-hand side, its Jacobian, the forces' state and a table's geometry of the bundled single
    wheelset — before the workers of a campaign with a ``nonlinear_hunting`` check start; returns the seconds it
    took (10–15 s cold, 0.3 s from the cache).  Prints one line to stderr when it took over 2 s and
    ``show_progress``."""
    from railopt.models.contact.rigid_contact import ContactTable
    from railopt.models.vehicle import load_vehicle
    from railopt.models.vehicle.nonlinear import nonlinear_vehicle
    from railopt.models.vehicle.wheelset_forces import SaturatedCreepLaw, profile_forces

    t = time.perf_counter()
    vehicle = load_vehicle("single-wheelset")
    wr = vehicle.wheel_rail()
    table = ContactTable.conical(wr.conicity, np.linspace(-0.01, 0.01, 21), r0=wr.r0, e0=wr.e0)
    for forces in (None, profile_forces(wr, table, SaturatedCreepLaw(0.3))):
        model = nonlinear_vehicle(vehicle, forces)
        x = np.zeros(2 * model.n_dof)
        model.rhs(0.0, x, 20.0)
        model.jacobian(x, 20.0)
        model.contact_state(x, 20.0)
        model.forces.geometry.points(np.zeros(1))
        model.forces.creep_law(model.forces.creep, np.zeros(1), np.zeros(1), np.zeros(1), np.ones(1), 1.0)
    seconds = time.perf_counter() - t
    if show_progress and seconds > 2.0:
        print(f"compiled the nonlinear wheel/rail kernels in {seconds:.0f} s (cached on disk for the workers and "
              "later runs)", file=sys.stderr, flush=True)
    return seconds
