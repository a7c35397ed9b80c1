"""Bad frames: injection rate and detector precision/recall on rendered fisheye frames."""

import numpy as np
import pytest

from avatarsim.avatar_models.generator import generate
from avatarsim.render_cams.device import DeviceError
from avatarsim.render_cams.fisheye import bad_frames
from avatarsim.render_cams.fisheye.model import FisheyeModel
from avatarsim.render_cams.fisheye.render import FisheyeRenderer
from avatarsim.render_cams.fisheye.rig import camera_poses, controller_cameras
from avatarsim.render_cams.scene import BodyScene


@pytest.fixture(scope="module")
def frames():
    motion = generate("box", duration_s=1.5, fps=30)
    poses = camera_poses(motion, controller_cameras())
    with BodyScene(motion.skeleton) as scene:
        renderer = FisheyeRenderer(scene, FisheyeModel.from_fov().scaled(0.2), face_size=64)
        out = []
        for t in range(motion.n_frames):
            scene.update(motion, t)
            out.append(renderer.render(poses[t, 0])[0])
    return np.stack(out)


def test_injection_rate_is_about_one_in_fifty():
    blank = np.zeros((5000, 2, 2, 3), np.uint8)
    _, flags, kinds = bad_frames.inject(blank, np.random.default_rng(0))
    assert flags.mean() == pytest.approx(1 / 50, abs=0.005)
    assert {k for k in kinds if k} == set(bad_frames.KINDS)


def test_detector_precision_and_recall(frames):
    truth, flagged = [], []
    for seed in range(6):  # a raised rate gives enough corrupted frames to measure
        corrupted, flags, _ = bad_frames.inject(frames, np.random.default_rng(seed), rate=0.15)
        truth.append(flags)
        flagged.append(bad_frames.detect(corrupted))
    scores = bad_frames.precision_recall(np.concatenate(truth), np.concatenate(flagged))
    assert scores["injected"] > 20
    assert scores["precision"] >= 0.9 and scores["recall"] >= 0.9
    assert not bad_frames.detect(frames).any()


def test_defects_the_filter_was_not_designed_around(frames):
    # Measured by ``avatarsim bench sensing``; here only that each defect is what it says.
    rng = np.random.default_rng(0)
    for kind in bad_frames.UNSEEN_KINDS:
        corrupted, flags, kinds = bad_frames.inject(frames, rng, rate=1.0, kinds=(kind,))
        assert flags.all() and set(kinds) == {kind}
        before, after = frames.astype(float), corrupted.astype(float)
        if kind == "motion_blur":  # smoother: less energy between neighbouring pixels
            assert np.abs(np.diff(after, axis=2)).mean() < np.abs(np.diff(before, axis=2)).mean()
        elif kind == "hand_in_view":  # a large part of every frame replaced
            changed = np.any(np.abs(after - before) > 20, axis=-1).mean(axis=(1, 2))
            assert np.all(changed > 0.2)
        else:  # brighter, more of it clipped white
            assert after.mean() > before.mean() + 30
            assert (corrupted == 255).mean() > (frames == 255).mean() + 0.2
    with pytest.raises(DeviceError, match="unknown bad-frame kinds"):
        bad_frames.inject(frames, rng, kinds=("smudge",))
