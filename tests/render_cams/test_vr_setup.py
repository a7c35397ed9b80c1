"""VR devices placed on a skeleton: known poses, rates, offsets, determinism, bad input."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from avatarsim.avatar_models import Motion, MotionValueError, RigError, Skeleton, quat
from avatarsim.avatar_models.rigs import available_rigs, load_rig
from avatarsim.render_cams import FULL_BODY, Device, DeviceError, UnknownDeviceError, VRSetup
from avatarsim.render_cams.vr import Attachment, OffsetSpread, PositionJitter, nominal_attachment
from tests.render_cams.builders import body17_motion, rest_motion

ZERO_OFFSETS = {
    "hmd": Attachment("head"),
    "left_controller": Attachment("l_wrist"),
    "right_controller": Attachment("r_wrist"),
}
Z90 = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])


def same_rotation(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|<a, b>| = 1 where the quaternions describe the same rotation."""
    return np.abs(np.sum(a * b, axis=-1))


def test_zero_offsets_reproduce_joint_fk_exactly():
    motion = body17_motion(fps=90.0)
    stream = VRSetup(offsets=ZERO_OFFSETS).sample(motion, seed=1)
    joints = motion.skeleton.indices(["head", "l_wrist", "r_wrist"])
    assert stream.n_samples == motion.n_frames
    np.testing.assert_array_equal(stream.positions, motion.global_positions()[:, joints])
    rots = motion.global_rotations()[:, joints]
    np.testing.assert_allclose(same_rotation(stream.quaternions, rots), 1.0, atol=1e-12)
    assert stream.validate() is stream


def test_offset_along_local_x_with_joint_turned_90_degrees_about_z():
    # Pelvis (root) at (1, 2, 0.95) turned +90 deg about Z: its local +X is world +Y.
    motion = rest_motion(root=(1.0, 2.0, 0.95), yaw=np.pi / 2)
    offsets = {"back_tracker": Attachment("pelvis", np.array([0.1, 0.0, 0.0]))}
    stream = VRSetup(devices=("hmd", "back_tracker"), offsets=offsets).sample(motion)
    back = stream.device("back_tracker")
    np.testing.assert_allclose(stream.positions[:, back], [[1.0, 2.1, 0.95]] * 3, atol=1e-12)
    np.testing.assert_allclose(same_rotation(stream.quaternions[:, back], Z90), 1.0, atol=1e-12)
    # Head is 0.5 + 0.12 m above the pelvis; the eyes 9 cm forward (world +Y) and 8 cm up.
    hmd = stream.device("hmd")
    np.testing.assert_allclose(stream.positions[:, hmd], [[1.0, 2.09, 1.65]] * 3, atol=1e-12)


