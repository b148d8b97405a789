"""Extended demonstrations: segment → pick the piece → G-PRM → complete demonstration.

``extend_demonstration(y, new_target)`` returns the complete extended demonstration, uniform in
time at the demonstration's sample period. Two ways (``approach``):

``"keep"`` (default): the demonstration's final approach, the straight last piece into its target
(:func:`final_approach`), is kept sample for sample and translated to the new target; G-PRM
grows only the transfer from seg to the start of that translated approach::

    y_dn = prefix ⊕ Tra_gen(seg → hover) ⊕ (approach + n_tar − tar)

With a ``scene`` (:class:`bidmp.Scene`) the roadmap's samples and edges are checked against the
parts for the tool, the parts at the new target excepted (it enters the tool), and a transfer
or approach that would touch a part is an error (:class:`bidmp.extension.roadmap.NoFreeRouteError`).

``"paper"``: the paper's protocol: the whole nearest piece is imitated down to the new target,

    y_dn = prefix ⊕ Tra_gen(seg → n_tar)

resampled to the demonstration's T samples.

Tra_gen is the G-PRM path, smoothed (it is a polyline) with its ends pinned, and timed by
:mod:`bidmp.extension.timing`. ``"keep"``: as long as it needs for its peak speed, acceleration
and jerk to stay within the demonstration's (a longer transfer takes longer; the extended
demonstration then has more samples than T, and :attr:`ExtendedDemonstration.time_scale` says
how much longer it lasts). ``"paper"``: the imitated piece's mean speed, to rest at the new
target, the whole resampled to T samples (the paper's protocol: the demonstration's duration).
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from .._checks import (
    as_indices,
    as_point,
    as_trajectory,
    check_callable,
    check_choice,
    check_real,
    check_seed,
    numerically_guarded,
)
from .._trajectory import arclength, path_extent, resample_time, savgol_filter
from ..primitives.approach import STRAIGHTNESS, straight_tail_start
from .refine import _lifted_route, _path_is_free, _refine_transfer, _smoothest_free_route
from .roadmap import (
    CollisionCallback,
    NoFreeRouteError,
    RoadmapOptions,
    RoadmapResult,
    _gaussian_prm,
    _options,
)
from .segmentation import Piece, _choose_piece, _segment
from .timing import _time_path, _timed_transfer

__all__ = [
    "ExtensionOptions",
    "check_extension_options",
    "ExtendedDemonstration",
    "extend_demonstration",
    "extend_pose_demonstration",
    "final_approach",
    "APPROACHES",
]

APPROACHES = ("keep", "paper")
# an approach deviates from its chord by at most this fraction of the chord
_STRAIGHTNESS = STRAIGHTNESS

logger = logging.getLogger(__name__)


@dataclass
class ExtendedDemonstration:
    """Result of :func:`extend_demonstration` (lengths in the demonstration's unit).

    Attributes
    ----------
    complete : array (T', D)
        The extended demonstration y_dn: starts at the demonstration's start, ends exactly at the
        new target, uniform in time at the demonstration's sample period (``"paper"``: T' = T;
        ``"keep"``: T' ≥ T when the transfer needs longer, see :attr:`time_scale`).
    tra_imi : array (n, D)
        The demonstrated piece that was imitated (seg → tar), original samples.
    tra_gen : array (k, D)
        The generated path (seg → new target; ``"keep"``: → the kept approach's start), as timed:
        ``"paper"``, G-PRM's smoothed (k = ``n_compare``); ``"keep"``, as :attr:`refinement` says.
    seg_index : int
        Index of seg in the demonstration.
    similarity_history : array (n_iter,)
        G-PRM similarity per iteration (empty when G-PRM was skipped).
    approach : {"keep", "paper"}
        How it was grown.
    approach_index : int or None
        First sample of the kept approach in the demonstration (``"keep"`` only).
    refinement : str or None
        ``"keep"``: how the transfer was made from G-PRM's path (:func:`bidmp.extension.refine.refine_transfer`):
        ``"template"`` (free, so the imitated piece's own shape), ``"smoothed"``, ``"shortcut"``, or
        ``"straight"`` (G-PRM not needed).
    orientations : array (T, 4) or None
        For :func:`extend_pose_demonstration`: the orientation (x, y, z, w) at each sample of
        ``complete``; :attr:`poses` is then the extended pose demonstration.

    With ``"keep"``, ``complete[-n:] == demonstration[-n:] + (new_target − demonstration[-1])``
    for ``n = T − approach_index``.
    """

    complete: np.ndarray
    tra_imi: np.ndarray
    tra_gen: np.ndarray
    seg_index: int
    similarity_history: np.ndarray
    demonstration: np.ndarray
    new_target: np.ndarray
    segmentation_points: np.ndarray
    piece: Piece
    similarity: float = float("nan")
    template: np.ndarray | None = None
    samples: np.ndarray | None = None
    approach: str = "paper"
    approach_index: int | None = None  # "keep": where the kept approach starts in the demonstration
    refinement: str | None = None  # "keep": how the transfer was made from G-PRM's path
    orientations: np.ndarray | None = None  # pose extensions: (T, 4) quaternions along complete

    @property
    def poses(self) -> np.ndarray:
        """The extended pose demonstration (T, 7) of :func:`extend_pose_demonstration`."""
        if self.orientations is None:
            raise AttributeError(
                "this extension has no orientations: it was grown from positions (see complete)"
            )
        return np.hstack([self.complete, self.orientations])

    @property
    def time_scale(self) -> float:
        """How long ``complete`` lasts over the demonstration (both at the demonstration's sample
        period): ``(T' − 1) / (T − 1)``. Pass ``duration=time_scale · dmp.duration_`` to
        :meth:`bidmp.BiDMP.learn` so that the skill is not rushed into the demonstration's time."""
        return (self.complete.shape[0] - 1) / (self.demonstration.shape[0] - 1)

    def duration_for(self, dmp) -> float:
        """How long ``complete`` lasts in seconds for ``dmp``, the DMP fitted on the demonstration
        it was grown from (or on the first of a chain of extensions): ``complete`` is sampled at
        that demonstration's period ``dmp.duration_ / (T − 1)``. What :meth:`bidmp.BiDMP.learn`
        takes as ``duration``."""
        from ..primitives.dmp import DMP

        if not isinstance(dmp, DMP) or getattr(dmp, "duration_", None) is None:
            raise TypeError(
                f"dmp must be the fitted bidmp.DMP the extension was grown for, got {type(dmp).__name__}"
            )
        return dmp.duration_ * ((self.complete.shape[0] - 1) / (dmp.n_steps_ - 1))

    @property
    def prefix(self) -> np.ndarray:
        """The demonstration before seg, (seg_index, D)."""
        return self.demonstration[: self.seg_index]


def _smooth_path(path: np.ndarray) -> np.ndarray:
    """Savitzky–Golay smoothing of a polyline with its two ends kept exactly."""
    n_points = path.shape[0]
    window = min(11, n_points - (1 - n_points % 2))
    if window < 5:
        return path.copy()
    smooth = savgol_filter(path, window, 3, axis=0, mode="interp")
    lam = np.linspace(0.0, 1.0, n_points)[:, None]
    smooth += (1.0 - lam) * (path[0] - smooth[0]) + lam * (path[-1] - smooth[-1])
    return smooth


def final_approach(y, segmentation_points, straightness: float = _STRAIGHTNESS) -> int:
    """Index where the demonstration's final approach starts: the straight last piece into its
    target.

    The last piece of the segmentation (from the last segmentation point to the end) is the
    approach when it is straight: no sample further than ``straightness`` × its chord from the
    chord, and never moving back along it. Otherwise the longest straight tail of that piece is.
    A demonstration whose end is not approached in a straight line (a tail shorter than 2
    samples) has no approach: the last index is returned, and the whole motion is the transfer.

    Parameters
    ----------
    y : array (T, D)
    segmentation_points : array of int or Segmentation
    straightness : float, default 0.02

    Returns
    -------
    int in [0, T − 1]
    """
    y = as_trajectory(y, "y")
    straightness = check_real(straightness, "straightness", positive=True, maximum=1.0)
    points = getattr(segmentation_points, "points", segmentation_points)
    points = as_indices(points, "segmentation_points", y.shape[0] - 1, "y")
    return _final_approach(y, points, straightness)


def _final_approach(y: np.ndarray, points: np.ndarray, straightness: float = _STRAIGHTNESS) -> int:
    """:func:`final_approach` of a checked demonstration and segmentation points."""
    last = y.shape[0] - 1
    start = int(points[points < last].max()) if np.any(points < last) else 0
    # The last piece if it is straight, else its longest straight tail (primitives.approach).
    return straight_tail_start(y, start, straightness)


# An extension's own options; a scenario file's flat form lists the roadmap's beside them.
_OWN_OPTIONS = ("eps_frac", "method", "approach")


@dataclass(frozen=True)
class ExtensionOptions:
    """How an extended demonstration is grown, checked once when made (``ValueError``/``TypeError``
    naming the first bad option): what a scenario's ``"extension"`` object stands for.

    Parameters
    ----------
    eps_frac : float, default 0.1
        The segmentation's persistence threshold, a fraction in (0, 1) (:func:`bidmp.segment`).
    method : {"persistence", "paper"}, default "persistence"
        The segmentation's method.
    approach : {"keep", "paper"}, default "keep"
        Keep the demonstration's final approach (moved to the new target), or the paper's protocol
        (:func:`extend_demonstration`).
    roadmap : RoadmapOptions
        G-PRM's options.
    """

    eps_frac: float = 0.1
    method: str = "persistence"
    approach: str = "keep"
    roadmap: RoadmapOptions = field(default_factory=RoadmapOptions)

    def __post_init__(self) -> None:
        eps_frac = check_real(self.eps_frac, "eps_frac")
        if not 0.0 < eps_frac < 1.0:
            raise ValueError(f"eps_frac must lie in (0, 1), got {eps_frac}")
        check_choice(self.method, "method", ("persistence", "paper"))
        check_choice(self.approach, "approach", APPROACHES)
        if not isinstance(self.roadmap, RoadmapOptions):
            raise TypeError(
                f"roadmap must be a bidmp.extension.RoadmapOptions, got {type(self.roadmap).__name__}"
            )
        object.__setattr__(self, "eps_frac", eps_frac)

    @classmethod
    def from_flat(cls, options: dict | None = None) -> ExtensionOptions:
        """The options from a scenario file's flat form (``{"eps_frac": 0.1, "n_iter": 20,
        ...}``: the roadmap's options beside the others); an unknown name is a ``TypeError``."""
        flat = dict(options or {})
        unknown = sorted(set(flat) - set(_OWN_OPTIONS) - set(RoadmapOptions.__dataclass_fields__))
        if unknown:
            raise TypeError(
                f"unknown extension option {unknown[0]!r} (known: eps_frac, method, approach, "
                f"{', '.join(RoadmapOptions.__dataclass_fields__)})"
            )
        own = {key: flat.pop(key) for key in _OWN_OPTIONS if key in flat}
        return cls(**own, roadmap=RoadmapOptions(**flat))

    @property
    def arguments(self) -> dict:
        """The keyword arguments of :func:`extend_demonstration` these options stand for."""
        return {key: getattr(self, key) for key in (*_OWN_OPTIONS, "roadmap")}

    @property
    def flat(self) -> dict:
        """A scenario file's form of these options (:meth:`from_flat` reads it back): the values
        that differ from the defaults, the roadmap's beside the others."""
        default = ExtensionOptions()
        out = {
            key: getattr(self, key)
            for key in _OWN_OPTIONS
            if getattr(self, key) != getattr(default, key)
        }
        roadmap = dataclasses.asdict(self.roadmap)
        out.update(
            {key: value for key, value in roadmap.items() if value != getattr(default.roadmap, key)}
        )
        return out

    def replace(self, **changes) -> ExtensionOptions:
        """These options with ``changes`` (checked again)."""
        return dataclasses.replace(self, **changes)


def check_extension_options(*, seed=0, **options) -> dict:
    """The options of :func:`extend_demonstration` in the flat form a scenario file writes them
    (``"extension": {"eps_frac": 0.1, "n_iter": 20, ...}``), checked without running anything;
    raise naming the first bad one.

    Returns
    -------
    dict
        The keyword arguments of :func:`extend_demonstration`: ``eps_frac``, ``method``,
        ``approach`` and ``roadmap`` (a :class:`~bidmp.extension.RoadmapOptions` of the rest), as
        :attr:`ExtensionOptions.arguments`.
    """
    check_seed(seed)
    return ExtensionOptions.from_flat(options).arguments


@numerically_guarded
def extend_demonstration(  # noqa: PLR0913 - the public call spells its options out, as users pass them
    y,
    new_target,
    *,
    seed: int | np.random.Generator | None = 0,
    eps_frac: float = 0.1,
    method: str = "persistence",
    roadmap: RoadmapOptions | None = None,
    is_free: CollisionCallback | None = None,
    approach: str = "keep",
    scene=None,
) -> ExtendedDemonstration:
    """Grow an extended demonstration from ``y`` to ``new_target`` (1D-SEG + G-PRM).

    Parameters
    ----------
    y : array (T, D), D = 2 or 3
        The demonstration, uniform in time.
    new_target : array (D,)
    seed : int or numpy.random.Generator
        Seed of the G-PRM sampling: same seed, same result.
    eps_frac, method
        Segmentation options, see :func:`bidmp.segment`.
    roadmap : RoadmapOptions, optional
        G-PRM's options (default ``RoadmapOptions()``).
    is_free : callable, optional
        A collision callback for the roadmap, see :func:`bidmp.extension.gaussian_prm`.
    approach : {"keep", "paper"}, default "keep"
        ``"keep"``: keep the demonstration's final approach (:func:`final_approach`), translated
        to the new target, and grow only the transfer to its start. ``"paper"``: the paper's
        protocol, the nearest piece imitated down to the new target.
    scene : bidmp.Scene, optional
        Parts to keep the tool away from (3-D only): the roadmap is checked against them (unless
        ``is_free`` is given) and the finished transfer and approach must not touch them; the
        parts at the new target are excepted.

    Returns
    -------
    ExtendedDemonstration

    Raises
    ------
    bidmp.extension.roadmap.NoFreeRouteError
        With a scene or ``is_free``: no collision-free route exists on the roadmap, or the kept
        approach, translated, would touch a part.
    """
    y = as_trajectory(y, "y", min_points=10)
    target = as_point(new_target, y.shape[1], "new_target", like="y")
    check_extension_options(eps_frac=eps_frac, method=method, seed=seed, approach=approach)
    if is_free is not None:
        check_callable(is_free, "is_free", "a collision callback is_free(points) -> bool array")
    exclude, is_free, scene_checker = _scene_checker(scene, y, target, is_free)
    roadmap_options = {"options": _options(roadmap, "roadmap"), "is_free": is_free}
    points = _segment(y, eps_frac, method).points
    if approach == "keep":
        if scene_checker is not None and scene.margin > 0.0:
            return _extend_keeping_the_margin(
                y, target, points, seed, roadmap_options, scene, exclude
            )
        return _extend_keeping_approach(y, target, points, seed, roadmap_options, (scene, exclude))
    return _extend_like_the_paper(y, target, points, seed, roadmap_options)


def _scene_checker(scene, y: np.ndarray, target: np.ndarray, is_free):
    """``(parts at the target, the roadmap's checker, the checker built here or None)``: with a
    scene and no ``is_free`` of the caller's, a checker of the scene's parts but those at the
    target (a caller's own ``is_free`` is kept as given)."""
    if scene is None:
        return (), is_free, None
    if not (hasattr(scene, "parts_at") and hasattr(scene, "checker")):
        raise TypeError(f"scene must be a bidmp.Scene, got {type(scene).__name__}")
    if y.shape[1] != 3:
        raise ValueError(f"scene needs a 3-D demonstration, got D = {y.shape[1]}")
    exclude = scene.parts_at(target)
    if is_free is not None:
        return exclude, is_free, None
    checker = scene.checker(exclude=exclude)
    return exclude, checker, checker


_MARGIN_ATTEMPTS = 3  # plannings with a wider margin before an extension that keeps it is given up


def _extend_keeping_the_margin(
    y, target, points, seed, roadmap_options, scene, exclude
) -> ExtendedDemonstration:
    """``approach="keep"`` in a scene with a clearance margin: the extension as timed and sampled
    (not only the roadmap's polyline) must keep the margin from every part but the target's. When
    it does not, it is planned again with the margin widened by the shortfall; after
    :data:`_MARGIN_ATTEMPTS` plannings the call fails naming the part."""
    planning = scene.margin
    for _ in range(_MARGIN_ATTEMPTS):
        options = {**roadmap_options, "is_free": scene.checker(exclude, margin=planning)}
        extension = _extend_keeping_approach(y, target, points, seed, options, (scene, exclude))
        clearance = scene.clearance(extension.complete, exclude=exclude)
        if clearance.clear:
            return extension
        planning += scene.margin - clearance.distance + 0.1 * scene.margin
        logger.info(
            "the extension passes %.3g from %s, inside the margin %g: planned again with %.3g",
            clearance.distance,
            clearance.part,
            scene.margin,
            planning,
        )
    raise NoFreeRouteError(
        f"no extension to {np.round(target, 3).tolist()} keeps the margin {scene.margin:g}: it comes "
        f"within {clearance.distance:.3g} of part {clearance.part!r} after {_MARGIN_ATTEMPTS} plannings"
    )


def _extend_like_the_paper(y, target, points, seed, roadmap_options) -> ExtendedDemonstration:
    """``approach="paper"``: the nearest piece imitated by G-PRM down to the new target, timed like
    the piece, appended to the demonstration up to the piece's start."""
    n_steps = y.shape[0]
    dt = 1.0 / n_steps
    piece = _choose_piece(y, points, target)
    tra_imi = y[piece.start : piece.end + 1]
    seg = y[piece.start]

    extent = path_extent(y)
    if np.linalg.norm(target - seg) <= 1e-9 * extent:
        logger.info("new target coincides with seg: G-PRM skipped")
        tra_gen = np.vstack([seg, target])
        history = np.empty(0)
        result = None
    else:
        result = _roadmap(tra_imi, target, seed, roadmap_options)
        tra_gen = _smooth_path(result.path)
        history = result.history

    prefix = y[: piece.start + 1]  # includes seg
    start_speed = (
        float(np.linalg.norm(y[piece.start] - y[piece.start - 1]) / dt) if piece.start > 0 else 0.0
    )
    imi_duration = max(piece.end - piece.start, 1) * dt
    mean_speed = arclength(tra_imi)[-1] / imi_duration
    if mean_speed <= 0.0:
        mean_speed = arclength(y)[-1]  # the piece does not move: use the demonstration's mean speed
    timed, _ = _time_path(tra_gen, start_speed, mean_speed, dt)
    complete = resample_time(np.vstack([prefix, timed]), n_steps)
    complete[-1] = target
    logger.debug(
        "extended demonstration: piece %d (samples %d-%d), %d G-PRM iterations",
        piece.index,
        piece.start,
        piece.end,
        len(history),
    )
    return _extension(complete, y, target, _Grown(points, piece, tra_gen, history, result))


def _log_dimensionless_jerk(points: np.ndarray, dt: float) -> float:
    """The log dimensionless jerk (Hogan & Sternad 2009), ``-ln(T⁵ / v_peak² ∫ |jerk|²)``, of
    samples ``dt`` apart (central differences): larger is smoother, independent of size and duration."""
    velocity = np.gradient(points, dt, axis=0)
    jerk = np.gradient(np.gradient(velocity, dt, axis=0), dt, axis=0)
    peak = float(np.max(np.linalg.norm(velocity, axis=1)))
    squared = float(np.trapezoid(np.sum(jerk**2, axis=1), dx=dt))
    if peak <= 0.0 or squared <= 0.0:
        return np.inf
    return float(-np.log((dt * (len(points) - 1)) ** 5 / peak**2 * squared))


class _Grown(NamedTuple):
    """How an extension was grown: the segmentation's points, the piece imitated, the generated
    path, G-PRM's similarity history and its result (None when G-PRM was skipped)."""

    points: np.ndarray
    piece: Piece
    tra_gen: np.ndarray
    history: np.ndarray
    result: RoadmapResult | None


def _extension(complete, y, target, grown: _Grown, **approach) -> ExtendedDemonstration:
    """The :class:`ExtendedDemonstration` both ways build."""
    points, piece, tra_gen, history, result = grown
    return ExtendedDemonstration(
        complete=complete,
        tra_imi=y[piece.start : piece.end + 1].copy(),
        tra_gen=tra_gen,
        seg_index=piece.start,
        similarity_history=np.asarray(history),
        demonstration=y,
        new_target=target,
        segmentation_points=points,
        piece=piece,
        similarity=float("nan") if result is None else result.similarity,
        template=None if result is None else result.template,
        samples=None if result is None else result.samples,
        **approach,
    )


def _extend_keeping_approach(
    y, target, points, seed, roadmap_options, keep_clear: tuple, approach_rotation=None
) -> ExtendedDemonstration:
    """``approach="keep"``: transfer by G-PRM to the translated approach's start, then the approach
    (rotated about the target by ``approach_rotation`` (D, D) when the target turns too);
    ``keep_clear`` = (the scene or None, the part labels at the target it may touch)."""
    scene, exclude = keep_clear
    n_steps = y.shape[0]
    dt = 1.0 / n_steps
    start = _final_approach(y, points)
    # The approach relative to the demonstrated target, moved (and turned) onto the new one.
    offsets = y[start:] - y[-1]
    if approach_rotation is not None:
        offsets = offsets @ np.asarray(approach_rotation, dtype=float).T
    hover, approach_tail = target + offsets[0], target + offsets[1:]
    if start == 0:
        # The whole demonstration is one straight approach: translate all of it but its start.
        piece = Piece(index=0, start=0, end=0, breakpoints=np.array([0, n_steps - 1]))
    else:
        head_points = points[points < start]
        piece = _choose_piece(y[: start + 1], head_points, hover)
    seg = y[piece.start]
    tra_imi = y[piece.start : piece.end + 1]
    if np.linalg.norm(hover - seg) <= 1e-9 * path_extent(y) or piece.end <= piece.start:
        candidates, history, result, refinement = (
            [np.vstack([seg, hover])],
            np.empty(0),
            None,
            "straight",
        )
    else:
        template = tra_imi if approach_rotation is None else _turned(tra_imi, approach_rotation)
        result, candidates, refinement = _route(template, hover, seed, roadmap_options)
        history = np.empty(0) if result is None else result.history
        logger.debug("transfer: %s (%d candidates)", refinement, len(candidates))
    if scene is not None:
        hit = scene.clearance(np.vstack([hover, approach_tail]), exclude=exclude)
        if not hit.collision_free:
            raise NoFreeRouteError(
                f"the demonstrated approach, translated to the new target {np.round(target, 3).tolist()}, "
                f"hits part {hit.part!r} ({-hit.distance:.3g} deep): no collision-free extension "
                f"keeps it; choose another target, or approach='paper'"
            )
    # Each candidate route timed like the demonstration; of those still free as timed (a corner's
    # blend moves the samples off the route), the smoothest timed transfer kept.
    seg_sample = y[piece.start : piece.start + 1]
    timed = [
        (_timed_transfer(route, y, piece.start, start, approach_tail, dt), route)
        for route in candidates
    ]
    is_free = roadmap_options.get("is_free")
    free = [
        pair for pair in timed if _path_is_free(np.vstack([seg_sample, pair[0]]), is_free)
    ] or timed
    transfer, tra_gen = max(
        free, key=lambda pair: _log_dimensionless_jerk(np.vstack([seg_sample, pair[0]]), dt)
    )
    complete = np.vstack([y[: piece.start + 1], transfer, approach_tail])
    logger.debug(
        "extended demonstration (keep): approach from sample %d kept, transfer from piece %d (samples %d-%d), "
        "%d G-PRM iterations",
        start,
        piece.index,
        piece.start,
        piece.end,
        len(history),
    )
    return _extension(
        complete,
        y,
        target,
        _Grown(points, piece, tra_gen, history, result),
        approach="keep",
        approach_index=start,
        refinement=refinement,
    )


def _turned(piece: np.ndarray, rotation) -> np.ndarray:
    """``piece`` (n, 3) with its steps turned progressively, by arc length, from not at all at its
    start to ``rotation`` (3, 3) at its end: the template of a transfer that joins an approach
    turned by ``rotation`` (its start and first direction kept, its last direction turned like
    the approach, so the route meets the approach without a corner the timing cannot blend)."""
    from scipy.spatial.transform import Rotation

    steps = np.diff(piece, axis=0)
    lengths = np.linalg.norm(steps, axis=1)
    total = float(lengths.sum())
    if total <= 0.0:
        return piece
    fraction = (np.cumsum(lengths) - 0.5 * lengths) / total  # at each step's middle
    turn = Rotation.from_matrix(np.asarray(rotation, dtype=float)).as_rotvec()
    turned = Rotation.from_rotvec(fraction[:, None] * turn).apply(steps)
    return np.vstack([piece[:1], piece[0] + np.cumsum(turned, axis=0)])


def _roadmap(tra_imi, target, seed, roadmap_options: dict, **changes) -> RoadmapResult:
    """G-PRM from the piece ``tra_imi`` to ``target`` with the extension's checked options (and
    ``changes`` to them), a generator from ``seed`` as :func:`gaussian_prm` makes one."""
    options = roadmap_options["options"]
    if changes:
        options = options.replace(**changes)
    return _gaussian_prm(tra_imi, target, options, roadmap_options["is_free"], check_seed(seed))


_WIDER = (3.0, 9.0)  # G-PRM's sampling spread, widened in turn when it finds no free route


def _route(tra_imi, hover, seed, roadmap_options) -> tuple:
    """``(G-PRM's result or None, the transfer, how it was made)`` from seg to ``hover``: G-PRM,
    then G-PRM sampling 3 and 9 times wider, then a route lifted over what is in the way
    (:func:`bidmp.extension.refine.lifted_route`); the first free one is refined. None free: G-PRM's
    own NoFreeRouteError."""
    is_free = roadmap_options.get("is_free")
    try:
        result = _roadmap(tra_imi, hover, seed, roadmap_options)
    except NoFreeRouteError as exc:
        first = exc
        for factor in _WIDER:
            sigma_rel = roadmap_options["options"].sigma_rel * factor
            try:
                result = _roadmap(tra_imi, hover, seed, roadmap_options, sigma_rel=sigma_rel)
                logger.info("G-PRM found a free route with its sampling %g times wider", factor)
                break
            except NoFreeRouteError:
                continue
        else:
            route = _lifted_route(tra_imi[0], hover, is_free)
            if route is None:
                raise first from None
            logger.info("no free route around: over, at %.4g", route[1, 2])
            smooth = _smoothest_free_route(route, is_free)
            return None, [route] if not smooth else smooth, "lifted"
    candidates, refinement = _refine_transfer(result.path, result.template, is_free)
    return result, candidates, refinement


@numerically_guarded
def extend_pose_demonstration(
    poses,
    new_target,
    *,
    seed: int | np.random.Generator | None = 0,
    scene=None,
    eps_frac: float = 0.1,
    method: str = "persistence",
    roadmap: RoadmapOptions | None = None,
):
    """Grow an extended pose demonstration (``approach="keep"``) from ``poses`` (T, 7) to the
    pose ``new_target`` (7,) (x, y, z, qx, qy, qz, qw).

    The final approach keeps its pose relative to the target: with ``R = g' g⁻¹`` (new and
    demonstrated target orientations) it is rotated about the target by ``R`` and moved onto the
    new one, positions and orientations alike (a pure translation when the target does not turn).
    The transfer's positions come from G-PRM as in :func:`extend_demonstration`; its orientation
    is slerped from the demonstration's at seg to the kept approach's first, by arc length.

    Returns
    -------
    ExtendedDemonstration
        As :func:`extend_demonstration` (``complete`` (T, 3) holds the positions), with
        ``orientations`` (T, 4) and ``poses`` (T, 7), the extended pose demonstration to learn.
    """
    from scipy.spatial.transform import Rotation, Slerp

    from ..primitives.cartesian import as_poses, as_quaternions

    positions, quaternions = as_poses(poses, "poses", min_points=10)
    target = as_point(new_target, 7, "new_target")
    target_q = as_quaternions(target[3:], "new_target's quaternion")[0]
    turn = Rotation.from_quat(target_q) * Rotation.from_quat(quaternions[-1]).inv()
    check_extension_options(eps_frac=eps_frac, method=method, seed=seed, approach="keep")
    exclude, is_free, _ = _scene_checker(scene, positions, target[:3], None)
    options = {"options": _options(roadmap, "roadmap"), "is_free": is_free}
    points = _segment(positions, eps_frac, method).points
    extension = _extend_keeping_approach(
        positions,
        target[:3],
        points,
        seed,
        options,
        (None, exclude),
        approach_rotation=turn.as_matrix(),
    )
    start, seg = extension.approach_index, extension.seg_index
    kept = (turn * Rotation.from_quat(quaternions[start:])).as_quat()
    # where the kept approach begins in complete
    hover = len(extension.complete) - (len(positions) - start)
    transfer = extension.complete[seg : hover + 1]
    arc = arclength(transfer)
    fraction = arc / arc[-1] if arc[-1] > 0 else np.linspace(0.0, 1.0, len(transfer))
    ends = Rotation.from_quat(np.vstack([quaternions[seg], kept[0]]))
    slerped = Slerp([0.0, 1.0], ends)(fraction).as_quat()
    orientations = np.vstack([quaternions[:seg], slerped, kept[1:]])
    from ..primitives.cartesian import continuous_quaternions

    orientations = continuous_quaternions(orientations)
    if scene is not None:
        hit = scene.clearance(extension.complete, exclude=exclude, orientations=orientations)
        if not hit.collision_free:
            raise NoFreeRouteError(
                f"the extended pose demonstration to {np.round(target[:3], 3).tolist()} hits part "
                f"{hit.part!r} ({-hit.distance:.3g} deep) with the tool as it is turned"
            )
    return dataclasses.replace(extension, orientations=orientations)
