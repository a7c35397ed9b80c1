"""The control model: compiled from the spec with motors and floor-only collisions, the
spec and its own model unchanged; a model the controller cannot drive is refused."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.sim.control.controller import Controller
from avatarsim.sim.control.model import BodyIndices, control_model, is_control_model


@pytest.fixture(scope="module")
def body():
    return build_body(load_rig("avatar").skeleton)


def test_control_model_has_motors_and_floor_only_contacts(body):
    model = body.model
    before = (model.actuator_gainprm.copy(), model.geom_contype.copy())
    controlled = control_model(body.spec)
    np.testing.assert_array_equal(model.actuator_gainprm, before[0])  # the body's own model
    np.testing.assert_array_equal(model.geom_contype, before[1])
    assert is_control_model(controlled) and not is_control_model(model)
    data = mujoco.MjData(controlled)
    data.ctrl[:] = 7.0
    mujoco.mj_forward(controlled, data)
    np.testing.assert_array_equal(data.actuator_force, 7.0)  # ctrl is the torque, unclamped
    world = controlled.geom_bodyid == 0
    body_pairs = controlled.geom_contype[~world][:, None] & controlled.geom_conaffinity[~world]
    assert not body_pairs.any()  # body geoms never collide with each other
    assert (controlled.geom_conaffinity[world] & controlled.geom_contype[~world][:, None]).all()


def test_the_controller_refuses_a_model_with_position_servos(body):
    with pytest.raises(MotionValueError, match="control variant"):
        Controller(body.model)


def test_body_indices_find_feet_hips_and_soles(body):
    indices = BodyIndices.of(control_model(body.spec))
    assert indices.sites.shape == (17,) and (indices.sites >= 0).all()
    assert len(indices.feet) == 2 and len(indices.hip_dof) == 2
    assert indices.sole_corners.shape == (indices.sole_geoms.size, 8, 3)
    for normal in indices.sole_normal:
        assert np.linalg.norm(normal) == pytest.approx(1.0)


def test_a_model_with_an_actuated_root_is_refused():
    spec = mujoco.MjSpec.from_string(
        '<mujoco><worldbody><body><freejoint name="root"/><geom size="0.1"/></body>'
        '</worldbody><actuator><motor joint="root"/></actuator></mujoco>'
    )
    with pytest.raises(MotionValueError, match="no actuator on the root"):
        control_model(spec)
