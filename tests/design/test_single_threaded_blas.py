"""Tasks run with single-threaded BLAS; the threadpool controller is built once per process (not per task) and
rebuilt when a module was imported since (a new extension may bring another BLAS)."""

from __future__ import annotations

from threadpoolctl import threadpool_info

from railopt.design import parallel
from railopt.design.parallel import map_unordered


def _blas_threads(_item) -> list[int]:
    return [lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"]


def test_every_task_sees_one_blas_thread_and_the_limit_is_lifted_afterwards():
    before = _blas_threads(None)
    results = list(map_unordered(_blas_threads, list(range(4))))
    assert results and all(threads and set(threads) == {1} for threads in results)
    assert _blas_threads(None) == before


def test_the_controller_is_reused_until_a_module_is_imported(monkeypatch):
    first = parallel._blas_controller()
    assert parallel._blas_controller() is first
    monkeypatch.setitem(__import__("sys").modules, "railopt_fake_new_module", object())
    assert parallel._blas_controller() is not first
