"""Run per-chunk jobs in parallel on Dask: an existing cluster (``--scheduler ADDRESS``) or a local one.

Each job writes its own chunk into the shared store and marks it done, so nothing but a frame
count travels back to the client, and an interrupted run keeps every finished chunk.
"""

from __future__ import annotations

import logging
import os
import signal
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any

from skyradar.errors import InputError
from skyradar.extras import import_extra

__all__ = [
    "connect",
    "close",
    "map_chunks",
    "map_frame_chunks",
    "check_workers",
    "check_scheduler",
    "max_local_workers",
]

_WORKERS_PER_CORE = 4  # more local worker processes than this only thrash (each holds numba + numpy)


def max_local_workers() -> int:
    """The most local worker processes a command starts: 4 per core of this machine.

    Examples
    --------
    >>> max_local_workers() >= 4
    True
    """
    return _WORKERS_PER_CORE * (os.cpu_count() or 1)


def check_workers(workers: int | None, option: str = "--workers") -> int | None:
    """``workers`` if None or a whole number from 1 to :func:`max_local_workers`, else :class:`InputError`.

    Without this bound ``--workers 99999999999999999999`` forked processes until the machine ran
    out of memory.

    Examples
    --------
    >>> check_workers(2)
    2
    >>> check_workers(10**20)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: --workers: must be an integer from 1 to ..., got 100000000000000000000
    """
    if workers is None:
        return None
    limit = max_local_workers()
    if isinstance(workers, bool) or int(workers) != workers or not 1 <= workers <= limit:
        raise InputError(
            f"{option}: must be an integer from 1 to {limit} (4 per core on this machine), got {workers!r}"
        )
    return int(workers)


def check_scheduler(scheduler: str | None, option: str = "--scheduler") -> str | None:
    """``scheduler`` if None or a Dask address with a port from 1 to 65535, else
    :class:`InputError`: checked before any work, not after the scenario is built or the output
    folder made (``tcp://host:99999`` waited 10 s for an answer that cannot come).

    Examples
    --------
    >>> check_scheduler("tcp://127.0.0.1:8786")
    'tcp://127.0.0.1:8786'
    >>> check_scheduler("tcp://127.0.0.1:99999")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: --scheduler tcp://127.0.0.1:99999: not a Dask scheduler address ...
    """
    if scheduler is None:
        return None
    addressing = import_extra("distributed.comm.addressing", "dask", f"{option} (a Dask cluster)")
    try:
        _host, port = addressing.get_address_host_port(scheduler)
        if not 1 <= int(port) <= 65535:
            raise ValueError(f"port {port} is not 1..65535")
    except (ValueError, TypeError) as exc:
        raise InputError(
            f"{option} {scheduler}: not a Dask scheduler address (tcp://HOST:PORT): {exc}"
        ) from None
    return scheduler


def connect(scheduler: str | None, workers: int | None, timeout_s: float = 10.0):
    """A ``distributed.Client`` on ``scheduler``, or on a new local cluster of ``workers`` processes.

    Needs the optional ``dask`` extra (:class:`~skyradar.extras.MissingExtraError` otherwise); runs
    without ``--workers`` / ``--scheduler`` never get here and need no Dask scheduler.
    """
    distributed = import_extra("distributed", "dask", "--workers/--scheduler (a Dask cluster)")
    Client, LocalCluster = distributed.Client, distributed.LocalCluster

    if scheduler is not None:
        try:
            return Client(scheduler, timeout=timeout_s)
        except ValueError as exc:  # distributed's address parser: no port, ipv6 without brackets...
            raise InputError(
                f"--scheduler {scheduler}: not a Dask scheduler address (tcp://HOST:PORT): {exc}"
            ) from exc
        except (OSError, TimeoutError) as exc:
            raise InputError(
                f"--scheduler {scheduler}: no Dask scheduler answered within {timeout_s:.0f} s ({exc})"
            ) from exc
    check_workers(workers)
    # A worker logs every failed task with its traceback (ERROR); the client re-raises the error
    # itself (bad input: one line), so our own cluster's workers log only what is critical.
    # Ctrl-C or SIGTERM while the cluster starts is held until it has started: a cluster interrupted
    # half way leaves workers starting, and distributed's exit handler fails on them with a traceback.
    with _interrupts_held() as held:
        cluster = LocalCluster(
            n_workers=int(workers or 2),
            threads_per_worker=1,
            processes=True,
            # No dashboard, and the scheduler's HTTP server on a free port: on the default 8787,
            # taken by any other cluster on the machine, distributed warns on stderr.
            dashboard_address=":0",
            scheduler_kwargs={"dashboard": False},
            silence_logs=logging.CRITICAL,
        )
        client = Client(cluster)
    if held:
        close(client, owns_cluster=True)
        raise KeyboardInterrupt
    return client


