"""The control model: motors, floor-only collisions, the caller's model unchanged; a model
the controller cannot drive is refused."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from avatar_models.body import build_body
from avatar_models.body.ik import humanoid_model
from avatar_models.errors import MotionValueError
from avatar_models.rigs import load_rig
from sim.control.model import BodyIndices, control_model


@pytest.fixture(scope="module")
def model():
    return humanoid_model(build_body(load_rig("avatar").skeleton))


def test_control_model_has_motors_and_floor_only_contacts(model):
    before = (model.actuator_gainprm.copy(), model.geom_contype.copy())
    controlled = control_model(model)
    np.testing.assert_array_equal(model.actuator_gainprm, before[0])  # the caller's model
    np.testing.assert_array_equal(model.geom_contype, before[1])
    data = mujoco.MjData(controlled)
    data.ctrl[:] = 7.0
    mujoco.mj_forward(controlled, data)
    np.testing.assert_array_equal(data.actuator_force, 7.0)  # ctrl is the torque, unclamped
    world = controlled.geom_bodyid == 0
    body_pairs = controlled.geom_contype[~world][:, None] & controlled.geom_conaffinity[~world]
    assert not body_pairs.any()  # body geoms never collide with each other
    assert (controlled.geom_conaffinity[world] & controlled.geom_contype[~world][:, None]).all()


def test_body_indices_find_feet_hips_and_soles(model):
    body = BodyIndices.of(control_model(model))
    assert body.sites.shape == (17,) and (body.sites >= 0).all()
    assert len(body.feet) == 2 and len(body.hip_dof) == 2
    assert body.sole_corners.shape == (body.sole_geoms.size, 8, 3)
    for normal in body.sole_normal:
        assert np.linalg.norm(normal) == pytest.approx(1.0)


def test_a_model_with_an_actuated_root_is_refused():
    spec = mujoco.MjSpec.from_string(
        '<mujoco><worldbody><body><freejoint name="root"/><geom size="0.1"/></body>'
        '</worldbody><actuator><motor joint="root"/></actuator></mujoco>'
    )
    with pytest.raises(MotionValueError, match="no actuator on the root"):
        control_model(spec.compile())
