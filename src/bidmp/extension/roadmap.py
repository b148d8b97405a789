"""G-PRM: a Gaussian probabilistic roadmap that grows a path to a new target in the shape of a
demonstrated piece (paper §3.2, Eq. 1–9), and the classic uniform PRM baseline.

One iteration of G-PRM:

1. Sampling points along the straight line ``seg → n_tar`` with Gaussian noise (Eq. 1–2), plus the
   bias learned so far (Eq. 9).
2. A roadmap on ``{seg} ∪ samples ∪ {n_tar}``: symmetric k-nearest-neighbour edges
   (:class:`scipy.spatial.cKDTree`), optional collision callback, shortest path by Dijkstra
   (:func:`scipy.sparse.csgraph.dijkstra`).
3. The path and the demonstrated piece resampled by arc length to ``n_compare`` points.
4. Similarity to the template ``T*`` (the piece mapped to end at ``n_tar``) by Fréchet similarity.
5. Bias update ``bv ← bv + (1 − s) η_it (T* − Tra_gen)`` with ``η_it = ρ^it`` (Eq. 8).

The best iteration is returned, with the similarity history.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from .._checks import (
    TaskRefusal,
    as_point,
    as_trajectory,
    check_callable,
    check_choice,
    check_int,
    check_limit,
    check_real,
    check_seed,
    numerically_guarded,
)
from .._progress import report
from .._trajectory import interp_columns, resample_arclength
from .similarity import _frechet_similarity

__all__ = [
    "NoFreeRouteError",
    "RoadmapOptions",
    "RoadmapResult",
    "template",
    "gaussian_prm",
    "classic_prm",
]

logger = logging.getLogger(__name__)


class NoFreeRouteError(TaskRefusal):
    """The roadmap found no collision-free route (never a path through an obstacle)."""


CollisionCallback = Callable[[np.ndarray], np.ndarray]
"""``is_free(points (M, D)) -> bool (M,)``: True where a point is collision-free."""

_DEGENERATE_AXIS = 1e-3  # |tar_j - seg_j| below this fraction of ‖tar - seg‖: ramp that axis
_MAX_AXIS_FACTOR = 10.0  # |sf_j| above this: ramp that axis too
_MAX_NEIGHBOURS = 32
_MAX_NEIGHBOURS_OPTION = 256  # k beyond this makes the roadmap dense (n·k edges) for no gain
_EDGE_CHECKS = 5  # points tested along each edge when a collision callback is given


@dataclass
class RoadmapResult:
    """Outcome of :func:`gaussian_prm` / :func:`classic_prm`.

    Attributes
    ----------
    path : array (n_compare, D)
        The generated trajectory ``Tra_gen`` of the chosen iteration, resampled by arc length;
        starts exactly at seg and ends exactly at n_tar.
    similarity : float
        Its similarity score.
    history : array (n_iter,)
        Similarity of every iteration.
    iteration : int
        Index of the chosen iteration.
    template : array (n_compare, D)
        The reference the paths were compared with.
    samples : array (n_samples, D)
        Sampling points of the chosen iteration (for figures).
    """

    path: np.ndarray
    similarity: float
    history: np.ndarray
    iteration: int
    template: np.ndarray
    samples: np.ndarray


def template(piece: np.ndarray, new_target: np.ndarray, scaling: str = "axis") -> np.ndarray:
    """The demonstrated piece mapped so that it starts at its own start and ends at ``new_target``.

    Parameters
    ----------
    piece : array (k, D)
        ``Tra_imi`` resampled by arc length, from seg to tar.
    new_target : array (D,)
    scaling : {"axis", "similarity"}
        ``"axis"``: per-axis factors ``sf = (n_tar − seg) / (tar − seg)``; an axis on which the
        piece barely moves (or whose factor exceeds 10) gets a ramp
        ``T*_j(λ) = piece_j(λ) + λ (n_tar_j − tar_j)`` along normalised arc length λ instead.
        ``"similarity"``: uniform scale and the minimal rotation taking ``tar − seg`` onto
        ``n_tar − seg``; never singular.

    Returns
    -------
    array (k, D), starting exactly at seg and ending exactly at ``new_target``.
    """
    piece = as_trajectory(piece, "piece", min_points=2, allow_static=True)
    new_target = as_point(new_target, piece.shape[1], "new_target", like="piece")
    check_choice(scaling, "scaling", ("axis", "similarity", "paper"))
    return _template(piece, new_target, scaling)


def _template(piece: np.ndarray, new_target: np.ndarray, scaling: str) -> np.ndarray:
    """:func:`template` of a checked piece and target."""
    seg, tar = piece[0], piece[-1]
    chord, new_chord = tar - seg, new_target - seg
    chord_length = np.linalg.norm(chord)
    lam = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(piece, axis=0), axis=1))])
    lam = lam / lam[-1] if lam[-1] > 0 else np.linspace(0.0, 1.0, len(piece))
    ramp = piece + lam[:, None] * (new_target - tar)
    if chord_length <= 1e-12 * max(np.abs(piece).max(), 1.0):
        out = ramp  # a closed piece has no direction to scale: translate its end along the way
    elif scaling == "axis":
        with np.errstate(divide="ignore", invalid="ignore"):
            factors = new_chord / chord
        degenerate = (np.abs(chord) < _DEGENERATE_AXIS * chord_length) | ~(
            np.abs(factors) <= _MAX_AXIS_FACTOR
        )
        scaled = seg + np.where(degenerate, 0.0, factors) * (piece - seg)
        out = np.where(degenerate, ramp, scaled)
    elif scaling == "similarity":
        scale = np.linalg.norm(new_chord) / chord_length
        out = seg + scale * (piece - seg) @ _minimal_rotation(chord, new_chord).T
    else:
        raise ValueError(f"scaling must be 'axis' or 'similarity' for a template, got {scaling!r}")
    out = np.array(out)
    out[0], out[-1] = seg, new_target
    return out


def _minimal_rotation(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotation (D × D) taking the direction of ``a`` onto that of ``b``, acting only in their plane."""
    n_dims = a.shape[0]
    u = a / np.linalg.norm(a)
    norm_b = np.linalg.norm(b)
    if norm_b == 0.0:
        return np.eye(n_dims)
    v = b / norm_b
    cos = float(np.clip(u @ v, -1.0, 1.0))
    w = v - cos * u
    sin = np.linalg.norm(w)
    if sin < 1e-12:
        if cos > 0:
            return np.eye(n_dims)
        if n_dims == 1:  # on a line, the opposite direction is the mirror image
            return -np.eye(1)
        # Opposite directions: turn by π in the plane of u and the axis least aligned with it.
        axis = np.eye(n_dims)[int(np.argmin(np.abs(u)))]
        w = axis - (axis @ u) * u
        w /= np.linalg.norm(w)
        return np.eye(n_dims) - 2.0 * np.outer(u, u) - 2.0 * np.outer(w, w)
    w /= sin
    # R = I + sinθ (w uᵀ − u wᵀ) + (cosθ − 1)(u uᵀ + w wᵀ)
    return (
        np.eye(n_dims)
        + sin * (np.outer(w, u) - np.outer(u, w))
        + (cos - 1.0) * (np.outer(u, u) + np.outer(w, w))
    )