@contextmanager
def _interrupts_held() -> Iterator[list[int]]:
    """Record SIGINT and SIGTERM instead of acting on them for the block; yields the list of those
    that came. Outside the main thread (where handlers cannot change) nothing is held."""
    held: list[int] = []
    previous = {}
    try:
        for signum in (signal.SIGINT, signal.SIGTERM):
            previous[signum] = signal.signal(signum, lambda number, frame: held.append(number))
    except ValueError:  # not the main thread
        pass
    try:
        yield held
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def close(client, owns_cluster: bool) -> None:
    """Close a client from :func:`connect`, and its local cluster when we started it.

    Called once the work is written (or while an error propagates): a cluster that does not shut
    down in time on a loaded machine loses nothing, and its worker processes end with this one, so
    a timeout here is logged in one line instead of raised over the result or the error. A client
    that times out closing still has its local cluster closed: the workers are stopped either way.

    Parameters
    ----------
    client : distributed.Client
        The client (anything with ``close()`` and, for a local cluster, ``cluster.close()``).
    owns_cluster : bool
        Close the client's cluster too (it was started by :func:`connect`).

    Examples
    --------
    With stand-ins for a client and its cluster (no Dask needed); a timeout is logged, not raised:

    >>> class Part:
    ...     def __init__(self, name, fail=False):
    ...         self.name, self.fail = name, fail
    ...     def close(self):
    ...         print("closed", self.name)
    ...         if self.fail:
    ...             raise TimeoutError("slow shutdown")
    >>> client = Part("client"); client.cluster = Part("cluster")
    >>> close(client, owns_cluster=True)
    closed client
    closed cluster
    >>> close(client, owns_cluster=False)
    closed client
    >>> client.cluster = Part("cluster", fail=True)
    >>> close(client, owns_cluster=True)
    closed client
    closed cluster
    >>> slow = Part("client", fail=True); slow.cluster = Part("cluster")
    >>> close(slow, owns_cluster=True)
    closed client
    closed cluster
    """
    cluster = getattr(client, "cluster", None)
    parts = [client] + ([cluster] if owns_cluster and cluster is not None else [])
    for part in parts:
        try:
            part.close()
        except (TimeoutError, OSError) as exc:
            logging.getLogger(__name__).warning("the Dask cluster did not shut down cleanly: %r", exc)


def map_chunks(
    job: Callable[..., int],
    *args: Any,
    client,
    chunks: Sequence[int] = (),
    progress: Callable[[int], None] | None = None,
) -> None:
    """Run ``job(*args, index)`` for each chunk index on ``client``; ``progress(frames)`` per chunk."""
    from distributed import as_completed

    try:
        futures = []
        scattered = [
            client.scatter(a, broadcast=True) if not isinstance(a, str | int | float) else a for a in args
        ]
        futures = [client.submit(job, *scattered, index, pure=False) for index in chunks]
        for future in as_completed(futures):
            frames = future.result()
            if progress:
                progress(frames)
    except BaseException:
        for future in futures:
            future.cancel()
        raise


def map_frame_chunks(
    job: Callable[..., Any],
    path: str,
    n_frames: int,
    chunk_frames: int,
    *args: Any,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[int], None] | None = None,
) -> list[Any]:
    """``[job(path, start, stop, *args) for each time chunk]`` in order, on Dask or in a plain loop.

    Workers open the run themselves from ``path`` (a shared filesystem), so only the chunk bounds
    travel to them and only each chunk's (small) result travels back.

    Parameters
    ----------
    job : callable
        ``job(path, start, stop, *args)``: the result of frames ``start`` to ``stop`` (exclusive).
        On Dask it must be importable by the workers (a module-level function).
    path : str
        The run, opened by ``job`` itself.
    n_frames : int
        Frames in the run.
    chunk_frames : int
        Frames per chunk (the last may be shorter).
    *args
        Further arguments of ``job``.
    scheduler : str, optional
        A Dask scheduler address (``tcp://HOST:PORT``).
    workers : int, optional
        Processes of a local Dask cluster; without ``scheduler`` and ``workers`` the chunks run here,
        one after the other.
    progress : callable, optional
        ``progress(frames)`` after each chunk, with its number of frames.

    Returns
    -------
    list
        The chunks' results in frame order.

    Examples
    --------
    Without a scheduler or workers, in a plain loop:

    >>> done = []
    >>> map_frame_chunks(lambda path, start, stop, k: (start, stop * k), "run.zarr", 10, 4, 10,
    ...                  progress=done.append)
    [(0, 40), (4, 80), (8, 100)]
    >>> done
    [4, 4, 2]
    """
    bounds = [(s, min(s + chunk_frames, n_frames)) for s in range(0, n_frames, chunk_frames)]
    if scheduler is None and not workers:
        here = []
        for start, stop in bounds:
            here.append(job(path, start, stop, *args))
            if progress:
                progress(stop - start)
        return here
    client = connect(scheduler, workers)
    from distributed import as_completed

    try:
        futures = [client.submit(job, path, start, stop, *args, pure=False) for start, stop in bounds]
        order = {f.key: i for i, f in enumerate(futures)}
        results: list[Any] = [None] * len(futures)
        for future in as_completed(futures):
            results[order[future.key]] = future.result()
            if progress:
                start, stop = bounds[order[future.key]]
                progress(stop - start)
        return results
    finally:
        close(client, owns_cluster=scheduler is None)
