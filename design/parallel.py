"""Where tasks run: in-process, or on dask.distributed (an embedded LocalCluster or a scheduler).

The design layer takes an optional ``client``; with none, the same code runs serially.
Results stream back in completion order; a lost worker's tasks are retried by the scheduler.
Every task runs with single-threaded BLAS: parallelism is across tasks, small matrices gain
nothing from threads, and a threaded BLAS rounds differently — with it, a serial run and a
dask run of the same campaign would not give the same table.

Failures the dask paths turn into one clear exception (never a dask traceback, never a hang):

* a task that cannot be pickled: ``ValueError`` naming what cannot be sent (e.g. ``problem.functions``),
  raised before anything is submitted (:func:`check_picklable`);
* a task that kills every worker it runs on (a crash in native code, out of memory): with ``on_lost``
  the task's result is made by ``on_lost(item, exc)`` (``multistart`` stores the start as
  ``worker_lost``) and the other tasks go on; without it :class:`WorkerLost` is raised;
* a scheduler address that is not a dask scheduler, that never answers, that has no workers, or that
  goes away during the run: :class:`SchedulerError` (a ``ConnectionError``) naming the address and the
  way out, within the scheduler timeout plus :data:`SCHEDULER_MARGIN` seconds.

What a cluster did is recorded (:func:`cluster_record`): the workers at the start, at the end and the most seen,
the workers lost while a map ran and how many of its tasks they were running — tasks the scheduler re-ran on
other workers, which changes no result (every task is self-contained) but must be said (``railopt run`` prints it
and writes it to ``timing.csv``).

Shipping.  A campaign's problem goes to the workers once (:func:`shipping`, a worker plugin the scheduler also
gives to workers that join later), and its tasks carry a :class:`Shipped` handle instead of the problem.
:func:`map_unordered_groups` gives the results that finished together in one list, for a consumer that does one
costly thing per list (the campaign store's group commit).

Logs.  While a client made by :func:`dask_client` is open, dask's own log lines (warnings about
restarted workers, cancelled instructions at shutdown) are kept out of the terminal: set
``$RAILOPT_DASK_LOGS`` to a level name (e.g. ``WARNING``) to see them.  The workers of the embedded
LocalCluster ignore SIGINT: Ctrl-C in a terminal (SIGINT to the whole process group) interrupts the
main process only, which shuts the cluster down.
"""

from __future__ import annotations

import itertools
import logging
import math
import numbers
import os
import queue
import signal
import sys
import threading
import time
import weakref
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field, fields, is_dataclass
from pathlib import Path
from typing import Any

from threadpoolctl import ThreadpoolController

from railopt.design.runner import Runner

SCHEDULER_ENV = "RAILOPT_SCHEDULER"
SCHEDULER_TIMEOUT_ENV = "RAILOPT_SCHEDULER_TIMEOUT"
DASK_LOGS_ENV = "RAILOPT_DASK_LOGS"
DEFAULT_SCHEDULER_TIMEOUT = 5.0
SCHEDULER_MARGIN = 5.0  # s beyond the scheduler timeout that giving up on a silent or dead scheduler may take
_POLL = 1.0  # s between checks of the scheduler's health while waiting for results (each costs the scheduler CPU)
LOCAL_NO_WORKERS_LIMIT = 120.0  # s the embedded LocalCluster may have no worker (restarting) before an error


def _worker_setup_source() -> str:
    """The worker preload as source text: a restarted worker registers without importing railopt first."""
    return (Path(__file__).with_name("_worker_setup.py")).read_text()


@dataclass(frozen=True)
class _SingleThreaded:
    fn: Callable[[Any], Any]

    def __call__(self, item: Any) -> Any:
        with _blas_controller().limit(limits=1, user_api="blas"):
            return self.fn(item)


_CONTROLLER: tuple[int, ThreadpoolController] | None = None


def _blas_controller() -> ThreadpoolController:
    """The process's threadpool controller, rebuilt only when a module was imported since (a new extension may
    have loaded another BLAS).  ``threadpool_limits`` scans every loaded library on each call — about 1.3 ms, more
    than a batched surface row's own work."""
    global _CONTROLLER
    loaded = len(sys.modules)
    if _CONTROLLER is None or _CONTROLLER[0] != loaded:
        _CONTROLLER = (loaded, ThreadpoolController())
    return _CONTROLLER[1]


def call(task: Callable[[], Any]) -> Any:
    """Run a self-contained task object: ``map_unordered(call, tasks, client)``."""
    return task()


class SchedulerError(ConnectionError):
    """The dask scheduler cannot be used (unreachable, not a scheduler, no workers, lost); the message names it."""


class WorkerLost(ChildProcessError):
    """A task killed every worker that ran it (``distributed.KilledWorker``); names the last worker.

    An ``OSError`` (a child process failed), so that a command line reports it as one line.
    """

    def __init__(self, message: str, worker: str | None = None) -> None:
        super().__init__(message)
        self.worker = worker


@dataclass(frozen=True)
class _ClientInfo:
    address: str
    timeout: float
    external: bool


_CLIENTS: weakref.WeakKeyDictionary[Any, _ClientInfo] = weakref.WeakKeyDictionary()


