"""Every real clip in ../shared/mocap loads with sane geometry; positions agree with bvhio.

bvhio conventions, checked against its source (``bvhio/lib/Parser.py``): position channels
replace the OFFSET on every joint, the root included (we add the root's channels to its
OFFSET; every real file here has a zero root OFFSET, so both agree); End Sites are not joints
(compared joints exclude our site joints); it keeps Y up and file units (we apply the same
``C`` and scale to its positions); its arithmetic is float32 (glm), hence the 1e-5 m tolerance.
Bandai files translate ``Hips`` under a static ``joint_Root``: our reader folds the root onto
Hips, so ``joint_Root`` is left out of the comparison for those files.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from avatarsim.avatar_models.formats.bvh import read_bvh, write_bvh
from avatarsim.avatar_models.formats.units import Y_UP_TO_Z_UP
from avatarsim.avatar_models.measure import bone_lengths_over_time, lowest_point, standing_height
from avatarsim.avatar_models.rigs import body17_positions, identify_rig
from tests.conftest import require_module

pytestmark = pytest.mark.mocap

ORACLE_CLIPS = [
    "cmu/09_01.bvh",
    "cmu/13_33.bvh",
    "cmu/125_01.bvh",
    "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh",
    "bandai/dataset-1/data/dataset-1_dash_normal_001.bvh",
    "bandai/dataset-2/data/dataset-2_wave-right-hand_youthful_001.bvh",
]


@pytest.fixture(scope="module")
def clips(mocap_dir: Path) -> dict[str, object]:
    """Every .bvh under the mocap folder, read with unit detection: path -> Motion or error."""
    out = {}
    for path in sorted(mocap_dir.rglob("*.bvh")):
        try:
            out[str(path.relative_to(mocap_dir))] = read_bvh(path)
        except Exception as exc:  # collected and reported by the test below
            out[str(path.relative_to(mocap_dir))] = exc
    return out


# What the shared folder's README says of each source: file unit and frame rate.
SOURCE_FACTS = {"cmu": ("cmu", 120.0), "bandai": ("cm", 30.0)}


def test_every_clip_loads_with_its_rig(clips):
    """Every clip, not one per source: its rig, unit and frame rate are those the shared
    README gives for its source, its arrays are finite, it has frames to speak of. (Heights
    and bone lengths of every clip are checked below.)"""
    failures = {k: repr(v) for k, v in clips.items() if isinstance(v, Exception)}
    assert len(clips) >= 390 and not failures
    per_source = {s: [k for k in clips if k.split("/")[0] == s] for s in SOURCE_FACTS}
    assert len(per_source["cmu"]) == 9 and len(per_source["bandai"]) >= 384
    wrong = {}
    for key, motion in clips.items():
        source = key.split("/")[0]
        unit, fps = SOURCE_FACTS[source]
        got = (identify_rig(motion.skeleton).name, motion.meta["unit"], motion.fps)
        if got != (source, unit, fps):
            wrong[key] = got
        b17 = body17_positions(motion)
        if b17.shape != (motion.n_frames, 17, 3) or not np.isfinite(b17).all():
            wrong[key] = "body17 not finite (T, 17, 3)"
        if not (np.isfinite(motion.root_pos).all() and np.isfinite(motion.local_rot).all()):
            wrong[key] = "non-finite root or rotations"
        if motion.n_frames < 10:  # the shortest real clips (Bandai dash, run) last 0.6 s
            wrong[key] = f"only {motion.n_frames} frames"
    assert not wrong, wrong


def test_bone_lengths_are_constant(clips):
    worst = {k: float(np.ptp(bone_lengths_over_time(m), axis=0).max()) for k, m in clips.items()}
    assert max(worst.values()) < 1e-6, max(worst, key=worst.get)


def test_standing_heights_are_human(clips):
    heights = {k: standing_height(m) for k, m in clips.items()}
    bad = {k: h for k, h in heights.items() if not 1.4 <= h <= 2.0}
    assert not bad


def test_feet_touch_the_floor_when_walking(clips):
    walks = {k: m for k, m in clips.items() if "_walk_" in k or "_walk-" in k}
    assert len(walks) > 20
    for key, motion in walks.items():
        assert abs(float(lowest_point(motion).min())) <= 0.05, key


def test_clips_walk_forward_with_left_on_the_left(clips):
    """Forward, left, up must be right-handed: a mirrored or wrongly turned load walks backwards."""
    for key in ("cmu/09_01.bvh", "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh"):
        b17 = body17_positions(clips[key])
        head, pelvis, l_hip, r_hip = b17[:, 0], b17[:, 2], b17[:, 9], b17[:, 13]
        assert np.all(head[:, 2] > pelvis[:, 2] + 0.3)  # Z is up
        forward = np.cross(l_hip - r_hip, head - pelvis).mean(axis=0)  # left x up = forward
        travel = pelvis[-1] - pelvis[0]
        assert np.linalg.norm(travel[:2]) > 1.0
        assert np.dot(forward, travel) / np.linalg.norm(forward) / np.linalg.norm(travel) > 0.8


def _bvhio_positions(path: Path, frames: list[int]) -> dict[str, np.ndarray]:
    bvhio = require_module("bvhio")
    root = bvhio.readAsHierarchy(str(path))
    out: dict[str, list] = {}
    for frame in frames:
        root.loadPose(frame)
        for joint, _, _ in root.layout():
            out.setdefault(joint.Name, []).append(np.array(joint.PositionWorld, dtype=float))
    return {k: np.array(v) for k, v in out.items()}


@pytest.mark.parametrize("clip", ORACLE_CLIPS)
def test_positions_agree_with_bvhio(mocap_dir, clips, clip):
    motion = clips[clip]
    frames = sorted({0, 1, motion.n_frames // 2, motion.n_frames - 1})
    # A prepended T-pose frame (CMU) is dropped by the reader: file frame = ours + 1.
    skipped = len(motion.meta.get("dropped_frames", {}).get("frames", []))
    theirs = _bvhio_positions(mocap_dir / clip, [f + skipped for f in frames])
    ours = motion.global_positions()[frames]
    folded = motion.meta.get("folded_root_into")
    compared = [n for n in theirs if not (folded and n == motion.skeleton.names[0])]
    assert len(compared) >= 21
    for name in compared:
        expected = theirs[name] * motion.meta["unit_scale_m"] @ Y_UP_TO_Z_UP.T
        got = ours[:, motion.skeleton.index(name)]
        np.testing.assert_allclose(got, expected, atol=1e-5, err_msg=f"{clip} {name}")


@pytest.mark.parametrize(
    "clip", ["cmu/16_35.bvh", "bandai/dataset-2/data/dataset-2_run_normal_003.bvh"]
)
def test_real_clip_write_read_round_trip(tmp_path, clips, clip):
    motion = clips[clip]
    unit = motion.meta["unit"]
    back = read_bvh(write_bvh(motion, tmp_path / "rt.bvh", unit=unit), unit=unit)
    assert back.skeleton.names == motion.skeleton.names
    np.testing.assert_allclose(back.global_positions(), motion.global_positions(), atol=1e-6)


@pytest.mark.parametrize(
    "clip", ["cmu/06_06.bvh", "bandai/dataset-1/data/dataset-1_walk_normal_001.bvh"]
)
def test_converted_real_clip_reads_the_same_in_bvhio(tmp_path, mocap_dir, clips, clip):
    """``avatarsim convert`` of a real clip to BVH, read back by a second library (bvhio):
    every joint's world position equals ours on the source (written in cm, Y up)."""
    from typer.testing import CliRunner

    from avatarsim.scripts.cli import app

    out = tmp_path / "converted.bvh"
    result = CliRunner().invoke(app, ["convert", str(mocap_dir / clip), str(out)])
    assert result.exit_code == 0, result.output
    motion = clips[clip]
    frames = sorted({0, motion.n_frames // 3, motion.n_frames - 1})
    theirs = _bvhio_positions(out, frames)
    ours = motion.global_positions()[frames]
    joints = [
        n for n in motion.skeleton.names if not motion.skeleton.is_site[motion.skeleton.index(n)]
    ]
    assert sorted(theirs) == sorted(joints)
    for name in joints:
        expected = theirs[name] * 0.01 @ Y_UP_TO_Z_UP.T
        got = ours[:, motion.skeleton.index(name)]
        np.testing.assert_allclose(got, expected, atol=2e-5, err_msg=f"{clip} {name}")
