"""Running a suite's scenarios, one after another or in a process pool (``--workers``).

Every scenario carries its own seed and runs in a fresh output folder, so its results do
not depend on which worker ran it or in which order; the outcomes come back in the suite's
order. Workers start by ``forkserver`` (``spawn`` where it is missing), never ``fork``:
MuJoCo's EGL contexts and BLAS thread pools of a running process do not survive a fork.
"""

from __future__ import annotations

import multiprocessing
import os
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rich.console import Console

from avatarsim.avatar_models.errors import AvatarsimError
from avatarsim.scripts.pipeline import run_scenario
from avatarsim.scripts.suite.discovery import SuiteEntry

STATUSES = ("passed", "failed", "skipped", "error")


@dataclass(frozen=True)
class Outcome:
    """What became of one scenario: ``status`` in :data:`STATUSES`, its ``results.json``
    when it ran, ``message`` why it was skipped or errored, ``time_s`` its wall time."""

    entry: SuiteEntry
    status: str
    results: dict[str, Any] | None = None
    message: str = ""
    time_s: float = 0.0

    @property
    def name(self) -> str:
        return self.entry.name


def run_one(entry: SuiteEntry, out_dir: Path) -> Outcome:
    """Run ``entry`` into ``out_dir`` (a pool's task: module-level, so it pickles)."""
    t0 = time.perf_counter()
    try:
        results = run_scenario(entry.scenario, out_dir, Console(stderr=True, quiet=True))
    except AvatarsimError as exc:  # found only while running (e.g. an unreadable motion file)
        return Outcome(entry, "error", message=str(exc), time_s=time.perf_counter() - t0)
    except Exception as exc:  # noqa: BLE001 - a bug in one scenario must not end the suite;
        # it becomes that scenario's JUnit <error> and the suite's exit code says so.
        message = f"internal error: {type(exc).__name__}: {exc}"
        return Outcome(entry, "error", message=message, time_s=time.perf_counter() - t0)
    status = "passed" if results["passed"] else "failed"
    return Outcome(entry, status, results, time_s=time.perf_counter() - t0)


def _limit_threads(threads: int) -> None:
    """Pool initializer: ``threads`` BLAS/OpenMP threads per worker, so N workers share the
    cores instead of each starting one thread per core."""
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=threads)


def _context() -> multiprocessing.context.BaseContext:
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    context = multiprocessing.get_context("forkserver")
    # The server imports the stages once (no GL context or thread pool is made at import);
    # each worker forks from it instead of importing them again (seconds per worker).
    context.set_forkserver_preload([__name__])
    return context


def run_suite(
    entries: Sequence[SuiteEntry],
    out_dir: Path,
    workers: int = 1,
    fail_fast: bool = False,
    on_done: Callable[[Outcome], None] | None = None,
) -> list[Outcome]:
    """Outcomes of ``entries`` in their order; each scenario writes ``out_dir/<name>/``.

    With ``fail_fast`` nothing new starts after the first failure or error; scenarios not
    started are skipped with that reason (with workers, those already running finish).
    """
    done: dict[str, Outcome] = {
        e.name: Outcome(e, "skipped", message=e.skip_reason) for e in entries if e.skip_reason
    }
    todo = [e for e in entries if not e.skip_reason]
    stopped_by: list[Outcome] = []

    def finished(outcome: Outcome) -> None:
        done[outcome.name] = outcome
        if on_done is not None:
            on_done(outcome)
        if fail_fast and outcome.status in ("failed", "error") and not stopped_by:
            stopped_by.append(outcome)

    if workers == 1:
        for entry in todo:
            finished(run_one(entry, out_dir / entry.name))
            if stopped_by:
                break
    else:
        threads = max(1, (os.cpu_count() or 1) // workers)
        with ProcessPoolExecutor(
            workers, mp_context=_context(), initializer=_limit_threads, initargs=(threads,)
        ) as pool:
            futures: dict[Future, SuiteEntry] = {
                pool.submit(run_one, e, out_dir / e.name): e for e in todo
            }
            for future in as_completed(futures):
                if future.cancelled():
                    continue
                finished(future.result())
                if stopped_by:
                    for pending in futures:
                        pending.cancel()
    reason = ""
    if stopped_by:
        reason = f"not run: --fail-fast after {stopped_by[0].name} {stopped_by[0].status}"
    return [done.get(e.name) or Outcome(e, "skipped", message=reason) for e in entries]
