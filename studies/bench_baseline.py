"""``railopt bench`` row of a constrained flagship start against the code of an earlier commit, in the same run.

Issue 25 asks for a constrained flagship start at ≤ 0.5× "today's time" on the same machine in the same run; its
today is commit :data:`BASELINE_COMMIT`.  The bench takes that commit's ``railopt``, ``models``, ``design`` and
``studies`` folders from the checkout's git history (``git archive``), lays them out as the ``railopt`` package in a
temporary folder, and runs the same constrained multistart of the flagship (SLSQP, exact objective, the stability
rows; ``BASELINE_STARTS`` starts from the same Sobol seed, after two warm-up starts, one BLAS thread) in fresh
processes, old and current alternating, :data:`BASELINE_ROUNDS` rounds; the row gives the median time of each and
checks that both found the same U at every start (the same problem: within :data:`SAME_U`, else the row is
not a result).  Without git or that commit (an installed package, a shallow clone) the row says it was skipped; a
run that fails makes the row "failed, not a result", never the whole bench.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
BASELINE_COMMIT = "54b5f8ccf59cf7a185d350edbff1300fbdcc0381"
"""The commit whose constrained flagship start is issue 25's "today's time"."""
BASELINE_STARTS = 6
BASELINE_ROUNDS = 3
SAME_U = 1e-8  # the two codes' U at every start agree within this (relative), or the row is not a result

HERMETIC = """
import sys
# the editable install's finder would hand a module the old tree lacks over from the current checkout
sys.meta_path[:] = [f for f in sys.meta_path if not (getattr(f, "__module__", None) or "").startswith("__editable__")]
"""
"""Prepended to the baseline's process: only the laid-out commit's code is importable as ``railopt``."""

_RUN = """
import json, sys, time
from pathlib import Path
from threadpoolctl import threadpool_limits
import railopt
from railopt.design.multistart import multistart
from railopt.studies.config import load_study
from railopt.studies.kinds.campaign import campaign_problem
_, config, _ = load_study(Path(sys.argv[1]))
problem = campaign_problem(config, config.setups()["sd40-2"], "exact")
with threadpool_limits(1):
    multistart(problem, 2, seed=99)
    t = time.perf_counter()
    table = multistart(problem, int(sys.argv[2]), seed=1).sort_values("start_id")
    seconds = time.perf_counter() - t
print(json.dumps({"railopt": railopt.__file__, "seconds": seconds, "U": table["value"].tolist(),
                  "evaluations": table["evaluations"].tolist()}))
"""


def _old_package(folder: Path) -> Path:
    """The baseline commit's code laid out as the ``railopt`` package under ``folder``; returns the folder to put
    on PYTHONPATH.  Raises CalledProcessError or OSError where the checkout cannot give it."""
    src = folder / "src"
    src.mkdir()
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", BASELINE_COMMIT, "railopt", "models", "design",
                              "studies"], check=True, capture_output=True, timeout=120).stdout
    subprocess.run(["tar", "-x", "-C", str(src)], input=archive, check=True, capture_output=True, timeout=120)
    package = folder / "pkg" / "railopt"
    shutil.copytree(src / "railopt", package)
    for part in ("models", "design", "studies"):  # the pyproject's package-dir mapping
        shutil.copytree(src / part, package / part)
    return folder / "pkg"


