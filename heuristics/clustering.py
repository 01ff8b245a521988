"""Clustering of viewpoints into one group per UAV: DPC and the paper's ADPC.

Both follow the scikit-learn contract so that :class:`sklearn.cluster.KMeans` drops into the
same slot: ``__init__`` only stores hyperparameters, ``fit(X)`` returns ``self`` and sets
``labels_`` (cluster of each row of X) and ``cluster_centers_`` (centre coordinates), plus
``centers_`` (row indices of the centres in X).

Density peaks (Rodriguez & Laio, Science 344:1492, 2014), Gaussian kernel:

* ρ_i = Σ_{j≠i} exp(-(d_ij / d_c)²);
* δ_i = distance to the nearest point of higher density (ties in ρ broken by row order, so the
  "denser" relation is a strict total order); the densest point takes its largest distance;
* γ_i = ρ_i·δ_i; the ``n_clusters`` points of largest γ are the centres.

Cut-off d_c: by default the 2nd percentile of the pairwise distances, Rodriguez & Laio's rule of
thumb (each point has on average 1–2 % of the points as neighbours). On the paper's SAR
instances (K views H·cosθ ≈ 141 m around each target) this makes d_c about the spacing of a
target's own views, so ρ counts neighbouring targets only through the Gaussian tail.

DPC assigns every other point, in decreasing density, to the cluster of its nearest denser
point. ADPC (the paper's) keeps the same centres and instead assigns the remaining points in
order farthest-from-base first, each to the centre minimising

    σ_i = D(v, C_i) · ω_i^(ξ·r_i),

where ω_i is the current size of cluster i, r_i = ‖C_i − base‖ / mean_k ‖C_k − base‖ and ξ is the
expansion index. A cluster starts with its centre, so ω_i ≥ 1 and ω_i = 0 never occurs (with
ω_i = 0 every σ_i would be 0 and the first points would go to an arbitrary centre). Large r_i
(far centres) make the penalty grow fastest, so far clusters stay small: their UAV spends its
energy flying out, not imaging.

Defaults: ξ = 0.25 and d_c at the 2nd percentile. A larger ξ costs coverage on the paper preset
(the big near-base clusters it creates overflow their budget); ξ = 0.25 keeps the paper's idea at a
small cost. The tuning tables are in ``docs/heuristics.md``.

When there are fewer points than clusters, every point is its own cluster
(``n_clusters_`` tells how many were made).
"""

from __future__ import annotations

import numpy as np


def pairwise_distances(X: np.ndarray) -> np.ndarray:
    diff = X[:, None, :] - X[None, :, :]
    return np.sqrt((diff**2).sum(axis=-1))


def cutoff_distance(D: np.ndarray, percentile: float) -> float:
    """d_c: the given percentile of the pairwise distances (i < j); 1.0 if all are zero."""
    n = D.shape[0]
    if n < 2:
        return 1.0
    d = D[np.triu_indices(n, k=1)]
    dc = float(np.percentile(d, percentile))
    if dc <= 0.0:
        positive = d[d > 0]
        dc = float(positive.min()) if positive.size else 1.0
    return dc


def density_peaks(D: np.ndarray, dc: float):
    """(ρ, δ, nearest denser neighbour, density order) of Rodriguez & Laio.

    ``order`` lists the points by decreasing ρ (stable in row order); ``neighbour[order[0]]``
    is -1 (the densest point has no denser neighbour).
    """
    n = D.shape[0]
    rho = np.exp(-((D / dc) ** 2)).sum(axis=1) - 1.0  # minus the point itself
    order = np.argsort(-rho, kind="stable")
    rank = np.empty(n, dtype=int)
    rank[order] = np.arange(n)
    denser = rank[None, :] < rank[:, None]  # denser[i, j]: j is denser than i
    masked = np.where(denser, D, np.inf)
    neighbour = np.argmin(masked, axis=1)
    delta = masked[np.arange(n), neighbour]
    top = order[0]
    neighbour[top] = -1
    delta[top] = D[top].max() if n > 1 else 0.0
    return rho, delta, neighbour, order