# ---------------------------------------------------------------------- what a cluster did
@dataclass
class ClusterRecord:
    """What a client's cluster did while railopt used it (:func:`cluster_record`).

    Attributes
    ----------
    address : str
        The scheduler's address.
    workers_at_start, workers_at_end, workers_max : int or None
        Workers when the record began (the client was opened, or first used by :func:`map_unordered`), when
        :func:`dask_client` closed it (``None`` until then, or when the scheduler did not answer), and the most
        seen meanwhile (from the scheduler's add-worker and remove-worker events).
    lost_workers : list of str
        Addresses of the workers that left the cluster meanwhile (a crash, a killed process, a scaled-down
        cluster), in order.
    rerun_tasks : int
        Tasks of :func:`map_unordered` that a lost worker was running or held the result of: the scheduler ran
        them again on another worker (the result is the same: a task depends on nothing but itself).
    """

    address: str
    workers_at_start: int | None = None
    workers_at_end: int | None = None
    workers_max: int | None = None
    lost_workers: list[str] = field(default_factory=list)
    rerun_tasks: int = 0
    _live: set[str] = field(default_factory=set, repr=False)
    _keys: set[Any] = field(default_factory=set, repr=False)

    def _start(self, workers: Iterable[str]) -> None:
        self._live = set(workers)
        self.workers_at_start = self.workers_max = len(self._live)

    def _event(self, event: Any) -> None:
        """A scheduler event ``(time, message)`` of topic ``all`` (runs in the client's event-loop thread)."""
        message = event[1] if isinstance(event, tuple | list) and len(event) == 2 else event
        if not isinstance(message, dict):
            return
        action, worker = message.get("action"), message.get("worker")
        if action == "add-worker" and worker:
            self._live.add(worker)
            self.workers_max = max(self.workers_max or 0, len(self._live))
        elif action == "remove-worker" and worker:
            self._live.discard(worker)
            self.lost_workers.append(str(worker))
            ours = {*(message.get("processing-tasks") or ()), *(message.get("lost-computed-tasks") or ())}
            self.rerun_tasks += len(ours & self._keys)

    def describe(self) -> str:
        """One sentence on lost workers and re-run tasks (empty when there were none)."""
        if not self.lost_workers:
            return ""
        n, k = len(self.lost_workers), self.rerun_tasks
        shown = ", ".join(self.lost_workers[:3]) + (f" and {n - 3} more" if n > 3 else "")
        tasks = (f"{k} task{' was' if k == 1 else 's were'} re-run on other workers (a task depends on nothing but "
                 "itself: the results are unchanged)" if k else "no task of this run was running there")
        lost = f"{n} dask worker{'' if n == 1 else 's'} left the cluster {self.address} during the run"
        return f"{lost} ({shown}); {tasks}"


def cluster_summary(records: Iterable[ClusterRecord]) -> dict[str, Any]:
    """The columns ``timing.csv`` gives the clusters a run used (none: serial): ``workers_at_start`` (of the
    first), ``workers_at_end`` (of the last; empty when its scheduler did not answer), ``workers_max``,
    ``workers_lost`` and ``tasks_rerun`` (totals) and ``cluster_events`` (:meth:`ClusterRecord.describe`)."""
    records = list(records)
    if not records:
        return {"workers_at_start": 0, "workers_at_end": 0, "workers_max": 0, "workers_lost": 0, "tasks_rerun": 0,
                "cluster_events": ""}
    end = records[-1].workers_at_end
    return {"workers_at_start": records[0].workers_at_start, "workers_at_end": end,
            "workers_max": max(r.workers_max or 0 for r in records),
            "workers_lost": sum(len(r.lost_workers) for r in records),
            "tasks_rerun": sum(r.rerun_tasks for r in records),
            "cluster_events": "; ".join(r.describe() for r in records if r.describe())}


_RECORDS: weakref.WeakKeyDictionary[Any, ClusterRecord] = weakref.WeakKeyDictionary()


def cluster_record(client: Any) -> ClusterRecord | None:
    """The :class:`ClusterRecord` of ``client`` (a client opened by :func:`dask_client`, or used by
    :func:`map_unordered`); ``None`` for ``None`` (serial) or a client railopt never used."""
    return None if client is None else _RECORDS.get(client)


def _track(client: Any, timeout: float) -> ClusterRecord:
    """The record of ``client``, begun now if it has none: the workers now, then the scheduler's events."""
    record = _RECORDS.get(client)
    if record is not None:
        return record
    record = ClusterRecord(_address(client))
    record._start(_workers(client, timeout) or {})
    try:
        previous = getattr(client, "_event_handlers", {}).get("all")

        def handler(event: Any) -> None:
            record._event(event)
            if previous is not None:  # a handler the user had: still called
                previous(event)

        client.subscribe_topic("all", handler)
    except Exception:  # noqa: BLE001, S110  (a Runner without events: the counts at start and end only)
        pass
    _RECORDS[client] = record
    return record


def _finish(client: Any, timeout: float) -> None:
    """The workers at the end, asked before the client closes (``workers_at_end`` stays None without an answer)."""
    record = _RECORDS.get(client)
    if record is None:
        return
    workers = _workers(client, timeout)
    if workers is not None:
        record.workers_at_end = len(workers)
        record.workers_max = max(record.workers_max or 0, len(workers))


