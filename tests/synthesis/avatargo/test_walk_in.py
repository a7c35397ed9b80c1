"""The walk-in T-pose of the clip's own rig: rest T-poses stay as they are; a rig whose rest
pose is none (Bandai's) is stood in one built from the clip, and the walk-in sample on it
calibrates (roles, facing) on a real clip of each source."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from avatarsim.avatar_models.formats.bvh import read_bvh
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.generator.subject import Subject
from avatarsim.avatar_models.rigs import identify_rig, load_rig
from avatarsim.render_cams.vr import FULL_BODY, VRSetup
from avatarsim.synthesis.avatargo.calibration import classes_of, identify_roles
from avatarsim.synthesis.avatargo.walk_in import is_t_pose, t_pose, walk_in

REAL_CLIPS = {
    "cmu": "cmu/09_01.bvh",
    "bandai-1": "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh",
    "bandai-2": "bandai/dataset-2/data/dataset-2_wave-right-hand_normal_001.bvh",
}


def test_rest_t_poses_are_recognised():
    """The avatar rig and CMU stand in T-poses at rest; Bandai's rest pose lies in a line."""
    assert is_t_pose(load_rig("avatar").skeleton) and is_t_pose(load_rig("cmu").skeleton)
    assert not is_t_pose(load_rig("bandai").skeleton)


def test_a_rest_t_pose_is_the_walk_in_pose():
    """A rig standing in a T-pose at rest keeps it (turned to the heading), whatever the clip
    does."""
    motion = generate("wave", Subject(), 0.2, 90.0, 0)
    pose = t_pose(motion, 0.0, 0.0)
    np.testing.assert_allclose(
        pose.local_rot[0, 1:], np.tile([1.0, 0, 0, 0], (pose.skeleton.n_joints - 1, 1))
    )


ARM_BONES = (("shoulder", "elbow"), ("elbow", "wrist"))


def _length(motion, a: str, b: str) -> float:
    """Distance between body17 joints ``a`` and ``b`` in the first frame."""
    pa, pb = _body17(motion, [a, b])
    return float(np.linalg.norm(pa - pb))


def _body17(motion, names):
    rig = identify_rig(motion.skeleton)
    return motion.global_positions()[0, motion.skeleton.indices([rig.body17[n] for n in names])]


@pytest.mark.mocap
@pytest.mark.parametrize("source", sorted(REAL_CLIPS))
def test_walk_in_on_a_real_clip_calibrates(mocap_dir: Path, source):
    """On a clip of each source, facing 40 deg: the arms stretch sideways at shoulder height
    (wrists within 5 cm of the shoulders' height, as far apart along the left axis as the
    shoulders plus both arms' bones, to 2 cm), the ankles under the hips, left of right
    (10 cm), the lowest joint on the floor (2 cm; CMU stands on its body's feet); the walk-in
    sample identifies every device's role and the facing to 3 deg (measured 0.96,
    1.30, 0.21 deg for Bandai-1, Bandai-2, CMU; no noise, so no seed dependence: the plane
    fit's tilt from the arms' and legs' own offsets)."""
    motion = read_bvh(mocap_dir / REAL_CLIPS[source])[:30]
    heading = np.radians(40.0)
    pose = t_pose(motion, heading, 0.0)
    facing = np.array([np.cos(heading), np.sin(heading), 0.0])
    left = np.array([-np.sin(heading), np.cos(heading), 0.0])
    shoulders, wrists, hips, ankles = (
        _body17(pose, [f"l_{j}", f"r_{j}"]) for j in ("shoulder", "wrist", "hip", "ankle")
    )
    assert np.abs(wrists[:, 2] - shoulders[:, 2]).max() < 0.05
    arms = sum(_length(pose, f"{s}_{a}", f"{s}_{b}") for s in "lr" for a, b in ARM_BONES)
    span = (wrists[0] - wrists[1]) @ left
    assert abs(span - (shoulders[0] - shoulders[1]) @ left - arms) < 0.02
    assert np.abs((ankles - hips) @ facing).max() < 0.05  # no stride
    assert (ankles[0] - ankles[1]) @ left > 0.1  # side by side (CMU's rest legs spread 20 deg)
    assert abs(pose.global_positions()[0, :, 2].min()) < 0.02

    sample = walk_in(VRSetup(devices=FULL_BODY), motion, seed=0, heading_rad=heading)
    roles = identify_roles(sample.positions, sample.quaternions, classes_of(sample.device_names))
    np.testing.assert_array_equal(roles.index, np.arange(len(FULL_BODY)))  # role order
    assert np.degrees(np.arccos(np.clip(roles.facing @ facing, -1, 1))) < 3.0
