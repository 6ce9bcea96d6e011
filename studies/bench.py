"""``railopt bench``: the hot paths measured against their floors, printed as ratios in one run.

1. One U(x) of the TMD model (thesis method) vs the floor: one eigen-decomposition of G plus the
   n+2 complex solves of Z(Ω)X = F; and, for non-symmetric systems of n = 3, 9, 15, 27, 60, the exact
   (certified) U against the thesis-method U and the floor, with the pole–residue form of H checked
   against direct solves.
2. Thesis-method U and exact (certified) U vs a dense frequency sweep: the sweep size needed to
   reach the exact option's accuracy, and the 2,000-point sweep's own error.
3. Analytic gradient of f_k vs central finite differences.
4. Multi-start throughput: starts/s serial vs a 2-worker dask LocalCluster, and the machine's own ceiling: the
   same starts in plain processes at once (no dask) against one alone.  The ceiling is measured first: below
   :data:`BUSY_CEILING` (other work on the machine) the parallel rows are marked as not results (their ratio left
   empty, the measured one in the note).  Dask's own floor at the short campaign's size: pure-CPU tasks of its
   serial work, no railopt code.  Task dispatch of a short-start campaign of the flagship's problem at 1,
   2 and 4 local workers, the problem shipped once per campaign against the problem sent with every task.
5. Critical speed of the locomotive (rigid track): eigen-solves and time of the bracketing + Brent
   search against a dense root-locus scan at the same resolution.
6. Exact certified U against python-control's ``linfnorm`` (SLICOT AB13DD) on the same chains without delays
   (skipped with a note when the optional ``bench`` extra is not installed); import + first certified U in a
   fresh process with the compiled kernels' cache cold and warm; the cab model and the full lateral
   model (6 delayed axle inputs) against the floor; a constrained flagship start against the same starts with
   the code of an earlier commit (:mod:`.bench_baseline`, not in ``--quick``).
7. Stability constraints with gradients against one eig(G) per speed; the random-response RMS by quadrature
   against the modal Lyapunov covariance at equal accuracy.
8. The nonlinear hunting analysis (:mod:`.bench_nonlinear`): seconds per simulated second of the nonlinear coach
   and single wheelset on S1002/60E1, and per bifurcation diagram, against the certified linear critical speed.

Timings are medians of repeated runs (``time.perf_counter``); results go to ``bench.csv`` and ``bench.md`` in
``--out`` (default ``runs/benchmarks/``; the committed rows: ``railopt bench --out results/benchmarks``), the full
campaign's row read from the ``timing.csv`` of ``cab_lateral_minimax_campaign`` beside that folder.
"""

from __future__ import annotations

import os
import platform
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd
from threadpoolctl import threadpool_limits

from railopt.design import MinimaxProblem, dask_client, multistart
from railopt.design.parallel import map_unordered
from railopt.models import LinearSystem
from railopt.models.stability import critical_speed
from railopt.models.tmd import nishihara_asami
from railopt.models.units import INCH, RAD_PER_HZ
from railopt.models.vehicle import load_vehicle
from railopt.studies.adapter import response_target
from railopt.studies.bench_baseline import baseline_row
from railopt.studies.bench_nonlinear import nonlinear_rows
from railopt.studies.bench_stability import critical_speed_rows, stacked_rows_row
from railopt.studies.config import load_study
from railopt.studies.kinds.campaign import campaign_problem
from railopt.studies.output.markdown import markdown_table
from railopt.studies.output.writer import Writer

__all__ = ["BUSY_CEILING", "busy_marked", "random_chain", "run_bench", "surface_row"]

STUDIES = Path(__file__).resolve().parent


def _median_time(fn: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times))


def _dense_peak(system, band: tuple[float, float], points: int) -> float:
    return float(np.max(np.abs(system.frf(omega_rad_s=np.linspace(*band, points)))))


def random_chain(n: int, seed: int, damping: float = 0.02, real_forcing: bool = False) -> LinearSystem:
    """A lightly damped non-symmetric n-DOF chain (creep-like skew terms of size 0.15/n, so that every chain of
    the bench is stable: with a fixed 0.05 the chains of n ≥ 9 flutter and U is +inf), unit-order masses.
    ``real_forcing``: a real F (a real state-space model, as python-control needs)."""
    rng = np.random.default_rng(seed)
    M = np.diag(rng.uniform(0.5, 2.0, n))
    k = rng.uniform(0.5, 3.0, n)
    K = np.diag(k + np.r_[k[1:], 0.0]) - np.diag(k[1:], 1) - np.diag(k[1:], -1)
    K += (0.15 / n) * (rng.standard_normal((n, n)) - rng.standard_normal((n, n)).T)
    C = damping * K + 0.01 * np.eye(n)
    F = rng.standard_normal(n) + (0.0 if real_forcing else 1j) * rng.standard_normal(n)
    return LinearSystem(M, C, K, F, rng.standard_normal(n))


def _state_space(system: LinearSystem):
    """The chain as a python-control state-space model: x = [q, q̇], u the (real) force amplitude, y = c·q."""
    import control

    n = system.n
    B = np.zeros((2 * n, 1))
    B[n:, 0] = np.linalg.solve(system.M, system.forcing_at(0.0).real)
    Cm = np.zeros((1, 2 * n))
    Cm[0, :n] = system.output
    return control.ss(system.state_matrix(), B, Cm, np.zeros((1, 1)))


