"""Known-answer tests of the CoolMoves building blocks (features, filter, search, alignment,
blending, smoothing, limits)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.synthesis.coolmoves import correlation
from avatarsim.synthesis.coolmoves.alignment import alignment_yaw, ramp_weights, turn_about_vertical
from avatarsim.synthesis.coolmoves.blend import (
    blend_rotations,
    group_weights,
    inverse_distance_weights,
)
from avatarsim.synthesis.coolmoves.features import (
    RATE_HZ,
    WINDOW_SAMPLES,
    feature_vectors,
    search_vectors,
    speed_windows,
    window_stride,
)
from avatarsim.synthesis.coolmoves.knn import (
    K_NEIGHBOURS,
    BothHandsKNN,
    KNNMatcher,
    leaf_ordered_tree,
)
from avatarsim.synthesis.coolmoves.limits import JointLimits
from avatarsim.synthesis.coolmoves.smoothing import ewma, ewma_step
from tests.synthesis.conftest import yaw_matrix


def test_window_geometry_is_the_papers():
    """§3.1.2: 90 Hz, 100 ms windows of 9 samples overlapping their neighbours by 50 ms
    (half a window); §3.1.3: the top 5 matches per hand."""
    assert RATE_HZ == 90.0 and WINDOW_SAMPLES == 9 and K_NEIGHBOURS == 5
    shared = WINDOW_SAMPLES - window_stride(WINDOW_SAMPLES, RATE_HZ)
    # 50 ms at 90 Hz is 4.5 sample periods: the windows share 4 or 5 samples.
    assert abs(shared - 0.5 * WINDOW_SAMPLES) <= 0.5


def test_alignment_contributions_step_from_zero():
    """§3.1.4: "c_i from 0 to 1, increasing them in step-size 1/n" from the oldest sample."""
    c = ramp_weights(9)
    assert c[0] == 0.0
    np.testing.assert_allclose(np.diff(c), 1 / 9)
    # The reading that ends at exactly 1 (step 1/(n-1)) is a constant factor away: the
    # closed form gives the same angle, with and without the centroid terms.
    rng = np.random.default_rng(4)
    query, source = rng.normal(size=(1, 9, 2, 3)), rng.normal(size=(1, 3, 9, 2, 3))
    for centroid in (False, True):
        ours = alignment_yaw(query, source, free_translation=centroid)
        scaled = alignment_yaw(query, source, np.full((1, 2), 9 / 8), centroid)
        np.testing.assert_allclose(ours, scaled, atol=1e-12)
    # The oldest sample does not count: changing it does not turn the match.
    moved = query.copy()
    moved[:, 0] += 5.0
    np.testing.assert_allclose(alignment_yaw(moved, source), alignment_yaw(query, source))


def test_search_vectors_preserve_feature_distances():
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(2, 50, 9, 3))
    full = np.linalg.norm(feature_vectors(a) - feature_vectors(b), axis=-1)
    reduced = np.linalg.norm(search_vectors(a) - search_vectors(b), axis=-1)
    np.testing.assert_allclose(reduced, full, rtol=1e-10)
    assert feature_vectors(a).shape == (50, 81) and search_vectors(a).shape == (50, 27)


def test_features_of_constant_velocity_window():
    # p_i = v * i / 90: velocity v everywhere, acceleration 0; W = 8/90 s.
    v = np.array([0.9, -0.45, 0.18])
    window = np.arange(9)[:, None] / 90.0 * v
    f = feature_vectors(window).reshape(27, 3)
    np.testing.assert_allclose(f[:9], window)
    np.testing.assert_allclose(f[9:18], np.tile(v * 8 / 90, (9, 1)), atol=1e-12)
    np.testing.assert_allclose(f[18:], 0.0, atol=1e-9)


def test_speed_window_scales_velocity_and_keeps_last_sample():
    series = (np.arange(40) ** 2 / 100.0)[:, None]  # x = t^2 / 100 (frames)
    ends = np.array([20, 30])
    for speed in (0.5, 1.0, 1.5):
        w = speed_windows(series, ends, speed)
        np.testing.assert_allclose(w[:, -1, 0], series[ends, 0])
        # Sample i sits at frame end - speed * (8 - i).
        expected_frames = ends[:, None] - speed * np.arange(8, -1, -1)[None]
        exact = expected_frames**2 / 100.0
        np.testing.assert_allclose(w[..., 0], exact, atol=0.01 * speed)  # linear interpolation


def test_pearson_filter_by_hand():
    a = np.array([1.0, 2.0, 3.0, 4.0])  # deviations -1.5 -0.5 0.5 1.5
    b = np.array([1.0, 3.0, 2.0, 4.0])  # deviations -1.5 0.5 -0.5 1.5: r = 4 / 5 = 0.8
    assert correlation.pearson(a, b) == pytest.approx(0.8)
    # Hands and feet as one (X, Y, Z) series each (§3.1.2): x moving as a and b, y still,
    # z at their heights; r of the 12-value series, the same for all four pairs.
    hands, feet = np.zeros((2, 4, 2, 3))
    hands[..., 0], feet[..., 0] = a[:, None], b[:, None]
    hands[..., 2], feet[..., 2] = -0.3, -1.5
    expected = np.corrcoef(hands[:, 0].T.ravel(), feet[:, 0].T.ravel())[0, 1]
    assert correlation.hand_foot_correlation(hands, feet) == pytest.approx(expected)
    assert correlation.keeps(hands, feet)
    # Signed: feet moving against the hands, below them, do not pass.
    assert correlation.hand_foot_correlation(hands, feet * [-1, 1, -1]) < -0.5
    assert not correlation.keeps(hands, feet * [-1, 1, -1])


def test_pearson_of_quadrature_signals_is_zero():
    t = np.arange(360) / 90.0
    assert correlation.pearson(np.sin(2 * np.pi * t), np.cos(2 * np.pi * t)) == pytest.approx(
        0.0, abs=1e-9
    )


def test_query_identical_to_database_window_returns_it(small_db):
    for side in (0, 1):
        matcher = KNNMatcher(small_db.search[side], k=5, max_distance=0.5)
        i = small_db.n_windows // 3
        dist, idx, _ = matcher.query(search_vectors(small_db.windows[[i], :, side]))
        assert dist[0, 0] == 0.0
        np.testing.assert_array_equal(
            small_db.windows[idx[0, 0], :, side], small_db.windows[i, :, side]
        )
        assert np.all(np.diff(dist[0][np.isfinite(dist[0])]) >= 0)


def test_knn_threshold_drops_far_matches_but_never_all(small_db):
    """Within the threshold only the near matches count; an input beyond it from every
    window still gets its k nearest (the output must not freeze)."""
    exact = search_vectors(small_db.windows[[0], :, 0])
    tree = KNNMatcher(small_db.search[0], k=5, max_distance=1e9)
    second = tree.query(exact)[0][0, 1]
    near = KNNMatcher(small_db.search[0], k=5, max_distance=second / 2)
    dist, idx, w = near.query(exact)
    assert dist[0, 0] == 0.0 and np.all(np.isinf(dist[0, 1:])) and np.all(idx[0, 1:] == -1)
    assert w[0, 0] == pytest.approx(1.0)
    far = search_vectors(small_db.windows[[0], :, 0] + 1.0)
    dist, idx, w = KNNMatcher(small_db.search[0], k=5, max_distance=1e-6).query(far)
    assert np.all(np.isfinite(dist)) and np.all(idx >= 0)
    assert w.sum() == pytest.approx(1.0) and np.all(np.diff(dist[0]) >= 0)


def test_leaf_ordered_tree_answers_as_scipys_tree():
    """The same neighbours, distances and order as a plain ``cKDTree``, ties included
    (duplicated points, as held poses give), with the data stored in another order."""
    rng = np.random.default_rng(3)
    points = rng.normal(size=(3000, 6))
    points[1000:1400] = points[:400]  # exact duplicates: equidistant from every query
    points[2000:2100] = 0.0
    queries = np.concatenate([rng.normal(size=(200, 6)), points[:50], np.zeros((5, 6))])
    tree, order = leaf_ordered_tree(points)
    assert not np.array_equal(order, np.arange(len(points)))
    np.testing.assert_array_equal(tree.data, points[order])
    want = cKDTree(points, balanced_tree=False).query(queries, k=8)
    got_dist, got_idx = tree.query(queries, k=8)
    np.testing.assert_array_equal(got_dist, want[0])
    np.testing.assert_array_equal(order[got_idx], want[1])


def test_knn_k_of_one(small_db):
    dist, idx, w = KNNMatcher(small_db.search[0], k=1).query(small_db.search[0][:3])
    assert dist.shape == idx.shape == w.shape == (3, 1) and np.all(w == 1.0)
    # Both hands in one tree: database windows of each side find themselves, k = 1 too.
    queries = np.stack([small_db.search[0][:3], small_db.search[1][5:8]], axis=1)  # (3, 2, F)
    for k in (1, K_NEIGHBOURS):
        dist, idx, _ = BothHandsKNN(small_db.search, k=k).query(queries, np.ones((3, 2), bool))
        assert dist.shape == idx.shape == (2, 3, k)
        np.testing.assert_array_equal(dist[:, :, 0], 0.0)
        np.testing.assert_array_equal(idx[:, :, 0], [[0, 1, 2], [5, 6, 7]])


@pytest.mark.parametrize("theta", [0.3, -1.2, 2.9, np.pi / 2])
def test_alignment_recovers_known_yaw(theta):
    rng = np.random.default_rng(1)
    query = rng.normal(scale=0.3, size=(1, 9, 2, 3))
    # The database copy is the query turned by -theta and shifted sideways: turning it back by
    # +theta aligns it (the 1/sum c terms make the answer independent of the shift).
    source = query @ yaw_matrix(-theta).T + np.array([0.2, -0.1, 0.05])
    got = alignment_yaw(query, source[:, None], free_translation=True)
    assert got[0, 0] == pytest.approx(theta, abs=1e-9)
    # About the head (the default) a copy turned about the head is undone exactly.
    about_head = alignment_yaw(query, (query @ yaw_matrix(-theta).T)[:, None])
    assert about_head[0, 0] == pytest.approx(theta, abs=1e-9)


def test_turning_matches_about_the_vertical_is_scipys_turn():
    rng = np.random.default_rng(3)
    poses = Rotation.random(60, random_state=4)
    yaw = rng.uniform(-np.pi, np.pi, 60)
    got = turn_about_vertical(quat.from_scipy(poses), yaw)
    expected = Rotation.from_rotvec(yaw[:, None] * [0.0, 0.0, 1.0]) * poses
    np.testing.assert_allclose(quat.to_matrix(got), expected.as_matrix(), atol=1e-12)
    # The same numbers as the general product it shortens (streaming relies on it).
    general = quat.mul(quat.from_axis_angle(np.array([0.0, 0, 1]), yaw), quat.from_scipy(poses))
    np.testing.assert_array_equal(got, general)


def test_alignment_about_head_keeps_forward_reach():
    """Two hands held forward of the head, the right one punching further: the centred cloud
    (paper's printed form) is turned to fit the hand-to-hand vector, the head pivot keeps the
    forward reach and finds a far smaller yaw."""
    t = np.linspace(0.0, 1.0, 9)[:, None]
    query = np.stack([[0.35, 0.2, -0.3] + 0 * t, [0.35, -0.2, -0.3] + t * [0.25, 0, 0]], 1)
    source = np.stack([[0.35, 0.2, -0.3] + 0 * t, [0.35, -0.2, -0.3] + 0 * t], 1)
    about_centroid = alignment_yaw(query[None], source[None, None], free_translation=True)
    about_head = alignment_yaw(query[None], source[None, None])
    assert abs(about_centroid[0, 0]) > 3 * abs(about_head[0, 0])


def test_alignment_weights_favour_the_newest_samples():
    """The samples agree on a turn of 0.5 rad but one: the oldest (c = 0) leaves the angle
    exactly 0.5, the newest (c = 8/9) pulls it toward its own 0.4 rad less than all."""
    rng = np.random.default_rng(2)
    query = rng.normal(scale=0.3, size=(1, 9, 2, 3))
    source = query @ yaw_matrix(-0.5).T
    oldest, newest = source.copy(), source.copy()
    oldest[:, 0] = query[:, 0] @ yaw_matrix(-0.4).T
    newest[:, -1] = query[:, -1] @ yaw_matrix(-0.4).T
    assert alignment_yaw(query, oldest[:, None])[0, 0] == pytest.approx(0.5, abs=1e-12)
    pulled = alignment_yaw(query, newest[:, None])[0, 0]
    assert 0.4 < pulled < 0.5 - 1e-3


def test_alignment_ignores_untracked_hand():
    rng = np.random.default_rng(3)
    query = rng.normal(scale=0.3, size=(1, 9, 2, 3))
    source = query @ yaw_matrix(-0.7).T
    source[:, :, 1] = rng.normal(size=(9, 3))  # right hand garbage in the database window
    query[:, :, 1] = np.nan  # and untracked in the query
    got = alignment_yaw(query, source[:, None], side_weights=np.array([[1.0, 0.0]]))
    assert got[0, 0] == pytest.approx(0.7, abs=1e-9)


def test_alignment_per_match_fits_each_hands_own_window():
    """§3.1.4 aligns "the input feature vector" q and "the feature vector from the MoCap
    database" s, and a feature vector is one hand's window (§3.1.2): with side weights per
    match, a left-hand match turns to fit the left hand whatever the right hand of its
    database window does, a right-hand match the right hand."""
    rng = np.random.default_rng(5)
    query = rng.normal(scale=0.3, size=(1, 9, 2, 3))
    source = rng.normal(scale=0.3, size=(1, 2, 9, 2, 3))  # garbage where not set below
    source[0, 0, :, 0] = query[0, :, 0] @ yaw_matrix(-0.3).T
    source[0, 1, :, 1] = query[0, :, 1] @ yaw_matrix(-0.6).T
    own_hand = np.array([[[1.0, 0.0], [0.0, 1.0]]])  # (B, K, S)
    np.testing.assert_allclose(alignment_yaw(query, source, own_hand)[0], [0.3, 0.6], atol=1e-9)
    # Per-match weights equal for every match are the per-query weights.
    both = np.array([[1.0, 1.0]])
    np.testing.assert_array_equal(
        alignment_yaw(query, source, np.repeat(both[:, None], 2, axis=1)),
        alignment_yaw(query, source, both),
    )


def test_inverse_distance_weights_by_hand():
    w = inverse_distance_weights(np.array([[1.0, 2.0, np.inf], [np.inf, np.inf, np.inf]]))
    np.testing.assert_allclose(w, [[2 / 3, 1 / 3, 0.0], [0.0, 0.0, 0.0]], atol=1e-8)
    exact = inverse_distance_weights(np.array([[0.0, 0.1, 0.2]]))
    assert exact[0, 0] > 0.999999


def test_group_weights_route_hands_to_their_arms():
    dl = np.array([[0.1, 0.2]])
    dr = np.array([[0.3, np.inf]])
    weights, conf = group_weights(np.stack([dl, dr]), max_distance=0.5)
    np.testing.assert_allclose(weights[0, 0], [2 / 3, 1 / 3, 0, 0], atol=1e-8)
    np.testing.assert_allclose(weights[0, 1], [0, 0, 1, 0], atol=1e-8)
    # Each match's likelihood t / (t + d): 0.5/0.6 and 0.5/0.7 on the left, 0.5/0.8 right.
    ql = 2 / 3 * 5 / 6 + 1 / 3 * 5 / 7
    qr = 5 / 8
    np.testing.assert_allclose(conf[0], [ql, qr, (ql + qr) / 2])
    share = ql / (ql + qr)
    np.testing.assert_allclose(weights[0, 2], [share * 2 / 3, share / 3, 1 - share, 0], atol=1e-8)


def test_blending_one_match_reproduces_it():
    pose = quat.from_scipy(Rotation.random(7, random_state=5))[None, None]  # (1, 1, 7, 4)
    other = quat.from_scipy(Rotation.random(7, random_state=6))[None, None]
    weights = np.zeros((1, 7, 2))
    weights[..., 0] = 1.0
    out = blend_rotations(np.concatenate([pose, other], axis=1), weights)
    assert np.allclose(np.abs(np.sum(out[0] * pose[0, 0], axis=-1)), 1.0)
    # Two matches, equal weights: the midpoint (slerp at 1/2) for nearby rotations.
    a = quat.from_axis_angle(np.array([0, 0, 1.0]), np.array(0.2))
    b = quat.from_axis_angle(np.array([0, 0, 1.0]), np.array(-0.6))
    mid = blend_rotations(np.stack([a, -b])[None, :, None], np.full((1, 1, 2), 0.5))
    assert quat.yaw(mid[0, 0]) == pytest.approx(-0.2)


def test_ewma_weight_one_is_identity_and_zero_holds():
    prev = quat.from_scipy(Rotation.random(5, random_state=1))
    cur = quat.from_scipy(Rotation.random(5, random_state=2))
    np.testing.assert_allclose(np.abs(np.sum(ewma_step(prev, cur, np.ones(5)) * cur, -1)), 1.0)
    np.testing.assert_allclose(ewma_step(prev, cur, np.zeros(5)), prev)
    seq = quat.from_scipy(Rotation.random(30, random_state=3), (6, 5))
    out = ewma(seq, np.ones((6, 5)), prev)
    np.testing.assert_allclose(np.abs(np.sum(out * seq, -1)), 1.0)


def test_ewma_half_weight_is_halfway():
    a = quat.from_axis_angle(np.array([1.0, 0, 0]), np.array([0.0]))
    b = quat.from_axis_angle(np.array([1.0, 0, 0]), np.array([0.4]))
    mid = ewma_step(a, b, np.array([0.5]))
    assert quat.angle(mid)[0] == pytest.approx(0.2)


def test_joint_limits_clamp_knee_and_keep_legal_poses():
    sk = load_rig("avatar").skeleton
    limits = JointLimits(sk)
    rot = np.tile(quat.IDENTITY, (2, sk.n_joints, 1))
    knee = sk.index("Bip01 L Calf")
    # Knee flexion is +ry up to 140 degrees: 170 is clipped to 140, 60 is kept.
    rot[0, knee] = quat.from_axis_angle(np.array([0, 1.0, 0]), np.array(np.radians(170)))
    rot[1, knee] = quat.from_axis_angle(np.array([0, 1.0, 0]), np.array(np.radians(60)))
    out = limits.clamp(rot)
    assert np.degrees(quat.angle(out[0, knee])) == pytest.approx(140.0)
    np.testing.assert_allclose(out[1], rot[1])
