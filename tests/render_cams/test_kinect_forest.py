"""The forest's numpy evaluation against scikit-learn's own prediction on the same trees."""

from __future__ import annotations

import numpy as np
import pytest
from sklearn.ensemble import ExtraTreesClassifier

from avatarsim.render_cams.kinect.features import DepthFeatures
from avatarsim.render_cams.kinect.forest import from_sklearn, load_forest
from avatarsim.render_cams.kinect.sensors import KinectError

K = np.array([[200.0, 0.0, 32.0], [0.0, 200.0, 24.0], [0.0, 0.0, 1.0]])


def blob_frames(rng: np.random.Generator, n: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """``n`` ``(48, 64)`` depth images of a box at 1.5-2.5 m on a 10 m background, labelled
    by quadrant of the box (classes 0..3): a task the depth features can learn."""
    frames = []
    for _ in range(n):
        depth = np.full((48, 64), 10.0, np.float32)
        labels = np.full((48, 64), -1)
        r0, c0 = rng.integers(4, 16), rng.integers(4, 24)
        h, w = rng.integers(20, 28), rng.integers(24, 34)
        depth[r0 : r0 + h, c0 : c0 + w] = rng.uniform(1.5, 2.5)
        rr, cc = np.mgrid[r0 : r0 + h, c0 : c0 + w]
        labels[rr, cc] = 2 * (rr >= r0 + h // 2) + (cc >= c0 + w // 2)
        frames.append((depth, labels))
    return frames


@pytest.fixture(scope="module")
def fitted():
    rng = np.random.default_rng(0)
    features = DepthFeatures.sample(40, 0.3, rng)
    X, y, pixels = [], [], []
    for depth, labels in blob_frames(rng, 12):
        rows, cols = np.nonzero(labels >= 0)
        X.append(features.evaluate(depth, K, rows, cols, np.arange(40)[None]))
        y.append(labels[rows, cols])
        pixels.append((depth, rows, cols))
    model = ExtraTreesClassifier(n_estimators=3, max_depth=8, random_state=0, n_jobs=1)
    model.fit(np.concatenate(X).astype(np.float32), np.concatenate(y))
    return model, features, pixels


def test_numpy_evaluation_equals_sklearn_predict_proba(fitted):
    model, features, pixels = fitted
    forest = from_sklearn(model, features, 4)
    for depth, rows, cols in pixels[:4]:
        X = features.evaluate(depth, K, rows, cols, np.arange(40)[None]).astype(np.float32)
        ours = forest.predict_proba(depth, K, rows, cols)
        np.testing.assert_allclose(ours, model.predict_proba(X), atol=1e-6)
    assert forest.depth == max(e.tree_.max_depth for e in model.estimators_)


def test_absent_classes_get_probability_zero(fitted):
    model, features, pixels = fitted
    forest = from_sklearn(model, features, 6)  # classes 4 and 5 never seen
    depth, rows, cols = pixels[0]
    probs = forest.predict_proba(depth, K, rows, cols)
    assert probs.shape == (len(rows), 6)
    np.testing.assert_array_equal(probs[:, 4:], 0.0)
    np.testing.assert_allclose(probs.sum(1), 1.0, atol=1e-6)


def test_a_saved_forest_predicts_the_same_classes_with_its_metadata(fitted, tmp_path):
    model, features, pixels = fitted
    forest = from_sklearn(model, features, 4)
    path = forest.save(tmp_path / "f.npz", {"seed": 7, "config": {"trees": 3}})
    loaded, meta = load_forest(path)
    assert meta == {"seed": 7, "config": {"trees": 3}}
    for depth, rows, cols in pixels[:4]:
        X = features.evaluate(depth, K, rows, cols, np.arange(40)[None]).astype(np.float32)
        ours = loaded.predict_proba(depth, K, rows, cols)
        # Leaf distributions are stored in 1/255 steps.
        np.testing.assert_allclose(ours, model.predict_proba(X), atol=3 / 255)


def test_a_file_that_is_no_forest_is_refused(tmp_path):
    bad = tmp_path / "bad.npz"
    np.savez(bad, something=np.zeros(3))
    with pytest.raises(KinectError, match="not a Kinect tracker model"):
        load_forest(bad)
    with pytest.raises(KinectError, match="not a Kinect tracker model"):
        load_forest(tmp_path / "missing.npz")