# ---------------------------------------------------------------------- pickling
def _pickle_error(obj: Any) -> Exception | None:
    import cloudpickle

    try:
        cloudpickle.dumps(obj)
    except Exception as exc:  # any failure to serialise (TypeError, PicklingError, AttributeError, ...)
        return exc
    return None


def _parts(obj: Any) -> list[tuple[str, Any]]:
    """Named parts of an object to look into for the one that does not pickle."""
    if is_dataclass(obj) and not isinstance(obj, type):
        return [(f.name, getattr(obj, f.name, None)) for f in fields(obj)]
    if callable(obj) and getattr(obj, "__closure__", None):
        names = obj.__code__.co_freevars
        return [(n, c.cell_contents) for n, c in zip(names, obj.__closure__, strict=False) if _has_contents(c)]
    if isinstance(obj, dict):
        return [(repr(k), v) for k, v in obj.items()]
    if isinstance(obj, list | tuple):
        return [(f"[{i}]", v) for i, v in enumerate(obj)]
    if hasattr(obj, "__dict__") and not isinstance(obj, type):
        return [(k.lstrip("_"), v) for k, v in vars(obj).items()]
    return []


def _has_contents(cell: Any) -> bool:
    try:
        cell.cell_contents  # noqa: B018
    except ValueError:
        return False
    return True


def _find_unpicklable(obj: Any, path: str, depth: int = 0) -> tuple[str, Exception] | None:
    exc = _pickle_error(obj)
    if exc is None:
        return None
    if depth < 6:
        for name, part in _parts(obj):
            sep = "" if name.startswith("[") or not path else "."
            found = _find_unpicklable(part, f"{path}{sep}{name}", depth + 1)
            if found is not None:
                return found
    return path or type(obj).__name__, exc


def check_picklable(obj: Any, name: str = "") -> None:
    """Raise ``ValueError`` naming the part of ``obj`` that cannot be sent to dask workers.

    ``name`` prefixes the path (empty: paths start at ``obj``'s fields, e.g. ``problem.functions``).

    The message names the innermost attribute, field or closure variable that does not pickle, e.g.
    ``problem.functions.lock: cannot be sent to dask workers (TypeError: cannot pickle '_thread.lock'
    object); define it at module level or use workers=0``.
    """
    found = _find_unpicklable(obj, name)
    if found is not None:
        path, exc = found
        text = " ".join(f"{type(exc).__name__}: {exc}".split())
        raise ValueError(f"{path}: cannot be sent to dask workers ({text[:300]}); define it at module level "
                         "(without open files, locks or connections) or use workers=0 (serial)")


# ---------------------------------------------------------------------- progress
ProgressCallback = Callable[[int, int], None]
"""``progress(done, total)``: called with ``done = 0`` when a map begins, then after every finished task (a grid
map of :mod:`railopt.design.surface` counts rows: a task of several rows adds them all)."""

_PROGRESS: ContextVar[ProgressCallback | None] = ContextVar("railopt_design_progress", default=None)


@contextmanager
def reporting_progress(progress: ProgressCallback | None) -> Iterator[None]:
    """Within the block, every :func:`map_unordered` called without its own ``progress`` reports to ``progress``
    (``None``: to nothing): long work made of many maps (trade-off sweeps, objective surfaces, checks) shows
    progress without each caller passing a callback down.  Each map calls ``progress(0, total)`` when it begins."""
    token = _PROGRESS.set(progress)
    try:
        yield
    finally:
        _PROGRESS.reset(token)


def progress_of(progress: ProgressCallback | None) -> ProgressCallback | None:
    """The callback a map given ``progress`` reports to: ``progress`` itself, else the enclosing
    :func:`reporting_progress` block's (None outside one) — for a caller that counts its own units (rows of a
    surface computed in blocks) and passes :func:`no_progress` to the map."""
    return progress if progress is not None else _PROGRESS.get()


def no_progress(done: int, total: int) -> None:
    """A progress callback that reports nothing (a map whose caller reports in its own units)."""


# ---------------------------------------------------------------------- shipping once
@dataclass(frozen=True)
class Shipped:
    """A handle to an object sent once to every worker by :func:`shipping`: what a task carries instead of it.

    ``resolve(handle)`` gives the object back inside a task; the handle itself pickles to a few dozen bytes.
    """

    name: str

    def get(self) -> Any:
        """The object, from the worker plugin of this name on the worker running the task.

        Raises ``RuntimeError`` outside a dask worker, or on a worker without the plugin (it was removed: the
        campaign that shipped it has ended)."""
        from distributed import get_worker

        try:
            worker = get_worker()
        except ValueError:
            raise RuntimeError(f"{self.name}: a shipped object is resolved only inside a dask task") from None
        plugin = worker.plugins.get(self.name)
        if plugin is None:
            raise RuntimeError(f"{self.name}: not on worker {worker.address} (its campaign has ended, or the "
                               "plugin was removed)")
        return plugin.value


def resolve(obj: Any) -> Any:
    """``obj``, or the object a :class:`Shipped` handle stands for (inside a dask task)."""
    return obj.get() if isinstance(obj, Shipped) else obj


