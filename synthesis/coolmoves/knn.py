"""Per-hand k-nearest-neighbour search on a KD-tree (CoolMoves §3.1.3).

"we use a K-Nearest Neighbor implementation based on a KDTree data structure with a
neighborhood distance threshold, using the L2 norm as our distance metric", separately for
the left and the right hand. The paper's Fig. 3 shows the top 5 matches per hand, hence
``K_NEIGHBOURS = 5``. The paper gives no value for the threshold; ours is in the units of
:mod:`.features` (metres over one window).

The threshold narrows the k nearest to those within it; it never leaves a hand without
matches: when even the nearest window lies beyond it (an input unlike every database window,
e.g. tracking with centimetres of jitter, whose accelerations no clean recording has), the k
nearest are blended all the same, as the paper's pipeline always produces a pose (§3.1.4).
Dropping every match there froze the output in its last pose (hand correlation exactly 0
on 2 cm jitter, a real CMU run and a Bandai wave against generated databases).

The accuracy protocols choose the threshold per fold on a validation split of the fold's
training data (:mod:`synthesis.evaluate.validation`); :data:`MAX_DISTANCE` is the default
elsewhere (scenarios, benchmarks, a plain ``CoolMoves``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.spatial import cKDTree

from avatarsim.synthesis.coolmoves.blend import inverse_distance_weights

K_NEIGHBOURS = 5
"""Matches per hand, as in the paper's Fig. 3 ("top 5 matches")."""
MAX_DISTANCE = 0.6
"""Neighbourhood distance threshold (our choice; the paper gives none), chosen on the built-in
generator's cross-subject evaluation, i.e. seeing its test folds; so the protocols do not use
it as such (:func:`synthesis.evaluate.validation.choose_max_distance` picks from a grid
around it on training data only)."""


SIDE_SEPARATION = 1e6
"""Extra coordinate of the right hand's windows in :class:`BothHandsKNN` (the left's is 0):
far beyond any distance between two windows of one side (metres over one window)."""


def leaf_ordered_tree(points: np.ndarray) -> tuple[cKDTree, np.ndarray]:
    """A sliding-midpoint KD-tree of ``points (N, F)`` whose data rows lie in leaf order, and
    ``order (N,)``, the row of ``points`` each of its rows is (``order[idx]`` maps its query
    indices back).

    Why: ``cKDTree`` keeps the points in input order and reaches a leaf's points through its
    index array, so a query reads rows scattered over the whole data (5 MB for the bench's
    23 218 windows), evicting the rest of a step's working set from the cache. Here the
    same tree (its nodes, from the pickled state) is given its data permuted by that index
    array and the identity as index array: the search visits the same nodes and the same
    points in the same order at the same distances (ties break alike), reading each
    leaf's points from consecutive rows. Sliding-midpoint splits: median splits
    (``balanced_tree``) make deeper, costlier queries on these clustered windows (twice the
    p99 query time); both are exact.
    """
    tree = cKDTree(np.asarray(points, float), balanced_tree=False)
    state = list(tree.__getstate__())  # nodes, data, n, m, leafsize, maxes, mins, indices, ...
    order = state[7] if len(state) == 10 else None
    if order is None or not (
        np.array_equal(order, tree.indices) and state[1].shape == tree.data.shape
    ):
        return tree, np.arange(tree.n)  # another scipy's state layout: the plain tree
    state[1], state[7] = np.ascontiguousarray(state[1][order]), np.arange(tree.n)
    ordered = cKDTree.__new__(cKDTree)
    ordered.__setstate__(tuple(state))
    return ordered, order


def within_threshold(dist: np.ndarray, idx: np.ndarray, max_distance: float):
    """The k nearest ``dist, idx (..., k)`` (nearest first) narrowed to those within
    ``max_distance``, or all k where even the nearest is beyond it; the dropped ones get
    distance ``inf`` and index -1. Returns ``(dist, idx, inverse-distance weights)``."""
    keep = (dist <= max_distance) | (dist[..., :1] > max_distance)
    dist = np.where(keep, dist, np.inf)  # untracked sides come as inf and stay so
    return dist, np.where(np.isfinite(dist), idx, -1), inverse_distance_weights(dist)


