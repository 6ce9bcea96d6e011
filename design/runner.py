"""What the design layer needs of a parallel runner: :class:`Runner`."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any, Protocol, runtime_checkable

__all__ = ["Runner"]


@runtime_checkable
class Runner(Protocol):
    """The part of a dask client that :func:`~railopt.design.parallel.map_unordered` and
    :func:`~railopt.design.multistart.multistart` (and the functions built on them) use.

    A :class:`dask.distributed.Client` satisfies it; wherever a ``client: Runner | None`` is taken, ``None``
    means serial (the same code, in this process).  The contract:

    - ``map(fn, items, pure=False, retries=n)`` submits ``fn`` over ``items`` and returns one future per item
      (futures with a ``key``, accepted by ``distributed.as_completed``);
    - ``nthreads()`` maps each worker to its thread count;
    - ``status`` is ``"running"`` while the connection is healthy;
    - ``scheduler`` has an ``address`` and an ``identity`` coroutine, which ``sync(fn, ...)`` runs with
      ``callback_timeout`` to list the workers and their threads (a lost scheduler is reported, never waited on
      forever; a campaign sizes its tasks and how many go ahead of the workers from those threads).

    Runners are hashable (open clients are remembered by identity).
    """

    status: str
    scheduler: Any

    def map(self, fn: Callable[[Any], Any], items: Iterable[Any], *, pure: bool = ..., retries: int = ...
            ) -> list[Any]:
        """Submit ``fn`` over ``items``; one future per item."""
        ...

    def nthreads(self) -> Mapping[str, int]:
        """Threads of each worker."""
        ...

    def sync(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
        """Run the coroutine function ``fn`` on the client's event loop and return its result."""
        ...
