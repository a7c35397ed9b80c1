"""The physics-control variant of the body's model, derived from its spec."""

from __future__ import annotations

import copy

import mujoco
import numpy as np
import pytest

from avatarsim.avatar_models.body import build_body, control_spec
from avatarsim.avatar_models.rigs import load_rig

BODY_LEVEL = ("body_contype", "body_conaffinity")
"""Per-body unions of the geoms' contact bits, which MuJoCo derives when compiling; editing a
compiled model's geom bits leaves them stale (they only prune body pairs before the geom
test, so contacts are the same)."""


def _edited_copy(model: mujoco.MjModel) -> mujoco.MjModel:
    """The physics-control variant as the tracker used to make it: a compiled model's copy
    with motors and floor-only contacts."""
    out = copy.copy(model)
    out.actuator_gainprm[:] = 0.0
    out.actuator_gainprm[:, 0] = 1.0
    out.actuator_biasprm[:] = 0.0
    out.actuator_ctrllimited[:] = 0
    world = out.geom_bodyid == 0
    out.geom_contype[:] = np.where(world, 0, 1)
    out.geom_conaffinity[:] = np.where(world, 1, 0)
    return out


def _arrays(model: mujoco.MjModel) -> dict[str, np.ndarray]:
    return {
        n: v
        for n in dir(model)
        if not n.startswith("_") and isinstance(v := getattr(model, n), np.ndarray)
    }


@pytest.mark.parametrize("rig", ("avatar", "cmu"))
def test_control_spec_compiles_to_the_edited_model(rig):
    body = build_body(load_rig(rig).skeleton)
    derived = _arrays(control_spec(body.spec).compile())
    edited = _arrays(_edited_copy(body.model))
    differing = [n for n in derived if not np.array_equal(derived[n], edited[n], equal_nan=True)]
    assert set(differing) <= set(BODY_LEVEL)
    # The derived body bits are the union of each body's geoms': world 0/1, the body 1/0
    # (a body without geoms 0/0).
    model = control_spec(body.spec).compile()
    assert model.body_contype[0] == 0 and model.body_conaffinity[0] == 1
    solid = np.isin(np.arange(1, model.nbody), model.geom_bodyid)
    assert np.array_equal(model.body_contype[1:], solid.astype(int))
    assert np.all(model.body_conaffinity[1:] == 0)


def test_control_spec_leaves_the_body_spec_alone():
    body = build_body(load_rig("avatar").skeleton)
    control_spec(body.spec).compile()
    model = body.spec.compile()
    assert np.all(model.actuator_ctrllimited == 1) and np.all(model.geom_conaffinity == 1)


def test_control_model_simulates_like_the_edited_copy():
    """Same torques, same contacts: the two variants step bit for bit alike."""
    body = build_body(load_rig("avatar").skeleton)
    variants = (_edited_copy(body.model), control_spec(body.spec).compile())
    torques = np.random.default_rng(0).normal(scale=20.0, size=(500, body.model.nu))
    paths = []
    for model in variants:
        data = mujoco.MjData(model)
        path = []
        for tau in torques:  # MuJoCo steps one state per call
            data.ctrl[:] = tau
            mujoco.mj_step(model, data)
            path.append((data.qpos.copy(), data.ncon))
        paths.append(path)
    assert sum(n for _, n in paths[0]) > 0  # the feet touch the floor
    for (q0, n0), (q1, n1) in zip(*paths, strict=True):
        assert n0 == n1 and np.array_equal(q0, q1)