def _paper_scaled(
    path: np.ndarray, seg: np.ndarray, tar: np.ndarray, new_target: np.ndarray
) -> np.ndarray:
    """Eq. 6–7 as printed: the factors ``(n_tar − seg)/(tar − seg)`` applied to Tra_gen."""
    chord = tar - seg
    with np.errstate(divide="ignore", invalid="ignore"):
        factors = (new_target - seg) / chord
    bad = (np.abs(chord) < _DEGENERATE_AXIS * max(np.linalg.norm(chord), 1e-300)) | ~(
        np.abs(factors) <= _MAX_AXIS_FACTOR
    )
    return seg + np.where(bad, 1.0, factors) * (path - seg)


def _shortest_path(
    nodes: np.ndarray, n_neighbours: int = 8, is_free: CollisionCallback | None = None
) -> np.ndarray | None:
    """Dijkstra path from ``nodes[0]`` to ``nodes[-1]`` on a symmetric kNN roadmap.

    Returns the node indices of the path, or None when the target is unreachable even with
    ``n_neighbours`` doubled up to 32.
    """
    n_nodes = nodes.shape[0]  # a private core: the roadmap's own nodes, checked options
    tree = cKDTree(nodes)
    k = n_neighbours
    while True:
        k_query = min(k + 1, n_nodes)
        distances, neighbours = tree.query(nodes, k=k_query)
        rows = np.repeat(np.arange(n_nodes), k_query - 1)
        cols = neighbours[:, 1:].ravel()
        weights = distances[:, 1:].ravel()
        if is_free is not None:
            keep = _undirected_free(nodes, rows, cols, is_free)
            rows, cols, weights = rows[keep], cols[keep], weights[keep]
        # Coincident nodes would give zero weights, which a sparse matrix drops: keep them tiny.
        weights = np.maximum(weights, 1e-300)
        graph = csr_matrix((weights, (rows, cols)), shape=(n_nodes, n_nodes))
        dist, predecessors = dijkstra(graph, directed=False, indices=0, return_predecessors=True)
        if np.isfinite(dist[-1]):
            path = [n_nodes - 1]
            while path[-1] != 0:
                path.append(int(predecessors[path[-1]]))
            return np.asarray(path[::-1])
        if k >= _MAX_NEIGHBOURS or k_query >= n_nodes:
            return None
        k = min(2 * k, _MAX_NEIGHBOURS)