def _bounded(fn: Callable[[], Any], wait: float, what: str, info: _ClientInfo) -> Any:
    """``fn()`` in a thread, given up after ``wait`` + :data:`SCHEDULER_MARGIN` s (a lost scheduler: SchedulerError)."""
    box: dict[str, Any] = {}

    def target() -> None:
        try:
            box["value"] = fn()
        except BaseException as exc:  # noqa: BLE001  (re-raised below, in the caller's thread)
            box["error"] = exc

    thread = threading.Thread(target=target, name=f"railopt-{what}", daemon=True)
    thread.start()
    thread.join(wait + SCHEDULER_MARGIN)
    if thread.is_alive():
        raise _lost(info, TimeoutError(f"{what}: no answer within {wait + SCHEDULER_MARGIN:g} s"))
    if "error" in box:
        raise box["error"]
    return box.get("value")


@contextmanager
def shipping(client: Runner | None, obj: Any, name: str = "problem") -> Iterator[Any]:
    """Send ``obj`` to every worker of ``client`` once; within the block, tasks carry the yielded handle.

    With a dask client, ``obj`` goes out as a worker plugin (:class:`~railopt.design._worker_setup.ShippedObject`):
    the scheduler keeps one pickled copy and gives it to every worker, those that join (or are restarted) later
    included, and the block's end removes it.  A task then carries a :class:`Shipped` handle of a few dozen bytes
    and calls :func:`resolve` on it.  A plugin rather than ``client.scatter``: scattered data lives on the workers
    only, and is gone when the workers holding it die (a start that crashes the one worker of a cluster would take
    the problem with it, and every later task would fail); the scheduler keeps a plugin and gives it to the
    restarted worker.  Serial (``client`` None), or a :class:`~railopt.design.runner.Runner` without
    ``register_plugin``: the block yields ``obj`` itself, which the tasks then carry (the same numbers: only the
    transport differs).

    Measured on 2 cores (``railopt bench``, the flagship's 190 kB problem): the problem pickled and sent with every
    task held a short-start campaign near 30 tasks/s at 1 and 2 workers; shipped once, the rate follows the
    workers.

    Raises
    ------
    ValueError
        Before anything is sent, naming the part of ``obj`` that cannot be pickled (``problem.functions...``).
    SchedulerError
        The scheduler did not take the plugin within its timeout.
    """
    if client is None:
        yield obj
        return
    check_picklable(obj, name)
    register = getattr(client, "register_plugin", None)
    if register is None:
        yield obj
        return
    from railopt.design._worker_setup import ShippedObject

    info = _CLIENTS.get(client) or _ClientInfo(_address(client), scheduler_timeout(), True)
    key = f"railopt-{name}-{os.getpid()}-{next(_SHIPMENTS)}-{time.time_ns():x}"
    try:
        _bounded(lambda: register(ShippedObject(key, obj), name=key), info.timeout, "shipping", info)
    except SchedulerError:
        raise
    except (OSError, TimeoutError) as exc:  # the connection broke meanwhile
        raise _lost(info, exc) from None
    try:
        yield Shipped(key)
    finally:
        try:  # the scheduler and every worker let go of it; a lost scheduler is not waited on
            _bounded(lambda: client.unregister_worker_plugin(key), info.timeout, "unshipping", info)
        except Exception:  # noqa: BLE001, S110  (already gone with its scheduler: nothing is held any more)
            pass


_SHIPMENTS = itertools.count()


# ---------------------------------------------------------------------- mapping
def map_unordered(
    fn: Callable[[Any], Any],
    items: Iterable[Any],
    client: Runner | None = None,
    retries: int = 3,
    on_lost: Callable[[Any, WorkerLost], Any] | None = None,
    progress: ProgressCallback | None = None,
) -> Iterator[Any]:
    """Yield ``fn(item)`` for each item, in completion order; serial when ``client`` is None.

    Parameters
    ----------
    fn : callable
        Applied to each item (on a worker when ``client`` is given).
    items : iterable
    client : Runner, optional
        A dask.distributed.Client, or anything else satisfying :class:`~railopt.design.runner.Runner`; None: serial.
    retries : int
        Re-runs of a task that raised (dask's ``retries``); a task whose worker died is re-run by
        the scheduler (``distributed.scheduler.allowed-failures``).
    on_lost : callable(item, WorkerLost), optional
        Makes the result of a task that killed every worker it ran on; ``None``: raise :class:`WorkerLost`.
    progress : callable(done, total), optional
        Called with 0 when the map begins and after each finished task; default: the one of the enclosing
        :func:`reporting_progress` block, if any.

    Raises
    ------
    ValueError
        Before submitting anything, naming what cannot be pickled (``fn`` or a part of the first item).
    SchedulerError
        The scheduler was lost, or had no workers for longer than its timeout; names the address.
    WorkerLost
        Without ``on_lost``, for a task that killed its workers.
    """
    for group in map_unordered_groups(fn, items, client, retries, on_lost, progress, most=1):
        yield from group


