"""The MuJoCo model of the body: loads, stands, replays motions exactly."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body import BodyDescription, BodyError, build_body, hinge_name
from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.rigs import load_rig

RIGS = ("body17", "avatar", "cmu")
DATA = Path(__file__).resolve().parents[1] / "data" / "mjcf"


def _model(body: BodyDescription) -> tuple[mujoco.MjModel, mujoco.MjData]:
    return body.model, mujoco.MjData(body.model)


def _random_motion(rig: str, frames: int, seed: int, max_angle: float) -> Motion:
    """Random local rotations up to ``max_angle`` radians about random axes."""
    sk = load_rig(rig).skeleton
    rng = np.random.default_rng(seed)
    axes = rng.normal(size=(frames, sk.n_joints, 3))
    angles = rng.uniform(-max_angle, max_angle, size=(frames, sk.n_joints))
    root = rng.normal(size=(frames, 3)) + [0.0, 0.0, 1.0]
    return Motion(sk, 30.0, root, quat.from_axis_angle(axes, angles))


@pytest.mark.parametrize("rig", RIGS)
def test_model_loads_with_limited_actuated_hinges(rig):
    body = build_body(load_rig(rig).skeleton)
    model, _ = _model(body)
    n_hinged = len(body.simulated_joints) - 1
    assert model.nq == 7 + 3 * n_hinged
    assert model.nu == 3 * n_hinged
    hinges = model.jnt_type == mujoco.mjtJoint.mjJNT_HINGE
    assert hinges.sum() == 3 * n_hinged and model.jnt_limited[hinges].all()
    assert model.body_subtreemass[1] == pytest.approx(75.0, rel=0.01)
    for name in BODY17:
        model.site(name)  # raises KeyError if absent
    for segment in body.segments:
        assert model.geom(segment.name).bodyid == model.body(body.skeleton.names[segment.body]).id
    assert model.ngeom == len(body.segments) + 1  # + floor


def test_actuator_gains_scale_with_body_mass():
    sk = load_rig("avatar").skeleton
    light, _ = _model(build_body(sk, mass_kg=60.0))
    heavy, _ = _model(build_body(sk, mass_kg=90.0))
    for joint in ("Bip01 L Foot", "Bip01 L Forearm", "Bip01 Neck"):
        name = hinge_name(joint, "y")
        ratio = heavy.actuator(name).gainprm[0] / light.actuator(name).gainprm[0]
        assert ratio == pytest.approx(1.5, rel=1e-6)
    # Legs carry the whole body, so the ankle is stiffer than the much lighter wrist.
    assert (
        light.actuator(hinge_name("Bip01 L Foot", "y")).gainprm[0]
        > 50 * light.actuator(hinge_name("Bip01 L Hand", "y")).gainprm[0]
    )


@pytest.mark.parametrize("rig", RIGS)
@pytest.mark.parametrize("foot", ["box", "capsule"])
def test_rest_pose_soles_touch_the_floor(rig, foot):
    body = build_body(load_rig(rig).skeleton, foot=foot)
    model, data = _model(body)
    mujoco.mj_forward(model, data)
    lowest = []
    for segment in body.segments:
        if segment.kind != "foot":
            continue
        g = model.geom(segment.name)
        pos, rot = data.geom_xpos[g.id], data.geom_xmat[g.id].reshape(3, 3)
        if foot == "box":
            corners = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
            lowest.append((pos + (corners * g.size) @ rot.T)[:, 2].min())
        else:  # capsule along its local z, half length size[1]
            ends = pos + np.outer([-1, 1], rot[:, 2] * g.size[1])
            lowest.append(ends[:, 2].min() - g.size[0])
    assert min(lowest) == pytest.approx(0.0, abs=0.002)


@pytest.mark.parametrize(
    ("rig", "foot"), [("body17", "box"), ("avatar", "box"), ("avatar", "capsule")]
)
def test_standing_pose_is_held_for_two_seconds(rig, foot):
    body = build_body(load_rig(rig).skeleton, foot=foot)
    model, data = _model(body)
    root = model.body(body.skeleton.names[0]).id
    floor = model.geom("floor").id
    start_height = body.root_height
    deepest, lowest_root, least_upright = 0.0, np.inf, 1.0
    for _ in range(int(2.0 / model.opt.timestep)):
        data.ctrl[:] = 0.0  # the rest pose
        mujoco.mj_step(model, data)
        lowest_root = min(lowest_root, data.xpos[root, 2])
        least_upright = min(least_upright, data.xmat[root].reshape(3, 3)[2, 2])
        for c in data.contact[: data.ncon]:
            if floor in (c.geom1, c.geom2):
                deepest = max(deepest, -c.dist)
    assert np.isfinite(data.qpos).all()
    assert least_upright > np.cos(np.radians(5.0))
    assert lowest_root > 0.97 * start_height
    assert deepest < 0.01


@pytest.mark.parametrize("rig", RIGS)
@pytest.mark.parametrize("max_angle", [0.6, np.pi])
def test_qpos_reproduces_global_positions(rig, max_angle):
    motion = _random_motion(rig, frames=20, seed=7, max_angle=max_angle)
    body = build_body(motion.skeleton)
    model, data = _model(body)
    qpos = body.qpos_from_motion(motion)
    assert qpos.shape == (motion.n_frames, model.nq)
    expected = motion.global_positions()
    body_ids = [model.body(motion.skeleton.names[j]).id for j in body.simulated_joints]
    body17 = load_rig(body.rig.name).body17_indices(motion.skeleton)
    site_ids = [model.site(name).id for name in BODY17]
    for t in range(motion.n_frames):
        data.qpos[:] = qpos[t]
        mujoco.mj_kinematics(model, data)
        np.testing.assert_allclose(
            data.xpos[body_ids], expected[t, body.simulated_joints], atol=1e-6
        )
        np.testing.assert_allclose(data.site_xpos[site_ids], expected[t, body17], atol=1e-6)


def test_qpos_hinge_angles_are_continuous_through_a_full_turn():
    sk = load_rig("avatar").skeleton
    turn = np.linspace(0.0, 4 * np.pi, 241)  # two turns of the first hinge of the left hip
    rot = np.tile(quat.IDENTITY, (turn.size, sk.n_joints, 1))
    hip = sk.index("Bip01 L Thigh")
    rot[:, hip] = quat.from_scipy(
        Rotation.from_euler("YXZ", np.c_[turn, 0.2 + 0 * turn, 0.1 + 0 * turn])
    )
    motion = Motion(sk, 60.0, np.tile([0.0, 0.0, 1.0], (turn.size, 1)), rot)
    body = build_body(sk)
    qpos = body.qpos_from_motion(motion)
    column = 7 + body.hinges.index((hip, "y"))
    np.testing.assert_allclose(qpos[:, column], turn, atol=1e-9)


def test_qpos_rejects_a_motion_on_another_skeleton():
    body = build_body(load_rig("avatar").skeleton)
    with pytest.raises(BodyError, match="skeleton"):
        body.qpos_from_motion(_random_motion("body17", 2, 0, 0.1))


def test_non_adjacent_segments_collide_adjacent_do_not():
    body = build_body(load_rig("body17").skeleton)
    model, data = _model(body)
    # Both arms swung 110 degrees forward horizontally: the forearms cross in front.
    qpos = model.qpos0.copy()
    for joint, sign in (("l_shoulder", -1.0), ("r_shoulder", 1.0)):
        qpos[model.joint(hinge_name(joint, "z")).qposadr[0]] = sign * np.radians(110.0)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    touching = {
        frozenset((model.geom_bodyid[c.geom1], model.geom_bodyid[c.geom2]))
        for c in data.contact[: data.ncon]
    }
    left = {model.body(n).id for n in ("l_elbow", "l_wrist")}
    right = {model.body(n).id for n in ("r_elbow", "r_wrist")}
    assert any(len(pair & left) == 1 and len(pair & right) == 1 for pair in touching)
    excluded = {
        frozenset((a, b))
        for a, b in zip(
            model.exclude_signature >> 16, model.exclude_signature & 0xFFFF, strict=True
        )
    }
    assert frozenset((model.body("l_hip").id, model.body("l_knee").id)) in excluded


@pytest.mark.mocap
def test_qpos_replays_real_cmu_mocap_exactly(mocap_dir):
    from avatarsim.avatar_models.formats import load_motion

    motion = load_motion(mocap_dir / "cmu" / "09_01.bvh")[::12]
    body = build_body(motion.skeleton)
    assert body.rig.name == "cmu"
    model, data = _model(body)
    qpos = body.qpos_from_motion(motion)
    expected = motion.global_positions()[:, body.simulated_joints]
    body_ids = [model.body(motion.skeleton.names[j]).id for j in body.simulated_joints]
    for t in range(motion.n_frames):
        data.qpos[:] = qpos[t]
        mujoco.mj_kinematics(model, data)
        np.testing.assert_allclose(data.xpos[body_ids], expected[t], atol=1e-6)


@pytest.mark.parametrize("rig", RIGS)
def test_toes_are_hinged_bodies_not_colliding_with_their_foot(rig):
    body = build_body(load_rig(rig).skeleton)
    model, _ = _model(body)
    excluded = {
        frozenset((a, b))
        for a, b in zip(
            model.exclude_signature >> 16, model.exclude_signature & 0xFFFF, strict=True
        )
    }
    for side in "lr":
        ankle = body.skeleton.names[body.anatomy.body17[f"{side}_ankle"]]
        toe = body.skeleton.names[body.anatomy.body17[f"{side}_foot"]]
        assert model.body(toe).parentid[0] == model.body(ankle).id
        assert model.body(toe).jntnum[0] == 3
        assert model.actuator(hinge_name(toe, "y")).trntype == mujoco.mjtTrn.mjTRN_JOINT
        assert frozenset((model.body(ankle).id, model.body(toe).id)) in excluded
        toe_geoms = [s for s in body.segments if s.body == body.skeleton.index(toe)]
        assert [s.kind for s in toe_geoms] == ["foot"]


def test_generated_walk_rolls_over_the_toes_without_sinking_into_the_floor():
    from avatarsim.avatar_models.generator import generate

    motion = generate("walk", duration_s=2.0, fps=60.0)
    body = build_body(motion.skeleton)
    model, data = _model(body)
    qpos = body.qpos_from_motion(motion)
    toe_flexion = qpos[:, model.joint(hinge_name("Bip01 L Toe0", "y")).qposadr[0]]
    assert toe_flexion.min() < np.radians(-20.0)  # push-off bends the toes up
    floor = model.geom("floor").id
    deepest = np.zeros(len(qpos))
    for t, q in enumerate(qpos):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        con = data.contact[: data.ncon]
        on_floor = (con.geom1 == floor) | (con.geom2 == floor)
        deepest[t] = max(0.0, -con.dist[on_floor].min(initial=0.0))
    # A rigid heel-to-toe box sank about 3 cm at push-off, a sole reaching behind the heel
    # joint (the pivot of the heel rocker) 3.6 mm after heel strike.
    assert deepest.max() < 0.001


def test_wrist_twist_is_replayed_as_forearm_rotation():
    """CMU carries pronation/supination as the wrist joint's twist about the forearm; the
    qpos puts it on the elbow's axial hinge, the hand's pose unchanged."""
    sk = load_rig("cmu").skeleton
    frames, twist = 5, np.radians(np.linspace(-70.0, 70.0, 5))
    rot = np.tile(quat.IDENTITY, (frames, sk.n_joints, 1))
    elbow, wrist = sk.index("RightForeArm"), sk.index("RightHand")
    rot[:, elbow] = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.full(frames, 1.2))
    rot[:, wrist] = quat.from_axis_angle(sk.offsets[wrist], twist)
    motion = Motion(sk, 30.0, np.tile([0.0, 0.0, 1.0], (frames, 1)), rot)
    body = build_body(sk)
    model, data = _model(body)
    qpos = body.qpos_from_motion(motion)
    hinge = {h: 7 + i for i, h in enumerate(body.hinges)}
    np.testing.assert_allclose(qpos[:, [hinge[(wrist, a)] for a in "xyz"]], 0.0, atol=1e-9)
    # The right forearm points along -Y, so a twist about its bone is -ry.
    np.testing.assert_allclose(qpos[:, hinge[(elbow, "y")]], -twist, atol=1e-9)
    expected = motion.global_rotations()[:, wrist]
    for t in range(frames):
        data.qpos[:] = qpos[t]
        mujoco.mj_kinematics(model, data)
        got = data.xquat[model.body("RightHand").id]
        assert abs(np.dot(got, expected[t])) == pytest.approx(1.0, abs=1e-9)


def test_chain_tendons_limit_the_sum_of_the_chains_hinges():
    """CMU's neck (Neck, Neck1, Head): each hinge has the whole cervical range, a fixed tendon
    per axis sums the three hinges and has that range too."""
    body = build_body(load_rig("cmu").skeleton)
    model, data = _model(body)
    names = ("Neck", "Neck1", "Head")
    tendon = model.tendon("Neck+Neck1+Head:ry")
    assert model.tendon_limited[tendon.id]
    assert np.degrees(model.tendon_range[tendon.id]) == pytest.approx([-45, 45])
    for n in names:
        assert np.degrees(model.joint(hinge_name(n, "y")).range) == pytest.approx([-45, 45])
    for n, angle in zip(names, (-0.3, 0.6, 0.25), strict=True):
        data.qpos[model.joint(hinge_name(n, "y")).qposadr[0]] = angle
    mujoco.mj_kinematics(model, data)
    mujoco.mj_tendon(model, data)
    assert data.ten_length[tendon.id] == pytest.approx(0.55)
    assert model.ntendon == 3 * len(body.chains) == 6  # spine and neck, x y z each


def _array_fields(model: mujoco.MjModel) -> dict[str, np.ndarray]:
    """Every numeric array of ``model`` and of its ``opt``, by name."""
    out = {f"opt.{n}": getattr(model.opt, n) for n in dir(model.opt) if not n.startswith("_")}
    out |= {n: getattr(model, n) for n in dir(model) if not n.startswith("_")}
    return {n: np.asarray(v) for n, v in out.items() if isinstance(v, np.ndarray | int | float)}


def test_model_is_the_mjcf_elementtree_wrote_before_mjspec():
    """The avatar rig's model is bit for bit the one the MJCF text of commit 4b8d946
    (ElementTree, 9 significant digits; tests/data/mjcf) compiles to."""
    before = mujoco.MjModel.from_xml_path(str(DATA / "avatar_elementtree.xml"))
    now = build_body(load_rig("avatar").skeleton).model
    old, new = _array_fields(before), _array_fields(now)
    assert old.keys() == new.keys() and len(new) > 300
    differing = [n for n in new if not np.array_equal(old[n], new[n], equal_nan=True)]
    assert differing == []


@pytest.mark.parametrize("rig", ("avatar", "cmu"))
def test_spec_model_matches_its_xml_round_trip(rig):
    """MuJoCo's XML export of the spec recompiles to the same model: every integer array
    equal, every float to the 6 significant digits MuJoCo writes."""
    body = build_body(load_rig(rig).skeleton)
    spec_model = body.model
    xml_model = mujoco.MjModel.from_xml_string(body.to_mjcf())
    ours, theirs = _array_fields(spec_model), _array_fields(xml_model)
    assert ours.keys() == theirs.keys()
    for name, value in ours.items():
        if value.dtype.kind == "f":
            np.testing.assert_allclose(theirs[name], value, rtol=1e-5, atol=1e-6, err_msg=name)
        else:
            np.testing.assert_array_equal(theirs[name], value, err_msg=name)


def test_body_is_compiled_once_and_specs_are_shared_by_copy():
    body = build_body(load_rig("avatar").skeleton)
    assert body.model is body.model and body.spec is body.spec
    edited = body.spec.copy()
    edited.option.timestep = 0.01
    assert edited.compile().opt.timestep == 0.01 and body.spec.option.timestep == 0.002
