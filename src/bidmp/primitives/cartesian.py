"""Pose skills: position + unit quaternion DMPs, and their Bi-DMP.

Orientation is learned in the tangent space at the goal. A demonstrated orientation ``q(t)`` is
mapped to the rotation vector of its error to the goal,

    e(t) = Log(q(t) ⊗ g⁻¹) ∈ R³            (radians; e(T) = 0)

taken *continuous along the demonstration* (:func:`bidmp.primitives.so3.continuous_log`), so a turn of
several revolutions keeps its whole angle, and a position DMP with goal 0 is fitted on ``e``. A
rollout to a new goal orientation ``g'`` from a start ``q₀`` runs that DMP from ``Log(q₀ ⊗ g'⁻¹)``
(the equivalent nearest the demonstrated start's, so it turns the same way, as many times) to 0
and maps back, ``q(t) = Exp(e(t)) ⊗ g'``. This is the formulation of Koutras & Doulgeri (2020,
"A correct formulation for the orientation dynamic movement primitives for robot control in the
Cartesian space"): unlike the quaternion DMP of Ude et al. (2014) it is a plain DMP in R³. So it
converges to any goal orientation with the position DMP's guarantees, keeps the quaternion unit
by construction, and inherits everything bidmp's DMP has: both protocols, the smooth goal share,
temporal scaling, limits, the stepper, and the Bi-DMP increments.

A part that does not move (a socket held straight down while the tool travels, or a rotation in
place) is fitted all the same: its goal share follows the other part's progress.

Quaternions are ``(x, y, z, w)``, scalar last, as in SciPy and PyBullet. Poses are ``(T, 7)``
arrays ``x, y, z, qx, qy, qz, qw``. Angular velocities are in the world frame, in rad/s.
"""

from __future__ import annotations

import logging

import numpy as np

from .._api import Estimator
from .._checks import (
    as_point,
    as_trajectory,
    check_fitted,
    check_int,
    check_loaded,
    numerically_guarded,
)
from .._state import Prefixed, state_reader
from .._threads import single_threaded
from .._trajectory import continuous_quaternions as _continuous
from .dmp import DMP
from .forcing import _check_forcing_increment
from .goals import _arclength_progress
from .interface import _none_if_empty, _refuse_start_velocity
from .pose_timing import PoseStepper, PoseTrajectory, _pose_trajectory
from .so3 import (
    _nearest_turn,
    _quaternion_rows,
    angle_between,
    as_quaternions,
    continuous_log,
    orientation_from_log,
)
from .timing import _Rollout

__all__ = [
    "CartesianDMP",
    "PoseModel",
    "PoseStepper",
    "PoseTrajectory",
    "as_quaternions",
    "as_poses",
    "continuous_quaternions",
    "orientation_error",
    "angle_between",
]

logger = logging.getLogger(__name__)


def orientation_error(q, goal) -> np.ndarray:
    """Rotation vectors ``Log(q ⊗ goal⁻¹)`` (n, 3), radians, continuous along ``q`` (several
    turns keep their whole angle; see :func:`bidmp.primitives.so3.continuous_log`)."""
    return continuous_log(q, goal)