def _start_times(pythonpath: Path | None, study: Path, expected: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    if pythonpath is not None:
        env["PYTHONPATH"] = str(pythonpath)
    code = (HERMETIC if pythonpath is not None else "") + _RUN
    # -P: the working folder stays off sys.path (the studies folder's modules must not become top-level names)
    done = subprocess.run([sys.executable, "-P", "-c", code, str(study), str(BASELINE_STARTS)], env=env,
                          cwd=str(study.parent), capture_output=True, text=True, timeout=900)
    if done.returncode != 0:
        tail = " | ".join(done.stderr.strip().splitlines()[-3:])
        raise RuntimeError(f"exit status {done.returncode}: {tail}")
    out = json.loads(done.stdout.strip().splitlines()[-1])
    if not Path(out["railopt"]).resolve().is_relative_to(expected.resolve()):
        raise RuntimeError(f"the run imported railopt from {out['railopt']}, not from {expected}")
    return out


def baseline_row() -> dict:
    """The row: median seconds of the constrained starts now against at :data:`BASELINE_COMMIT` (a ratio ≤ 0.5 is
    the issue's goal), with the largest relative difference of U between the two (the same problem)."""
    name = (f"constrained flagship start (SLSQP, exact cab U, stability rows; {BASELINE_STARTS} starts, fresh "
            f"processes alternating, median of {BASELINE_ROUNDS})")
    if shutil.which("git") is None or shutil.which("tar") is None:
        return {"benchmark": name, "note": "skipped: needs git and tar (the baseline is built from the checkout's "
                                           "history)"}
    with tempfile.TemporaryDirectory(prefix="railopt-baseline-") as tmp:
        try:
            old_path = _old_package(Path(tmp))
        except subprocess.CalledProcessError as exc:
            return {"benchmark": name, "note": f"skipped: commit {BASELINE_COMMIT} is not in this checkout's history "
                                               f"(git: {(exc.stderr or b'').decode(errors='replace').strip()[:120]}; "
                                               "a shallow clone or an installed package)"}
        except (OSError, subprocess.TimeoutExpired) as exc:
            return {"benchmark": name, "note": f"skipped: the baseline could not be laid out ({type(exc).__name__}: "
                                               f"{exc})"}
        old_study = old_path / "railopt" / "studies" / "cab_lateral_minimax.toml"
        new_study = ROOT / "studies" / "cab_lateral_minimax.toml"
        old, new = [], []
        try:
            for _ in range(BASELINE_ROUNDS):
                old.append(_start_times(old_path, old_study, old_path))
                new.append(_start_times(None, new_study, ROOT))
        except (RuntimeError, ValueError, KeyError, IndexError, subprocess.TimeoutExpired) as exc:
            return {"benchmark": name, "ratio": float("nan"),
                    "note": f"failed, not a result: {'the baseline' if len(old) == len(new) else 'the current code'} "
                            f"run ({type(exc).__name__}: {exc})"}
    t_old = float(np.median([r["seconds"] for r in old]))
    t_new = float(np.median([r["seconds"] for r in new]))
    u_old, u_new = np.array(old[0]["U"], dtype=float), np.array(new[0]["U"], dtype=float)
    runs = (", ".join(f"{r['seconds']:.2f}" for r in old) + " s then, "
            + ", ".join(f"{r['seconds']:.2f}" for r in new) + " s now")
    if u_old.shape != u_new.shape or not (np.all(np.isfinite(u_old)) and np.all(np.isfinite(u_new))):
        return {"benchmark": name, "ratio": float("nan"),
                "note": f"not a result: the two runs did not solve the same starts (U {u_old.tolist()} then, "
                        f"{u_new.tolist()} now); {runs}"}
    diff = float(np.max(np.abs(u_new - u_old) / np.abs(u_old)))
    if diff > SAME_U:
        return {"benchmark": name, "ratio": float("nan"),
                "note": f"not a result: U differs by {diff:.1e} > {SAME_U:g} between the two codes (not the same "
                        f"problem); {runs}"}
    evaluations = f"evaluations {sum(old[0]['evaluations'])} then, {sum(new[0]['evaluations'])} now"
    return {"benchmark": name, "ours_s": t_new / BASELINE_STARTS, "reference_s": t_old / BASELINE_STARTS,
            "reference": f"the same starts with the code of commit {BASELINE_COMMIT[:7]} (issue 25's \"today\")",
            "ratio": t_new / t_old,
            "note": f"goal ≤ 0.5×; max |ΔU|/U over the starts {diff:.1e} (the same problem; {evaluations}); "
                    f"runs {runs}"}


__all__ = ["BASELINE_COMMIT", "HERMETIC", "baseline_row"]
