"""A randomised decision forest over :mod:`.features`, stored as plain arrays.

Trained with scikit-learn (:func:`from_sklearn`), kept as the trees' arrays (feature index,
threshold, children, leaf class distributions; scikit-learn's ``tree_`` attributes) in an
``.npz`` file, and evaluated with vectorised numpy: loading a model reads numbers and never
runs code (no pickle), and the tracker needs no scikit-learn at run time. A pixel descends
each tree computing only the features on its path (Shotton section 3.2: depth ~20, a few
trees); the class distribution is the mean of its leaves'.
"""

from __future__ import annotations

import json
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from avatarsim.avatar_models.fileio import atomic_file
from avatarsim.render_cams.kinect.features import DepthFeatures
from avatarsim.render_cams.kinect.sensors import KinectError

LEAF = -1
"""Child index of a leaf (scikit-learn's ``TREE_LEAF``)."""


@dataclass(frozen=True, eq=False)
class Forest:
    """``N`` nodes of all trees together, ``C`` classes.

    Attributes:
        features: the depth features the nodes test.
        roots: ``(n_trees,)`` node index of each tree's root.
        feature: ``(N,)`` int feature tested at a split node.
        threshold: ``(N,)`` float32 metres: go left when the feature is ``<=`` it.
        left, right: ``(N,)`` int32 children (:data:`LEAF` at leaves).
        leaf_probs: ``(N, C)`` float32 class distribution (used at leaves).
        depth: the deepest tree's depth (number of splits on its longest path).
    """

    features: DepthFeatures
    roots: np.ndarray
    feature: np.ndarray
    threshold: np.ndarray
    left: np.ndarray
    right: np.ndarray
    leaf_probs: np.ndarray
    depth: int

    @property
    def n_classes(self) -> int:
        return self.leaf_probs.shape[1]

    def predict_proba(
        self, depth: np.ndarray, K: np.ndarray, rows: np.ndarray, cols: np.ndarray
    ) -> np.ndarray:
        """``(N, C)`` class probabilities of pixels ``(rows, cols)`` of a body depth image
        (:func:`~render_cams.kinect.features.body_depth`) with intrinsics ``K``."""
        probs = np.zeros((len(rows), self.n_classes), np.float32)
        for root in self.roots:
            node = np.full(len(rows), root, np.int32)
            active = np.flatnonzero(self.left[node] != LEAF)
            while active.size:
                at = node[active]
                value = self.features.evaluate(
                    depth, K, rows[active], cols[active], self.feature[at]
                )
                node[active] = np.where(value <= self.threshold[at], self.left[at], self.right[at])
                active = active[self.left[node[active]] != LEAF]
            probs += self.leaf_probs[node]
        return probs / len(self.roots)

    def save(self, path: str | Path, meta: dict[str, Any]) -> Path:
        """Write the forest and ``meta`` (JSON-ready: config, seed, data hash...) to ``path``
        atomically (the whole file or nothing)."""
        path = Path(path)
        with atomic_file(path) as fh:
            np.savez_compressed(
                fh,
                u=self.features.u.astype(np.float32),
                v=self.features.v.astype(np.float32),
                roots=self.roots.astype(np.int32),
                feature=self.feature.astype(np.int16),
                threshold=self.threshold.astype(np.float32),
                left=self.left.astype(np.int32),
                right=self.right.astype(np.int32),
                leaf_probs=np.rint(self.leaf_probs * 255).astype(np.uint8),
                depth=np.int32(self.depth),
                meta=np.array(json.dumps(meta, sort_keys=True)),
            )
        return path


def load_forest(path: str | Path) -> tuple[Forest, dict[str, Any]]:
    """The forest and its metadata from a file written by :meth:`Forest.save`.

    Raises:
        KinectError: not such a file.
    """
    try:
        with np.load(path, allow_pickle=False) as z:
            probs = z["leaf_probs"].astype(np.float32)
            forest = Forest(
                DepthFeatures(z["u"].astype(float), z["v"].astype(float)),
                z["roots"],
                z["feature"].astype(np.intp),
                z["threshold"],
                z["left"],
                z["right"],
                probs / np.maximum(probs.sum(1, keepdims=True), 1.0),
                int(z["depth"]),
            )
            meta = json.loads(str(z["meta"]))
    except (OSError, KeyError, ValueError, IndexError, TypeError, zipfile.BadZipFile) as exc:
        raise KinectError(f"{path}: not a Kinect tracker model ({exc})") from exc
    return forest, meta


def from_sklearn(model, features: DepthFeatures, n_classes: int) -> Forest:
    """A :class:`Forest` from a fitted scikit-learn forest classifier whose classes are
    integers in ``0..n_classes-1`` (absent classes get probability 0)."""
    roots, feature, threshold, left, right, probs = [], [], [], [], [], []
    offset = 0
    classes = np.asarray(model.classes_, int)
    for estimator in model.estimators_:
        tree = estimator.tree_
        roots.append(offset)
        feature.append(np.maximum(tree.feature, 0))
        threshold.append(tree.threshold.astype(np.float32))
        for children, out in ((tree.children_left, left), (tree.children_right, right)):
            out.append(np.where(children == LEAF, LEAF, children + offset))
        value = tree.value[:, 0, :]
        full = np.zeros((tree.node_count, n_classes), np.float32)
        full[:, classes] = value / np.maximum(value.sum(1, keepdims=True), 1e-12)
        probs.append(full)
        offset += tree.node_count
    return Forest(
        features,
        np.array(roots, np.int32),
        np.concatenate(feature).astype(np.intp),
        np.concatenate(threshold),
        np.concatenate(left).astype(np.int32),
        np.concatenate(right).astype(np.int32),
        np.concatenate(probs),
        max(int(e.tree_.max_depth) for e in model.estimators_),
    )
