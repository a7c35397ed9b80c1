"""The search: its walk is one plain simulation with chosen targets (replayed exactly,
nothing on the root), the cost sees falls, it stops at its budget, backtracks stay within the
windows simulated, and walks last 10 s."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.sim.control.controller import Controller
from avatarsim.sim.control.model import control_model
from avatarsim.sim.control.reference import looped
from avatarsim.sim.control.search import Beam, Node, SearchSettings, replay, search, state_cost
from tests.sim.control.test_controller import BANDAI_WALK, RootWatch, summary_line


@pytest.fixture(scope="module")
def body():
    return build_body(load_rig("avatar").skeleton)


def test_search_walks_and_its_path_replays_exactly_without_root_forces(body):
    walk = generate("walk", duration_s=3.0, fps=30.0, seed=0)
    qpos = body.qpos_from_motion(walk)
    searched = search(control_model(body.spec), qpos, walk.fps)
    assert not searched.result.fell, searched.result.summary()
    assert searched.offsets.shape == (15, control_model(body.spec).nu)  # 3 s in 0.2 s windows
    assert np.any(searched.offsets)  # some window chose a sampled offset
    assert searched.simulated_s >= 2 * 8 * 3.0  # 8 samples per state, each with a look-ahead
    again = replay(
        RootWatch(control_model(body.spec)), qpos, walk.fps, searched.offsets, searched.window_steps
    )
    np.testing.assert_array_equal(again.qpos, searched.result.qpos)


def test_cost_is_zero_on_the_reference_and_infinite_once_fallen(body):
    walk = generate("walk", duration_s=1.0, fps=30.0, seed=0)
    qpos = body.qpos_from_motion(walk)
    controller = Controller(control_model(body.spec))
    ref = controller.reference(qpos, walk.fps)
    progress = controller.start(ref)  # the humanoid is on the reference's first frame
    settings = SearchSettings()
    assert state_cost(controller, ref, progress, settings) < 0.01  # smoothed reference velocity
    d = controller.data
    d.qpos[3:7] = [np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0]  # lying on its side
    d.qpos[2] = 0.2
    mujoco.mj_forward(controller.model, d)
    assert state_cost(controller, ref, progress, settings) == np.inf


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_searched_walk_10_s_without_falling(body, seed):
    walk = generate("walk", duration_s=10.0, fps=30.0, seed=seed)
    searched = search(control_model(body.spec), body.qpos_from_motion(walk), walk.fps)
    summary_line(f"searched builtin walk seed {seed}", searched.result)
    assert not searched.result.fell


@pytest.mark.slow
@pytest.mark.mocap
def test_searched_bandai_walk_10_s_without_falling(mocap_dir):
    from avatarsim.avatar_models.formats import load_motion
    from avatarsim.sim.retarget import retarget

    walk = retarget(load_motion(mocap_dir / BANDAI_WALK), level_feet=True)
    qpos = looped(walk.qpos, walk.motion.fps, 10.0)
    model = control_model(build_body(walk.motion.skeleton).spec)
    searched = search(model, qpos, walk.motion.fps)
    summary_line("searched bandai walk", searched.result)
    assert not searched.result.fell


def test_search_stops_at_its_budget_upright_and_incomplete(body):
    """A search that cannot finish within its budget (simulated seconds per second of
    reference) gives up with its best path so far, which has not fallen. With a budget of 5:
    the first window costs 8 samples x 0.4 s (window + look-ahead) = 3.2 s, the second
    6 x 8 x 0.4 = 19.2 s, which spends 1 s of reference's 5 s; the third never starts."""
    walk = generate("walk", duration_s=1.0, fps=30.0, seed=0)
    searched = search(
        control_model(body.spec),
        body.qpos_from_motion(walk),
        walk.fps,
        search_settings=SearchSettings(budget=5.0),
    )
    assert not searched.completed and not searched.result.fell
    assert searched.offsets.shape[0] == 2  # two windows of 0.2 s
    assert searched.simulated_s == pytest.approx(3.2 + 19.2, abs=0.05)


def test_backtracking_steps_back_whole_windows_and_never_past_the_start():
    """A beam after 3 windows steps back 1 window to the beam of window 2, 2 to that of
    window 1; 5 to the start, which it never leaves."""
    start = Beam([Node(0.0, np.zeros(1), None, ())])
    beams = [start]
    for _ in range(3):
        beams.append(beams[-1].then(list(beams[-1].nodes)))
    top = beams[-1]
    assert top.windows == 3
    assert top.back(1) is beams[2] and top.back(2) is beams[1]
    assert top.back(5) is start and start.back(1) is start
