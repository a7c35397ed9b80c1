"""The one motion-to-humanoid path (:func:`sim.humanoid.humanoid_for`) on every kind of rig."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.measure import standing_height
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.sim.humanoid import humanoid_for
from avatarsim.sim.replay import replay_kinematic

BANDAI_WALK = "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh"


def _site_positions(h) -> np.ndarray:
    """``(T, 17, 3)`` MuJoCo's body17 sites over the humanoid's qpos."""
    data = mujoco.MjData(h.model)
    ids = [h.model.site(n).id for n in BODY17]
    out = np.empty((h.qpos.shape[0], len(BODY17), 3))
    for t, q in enumerate(h.qpos):  # MuJoCo evaluates one configuration per call
        data.qpos[:] = q
        mujoco.mj_kinematics(h.model, data)
        out[t] = data.site_xpos[ids]
    return out


def test_own_rig_is_exact_and_not_retargeted():
    walk = generate("walk", duration_s=0.5)
    h = humanoid_for(walk)
    assert not h.retargeted and h.motion is walk and np.all(h.residual_cm == 0)
    # MuJoCo's bodies at the motion's own FK: the qpos is exact.
    trace = replay_kinematic(h.model, h.qpos)
    pelvis = h.model.body(walk.skeleton.names[0]).id
    assert np.allclose(trace.body_pos[:, pelvis], walk.global_positions()[:, 0], atol=1e-9)
    # The model is the body's, compiled once from its spec; the MJCF is that spec's text.
    assert h.model is h.body.model and h.spec is h.body.spec
    assert h.model.nq == h.qpos.shape[1] and "<mujoco" in h.mjcf
    # The control variant is compiled anew: motors, and the shared model is left as it is.
    control = h.control_model()
    assert control is not h.model and not control.actuator_ctrllimited.any()
    assert h.model.actuator_ctrllimited.all()
    assert h.for_control() is h  # own feet: nothing to level


def test_height_scales_motion_and_body_together():
    walk = generate("walk", duration_s=0.5)
    h = humanoid_for(walk, height_m=1.5)
    assert standing_height(h.source) == pytest.approx(1.5, abs=1e-6)
    sites = _site_positions(h)
    assert np.allclose(sites, body17_positions(h.source), atol=1e-6)


@pytest.mark.parametrize("height", [0.0, -1.0, np.inf, 5.0])
def test_absurd_height_is_refused(height):
    with pytest.raises(MotionValueError, match="height"):
        humanoid_for(generate("walk", duration_s=0.2), height_m=height)


@pytest.mark.mocap
def test_cmu_keeps_its_own_rig(mocap_dir):
    motion = load_motion(mocap_dir / "cmu" / "09_01.bvh")[:30]
    h = humanoid_for(motion)
    assert h.body.rig.name == "cmu" and not h.retargeted
    assert np.allclose(_site_positions(h), body17_positions(motion), atol=1e-6)


@pytest.mark.mocap
def test_bandai_is_retargeted_once_and_levelled_on_the_same_model(mocap_dir):
    motion = load_motion(mocap_dir / BANDAI_WALK)[:40]
    h = humanoid_for(motion)
    assert h.retargeted and h.body.rig.name == "avatar"
    # The residual is what MuJoCo's sites say: mean body17 distance to the source's joints.
    measured = 100 * np.linalg.norm(_site_positions(h) - body17_positions(motion), axis=-1)
    assert np.allclose(h.residual_cm, measured.mean(axis=1), atol=1e-6)
    assert h.residual_cm.mean() < 1.0
    levelled = h.for_control()
    assert levelled.levelled and levelled.model is h.model and levelled.body is h.body
    assert levelled.for_control() is levelled


def test_a_subject_label_is_not_a_subject_record():
    """Library clips carry ``meta["subject"]`` as a label; only the generator's is a record."""
    walk = generate("walk", duration_s=0.3)
    labelled = walk.replace(meta={**walk.meta, "subject": "S01"})
    assert humanoid_for(labelled).body.mass_kg == 75.0
    scaled = humanoid_for(walk, height_m=1.9).source
    assert scaled.meta["subject"]["height_m"] == 1.9