CHAIN_SIZES = (3, 9, 15, 27, 60)  # the non-symmetric chains of the certified-U rows


def _certified_rows(reps: int) -> list[dict]:
    """Exact certified U against the thesis-method U and the floor on the non-symmetric chains, with the
    pole–residue form of H checked against direct solves."""
    rows = []
    for size in CHAIN_SIZES:
        chain = random_chain(size, seed=size)
        chain_band = (0.0, 1.2 * chain.damped_frequencies().max())
        n_reps = reps if size < 60 else max(reps // 5, 5)
        t_fl = _floor(chain, chain_band, n_reps)
        t_th = _median_time(lambda c=chain, b=chain_band: _fresh(c).response_maxima(band_rad_s=b), n_reps)
        t_ex = _median_time(lambda c=chain, b=chain_band: _fresh(c).response_maxima(band_rad_s=b, exact=True),
                            n_reps)
        w = np.linspace(*chain_band, 4001)
        direct = chain.frf_outputs(omega_rad_s=w)
        pr_err = float(np.max(np.abs(chain.pole_residue().evaluate(w) - direct)) / np.max(np.abs(direct)))
        rm = chain.response_maxima(band_rad_s=chain_band, exact=True)
        rows.append({"benchmark": f"exact certified U vs thesis U, non-symmetric n={size} ({rm.grid_points} "
                                  f"grid points)", "ours_s": t_ex, "reference_s": t_th,
                     "reference": "thesis-method U (eig + n+2 solves)", "ratio": t_ex / t_th,
                     "note": f"exact / floor {t_ex / t_fl:.2f}, thesis / floor {t_th / t_fl:.2f}; pole-residue vs "
                             f"direct H: max rel. diff {pr_err:.1e}"})
    return rows


FIRST_CALL = """
import time
t = time.perf_counter()
import numpy as np
from railopt.models import LinearSystem
K = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])
s = LinearSystem(np.diag([1.0, 2.0, 1.5]), 0.02 * K + 0.01 * np.eye(3), K, [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
s.response_maxima(band_rad_s=(0.0, 3.0), exact=True)
print(time.perf_counter() - t)
"""


def _first_call_row() -> dict:
    """Import and first certified U in a fresh process, with the kernels' cache (``NUMBA_CACHE_DIR``) empty (every
    kernel compiles) against the same process once that cache is written (the kernels load)."""
    import subprocess
    import sys
    import tempfile

    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        cold, warm = (float(subprocess.run([sys.executable, "-c", FIRST_CALL], env=env, check=True,
                                           capture_output=True, text=True).stdout.split()[-1]) for _ in range(2))
    return {"benchmark": "import railopt.models + first certified U (n=3) in a fresh process, kernel cache cold",
            "ours_s": cold,
            "reference_s": warm, "reference": "the same with the cache written (NUMBA_CACHE_DIR)",
            "ratio": cold / warm, "note": "the cold run compiles every kernel once per cache directory"}


def _linfnorm_rows(reps: int) -> list[dict]:
    """Exact certified U against python-control's ``linfnorm`` (SLICOT AB13DD) on the same chains without delays.

    AB13DD's L∞ norm is over all frequencies; the band (0, 1.2·max ω_d) of the thesis rows holds the peak of these
    displacement outputs (the agreement is printed in the note)."""
    try:
        import control
        import slycot  # noqa: F401  (linfnorm uses SLICOT's AB13DD)
    except ImportError:
        print("note: python-control/slycot not installed (pip install 'railopt[bench]'): the linfnorm rows are "
              "skipped")
        return []
    rows = []
    for size in CHAIN_SIZES:
        chain = random_chain(size, seed=size, real_forcing=True)
        band = (0.0, 1.2 * chain.damped_frequencies().max())
        ss = _state_space(chain)
        peak, _ = control.linfnorm(ss, tol=1e-12)
        ours = chain.response_maxima(band_rad_s=band, exact=True)
        n_reps = reps if size < 60 else max(reps // 5, 5)
        t_ours = _median_time(lambda c=chain, b=band: _fresh(c).response_maxima(band_rad_s=b, exact=True), n_reps)
        t_ref = _median_time(lambda m=ss: control.linfnorm(m, tol=1e-12), n_reps)
        diff = abs(ours.value - float(peak)) / float(peak)
        rows.append({"benchmark": f"exact certified U vs python-control linfnorm, non-symmetric n={size}",
                     "ours_s": t_ours, "reference_s": t_ref,
                     "reference": f"control.linfnorm (SLICOT AB13DD, python-control {control.__version__})",
                     "ratio": t_ours / t_ref,
                     "note": f"|ΔU|/U = {diff:.1e} ({'agree' if diff <= 1e-10 else 'DISAGREE'} to 1e-10); "
                             f"certified {ours.certified}"})
    return rows


def _stability_row(reps: int) -> dict:
    """Stability constraints with gradients (root_constraints) against their floor, one eig(G) per speed."""
    from railopt.models.stability_rows import root_constraints

    family = load_vehicle("sd40-2").lateral("rigid").family(["K2", "K3", "C13", "C15"])
    p = family.values
    speeds = [10.0, 20.0, 30.0]
    wrt = list(range(len(family.parameters)))
    Gs = [family.at(p, speed=S).state_matrix() for S in speeds]

    def floor() -> None:
        for G in Gs:
            np.linalg.eigvals(G)

    t_floor = _median_time(floor, reps)
    t_ours = _median_time(lambda: root_constraints(family, p, speeds, wrt=wrt), reps)
    g, dg = root_constraints(family, p, speeds, wrt=wrt)
    return {"benchmark": f"stability constraints + gradients, sd40-2 lateral rigid (n={family.n}, "
                         f"{len(speeds)} speeds, {dg.shape[1]} parameters)", "ours_s": t_ours,
            "reference_s": t_floor, "reference": "floor: one eig(G) per speed", "ratio": t_ours / t_floor,
            "note": f"{g.size} rows, max g = {np.max(g):.4g} 1/s"}


def _vehicle_summary_row() -> dict:
    """``railopt vehicle sd40-2``'s summary (modes, both critical speeds) against its two critical-speed searches."""
    from railopt.models.vehicle.summary import SPEED_RANGE, TOL, vehicle_summary

    loco = load_vehicle("sd40-2")
    t = time.perf_counter()
    vehicle_summary(loco, speed=25.0, track="flexible")
    t_summary = time.perf_counter() - t
    t = time.perf_counter()
    for track in ("rigid", "flexible"):
        critical_speed(loco, track=track, speed_range=SPEED_RANGE, tol=TOL)
    t_searches = time.perf_counter() - t
    return {"benchmark": "vehicle summary sd40-2 (railopt vehicle: masses, modes, critical speeds)",
            "ours_s": t_summary, "reference_s": t_searches, "reference": "its two critical-speed searches alone",
            "ratio": t_summary / t_searches, "note": "the CLI's promise: a summary in a few seconds"}


def _random_response_row(reps: int) -> dict:
    """RMS by adaptive quadrature (a) against the modal Lyapunov covariance (b) at equal accuracy."""
    from railopt.models.random_response import rms, rms_state_space
    from railopt.models.track.spectra import irregularity_spectrum
    from railopt.models.vehicle.irregularity import Irregularity

    speed = 25.0
    system = load_vehicle("sd40-2").lateral("rigid", speed=speed).forced_system(
        Irregularity("alignment", amplitude_m=1.0), ["body.v"], quantity="acceleration")
    spec = irregularity_spectrum("erri_b176", level="low", component="alignment")
    band = (1e-6, 1e3)  # the tails beyond are below 1e-10 of the variance
    lyap = rms_state_space(system, spec, speed)
    rtol = 1e-8
    quad = rms(system, spec.unbounded(), speed, band, rtol=rtol)
    t_q = _median_time(lambda: rms(system, spec.unbounded(), speed, band, rtol=rtol), 3)
    t_l = _median_time(lambda: rms_state_space(system, spec, speed), reps)
    return {"benchmark": f"random-response RMS by quadrature (rtol {rtol:g}, {band[0]:g}–{band[1]:g} Hz), "
                         "sd40-2 lateral, 6 delayed axles, ERRI low alignment", "ours_s": t_q, "reference_s": t_l,
            "reference": "modal Lyapunov covariance with exact delays (rms_state_space)", "ratio": t_q / t_l,
            "note": f"|Δrms|/rms = {abs(quad / lyap - 1):.1e}"}


def _floor(system: LinearSystem, band: tuple[float, float], reps: int) -> float:
    """Median time of the floor of one U(x): eig(G) plus n + 2 complex solves Z(Ω)X = F."""
    G = system.state_matrix()
    Zs = [system.impedance(w) for w in np.linspace(*band, system.n + 2)]
    F = system.forcing_at(1.0)

    def floor() -> None:
        np.linalg.eigvals(G)
        for Z in Zs:
            np.linalg.solve(Z, F)

    return _median_time(floor, reps)


def _fresh(sys: LinearSystem) -> LinearSystem:
    """The same system with empty caches (each timed U(x) pays for its eigen-decomposition)."""
    return LinearSystem._trusted(sys.M, sys.C, sys.K, sys.forcing, sys.outputs, sys.names)


def _plain_rate(n_starts: int, barrier=None, out=None) -> float:
    """Starts per second of the exact TMD multistart in this process, serial (one process of the ceiling row):
    warmed up, then timed from ``barrier`` (all processes start together); the rate is also put on ``out``."""
    _, config, _ = load_study(STUDIES / "tmd_hinf.toml")
    problem = campaign_problem(config, config.setups()["mu0.05"], "exact")
    with threadpool_limits(1):
        multistart(problem, 4, seed=99)  # warm (imports, caches)
        if barrier is not None:
            barrier.wait()
        t = time.perf_counter()
        multistart(problem, n_starts, seed=1)
        rate = n_starts / (time.perf_counter() - t)
    if out is not None:
        out.put(rate)
    return rate


def _plain_rates(processes: int, n_starts: int) -> list[float]:
    """The rates of ``processes`` plain spawned processes running the same starts at once."""
    import multiprocessing

    ctx = multiprocessing.get_context("spawn")
    barrier, out = ctx.Barrier(processes), ctx.Queue()
    procs = [ctx.Process(target=_plain_rate, args=(n_starts, barrier, out)) for _ in range(processes)]
    for proc in procs:
        proc.start()
    rates = [out.get() for _ in procs]
    for proc in procs:
        proc.join()
    return rates


def _ceiling_row(workers: int, n_starts: int) -> dict:
    """What this machine allows ``workers`` processes: the same starts in plain processes (no dask, no shared
    work) all at once, their summed rate against one such process alone (same starts, same count).  A dask
    speed-up can only approach it."""
    alone = _plain_rates(1, n_starts)[0]
    rates = _plain_rates(workers, n_starts)
    return {"benchmark": f"parallel ceiling of this machine: {workers} plain processes of the exact TMD multistart "
                         "at once (no dask)", "ours_s": 1.0 / sum(rates), "reference_s": 1.0 / alone,
            "reference": "one such process alone", "ratio": alone / sum(rates),
            "note": f"{alone:.1f} starts/s alone; " + ", ".join(f"{r:.1f}" for r in rates)
                    + f" starts/s at once ({sum(rates) / alone:.2f}× at best)"}


BUSY_CEILING = 1.8  # a ceiling (summed rate of 2 plain processes / one alone) below this: the machine is busy


def busy_marked(row: dict, ceiling: float, workers: int) -> dict:
    """``row`` of a parallel measurement, marked when the machine's measured ceiling (``workers`` plain processes
    at once against one alone, :func:`_ceiling_row`) is below :data:`BUSY_CEILING`: its ratio is left empty (the
    measured ratio goes into the note) and its name says so — other work on the machine took the cores, and the
    row measures that, not railopt."""
    if ceiling >= BUSY_CEILING:
        return row
    measured = row.get("ratio")
    shown = f"measured ratio {measured:.3g}; " if isinstance(measured, float) and np.isfinite(measured) else ""
    return {**row, "benchmark": f"[machine busy: not a result] {row['benchmark']}", "ratio": float("nan"),
            "note": f"machine busy: {workers} plain processes reached {ceiling:.2f}× one alone (< {BUSY_CEILING}×); "
                    f"{shown}{row.get('note', '')}"}


DISPATCH_WORKERS = (1, 2, 4)


def _loaded() -> bool:
    """Run on every worker before timing: unpickling it there imports this module (what :func:`_touch` needs)."""
    return True


def _touch(problem) -> int:
    """A task that only gets its problem (shipped or sent with it): what dispatching one task costs."""
    from railopt.design.parallel import resolve

    return len(resolve(problem).space.names)


def _dispatch_rates(problem: MinimaxProblem, client, n_tasks: int, n_starts: int) -> dict[str, float]:
    """Tasks/s on ``client``: empty tasks (:func:`_touch`) and a short-start campaign (one start per task,
    ``maxeval`` 1), each with the problem shipped once (``once``, as ``multistart`` does) and with the problem sent
    with every task (``each``: the tasks built by hand, as before issue 25); each rate the better of two runs."""
    from railopt.design.multistart import _StartBatch
    from railopt.design.parallel import call, map_unordered, shipping
    from railopt.design.starts import start_points

    def rate(fn, items) -> float:
        t = time.perf_counter()
        for _ in map_unordered(fn, items, client=client):
            pass
        return len(items) / (time.perf_counter() - t)

    options = {"maxeval": 1}
    # warm every worker: the modules of the tasks (this one, for _touch: running _loaded imports it) and the
    # solver's first call
    client.run(_loaded)
    multistart(problem, 2 * len(client.nthreads()), seed=99, batch=1, options=options, client=client)
    tasks = [_StartBatch(problem, (s,), "slsqp", options) for s in start_points(problem.space, n_starts, seed=1)]
    out: dict[str, float] = {}
    for _ in range(2):  # each the better of two, in turns (a busy machine's noise hits both alike)
        with shipping(client, problem) as handle:
            once = rate(_touch, [handle] * n_tasks)
        each = rate(_touch, [problem] * n_tasks)
        t = time.perf_counter()
        multistart(problem, n_starts, seed=1, batch=1, options=options, client=client)
        starts_once = n_starts / (time.perf_counter() - t)
        starts_each = rate(call, tasks)
        for key, value in (("tasks once", once), ("tasks each", each), ("starts once", starts_once),
                           ("starts each", starts_each)):
            out[key] = max(out.get(key, 0.0), value)
    return out


def _dispatch_rows(quick: bool, ceiling: float, workers: int) -> list[dict]:
    """Task dispatch of the flagship's exact cab problem (~190 kB pickled) at 1, 2 and 4 local workers: tasks/s
    with the problem shipped once per campaign (ours) against the problem sent with every task (reference), for
    empty tasks (the transport alone) and for a short-start campaign (one start of ``maxeval`` 1 per task); the
    ratio is the time per task, ours / reference, at the most workers."""
    import cloudpickle

    _, config, _ = load_study(STUDIES / "cab_lateral_minimax.toml")
    problem = campaign_problem(config, config.setups()["sd40-2"], "exact")
    size = len(cloudpickle.dumps(problem))
    n_tasks, n_starts = (60, 40) if quick else (300, 120)
    t = time.perf_counter()
    multistart(problem, n_starts // 4, seed=1, batch=1, options={"maxeval": 1})
    serial = (n_starts // 4) / (time.perf_counter() - t)
    rates = {}
    for n in DISPATCH_WORKERS:
        with dask_client(workers=n) as client:
            rates[n] = _dispatch_rates(problem, client, n_tasks, n_starts)
    top = max(DISPATCH_WORKERS)
    cpus = os.cpu_count() or 1
    machine = (f"{cpus} CPUs, measured ceiling of {workers} processes {ceiling:.2f}×"
               + (f"; {top} workers oversubscribe {cpus} CPUs" if top > cpus else ""))

    def row(kind: str, what: str, extra: str) -> dict:
        once, each = rates[top][f"{kind} once"], rates[top][f"{kind} each"]
        return {"benchmark": f"task dispatch, {what} (flagship exact cab problem, {size / 1e3:.0f} kB pickled), "
                             "problem shipped once per campaign",
                "ours_s": 1.0 / once, "reference_s": 1.0 / each,
                "reference": f"the problem sent with every task; s per task at {top} workers", "ratio": each / once,
                "note": "tasks/s shipped once / sent with every task: "
                        + ", ".join(f"{n} worker{'s' if n > 1 else ''} {rates[n][f'{kind} once']:.0f} / "
                                    f"{rates[n][f'{kind} each']:.0f}" for n in DISPATCH_WORKERS)
                        + f"; {extra}{machine}"}

    return [row("tasks", f"{n_tasks} empty tasks", ""),
            row("starts", f"short-start campaign, {n_starts} tasks of one start (maxeval 1)",
                f"serial {serial:.0f} starts/s; ")]


def _throughput(problem: MinimaxProblem, objective: str, workers: int, sizes: tuple[int, ...]) -> list[dict]:
    """Starts per second of ``problem``'s multistart, serial against a LocalCluster of ``workers``, at each campaign
    size: for the TMD a short campaign (dask's fixed cost per campaign and per task weighs on ~1 s of work) and a
    long one (the throughput a campaign of many starts gets); ``objective`` names the problem in the rows."""
    serial, runs = {}, {}
    multistart(problem, 2 * workers, seed=99)  # warm this process (first calls, caches), as the workers below
    for n in sizes:
        serial[n], runs[n] = _median_run(lambda n=n: multistart(problem, n, seed=1))
    rows = []
    with dask_client(workers=workers) as client:
        multistart(problem, 2 * workers, seed=99, client=client)  # warm the workers (imports)
        for n in sizes:
            t_dask, _ = _median_run(lambda n=n: multistart(problem, n, seed=1, client=client), runs[n])
            rows.append({"benchmark": f"multistart throughput, {n:,} starts ({objective})",
                         "ours_s": t_dask / n, "reference_s": serial[n] / n,
                         "reference": f"serial; ours = dask LocalCluster, {workers} workers",
                         "ratio": t_dask / serial[n],
                         "note": f"{n / serial[n]:.1f} starts/s serial, {n / t_dask:.1f} starts/s dask; "
                                 f"{serial[n]:.1f} s of serial work; both warmed, median of {runs[n]} "
                                 f"run{'s' if runs[n] > 1 else ''} each"})
    return rows


SHORT_RUN_S = 5.0  # a campaign measured once when its serial run takes longer; else the median of 3 runs


def _median_run(run: Callable[[], object], count: int | None = None) -> tuple[float, int]:
    """Wall time of ``run()``: the median of ``count`` runs, or (``count`` None) of 3 when the first takes under
    :data:`SHORT_RUN_S` (a one-second campaign varies by several per cent run to run), else that one; returns
    the time and the number of runs."""
    first = _median_time(run, 1)
    count = count if count is not None else (3 if first < SHORT_RUN_S else 1)
    times = [first] + [_median_time(run, 1) for _ in range(count - 1)]
    return float(np.median(times)), count


def _spin(seconds: float) -> float:
    """Burn ``seconds`` of this thread's CPU time in pure Python (no railopt code): a task of known work."""
    end = time.thread_time() + seconds
    while time.thread_time() < end:
        pass
    return seconds


def _dask_floor_row(workers: int, work_s: float, n_starts: int, tasks: int = 16) -> dict:
    """What dask itself leaves of ``workers`` on a campaign of ``work_s`` seconds of serial work (the ``n_starts``-start
    TMD campaign's): ``tasks`` tasks of pure CPU (``_spin``, no railopt code) in the same LocalCluster set-up, against
    the same spins in this process.
    A short campaign's speed-up can only approach it: the gap is dask's cost per task and per map, on the same
    cores as the workers."""
    each = work_s / tasks
    t = time.perf_counter()
    for _ in range(tasks):
        _spin(each)
    serial = time.perf_counter() - t
    with dask_client(workers=workers) as client:
        list(map_unordered(_spin, [each] * 2 * workers, client=client))  # warm the workers (imports)
        times = []
        for _ in range(3):
            t = time.perf_counter()
            list(map_unordered(_spin, [each] * tasks, client=client))
            times.append(time.perf_counter() - t)
    ours = float(np.median(times))
    return {"benchmark": f"dask's own floor on {work_s:.1f} s of work: {tasks} tasks of pure CPU (no railopt code)",
            "ours_s": ours, "reference_s": serial, "reference": f"the same spins serially; ours = dask LocalCluster, "
            f"{workers} workers", "ratio": ours / serial,
            "note": f"{serial / ours:.2f}× speed-up: what dask's cost per task and per map leaves of {workers} "
                    f"workers at this size (the {n_starts}-start TMD campaign's serial work, in about as many "
                    "tasks)"}


def _cab_throughput(workers: int, quick: bool) -> dict:
    """Starts per second of the flagship's exact cab problem, serial against a LocalCluster."""
    _, config, _ = load_study(STUDIES / "cab_lateral_minimax.toml")
    problem = campaign_problem(config, config.setups()["sd40-2"], "exact")
    return _throughput(problem, "exact cab objective, the flagship", workers, (8 if quick else 32,))[0]


def _finite_difference_twin(problem: MinimaxProblem, constrained: bool) -> MinimaxProblem:
    """The same problem with finite-difference Jacobians: the same f and, where constrained (stability rows,
    strokes), the same g and ε, and the same exchange (each refined problem gets its twin too) — so that both
    solve the same semi-infinite problem (without the exchange the twin stops at a design the stability rows meet
    only at their grid speeds)."""
    def refine(x: np.ndarray) -> MinimaxProblem | None:
        refined = problem.refine(x)
        return None if refined is None else _finite_difference_twin(refined, constrained)

    return MinimaxProblem(problem.variables, lambda y: problem.evaluate(y).f,
                          constraints=(lambda y: problem.evaluate(y).g) if constrained else None,
                          epsilon=problem.epsilon if constrained else 0.0,
                          refine=refine if problem.refine is not None else None)


def _cab_rows(repeat: int) -> list[dict]:
    """U(x) of the cab model against its floor; SLSQP analytic vs FD gradients to the same optimum."""
    from railopt.design import solve

    _, config, _ = load_study(STUDIES / "cab_lateral_minimax.toml")
    setup = config.setups()["sd40-2"]
    names = [v.name for v in config.design.variables]
    x0 = np.array([setup.named_designs["existing"][n] for n in names])
    p, _ = setup.parameters(names, x0)
    cab = setup.family.at(p)
    band = response_target(config.objective, setup, exact=True).band
    reps = max(repeat // 4, 5)
    t_floor = _floor(cab, band, reps)
    t_thesis = _median_time(lambda: _fresh(cab).response_maxima(band_rad_s=band, output="cab_acceleration"), reps)
    t_exact = _median_time(
        lambda: _fresh(cab).response_maxima(band_rad_s=band, exact=True, output="cab_acceleration"), reps)
    rows = [{"benchmark": f"U(x), cab model (n={cab.n}, {len(cab.forcing.terms)} forcing term(s)), thesis method",
             "ours_s": t_thesis,
             "reference_s": t_floor, "reference": "floor: eig(G) + (n+2) complex solves", "ratio": t_thesis / t_floor},
            {"benchmark": "U(x), cab model, exact certified", "ours_s": t_exact, "reference_s": t_floor,
             "reference": "floor: eig(G) + (n+2) complex solves", "ratio": t_exact / t_floor,
             "note": f"exact / thesis {t_exact / t_thesis:.2f}"}]
    # the full lateral model with creep (rigid track, 9 DOF), forced by a delayed alignment: cab acceleration
    from railopt.models.vehicle.irregularity import Irregularity

    lateral = load_vehicle("sd40-2").lateral("rigid", speed=20.0)
    full = lateral.forced_system(Irregularity("alignment", 0.25 * INCH), ["cab.lateral"], quantity="acceleration")
    fband = (0.1 * RAD_PER_HZ, 3.0 * RAD_PER_HZ)
    t_ff = _floor(full, fband, reps)
    t_ft = _median_time(lambda: _fresh(full).response_maxima(band_rad_s=fband), reps)
    t_fe = _median_time(lambda: _fresh(full).response_maxima(band_rad_s=fband, exact=True), reps)
    rows += [{"benchmark": f"U(x), full lateral model with creep (n={full.n}, 6 delayed axle inputs), thesis method",
              "ours_s": t_ft, "reference_s": t_ff, "reference": "floor: eig(G) + (n+2) complex solves",
              "ratio": t_ft / t_ff},
             {"benchmark": "U(x), full lateral model, exact certified", "ours_s": t_fe, "reference_s": t_ff,
              "reference": "floor: eig(G) + (n+2) complex solves", "ratio": t_fe / t_ff,
              "note": f"exact / thesis {t_fe / t_ft:.2f}"}]
    analytic = campaign_problem(config, setup, "exact")
    fd = _finite_difference_twin(analytic, analytic.evaluate(x0).g.size > 0)
    t = time.perf_counter()
    ra = solve(analytic, x0, method="slsqp", xtol=1e-8, ftol=1e-10)
    t_a = time.perf_counter() - t
    t = time.perf_counter()
    rf = solve(fd, x0, method="slsqp", xtol=1e-8, ftol=1e-10)
    t_f = time.perf_counter() - t
    rows.append({"benchmark": f"SLSQP on the cab problem, analytic gradients: {ra.evaluations} evaluations, "
                              f"U = {ra.value:.6g}", "ours_s": t_a, "reference_s": t_f,
                 "reference": f"finite-difference gradients: {rf.evaluations} evaluations, U = {rf.value:.6g}",
                 "ratio": t_a / t_f, "note": f"|ΔU|/U = {abs(ra.value - rf.value) / rf.value:.1e}"})
    return rows


def surface_row(points: int | None = None, repeat: int = 5) -> dict:
    """The flagship's objective surface ([[surfaces]] of cab_lateral_minimax.toml: U over its two variables, the
    others at the existing design) by :func:`~railopt.design.objective_surface`, batched (one compiled call per block
    of whole rows, about :data:`~railopt.design.surface.BLOCK_POINTS` designs: one for 21 × 21,
    :func:`~railopt.models.response_maxima.batch_response_maxima`) against the same surface of the same
    objective without ``batch_functions`` (one ``value`` per point, the solvers' path), medians of ``repeat`` runs;
    the note gives the largest relative difference (issue 25: ≥ 5× faster)."""
    from railopt.design import objective_surface

    _, config, _ = load_study(STUDIES / "cab_lateral_minimax.toml")
    setup = config.setups()["sd40-2"]
    problem = campaign_problem(config, setup, "exact", "unconstrained")
    plain = MinimaxProblem(problem.variables, lambda x: problem.evaluate(x).f)  # the same f, point by point
    spec = config.surfaces[0]
    points = points or spec.points
    space = problem.space
    names = [v.name for v in config.design.variables]
    base = np.array([setup.named_designs["existing"][n] for n in names])
    xi, xj = (np.geomspace(space.lower[space.names.index(v)], space.upper[space.names.index(v)], points)
              for v in spec.variables)
    variables = tuple(spec.variables)
    objective_surface(problem, variables, xi[:2], xj[:2], base)  # compiled kernels loaded

    batched = objective_surface(problem, variables, xi, xj, base).values
    pointwise = objective_surface(plain, variables, xi, xj, base).values
    t_batch = _median_time(lambda: objective_surface(problem, variables, xi, xj, base), repeat)
    t_plain = _median_time(lambda: objective_surface(plain, variables, xi, xj, base), repeat)
    finite = np.isfinite(pointwise)
    diff = float(np.max(np.abs(batched[finite] - pointwise[finite]) / pointwise[finite], initial=0.0))
    same = bool(np.array_equal(np.isfinite(batched), finite))
    return {"benchmark": f"objective surface of the flagship ({points}×{points}, exact cab U), batched",
            "ours_s": t_batch, "reference_s": t_plain, "reference": "the same surface point by point (no batch)",
            "ratio": t_batch / t_plain,
            "note": f"speed-up {t_plain / t_batch:.1f}×; max |ΔU|/U = {diff:.1e}"
                    + ("" if same else "; the refused points DIFFER")}


MEMORY_LIMIT_MB = 50.0  # issue 18: RSS growth after warm-up of a 10,000-start campaign


def _memory_row(workers: int, n_starts: int) -> dict:
    """RSS growth of a long TMD campaign (driver + dask workers) from the end of its warm-up (the first tenth)
    to its end, with its SQLite store on disk as a study run has it."""
    import tempfile

    import psutil

    from railopt.design import CampaignStore

    def rss(client) -> tuple[float, float]:
        workers_rss = client.run(lambda: psutil.Process().memory_info().rss)
        return psutil.Process().memory_info().rss / 1e6, sum(workers_rss.values()) / 1e6

    _, config, _ = load_study(STUDIES / "tmd_hinf.toml")
    problem = campaign_problem(config, config.setups()["mu0.05"], "thesis")
    warm = n_starts // 10
    samples: dict[int, tuple[float, float]] = {}
    with tempfile.TemporaryDirectory() as tmp, dask_client(workers=workers) as client, \
            CampaignStore.create(Path(tmp) / "memory.sqlite", "memory", {}, problem.space.names) as store:
        def progress(done: int, total: int) -> None:
            if done in (warm, total) and done not in samples:
                samples[done] = rss(client)

        t = time.perf_counter()
        table = multistart(problem, n_starts, seed=7, client=client, store=store, progress=progress)
        elapsed = time.perf_counter() - t
    (d0, w0), (d1, w1) = samples[warm], samples[len(table)]
    growth = (d1 + w1) - (d0 + w0)
    return {"benchmark": f"memory: {len(table):,}-start TMD campaign (thesis objective, {workers} dask workers, "
                         "SQLite store on disk), RSS growth after warm-up", "ours_s": growth,
            "reference_s": MEMORY_LIMIT_MB, "reference": f"limit {MEMORY_LIMIT_MB:.0f} MB (the columns are MB here)",
            "ratio": growth / MEMORY_LIMIT_MB,
            "note": f"driver {d0:.0f} → {d1:.0f} MB, workers {w0:.0f} → {w1:.0f} MB from start {warm:,} to the end; "
                    f"{len(table) / elapsed:.0f} starts/s"}


def _campaign_row(results: Path, study: str = "cab_lateral_minimax_campaign", goal: float = 300.0) -> dict:
    """A bundled campaign's wall time as its last ``railopt run`` recorded it (``timing.csv``) against ``goal`` s."""
    path = results / study / "timing.csv"
    row = {"benchmark": f"full campaign {study}.toml", "reference_s": goal,
           "reference": f"goal: {goal / 60:g} min on 2 cores"}
    if not path.exists():
        return {**row, "note": f"not run yet: no {path}"}
    t = pd.read_csv(path).iloc[0]
    if bool(t.get("resumed", False)):
        return {**row, "note": f"its last run resumed stored starts ({path}): not a timing of the whole campaign; "
                               "run it with --fresh"}
    starts = path.with_name("starts.csv")
    count = f"{len(pd.read_csv(starts)):,} starts" if starts.exists() else "its starts"
    return {**row, "benchmark": f"{row['benchmark']} ({count}, checks, trade-offs, surfaces), as recorded by its "
                                "last run", "ours_s": float(t["total_s"]), "ratio": float(t["total_s"]) / goal,
            "note": f"compute {t['compute_s']:.0f} s + report {t['report_s']:.0f} s; {t['workers']}, "
                    f"{t['cpus']} CPUs (railopt run studies/{study}.toml)"}


def run_bench(out: Path, workers: int = 2, quick: bool = False) -> pd.DataFrame:
    """Run every benchmark, print a table of ratios, and write it to ``out``."""
    with threadpool_limits(1):  # every timing with single-threaded BLAS, as the campaign tasks run
        return _run(out, workers, quick)


def _run(out: Path, workers: int, quick: bool) -> pd.DataFrame:
    repeat = 20 if quick else 200
    mu = 0.05
    _, config, _ = load_study(STUDIES / "tmd_hinf.toml")
    setup = config.setups()["mu0.05"]
    ps = setup.family
    band = response_target(config.objective, setup, exact=True).band
    na = nishihara_asami(mu)
    p, _ = setup.parameters(["tuning", "damping_ratio"], np.array([na.tuning, na.damping_ratio]))
    sys = ps.at(p)
    rows = []

    # 4. the machine's parallel ceiling first, then starts per second, serial vs dask (measured before large BLAS
    # calls spin up threads); below BUSY_CEILING the parallel rows are marked, not given as results
    n_starts = 16 if quick else 64
    ceiling_row = _ceiling_row(workers, n_starts)
    ceiling = 1.0 / ceiling_row["ratio"]
    problem = campaign_problem(config, setup, "exact")
    tmd = _throughput(problem, "exact TMD objective", workers, (n_starts, 16 * n_starts))
    parallel = [*tmd, _dask_floor_row(workers, tmd[0]["reference_s"] * n_starts, n_starts),
                _cab_throughput(workers, quick), *_dispatch_rows(quick, ceiling, workers)]
    rows.append(ceiling_row)
    rows += [busy_marked(row, ceiling, workers) for row in parallel]

    # 1. U(x) vs the floor -------------------------------------------------------------------
    t_floor = _floor(sys, band, repeat)
    t_thesis = _median_time(lambda: ps.response_maxima(p, band_rad_s=band), repeat)
    t_exact = _median_time(lambda: ps.response_maxima(p, band_rad_s=band, exact=True), max(repeat // 10, 5))
    rows.append({"benchmark": "U(x), thesis method, TMD (n=2)", "ours_s": t_thesis, "reference_s": t_floor,
                 "reference": "floor: eig(G) + (n+2) complex solves", "ratio": t_thesis / t_floor})

    # 2. thesis / exact vs dense sweep at equal accuracy ----------------------------------------
    exact_peak = ps.response_maxima(p, band_rad_s=band, exact=True).value
    thesis_err = abs(ps.response_maxima(p, band_rad_s=band).value - exact_peak) / exact_peak
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
    analytic = campaign_problem(config, setup, "thesis")
    x = np.array([na.tuning, na.damping_ratio])
    t_grad = _median_time(lambda: analytic.evaluate(x, gradient=True), repeat)
    finite_diff = MinimaxProblem(analytic.variables, lambda y: analytic.evaluate(y).f)  # same f, FD Jacobian
    t_fd = _median_time(lambda: finite_diff.evaluate(x, gradient=True), repeat)
    grad_err = analytic.gradient_check(x)
    rows.append({"benchmark": f"analytic f_k + Jacobian (max rel. diff to FD {grad_err:.1e})", "ours_s": t_grad,
                 "reference_s": t_fd, "reference": "central finite differences (2d+1 evaluations)",
                 "ratio": t_grad / t_fd})

    # 1b. exact vs thesis vs floor for larger non-symmetric systems; pole–residue vs direct ------------
    rows += _certified_rows(max(repeat // 4, 5))
    rows += _linfnorm_rows(max(repeat // 4, 5))
    rows.append(_first_call_row())

    # 5. critical speed: certified (bialternate pencil) vs the sampled search and a dense scan ------------
    rows += critical_speed_rows()
    rows += nonlinear_rows(quick)

    rows.append(_vehicle_summary_row())

    # 6. the flagship cab model: U(x) vs the floor; SLSQP with analytic vs finite-difference gradients ------
    rows += _cab_rows(repeat)
    if not quick:  # ~50 s: the baseline commit's code from the checkout's history, in fresh processes
        rows.append(baseline_row())

    # 7. stability constraints with gradients; random response by quadrature vs Lyapunov ------------------------
    rows.append(_stability_row(max(repeat // 4, 5)))
    rows.append(stacked_rows_row(max(repeat // 4, 5)))
    rows.append(surface_row(repeat=5 if quick else 11))
    rows.append(_random_response_row(max(repeat // 4, 5)))

    # 8. campaign scale: memory of a long campaign; the full flagship campaign as last run -------------------
    rows.append(_memory_row(workers, 1000 if quick else 10_000))
    rows.append(_campaign_row(out.parent, "cab_lateral_minimax", 120.0))  # the flagship (README command 1)
    rows.append(_campaign_row(out.parent))

    table = pd.DataFrame(rows, columns=["benchmark", "ours_s", "reference_s", "ratio", "reference", "note"])
    Writer(out).table(table, "bench")
    header = (f"# railopt bench\n\nMachine: {platform.machine()}, {os.cpu_count()} CPUs, Python "
              f"{platform.python_version()}, {platform.system()}; repeat={repeat}. Times are medians in seconds; "
              "ratio = ours / reference (below 1 is faster).\n\n")
    (out / "bench.md").write_text(header + markdown_table(table.fillna(""), digits=3) + "\n")
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    print(f"\nwritten to {out}/bench.csv and bench.md")
    return table
