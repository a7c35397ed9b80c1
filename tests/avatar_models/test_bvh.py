"""BVH reader/writer: known poses, channel layouts, units, round trips and error reporting."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.errors import MotionFormatError
from avatarsim.avatar_models.formats.bvh import read_bvh, write_bvh
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.skeleton import Skeleton


def random_motion(rng: np.random.Generator, n_joints: int = 8, n_frames: int = 5) -> Motion:
    """A random tree (joints, then end sites on some leaves), random rotations and root path."""
    parents = [-1] + [int(rng.integers(0, j)) for j in range(1, n_joints)]
    leaves = [j for j in range(n_joints) if j not in parents[1:]]
    parents += leaves
    is_site = [False] * n_joints + [True] * len(leaves)
    names = [f"j{j}" for j in range(n_joints)] + [f"j{p}_end" for p in leaves]
    offsets = rng.uniform(-0.3, 0.3, (len(names), 3))
    skeleton = Skeleton(names, parents, offsets, is_site)
    rot = quat.from_scipy(Rotation.random(n_frames * len(names), rng=rng), (n_frames, len(names)))
    rot[:, np.asarray(is_site)] = quat.IDENTITY
    root = rng.uniform(-2.0, 2.0, (n_frames, 3))
    return Motion(skeleton, 60.0, root, rot)


def positions_by_name(motion: Motion) -> dict[str, np.ndarray]:
    pos = motion.global_positions()
    return {n: pos[:, j] for j, n in enumerate(motion.skeleton.names)}


def write_text(tmp_path, text: str, name: str = "clip.bvh"):
    path = tmp_path / name
    path.write_text(text)
    return path


TWO_JOINT = """HIERARCHY
ROOT A
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT B
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 10 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
1 2 3 90 0 0 0 0 0
1 2 3 90 0 0 0 90 0
"""


def test_known_pose_after_y_up_to_z_up(tmp_path):
    m = read_bvh(write_text(tmp_path, TWO_JOINT), unit="cm")
    pos = positions_by_name(m)
    # File frame 0: Rz(90) turns B's offset (0,10,0) to (-10,0,0): B at (-9,2,3) cm, tip at
    # (-19,2,3). Z-up maps (x, y, z) -> (z, x, y).
    np.testing.assert_allclose(pos["A"][0], [0.03, 0.01, 0.02], atol=1e-12)
    np.testing.assert_allclose(pos["B"][0], [0.03, -0.09, 0.02], atol=1e-12)
    np.testing.assert_allclose(pos["B_end"][0], [0.03, -0.19, 0.02], atol=1e-12)
    # Frame 1: B also turns 90 deg about X, its offset (0,10,0) -> (0,0,10); Rz leaves it: tip
    # at (-9,2,13) cm in the file, (13,-9,2) cm Z up.
    np.testing.assert_allclose(pos["B_end"][1], [0.13, -0.09, 0.02], atol=1e-12)
    # The root's rotation, 90 deg about the file's Z, is 90 deg about world +X (C z = x).
    expected = quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), np.array(np.pi / 2))
    assert abs(abs(np.dot(m.global_rotations()[0, 0], expected)) - 1.0) < 1e-12
    assert m.fps == 30.0 and m.meta["frame_time_s"] == 0.0333333
    assert m.meta["unit_scale_m"] == 0.01 and m.meta["source"].endswith("clip.bvh")


def test_up_z_keeps_axes(tmp_path):
    m = read_bvh(write_text(tmp_path, TWO_JOINT), unit="cm", up="z")
    np.testing.assert_allclose(positions_by_name(m)["B_end"][0], [-0.19, 0.02, 0.03], atol=1e-12)


def _elementary(axis: str, deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return {
        "X": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
        "Y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        "Z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


@pytest.mark.parametrize("order", ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX", "ZX", "Y"])
def test_channel_order_is_intrinsic_euler_order(tmp_path, order):
    angles = [31.0, -47.0, 12.5][: len(order)]
    channels = " ".join(f"{a}rotation" for a in order)
    text = TWO_JOINT.replace(
        "CHANNELS 3 Zrotation Xrotation Yrotation", f"CHANNELS {len(order)} {channels}"
    )
    text = text.replace("1 2 3 90 0 0 0 0 0\n1 2 3 90 0 0 0 90 0\n", "")
    text = (
        text.replace("Frames: 2", "Frames: 1") + "0 0 0 0 0 0 " + " ".join(map(str, angles)) + "\n"
    )
    m = read_bvh(write_text(tmp_path, text), unit="m", up="z")
    rotation = np.eye(3)
    for axis, deg in zip(order, angles, strict=True):
        rotation = rotation @ _elementary(axis, deg)  # intrinsic: R = R1 R2 R3
    tip = np.array([0.0, 10.0, 0.0]) + rotation @ np.array([0.0, 10.0, 0.0])
    np.testing.assert_allclose(positions_by_name(m)["B_end"][0], tip, atol=1e-12)


BANDAI_LIKE = """HIERARCHY
ROOT joint_Root
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Hips
  {
    OFFSET 0 90 0
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
    JOINT Spine
    {
      OFFSET 15 0 0
      CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
      End Site
      {
        OFFSET 0 0 0
      }
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.0333333
0 0 0 0 0 0 5 91 -40 90 0 0 20 0.000001 0 0 0 0
0 0 0 0 0 0 6 92 -30 90 0 0 20 0.000001 0 0 30 0
0 0 0 0 0 0 7 93 -20 90 0 0 20 0.000001 0 0 0 0
"""


def test_six_channel_joints_fold_the_static_root(tmp_path):
    m = read_bvh(write_text(tmp_path, BANDAI_LIKE), unit="cm")
    pos = positions_by_name(m)
    # Hips' position channels replace its OFFSET: (5,91,-40) cm, Z up (-0.40, 0.05, 0.91).
    np.testing.assert_allclose(
        pos["Hips"][:, [1, 2, 0]] * 100, [[5, 91, -40], [6, 92, -30], [7, 93, -20]]
    )
    # Spine's constant channels (20, 1e-6, 0) are its offset, turned up by Hips' Rz(90).
    np.testing.assert_allclose(pos["Spine"] - pos["Hips"], [[0, 0, 0.2]] * 3, atol=1e-7)
    np.testing.assert_allclose(np.linalg.norm(pos["Spine"] - pos["Hips"], axis=1), 0.2, atol=1e-7)
    assert m.meta["folded_root_into"] == "Hips"
    np.testing.assert_allclose(pos["joint_Root"], pos["Hips"])


def test_moving_position_channels_below_the_root_are_rejected(tmp_path):
    text = BANDAI_LIKE.replace(
        "20 0.000001 0 0 0 0\n0 0 0 0 0 0 6", "25 0.000001 0 0 0 0\n0 0 0 0 0 0 6"
    )
    with pytest.raises(MotionFormatError, match="Spine.*moving position channels") as err:
        read_bvh(write_text(tmp_path, text), unit="cm")
    assert err.value.line == 10


def test_end_sites_are_site_joints(tmp_path):
    text = TWO_JOINT.replace(
        "    End Site\n", "    End Site\n    {\n      OFFSET 1 0 0\n    }\n    End Site\n", 1
    )
    m = read_bvh(write_text(tmp_path, text), unit="cm")
    assert m.skeleton.names == ("A", "B", "B_end", "B_end1")
    assert m.skeleton.is_site.tolist() == [False, False, True, True]
    assert m.skeleton.parents.tolist() == [-1, 0, 1, 1]


@pytest.mark.parametrize(
    ("unit", "scale"), [("cm", 0.01), ("m", 1.0), ("inch", 0.0254), ("cmu", 0.056444), (0.5, 0.5)]
)
def test_units_scale_positions(tmp_path, unit, scale):
    m = read_bvh(write_text(tmp_path, TWO_JOINT), unit=unit)
    np.testing.assert_allclose(
        positions_by_name(m)["B_end"][1], np.array([13.0, -9.0, 2.0]) * scale
    )


def _upright_chain(height_units: float) -> str:
    seg = height_units / 4
    return (
        "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
        f"JOINT b\n{{\nOFFSET 0 {seg} 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
        f"End Site\n{{\nOFFSET 0 {3 * seg} 0\n}}\n}}\n}}\nMOTION\nFrames: 1\nFrame Time: 0.01\n"
        "0 0 0 0 0 0\n"
    )


@pytest.mark.parametrize(
    ("height", "unit"), [(175.0, "cm"), (1.8, "m"), (30.0, "cmu"), (66.0, "inch")]
)
def test_unit_is_detected_from_standing_height(tmp_path, height, unit):
    assert read_bvh(write_text(tmp_path, _upright_chain(height))).meta["unit"] == unit


def test_implausible_size_asks_for_unit(tmp_path):
    with pytest.raises(MotionFormatError, match="give the unit with --unit"):
        read_bvh(write_text(tmp_path, _upright_chain(7.0)))


@pytest.mark.parametrize("seed", range(6))
def test_write_read_reproduces_global_positions(tmp_path, seed):
    rng = np.random.default_rng(seed)
    motion = random_motion(rng, n_joints=int(rng.integers(1, 12)), n_frames=7)
    order = "".join(rng.permutation(list("XYZ")))
    unit, up = [("cm", "y"), ("m", "z"), ("inch", "y")][seed % 3]
    path = write_bvh(motion, tmp_path / "out.bvh", unit=unit, up=up, order=order)
    back = read_bvh(path, unit=unit, up=up)
    expected, got = positions_by_name(motion), positions_by_name(back)
    assert set(expected) == set(got)
    for name, p in expected.items():
        np.testing.assert_allclose(got[name], p, atol=1e-6, err_msg=name)
    assert back.fps == motion.fps
    assert list(tmp_path.iterdir()) == [path]  # no temp file left behind


def test_failed_write_leaves_target_untouched(tmp_path):
    target = write_text(tmp_path, "keep", "out.bvh")
    with pytest.raises(MotionFormatError):
        write_bvh(random_motion(np.random.default_rng(0)), target, unit="furlong")
    assert target.read_text() == "keep"


MALFORMED = [
    ("empty", "", 1, "empty"),
    ("blank", "  \n\n", 1, "empty"),
    ("no motion", TWO_JOINT.split("MOTION")[0], 16, "no MOTION"),
    ("truncated frames", TWO_JOINT.rsplit("1 2 3 90 0 0 0 90 0", 1)[0], 19, "truncated"),
    ("extra frame", TWO_JOINT + "1 2 3 90 0 0 0 0 0\n", 21, "more frame lines"),
    ("short frame line", TWO_JOINT.replace("0 0 0 90 0", "0 0 90 0"), 20, "8 values"),
    ("channel count", TWO_JOINT.replace("CHANNELS 3 Z", "CHANNELS 2 Z"), 9, "'Yrotation'"),
    ("bad channel name", TWO_JOINT.replace("Xrotation Y", "Wrotation Y"), 9, "bad channel list"),
    (
        "unknown keyword",
        TWO_JOINT.replace("    End Site", "    Bone"),
        10,
        "unknown keyword 'Bone'",
    ),
    ("nan value", TWO_JOINT.replace("0 0 0 90 0", "0 0 nan 90 0"), 20, "NaN"),
    ("inf value", TWO_JOINT.replace("0 0 0 90 0", "0 0 1e999 90 0"), 20, "NaN or infinite"),
    ("word value", TWO_JOINT.replace("0 0 0 90 0", "0 0 x 90 0"), 20, "'x' is not a number"),
    ("bad frames", TWO_JOINT.replace("Frames: 2", "Frames: two"), 17, "Frames"),
    ("zero frames", TWO_JOINT.replace("Frames: 2", "Frames: 0"), 17, "Frames"),
    ("bad frame time", TWO_JOINT.replace("0.0333333", "-1"), 18, "Frame Time"),
    ("nan offset", TWO_JOINT.replace("OFFSET 0 10 0", "OFFSET 0 nan 0", 1), 8, "not finite"),
    ("duplicate name", TWO_JOINT.replace("JOINT B", "JOINT A"), 6, "duplicate"),
    ("unclosed", TWO_JOINT.replace("  }\n}\nMOTION", "MOTION"), 14, "ends early"),
]


@pytest.mark.parametrize(
    ("text", "line", "message"), [m[1:] for m in MALFORMED], ids=[m[0] for m in MALFORMED]
)
def test_malformed_files_name_file_and_line(tmp_path, text, line, message):
    path = write_text(tmp_path, text)
    with pytest.raises(MotionFormatError, match=message) as err:
        read_bvh(path, unit="cm")
    assert err.value.path == str(path)
    assert err.value.line == line
    assert f"clip.bvh:{line}:" in str(err.value)


def test_non_utf8_bytes_are_a_format_error(tmp_path):
    path = tmp_path / "clip.bvh"
    path.write_bytes(TWO_JOINT.encode().replace(b"JOINT B", b"JOINT \xff\xfe"))
    with pytest.raises(MotionFormatError, match="UTF-8") as err:
        read_bvh(path, unit="cm")
    assert err.value.line == 6


def test_missing_file_is_a_format_error(tmp_path):
    with pytest.raises(MotionFormatError, match="cannot read"):
        read_bvh(tmp_path / "absent.bvh")


@pytest.mark.parametrize("fmt, newline", [("%.6f", "\n"), ("%.10g", "\r\n"), ("%.3e", "\n")])
def test_fast_and_checked_frame_parsers_agree_bit_for_bit(tmp_path, fmt, newline):
    from avatarsim.avatar_models.formats.bvh.frames import checked_motion_values, motion_values

    values = np.random.default_rng(0).normal(scale=100.0, size=(40, 9))
    data = newline.join("\t".join(fmt % v for v in row) for row in values) + newline
    fast = motion_values(data, 40, 9, tmp_path / "x.bvh", 1)
    checked = checked_motion_values(data, 40, 9, tmp_path / "x.bvh", 1)
    assert fast.tobytes() == checked.tobytes()
    np.testing.assert_allclose(fast, values, rtol=1e-2 if fmt == "%.3e" else 1e-5, atol=1e-5)


def test_joint_names_with_spaces_round_trip(tmp_path):
    """The avatar rig is a 3ds Max Biped: 'Bip01 L Thigh' must survive write -> read."""
    from avatarsim.avatar_models.generator import generate

    motion = generate("wave", duration_s=0.3, fps=30.0)
    back = read_bvh(write_bvh(motion, tmp_path / "biped.bvh"))
    assert "Bip01 L Thigh" in back.skeleton.names
    np.testing.assert_allclose(
        back.positions_of(["Bip01 L Thigh", "Bip01 R Hand"]),
        motion.positions_of(["Bip01 L Thigh", "Bip01 R Hand"]),
        atol=1e-6,
    )
