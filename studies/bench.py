"""``railopt bench``: the hot paths measured against their floors, printed as ratios in one run.

1. One U(x) of the TMD model (thesis method) vs the floor: one eigen-decomposition of G plus the
   n+2 complex solves of Z(Ω)X = F.
2. Thesis-method U and exact (certified) U vs a dense frequency sweep: the sweep size needed to
   reach the exact option's accuracy, and the 2,000-point sweep's own error.
3. Analytic gradient of f_k vs central finite differences.
4. Multi-start throughput: starts/s serial vs a 2-worker dask LocalCluster.

Timings are medians of repeated runs (``time.perf_counter``); results go to
``results/benchmarks/bench.csv`` and ``bench.md``.
"""

from __future__ import annotations

import os
import platform
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

from railopt.design import MinimaxProblem, dask_client, multistart
from railopt.models.tmd import nishihara_asami
from railopt.studies.report import markdown_table
from railopt.studies.tmd_hinf import TMDDesign, TMDModel, tmd_problem


def _median_time(fn: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times))


def _dense_peak(system, band: tuple[float, float], points: int) -> float:
    return float(np.max(np.abs(system.frf(np.linspace(*band, points)))))


def run_bench(out: Path, workers: int = 2, quick: bool = False) -> pd.DataFrame:
    """Run every benchmark, print a table of ratios, and write it to ``out``."""
    repeat = 20 if quick else 200
    mu = 0.05
    model = TMDModel()
    band = model.band_rad_s
    ps = model.system(mu)
    na = nishihara_asami(mu)
    p, _ = model.parameters(mu, np.array([na.tuning, na.damping_ratio]))
    sys = ps.at(p)
    n = sys.n
    rows = []

    # 4. starts per second, serial vs dask (measured first: before large BLAS calls spin up threads)
    n_starts = 16 if quick else 64
    problem = tmd_problem(mu, model, TMDDesign(), exact=True)
    t = time.perf_counter()
    multistart(problem, n_starts, seed=1)
    t_serial = time.perf_counter() - t
    with dask_client(workers=workers) as client:
        multistart(problem, 2 * workers, seed=99, client=client)  # warm the workers (imports)
        t = time.perf_counter()
        multistart(problem, n_starts, seed=1, client=client)
        t_dask = time.perf_counter() - t
    rows.append({"benchmark": f"multistart throughput, {n_starts} starts (exact TMD objective)",
                 "ours_s": t_dask / n_starts, "reference_s": t_serial / n_starts,
                 "reference": f"serial; ours = dask LocalCluster, {workers} workers",
                 "ratio": t_dask / t_serial})
    rows[-1]["note"] = f"{n_starts / t_serial:.1f} starts/s serial, {n_starts / t_dask:.1f} starts/s dask"

    # 1. U(x) vs the floor -------------------------------------------------------------------
    G = sys.state_matrix()
    Zs = [sys.impedance(w) for w in np.linspace(*band, n + 2)]
    F = np.asarray(sys.forcing.value(1.0), dtype=complex)

    def floor() -> None:
        np.linalg.eigvals(G)
        for Z in Zs:
            np.linalg.solve(Z, F)

    t_floor = _median_time(floor, repeat)
    t_thesis = _median_time(lambda: ps.response_maxima(p, band), repeat)
    t_exact = _median_time(lambda: ps.response_maxima(p, band, exact=True), max(repeat // 10, 5))
    rows.append({"benchmark": "U(x), thesis method, TMD (n=2)", "ours_s": t_thesis, "reference_s": t_floor,
                 "reference": "floor: eig(G) + (n+2) complex solves", "ratio": t_thesis / t_floor})

    # 2. thesis / exact vs dense sweep at equal accuracy ----------------------------------------
    exact_peak = ps.response_maxima(p, band, exact=True).value
    thesis_err = abs(ps.response_maxima(p, band).value - exact_peak) / exact_peak
    dense_err_2000 = abs(_dense_peak(sys, band, 2000) - exact_peak) / exact_peak
    target = 1e-9
    n_dense = 2000
    while abs(_dense_peak(sys, band, n_dense) - exact_peak) / exact_peak > target and n_dense < 50_000_000:
        n_dense *= 2
    t_dense_2000 = _median_time(lambda: _dense_peak(sys, band, 2000), max(repeat // 10, 5))
    t_dense_eq = _median_time(lambda: _dense_peak(sys, band, n_dense), 3)
    rows.append({"benchmark": f"thesis U (rel. error {thesis_err:.1e}) vs 2,000-point sweep (rel. error "
                              f"{dense_err_2000:.1e})",
                 "ours_s": t_thesis, "reference_s": t_dense_2000, "reference": "2,000-point dense sweep",
                 "ratio": t_thesis / t_dense_2000})
    rows.append({"benchmark": f"exact certified U vs dense sweep of equal accuracy ({target:.0e}: {n_dense:,} points)",
                 "ours_s": t_exact, "reference_s": t_dense_eq, "reference": f"{n_dense:,}-point dense sweep",
                 "ratio": t_exact / t_dense_eq})

    # 3. analytic vs finite-difference gradient -----------------------------------------------
    analytic = tmd_problem(mu, model, TMDDesign(), exact=False)
    x = np.array([na.tuning, na.damping_ratio])
    t_grad = _median_time(lambda: analytic.evaluate(x, gradient=True), repeat)
    finite_diff = MinimaxProblem(analytic.variables, lambda y: analytic.evaluate(y).f)  # same f, FD Jacobian
    t_fd = _median_time(lambda: finite_diff.evaluate(x, gradient=True), repeat)
    grad_err = analytic.gradient_check(x)
    rows.append({"benchmark": f"analytic f_k + Jacobian (max rel. diff to FD {grad_err:.1e})", "ours_s": t_grad,
                 "reference_s": t_fd, "reference": "central finite differences (2d+1 evaluations)",
                 "ratio": t_grad / t_fd})

    table = pd.DataFrame(rows, columns=["benchmark", "ours_s", "reference_s", "ratio", "reference", "note"])
    out.mkdir(parents=True, exist_ok=True)
    table.to_csv(out / "bench.csv", index=False)
    header = (f"# railopt bench\n\nMachine: {platform.machine()}, {os.cpu_count()} CPUs, Python "
              f"{platform.python_version()}, {platform.system()}; repeat={repeat}. Times are medians in seconds; "
              "ratio = ours / reference (below 1 is faster).\n\n")
    (out / "bench.md").write_text(header + markdown_table(table.fillna(""), digits=3) + "\n")
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    print(f"\nwritten to {out}/bench.csv and bench.md")
    return table
