"""Kinematic replay geometry against analytic cases on hand-written MJCF models."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.sim.replay import replay_kinematic

XML = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    <body name="thing">
      <freejoint/>
      <geom type="{gtype}" size="{size}" euler="{euler}"/>
    </body>
  </worldbody>
</mujoco>
"""


def model(gtype: str, size: str, euler: str = "0 0 0") -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(XML.format(gtype=gtype, size=size, euler=euler))


def qpos_at_heights(heights: list[float]) -> np.ndarray:
    q = np.zeros((len(heights), 7))
    q[:, 2] = heights
    q[:, 3] = 1.0
    return q


def test_sphere_penetration_and_lowest_point():
    trace = replay_kinematic(model("sphere", "0.1"), qpos_at_heights([0.05, 0.1, 0.3]))
    np.testing.assert_allclose(trace.lowest_point, [-0.05, 0.0, 0.2], atol=1e-9)
    np.testing.assert_allclose(trace.floor_penetration[0], 0.05, atol=1e-6)
    assert trace.floor_contacts[0] >= 1 and trace.floor_contacts[2] == 0
    np.testing.assert_allclose(trace.body_pos[:, 1, 2], [0.05, 0.1, 0.3])


@pytest.mark.parametrize(
    "gtype, size, euler, expected_extent",
    [
        ("capsule", "0.05 0.2", "0 0 0", 0.25),  # upright: radius + half length
        ("capsule", "0.05 0.2", "90 0 0", 0.05),  # lying: radius only
        ("box", "0.1 0.2 0.3", "0 0 0", 0.3),
        ("box", "0.1 0.1 0.1", "45 0 0", 0.1 * np.sqrt(2)),  # on an edge
    ],
)
def test_lowest_point_of_rotated_geoms(gtype, size, euler, expected_extent):
    trace = replay_kinematic(model(gtype, size, euler), qpos_at_heights([1.0]))
    np.testing.assert_allclose(trace.lowest_point[0], 1.0 - expected_extent, atol=1e-9)


def test_bad_qpos_is_rejected():
    m = model("sphere", "0.1")
    with pytest.raises(MotionValueError):
        replay_kinematic(m, np.zeros((3, 5)))
    bad = qpos_at_heights([0.1, 0.2])
    bad[1, 0] = np.nan
    with pytest.raises(MotionValueError, match="NaN"):
        replay_kinematic(m, bad)