def test_nominal_placements_on_the_rest_pose():
    stream = VRSetup(devices=FULL_BODY).sample(rest_motion())
    pos, q = stream.positions[0], stream.quaternions[0]
    # body17 rest: wrists at (0, +-0.72, 1.42), ankles at (0, +-0.09, 0.05).
    expected = {
        "hmd": [0.09, 0.0, 1.65],
        "left_controller": [0.0, 0.80, 1.42],
        "right_controller": [0.0, -0.80, 1.42],
        "left_foot_tracker": [0.06, 0.09, 0.07],
        "right_foot_tracker": [0.06, -0.09, 0.07],
        "back_tracker": [-0.10, 0.0, 1.0],
    }
    for name, xyz in expected.items():
        np.testing.assert_allclose(pos[stream.device(name)], xyz, atol=1e-12, err_msg=name)
    # Controllers point along the outstretched arm with their top (the ring) on the thumb side:
    # forward in a T-pose with the palms down. The back tracker faces -X.
    axes = quat.to_matrix(q)
    for name, forward in (("left_controller", [0, 1, 0]), ("right_controller", [0, -1, 0])):
        np.testing.assert_allclose(axes[stream.device(name)][:, 0], forward, atol=1e-12)
        np.testing.assert_allclose(axes[stream.device(name)][:, 2], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(axes[stream.device("back_tracker")][:, 0], [-1, 0, 0], atol=1e-12)


@pytest.mark.parametrize("rig_name", available_rigs())
def test_devices_fit_every_rig(rig_name):
    """On each rig's rest pose the HMD sits at the eye offset and controllers in the palms."""
    rig = load_rig(rig_name)
    sk = rig.skeleton
    local = np.tile(quat.IDENTITY, (2, sk.n_joints, 1))
    motion = Motion(sk, 30.0, np.tile(sk.offsets[0], (2, 1)), local)
    stream = VRSetup().sample(motion)
    rest = motion.global_positions()[0]
    head = rest[sk.index(rig.body17["head"])]
    np.testing.assert_allclose(stream.positions[0, 0], head + [0.09, 0.0, 0.08], atol=1e-12)
    for device, side in (("left_controller", "l"), ("right_controller", "r")):
        wrist = rest[sk.index(rig.body17[f"{side}_wrist"])]
        gap = np.linalg.norm(stream.positions[0, stream.device(device)] - wrist)
        assert gap == pytest.approx(0.08)


def test_30_fps_motion_sampled_at_90_hz():
    motion = body17_motion(fps=30.0, seconds=2.0)
    stream = VRSetup(offsets=ZERO_OFFSETS).sample(motion)
    # The duration is kept: 61 frames span 2 s, which 90 Hz covers with 181 samples.
    assert stream.n_samples == 3 * (motion.n_frames - 1) + 1
    np.testing.assert_allclose(np.diff(stream.timestamps), 1 / 90, atol=1e-12)
    head = motion.positions_of(["head"])[:, 0]
    # Every third sample falls on a source frame.
    np.testing.assert_allclose(stream.positions[::3, 0], head, atol=1e-9)
    assert stream.meta["rate_hz"] == 90.0 and stream.meta["motion"]["fps"] == 30.0


def test_configurable_rate():
    stream = VRSetup(rate_hz=120.0).sample(body17_motion(fps=30.0, seconds=1.0))
    assert stream.n_samples == 121
    np.testing.assert_allclose(stream.timestamps[-1], 1.0)


def test_same_seed_gives_byte_identical_stream(tmp_path):
    setup = VRSetup(devices=FULL_BODY, noise=(PositionJitter(0.002),), offset_spread=OffsetSpread())
    motion = body17_motion()
    first = setup.sample(motion, seed=7).to_npz(tmp_path / "a.npz")
    second = setup.sample(motion, seed=7).to_npz(tmp_path / "b.npz")
    other = setup.sample(motion, seed=8).to_npz(tmp_path / "c.npz")
    assert first.read_bytes() == second.read_bytes()
    assert first.read_bytes() != other.read_bytes()


def test_generator_seed_is_recorded_and_reproduces_the_stream():
    setup = VRSetup(noise=(PositionJitter(0.002),))
    motion = body17_motion(seconds=0.5)
    stream = setup.sample(motion, seed=np.random.default_rng(3))
    again = setup.sample(motion, seed=stream.meta["seed"])
    np.testing.assert_array_equal(stream.positions, again.positions)


def test_per_user_offsets_are_sampled_recorded_and_overridable():
    motion = rest_motion()
    spread = OffsetSpread(position_sigma_m=0.02, rotation_sigma_rad=0.1)
    setup = VRSetup(devices=FULL_BODY, offset_spread=spread)
    users = [setup.sample(motion, seed=s) for s in range(40)]
    nominal = np.stack([nominal_attachment(d, motion.skeleton).position for d in FULL_BODY])
    recorded = np.stack(
        [[u.meta["offsets"][d]["position"] for d in FULL_BODY] for u in users]
    )  # (users, D, 3)
    deviation = recorded - nominal
    assert np.std(deviation) == pytest.approx(0.02, rel=0.15)
    assert np.abs(deviation.mean()) < 4 * 0.02 / np.sqrt(deviation.size)
    # The recorded offsets are the ones used: device = joint pose * offset (rest: translation).
    head = motion.positions_of(["head"])[0, 0]
    np.testing.assert_allclose(users[0].positions[0, 0], head + recorded[0, 0], atol=1e-12)
    explicit = VRSetup(offsets={"hmd": Attachment("head", np.array([0.0, 0.0, 0.2]))})
    np.testing.assert_allclose(explicit.sample(motion).positions[0, 0], head + [0, 0, 0.2])


def test_vr_setup_is_a_device():
    setup = VRSetup()
    assert isinstance(setup, Device)
    assert setup.name == "vr" and setup.rate_hz == 90.0


@pytest.mark.parametrize("rate", [-90.0, 0.0, float("nan"), "fast"])
def test_bad_rate_is_rejected(rate):
    with pytest.raises(DeviceError, match="rate"):
        VRSetup(rate_hz=rate)


def test_unknown_device_lists_the_known_ones():
    with pytest.raises(UnknownDeviceError, match="available: hmd, left_controller"):
        VRSetup(devices=("hmd", "left_shoe"))
    with pytest.raises(UnknownDeviceError):
        VRSetup(offsets={"tail": Attachment("pelvis")})
    with pytest.raises(DeviceError, match="distinct"):
        VRSetup(devices=("hmd", "hmd"))


def test_bad_attachment_and_seed_are_rejected():
    with pytest.raises(DeviceError, match="body17"):
        Attachment("left_pinky")
    with pytest.raises(DeviceError, match="position"):
        Attachment("head", np.array([0.0, np.nan, 0.0]))
    with pytest.raises(DeviceError, match="seed"):
        VRSetup().sample(rest_motion(), seed=-1)


def test_nan_motion_is_rejected():
    motion = rest_motion()
    with pytest.raises(MotionValueError, match="NaN"):
        motion.replace(root_pos=np.full_like(motion.root_pos, np.nan))
    # A motion corrupted after construction is still caught before devices are placed on it.
    corrupt = rest_motion()
    object.__setattr__(corrupt, "root_pos", np.full_like(corrupt.root_pos, np.nan))
    with pytest.raises(MotionValueError, match="NaN"):
        VRSetup().sample(corrupt)


def test_skeleton_without_a_rig_is_rejected():
    sk = Skeleton(("a", "b"), np.array([-1, 0]), np.array([[0, 0, 1.0], [0, 0, 0.5]]))
    motion = Motion(sk, 30.0, np.zeros((2, 3)), np.tile(quat.IDENTITY, (2, 2, 1)))
    with pytest.raises(RigError, match="no known rig"):
        VRSetup().sample(motion)


@pytest.mark.skipif(
    importlib.util.find_spec("avatarsim.avatar_models.generator") is None, reason="no generator yet"
)
def test_generated_walk_on_the_avatar_rig():
    from avatarsim.avatar_models.generator import generate

    motion = generate("walk", duration_s=3.0, fps=30.0, seed=0)
    offsets = {**ZERO_OFFSETS, "left_foot_tracker": Attachment("l_ankle")}
    devices = ("hmd", "left_controller", "right_controller", "left_foot_tracker")
    stream = VRSetup(devices=devices, offsets=offsets).sample(motion)
    rig = load_rig("avatar")
    names = [rig.body17[j] for j in ("head", "l_wrist", "r_wrist", "l_ankle")]
    np.testing.assert_allclose(stream.positions[::3], motion.positions_of(names), atol=1e-9)
    # A planted foot (the generator's plan) barely moves; a swinging one does.
    speed = np.linalg.norm(np.diff(stream.positions[::3, 3, :2], axis=0), axis=-1) * motion.fps
    planted = motion.meta["planned_contacts"][1:, 0] & motion.meta["planned_contacts"][:-1, 0]
    assert np.median(speed[planted]) < 0.2 * np.median(speed[~planted])
