"""The whole-body QP: the torques a body held leaning forward needs are what statics demands,
and only sole corners on the floor offer contact forces."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.generator import generate, sample_subject
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.sim.control.controller import Controller, ControlResult, control
from avatarsim.sim.control.model import control_model
from avatarsim.sim.soles import foot_bodies


def _leaning(body, degrees: float, frames: int = 61) -> Motion:
    """The rest pose leaning ``degrees`` forward about the ankles, feet flat where they stood
    (the root turned about +Y, each foot turned back by as much)."""
    sk = body.skeleton
    rot = np.zeros((frames, sk.n_joints, 4))
    rot[..., 0] = 1.0
    root_rest = np.array([0.0, 0.0, body.root_height])
    rest = Motion(sk, 30.0, np.tile(root_rest, (frames, 1)), rot.copy())
    feet = foot_bodies(control_model(body.spec))
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


def ankle_balance(body, degrees: float) -> tuple[ControlResult, dict[int, tuple[float, float]]]:
    """Hold ``body`` leaning ``degrees`` forward; the result and, at frames 40, 50 and 60, the
    (demanded, supplied) moment about the ankle line (N m): the weight of the body without its
    feet about that line, and the ankle actuators' torques about it."""
    model = control_model(body.spec)
    result = control(model, body.qpos_from_motion(_leaning(body, degrees)), 30.0)
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


def test_contacts_are_the_sole_corners_on_the_floor():
    """Standing flat, 1 mm into the floor: the 4 bottom corners of every sole box touch, 4
    pyramid edges each; lifted 10 cm: no contact is offered."""
    model = control_model(build_body(load_rig("avatar").skeleton).spec)
    controller = Controller(model)
    d = controller.data
    d.qpos[:] = controller.model.qpos0  # standing on the floor
    d.qpos[2] -= 0.001
    mujoco.mj_forward(controller.model, d)
    jc, je = controller.qp.contacts()
    boxes = controller.body.sole_geoms.size
    assert jc.shape == (3 * 4 * boxes, model.nv) and je.shape == (model.nv, 4 * 4 * boxes)
    d.qpos[2] += 0.1
    mujoco.mj_forward(controller.model, d)
    jc, je = controller.qp.contacts()
    assert jc.shape[0] == 0 and je.shape[1] == 0