def map_unordered_groups(
    fn: Callable[[Any], Any],
    items: Iterable[Any],
    client: Runner | None = None,
    retries: int = 3,
    on_lost: Callable[[Any, WorkerLost], Any] | None = None,
    progress: ProgressCallback | None = None,
    most: int = 32,
    window: int | Callable[[], int] | None = None,
) -> Iterator[list[Any]]:
    """:func:`map_unordered`, the results given in lists: each list holds a result and those already finished
    when it was read, ``most`` at most; never waits for a result to fill a list.

    A consumer that does one costly thing per list (a store's transaction) then does it once for a run of
    results that arrived together, and at once for a result that arrived alone: lists grow only when results
    come faster than the consumer takes them.  Serially, each list holds one result.  Same parameters and
    errors as :func:`map_unordered`; ``progress`` is called after each finished task, before its list is given.
    When the scheduler is lost after some results of a list were read, the list is given first, then
    :class:`SchedulerError` is raised.

    ``window`` (a whole number >= 1, or a callable giving one, asked again at every draw — a cluster whose
    workers change; optional): ``items`` is then drawn lazily, at most ``window`` tasks unfinished at a time; the
    next items are drawn when the consumer asks for the next list, so an item may be made from the results given so
    far (:func:`~railopt.design.multistart.multistart` sizes its next batch from the starts' times).  A consumer
    that takes longer over a list than a queued task takes to run leaves workers idle meanwhile.  Without a window
    every item is submitted at once.  ``progress`` (or an enclosing :func:`reporting_progress`) needs a sized
    ``items``: a caller drawing lazily reports in its own units and passes :func:`no_progress`.
    """
    if isinstance(most, bool) or not isinstance(most, numbers.Integral) or most < 1:
        raise ValueError(f"most: must be a whole number of results >= 1, got {most!r}")
    if window is not None and not callable(window):
        _check_window(window)
    if window is None:
        items = list(items)
    report = progress_of(progress)
    if report is no_progress:
        report = None
    if report is not None and not hasattr(items, "__len__"):
        raise ValueError("progress: needs items of a known count (a list), not an iterator drawn lazily")
    groups = _map(fn, items, client, retries, on_lost, int(most), window)
    if report is None:
        yield from groups
        return
    total = len(items)  # type: ignore[arg-type]
    report(0, total)
    done = 0
    for group in groups:
        for _ in group:
            done += 1
            report(done, total)
        yield group


_DRAINED = object()  # the pump's last word: every future added to the stream so far has been handed on


def _check_window(window: Any) -> int:
    if isinstance(window, bool) or not isinstance(window, numbers.Integral) or window < 1:
        raise ValueError(f"window: must be a whole number of tasks >= 1, got {window!r}")
    return int(window)


def _map(fn: Callable[[Any], Any], items: Iterable[Any], client: Runner | None, retries: int,
         on_lost: Callable[[Any, WorkerLost], Any] | None, most: int,
         window: int | Callable[[], int] | None) -> Iterator[list[Any]]:
    """:func:`map_unordered_groups` without progress."""
    task = _SingleThreaded(fn)
    if client is None:
        for item in items:
            yield [task(item)]
        return
    source = iter(items)

    def limit() -> int:
        return _check_window(window() if callable(window) else window)

    first = list(source if window is None else itertools.islice(source, limit()))
    if not first:
        return
    check_picklable(fn, getattr(fn, "__name__", "function"))
    check_picklable(first[0])  # the tasks of one map share their problem and functions: the first tells
    from distributed import as_completed

    info = _CLIENTS.get(client) or _ClientInfo(_address(client), scheduler_timeout(), True)
    record = _track(client, info.timeout)
    item_of: dict[Any, Any] = {}
    # only unfinished tasks are held: a finished one's future is dropped once its result is read, so the worker
    # frees the result (a long campaign's workers would otherwise keep every result to the end)
    pending: dict[Any, Any] = {}

    def submit(batch: list[Any]) -> list[Any]:
        try:
            futures = client.map(task, batch, pure=False, retries=retries)
        except Exception as exc:  # e.g. the connection is gone already
            raise _lost(info, exc) from None
        record._keys.update(f.key for f in futures)  # a lost worker's event names the tasks it was running
        for future, item in zip(futures, batch, strict=True):
            item_of[future.key] = item
            pending[future.key] = future
        return futures

    stream = as_completed(submit(first))
    exhausted = window is None
    del first
    # as_completed blocks without a timeout: it runs in a thread, and this one watches the scheduler meanwhile.
    # Its iteration ends whenever every future added so far was handed on; when futures are added after that
    # (items drawn lazily), a new pump takes over the same stream.
    finished: queue.Queue = queue.Queue()

    def pump() -> None:
        try:
            for future in stream:
                finished.put(future)
        except Exception as exc:  # noqa: BLE001  (the client broke down: reported below)
            finished.put(exc)
        finally:
            finished.put(_DRAINED)

    def start_pump() -> None:
        threading.Thread(target=pump, name="railopt-as-completed", daemon=True).start()

    start_pump()
    pumping = True
    handed = 0  # futures handed on by the pump since it was last (re)started
    no_workers_since: float | None = None
    unhealthy_since: float | None = None
    try:
        while pending or not exhausted:
            if not exhausted and len(pending) < (room := limit()):
                more = list(itertools.islice(source, room - len(pending)))
                exhausted = not more
                if more:
                    stream.update(submit(more))
                    if not pumping:
                        start_pump()
                        pumping, handed = True, 0
                if not pending:
                    break
            try:
                got = finished.get(timeout=_POLL)
            except queue.Empty:
                now = time.monotonic()
                if client.status != "running":
                    unhealthy_since = unhealthy_since or now
                    if now - unhealthy_since > info.timeout:
                        raise _lost(info, None) from None
                    continue
                workers = _workers(client, info.timeout)
                if workers is None:  # no answer: counted as a connection in trouble
                    unhealthy_since = unhealthy_since or now
                    if time.monotonic() - unhealthy_since > info.timeout:
                        raise _lost(info, None) from None
                    continue
                unhealthy_since = None
                if not workers:
                    no_workers_since = no_workers_since or now
                    if now - no_workers_since > info.timeout:
                        raise SchedulerError(_no_workers(info, now - no_workers_since, resume=True)) from None
                else:
                    no_workers_since = None
                continue
            if got is _DRAINED:  # the pump saw an empty stream; futures added since are taken by a new one
                pumping = False
                if pending:
                    if not handed:  # it stopped while the stream still held unfinished futures: broken down
                        raise _lost(info, None)
                    start_pump()
                    pumping, handed = True, 0
                continue
            no_workers_since = unhealthy_since = None
            group: list[Any] = []
            failure: BaseException | None = None
            while True:  # this result, then those already waiting (never waiting for more)
                if isinstance(got, Exception):  # the stream of results broke down
                    failure = _lost(info, got)
                    break
                handed += 1
                key = got.key
                try:
                    result = _result(got, item_of.pop(key), info, on_lost)
                except BaseException as exc:  # the task's own error, or a lost connection: after the group
                    failure = exc
                    del pending[key], got
                    break
                del pending[key], got
                group.append(result)
                if not pending or len(group) >= most:
                    break
                try:
                    got = finished.get_nowait()
                except queue.Empty:
                    break
                if got is _DRAINED:  # handled at the top of the loop, after this group
                    finished.put(got)
                    break
            if group:
                yield group
            if failure is not None:
                raise failure
    finally:
        for future in pending.values():  # interrupted: do not leave work queued on a shared cluster
            if not future.done():
                try:
                    future.cancel()
                except Exception:  # noqa: S110  (the connection is gone: nothing is queued any more)
                    pass


