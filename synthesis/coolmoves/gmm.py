"""The Gaussian-mixture variant of matching that CoolMoves compares against (§3.1.3, §3.1.5).

"Using the left and right-hand feature vectors, we estimated a mixture of Gaussians to model
the probability of motions, similar to Xia et al. [85] and found it to be accurate but too slow
for our needs" (44 Hz against 82 Hz for nearest neighbours, §3.1.5). The paper gives no more
detail; ours:

1. a Gaussian mixture (full covariances, EM from a k-means start) is fitted to one hand's
   database features; each window belongs to its most responsible component;
2. the probability of window ``i`` given a query ``q`` is a Gaussian kernel centred on the
   window with its component's covariance scaled by Scott's bandwidth
   ``h_c = n_c^(-1 / (d + 4))`` (Scott 1992, *Multivariate Density Estimation*, eq. 6.43),
   times the component's prior: ``p(i | q) ~ pi_c / n_c * N(q; x_i, h_c^2 Sigma_c)``;
3. the ``k`` most probable windows are the matches, weighted by their normalised probability
   (in place of the inverse distance of the nearest-neighbour method).

Every query evaluates all ``N`` windows under their local metric: that is what makes it slower.

The variant is :class:`~synthesis.coolmoves.CoolMoves` with ``Options(matcher="gmm")``: the
same :class:`~synthesis.base.Synthesizer` and core, with this matcher in place of the KD-tree
(``coolmoves-gmm`` in ``avatarsim eval``).
"""

from __future__ import annotations

import numpy as np
from scipy.cluster.vq import kmeans2
from scipy.linalg import solve_triangular

N_COMPONENTS = 16
FIT_SAMPLES = 4096
EM_ITERATIONS = 10
_REGULARISATION = 1e-3  # of the mean feature variance, keeps covariances invertible


def _log_gauss(x: np.ndarray, means: np.ndarray, chol: np.ndarray) -> np.ndarray:
    """``(N, C)`` log densities of ``x (N, F)`` under ``C`` Gaussians (Cholesky factors)."""
    out = np.empty((x.shape[0], means.shape[0]))
    for c in range(means.shape[0]):  # C small solves, each vectorised over all N points
        z = solve_triangular(chol[c], (x - means[c]).T, lower=True)
        log_det = 2.0 * np.sum(np.log(np.diag(chol[c])))
        out[:, c] = -0.5 * (np.sum(z * z, axis=0) + log_det + x.shape[1] * np.log(2 * np.pi))
    return out


def fit_gmm(
    x: np.ndarray, n_components: int, rng: np.random.Generator, n_iter: int = EM_ITERATIONS
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """EM fit of a full-covariance mixture to ``x (N, F)``: weights ``(C,)``, means ``(C, F)``,
    Cholesky factors ``(C, F, F)``."""
    n, f = x.shape
    c = int(min(n_components, n))
    _, labels = kmeans2(x, c, minit="++", seed=rng)
    resp = np.eye(c)[labels]
    reg = _REGULARISATION * np.mean(np.var(x, axis=0)) * np.eye(f)
    for _ in range(n_iter + 1):
        counts = resp.sum(axis=0) + 1e-12
        means = (resp.T @ x) / counts[:, None]
        diff = x[:, None, :] - means[None]  # (N, C, F)
        cov = np.einsum("nc,ncf,ncg->cfg", resp, diff, diff) / counts[:, None, None] + reg
        chol = np.linalg.cholesky(cov)
        log_p = _log_gauss(x, means, chol) + np.log(counts / n)
        log_p -= log_p.max(axis=1, keepdims=True)
        resp = np.exp(log_p)
        resp /= resp.sum(axis=1, keepdims=True)
    return counts / n, means, chol


class GaussianMixtureMatcher:
    """Matches of one side by mixture probability (see the module docstring).

    Same interface as :class:`~synthesis.coolmoves.knn.KNNMatcher`; ``query`` also returns
    the match weights.
    """

    def __init__(
        self,
        vectors: np.ndarray,
        k: int,
        max_distance: float,
        n_components: int = N_COMPONENTS,
        seed: int = 0,
    ):
        x = np.asarray(vectors, float)
        rng = np.random.default_rng(seed)
        fit_rows = rng.choice(len(x), size=min(len(x), FIT_SAMPLES), replace=False)
        weights, means, chol = fit_gmm(x[fit_rows], n_components, rng)
        component = np.argmax(_log_gauss(x, means, chol) + np.log(weights), axis=1)
        counts = np.bincount(component, minlength=len(weights)).astype(float)
        d = x.shape[1]
        bandwidth = np.maximum(counts, 1.0) ** (-1.0 / (d + 4))
        # Whitening per component: w = (h_c L_c)^-1, so kernel distances are plain L2.
        self._whiten = np.stack(
            [np.linalg.inv(chol[c]) / bandwidth[c] for c in range(len(weights))]
        )
        self._component = component
        self._points = np.einsum("nfg,ng->nf", self._whiten[component], x)
        log_det = 2.0 * (np.log(np.diagonal(chol, axis1=1, axis2=2)).sum(1) + d * np.log(bandwidth))
        self._log_prior = (np.log(weights) - np.log(np.maximum(counts, 1.0)) - 0.5 * log_det)[
            component
        ]
        self._vectors = x
        self.k = int(min(k, len(x)))
        self.max_distance = float(max_distance)

    def query(self, queries: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Distances, indices and weights ``(B, k)``, most probable first."""
        queries = np.asarray(queries, float)
        whitened = np.einsum("cfg,bg->bcf", self._whiten, queries)[:, self._component]  # (B,N,F)
        log_p = self._log_prior - 0.5 * np.sum((whitened - self._points) ** 2, axis=-1)
        top = np.argpartition(-log_p, self.k - 1, axis=1)[:, : self.k]
        top = np.take_along_axis(top, np.argsort(-np.take_along_axis(log_p, top, 1), 1), 1)
        dist = np.linalg.norm(self._vectors[top] - queries[:, None], axis=-1)
        far = dist > self.max_distance
        log_top = np.where(far, -np.inf, np.take_along_axis(log_p, top, 1))
        best = np.max(log_top, axis=1, keepdims=True)
        prob = np.where(far, 0.0, np.exp(log_top - np.where(np.isfinite(best), best, 0.0)))
        total = prob.sum(axis=1, keepdims=True)
        weights = np.divide(prob, total, out=np.zeros_like(prob), where=total > 0)
        return np.where(far, np.inf, dist), np.where(far, -1, top), weights