class KNNMatcher:
    """k nearest database windows of one side, within ``max_distance``.

    Args:
        vectors: ``(N, F)`` search vectors of the database windows.
    """

    def __init__(
        self, vectors: np.ndarray, k: int = K_NEIGHBOURS, max_distance: float = MAX_DISTANCE
    ):
        self.k = int(min(k, len(vectors)))
        self.max_distance = float(max_distance)
        self.tree, self._order = leaf_ordered_tree(vectors)

    def query(self, queries: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Distances, indices and blend weights ``(B, k)`` for ``queries (B, F)``, nearest
        first; weights are inversely proportional to distance (§3.1.4).

        Matches dropped by the threshold (:func:`within_threshold`) have distance ``inf``,
        index ``-1`` and weight 0.
        """
        dist, idx = self.tree.query(queries, k=list(range(1, self.k + 1)), workers=1)
        return within_threshold(dist, self._order[idx], self.max_distance)


class BothHandsKNN:
    """Both hands' :class:`KNNMatcher` searches in one KD-tree, so that one sample costs one
    query call (the per-call set-up of ``cKDTree.query`` is most of a single query's time).

    The sides' vectors get one extra coordinate, 0 for the left hand and
    :data:`SIDE_SEPARATION` for the right: a query carrying its side's coordinate finds its
    k nearest on its own side, at the distances of the side's own tree (the extra term is
    exactly 0).

    Measured on the ``avatarsim bench coolmoves`` database (11 609 windows a side, per-frame
    best of 5, thread CPU time, a loaded 2-core machine): this query takes 78 us at the
    median, 150 us at p99, of which about 37 us is ``cKDTree.query``'s fixed cost per call
    (a 50-point tree costs as much). Two per-side trees took 103 / 179 us; leaf sizes 24 to
    96 gained nothing reliable and reorder equidistant matches; a brute-force product with
    ``argpartition`` took 440 us; the previous step's k-th distance as
    ``distance_upper_bound`` gained nothing (a window's neighbours are found fast, proving
    them is the cost). In a step the query costs about twice as much as alone: the rest of
    the step evicts the tree from the cache. With the data in leaf order
    (:func:`leaf_ordered_tree`), ``cKDTree.query`` inside the bench's steps (per frame best
    of 9, passes alternating with scipy's layout, three rounds at load 3.8-4.1) took
    112-120 / 226-338 us at p50 / p99, against 123-152 / 288-386 us; alone, with 4 MB read
    between queries (four rounds at load 2.1-2.4), 77-81 / 152-211 against 86-139 / 189-274.

    Args:
        vectors: per side (left, right) ``(N_s, F)`` search vectors of the database windows.
    """

    def __init__(
        self,
        vectors: Sequence[np.ndarray],
        k: int = K_NEIGHBOURS,
        max_distance: float = MAX_DISTANCE,
    ):
        self.k = int(min(k, *(len(v) for v in vectors)))
        self.max_distance = float(max_distance)
        self._side_coord = np.array([0.0, SIDE_SEPARATION])
        self._first = np.cumsum([0] + [len(v) for v in vectors[:-1]])  # (2,) index offsets
        points = np.concatenate(
            [
                np.column_stack([np.asarray(v, float), np.full(len(v), c)])
                for v, c in zip(vectors, self._side_coord, strict=True)
            ]
        )
        self.tree, order = leaf_ordered_tree(points)
        # The side-relative index of each tree row (the right side's offset taken off).
        self._order = order - self._first[np.searchsorted(self._first, order, "right") - 1]

    def query(
        self, queries: np.ndarray, tracked: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Distances, per-side indices and weights ``(2, B, k)`` for ``queries (B, 2, F)``
        (left, right); sides not ``tracked (B, 2)`` get no matches (``inf``, -1, 0)."""
        b = queries.shape[0]
        points = np.empty((b, 2, queries.shape[-1] + 1))
        points[..., :-1] = np.where(tracked[..., None], queries, 0.0)  # NaN-free
        points[..., -1] = self._side_coord
        dist, idx = self.tree.query(points.reshape(2 * b, -1), k=self.k, workers=1)
        dist = np.where(tracked[..., None], dist.reshape(b, 2, self.k), np.inf)
        idx = self._order[idx.reshape(b, 2, self.k)]
        return within_threshold(dist.transpose(1, 0, 2), idx.transpose(1, 0, 2), self.max_distance)


class PerHand:
    """One matcher per side behind :class:`BothHandsKNN`'s interface (for matchers, like the
    mixture variant's, that cannot share one search structure)."""

    def __init__(self, matchers: Sequence):
        self.matchers = list(matchers)
        self.k = self.matchers[0].k

    def query(
        self, queries: np.ndarray, tracked: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """As :meth:`BothHandsKNN.query`."""
        b = queries.shape[0]
        dist = np.full((2, b, self.k), np.inf)
        idx = np.full((2, b, self.k), -1)
        weights = np.zeros((2, b, self.k))
        for side, matcher in enumerate(self.matchers):
            rows = np.flatnonzero(tracked[:, side])
            if rows.size:
                dist[side, rows], idx[side, rows], weights[side, rows] = matcher.query(
                    queries[rows, side]
                )
        return dist, idx, weights