def _result(future: Any, item: Any, info: _ClientInfo, on_lost: Callable[[Any, WorkerLost], Any] | None) -> Any:
    from distributed import KilledWorker

    status = future.status
    if status == "cancelled":
        raise _lost(info, None)
    try:
        return future.result()
    except KilledWorker as exc:
        worker = getattr(getattr(exc, "last_worker", None), "address", None) or str(getattr(exc, "last_worker", ""))
        lost = WorkerLost(f"the task killed every worker that ran it (last: {worker}; a crash in native code or "
                          f"out of memory?)", worker)
        if on_lost is None:
            raise lost from None
        return on_lost(item, lost)
    except Exception as exc:
        if status == "error":  # the task itself raised: its own exception, as it would serially
            raise
        raise _lost(info, exc) from None  # fetching the result failed: the connection


def _address(client: Runner) -> str:
    try:
        return str(client.scheduler.address)
    except Exception:
        return "the dask scheduler"


def _workers(client: Runner, timeout: float) -> dict | None:
    """The scheduler's workers, asked now (bounded in time); None when the scheduler does not answer."""
    try:
        identity = client.sync(client.scheduler.identity, n_workers=-1, callback_timeout=timeout)
        return dict(identity.get("workers", {}))
    except Exception:
        return None


def worker_threads(client: Runner, timeout: float | None = None) -> int | None:
    """Threads of all of ``client``'s workers, asked now and bounded in time (``timeout``, s; default
    :func:`scheduler_timeout`); None when the scheduler does not answer or lists no threads."""
    workers = _workers(client, scheduler_timeout(timeout))
    if not workers:
        return None
    threads = sum(int(w.get("nthreads", 0) or 0) for w in workers.values() if isinstance(w, dict))
    return threads or None


def _lost(info: _ClientInfo, exc: BaseException | None) -> SchedulerError:
    # dask's own text (e.g. "in <TCP (closed) ConnectionPool.gather ... remote=<a worker>>") would name a
    # worker or a pool, not the scheduler: it is kept as the exception's __cause__ only
    where = f"{info.address!r}" if info.external else f"the local dask cluster at {info.address}"
    error = SchedulerError(f"scheduler: lost the connection to {where}; finished starts are kept, rerun with --resume")
    error.__cause__ = exc
    return error


def _no_workers(info: _ClientInfo, waited: float, resume: bool) -> str:
    after = "finished starts are kept, rerun with --resume once workers are attached" if resume else (
        "attach workers (dask worker ADDRESS)")
    return (f"scheduler: {info.address!r} has no workers (waited {waited:.0f} s); {after}, "
            "or run on a local cluster with --workers N")