class DPC:
    """Density peaks clustering (Rodriguez & Laio 2014) with a Gaussian kernel.

    n_clusters: number of centres. dc: cut-off distance, or None to use ``dc_percentile`` of
    the pairwise distances (default 2 %).
    """

    def __init__(self, n_clusters: int = 2, *, dc: float | None = None, dc_percentile: float = 2.0):
        self.n_clusters = n_clusters
        self.dc = dc
        self.dc_percentile = dc_percentile

    def _peaks(self, X: np.ndarray) -> np.ndarray:
        X = np.asarray(X, dtype=float)
        n = X.shape[0]
        if n == 0:
            raise ValueError("cannot cluster an empty set of points")
        k = int(min(self.n_clusters, n))
        if k < 1:
            raise ValueError(f"n_clusters must be >= 1, got {self.n_clusters}")
        D = pairwise_distances(X)
        dc = float(self.dc) if self.dc is not None else cutoff_distance(D, self.dc_percentile)
        rho, delta, neighbour, order = density_peaks(D, dc)
        gamma = rho * delta
        centres = np.argsort(-gamma, kind="stable")[:k]
        if order[0] not in centres:  # cannot happen without ties; keeps every chain rooted
            centres[-1] = order[0]
        self.dc_ = dc
        self.rho_, self.delta_, self.gamma_ = rho, delta, gamma
        self.n_clusters_ = k
        self.centers_ = centres
        self.cluster_centers_ = X[centres]
        self._D, self._neighbour, self._order = D, neighbour, order
        return X

    def fit(self, X, y=None) -> "DPC":
        self._peaks(X)
        labels = np.full(len(self._order), -1, dtype=int)
        labels[self.centers_] = np.arange(self.n_clusters_)
        for i in self._order:  # decreasing density: the denser neighbour is already labelled
            if labels[i] < 0:
                labels[i] = labels[self._neighbour[i]]
        self.labels_ = labels
        del self._D, self._neighbour, self._order
        return self

    def fit_predict(self, X, y=None) -> np.ndarray:
        return self.fit(X).labels_


class ADPC(DPC):
    """The paper's adaptive DPC: DPC centres, then size-penalised assignment far points first.

    base: the UAV base (the instance's start). xi: expansion index ξ (default 0.25, see the module docstring).
    """

    def __init__(
        self,
        n_clusters: int = 2,
        *,
        base=(0.0, 0.0),
        xi: float = 0.25,
        dc: float | None = None,
        dc_percentile: float = 2.0,
    ):
        super().__init__(n_clusters, dc=dc, dc_percentile=dc_percentile)
        self.base = base
        self.xi = xi

    def fit(self, X, y=None) -> "ADPC":
        X = self._peaks(X)
        D = self._D
        del self._D, self._neighbour, self._order
        base = np.asarray(self.base, dtype=float).reshape(2)
        to_base = np.linalg.norm(X - base, axis=1)
        centres = self.centers_
        k = self.n_clusters_
        reach = to_base[centres]
        mean = reach.mean()
        r = reach / mean if mean > 0 else np.ones(k)
        self.r_ = r
        labels = np.full(X.shape[0], -1, dtype=int)
        labels[centres] = np.arange(k)
        size = np.ones(k)  # ω_i: a cluster starts with its centre
        exponent = self.xi * r
        rest = np.flatnonzero(labels < 0)
        rest = rest[np.argsort(-to_base[rest], kind="stable")]  # farthest from base first
        dist = D[np.ix_(rest, centres)]
        for row, v in enumerate(rest):
            i = int(np.argmin(dist[row] * size**exponent))
            labels[v] = i
            size[i] += 1
        self.labels_ = labels
        return self