def _undirected_free(
    nodes: np.ndarray, rows: np.ndarray, cols: np.ndarray, is_free: CollisionCallback
) -> np.ndarray:
    """Which edges ``rows[e] -> cols[e]`` of the roadmap are free, each pair of nodes checked once:
    a kNN roadmap lists a pair from both ends when each is among the other's neighbours (about
    two in three of its edges), and a straight move is free or not whichever way it is checked
    (a conservative advancement either way stops short of the margin; only a move that grazes it
    to the last resolution step could differ). The edge checks are most of a route's cost."""
    low, high = np.minimum(rows, cols), np.maximum(rows, cols)
    _, first, inverse = np.unique(
        low * nodes.shape[0] + high, return_index=True, return_inverse=True
    )
    return _edges_free(nodes[rows[first]], nodes[cols[first]], is_free)[inverse.ravel()]


def _edges_free(a: np.ndarray, b: np.ndarray, is_free: CollisionCallback) -> np.ndarray:
    # A callback that can check straight moves continuously (bidmp.scene.SceneChecker) does;
    # a plain point callback is asked at _EDGE_CHECKS points along each edge.
    segments_free = getattr(is_free, "segments_free", None)
    if segments_free is not None:
        return np.asarray(segments_free(a, b), dtype=bool)
    t = np.linspace(0.0, 1.0, _EDGE_CHECKS + 2)[1:-1]
    points = a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]
    free = np.asarray(is_free(points.reshape(-1, a.shape[1])), dtype=bool).reshape(a.shape[0], -1)
    return free.all(axis=1)


def _path_through(
    samples: np.ndarray,
    seg: np.ndarray,
    new_target: np.ndarray,
    order: np.ndarray,
    n_neighbours: int,
    is_free: CollisionCallback | None,
) -> np.ndarray:
    nodes = np.vstack([seg, samples, new_target])
    if is_free is not None:
        free = np.asarray(is_free(nodes), dtype=bool)
        if not (free[0] and free[-1]):
            raise NoFreeRouteError(
                f"the {'start (seg)' if not free[0] else 'new target'} "
                f"{np.round(nodes[0] if not free[0] else nodes[-1], 3).tolist()} is inside an "
                f"obstacle according to is_free"
            )
        keep = free.copy()
        nodes, order = nodes[keep], order[keep[1:-1]]
    indices = _shortest_path(nodes, n_neighbours, is_free)
    if indices is None:
        if is_free is not None:
            raise NoFreeRouteError(
                f"no collision-free route from seg {np.round(seg, 3).tolist()} to "
                f"{np.round(new_target, 3).tolist()}: the roadmap's {nodes.shape[0] - 2} free samples "
                f"do not connect them even with {_MAX_NEIGHBOURS} neighbours (the parts block the "
                f"way, or sigma_rel / n_samples are too small to go around them)"
            )
        # Unreachable even with 32 neighbours: chain the samples in their sampling order.
        logger.warning(
            "new target unreachable on the roadmap even with %d neighbours: chaining the samples in order",
            _MAX_NEIGHBOURS,
        )
        inner = nodes[1:-1][np.argsort(order, kind="stable")]
        return np.vstack([seg, inner, new_target])
    return nodes[indices]


