"""One timed physics control run, as the ``control`` command and the scenario stage report it:
the search (:func:`sim.control.search.search`) or the plain controller, its summary, wall time
and outcome."""

from __future__ import annotations

import time

import mujoco
import numpy as np

from avatarsim.sim.control import search as control_search
from avatarsim.sim.control.controller import ControlResult, control
from avatarsim.sim.control.search import SearchSettings


def timed_control(
    model: mujoco.MjModel,
    qpos_ref: np.ndarray,
    fps: float,
    search: SearchSettings | None,
    progress_bar: bool = False,
) -> tuple[ControlResult, dict]:
    """Follow ``qpos_ref (T, nq)`` with the humanoid ``model`` (not changed): by the search
    with ``search``, or by the plain controller when it is ``None``. Returns the result and
    its summary (:meth:`ControlResult.summary`) with the mode, the search's settings and
    simulated seconds, the wall time and the speed next to real time, and the outcome:
    ``requested_s`` (the reference's length), ``completed`` (followed to its end without a
    fall) and ``failure`` (``None``, ``"fell"``, or ``"search exhausted"`` when the search
    gave up before the end: every sample fell within its look-ahead)."""
    start = time.perf_counter()
    reached = True
    if search is None:
        result, extra = control(model, qpos_ref, fps), {"mode": "plain"}
    else:
        searched = control_search.search(
            model, qpos_ref, fps, search_settings=search, progress_bar=progress_bar
        )
        result, reached = searched.result, searched.completed
        extra = {
            "mode": "search",
            "samples": search.samples,
            "beam": search.beam,
            "simulated_s": searched.simulated_s,
        }
    wall = time.perf_counter() - start
    failure = "fell" if result.fell else None if reached else "search exhausted"
    outcome = {
        "requested_s": qpos_ref.shape[0] / fps,
        "completed": failure is None,
        "failure": failure,
    }
    summary = result.summary() | extra | outcome | {"wall_s": wall}
    return result, summary | {"x_real_time": summary["duration_s"] / wall}
