"""The Dask engine of every study: chunks of independent work, run locally or on a dask.distributed cluster.

Without a scheduler address (``--scheduler`` or ``LINKWORK_SCHEDULER``) a :class:`~dask.distributed.LocalCluster`
of worker processes on this machine is started and shut down again (no set-up); with one, the same tasks go to
that cluster (its workers need linkwork installed). A study of a single chunk, or ``workers=0``, runs in this
process. Results come back in chunk order whichever worker finished first, so written files never depend on the
schedule; at most a few chunks per worker are in flight, so memory stays bounded however many chunks there are.
"""

from __future__ import annotations

import contextlib
import logging
import os
import uuid
from collections.abc import Callable, Iterator, Sequence
from typing import Any, TypeVar

from linkwork.errors import LinkworkError
from linkwork.progress import Progress

T = TypeVar("T")

ENV_SCHEDULER = "LINKWORK_SCHEDULER"


def scheduler_address(scheduler: str | None) -> str | None:
    """The scheduler to use: the given address, else ``$LINKWORK_SCHEDULER``, else ``None`` (local)."""
    address = scheduler or os.environ.get(ENV_SCHEDULER) or None
    if address is not None and "://" not in address and ":" not in address:
        raise LinkworkError(f"scheduler {address!r}: expected an address like tcp://HOST:PORT")
    return address


def default_workers() -> int:
    """Local worker processes: one per available core."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


@contextlib.contextmanager
def dask_client(scheduler: str | None, workers: int | None = None) -> Iterator[Any]:
    """A connected :class:`~dask.distributed.Client`: to ``scheduler``, or to a fresh local cluster of
    ``workers`` single-threaded processes that is shut down on exit."""
    from dask.distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="10s")
        except OSError as exc:
            raise LinkworkError(f"cannot reach the Dask scheduler at {scheduler}: {exc}") from None
        with client:
            yield client
        return
    n = workers or default_workers()
    with (
        LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=":0",
            silence_logs=logging.ERROR,
        ) as cluster,
        Client(cluster) as client,
    ):
        yield client


def map_chunks(
    func: Callable[..., T],
    shared: Any,
    chunks: Sequence[tuple[Any, ...]],
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    client: Any = None,
    progress: Progress | None = None,
) -> Iterator[T]:
    """Yield ``func(shared, *chunk)`` for every chunk, in chunk order.

    ``shared`` (the study's set-up) is sent to every worker once. ``client`` reuses a connected Dask client;
    otherwise one is made from ``scheduler`` / ``workers`` (``workers=0``: run here, in this process).
    """
    address = scheduler_address(scheduler)
    total = len(chunks)
    if client is None and address is None and (workers == 0 or total <= 1):
        for done, chunk in enumerate(chunks, start=1):
            result = func(shared, *chunk)
            if progress is not None:
                progress(done, total)
            yield result
        return
    if client is not None:
        yield from _run_on(client, func, shared, chunks, progress)
        return
    with dask_client(address, workers) as own:
        yield from _run_on(own, func, shared, chunks, progress)


def _run_on(
    client: Any,
    func: Callable[..., T],
    shared: Any,
    chunks: Sequence[tuple[Any, ...]],
    progress: Progress | None,
) -> Iterator[T]:
    """Submit chunks to ``client`` with a bounded window and yield their results in order."""
    from dask.distributed import as_completed

    n_workers = max(1, len(client.scheduler_info(n_workers=-1).get("workers", {})))
    window = max(2, 3 * n_workers)
    [remote] = client.scatter([shared], broadcast=True, hash=False)
    token = uuid.uuid4().hex
    pending = iter(enumerate(chunks))
    futures: dict[Any, int] = {}
    done_set = as_completed()

    def submit_next() -> None:
        item = next(pending, None)
        if item is not None:
            index, chunk = item
            fut = client.submit(func, remote, *chunk, pure=False, key=f"linkwork-chunk-{token}-{index}")
            futures[fut] = index
            done_set.add(fut)

    for _ in range(window):
        submit_next()
    ready: dict[int, T] = {}
    next_index = 0
    finished = 0
    for fut in done_set:
        index = futures.pop(fut)
        try:
            ready[index] = fut.result()
        except ImportError as exc:
            raise LinkworkError(
                f"a Dask worker cannot import what the study needs ({exc}); install linkwork (the same version) "
                "on every worker"
            ) from None
        fut.release()
        finished += 1
        if progress is not None:
            progress(finished, len(chunks))
        submit_next()
        while next_index in ready:
            yield ready.pop(next_index)
            next_index += 1