# ---------------------------------------------------------------------- clients
def scheduler_timeout(timeout: float | None = None, field: str = "timeout") -> float:
    """Seconds to wait for a scheduler: ``timeout``, else ``$RAILOPT_SCHEDULER_TIMEOUT``, else 5.

    A value that is not a positive finite number raises ``ValueError`` naming ``field`` (or the variable).
    """
    if timeout is None:
        text = os.environ.get(SCHEDULER_TIMEOUT_ENV, "").strip()
        try:
            timeout, field = (float(text), SCHEDULER_TIMEOUT_ENV) if text else (DEFAULT_SCHEDULER_TIMEOUT, field)
        except ValueError:
            raise ValueError(f"{SCHEDULER_TIMEOUT_ENV}: must be a number of seconds, got {text!r}") from None
    if not (isinstance(timeout, numbers.Real) and not isinstance(timeout, bool) and 0 < timeout < math.inf):
        raise ValueError(f"{field}: must be a positive number of seconds, got {timeout!r}")
    return float(timeout)


class _Below(logging.Filter):
    def __init__(self, level: int) -> None:
        super().__init__()
        self.level = level

    def filter(self, record: logging.LogRecord) -> bool:
        return record.levelno >= self.level


@contextmanager
def _quiet_dask_logs() -> Iterator[None]:
    """Keep dask's (and tornado's) log records out of this process's terminal until exit.

    A filter on their stream handlers (it survives LocalCluster's own ``silence_logs`` level changes);
    ``$RAILOPT_DASK_LOGS`` = a level name lets records of that level and above through.
    """
    text = os.environ.get(DASK_LOGS_ENV, "").strip().upper()
    level = logging.getLevelName(text) if text else logging.CRITICAL + 1
    if not isinstance(level, int):
        raise ValueError(f"{DASK_LOGS_ENV}: must be a logging level name (e.g. WARNING), got {text!r}")
    import distributed  # noqa: F401  (sets up dask's loggers and handlers first)

    quiet = _Below(level)
    handlers = []
    for name, logger in list(logging.root.manager.loggerDict.items()):
        if isinstance(logger, logging.Logger) and name.split(".")[0] in ("distributed", "tornado", "asyncio"):
            handlers += [h for h in logger.handlers if isinstance(h, logging.StreamHandler)]
    for handler in handlers:
        handler.addFilter(quiet)
    try:
        yield
    finally:
        for handler in handlers:
            handler.removeFilter(quiet)


def _connect(scheduler: str, wait: float) -> Any:
    """``Client(scheduler)`` within ``wait`` s (+ margin), whatever answers at the address."""
    from dask.distributed import Client

    hint = f"check the address (--scheduler or ${SCHEDULER_ENV}), or run on a local cluster with --workers N"
    box: dict[str, Any] = {}

    def connect() -> None:
        try:
            box["client"] = Client(scheduler, timeout=wait)
        except BaseException as exc:  # noqa: BLE001  (reported below, in the caller's thread)
            box["error"] = exc

    # a server that accepts the connection and never speaks makes Client() wait for ever: a thread with a deadline
    thread = threading.Thread(target=connect, name="railopt-connect", daemon=True)
    thread.start()
    thread.join(wait + SCHEDULER_MARGIN)
    if thread.is_alive():
        raise SchedulerError(f"scheduler: {scheduler!r} did not answer as a dask scheduler within "
                             f"{wait + SCHEDULER_MARGIN:g} s; {hint}")
    exc = box.get("error")
    if exc is None:
        return box["client"]
    text = " ".join(f"{type(exc).__name__}: {exc}".split())[:200]
    if isinstance(exc, KeyboardInterrupt | SystemExit):
        raise exc
    if isinstance(exc, ValueError | TypeError):
        raise SchedulerError(f"scheduler: {scheduler!r} is not a valid address ({exc}); {hint}")
    if isinstance(exc, OSError):
        raise SchedulerError(f"scheduler: cannot connect to {scheduler!r} within {wait:g} s ({exc}); {hint}")
    if isinstance(exc, MemoryError):  # dask took the first bytes of another protocol ("HTTP/1.0") as a frame length
        text = "its reply is not dask's protocol: an HTTP server, e.g. a dashboard port?"
    raise SchedulerError(f"scheduler: {scheduler!r} did not answer as a dask scheduler ({text}); {hint}")


def _close(client: Any, wait: float) -> None:
    """Close a client without hanging or raising when its scheduler is gone."""
    done = threading.Event()

    def close() -> None:
        try:
            client.close(timeout=wait)
        except BaseException:  # noqa: BLE001, S110  (closing a broken connection: nothing to keep)
            pass
        finally:
            done.set()

    threading.Thread(target=close, name="railopt-close", daemon=True).start()
    done.wait(wait + SCHEDULER_MARGIN)