@dataclass
class _Comparison:
    """How a generated path is scored and which way the bias pushes."""

    piece: np.ndarray  # Tra_imi resampled
    new_target: np.ndarray
    scaling: str
    compare: str
    denom: str

    def __post_init__(self):
        if self.scaling == "paper":
            self.reference = self.piece
        else:
            self.reference = _template(self.piece, self.new_target, self.scaling)
        self.target_shape = (
            self.reference if self.compare == "template" or self.scaling == "paper" else self.piece
        )

    def score(self, path: np.ndarray) -> tuple[float, np.ndarray]:
        """(similarity, bias direction) for a resampled path."""
        if self.scaling == "paper":
            scaled = _paper_scaled(path, self.piece[0], self.piece[-1], self.new_target)
            return _frechet_similarity(scaled, self.piece, self.denom), self.piece - scaled
        return _frechet_similarity(path, self.target_shape, self.denom), self.reference - path


@dataclass(frozen=True)
class RoadmapOptions:
    """The options of G-PRM (:func:`gaussian_prm`) and the classic PRM (:func:`classic_prm`),
    checked once when made (``ValueError``/``TypeError`` naming the first bad one).

    Sizes are bounded so that one run stays within seconds: ``n_samples · n_iter <=
    max_roadmap_nodes`` and ``n_compare² · n_iter <= max_frechet_cells``
    (:func:`bidmp.set_limits`).

    Parameters
    ----------
    n_samples : int, default 300
        Sampling points per iteration.
    sigma_rel : float, default 0.03
        G-PRM: standard deviation of the sampling noise per axis, relative to ‖n_tar − seg‖.
    n_neighbours : int, default 8
        k of the kNN roadmap (doubled up to 32 while the target is unreachable).
    n_compare : int, default 100
        Points of the arc-length resampling used to compare shapes.
    n_iter : int, default 10
        Iterations (each draws a new roadmap).
    rho : float, default 0.9
        G-PRM's learning factor: ``η_it = ρ^it`` (``schedule="geometric"``) or ``ρ / it``
        (``"harmonic"``).
    schedule : {"geometric", "harmonic"}, default "geometric"
    scaling : {"axis", "similarity", "paper"}, default "axis"
        Template mapping (see :func:`template`); ``"paper"`` applies the factors to Tra_gen and
        compares with Tra_imi, as printed in the paper.
    compare : {"template", "raw"}, default "template"
        Score against the template (shape only) or against Tra_imi itself.
    select : {"best", "last"}, default "best"
        Which iteration to return.
    denom : {"sqrt2", "2"}, default "sqrt2"
        The Fréchet similarity's normaliser (:func:`bidmp.frechet_similarity`).
    padding : float, default 0.3
        Classic PRM: the sampling box around seg and n_tar, padded by ``padding · ‖n_tar − seg‖``.
    """

    n_samples: int = 300
    sigma_rel: float = 0.03
    n_neighbours: int = 8
    n_compare: int = 100
    n_iter: int = 10
    rho: float = 0.9
    schedule: str = "geometric"
    scaling: str = "axis"
    compare: str = "template"
    select: str = "best"
    denom: str = "sqrt2"
    padding: float = 0.3

    def __post_init__(self) -> None:
        checked = {
            "n_samples": check_int(self.n_samples, "n_samples", minimum=2),
            "n_neighbours": check_int(
                self.n_neighbours, "n_neighbours", minimum=1, maximum=_MAX_NEIGHBOURS_OPTION
            ),
            "n_compare": check_int(self.n_compare, "n_compare", minimum=3),
            "n_iter": check_int(self.n_iter, "n_iter", minimum=1),
            "sigma_rel": check_real(self.sigma_rel, "sigma_rel", nonnegative=True, maximum=10.0),
            "rho": check_real(self.rho, "rho", positive=True, maximum=2.0),
            "padding": check_real(self.padding, "padding", nonnegative=True, maximum=100.0),
        }
        check_limit(
            checked["n_samples"] * checked["n_iter"],
            "max_roadmap_nodes",
            "the roadmap nodes drawn, n_samples * n_iter",
        )
        check_limit(
            checked["n_compare"] ** 2 * checked["n_iter"],
            "max_frechet_cells",
            "the similarity work, n_compare^2 * n_iter",
        )
        check_choice(self.schedule, "schedule", ("geometric", "harmonic"))
        check_choice(self.scaling, "scaling", ("axis", "similarity", "paper"))
        check_choice(self.compare, "compare", ("template", "raw"))
        check_choice(self.select, "select", ("best", "last"))
        check_choice(self.denom, "denom", ("sqrt2", "2"))
        for name, value in checked.items():
            object.__setattr__(self, name, value)

    def replace(self, **changes) -> RoadmapOptions:
        """These options with ``changes`` (checked again)."""
        return replace(self, **changes)


