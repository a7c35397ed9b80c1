"""Skeleton validation, lookup and mirror pairing."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.errors import MotionValueError, UnknownJointError
from avatarsim.avatar_models.skeleton import Skeleton


def test_mirror_map_pairs_common_naming_schemes():
    names = [
        "Hips",
        "LeftUpLeg",
        "RightUpLeg",
        "Shoulder_L",
        "Shoulder_R",
        "Bip01 L Hand",
        "Bip01 R Hand",
        "lfemur",
        "rfemur",
    ]
    sk = Skeleton(names, [-1] + [0] * 8, np.zeros((9, 3)))
    m = sk.mirror_map()
    pairs = {names[i]: names[j] for i, j in enumerate(m)}
    assert pairs["LeftUpLeg"] == "RightUpLeg" and pairs["Shoulder_R"] == "Shoulder_L"
    assert pairs["Bip01 L Hand"] == "Bip01 R Hand" and pairs["lfemur"] == "rfemur"
    assert pairs["Hips"] == "Hips"


@pytest.mark.parametrize(
    "names, parents",
    [([], []), (["a", "a"], [-1, 0]), (["a", "b"], [-1, 1]), (["a", "b"], [0, -1])],
)
def test_invalid_skeletons(names, parents):
    with pytest.raises(MotionValueError):
        Skeleton(names, parents, np.zeros((len(names), 3)))


def test_unknown_joint_message_lists_joints():
    sk = Skeleton(["root", "knee"], [-1, 0], [[0, 0, 0], [0, 0, -0.4]])
    with pytest.raises(UnknownJointError, match="knee"):
        sk.index("elbow")
    assert sk.chain(1) == [0, 1]
    np.testing.assert_allclose(sk.rest_positions()[1], [0, 0, -0.4])