@contextmanager
def dask_client(workers: int | None = None, scheduler: str | None = None,
                timeout: float | None = None) -> Iterator[Any]:
    """A dask client: the ``scheduler`` address if given, else a LocalCluster (or serial).

    ``workers`` = number of worker processes of the embedded cluster (one thread each); ``0``
    yields ``None`` (serial, in-process).  ``$RAILOPT_SCHEDULER`` is used only when neither
    ``scheduler`` nor ``workers`` is given: an explicit request wins over the environment.
    ``timeout`` (s; default :func:`scheduler_timeout`) bounds the wait for a scheduler.

    Raises
    ------
    SchedulerError
        Within ``timeout`` + :data:`SCHEDULER_MARGIN` s, naming the address: not a valid address,
        nothing listening, something that is not a dask scheduler (or never answers), or a scheduler
        without workers (none joined within ``timeout``).
    ValueError
        ``workers`` < 0, or a bad timeout (naming it).
    """
    if scheduler is None and workers is None:
        scheduler = os.environ.get(SCHEDULER_ENV) or None
    if scheduler is None and workers == 0:
        yield None
        return
    if scheduler is not None:
        wait = scheduler_timeout(timeout)
        with _quiet_dask_logs():
            client = _connect(scheduler, wait)
            _CLIENTS[client] = info = _ClientInfo(str(scheduler), wait, True)
            try:
                try:
                    client.wait_for_workers(1, timeout=wait)
                except Exception:  # TimeoutError, or the scheduler went away meanwhile
                    if client.status == "running" and _workers(client, wait) == {}:
                        raise SchedulerError(_no_workers(info, wait, resume=False)) from None
                    if client.status != "running":
                        raise _lost(info, None) from None
                _track(client, wait)
                yield client
                _finish(client, wait)
            finally:
                _close(client, wait)
        return
    n = workers if workers is not None else (os.cpu_count() or 1)
    if n < 0:
        raise ValueError(f"workers: must be ≥ 0, got {n}")
    import dask
    from dask.distributed import Client, LocalCluster

    # how long the embedded cluster may be without workers (its nannies restart crashed ones) before giving up
    wait = LOCAL_NO_WORKERS_LIMIT
    # A start that kills its worker is tried twice, not four times, before it is reported as lost; each worker
    # holds one task at a time (worker-saturation 1), though dask still blames a death on a task queued on the dying
    # worker after a restart (multistart re-runs a lost task's starts alone for that).  The cluster never gives up a
    # crashed worker for good: dask closes a nanny whose worker is still restarting 15 s after a crash
    # (lost-worker-timeout), which a run of crashing starts hits; our own limit is LOCAL_NO_WORKERS_LIMIT.
    # Ctrl-C while the cluster starts: SIGINT is blocked in this thread, and so in every thread and worker process
    # started meanwhile (they inherit the mask), until the cluster is up; a Ctrl-C pressed meanwhile then lands
    # here, in one place, and the cluster is shut down as after any interruption — no half-started cluster, no
    # traceback of a worker process interrupted while importing
    blocked = _block_sigint()
    try:
        with (
            _quiet_dask_logs(),
            dask.config.set({"distributed.scheduler.allowed-failures": 1,
                             "distributed.scheduler.worker-saturation": 1.0,
                             "distributed.deploy.lost-worker-timeout": "1000 days",
                             # a worker's own threads take the GIL from the solving thread: its sampling profiler
                             # (every 10 ms), the event-loop tick (20 ms), memory (100 ms) and system (500 ms)
                             # monitors
                             "distributed.worker.profile.enabled": False, "distributed.admin.tick.interval": "200ms",
                             "distributed.worker.memory.monitor-interval": "500ms",
                             "distributed.admin.system-monitor.interval": "2s",
                             # dask starts its workers with MALLOC_TRIM_THRESHOLD_=65536 (memory handed back to the
                             # OS early); setting it also switches off glibc's adaptive mmap threshold, so every
                             # array over 128 kB is a fresh mmap, page-faulted in: the flagship's starts ran 5-8 %
                             # slower in a worker than in a plain process.  None drops dask's value (glibc's
                             # defaults); a MALLOC_TRIM_THRESHOLD_ in the user's own environment
                             # still reaches the workers (they inherit this process's environment)
                             "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}),
            LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                         # the scheduler's HTTP routes on a free local port, not 8787 (taken: a warning on stderr)
                         scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                         silence_logs=logging.ERROR, preload=[_worker_setup_source()]) as cluster,
            Client(cluster) as client,
        ):
            _unblock_sigint(blocked)  # a Ctrl-C pressed while the cluster started is raised here
            _CLIENTS[client] = _ClientInfo(str(cluster.scheduler_address), wait, False)
            _track(client, wait)
            yield client
            _finish(client, wait)
    finally:
        _unblock_sigint(blocked)


def _block_sigint() -> set[int] | None:
    """Block SIGINT in this thread (main thread only); the previous mask, or None when nothing was changed.

    multiprocessing's resource tracker is started first: starting it unblocks SIGINT in the thread that does, which
    would otherwise be the cluster's event-loop thread, and the workers it starts would not inherit the block."""
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "pthread_sigmask"):
        return None
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()
    return set(signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT}))


def _unblock_sigint(previous: set[int] | None) -> None:
    """Restore the mask :func:`_block_sigint` changed (a pending SIGINT is then delivered: KeyboardInterrupt)."""
    if previous is not None and signal.SIGINT not in previous:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


__all__ = [
    "DASK_LOGS_ENV", "DEFAULT_SCHEDULER_TIMEOUT", "LOCAL_NO_WORKERS_LIMIT", "SCHEDULER_ENV", "SCHEDULER_MARGIN",
    "SCHEDULER_TIMEOUT_ENV", "ClusterRecord", "ProgressCallback", "SchedulerError", "WorkerLost", "call",
    "Shipped", "check_picklable", "cluster_record", "cluster_summary", "dask_client", "map_unordered",
    "map_unordered_groups", "no_progress", "progress_of", "reporting_progress", "resolve", "scheduler_timeout",
    "shipping", "worker_threads",
]
