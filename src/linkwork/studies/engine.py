"""The Dask engine of every study: chunks of independent work, run locally or on a dask.distributed cluster.

Without a scheduler address (``--scheduler`` or ``LINKWORK_SCHEDULER``) a :class:`~dask.distributed.LocalCluster`
of worker processes on this machine is started and shut down again (no set-up); with one, the same tasks go to
that cluster (its workers need linkwork installed). A study of a single chunk, or ``workers=0``, runs in this
process. Results come back in chunk order whichever worker finished first, so written files never depend on the
schedule; at most a few chunks per worker are in flight, so memory stays bounded however many chunks there are.

A run given a :class:`RunStatus` ends early, keeping every chunk finished so far, when it is interrupted (SIGINT,
SIGTERM), when every worker or the scheduler is lost, or when a chunk cannot be computed; the status says which
and how much was done, and the caller writes what it has. A scheduler must answer within
``$LINKWORK_CONNECT_TIMEOUT`` seconds (default :data:`CONNECT_TIMEOUT`): one that accepts the connection and then
says nothing is an error after that time, and so is a cluster left without any worker for that long. Dask's own
log lines and tracebacks are kept off the terminal while a run lasts.
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
import signal
import threading
import time
import uuid
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import CancelledError
from dataclasses import dataclass
from typing import Any, TypeVar

from linkwork.errors import LinkworkError, RequestNotMetError, SpecError
from linkwork.interrupts import Interrupted, exit_code, held_signals, requested, stop_text, whole
from linkwork.progress import Progress

T = TypeVar("T")

ENV_SCHEDULER = "LINKWORK_SCHEDULER"
ENV_CONNECT_TIMEOUT = "LINKWORK_CONNECT_TIMEOUT"

CONNECT_TIMEOUT = 30.0
"""Seconds a scheduler has to answer a connection, and a cluster may stay without a worker, before the run gives
up (override with ``$LINKWORK_CONNECT_TIMEOUT``)."""

LOCAL_CLUSTER_CONFIG: dict[str, object] = {
    "distributed.admin.tick.interval": "1s",
    "distributed.worker.profile.enabled": False,
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.scheduler.active-memory-manager.start": False,
    "distributed.client.scheduler-info-interval": "10s",
}
"""Dask settings of the local clusters the engine starts (the worker processes inherit them). Dask's defaults
suit a dashboard: every server (scheduler, nannies and workers) wakes 50 times a second to time its event loop,
and every worker samples its running task's stack 100 times a second for the dashboard's profile, which linkwork
does not start. On an idle two-worker cluster these cost about 30 ms of CPU a second in this process and 20 in
each worker, taken from the cores the workers compute on; with the first two settings, about 13 and 7. Also
less often: the system monitor (every server's CPU and memory for the dashboard: 2 s, not 0.5), the nannies'
and workers' memory checks (1 s, not 0.1: the memory limit still holds) and the client's cluster summary (for
a notebook widget); and no active memory manager: the study's set-up is broadcast to every worker on purpose, and
the manager's duty is to drop such replicas. During a run of 8,000 hexagons on two workers (load 3-4: indicative)
this process's event loop took 0.12-0.15 s of CPU against 0.14-0.19, each worker's own threads 0.04-0.07
against 0.06-0.08."""

POLL = 0.5
"""Seconds between checks of the cluster's health while waiting for results."""


@dataclass
class RunStatus:
    """How a run on the engine ended: complete, or why it stopped early and how much was done.

    Attributes
    ----------
    total
        Chunks asked for.
    done
        Chunks finished and handed back, in order (the first ``done`` chunks).
    stopped
        Why the run stopped early (``""`` when it is complete): e.g. ``"interrupted (SIGINT)"``.
    code
        The exit code that fits: 0 complete, 130 SIGINT, 143 SIGTERM, 3 a lost cluster.
    signal
        The first SIGINT or SIGTERM received during the run (0: none).
    """

    total: int = 0
    done: int = 0
    stopped: str = ""
    code: int = 0
    signal: int = 0

    @property
    def complete(self) -> bool:
        """Whether every chunk was computed."""
        return not self.stopped

    def stop(self, reason: str, code: int) -> None:
        """Record the first reason the run stopped early."""
        if not self.stopped:
            self.stopped, self.code = reason, code


def connect_timeout() -> float:
    """``$LINKWORK_CONNECT_TIMEOUT`` seconds, else :data:`CONNECT_TIMEOUT`."""
    raw = os.environ.get(ENV_CONNECT_TIMEOUT, "").strip()
    if not raw:
        return CONNECT_TIMEOUT
    try:
        value = float(raw)
    except ValueError:
        value = float("nan")
    if not 0.0 < value <= 3600.0:
        raise SpecError(
            f"{ENV_CONNECT_TIMEOUT}={raw[:40]!r}: expected a number of seconds, 0 < seconds <= 3600"
        )
    return value


_ADDRESS = re.compile(
    r"(?:(?P<scheme>[a-z][a-z0-9+.-]*)://)?(?P<host>\[[0-9a-fA-F:.]+\]|[^:/\s\[\]]+):(?P<port>\d+)"
)


def scheduler_address(scheduler: str | None) -> str | None:
    """The scheduler to use: the given address, else ``$LINKWORK_SCHEDULER``, else ``None`` (local).

    An address is ``tcp://HOST:PORT`` (or ``tls://``, or ``HOST:PORT``) with a port from 1 to 65535."""
    flag = "--scheduler" if scheduler else ENV_SCHEDULER
    address = scheduler or os.environ.get(ENV_SCHEDULER) or None
    if address is None:
        return None
    match = _ADDRESS.fullmatch(address.strip())
    scheme = (match.group("scheme") or "tcp") if match else ""
    if match is None or scheme not in ("tcp", "tls") or not 1 <= int(match.group("port")[:6]) <= 65535:
        from linkwork.io.toml_reader import show

        raise SpecError(f"{flag} {show(address)}: expected an address like tcp://HOST:PORT, port 1 to 65535")
    return f"{scheme}://{match.group('host')}:{int(match.group('port'))}"


def default_workers() -> int:
    """Local worker processes: one per available core."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


_DASK_LOGGERS = ("distributed", "tornado", "asyncio", "bokeh")


@contextlib.contextmanager
def quiet_dask(restore: bool = True) -> Iterator[None]:
    """Dask's loggers silenced (their tracebacks would reach the terminal) while the block runs, and after it
    unless ``restore`` (a client's reconnection attempts may still log while the process ends)."""
    import distributed  # noqa: F401 - configures its loggers, which are then silenced

    loggers = [logging.getLogger(name) for name in _DASK_LOGGERS]
    loggers += [
        logging.getLogger(name)
        for name in list(logging.root.manager.loggerDict)
        if name.split(".")[0] in _DASK_LOGGERS and "." in name
    ]
    before = [log.level for log in loggers]
    for log in loggers:
        log.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        if restore:
            for log, level in zip(loggers, before, strict=True):
                log.setLevel(level)


class _Stop(Exception):
    """The run stops early: a signal was received, or the cluster is gone (the message says which)."""


def _check_signal(state: RunStatus) -> None:
    """Stop the run at a held SIGINT or SIGTERM (:func:`linkwork.interrupts.held_signals`, the run's own or its
    caller's), recording it in ``state.signal``."""
    state.signal = state.signal or requested()
    if state.signal:
        raise _Stop(stop_text(state.signal))


@contextlib.contextmanager
def _signals_ignored() -> Iterator[None]:
    """SIGINT and SIGTERM ignored while a local cluster starts its worker processes, which inherit that (an
    ignored signal stays ignored in a new Python process): a Ctrl-C in the terminal, sent to every process of
    the group, then reaches this process alone, which stops the workers itself. A signal during the start-up
    itself (seconds) is not seen."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = {sig: signal.signal(sig, signal.SIG_IGN) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in before.items():
            signal.signal(sig, handler)


def _connect(address: str, timeout: float) -> Any:
    """A :class:`~dask.distributed.Client` of the scheduler at ``address``, or a :class:`RequestNotMetError` when
    it cannot be reached or does not answer within ``timeout`` seconds (Dask's own timeout does not cover a
    server that accepts the connection and then says nothing, so the connection is made in a thread)."""
    from dask.distributed import Client

    box: dict[str, Any] = {}

    def connect() -> None:
        try:
            box["client"] = Client(address, timeout=f"{timeout}s")
        except BaseException as exc:  # reported below, in the caller's thread
            box["error"] = exc

    worker = threading.Thread(target=connect, name="linkwork-connect", daemon=True)
    worker.start()
    worker.join(timeout + 5.0)
    if worker.is_alive():
        raise RequestNotMetError(
            f"the Dask scheduler at {address} accepted the connection but did not answer within {timeout:g} s "
            f"(set {ENV_CONNECT_TIMEOUT} to wait longer)"
        )
    if "error" in box:
        exc = box["error"]
        raise RequestNotMetError(
            f"cannot reach the Dask scheduler at {address} within {timeout:g} s: {type(exc).__name__} {exc}"[
                :500
            ]
        ) from None
    return box["client"]


@contextlib.contextmanager
def dask_client(scheduler: str | None, workers: int | None = None) -> Iterator[Any]:
    """A connected :class:`~dask.distributed.Client`: to ``scheduler``, or to a fresh local cluster of
    ``workers`` single-threaded processes that is shut down on exit (configured by :data:`LOCAL_CLUSTER_CONFIG`,
    its HTTP endpoint on a free port of 127.0.0.1, no dashboard)."""
    import dask
    from dask.distributed import Client, LocalCluster

    timeout = connect_timeout()
    if scheduler is not None:
        client = _connect(scheduler, timeout)
        try:
            yield client
        finally:
            with contextlib.suppress(Exception):
                client.close(timeout=timeout)
        return
    n = workers or default_workers()
    try:
        with _signals_ignored(), dask.config.set(LOCAL_CLUSTER_CONFIG):
            cluster = LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address=None,
                # The scheduler's HTTP endpoint (health, metrics) on a free port: its default, 8787, may be taken
                # (another cluster, a notebook's dashboard), and dask then warns on the terminal.
                scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                silence_logs=logging.CRITICAL,
            )
    except Exception as exc:  # a machine that cannot start worker processes
        raise RequestNotMetError(f"cannot start {n} local Dask worker processes: {exc}"[:500]) from None
    try:
        with Client(cluster) as client:
            yield client
    finally:
        with contextlib.suppress(Exception):
            cluster.close(timeout=timeout)


def map_chunks(
    func: Callable[..., T],
    shared: Any,
    chunks: Sequence[tuple[Any, ...]],
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    client: Any = None,
    progress: Progress | None = None,
    status: RunStatus | None = None,
    failed: Callable[[tuple[Any, ...], str], T] | None = None,
) -> Iterator[T]:
    """Yield ``func(shared, *chunk)`` for every chunk, in chunk order.

    ``shared`` (the study's set-up) is sent to every worker once. ``client`` reuses a connected Dask client;
    otherwise one is made from ``scheduler`` / ``workers`` (``workers=0``: run here, in this process).

    With ``status``, SIGINT and SIGTERM, the loss of every worker or of the scheduler, or a chunk that cannot
    be computed end the run quietly after the chunks finished so far (``status`` says why); without it they
    raise (:class:`KeyboardInterrupt`, :class:`~linkwork.errors.RequestNotMetError`). ``failed(chunk, reason)``
    stands in for a chunk whose task failed on a worker (it killed its workers, or raised), so the run goes on.
    """
    address = scheduler_address(scheduler)
    state = status if status is not None else RunStatus()
    state.total = len(chunks)
    # with a status, the first SIGINT or SIGTERM is held (the one hold of every command) and the run stops after
    # the chunks in hand; a chunk computed here runs whole (a trace in it is not cut short by the signal)
    guard = held_signals() if status is not None else contextlib.nullcontext()
    try:
        with guard, quiet_dask(restore=status is None):
            if client is None and address is None and (workers == 0 or len(chunks) <= 1):
                for chunk in chunks:
                    _check_signal(state)
                    with whole():
                        result = func(shared, *chunk)
                    state.done += 1
                    if progress is not None:
                        progress(state.done, state.total)
                    yield result
                return
            if client is not None:
                yield from _run_on(client, func, shared, chunks, progress, state, failed)
                return
            _check_signal(state)
            with dask_client(address, workers) as own:
                yield from _run_on(own, func, shared, chunks, progress, state, failed)
    except CancelledError:  # work the cluster dropped, met anywhere else in the run
        if status is None:
            raise RequestNotMetError("lost the Dask cluster: the work in hand was cancelled") from None
        status.stop("lost the Dask cluster; the work in hand was cancelled", 3)
    except _Stop as exc:
        if status is None and state.signal:
            # a caller's hold, and no status to say so: the usual interrupt
            if state.signal == signal.SIGINT:
                raise KeyboardInterrupt from None
            raise Interrupted(state.signal, again=False) from None
        if status is None:
            raise RequestNotMetError(str(exc)) from None
        if state.signal:
            status.stop(str(exc), exit_code(state.signal))
        else:
            status.stop(str(exc), 3)


def _run_on(
    client: Any,
    func: Callable[..., T],
    shared: Any,
    chunks: Sequence[tuple[Any, ...]],
    progress: Progress | None,
    state: RunStatus,
    failed: Callable[[tuple[Any, ...], str], T] | None,
) -> Iterator[T]:
    """Submit chunks to ``client`` with a bounded window and yield their results in order."""
    from dask.distributed import wait
    from distributed.comm.core import CommClosedError

    n_workers = max(1, worker_count(client))
    window = max(2, 3 * n_workers)
    [remote] = client.scatter([shared], broadcast=True, hash=False)
    token = uuid.uuid4().hex
    pending = iter(enumerate(chunks))
    futures: dict[Any, int] = {}
    ready: dict[int, T] = {}
    next_index = 0
    finished = 0
    watch = _Watch(client, connect_timeout())

    def submit_next() -> None:
        item = next(pending, None)
        if item is not None:
            index, chunk = item
            fut = client.submit(func, remote, *chunk, pure=False, key=f"linkwork-chunk-{token}-{index}")
            futures[fut] = index

    for _ in range(window):
        submit_next()
    try:
        while futures:
            _check_signal(state)
            try:
                done = wait(list(futures), timeout=POLL, return_when="FIRST_COMPLETED").done
            except TimeoutError:
                done = set()
            except (CancelledError, CommClosedError, OSError):  # wait() raises for work the cluster dropped
                raise _Stop(watch.lost()) from None
            if not done:
                watch.check(finished)
                continue
            _check_signal(state)
            for fut in [f for f in futures if f in done]:
                index = futures.pop(fut)
                ready[index] = _result(fut, chunks[index], failed, watch)
                fut.release()
                finished += 1
                if progress is not None:
                    progress(finished, len(chunks))
                submit_next()
            while next_index in ready:
                state.done += 1
                yield ready.pop(next_index)
                next_index += 1
    finally:
        for fut in futures:
            with contextlib.suppress(Exception):
                fut.cancel()


def _result(
    fut: Any, chunk: tuple[Any, ...], failed: Callable[[tuple[Any, ...], str], T] | None, watch: _Watch
) -> T:
    """A finished future's result; a chunk that failed on its worker is ``failed(chunk, reason)`` or ends the
    run; a future cancelled because the scheduler is gone ends the run."""
    from dask.distributed import KilledWorker
    from distributed.comm.core import CommClosedError

    if fut.status == "cancelled":
        raise _Stop(watch.lost())
    try:
        return fut.result()
    except ImportError as exc:
        raise LinkworkError(
            f"a Dask worker cannot import what the study needs ({exc}); install linkwork (the same version) "
            "on every worker"
        ) from None
    except (CancelledError, CommClosedError, OSError, TimeoutError):
        raise _Stop(watch.lost()) from None
    except KilledWorker:
        reason = "its task killed the Dask workers that ran it (out of memory?)"
    except Exception as exc:  # a worker-side failure of one chunk
        if isinstance(exc, LinkworkError) and failed is None:
            raise
        reason = f"failed on a Dask worker: {type(exc).__name__}: {exc}"[:500]
    if failed is None:
        raise _Stop(f"a chunk of the study {reason}")
    return failed(chunk, reason)


def worker_count(client: Any) -> int:
    """The workers the scheduler knows now (their number only: the scheduler does not describe each)."""
    info = client.scheduler_info(n_workers=0)
    if "n_workers" in info:
        return int(info["n_workers"])
    return len(client.scheduler_info(n_workers=-1).get("workers", {}))  # pragma: no cover - older dask


class _Watch:
    """Gives up on a cluster that has had no worker, or no scheduler connection, for ``timeout`` seconds."""

    def __init__(self, client: Any, timeout: float) -> None:
        self.client = client
        self.timeout = timeout
        self.bad_since: float | None = None

    def check(self, finished: int) -> None:
        """Raise :class:`_Stop` when the scheduler is gone, or has had no worker for ``timeout`` seconds."""
        now = time.monotonic()
        status = getattr(self.client, "status", "running")
        if status in ("closed", "closing", "failed"):
            raise _Stop(f"lost the Dask scheduler (client {status}) after {finished} finished chunk(s)")
        healthy = status == "running" and self._workers() > 0
        if healthy:
            self.bad_since = None
            return
        self.bad_since = self.bad_since or now
        if now - self.bad_since > self.timeout:
            what = "the Dask scheduler" if status != "running" else "every Dask worker"
            raise _Stop(f"lost {what} for {self.timeout:g} s (set {ENV_CONNECT_TIMEOUT} to wait longer)")

    def lost(self) -> str:
        """What was lost, when the scheduler cancelled the work in hand."""
        status = getattr(self.client, "status", "running")
        if status != "running":
            return f"lost the Dask scheduler (client {status}); the work in hand was cancelled"
        if not self._scheduler_answers():  # the client's status lags behind a scheduler that just died
            return "lost the Dask scheduler (it does not answer); the work in hand was cancelled"
        if self._workers() == 0:
            return "lost every Dask worker; the work in hand was cancelled"
        return "the Dask scheduler cancelled the work in hand (was it restarted?)"

    def _scheduler_answers(self) -> bool:
        """Whether the scheduler answers a request now (``scheduler_info`` would return a cached answer)."""
        try:
            self.client.sync(self.client.scheduler.identity, n_workers=0, callback_timeout=5)
        except Exception:  # refused, reset or timed out: no scheduler to talk to
            return False
        return True

    def _workers(self) -> int:
        try:
            return worker_count(self.client)
        except Exception:  # an unreachable scheduler has no workers we can use
            return 0