def as_poses(poses, name: str = "poses", min_points: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Split ``(T, 7)`` poses into positions ``(T, 3)`` and validated quaternions ``(T, 4)``."""
    if not isinstance(name, str) or not name or len(name) > 100:
        raise TypeError(
            f"name must be the argument's name (a short string), got {type(name).__name__}"
        )
    min_points = check_int(min_points, "min_points", minimum=1, limit="max_samples")
    array = as_trajectory(poses, name, min_points=min_points, allow_static=True)
    if array.shape[1] != 7:
        raise ValueError(
            f"{name} must have 7 columns (x, y, z, qx, qy, qz, qw), got {array.shape[1]}"
        )
    return array[:, :3].copy(), as_quaternions(array[:, 3:], f"{name}' quaternions")


def _fit_parts(
    position: DMP, orientation: DMP, positions, log, t, units, name: str = "poses"
) -> None:
    """Fit the two parts; a part that does not move follows the other's progress."""
    position_still = np.ptp(positions, axis=0).max() == 0.0
    orientation_still = np.ptp(log, axis=0).max() <= 1e-12
    if position_still:
        orientation.fit(log, t, called=(f"{name}' orientation", "rad"))
        position.fit(
            positions,
            t,
            units,
            progress=_arclength_progress(orientation.training_trajectory(log)),
            called=(f"{name}' positions", None),
        )
        return
    position.fit(positions, t, units, called=(f"{name}' positions", None))
    progress = (
        _arclength_progress(position.training_trajectory(positions)) if orientation_still else None
    )
    orientation.fit(log, t, progress=progress, called=(f"{name}' orientation", "rad"))


_SAME_TURN = 1e-9  # rad: a via orientation this close to the motion's own asks no change
_PART_PARAMS = tuple(DMP._get_param_names())  # a pose model's parameters are its parts' own


def continuous_quaternions(q) -> np.ndarray:
    """Quaternions ``(n, 4)`` (x, y, z, w) with signs flipped so that neighbours lie in the same
    hemisphere (``q`` and ``-q`` are one rotation); checked first: real, finite, not zero."""
    return _continuous(_quaternion_rows(q, "q"))


class PoseModel:
    """What a pose model is made of, shared by :class:`CartesianDMP` (two DMPs) and the pose
    Bi-DMP (:class:`bidmp.CartesianBiDMP`, two Bi-DMPs): a position part and an orientation part
    on the log map at the goal (module docstring). The subclass holds the parts as ``position_``
    and ``orientation_``; this class splits pose demonstrations into the parts' data, finds a
    start's turn, times the two parts together, and writes and reads them in model files."""

    @staticmethod
    def _split_poses(poses) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Positions (T, 3), quaternions (T, 4) and the continuous orientation log (T, 3) of a pose
        demonstration; refused if neither part moves."""
        positions, quaternions = as_poses(poses)
        log = continuous_log(quaternions, quaternions[-1])
        if np.ptp(positions, axis=0).max() == 0.0 and np.ptp(log, axis=0).max() <= 1e-12:
            raise ValueError(
                f"poses: the demonstration does not move: all {len(positions)} poses are the same "
                f"(position {np.round(positions[0], 6).tolist()}, one orientation)"
            )
        return positions, quaternions, log

    @staticmethod
    def _start_error(start_q, goal_q, reference) -> np.ndarray:
        """The start's ``Log(q ⊗ goal⁻¹)`` on the turn nearest ``reference`` (a multi-turn
        skill turns the same way, as many times, from another start)."""
        return _nearest_turn(start_q, goal_q, reference)

    def _at_rest_with(self, start_velocity, via):
        """A pose motion starts at rest (a start velocity is refused, naming the kind); ``via``
        with an empty sequence read as none."""
        _refuse_start_velocity(start_velocity, type(self).__name__)
        return _none_if_empty(via)

    @staticmethod
    def _timed(parts: tuple, ends: tuple, increments: tuple, units, **request):
        """The two parts timed together (:class:`PoseTrajectory`, see :func:`_pose_trajectory`);
        ``request``: duration, dt, limits, coupling, via (the two parts' via-points), via_until."""
        return _pose_trajectory(parts, ends, _Rollout(**request), increments, units)

    @staticmethod
    def _via_errors(
        orientation: DMP, via, goal_q, start_e, duration, dt, orientation_increment
    ) -> tuple[list, list]:
        """(position via-points, orientation-error via-points) of via poses ``[(t, pose (7,)), ...]``;
        ``orientation`` the orientation part (a DMP) and its skill's increment."""
        if not isinstance(via, (list, tuple)):
            raise TypeError(
                f"via must be a list of (t_seconds, pose) pairs, got {type(via).__name__}"
            )
        pairs = []
        for index, pair in enumerate(via):
            if isinstance(pair, (str, bytes)) or not hasattr(pair, "__len__") or len(pair) != 2:
                raise TypeError(f"via[{index}] must be a (t_seconds, pose) pair")
            pairs.append((pair[0], as_point(pair[1], 7, f"via[{index}] pose")))
        # The orientation part's own motion gives each via pose's turn (a multi-turn motion stays one).
        plain = orientation.trajectory(
            np.zeros(3),
            start=start_e,
            duration=duration,
            dt=dt,
            forcing_increment=orientation_increment,
        )
        errors = []
        for index, (t, pose) in enumerate(pairs):
            q = as_quaternions(pose[3:], f"via[{index}] quaternion")[0]
            reference = np.array([np.interp(float(t), plain.t, column) for column in plain.y.T])
            turn = _nearest_turn(q, goal_q, reference)
            # A via orientation the part passes anyway asks no change of its weights: left out, so
            # that a via pose which only moves the position (a lift) leaves the orientation as it is.
            if np.linalg.norm(turn - reference) > _SAME_TURN:
                errors.append((t, turn))
        return [(t, pose[:3]) for t, pose in pairs], errors or None

    def _parts_state(self, meta: dict, arrays: dict) -> tuple[dict, dict]:
        """A pose model's state: its own ``meta``/``arrays`` plus those of its ``position_`` and
        ``orientation_`` parts, the parts' members prefixed with their names."""
        for part in ("position", "orientation"):
            part_meta, part_arrays = getattr(self, f"{part}_").to_state()
            meta[part] = part_meta
            arrays.update({f"{part}/{k}": v for k, v in part_arrays.items()})
        return meta, arrays

    @staticmethod
    def _parts_from_state(part_class, name: str, meta: dict, arrays) -> tuple:
        """The (position, orientation) parts of a stored pose model, each read lazily from its prefix."""
        for key in ("params", "position", "orientation"):
            if not isinstance(meta.get(key), dict):
                raise ValueError(f"the {name} state has no {key} object")
        return tuple(
            part_class.from_state(meta[part], Prefixed(arrays, f"{part}/"))
            for part in ("position", "orientation")
        )

    @staticmethod
    def _stored_params(params: dict) -> dict:
        """A stored pose model's parameters; format 1-3 files integrated with explicit Euler."""
        params = dict(params)
        params.setdefault("integrator", "euler")
        return params

    def _read_pose_ends(self, arrays) -> None:
        """``start_``, ``goal_`` and ``start_log_`` of a stored pose model (format 3: ``start_pose_``
        and ``goal_pose_``, and the principal log at the start)."""
        from .so3 import principal_log

        old = "start_" not in arrays
        self.start_ = check_loaded(arrays["start_pose_" if old else "start_"], "start_", (7,))
        self.goal_ = check_loaded(arrays["goal_pose_" if old else "goal_"], "goal_", (7,))
        for name in ("start_", "goal_"):
            if abs(np.linalg.norm(getattr(self, name)[3:]) - 1.0) > 1e-6:
                raise ValueError(f"member {name} does not hold a unit quaternion")
        if old:
            self.start_log_ = principal_log(self.start_[None, 3:], self.goal_[3:])[0]
        else:
            self.start_log_ = check_loaded(arrays["start_log_"], "start_log_", (3,))


class CartesianDMP(PoseModel, Estimator):
    """A pose DMP: a position DMP and an orientation DMP on ``Log(q ⊗ g⁻¹)`` (module docstring).

    Parameters
    ----------
    dmp : DMP, optional
        The parts' template: both parts are fitted copies of it (its parameters, unfitted), so they
        share its parameters; default ``DMP()`` (the robot protocol). As for a DMP, only ``tau``
        may change after ``fit`` (``set_params(dmp__tau=2.0)``); the parts follow it.

    Attributes
    ----------
    position_, orientation_ : DMP
        The two parts (the orientation part's unit is the radian).
    start_, goal_ : array (7,)
        The demonstration's first and last pose (x, y, z, qx, qy, qz, qw).
    start_log_ : array (3,)
        The demonstrated start orientation's continuous log at the goal (rad; several turns
        included).
    units_ : str
    """

    def __init__(self, dmp: DMP | None = None) -> None:
        self.dmp = dmp

    def _template(self) -> DMP:
        """The parts' template: ``dmp``, checked, or the default DMP."""
        if self.dmp is None:
            return DMP()
        if not isinstance(self.dmp, DMP):
            raise TypeError(
                f"dmp must be a bidmp.DMP (the parts' template) or None, got {type(self.dmp).__name__}"
            )
        return self.dmp

    def _dmp(self) -> DMP:
        return DMP(**self._template().get_params())

    @numerically_guarded
    @single_threaded  # small dense algebra: idle BLAS threads only steal the core
    def fit(self, poses, t=None, units: str | None = None) -> CartesianDMP:
        """Learn from one pose demonstration ``(T, 7)`` (x, y, z, qx, qy, qz, qw), with optional
        timestamps ``t`` (s) as :meth:`bidmp.DMP.fit`. Quaternion sign flips are made continuous;
        non-unit quaternions are normalised with a warning; zero ones refused."""
        positions, quaternions, log = self._split_poses(poses)
        position, orientation = self._dmp(), self._dmp()
        _fit_parts(position, orientation, positions, log, t, units)
        self.position_, self.orientation_ = position, orientation
        self.start_ = np.concatenate([positions[0], quaternions[0]])
        self.goal_ = np.concatenate([positions[-1], quaternions[-1]])
        self.start_log_ = log[0].copy()
        self.units_ = position.units_
        return self

    def __sklearn_is_fitted__(self) -> bool:
        return "position_" in self.__dict__ and self.position_.__sklearn_is_fitted__()

    def check_fitted(self) -> None:
        """Raise :class:`bidmp.NotFittedError`, saying what to do, unless both parts are fitted
        with the parameters the model has now (one changed since ``fit`` is named)."""
        self.fitted_parts()

    def fitted_parts(self) -> tuple[DMP, DMP]:
        """The fitted parts ``(position_, orientation_)`` with the template's parameters passed on
        (a changed ``tau`` slows both); a learned parameter changed since ``fit`` raises
        :class:`bidmp.NotFittedError` naming it."""
        check_fitted(self, "position_")
        template = self._template()
        for part in (self.position_, self.orientation_):
            for (
                name
            ) in _PART_PARAMS:  # attribute access, not get_params(): this runs on every query
                value = getattr(template, name)
                if getattr(part, name) is not value:
                    setattr(part, name, value)
            part.check_fitted()
        return self.position_, self.orientation_

    @property
    def duration_(self) -> float:
        check_fitted(self, "position_")
        return self.position_.duration_

    def _query(self, goal, start):
        self.fitted_parts()
        goal = self.goal_ if goal is None else as_point(goal, 7, "goal")
        start = self.start_ if start is None else as_point(start, 7, "start")
        goal_q = as_quaternions(goal[3:], "goal's quaternion")[0]
        start_q = as_quaternions(start[3:], "start's quaternion")[0]
        return goal[:3], goal_q, start[:3], self._start_error(start_q, goal_q, self.start_log_)

    @numerically_guarded
    def trajectory(  # noqa: PLR0913 - the public call spells its options out, as users pass them
        self,
        goal=None,
        *,
        start=None,
        start_velocity=None,
        duration: float | None = None,
        dt: float | None = None,
        limits=None,
        position_increment=None,
        orientation_increment=None,
        coupling=None,
        via=None,
        via_until: float | None = None,
    ) -> PoseTrajectory:
        """A timed pose rollout (see :meth:`bidmp.DMP.trajectory`).

        Parameters
        ----------
        goal, start : array (7,), optional
            Poses (x, y, z, qx, qy, qz, qw); default the demonstration's.
        duration, dt : float, optional
            Seconds; temporal scaling as for positions.
        start_velocity : None
            A pose motion starts at rest: anything but None is refused.
        limits : bidmp.MotionLimits or dict, optional
            Position limits as :meth:`bidmp.DMP.trajectory` (``max_velocity`` ... in units/s);
            the orientation follows the same timing.
        coupling : list of coupling terms, optional
            Added to the position part's acceleration (units/s², see :meth:`bidmp.DMP.trajectory`);
            both parts then run the step integrator.
        via : list of (t, pose), optional
            Via poses (7,) passed exactly at ``t`` seconds: the position part through the
            positions, the orientation part through ``Log(q ⊗ goal⁻¹)`` on the turn nearest its
            own motion at that time (both least-norm, as :meth:`bidmp.DMP.trajectory`).
        via_until : float, optional
            With ``via``: only the kernels acting before this time (s) change, in both parts (as
            :meth:`bidmp.DMP.trajectory`).
        """
        via = self._at_rest_with(start_velocity, via)
        goal_p, goal_q, start_p, start_e = self._query(goal, start)
        _check_forcing_increment(position_increment, "position_increment")
        _check_forcing_increment(orientation_increment, "orientation_increment")
        vias = (
            None
            if via is None
            else self._via_errors(
                self.orientation_, via, goal_q, start_e, duration, dt, orientation_increment
            )
        )
        return self._timed(
            (self.position_, self.orientation_),
            (goal_p, start_p, goal_q, start_e),
            (position_increment, orientation_increment),
            self.units_,
            duration=duration,
            dt=dt,
            limits=limits,
            coupling=coupling,
            via=vias,
            via_until=via_until,
        )

    def rollout(self, goal=None, *, start=None, n_steps: int | None = None) -> np.ndarray:
        """Poses (n, 7) on the DMP's sample grid, in normalised time (as :meth:`bidmp.DMP.rollout`;
        :meth:`trajectory` is in seconds)."""
        goal_p, goal_q, start_p, start_e = self._query(goal, start)
        position = self.position_.rollout(goal_p, start=start_p, n_steps=n_steps)
        error = self.orientation_.rollout(np.zeros(3), start=start_e, n_steps=n_steps)
        return np.hstack([position, orientation_from_log(error, goal_q)])

    def stepper(
        self, goal=None, *, start=None, duration: float | None = None, coupling=0.0
    ) -> PoseStepper:
        """A step-by-step integrator for a control loop; phase stopping on the position error."""
        goal_p, goal_q, start_p, start_e = self._query(goal, start)
        return PoseStepper(
            self.position_.stepper(goal_p, start=start_p, duration=duration, coupling=coupling),
            self.orientation_.stepper(np.zeros(3), start=start_e, duration=duration),
            goal_q,
        )

    # -- persistence (used by bidmp.io) --------------------------------------------------------
    def to_state(self) -> tuple[dict, dict]:
        """The model-file form of the fitted model, ``(meta, arrays)``: its parameters and scalars
        as a JSON-able dict, its learned arrays by name (:func:`bidmp.io.save_model` writes the two
        into one ``.npz``; no pickle). Raises :class:`bidmp.NotFittedError` before ``fit``."""
        self.fitted_parts()
        return self._parts_state(
            {"params": self._template().get_params()},  # the template's, as files always held
            {"start_": self.start_, "goal_": self.goal_, "start_log_": self.start_log_},
        )

    @classmethod
    @state_reader
    def from_state(cls, meta: dict, arrays) -> CartesianDMP:
        """The fitted model :meth:`to_state` described: ``meta`` as written, ``arrays`` a mapping of
        name to array, each read when needed and checked for dtype, shape and finiteness
        (:func:`bidmp.io.load_model` calls it; a bad file raises, naming the member)."""
        position, orientation = cls._parts_from_state(DMP, "CartesianDMP", meta, arrays)
        model = cls(DMP(**cls._stored_params(meta["params"])))
        model.position_, model.orientation_ = position, orientation
        for part in (model.position_, model.orientation_):
            if part.n_dims_ != 3:
                raise ValueError(f"a CartesianDMP's parts are 3-D; the file has D = {part.n_dims_}")
        model._read_pose_ends(arrays)
        model.units_ = model.position_.units_
        return model
