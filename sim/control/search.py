"""Sampling-based control: a beam search over small corrections to the controller's targets.

After SAMCON (Liu et al. 2010, "Sampling-based contact-rich motion control", SIGGRAPH): the
whole-body controller of :mod:`sim.control.controller` is good for a step or two, but a walk
is chaotic, and a small error in one stance becomes a fall three steps later. So the reference
is followed window by window (:attr:`SearchSettings.window_s`); from each of the
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
:class:`SearchSettings` and squared. A fallen or lost state (:mod:`sim.control.falls`), or
one where MuJoCo met a diverging acceleration (:meth:`Controller.unstable`), costs infinity.

Shapes: ``T`` reference frames, ``nq``/``nu`` MuJoCo sizes, ``W`` windows.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from tqdm import tqdm

from avatarsim.avatar_models.body17 import BODY17
from avatarsim.sim.control.controller import Controller, ControlResult, Progress
from avatarsim.sim.control.falls import HEAD, fallen, tilt_deg
from avatarsim.sim.control.reference import Reference
from avatarsim.sim.control.settings import ControlSettings
from avatarsim.sim.soles import subtree_mask, thigh_bodies

PELVIS = BODY17.index("pelvis")
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
        retry_factor, max_backtracks: what is done when every sample falls (:func:`search`).
        budget: seconds simulated (samples, look-aheads, retries) per second of reference at
            most; past it the search gives up, incomplete. A walk that is followed takes about
            100 (3 s built-in walk: 15 windows x 48 samples x 0.4 s); a clip the controller
            cannot follow (Bandai run_normal_001: the plain controller falls at 0.4 s)
            backtracks without end, over 10 minutes for 3 s, without one.
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
class SearchResult:
    """The result of :func:`search`.

    Attributes:
        result: the control run of the best path.
        offsets: ``(W, nu)`` its target offset in each window (radians; zeros where the
            plain controller's targets won), for :func:`replay`.
        window_steps: simulation steps per window.
        simulated_s: seconds simulated in all, samples included (the search's cost).
        completed: whether the path reaches the reference's end; ``False`` when the search
            gave up: every sample fell, retries and backtracks exhausted (``result`` is the
            path that fell last), or the budget was spent (``result`` is the best path that
            got furthest, upright); either is shorter than the reference.
    """

    result: ControlResult
    offsets: np.ndarray
    window_steps: int
    simulated_s: float
    completed: bool = True


@dataclass(frozen=True)
class Node:
    """A simulated state on a search path: its cost, MuJoCo's state (``mj_getState``), the
    controller's state, and the target offsets ``(nu,)`` of the windows that led to it."""

    cost: float
    state: np.ndarray
    progress: Progress
    offsets: tuple[np.ndarray, ...]


@dataclass(frozen=True)
class Beam:
    """The states kept after a window, best first, and the beam they grew from: the search's
    stack of windows, which backtracking walks down without changing it.

    Attributes:
        nodes: the kept states, cost ascending.
        before: the beam of the window before (``None`` for the start).
        windows: windows simulated to get here (0 for the start).
    """

    nodes: list[Node]
    before: Beam | None = None
    windows: int = 0

    @property
    def best(self) -> Node:
        return self.nodes[0]

    def then(self, nodes: list[Node]) -> Beam:
        """The beam of the next window, ``nodes`` kept."""
        return Beam(nodes, self, self.windows + 1)

    def back(self, windows: int) -> Beam:
        """The beam ``windows`` windows earlier, or the start's."""
        beam = self
        while beam.before is not None and beam.windows > self.windows - windows:
            beam = beam.before
        return beam


def state_cost(
    controller: Controller, ref: Reference, progress: Progress, settings: SearchSettings
) -> float:
    """Cost of the controller's current state against the reference at ``progress.clock``
    (module docstring); infinity once fallen."""
    d = controller.data
    point = ref.at(progress.clock)
    q_ref, sites = ref.frame_qpos(point.frame), ref.sites_at(point.frame)
    now = d.site_xpos[controller.body.sites]
    unstable = controller.unstable()
    if fallen(controller.settings, d.qpos[None], q_ref[None], now[None], sites[None], unstable)[0]:
        return np.inf
    capture = np.linalg.norm(controller.capture_error(q_ref, point.com))
    tilt = tilt_deg(d.qpos[None], q_ref[None])[0]
    head = abs(now[HEAD, 2] - sites[HEAD, 2])
    pelvis = d.site_xpos[controller.body.sites[PELVIS]]
    pose = np.linalg.norm((now - pelvis) - (sites - sites[PELVIS]), axis=1).mean()
    # Roll and pitch rates of the root (its local x, y), which the capture point (linear
    # momentum) does not see: a body upright now but rotating fast falls a window later.
    spin = np.degrees(np.linalg.norm(d.qvel[3:5] - point.qvel[3:5]))
    return float(
        (capture / settings.capture_scale_m) ** 2
        + (tilt / settings.tilt_scale_deg) ** 2
        + (spin / settings.spin_scale_deg_s) ** 2
        + (head / settings.head_scale_m) ** 2
        + (pose / settings.pose_scale_m) ** 2
    )


class BeamSearch:
    """The search of :func:`search` for one reference: it samples windows and counts the
    steps it simulated (:attr:`simulated`)."""

    def __init__(self, controller: Controller, ref: Reference, settings: SearchSettings):
        self.controller, self.ref, self.settings = controller, ref, settings
        m = controller.model
        self.rng = np.random.default_rng(settings.seed)
        leg = subtree_mask(m, thigh_bodies(m))[m.jnt_bodyid[m.actuator_trnid[:, 0]]]
        self.sigma = np.where(leg, settings.sigma_leg_rad, settings.sigma_rad)
        self.window = max(1, int(round(settings.window_s / m.opt.timestep)))
        self.lookahead = int(round(settings.lookahead_s / m.opt.timestep))
        self.simulated = 0

    def snapshot(self) -> np.ndarray:
        """MuJoCo's current state (``mj_getState``)."""
        m = self.controller.model
        state = np.empty(mujoco.mj_stateSize(m, STATE))
        mujoco.mj_getState(m, self.controller.data, state, STATE)
        return state

    def start(self) -> Beam:
        """The beam of the reference's first frame."""
        progress = self.controller.start(self.ref)
        return Beam([Node(0.0, self.snapshot(), progress, ())])

    def next_window(self, beam: Beam) -> list[Node]:
        """The end states of the next window from every state of ``beam``, cost ascending;
        sampled again :attr:`SearchSettings.retry_factor` times as often when all fell."""
        children = self.expand(beam, self.settings.samples)
        if np.isfinite(children[0].cost):
            return children
        return self.expand(beam, self.settings.samples * self.settings.retry_factor)

    def expand(self, beam: Beam, samples: int) -> list[Node]:
        """``samples`` simulations of the next window from each state of ``beam`` (the first
        without an offset), cost ascending."""
        controller, ref, settings = self.controller, self.ref, self.settings
        nu = controller.model.nu
        children = []
        for node in beam.nodes:
            for sample in range(samples):
                offset = np.zeros(nu) if sample == 0 else self.rng.normal(0.0, self.sigma)
                controller.restore(node.state, STATE)
                progress = controller.advance(ref, node.progress, self.window, offset)
                self.simulated += progress.step - node.progress.step
                state = self.snapshot()
                cost = state_cost(controller, ref, progress, settings)
                if np.isfinite(cost) and settings.lookahead_s > 0:
                    # Judged where the plain controller takes it next: a state that is fine
                    # now but falls a moment later is not kept.
                    ahead = controller.advance(ref, progress, self.lookahead, np.zeros(nu))
                    self.simulated += ahead.step - progress.step
                    cost = max(cost, state_cost(controller, ref, ahead, settings))
                children.append(Node(cost, state, progress, node.offsets + (offset,)))
        children.sort(key=lambda c: c.cost)
        return children


def search(
    model: mujoco.MjModel,
    qpos_ref: np.ndarray,
    fps: float,
    settings: ControlSettings | None = None,
    search_settings: SearchSettings | None = None,
    progress_bar: bool = False,
) -> SearchResult:
    """Follow ``qpos_ref (T, nq)`` at ``fps`` by beam search (module docstring) with a
    :class:`~sim.control.controller.Controller` on ``model``. Costs about ``samples x beam``
    plain control runs.

    When every sample of a window falls, the window is sampled again with
    :attr:`SearchSettings.retry_factor` times as many samples; when those fall too, the search
    steps back one window (two after a second failure in a row, and so on) and samples from
    there again (at most :attr:`SearchSettings.max_backtracks` times in all). If nothing
    survives even then, the path that fell last is returned (its result says when it fell).
    Past :attr:`SearchSettings.budget` the search stops with the best path that got
    furthest, upright but short of the reference's end."""
    search_settings = search_settings or SearchSettings()
    controller = Controller(model, settings)
    ref = controller.reference(qpos_ref, fps)
    beam_search = BeamSearch(controller, ref, search_settings)
    beam = beam_search.start()
    total = controller.steps_of(ref)
    bar = tqdm(total=total, unit="step", disable=not progress_bar, leave=False)
    budget_steps = search_settings.budget * total
    backtracks, step_back = 0, 1  # backtracks so far; how far the next one goes
    last_fallen = deepest = beam.best  # deepest: the best state furthest along
    over_budget = False
    while not controller.finished(ref, beam.best.progress):
        if beam_search.simulated > budget_steps:
            over_budget = True
            break
        children = beam_search.next_window(beam)
        if not np.isfinite(children[0].cost):
            last_fallen = children[0]
            if backtracks >= search_settings.max_backtracks or beam.before is None:
                break
            # The fall may have been decided several windows back: each failure in a row
            # steps back one window further.
            backtracks += 1
            beam = beam.back(step_back)
            step_back += 1
            continue
        beam = beam.then([c for c in children if np.isfinite(c.cost)][: search_settings.beam])
        if beam.best.progress.step > deepest.progress.step:
            step_back, deepest = 1, beam.best
        bar.update(beam.best.progress.step - bar.n)
    bar.close()
    completed = controller.finished(ref, beam.best.progress)
    best = beam.best if completed else deepest if over_budget else last_fallen
    return SearchResult(
        result=controller.result(ref, best.progress.recording),
        offsets=np.array(best.offsets).reshape(-1, model.nu),
        window_steps=beam_search.window,
        simulated_s=beam_search.simulated * model.opt.timestep,
        completed=completed,
    )


def replay(
    controller: Controller, qpos_ref: np.ndarray, fps: float, offsets: np.ndarray, window_steps: int
) -> ControlResult:
    """Follow ``qpos_ref`` again with ``controller`` (a fresh one, same model and settings as
    the search's) plus the target ``offsets (W, nu)`` the search found, one per window of
    ``window_steps``: one uninterrupted simulation, which reproduces the search's result
    (MuJoCo is deterministic)."""
    ref = controller.reference(qpos_ref, fps)
    progress = controller.start(ref)
    for offset in offsets:
        progress = controller.advance(ref, progress, window_steps, offset)
    return controller.result(ref, progress.recording)
