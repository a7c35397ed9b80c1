"""The local process pool of ``scripts.dataset.executors``: an abandoned run (an error,
SIGTERM as SystemExit, a consumer that stops) does not wait for the items still running."""

from __future__ import annotations

import time
from multiprocessing import active_children
from pathlib import Path

from avatarsim.scripts.dataset.executors import run

SLOW_ITEM_S = 8.0
"""Far longer than shutting a pool down takes."""


def finish_after(seconds: float, marker: str) -> str:
    """Sleep ``seconds``, then write ``marker`` (module level: pool workers import it)."""
    time.sleep(seconds)
    Path(marker).write_text("done")
    return marker


def test_abandoned_pool_run_does_not_wait_for_running_items(tmp_path):
    quick, slow = tmp_path / "quick", tmp_path / "slow"
    results = run(finish_after, [(0.0, str(quick)), (SLOW_ITEM_S, str(slow))], workers=2)
    assert next(results) == str(quick)
    results.close()  # what SystemExit or an error in the consumer does to the generator
    assert not slow.exists()  # the slow item was still running when close() returned
    for worker in active_children():  # stopped, not left to finish (or to hold up our exit)
        worker.join(SLOW_ITEM_S / 2)
    assert not active_children()
    assert not slow.exists()
