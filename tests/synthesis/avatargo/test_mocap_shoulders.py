"""CMU 09_01 (running): the avatar's shoulders stay with the user's. The analytic solver
(the default) keeps the clavicles at rest, so the shoulders follow the chest (measured mean
error, 3 s, seed 0 user, realistic noise: left 7.8 cm, right 5.4 cm; the pelvis 3.9 cm, one
90 Hz frame of tracking latency at a run's speed); mink's QP drags the left shoulder 31.5 cm
off (elbow 18 cm) to bring the hand to its controller, the artefact this guards against."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from avatarsim.avatar_models.formats.bvh import read_bvh
from avatarsim.avatar_models.rigs import identify_rig
from avatarsim.render_cams.vr.noise import Drift, Latency, PositionJitter, RotationJitter
from avatarsim.sim.humanoid import humanoid_for
from avatarsim.synthesis.avatargo.study import sample_user, study_run

NOISE = (Latency(seconds=1 / 90), PositionJitter(), RotationJitter(), Drift())


@pytest.mark.mocap
def test_cmu_run_shoulders_follow_the_user(mocap_dir: Path):
    """Bound: each shoulder's mean error under 15 cm (measured 7.8 / 5.4)."""
    motion = read_bvh(mocap_dir / "cmu" / "09_01.bvh")
    truth = humanoid_for(motion[: int(3 * motion.fps) + 1]).motion.resample(90.0)
    user = sample_user(0, truth.skeleton)
    out = study_run(truth, user, NOISE, fingers=False)["motions"]["exact"]
    n = min(out.n_frames, truth.n_frames)
    truth_joint, out_joint = identify_rig(truth.skeleton).body17, identify_rig(out.skeleton).body17
    for side in ("l_shoulder", "r_shoulder"):
        got = out.global_positions()[:n, out.skeleton.index(out_joint[side])]
        want = truth.global_positions()[:n, truth.skeleton.index(truth_joint[side])]
        assert np.linalg.norm(got - want, axis=-1).mean() < 0.15, side
