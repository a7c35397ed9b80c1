"""CoolMoves on real Bandai mocap: style sub-libraries (§5.2) choose the style of the output."""

from __future__ import annotations

import numpy as np
import pytest

from avatarsim.avatar_models.library import MotionLibrary
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams import VRSetup
from avatarsim.synthesis.base import TrackingFrame
from avatarsim.synthesis.coolmoves import CoolMoves, Options, build_database
from avatarsim.synthesis.coolmoves.applications import style_sub_library
from avatarsim.synthesis.coolmoves.features import search_vectors, sliding_windows
from avatarsim.synthesis.coolmoves.knn import KNNMatcher
from avatarsim.synthesis.scoring import body17_errors_cm

STYLES = ("exhausted", "youthful")


@pytest.fixture(scope="module")
def walks(mocap_dir):
    """Dataset-2 walks of two styles: ``{(style, take): Motion}``."""
    library = MotionLibrary.index(mocap_dir / "bandai" / "dataset-2")
    clips = library.query(activity="walk", style=list(STYLES))
    return {(c.style, int(c.take)): c.load() for c in clips}


@pytest.mark.mocap
def test_a_style_stream_matches_its_own_style(walks):
    # Both styles in one database (takes 2 and 3); the held-out take 1 of each style drives it.
    train = [m for (style, take), m in walks.items() if take != 1]
    db = build_database(train)
    assert db.skeleton.name == "bandai" and all(c["kept"] for c in db.clips)
    clip_style = np.array([c["style"] for c in db.clips])[db.window_clips()]
    for style in STYLES:
        stream = VRSetup().sample(walks[(style, 1)], seed=0)
        rel = stream.positions[:, 1:] - stream.positions[:, :1]  # (T, 2, 3) head-relative
        windows = sliding_windows(rel, np.arange(8, stream.n_samples))  # (E, 9, 2, 3)
        picked = []
        for side in (0, 1):
            _, idx, _ = KNNMatcher(db.search[side]).query(search_vectors(windows[:, :, side]))
            picked.append(clip_style[idx[idx >= 0]])
        share = np.mean(np.concatenate(picked) == style)
        assert share > 0.75, (style, share)


@pytest.mark.mocap
def test_style_sub_library_changes_the_output(walks):
    truth = walks[("exhausted", 1)]
    stream = VRSetup().sample(truth, seed=0)
    outputs = {}
    for style in STYLES:
        motions = style_sub_library([m for (_, take), m in walks.items() if take != 1], style)
        outputs[style] = CoolMoves(build_database(motions)).run(stream)
        assert np.isfinite(outputs[style].local_rot).all()
    a, b = (body17_positions(outputs[s]) for s in STYLES)
    n = min(len(a), len(b))
    # Same input, other style: a different body (cm apart), and the matching style is closer.
    assert np.linalg.norm(a[:n] - b[:n], axis=-1).mean() > 0.03
    own, other = (body17_errors_cm(outputs[s], truth)["full"] for s in STYLES)
    assert own < other


@pytest.mark.mocap
@pytest.mark.parametrize("arm_ik", [0.0, 1.0])  # the paper's pipeline, and arm IK on top
def test_stepping_a_real_clip_is_the_batch_run(walks, arm_ik):
    """One core: a Bandai take stepped sample by sample is bit for bit the batch run."""
    truth = walks[("exhausted", 1)]
    database = build_database([walks[("exhausted", 2)], walks[("youthful", 2)]])
    synth = CoolMoves(database, options=Options(arm_ik=arm_ik))
    stream = VRSetup().sample(truth[: int(3 * truth.fps)], seed=0)
    batch = synth.run(stream)
    synth.reset()
    poses = [synth.step(TrackingFrame.from_stream(stream, i)) for i in range(stream.n_samples)]
    np.testing.assert_array_equal(np.stack([p.local_rot for p in poses]), batch.local_rot)
    np.testing.assert_array_equal(np.stack([p.root_pos for p in poses]), batch.root_pos)
