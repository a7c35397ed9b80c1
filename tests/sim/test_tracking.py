"""Physics tracking: the root is never actuated, standing holds, the walk is tracked, falls are
detected, looping a clip continues the walk."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from avatar_models import quat
from avatar_models.body import build_body
from avatar_models.body.ik import humanoid_model
from avatar_models.errors import MotionValueError
from avatar_models.generator import generate, sample_subject
from avatar_models.motion import Motion
from avatar_models.rigs import load_rig
from sim.soles import foot_bodies
from sim.tracking import Tracker, TrackingResult, TrackingSettings, looped, track

BANDAI_WALK = "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh"


@pytest.fixture(scope="module")
def body():
    return build_body(load_rig("avatar").skeleton)


class _RootWatch(Tracker):
    """A tracker that checks, before every simulation step, that nothing pushes the root."""

    def _torques(self, *args):
        d = self.data
        assert not d.xfrc_applied.any()
        assert not d.qfrc_applied.any()
        assert not d.qfrc_actuator[:6].any()  # the actuators move hinges only
        return super()._torques(*args)


def test_root_is_unactuated_while_walking(body):
    model = humanoid_model(body)
    free = np.flatnonzero(model.jnt_type == 0)
    assert free.tolist() == [0]
    assert not np.isin(model.actuator_trnid[:, 0], free).any()
    walk = generate("walk", duration_s=0.5, fps=30.0)
    tracker = _RootWatch(model)
    result = tracker.run(body.qpos_from_motion(walk), walk.fps)
    assert not tracker.data.xfrc_applied.any() and not tracker.data.qfrc_applied.any()
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


def _newton_residual_bw(body, seconds: float, push_bw: float = 0.0, seed: int = 0) -> np.ndarray:
    """``(steps - 1,)`` |d(m v_com)/dt - (floor forces + m g)| / body weight at each step of a
    tracked built-in walk. ``push_bw`` lifts the root by that share of the body weight through
    ``xfrc_applied`` (a hidden force the residual must show)."""
    model = humanoid_model(body)
    walk = generate("walk", duration_s=seconds, fps=30.0, seed=seed)
    tracker = Tracker(model)
    model = tracker.model  # the tracker's own copy: motors, floor-only contacts
    ref = tracker.reference(body.qpos_from_motion(walk), walk.fps)
    progress = tracker.start(ref)
    data, probe = tracker.data, mujoco.MjData(model)
    mass = model.body_subtreemass[0]
    data.xfrc_applied[1, 2] = push_bw * mass * 9.81
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    state = np.empty(mujoco.mj_stateSize(model, spec))
    forces, momenta = [], []
    while not tracker.finished(ref, progress):
        mujoco.mj_getState(model, data, state, spec)
        progress = tracker.advance(ref, progress, 1)
        # The state this step started from, with the torques it used, evaluated again: its
        # contact forces are the ones the step integrated.
        mujoco.mj_setState(model, probe, state, spec)
        probe.ctrl[:] = data.ctrl
        mujoco.mj_forward(model, probe)
        mujoco.mj_subtreeVel(model, probe)
        forces.append(_floor_force_on_body(model, probe))
        momenta.append(mass * probe.subtree_linvel[0])
    assert not tracker.result(ref, progress.frames).fell
    rate = np.diff(momenta, axis=0) / model.opt.timestep
    expected = np.array(forces[:-1]) + mass * np.array([0.0, 0.0, -9.81])
    return np.linalg.norm(rate - expected, axis=1) / (mass * 9.81)


def test_nothing_but_the_floor_and_gravity_holds_the_body_up(body):
    """Newton for the whole body during a 2 s tracked walk: the rate of its linear momentum
    (total mass x ``subtree_linvel`` of the world, finite-differenced over one 2 ms step)
    equals the floor's contact forces plus m g. Anything else holding the body up (a weld,
    gravity compensation, a root actuator, damping or stiffness on the root, changed
    gravity, fluid forces) leaves a residual of its size.

    Measured (seeds 0-3, ``python -m tests.measurements.newton_residual 0 1 2 3``): residual mean
    0.5-0.6 %, max 2.0-2.8 % of body weight per step (finite differencing across the
    implicit integrator's step), while floor forces reach 4 body weights. Bounds: twice the
    worst measured. A hidden lift of 10 % of body weight on the root is caught."""
    model = humanoid_model(body)
    assert model.neq == 0  # no equality constraint (weld, connect) to the world
    assert not model.body_gravcomp.any()
    np.testing.assert_array_equal(model.opt.gravity, [0.0, 0.0, -9.81])
    assert model.opt.density == 0 and model.opt.viscosity == 0 and not model.opt.wind.any()
    assert model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE and model.jnt_stiffness[0] == 0
    root = slice(0, 6)
    for field in (model.dof_damping, model.dof_armature, model.dof_frictionloss):
        assert not field[root].any()
    residual = _newton_residual_bw(body, 2.0)
    assert residual.mean() < 0.012 and residual.max() < 0.06, (residual.mean(), residual.max())
    pushed = _newton_residual_bw(body, 0.5, push_bw=0.1)
    assert np.median(pushed) > 0.08


def test_standing_still_holds_for_2_s(body):
    model = humanoid_model(body)
    result = track(model, np.tile(model.qpos0, (61, 1)), 30.0)
    assert not result.fell
    assert result.body17_error.mean() < 0.01  # metres


def _leaning(body, degrees: float, frames: int = 61) -> Motion:
    """The rest pose leaning ``degrees`` forward about the ankles, feet flat where they stood
    (the root turned about +Y, each foot turned back by as much)."""
    sk = body.skeleton
    rot = np.zeros((frames, sk.n_joints, 4))
    rot[..., 0] = 1.0
    root_rest = np.array([0.0, 0.0, body.root_height])
    rest = Motion(sk, 30.0, np.tile(root_rest, (frames, 1)), rot.copy())
    feet = foot_bodies(humanoid_model(body))
    foot_rest = rest.global_positions()[0, sk.index(feet[0])]
    lean = Rotation.from_euler("y", degrees, degrees=True)
    rot[:, 0] = quat.from_scipy(lean)
    for foot in feet:
        rot[:, sk.index(foot)] = quat.from_scipy(lean.inv())
    root = foot_rest - lean.apply(foot_rest - root_rest)
    return Motion(sk, 30.0, np.tile(root, (frames, 1)), rot)


@pytest.mark.parametrize("subject", [None, 0, 1], ids=["default", "sampled0", "sampled1"])
def test_ankle_torques_are_what_statics_demands_leaning_forward(subject):
    """Torques judged by statics, not by a size guess: a body held still leaning 4 degrees
    forward at the ankles. Everything above the feet is in equilibrium, so about the line
    through both ankle joints (where the ankle joint forces act, with no moment about it) the
    ankle actuators' torques balance the moment of its weight: sum tau_j (axis_j . u) =
    ((c - p_ankle) x (-W z)) . u, with c and W the centre of mass and weight of the body
    without its feet (from the model's kinematics, independent of the controller).

    Measured (default + sampled subjects, ``python -m tests.measurements.lean_statics``):
    demanded 42-52 Nm, supplied equal to within 0.01 Nm at frames 40-60. Bound: 2 % + 0.5 Nm
    for residual accelerations."""
    if subject is None:
        lean_body = build_body(load_rig("avatar").skeleton)
    else:
        rng = np.random.default_rng(5)
        people = [sample_subject(rng) for _ in range(2)]
        lean_body = build_body(generate("walk", people[subject], 0.1, 30.0).skeleton)
    result, moments = ankle_balance(lean_body, 4.0)
    assert not result.fell and result.body17_error[-1].mean() < 0.01
    for t, (demanded, supplied) in moments.items():
        assert abs(demanded) > 30.0  # the lean makes it a real load (N m)
        assert abs(supplied - demanded) < 0.02 * abs(demanded) + 0.5, (t, supplied, demanded)


def ankle_balance(body, degrees: float) -> tuple[TrackingResult, dict[int, tuple[float, float]]]:
    """Track ``body`` held leaning ``degrees`` forward; the result and, at frames 40, 50 and
    60, the (demanded, supplied) moment about the ankle line (N m): the weight of the body
    without its feet about that line, and the ankle actuators' torques about it."""
    model = humanoid_model(body)
    result = track(model, body.qpos_from_motion(_leaning(body, degrees)), 30.0)
    data = mujoco.MjData(model)
    feet = [model.body(name).id for name in foot_bodies(model)]
    at_ankle = [k for k, j in enumerate(model.actuator_trnid[:, 0]) if model.jnt_bodyid[j] in feet]
    mass, foot_mass = model.body_subtreemass[0], model.body_subtreemass[feet]
    moments = {}
    for t in (40, 50, 60):
        data.qpos[:] = result.qpos[t]
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        com = (mass * data.subtree_com[0] - foot_mass @ data.subtree_com[feet]) / (
            mass - foot_mass.sum()
        )
        weight = (mass - foot_mass.sum()) * 9.81
        left, right = (data.xanchor[model.body_jntadr[f]] for f in feet)
        u = (left - right) / np.linalg.norm(left - right)
        demanded = np.cross(com - left, [0.0, 0.0, -weight]) @ u
        axes = data.xaxis[model.actuator_trnid[at_ankle, 0]]
        moments[t] = (float(demanded), float(result.torque[t, at_ankle] @ (axes @ u)))
    return result, moments


# Walks the plain controller was measured on: (subject index or None for the default, seed).
# Subjects: sample_subject(default_rng(123)) drawn 8 times in order (0: 1.81 m, 5: 1.63 m).
FIRST_SECOND_WALKS = [(None, 7), (0, 0), (5, 5)]


@pytest.mark.parametrize(("subject", "seed"), FIRST_SECOND_WALKS, ids=["seed7", "tall", "short"])
def test_plain_controller_tracks_the_first_second_of_a_walk(subject, seed):
    """On its own the controller does not reliably keep a 2 s walk. Measured over 16 walks
    of 2 s (seeds 0-7 on the default subject and on 8 sampled subjects, ``python -m
    tests.measurements.walk_spread``): 3 fell or were lost before 2 s (at 1.33, 1.9 and 2.0 s) and 6
    more were 30-42 cm from the reference at 2.0 s against the 0.5 m lost limit; at 1.5 s
    one was already 71 cm away. In the first 1.0 s none fell and the frame-wise mean body17
    distance never exceeded 9.2 cm (seed 7: 7.2, subject 0: 9.2, subject 5: 8.1). That is
    what is tested, on those three (the worst and the shortest-lived), bound 15 cm. Longer
    walks need the search of ``sim.sampling`` (tests/sim/test_sampling.py)."""
    rng = np.random.default_rng(123)
    people = [sample_subject(rng) for _ in range(8)]
    walk = generate("walk", None if subject is None else people[subject], 2.0, 30.0, seed)
    walk_body = build_body(walk.skeleton)
    tracker = Tracker(humanoid_model(walk_body))
    ref = tracker.reference(walk_body.qpos_from_motion(walk), walk.fps)
    one_second = int(round(1.0 / tracker.model.opt.timestep))
    progress = tracker.advance(ref, tracker.start(ref), one_second)
    result = tracker.result(ref, progress.frames)
    assert result.qpos.shape[0] == 31
    assert not result.fell
    assert result.body17_error.mean(axis=1).max() < 0.15  # metres


def test_reference_clock_follows_the_capture_point(body):
    """A reference standing 5 cm ahead: the body leans after it, its capture point leads, so
    the adaptive clock plays the reference faster than real time; without clock feedback the
    reference plays at real time."""
    model = humanoid_model(body)
    ahead = np.tile(model.qpos0, (31, 1))
    ahead[1:, 0] += 0.05
    adaptive = track(model, ahead, 30.0).reference_frame
    fixed = track(humanoid_model(body), ahead, 30.0, TrackingSettings(clock_gain=0.0))
    step = model.opt.timestep * 30.0  # frames are sampled at the first step past them
    np.testing.assert_allclose(fixed.reference_frame, np.arange(31), atol=step + 1e-9)
    assert np.all(np.diff(adaptive[:20]) > 1.0)
    assert adaptive[-1] == 30.0  # the reference ended early and holds its last frame


def test_open_loop_body_falls_and_is_detected(body):
    """Torques computed once and never updated cannot balance a walk."""
    walk = generate("walk", duration_s=3.0, fps=30.0)
    blind = TrackingSettings(control_period=10**9)
    result = track(humanoid_model(body), body.qpos_from_motion(walk), walk.fps, blind)
    assert result.fell and 0.0 < result.fall_time_s < 3.0


def test_bad_reference_is_refused(body):
    model = humanoid_model(body)
    with pytest.raises(MotionValueError, match="reference must"):
        track(model, np.full((3, model.nq), np.nan), 30.0)
    with pytest.raises(MotionValueError, match="at least 2 frames"):
        track(model, model.qpos0[None], 30.0)
    with pytest.raises(MotionValueError, match="too short to loop"):
        looped(np.tile(model.qpos0, (2, 1)), 30.0, 5.0)


def test_looped_clip_continues_the_walk(body):
    """A 2 s walk looped to 5 s keeps moving forward at the clip's speed, without jumps."""
    walk = generate("walk", duration_s=2.0, fps=30.0)
    qpos = body.qpos_from_motion(walk)
    out = looped(qpos, walk.fps, 5.0)
    assert out.shape == (151, qpos.shape[1])
    np.testing.assert_array_equal(out[:24], qpos[:24])  # the clip plays first (cycle >= 0.8 s)
    step = np.linalg.norm(np.diff(out[:, :2], axis=0), axis=1)
    speed = np.linalg.norm(np.diff(qpos[:, :2], axis=0), axis=1)
    assert step.max() < 2.0 * speed.max()  # no seam jump
    assert out[-1, 0] > 2.3 * qpos[-1, 0]  # 5 s of walking go 2.5x as far as 2 s


def _summary_line(name, result):
    s = result.summary()
    print(name, {k: s[k] for k in ("fell", "fall_time_s", "body17_err_cm_mean")})


def test_a_diverging_simulation_counts_as_a_fall(body):
    """Absurd gains make MuJoCo's accelerations diverge; it then resets the state to the rest
    pose and goes on, which must not pass for tracking."""
    walk = generate("walk", duration_s=1.0, fps=30.0)
    tracker = Tracker(humanoid_model(body), TrackingSettings(kp=1e6, kd=2e3))
    result = tracker.run(body.qpos_from_motion(walk), walk.fps)
    assert tracker.unstable()
    assert result.fall_frame == 1


def test_a_body_left_behind_by_its_reference_is_lost(body):
    """The reference stands, then jumps 1 m sideways: the humanoid stays up but is lost
    (mean body17 distance over 0.5 m) from the jump on."""
    model = humanoid_model(body)
    jumped = np.tile(model.qpos0, (31, 1))
    jumped[15:, 1] += 1.0
    result = track(model, jumped, 30.0)
    assert result.fall_frame == 15
    assert result.body17_error[:15].mean() < 0.01