def _options(options, name: str = "options") -> RoadmapOptions:
    """``options`` as :class:`RoadmapOptions` (None: the defaults)."""
    if options is None:
        return RoadmapOptions()
    if not isinstance(options, RoadmapOptions):
        raise TypeError(
            f"{name} must be a bidmp.extension.RoadmapOptions (or None), got {type(options).__name__}"
        )
    return options


def _setup(tra_imi, new_target, is_free, seed):
    """Validate what both roadmaps take besides their options; return (piece, target, random
    generator)."""
    piece = as_trajectory(tra_imi, "tra_imi", min_points=2)
    target = as_point(new_target, piece.shape[1], "new_target", like="tra_imi")
    if is_free is not None:
        check_callable(is_free, "is_free", "a collision callback is_free(points) -> bool array")
    rng = check_seed(seed)
    if np.linalg.norm(target - piece[0]) == 0.0:
        raise ValueError(
            "new_target coincides with the start of the piece (seg): nothing to generate"
        )
    return piece, target, rng


def _comparison(piece: np.ndarray, target: np.ndarray, options: RoadmapOptions) -> _Comparison:
    """How both roadmaps score a path against ``piece`` mapped to ``target``."""
    return _Comparison(
        resample_arclength(piece, options.n_compare),
        target,
        options.scaling,
        options.compare,
        options.denom,
    )


def _iterate(
    comparison: _Comparison, options: RoadmapOptions, draw, learn, is_free
) -> RoadmapResult:
    """The loop both roadmaps share: draw samples, shortest path, score, learn (G-PRM only).

    ``draw(iteration) -> (samples (n, D), order (n,))``; ``learn(iteration, similarity,
    direction)`` or None.
    """
    seg, target = comparison.piece[0], comparison.new_target
    n_compare = comparison.piece.shape[0]
    n_iter, n_neighbours = options.n_iter, options.n_neighbours
    history, paths, all_samples = [], [], []
    for iteration in range(1, n_iter + 1):
        samples, order = draw(iteration)
        path = resample_arclength(
            _path_through(samples, seg, target, order, n_neighbours, is_free), n_compare
        )
        similarity, direction = comparison.score(path)
        if learn is not None:
            learn(iteration, similarity, direction)
        history.append(similarity)
        paths.append(path)
        all_samples.append(samples)
        report("G-PRM iterations", iteration, n_iter)
    history = np.asarray(history)
    chosen = int(np.argmax(history)) if options.select == "best" else len(history) - 1
    return RoadmapResult(
        path=paths[chosen],
        similarity=float(history[chosen]),
        history=history,
        iteration=chosen,
        template=comparison.reference,
        samples=all_samples[chosen],
    )


