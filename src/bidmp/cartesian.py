"""Pose skills: position + unit quaternion DMPs, and their Bi-DMP (issue 13).

Orientation is learned in the tangent space at the goal. A demonstrated orientation ``q(t)`` is
mapped to the rotation vector of its error to the goal,

    e(t) = Log(q(t) ⊗ g⁻¹) ∈ R³            (radians; e(T) = 0)

and a position DMP with goal 0 is fitted on ``e``. A rollout to a new goal orientation ``g'``
from a start ``q₀`` runs that DMP from ``Log(q₀ ⊗ g'⁻¹)`` to 0 and maps back,
``q(t) = Exp(e(t)) ⊗ g'``. This is the formulation of Koutras & Doulgeri (2020, "A correct
formulation for the orientation dynamic movement primitives for robot control in the Cartesian
space"): unlike the quaternion DMP of Ude et al. (2014) it is a plain DMP in R³. So it converges
to any goal orientation with the position DMP's guarantees, keeps the quaternion unit by
construction, and inherits everything bidmp's DMP has: both protocols, the progress gate's smooth
starts, temporal scaling, limits, the stepper, and the Bi-DMP increments. Ude's DMP
(movement_primitives' ``CartesianDMP``) and this one agree where they should. A test compares the
two on the same data with the same gains and phase.

Quaternions are ``(x, y, z, w)``, scalar last, as in SciPy and PyBullet. Poses are ``(T, 7)``
arrays ``x, y, z, qx, qy, qz, qw``. Angular velocities are in the world frame, in rad/s.
"""

from __future__ import annotations

import logging
import warnings
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation
from sklearn.base import BaseEstimator

from ._checks import as_point, as_trajectory, check_fitted, numerically_guarded
from ._trajectory import continuous_quaternions
from .dmp import DMP

__all__ = ["CartesianDMP", "CartesianBiDMP", "pose_forgetting", "prepare_poses", "PoseStepper", "PoseTrajectory", "as_quaternions", "as_poses", "continuous_quaternions",
           "orientation_error", "left_jacobian", "angle_between"]

logger = logging.getLogger(__name__)

_NORM_TOLERANCE = 1e-6  # a quaternion further than this from unit length is normalised, with a warning


def as_quaternions(q, name: str = "quaternions") -> np.ndarray:
    """Validate quaternions ``(n, 4)`` (x, y, z, w): finite, not zero; non-unit ones are
    normalised with a warning; signs made continuous."""
    array = np.asarray(q, dtype=float)
    if array.ndim == 1:
        array = array[None]
    if array.ndim != 2 or array.shape[1] != 4:
        raise ValueError(f"{name} must have shape (n, 4) (qx, qy, qz, qw), got {np.shape(q)}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} contain NaN or inf")
    norms = np.linalg.norm(array, axis=1)
    if np.any(norms < 1e-9):
        raise ValueError(f"{name}: row {int(np.argmax(norms < 1e-9))} is a zero quaternion, which is no rotation")
    off = np.abs(norms - 1.0) > _NORM_TOLERANCE
    if np.any(off):
        warnings.warn(f"{name}: {int(off.sum())} quaternion(s) were not of unit length (up to {np.max(np.abs(norms - 1)):.3g} off) "
                      f"and were normalised", UserWarning, stacklevel=3)
    return continuous_quaternions(array / norms[:, None])


