"""The controller: the root is never actuated, nothing but the floor holds the body up,
standing holds, the first second of a walk is followed, an open loop or a diverging
simulation falls, bad references are refused."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.generator import generate, sample_subject
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.sim.control.controller import Controller, ControlResult, control
from avatarsim.sim.control.model import control_model
from avatarsim.sim.control.settings import ControlSettings

BANDAI_WALK = "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh"


@pytest.fixture(scope="module")
def body():
    return build_body(load_rig("avatar").skeleton)


class RootWatch(Controller):
    """A controller that checks, before every QP, that nothing pushes the root."""

    def __init__(self, model: mujoco.MjModel, settings: ControlSettings | None = None):
        super().__init__(model, settings)
        torques = self.qp.torques

        def watched(*args):
            d = self.data
            assert not d.xfrc_applied.any()
            assert not d.qfrc_applied.any()
            assert not d.qfrc_actuator[:6].any()  # the actuators move hinges only
            return torques(*args)

        self.qp.torques = watched


def summary_line(name: str, result: ControlResult) -> None:
    s = result.summary()
    print(name, {k: s[k] for k in ("fell", "fall_time_s", "body17_err_cm_mean")})


def test_root_is_unactuated_while_walking(body):
    model = control_model(body.spec)
    free = np.flatnonzero(model.jnt_type == 0)
    assert free.tolist() == [0]
    assert not np.isin(model.actuator_trnid[:, 0], free).any()
    walk = generate("walk", duration_s=0.5, fps=30.0)
    controller = RootWatch(model)
    result = controller.run(body.qpos_from_motion(walk), walk.fps)
    assert not controller.data.xfrc_applied.any() and not controller.data.qfrc_applied.any()
    assert result.torque.any()


def _floor_force_on_body(model, data) -> np.ndarray:
    """``(3,)`` world force of every active floor contact on the body (``mj_contactForce``
    gives it in the contact frame, whose rows are the normal and tangents, acting on geom2)."""
    total, force = np.zeros(3), np.zeros(6)
    for i, contact in enumerate(data.contact):
        if contact.efc_address < 0:  # within the margin, not a constraint
            continue
        mujoco.mj_contactForce(model, data, i, force)
        world = contact.frame.reshape(3, 3).T @ force[:3]
        total += world if model.geom_bodyid[contact.geom1] == 0 else -world
    return total


def newton_residual_bw(body, seconds: float, push_bw: float = 0.0, seed: int = 0) -> np.ndarray:
    """``(steps - 1,)`` |d(m v_com)/dt - (floor forces + m g)| / body weight at each step of a
    built-in walk the controller follows. ``push_bw`` lifts the root by that share of the body
    weight through ``xfrc_applied`` (a hidden force the residual must show)."""
    model = control_model(body.spec)
    walk = generate("walk", duration_s=seconds, fps=30.0, seed=seed)
    controller = Controller(model)
    ref = controller.reference(body.qpos_from_motion(walk), walk.fps)
    progress = controller.start(ref)
    data, probe = controller.data, mujoco.MjData(model)
    mass = model.body_subtreemass[0]
    data.xfrc_applied[1, 2] = push_bw * mass * 9.81
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    state = np.empty(mujoco.mj_stateSize(model, spec))
    forces, momenta = [], []
    while not controller.finished(ref, progress):
        mujoco.mj_getState(model, data, state, spec)
        progress = controller.advance(ref, progress, 1)
        # The state this step started from, with the torques it used, evaluated again: its
        # contact forces are the ones the step integrated.
        mujoco.mj_setState(model, probe, state, spec)
        probe.ctrl[:] = data.ctrl
        mujoco.mj_forward(model, probe)
        mujoco.mj_subtreeVel(model, probe)
        forces.append(_floor_force_on_body(model, probe))
        momenta.append(mass * probe.subtree_linvel[0])
    assert not controller.result(ref, progress.recording).fell
    rate = np.diff(momenta, axis=0) / model.opt.timestep
    expected = np.array(forces[:-1]) + mass * np.array([0.0, 0.0, -9.81])
    return np.linalg.norm(rate - expected, axis=1) / (mass * 9.81)


def test_nothing_but_the_floor_and_gravity_holds_the_body_up(body):
    """Newton for the whole body during a 2 s controlled walk: the rate of its linear momentum
    (total mass x ``subtree_linvel`` of the world, finite-differenced over one 2 ms step)
    equals the floor's contact forces plus m g. Anything else holding the body up (a weld,
    gravity compensation, a root actuator, damping or stiffness on the root, changed
    gravity, fluid forces) leaves a residual of its size.

    Measured (seeds 0-3, ``python -m tests.measurements.newton_residual 0 1 2 3``): residual mean
    0.5-0.6 %, max 2.0-2.8 % of body weight per step (finite differencing across the
    implicit integrator's step), while floor forces reach 4 body weights. Bounds: twice the
    worst measured. A hidden lift of 10 % of body weight on the root is caught."""
    model = control_model(body.spec)
    assert model.neq == 0  # no equality constraint (weld, connect) to the world
    assert not model.body_gravcomp.any()
    np.testing.assert_array_equal(model.opt.gravity, [0.0, 0.0, -9.81])
    assert model.opt.density == 0 and model.opt.viscosity == 0 and not model.opt.wind.any()
    assert model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE and model.jnt_stiffness[0] == 0
    root = slice(0, 6)
    for field in (model.dof_damping, model.dof_armature, model.dof_frictionloss):
        assert not field[root].any()
    residual = newton_residual_bw(body, 2.0)
    assert residual.mean() < 0.012 and residual.max() < 0.06, (residual.mean(), residual.max())
    pushed = newton_residual_bw(body, 0.5, push_bw=0.1)
    assert np.median(pushed) > 0.08


def test_standing_still_holds_for_2_s(body):
    model = control_model(body.spec)
    result = control(model, np.tile(model.qpos0, (61, 1)), 30.0)
    assert not result.fell
    assert result.body17_error.mean() < 0.01  # metres


# Walks the plain controller was measured on: (subject index or None for the default, seed).
# Subjects: sample_subject(default_rng(123)) drawn 8 times in order (0: 1.81 m, 5: 1.63 m).
FIRST_SECOND_WALKS = [(None, 7), (0, 0), (5, 5)]


@pytest.mark.parametrize(("subject", "seed"), FIRST_SECOND_WALKS, ids=["seed7", "tall", "short"])
def test_plain_controller_follows_the_first_second_of_a_walk(subject, seed):
    """On its own the controller does not reliably keep a 2 s walk. Measured over 16 walks
    of 2 s (seeds 0-7 on the default subject and on 8 sampled subjects, ``python -m
    tests.measurements.walk_spread``): 3 fell or were lost before 2 s (at 1.33, 1.9 and 2.0 s) and 6
    more were 30-42 cm from the reference at 2.0 s against the 0.5 m lost limit; at 1.5 s
    one was already 71 cm away. In the first 1.0 s none fell and the frame-wise mean body17
    distance never exceeded 9.2 cm (seed 7: 7.2, subject 0: 9.2, subject 5: 8.1). That is
    what is tested, on those three (the worst and the shortest-lived), bound 15 cm. Longer
    walks need the search of ``sim.control.search`` (tests/sim/control/test_search.py)."""
    rng = np.random.default_rng(123)
    people = [sample_subject(rng) for _ in range(8)]
    walk = generate("walk", None if subject is None else people[subject], 2.0, 30.0, seed)
    walk_body = build_body(walk.skeleton)
    controller = Controller(control_model(walk_body.spec))
    ref = controller.reference(walk_body.qpos_from_motion(walk), walk.fps)
    one_second = int(round(1.0 / controller.model.opt.timestep))
    progress = controller.advance(ref, controller.start(ref), one_second)
    result = controller.result(ref, progress.recording)
    assert result.qpos.shape[0] == 31
    assert not result.fell
    assert result.body17_error.mean(axis=1).max() < 0.15  # metres


def test_open_loop_body_falls_and_is_detected(body):
    """Torques computed once and never updated cannot balance a walk."""
    walk = generate("walk", duration_s=3.0, fps=30.0)
    blind = ControlSettings(control_period=10**9)
    result = control(control_model(body.spec), body.qpos_from_motion(walk), walk.fps, blind)
    assert result.fell and 0.0 < result.fall_time_s < 3.0


def test_bad_reference_is_refused(body):
    model = control_model(body.spec)
    with pytest.raises(MotionValueError, match="reference must"):
        control(model, np.full((3, model.nq), np.nan), 30.0)
    with pytest.raises(MotionValueError, match="at least 2 frames"):
        control(model, model.qpos0[None], 30.0)


def test_a_diverging_simulation_counts_as_a_fall(body):
    """Absurd gains make MuJoCo's accelerations diverge; it then resets the state to the rest
    pose and goes on, which must not pass for control."""
    walk = generate("walk", duration_s=1.0, fps=30.0)
    controller = Controller(control_model(body.spec), ControlSettings(kp=1e6, kd=2e3))
    result = controller.run(body.qpos_from_motion(walk), walk.fps)
    assert controller.unstable()
    assert result.fall_frame == 1


def test_a_run_advanced_in_pieces_equals_one_run(body):
    """The controller's state between calls of ``advance`` is all of it: a walk simulated in
    windows of 37 steps records exactly what one uninterrupted run records."""
    walk = generate("walk", duration_s=0.6, fps=30.0)
    qpos = body.qpos_from_motion(walk)
    whole = control(control_model(body.spec), qpos, walk.fps)
    controller = Controller(control_model(body.spec))
    ref = controller.reference(qpos, walk.fps)
    progress = controller.start(ref)
    while not controller.finished(ref, progress):
        progress = controller.advance(ref, progress, 37)
    pieces = controller.result(ref, progress.recording)
    np.testing.assert_array_equal(pieces.qpos, whole.qpos)
    np.testing.assert_array_equal(pieces.reference_frame, whole.reference_frame)