@numerically_guarded
def gaussian_prm(
    tra_imi,
    new_target,
    options: RoadmapOptions | None = None,
    *,
    is_free: CollisionCallback | None = None,
    seed: int | np.random.Generator | None = 0,
) -> RoadmapResult:
    """Generate ``Tra_gen`` from seg (the piece's start) to ``new_target`` with G-PRM.

    Parameters
    ----------
    tra_imi : array (n, D)
        The demonstrated piece to imitate, from seg to tar.
    new_target : array (D,)
    options : RoadmapOptions, optional
        The roadmap's options (default ``RoadmapOptions()``; ``padding`` is the classic PRM's).
    is_free : callable, optional
        Collision callback ``is_free(points (M, D)) -> bool (M,)``; nodes and edges where it is
        False are left out of the roadmap. An ``is_free.segments_free(a, b)`` method, when the
        callback has one (:meth:`bidmp.Scene.checker`), checks the edges continuously; otherwise
        edges are checked at 5 interior points, so an obstacle thinner than a fifth of an edge can
        slip between them: inflate thin obstacles. When no free route joins seg and the target,
        :class:`NoFreeRouteError` (a ``ValueError``) is raised: never a path through an obstacle.
    seed : int or numpy.random.Generator
    """
    options = _options(options)
    piece, target, rng = _setup(tra_imi, new_target, is_free, seed)
    return _gaussian_prm(piece, target, options, is_free, rng)


def _gaussian_prm(piece, target, options: RoadmapOptions, is_free, rng) -> RoadmapResult:
    """:func:`gaussian_prm` on a checked piece (n, D), target (D,) apart from its start, options
    and random generator (what an extended demonstration runs, its input checked once)."""
    comparison = _comparison(piece, target, options)
    sampler = _ChordSampler(piece[0], target, options, rng)
    return _iterate(comparison, options, sampler.draw, sampler.learn, is_free)


class _ChordSampler:
    """G-PRM's sampler: ``options.n_samples`` points spread along the chord seg → n_tar (Eq. 1–2)
    with Gaussian noise of ``sigma_rel · ‖n_tar − seg‖`` per axis, shifted by a bias learned over
    the comparison's ``n_compare`` arc-length stations (Eq. 8–9)."""

    def __init__(self, seg, target, options: RoadmapOptions, rng):
        self.sigma = options.sigma_rel * np.linalg.norm(target - seg)
        self.t = np.linspace(0.0, 1.0, options.n_samples)
        self.line = seg + self.t[:, None] * (target - seg)
        self.lam = np.linspace(0.0, 1.0, options.n_compare)
        self.bias = np.zeros((options.n_compare, seg.shape[0]))
        self.order = np.arange(options.n_samples)
        self.rho, self.schedule, self.rng = options.rho, options.schedule, rng

    def draw(self, iteration):
        bias_at_samples = interp_columns(self.t, self.lam, self.bias)  # Eq. 9
        return self.line + self.rng.normal(
            scale=self.sigma, size=self.line.shape
        ) + bias_at_samples, self.order

    def learn(self, iteration, similarity, direction):  # Eq. 8
        rate = self.rho**iteration if self.schedule == "geometric" else self.rho / iteration
        self.bias = self.bias + (1.0 - similarity) * rate * direction


@numerically_guarded
def classic_prm(
    tra_imi,
    new_target,
    options: RoadmapOptions | None = None,
    *,
    is_free: CollisionCallback | None = None,
    seed: int | np.random.Generator | None = 0,
) -> RoadmapResult:
    """Classic PRM baseline (paper Table 5): uniform samples in the bounding box of seg and
    ``new_target`` padded by ``options.padding · ‖n_tar − seg‖``, no bias; each iteration only
    redraws. Scored exactly like :func:`gaussian_prm` (its other options likewise; G-PRM's
    ``sigma_rel``, ``rho`` and ``schedule`` are not used)."""
    options = _options(options)
    piece, target, rng = _setup(tra_imi, new_target, is_free, seed)
    comparison = _comparison(piece, target, options)
    seg = piece[0]
    margin = options.padding * np.linalg.norm(target - seg)
    low, high = np.minimum(seg, target) - margin, np.maximum(seg, target) + margin
    n_samples = options.n_samples

    def draw(iteration):
        samples = rng.uniform(low, high, size=(n_samples, piece.shape[1]))
        # Uniform samples have no order of their own: the fallback chain follows the chord.
        order = np.argsort(
            np.argsort((samples - seg) @ (target - seg), kind="stable"), kind="stable"
        )
        return samples, order

    return _iterate(comparison, options, draw, None, is_free)
