"""Sampling-based tracking: a beam search over small corrections to the tracker's targets.

After SAMCON (Liu et al. 2010, "Sampling-based contact-rich motion control", SIGGRAPH): the
whole-body controller of :mod:`sim.tracking` is good for a step or two, but a walk is
chaotic, and a small error in one stance becomes a fall three steps later. So the reference is
tracked window by window (:attr:`SearchSettings.window_s`); from each of the
:attr:`SearchSettings.beam` best states so far, the window is simulated several times, once as
the controller would and otherwise with a random constant offset added to every actuated
hinge's target (Gaussian, :attr:`SearchSettings.sigma_leg_rad` on the legs and
:attr:`SearchSettings.sigma_rad` elsewhere); the ``beam`` end states of lowest cost go on.
Each end state is judged twice, at the window's end and :attr:`SearchSettings.lookahead_s`
later with the plain controller simulated on, so a state that looks fine but is about to fall
is not kept (without this look-ahead, real walks fell in 3 of 6 searches).

Nothing changes about the physics: every sample is a full MuJoCo simulation of the same
humanoid, the root unactuated and nothing pushing it, started from a state MuJoCo itself
produced (``mj_getState`` / ``mj_setState``). The search only chooses the targets.

The cost of a state (:func:`state_cost`) is what predicts a fall a step later, relative to the
reference at its played clock: the horizontal capture-point error (m), the tilt of the root's
up axis (degrees) and its roll and pitch rate error (degrees/s), the head's height error (m),
and the mean body17 error in the root's frame (the pose, m), each divided by its scale in
:class:`SearchSettings` and squared. A fallen or lost state (``sim.tracking``'s criteria), or
one where MuJoCo met a diverging acceleration (:meth:`Tracker.unstable`), costs infinity.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import mujoco
import numpy as np
from tqdm import tqdm

from avatar_models.body17 import BODY17
from sim.soles import subtree_mask, thigh_bodies
from sim.tracking import (
    Progress,
    Reference,
    Tracker,
    TrackingResult,
    TrackingSettings,
    _up,
    track,
)

HEAD = BODY17.index("head")
STATE = mujoco.mjtState.mjSTATE_INTEGRATION


@dataclass(frozen=True)
class SearchSettings:
    """Beam search parameters.

    Attributes:
        window_s: length of a window with one constant target offset (SAMCON uses 0.1 s).
        samples: simulations of each window per kept state (the first without an offset).
        beam: states kept after each window.
        sigma_rad, sigma_leg_rad: standard deviation of the target offsets, upper body and
            legs (hips, knees, ankles, toes).
        capture_scale_m, tilt_scale_deg, spin_scale_deg_s, head_scale_m, pose_scale_m: cost
            scales.
        lookahead_s: each sample is also judged this much later, the plain controller
            simulated on from its end (the larger of both costs counts); 0: not at all.
        retry_factor, max_backtracks: what is done when every sample falls
            (:func:`search_track`).
        budget: seconds simulated (samples, look-aheads, retries) per second of reference at
            most; past it the search gives up, incomplete. A walk that tracks takes about 100
            (3 s built-in walk: 15 windows x 48 samples x 0.4 s); a clip the controller cannot
            follow (Bandai run_normal_001: the plain controller falls at 0.4 s) backtracks
            without end, over 10 minutes for 3 s, without one.
        seed: random generator seed (the search is deterministic for a seed).
    """

    window_s: float = 0.2
    samples: int = 8
    beam: int = 6
    sigma_rad: float = 0.03
    sigma_leg_rad: float = 0.08
    capture_scale_m: float = 0.05
    tilt_scale_deg: float = 5.0
    spin_scale_deg_s: float = 45.0
    head_scale_m: float = 0.05
    pose_scale_m: float = 0.05
    lookahead_s: float = 0.2
    retry_factor: int = 4
    max_backtracks: int = 20
    budget: float = 400.0
    seed: int = 0


@dataclass(frozen=True)
class _Node:
    """A simulated state on a search path: its cost, MuJoCo's state, the controller's
    state, and the target offsets ``(W, nu)`` of the windows that led to it."""

    cost: float
    state: np.ndarray
    progress: Progress
    offsets: tuple


@dataclass(frozen=True)
class SearchedTracking:
    """The result of :func:`search_track`.

    Attributes:
        result: the tracking of the best path.
        offsets: ``(W, nu)`` its target offset in each window (radians; zeros where the
            plain controller's targets won), for :func:`replay`.
        window_steps: simulation steps per window.
        simulated_s: seconds simulated in all, samples included (the search's cost).
        completed: whether the path reaches the reference's end; ``False`` when the search
            gave up: every sample fell, retries and backtracks exhausted (``result`` is the
            path that fell last), or the budget was spent (``result`` is the best path that
            got furthest, upright); either is shorter than the reference.
    """

    result: TrackingResult
    offsets: np.ndarray
    window_steps: int
    simulated_s: float
    completed: bool = True


def state_cost(
    tracker: Tracker, ref: Reference, progress: Progress, search: SearchSettings
) -> float:
    """Cost of the tracker's current state against the reference at ``progress.clock``
    (module docstring); infinity once fallen."""
    d = tracker.data
    clock = min(progress.clock, ref.qpos.shape[0] - 1.0)
    i = min(int(clock), ref.qpos.shape[0] - 2)
    a = clock - i
    com = (1 - a) * ref.com[i] + a * ref.com[i + 1]
    sites = (1 - a) * ref.sites[i] + a * ref.sites[i + 1]
    q_ref = ref.qpos[int(round(clock))]
    now = d.site_xpos[tracker.sites]
    if tracker.fallen(d.qpos[None], q_ref[None], now[None], sites[None], tracker.unstable())[0]:
        return np.inf
    tracker._com_jacobian()
    capture = np.linalg.norm(tracker._capture_error(q_ref, com))
    tilt = np.degrees(np.arccos(np.clip(_up(d.qpos[None])[0] @ _up(q_ref[None])[0], -1, 1)))
    head = abs(now[HEAD, 2] - sites[HEAD, 2])
    root = tracker.sites[BODY17.index("pelvis")]
    pose = np.linalg.norm(
        (now - d.site_xpos[root]) - (sites - sites[BODY17.index("pelvis")]),
        axis=1,
    ).mean()
    # Roll and pitch rates of the root (its local x, y), which the capture point (linear
    # momentum) does not see: a body upright now but rotating fast falls a window later.
    spin = np.degrees(
        np.linalg.norm(d.qvel[3:5] - ((1 - a) * ref.qvel[i] + a * ref.qvel[i + 1])[3:5])
    )
    return float(
        (capture / search.capture_scale_m) ** 2
        + (tilt / search.tilt_scale_deg) ** 2
        + (spin / search.spin_scale_deg_s) ** 2
        + (head / search.head_scale_m) ** 2
        + (pose / search.pose_scale_m) ** 2
    )


def search_track(
    model: mujoco.MjModel,
    qpos_ref: np.ndarray,
    fps: float,
    settings: TrackingSettings | None = None,
    search: SearchSettings | None = None,
    progress_bar: bool = False,
) -> SearchedTracking:
    """Track ``qpos_ref (T, nq)`` at ``fps`` by beam search (module docstring) with a
    :class:`~sim.tracking.Tracker` on ``model`` (which it modifies). Costs about
    ``samples x beam`` plain tracking runs.

    When every sample of a window falls, the window is sampled again with
    :attr:`SearchSettings.retry_factor` times as many samples; when those fall too, the search
    steps back one window (two after a second failure in a row, and so on) and samples from
    there again (at most :attr:`SearchSettings.max_backtracks` times in all). If nothing
    survives even then, the path that fell last is returned (its result says when it fell).
    Past :attr:`SearchSettings.budget` the search stops with the best path that got
    furthest, upright but short of the reference's end."""
    search = search or SearchSettings()
    tracker = Tracker(model, settings)
    m, d = tracker.model, tracker.data
    ref = tracker.reference(qpos_ref, fps)
    rng = np.random.default_rng(search.seed)
    leg = subtree_mask(m, thigh_bodies(m))[m.jnt_bodyid[m.actuator_trnid[:, 0]]]
    sigma = np.where(leg, search.sigma_leg_rad, search.sigma_rad)
    window = max(1, int(round(search.window_s / m.opt.timestep)))
    lookahead = int(round(search.lookahead_s / m.opt.timestep))
    size = mujoco.mj_stateSize(m, STATE)

    def expand(beam: list[_Node], samples: int) -> list[_Node]:
        nonlocal simulated
        children = []
        for node in beam:
            for sample in range(samples):
                offset = np.zeros(m.nu) if sample == 0 else rng.normal(0.0, sigma)
                tracker.restore(node.state, STATE)
                progress = tracker.advance(ref, node.progress, window, offset)
                simulated += progress.step - node.progress.step
                state = np.empty(size)
                mujoco.mj_getState(m, d, state, STATE)
                cost = state_cost(tracker, ref, progress, search)
                if np.isfinite(cost) and search.lookahead_s > 0:
                    # Judged where the plain controller takes it next: a state that is fine
                    # now but falls a moment later is not kept.
                    ahead = tracker.advance(ref, progress, lookahead, np.zeros(m.nu))
                    simulated += ahead.step - progress.step
                    cost = max(cost, state_cost(tracker, ref, ahead, search))
                children.append(_Node(cost, state, progress, node.offsets + (offset,)))
        children.sort(key=lambda c: c.cost)
        return children

    start = tracker.start(ref)
    state = np.empty(size)
    mujoco.mj_getState(m, d, state, STATE)
    history = [[_Node(0.0, state, start, ())]]  # the beam after each window
    simulated, backtracks, last_fallen = 0, 0, history[0][0]
    furthest, depth = 1, 1  # windows reached; how far the next step back goes
    bar = tqdm(total=tracker.steps_of(ref), unit="step", disable=not progress_bar, leave=False)
    budget_steps = search.budget * tracker.steps_of(ref)
    over_budget, deepest = False, history[0][0]  # deepest: the best state furthest along
    while not tracker.finished(ref, history[-1][0].progress):
        if simulated > budget_steps:
            over_budget = True
            break
        samples, children = search.samples, []
        for _ in range(2):
            children = expand(history[-1], samples)
            if np.isfinite(children[0].cost):
                break
            samples *= search.retry_factor
        if not np.isfinite(children[0].cost):
            last_fallen = children[0]
            if backtracks >= search.max_backtracks or len(history) == 1:
                break
            # The fall may have been decided several windows back: each failure in a row
            # steps back one window further.
            backtracks += 1
            del history[max(1, len(history) - depth) :]
            depth += 1
            continue
        history.append([c for c in children if np.isfinite(c.cost)][: search.beam])
        if len(history) > furthest:
            furthest, depth, deepest = len(history), 1, history[-1][0]
        bar.update(history[-1][0].progress.step - bar.n)
    bar.close()
    completed = tracker.finished(ref, history[-1][0].progress)
    best = history[-1][0] if completed else deepest if over_budget else last_fallen
    return SearchedTracking(
        result=tracker.result(ref, best.progress.frames),
        offsets=np.array(best.offsets).reshape(-1, m.nu),
        window_steps=window,
        simulated_s=simulated * m.opt.timestep,
        completed=completed,
    )


def replay(
    tracker: Tracker, qpos_ref: np.ndarray, fps: float, offsets: np.ndarray, window_steps: int
) -> TrackingResult:
    """Track ``qpos_ref`` again with ``tracker`` (a fresh one, same model and settings as the
    search's) plus the target ``offsets (W, nu)`` the search found, one per window of
    ``window_steps``: one uninterrupted simulation, which reproduces the search's result
    (MuJoCo is deterministic)."""
    ref = tracker.reference(qpos_ref, fps)
    progress = tracker.start(ref)
    for offset in offsets:
        progress = tracker.advance(ref, progress, window_steps, offset)
    return tracker.result(ref, progress.frames)


def timed_tracking(
    model: mujoco.MjModel,
    qpos_ref: np.ndarray,
    fps: float,
    search: SearchSettings | None,
    progress_bar: bool = False,
) -> tuple[TrackingResult, dict]:
    """Track ``qpos_ref (T, nq)`` on (a copy of) ``model``: by :func:`search_track` with
    ``search``, or by the plain controller when it is ``None``. Returns the result and its
    summary (:meth:`TrackingResult.summary`) with the mode, the search's settings and
    simulated seconds, the wall time and the speed next to real time, and the outcome:
    ``requested_s`` (the reference's length), ``completed`` (tracked to its end without a
    fall) and ``failure`` (``None``, ``"fell"``, or ``"search exhausted"`` when the search
    gave up before the end: every sample fell within its look-ahead)."""
    start = time.perf_counter()
    reached = True
    if search is None:
        result, extra = track(model, qpos_ref, fps), {"mode": "plain"}
    else:
        searched = search_track(model, qpos_ref, fps, search=search, progress_bar=progress_bar)
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
