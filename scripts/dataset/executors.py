"""Where shards are made: a local process pool or a Ray cluster.

An executor maps a picklable, module-level function over work items and yields the results
as they complete (in any order); the caller writes them. Results travel back to the calling
process, so a Ray cluster needs no filesystem shared with it: only the folder of the
process that runs ``generate`` is written.

- ``local``: ``workers == 1`` runs in this process; more spawn a pool whose processes run
  BLAS single-threaded (the pool is the parallelism) and exit when the parent dies, so a
  ``kill -9`` of ``generate`` leaves no orphan computing on.
- ``ray``: tasks of one CPU each, at most ``workers`` in flight, on the Ray instance this
  process is already connected to, else on the cluster at ``address`` (``"auto"``, a
  ``host:port`` or a ``ray://`` client address), else on a new local instance of ``workers``
  CPUs that is shut down afterwards. Every node needs the same avatarsim installed (README).
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from multiprocessing import active_children, get_context
from typing import Any

from avatarsim.avatar_models.errors import AvatarsimError

EXECUTORS = ("local", "ray")
PARENT_POLL_S = 0.5


class ExecutorError(AvatarsimError):
    """An executor that cannot run here (unknown, Ray missing, no cluster at the address)."""


def check_executor(executor: str, workers: int, address: str | None) -> None:
    """Raise :class:`ExecutorError` for an executor request that cannot work, before any
    work starts."""
    if executor not in EXECUTORS:
        raise ExecutorError(f"--executor must be one of {', '.join(EXECUTORS)}, got {executor!r}")
    if workers < 1:
        raise ExecutorError(f"--workers must be at least 1, got {workers}")
    if address is not None and executor != "ray":
        raise ExecutorError("--address names a Ray cluster; use it with --executor ray")
    if executor == "ray":
        try:
            import ray  # noqa: F401
        except ImportError:
            raise ExecutorError("--executor ray needs Ray: pip install 'avatarsim[ray]'") from None


def run(
    fn: Callable[..., Any],
    items: Sequence[tuple],
    executor: str = "local",
    workers: int = 1,
    address: str | None = None,
) -> Iterator[Any]:
    """``fn(*item)`` for each of ``items``, yielded as each completes (module docstring)."""
    check_executor(executor, workers, address)
    if executor == "ray":
        yield from _ray(fn, items, workers, address)
    elif workers == 1:
        yield from (fn(*item) for item in items)
    else:
        yield from _pool(fn, items, workers)


def _single_threaded_child_of(parent: int) -> None:
    """Pool initializer: one BLAS thread, and exit when the parent process is gone."""
    from threadpoolctl import threadpool_limits

    threadpool_limits(1)

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(PARENT_POLL_S)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


def _pool(fn: Callable[..., Any], items: Sequence[tuple], workers: int) -> Iterator[Any]:
    before = set(active_children())
    pool = ProcessPoolExecutor(
        max_workers=workers,
        mp_context=get_context("spawn"),
        initializer=_single_threaded_child_of,
        initargs=(os.getpid(),),
    )
    completed = False
    try:
        for future in as_completed([pool.submit(fn, *item) for item in items]):
            yield future.result()
        completed = True
    finally:
        # On an error, SIGTERM or an abandoned iteration: start no more items, and stop the
        # running ones (a leaderboard fold runs for minutes), since concurrent.futures would
        # otherwise wait for them when this process exits.
        pool.shutdown(wait=completed, cancel_futures=True)
        if not completed:
            for worker in set(active_children()) - before:
                worker.terminate()


def _single_threaded(fn: Callable[..., Any], *args: Any) -> Any:
    """``fn(*args)`` with one BLAS thread (a Ray task's CPU is the parallelism)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(1):
        return fn(*args)


def _ray(
    fn: Callable[..., Any], items: Sequence[tuple], workers: int, address: str | None
) -> Iterator[Any]:
    import ray

    started = not ray.is_initialized()
    if started:
        try:
            ray.init(
                address=address or "local",  # "local": a new instance, never a stray one
                num_cpus=None if address else workers,
                include_dashboard=False,
                log_to_driver=False,
                configure_logging=False,
            )
        except (ConnectionError, RuntimeError, ValueError) as exc:
            raise ExecutorError(
                f"cannot start or reach Ray at {address or 'local'}: {exc}"
            ) from None
    task = ray.remote(num_cpus=1, max_retries=2)(_single_threaded)
    pending: list = []
    queue = list(items)
    try:
        while queue or pending:
            while queue and len(pending) < workers:
                pending.append(task.remote(fn, *queue.pop(0)))
            done, pending = ray.wait(pending, num_returns=1)
            yield ray.get(done[0])
    finally:
        for ref in pending:
            ray.cancel(ref, force=True)
        if started:
            ray.shutdown()