def as_poses(poses, name: str = "poses", min_points: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Split ``(T, 7)`` poses into positions ``(T, 3)`` and validated quaternions ``(T, 4)``."""
    array = as_trajectory(poses, name, min_points=min_points, allow_static=True)
    if array.shape[1] != 7:
        raise ValueError(f"{name} must have 7 columns (x, y, z, qx, qy, qz, qw), got {array.shape[1]}")
    return array[:, :3].copy(), as_quaternions(array[:, 3:], f"{name}' quaternions")


def orientation_error(q, goal) -> np.ndarray:
    """Rotation vectors ``Log(q ⊗ goal⁻¹)`` (n, 3), radians."""
    return (Rotation.from_quat(q) * Rotation.from_quat(goal).inv()).as_rotvec()


def angle_between(q, p) -> np.ndarray:
    """The angle (rad) of the rotation between orientations ``q`` and ``p`` (n,)."""
    return np.linalg.norm(orientation_error(q, p), axis=-1)


def _skew(v: np.ndarray) -> np.ndarray:
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2], out[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    out[..., 1, 0], out[..., 2, 0], out[..., 2, 1] = v[..., 2], -v[..., 1], v[..., 0]
    return out


def left_jacobian(r: np.ndarray) -> np.ndarray:
    """Left Jacobian of SO(3), (n, 3, 3): ``ω = J_l(r) ṙ`` for ``R = Exp(r) G`` (world-frame ω)."""
    r = np.atleast_2d(r)
    theta = np.linalg.norm(r, axis=1)
    small = theta < 1e-6
    safe = np.where(small, 1.0, theta)
    a = np.where(small, 0.5 - theta**2 / 24.0, (1.0 - np.cos(safe)) / safe**2)
    b = np.where(small, 1.0 / 6.0 - theta**2 / 120.0, (safe - np.sin(safe)) / safe**3)
    k = _skew(r)
    return np.eye(3) + a[:, None, None] * k + b[:, None, None] * (k @ k)


@dataclass
class PoseTrajectory:
    """A timed pose trajectory (lengths in ``units``, angles in rad, time in s).

    Attributes
    ----------
    t : (n,)
    position, velocity, acceleration : (n, 3)
    orientation : (n, 4) unit quaternions (x, y, z, w)
    angular_velocity, angular_acceleration : (n, 3), world frame
    """

    t: np.ndarray
    position: np.ndarray
    orientation: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    acceleration: np.ndarray
    angular_acceleration: np.ndarray
    units: str = ""

    @property
    def poses(self) -> np.ndarray:
        """(n, 7): x, y, z, qx, qy, qz, qw."""
        return np.hstack([self.position, self.orientation])


def _orientation_from_error(error: np.ndarray, goal: np.ndarray) -> np.ndarray:
    q = (Rotation.from_rotvec(error) * Rotation.from_quat(goal)).as_quat()
    return continuous_quaternions(q / np.linalg.norm(q, axis=1, keepdims=True))


_ORIENTATION_WEIGHT = 1e-6  # rad -> "units" while prepare() filters: the idle ends are found from positions


def prepare_poses(poses, t, *, cutoff_hz: float = 6.0, idle_fraction: float = 0.05, units: str = ""):
    """:func:`bidmp.prepare` for a pose recording: uniform time, the same zero-phase low-pass on
    positions and on the orientation (in the tangent space at the last sample), idle ends
    trimmed by the positions' speed.

    Returns
    -------
    (poses (n, 7), t (n,), PrepareInfo)
        Uniform samples from 0 s; ``info.start_s`` is where they begin in the recording.
    """
    from .timing import prepare

    positions, quaternions = as_poses(poses, "poses", min_points=10)
    goal = quaternions[-1]
    # Scaled down, the orientation rides along through the same linear filter and resampling
    # without moving the speed threshold that finds the motion.
    stacked = np.hstack([positions, orientation_error(quaternions, goal) * _ORIENTATION_WEIGHT])
    trajectory, info = prepare(stacked, t, cutoff_hz=cutoff_hz, idle_fraction=idle_fraction, units=units)
    orientation = _orientation_from_error(trajectory.y[:, 3:] / _ORIENTATION_WEIGHT, goal)
    return np.hstack([trajectory.y[:, :3], orientation]), trajectory.t, info


class CartesianDMP(BaseEstimator):
    """A pose DMP: a position DMP and an orientation DMP on ``Log(q ⊗ g⁻¹)`` (module docstring).

    Parameters are those of :class:`bidmp.DMP` (the same for both parts). After ``fit``:
    ``position_``, ``orientation_`` (the two DMPs), ``start_pose_``, ``goal_pose_``.
    """

    def __init__(self, n_kernels=None, alpha=None, beta=None, K=None, alpha_phase=None, tau: float = 1.0,
                 regression: str = "lwr", derivatives: str = "gradient", ridge: float = 1e-8, widths: str = "spacing",
                 protocol: str = "robot", goal_rate=None) -> None:
        self.n_kernels = n_kernels
        self.alpha = alpha
        self.beta = beta
        self.K = K
        self.alpha_phase = alpha_phase
        self.tau = tau
        self.regression = regression
        self.derivatives = derivatives
        self.ridge = ridge
        self.widths = widths
        self.protocol = protocol
        self.goal_rate = goal_rate

    def _dmp(self) -> DMP:
        return DMP(**self.get_params())

    @numerically_guarded
    def fit(self, poses, t=None, units: str | None = None) -> "CartesianDMP":
        """Learn from one pose demonstration ``(T, 7)`` (x, y, z, qx, qy, qz, qw), with optional
        timestamps ``t`` (s) as :meth:`bidmp.DMP.fit`. Quaternion sign flips are made continuous;
        non-unit quaternions are normalised with a warning; zero ones refused."""
        positions, quaternions = as_poses(poses)
        goal = quaternions[-1]
        position = self._dmp().fit(positions, t, units)
        orientation = self._dmp().fit(orientation_error(quaternions, goal), t)
        self.position_, self.orientation_ = position, orientation
        self.start_pose_ = np.concatenate([positions[0], quaternions[0]])
        self.goal_pose_ = np.concatenate([positions[-1], goal])
        self.units_ = position.units_
        return self

    def __sklearn_is_fitted__(self) -> bool:
        return hasattr(self, "position_")

    @property
    def duration_(self) -> float:
        check_fitted(self, "position_")
        return self.position_.duration_

    def _query(self, goal, start):
        check_fitted(self, "position_")
        goal = self.goal_pose_ if goal is None else as_point(goal, 7, "goal")
        start = self.start_pose_ if start is None else as_point(start, 7, "start")
        goal_q = as_quaternions(goal[3:], "goal's quaternion")[0]
        start_q = as_quaternions(start[3:], "start's quaternion")[0]
        return goal[:3], goal_q, start[:3], orientation_error(start_q[None], goal_q)[0]

    @numerically_guarded
    def trajectory(self, goal=None, start=None, duration: float | None = None, dt: float | None = None, *,
                   limits: dict | None = None, position_increment=None, orientation_increment=None) -> PoseTrajectory:
        """A timed pose rollout (see :meth:`bidmp.DMP.trajectory`).

        Parameters
        ----------
        goal, start : array (7,), optional
            Poses (x, y, z, qx, qy, qz, qw); default the demonstration's.
        duration, dt : float, optional
            Seconds; temporal scaling as for positions.
        limits : dict, optional
            Position limits as :meth:`bidmp.DMP.trajectory` (``max_velocity`` ... in units/s);
            the orientation follows the same timing.
        """
        goal_p, goal_q, start_p, start_e = self._query(goal, start)
        position = self.position_.trajectory(goal_p, start_p, duration, dt, limits=limits,
                                             forcing_increment=position_increment)
        if limits:  # the orientation follows the motion time the position's limits chose
            duration = position.t[-1] / self.position_._params().settle
        error = self.orientation_.trajectory(np.zeros(3), start_e, duration, dt, forcing_increment=orientation_increment)
        n = min(len(position.t), len(error.t))
        orientation = _orientation_from_error(error.y[:n], goal_q)
        omega = np.einsum("nij,nj->ni", left_jacobian(error.y[:n]), error.yd[:n])
        alpha = np.gradient(omega, position.t[:n], axis=0) if n > 1 else np.zeros_like(omega)
        return PoseTrajectory(position.t[:n], position.y[:n], orientation, position.yd[:n], omega, position.ydd[:n],
                              alpha, self.units_)

    def rollout(self, goal=None, start=None, n_steps: int | None = None) -> np.ndarray:
        """Poses (n, 7) on the DMP's sample grid (as :meth:`bidmp.DMP.rollout`)."""
        goal_p, goal_q, start_p, start_e = self._query(goal, start)
        position = self.position_.rollout(goal_p, start_p, n_steps)
        error = self.orientation_.rollout(np.zeros(3), start_e, n_steps)
        return np.hstack([position, _orientation_from_error(error, goal_q)])

    def stepper(self, goal=None, start=None, duration: float | None = None, *, coupling: float = 0.0) -> "PoseStepper":
        """A step-by-step integrator for a control loop; phase stopping on the position error."""
        goal_p, goal_q, start_p, start_e = self._query(goal, start)
        return PoseStepper(self.position_.stepper(goal_p, start_p, duration, coupling=coupling),
                           self.orientation_.stepper(np.zeros(3), start_e, duration), goal_q)


    # -- persistence (used by bidmp.io) --------------------------------------------------------
    def _get_state(self) -> tuple[dict, dict]:
        check_fitted(self, "position_")
        return _parts_state(self, {"params": self.get_params()},
                            {"start_pose_": self.start_pose_, "goal_pose_": self.goal_pose_})

    @classmethod
    def _from_state(cls, meta: dict, arrays) -> "CartesianDMP":
        from ._checks import check_loaded

        position, orientation = _parts_from_state(DMP, "CartesianDMP", meta, arrays)
        model = cls(**meta["params"])
        model.position_, model.orientation_ = position, orientation
        for part in (model.position_, model.orientation_):
            if part.n_dims_ != 3:
                raise ValueError(f"a CartesianDMP's parts are 3-D; the file has D = {part.n_dims_}")
        model.start_pose_ = check_loaded(arrays["start_pose_"], "start_pose_", (7,))
        model.goal_pose_ = check_loaded(arrays["goal_pose_"], "goal_pose_", (7,))
        for name in ("start_pose_", "goal_pose_"):
            if abs(np.linalg.norm(getattr(model, name)[3:]) - 1.0) > 1e-6:
                raise ValueError(f"member {name} does not hold a unit quaternion")
        model.units_ = model.position_.units_
        return model


class CartesianBiDMP:
    """Bi-DMP on poses: the increment is learned on both forcing terms, position and orientation.

    Two :class:`bidmp.BiDMP` share the skill library: a query's skill is chosen on the position
    goal (``"nearest"``, ``"latest"`` or an index, as for positions), and the orientation part
    uses the same skill. Each skill keeps its own training start and goal orientation, so an
    extended pose demonstration is reproduced exactly where it was taught.

    Parameters
    ----------
    cartesian : CartesianDMP
        Fitted.
    **bidmp_params
        As :class:`bidmp.BiDMP` (n_windows, n_mapped, n_enhance, increments, shrink, reg, seed).
    """

    def __init__(self, cartesian: CartesianDMP, **bidmp_params):
        from .incremental import BiDMP

        check_fitted(cartesian, "position_")
        self.cartesian_ = cartesian
        self.position_ = BiDMP(cartesian.position_, **bidmp_params)
        self.orientation_ = BiDMP(cartesian.orientation_, **bidmp_params)
        self.skill_goal_orientations_ = [cartesian.goal_pose_[3:].copy()]
        self.skill_start_orientations_ = [cartesian.start_pose_[3:].copy()]

    @property
    def n_skills(self) -> int:
        return self.position_.n_skills

    def learn(self, poses) -> "CartesianBiDMP":
        """Learn a pose demonstration ``(T', 7)`` as a new skill (both parts). Returns self."""
        positions, quaternions = as_poses(poses, "poses")
        goal = quaternions[-1]
        self.position_.learn(positions)
        self.orientation_.learn(orientation_error(quaternions, goal))
        self.skill_goal_orientations_.append(goal.copy())
        self.skill_start_orientations_.append(quaternions[0].copy())
        return self

    def _query(self, goal, skill, start):
        goal = None if goal is None else as_point(goal, 7, "goal")
        index = self.position_.select_skill(None if goal is None else goal[:3], skill) if goal is not None or skill != "nearest" \
            else self.n_skills - 1
        goal_q = self.skill_goal_orientations_[index] if goal is None else as_quaternions(goal[3:], "goal's quaternion")[0]
        start = None if start is None else as_point(start, 7, "start")
        start_q = self.skill_start_orientations_[index] if start is None else as_quaternions(start[3:], "start's quaternion")[0]
        return (index, None if goal is None else goal[:3], None if start is None else start[:3], goal_q,
                orientation_error(start_q[None], goal_q)[0])

    def rollout(self, goal=None, skill="nearest", start=None, n_steps: int | None = None) -> np.ndarray:
        """Poses (n, 7) with one skill (chosen on the position goal)."""
        index, goal_p, start_p, goal_q, start_e = self._query(goal, skill, start)
        position = self.position_.rollout(goal_p, skill=index, start=start_p, n_steps=n_steps)
        error = self.orientation_.rollout(np.zeros(3), skill=index, start=start_e, n_steps=n_steps)
        return np.hstack([position, _orientation_from_error(error, goal_q)])

    # -- persistence (used by bidmp.io) --------------------------------------------------------
    def _get_state(self) -> tuple[dict, dict]:
        return _parts_state(self, {"params": self.cartesian_.get_params()},
                            {"start_pose_": self.cartesian_.start_pose_, "goal_pose_": self.cartesian_.goal_pose_,
                             "skill_goal_orientations_": np.array(self.skill_goal_orientations_),
                             "skill_start_orientations_": np.array(self.skill_start_orientations_)})

    @classmethod
    def _from_state(cls, meta: dict, arrays) -> "CartesianBiDMP":
        from ._checks import check_loaded
        from .incremental import BiDMP

        position, orientation = _parts_from_state(BiDMP, "CartesianBiDMP", meta, arrays)
        if position.n_skills != orientation.n_skills or position.dmp_.n_dims_ != 3 or orientation.dmp_.n_dims_ != 3:
            raise ValueError("the pose Bi-DMP's two parts do not match (skills or dimensions)")
        cartesian = CartesianDMP(**meta["params"])
        cartesian.position_, cartesian.orientation_ = position.dmp_, orientation.dmp_
        cartesian.start_pose_ = check_loaded(arrays["start_pose_"], "start_pose_", (7,))
        cartesian.goal_pose_ = check_loaded(arrays["goal_pose_"], "goal_pose_", (7,))
        cartesian.units_ = position.dmp_.units_
        model = cls.__new__(cls)
        model.cartesian_, model.position_, model.orientation_ = cartesian, position, orientation
        shape = (position.n_skills, 4)
        goals = check_loaded(arrays["skill_goal_orientations_"], "skill_goal_orientations_", shape)
        starts = check_loaded(arrays["skill_start_orientations_"], "skill_start_orientations_", shape)
        for name, values in (("skill_goal_orientations_", goals), ("skill_start_orientations_", starts)):
            if np.any(np.abs(np.linalg.norm(values, axis=1) - 1.0) > 1e-6):
                raise ValueError(f"member {name} does not hold unit quaternions")
        model.skill_goal_orientations_, model.skill_start_orientations_ = list(goals), list(starts)
        return model

    def stepper(self, goal=None, skill="nearest", start=None, duration: float | None = None, *,
                coupling: float = 0.0) -> "PoseStepper":
        index, goal_p, start_p, goal_q, start_e = self._query(goal, skill, start)
        return PoseStepper(self.position_.stepper(goal_p, skill=index, start=start_p, duration=duration, coupling=coupling),
                           self.orientation_.stepper(np.zeros(3), skill=index, start=start_e, duration=duration), goal_q)


def _parts_state(model, meta: dict, arrays: dict) -> tuple[dict, dict]:
    """A pose model's state: its own ``meta``/``arrays`` plus those of its ``position_`` and
    ``orientation_`` parts, the parts' members prefixed with their names."""
    for part in ("position", "orientation"):
        part_meta, part_arrays = getattr(model, f"{part}_")._get_state()
        meta[part] = part_meta
        arrays.update({f"{part}/{k}": v for k, v in part_arrays.items()})
    return meta, arrays


def _parts_from_state(part_class, name: str, meta: dict, arrays) -> tuple:
    """The (position, orientation) parts of a stored pose model, each read lazily from its prefix."""
    from .incremental import _Prefixed

    for key in ("params", "position", "orientation"):
        if not isinstance(meta.get(key), dict):
            raise ValueError(f"the {name} state has no {key} object")
    return tuple(part_class._from_state(meta[part], _Prefixed(arrays, f"{part}/")) for part in ("position", "orientation"))


def pose_forgetting(cartesian: CartesianDMP, demonstrations, skill: str = "nearest", **bidmp_params) -> np.ndarray:
    """Learn pose ``demonstrations`` in turn and measure forgetting: for each skill, the largest
    position error (units) and orientation error (rad) between its rollout after all were learned
    and right after it was learned, (n_skills, 2)."""
    model = CartesianBiDMP(cartesian, **bidmp_params)
    queries = [cartesian.goal_pose_]
    when_learned = [model.rollout(cartesian.goal_pose_, skill=skill)]
    for poses in demonstrations:
        model.learn(poses)
        goal = np.asarray(poses, dtype=float)[-1]
        queries.append(goal)
        when_learned.append(model.rollout(goal, skill=skill))
    out = np.zeros((len(queries), 2))
    for index, (goal, before) in enumerate(zip(queries, when_learned)):
        after = model.rollout(goal, skill=skill)
        out[index] = (np.max(np.linalg.norm(after[:, :3] - before[:, :3], axis=1)),
                      np.max(angle_between(after[:, 3:], before[:, 3:])))
    return out


class PoseStepper:
    """Steps a :class:`CartesianDMP`'s two parts together; the position part's phase stopping
    paces the orientation part too, so the two stay on the same motion time."""

    def __init__(self, position, orientation, goal_orientation):
        self.position = position
        self.orientation = orientation
        self.goal_orientation = goal_orientation

    @property
    def time(self) -> float:
        return self.position.time

    @property
    def y(self) -> np.ndarray:
        return np.concatenate([self.position.y, _orientation_from_error(self.orientation.y[None], self.goal_orientation)[0]])

    def step(self, dt: float, position_measured=None):
        """Command pose (7,), velocity (3,) and angular velocity (3,) now; advance ``dt`` s
        (less while the measured position lags)."""
        before = self.position.time
        y, yd, _ = self.position.step(dt, position_measured)
        advanced = self.position.time - before
        e, ed, _ = self.orientation.step(max(advanced, 1e-6))
        pace = advanced / dt if dt > 0 else 1.0
        q = _orientation_from_error(e[None], self.goal_orientation)[0]
        omega = left_jacobian(e)[0] @ ed * pace
        return np.concatenate([y, q]), yd, omega

