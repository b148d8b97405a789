"""Bi-DMP on poses: incremental skills on both forcing terms of a :class:`bidmp.CartesianDMP`
(position and orientation), and the forgetting measure for pose skills.

Layer 1 (the math): imports ``bidmp.primitives`` and ``bidmp.incremental.bidmp`` only.
"""

from __future__ import annotations

import numpy as np

from .._api import Estimator, clone
from .._checks import (
    NotFittedError,
    as_point,
    check_fitted,
    check_limit,
    check_loaded,
    numerically_guarded,
)
from .._state import state_reader
from .._threads import single_threaded
from ..primitives.cartesian import CartesianDMP, PoseModel, as_poses
from ..primitives.dmp import DMP
from ..primitives.pose_timing import PoseStepper, PoseTrajectory
from ..primitives.so3 import angle_between, as_quaternions, orientation_from_log, principal_log
from .bidmp import BiDMP

__all__ = ["CartesianBiDMP", "pose_forgetting"]


def pose_forgetting(
    cartesian: CartesianDMP, demonstrations, skill: str = "nearest", **bidmp_params
) -> np.ndarray:
    """Learn pose ``demonstrations`` in turn and measure forgetting: for each skill, the largest
    position error (units) and orientation error (rad) between its rollout after all were learned
    and right after it was learned, (n_skills, 2)."""
    if not isinstance(cartesian, CartesianDMP):
        raise TypeError(
            f"cartesian must be a fitted bidmp.CartesianDMP, got {type(cartesian).__name__}"
        )
    if not isinstance(demonstrations, (list, tuple)):
        raise TypeError(
            f"demonstrations must be a list of pose arrays (T', 7), got {type(demonstrations).__name__}"
        )
    check_limit(len(demonstrations), "max_targets", "demonstrations: the number of skills to learn")
    for index, poses in enumerate(demonstrations):
        as_poses(poses, f"demonstrations[{index}]")
    model = CartesianBiDMP(cartesian, BiDMP(**bidmp_params))
    queries = [cartesian.goal_]
    when_learned = [model.rollout(cartesian.goal_, skill=skill)]
    for poses in demonstrations:
        model.learn(poses)
        goal = np.asarray(poses, dtype=float)[-1]
        queries.append(goal)
        when_learned.append(model.rollout(goal, skill=skill))
    out = np.zeros((len(queries), 2))
    for index, (goal, before) in enumerate(zip(queries, when_learned)):
        after = model.rollout(goal, skill=skill)
        out[index] = (
            np.max(np.linalg.norm(after[:, :3] - before[:, :3], axis=1)),
            np.max(angle_between(after[:, 3:], before[:, 3:])),
        )
    return out


# A pose Bi-DMP's parts are Bi-DMPs with its template's parameters, each on a part of the pose DMP.
_BIDMP_PARAMS = tuple(name for name in BiDMP._get_param_names() if name != "dmp")


class CartesianBiDMP(PoseModel, Estimator):
    """Bi-DMP on poses: the increment is learned on both forcing terms, position and orientation.

    A scikit-learn style estimator like :class:`bidmp.BiDMP`: ``CartesianBiDMP(cartesian)``
    only stores its parameters; the model starts from the fitted ``cartesian`` at the first
    :meth:`learn` (used as skill 0, never modified), or from a pose demonstration with
    :meth:`fit`, which fits a copy of ``cartesian`` (default ``CartesianDMP()``).

    Two :class:`bidmp.BiDMP` share the skill library: a query's skill is chosen on the position
    goal (``"nearest"``, ``"latest"`` or an index, as for positions), and the orientation part
    uses the same skill. Each skill keeps its own training start and goal orientation, so an
    extended pose demonstration is reproduced exactly where it was taught.

    Parameters
    ----------
    cartesian : CartesianDMP, default None
    bidmp : BiDMP, optional
        The parts' template (``n_windows``, ``n_enhance``, ``increments``, … as
        :class:`bidmp.BiDMP`; its ``dmp`` unset: each part's DMP is the pose DMP's); default
        ``BiDMP()``. ``set_params(bidmp__n_enhance=...)`` changes both parts' before they start.

    Attributes
    ----------
    cartesian_ : CartesianDMP
    position_, orientation_ : BiDMP
    skill_goal_orientations_, skill_start_orientations_ : array (n_skills, 4)
    skill_start_logs_ : array (n_skills, 3)
    """

    def __init__(self, cartesian: CartesianDMP | None = None, bidmp: BiDMP | None = None) -> None:
        self.cartesian = cartesian
        self.bidmp = bidmp

    def _bidmp_params(self) -> dict:
        """The parts' Bi-DMP parameters: the template's, checked to be a Bi-DMP without a DMP."""
        if self.bidmp is None:
            return {}
        if not isinstance(self.bidmp, BiDMP):
            raise TypeError(
                f"bidmp must be a bidmp.BiDMP (the parts' template) or None, got {type(self.bidmp).__name__}"
            )
        if self.bidmp.dmp is not None:
            raise ValueError(
                "bidmp is the parts' template: leave its dmp unset (each part's DMP is the pose DMP's)"
            )
        return {name: getattr(self.bidmp, name) for name in _BIDMP_PARAMS}

    def _start(self, cartesian: CartesianDMP) -> None:

        cartesian.fitted_parts()
        self.cartesian_ = cartesian
        self.position_ = BiDMP(cartesian.position_, **self._bidmp_params())
        self.orientation_ = BiDMP(cartesian.orientation_, **self._bidmp_params())
        self.position_.check_params()
        self.skill_goal_orientations_ = cartesian.goal_[None, 3:].copy()
        self.skill_start_orientations_ = cartesian.start_[None, 3:].copy()
        self.skill_start_logs_ = cartesian.start_log_[None].copy()

    def check_fitted(self) -> None:
        """Raise :class:`bidmp.NotFittedError`, saying what to do, unless the model has its skill
        0 (fitted, or built on a fitted CartesianDMP) and its parts are still fitted."""
        if "cartesian_" not in self.__dict__ and not (
            isinstance(self.cartesian, CartesianDMP) and "position_" in self.cartesian.__dict__
        ):
            raise NotFittedError(
                "this CartesianBiDMP is not fitted yet: pass a fitted CartesianDMP "
                "(CartesianBiDMP(CartesianDMP().fit(poses))) or call fit(poses) first"
            )
        self._ensure_started()
        self.cartesian_.fitted_parts()

    def _ensure_started(self) -> None:
        if "cartesian_" in self.__dict__:
            return
        if self.cartesian is None or not isinstance(self.cartesian, CartesianDMP):
            raise TypeError(
                f"cartesian must be a fitted bidmp.CartesianDMP, got {type(self.cartesian).__name__}"
            )
        check_fitted(self.cartesian, "position_")
        self._start(self.cartesian)

    def __sklearn_is_fitted__(self) -> bool:
        return "cartesian_" in self.__dict__

    @numerically_guarded
    @single_threaded  # small dense algebra: idle BLAS threads only steal the core
    def fit(self, poses, t=None, units: str | None = None) -> CartesianBiDMP:
        """Fit a copy of ``cartesian`` (default ``CartesianDMP()``) on one pose demonstration as
        skill 0, with no learned skills yet. Returns self."""
        cartesian = (
            clone(self.cartesian) if isinstance(self.cartesian, CartesianDMP) else CartesianDMP()
        )
        self._start(cartesian.fit(poses, t, units))
        return self

    @property
    def n_skills(self) -> int:
        self._ensure_started()
        return self.position_.n_skills

    @numerically_guarded
    @single_threaded  # small dense algebra: idle BLAS threads only steal the core
    def learn(self, poses, *, duration: float | None = None) -> CartesianBiDMP:
        """Learn a pose demonstration ``(T', 7)`` as a new skill (both parts), lasting ``duration``
        seconds (default the demonstration's; see :meth:`bidmp.BiDMP.learn`). Returns self."""
        self._ensure_started()
        positions, quaternions, log = self._split_poses(poses)
        # A pose skill may keep its position or its orientation still (not both: _split_poses).
        self.position_.learn(
            positions, duration=duration, allow_static=True, called="poses' positions"
        )
        self.orientation_.learn(
            log, duration=duration, allow_static=True, called="poses' orientation"
        )
        self.skill_goal_orientations_ = np.vstack([self.skill_goal_orientations_, quaternions[-1]])
        self.skill_start_orientations_ = np.vstack([self.skill_start_orientations_, quaternions[0]])
        self.skill_start_logs_ = np.vstack([self.skill_start_logs_, log[0]])
        return self

    def select_skill(self, goal=None, skill="nearest") -> int:
        """The skill a query uses (chosen on the position goal, as :meth:`bidmp.BiDMP.select_skill`)."""
        self._ensure_started()
        if goal is None and isinstance(skill, str) and skill == "nearest":
            return self.n_skills - 1
        goal = None if goal is None else as_point(goal, 7, "goal")[:3]
        return self.position_.select_skill(goal, skill)

    def _query(self, goal, skill, start):
        self._ensure_started()
        self.cartesian_.fitted_parts()
        index = self.select_skill(goal, skill)
        goal = None if goal is None else as_point(goal, 7, "goal")
        goal_q = (
            self.skill_goal_orientations_[index]
            if goal is None
            else as_quaternions(goal[3:], "goal's quaternion")[0]
        )
        start = None if start is None else as_point(start, 7, "start")
        start_q = (
            self.skill_start_orientations_[index]
            if start is None
            else as_quaternions(start[3:], "start's quaternion")[0]
        )
        start_e = self._start_error(start_q, goal_q, self.skill_start_logs_[index])
        return (
            index,
            None if goal is None else goal[:3],
            None if start is None else start[:3],
            goal_q,
            start_e,
        )

    def rollout(
        self, goal=None, *, skill="nearest", start=None, n_steps: int | None = None
    ) -> np.ndarray:
        """Poses (n, 7) with one skill (chosen on the position goal)."""
        index, goal_p, start_p, goal_q, start_e = self._query(goal, skill, start)
        position = self.position_.rollout(goal_p, skill=index, start=start_p, n_steps=n_steps)
        error = self.orientation_.rollout(np.zeros(3), skill=index, start=start_e, n_steps=n_steps)
        return np.hstack([position, orientation_from_log(error, goal_q)])

    @numerically_guarded
    def trajectory(  # noqa: PLR0913 - the public call spells its options out, as users pass them
        self,
        goal=None,
        *,
        skill="nearest",
        start=None,
        start_velocity=None,
        duration: float | None = None,
        dt: float | None = None,
        limits=None,
        coupling=None,
        via=None,
        via_until: float | None = None,
    ) -> PoseTrajectory:
        """A timed pose rollout of one skill (see :meth:`CartesianDMP.trajectory`; ``via`` poses
        and ``via_until`` as there; a pose motion starts at rest: ``start_velocity`` other than
        None is refused)."""
        via = self._at_rest_with(start_velocity, via)
        index, goal_p, start_p, goal_q, start_e = self._query(goal, skill, start)
        _, goal_p, start_p, position_increment, position = self.position_.query(
            goal_p, skill=index, start=start_p
        )
        _, _, start_e, orientation_increment, orientation = self.orientation_.query(
            np.zeros(3), skill=index, start=start_e
        )
        vias = (
            None
            if via is None
            else self._via_errors(
                orientation, via, goal_q, start_e, duration, dt, orientation_increment
            )
        )
        return self._timed(
            (position, orientation),
            (goal_p, start_p, goal_q, start_e),
            (position_increment, orientation_increment),
            self.cartesian_.units_,
            duration=duration,
            dt=dt,
            limits=limits,
            coupling=coupling,
            via=vias,
            via_until=via_until,
        )

    def stepper(
        self, goal=None, *, skill="nearest", start=None, duration: float | None = None, coupling=0.0
    ) -> PoseStepper:
        index, goal_p, start_p, goal_q, start_e = self._query(goal, skill, start)
        return PoseStepper(
            self.position_.stepper(
                goal_p, skill=index, start=start_p, duration=duration, coupling=coupling
            ),
            self.orientation_.stepper(np.zeros(3), skill=index, start=start_e, duration=duration),
            goal_q,
        )

    # -- persistence (used by bidmp.io) --------------------------------------------------------
    def to_state(self) -> tuple[dict, dict]:
        """The model-file form of the fitted model, ``(meta, arrays)``: its parameters and scalars
        as a JSON-able dict, its learned arrays by name (:func:`bidmp.io.save_model` writes the two
        into one ``.npz``; no pickle). Raises :class:`bidmp.NotFittedError` before ``fit``."""
        self._ensure_started()
        cartesian = self.cartesian_
        return self._parts_state(
            # the parts' template's parameters, as files always held
            {"params": (DMP() if cartesian.dmp is None else cartesian.dmp).get_params()},
            {
                "start_": cartesian.start_,
                "goal_": cartesian.goal_,
                "start_log_": cartesian.start_log_,
                "skill_goal_orientations_": self.skill_goal_orientations_,
                "skill_start_orientations_": self.skill_start_orientations_,
                "skill_start_logs_": self.skill_start_logs_,
            },
        )

    @classmethod
    @state_reader
    def from_state(cls, meta: dict, arrays) -> CartesianBiDMP:
        """The fitted model :meth:`to_state` described: ``meta`` as written, ``arrays`` a mapping of
        name to array, each read when needed and checked for dtype, shape and finiteness
        (:func:`bidmp.io.load_model` calls it; a bad file raises, naming the member)."""
        position, orientation = cls._parts_from_state(BiDMP, "CartesianBiDMP", meta, arrays)
        if (
            position.n_skills != orientation.n_skills
            or position.dmp_.n_dims_ != 3
            or orientation.dmp_.n_dims_ != 3
        ):
            raise ValueError("the pose Bi-DMP's two parts do not match (skills or dimensions)")
        cartesian = CartesianDMP(DMP(**cls._stored_params(meta["params"])))
        cartesian.position_, cartesian.orientation_ = position.dmp_, orientation.dmp_
        cartesian._read_pose_ends(arrays)
        cartesian.units_ = position.dmp_.units_
        model = cls(cartesian, BiDMP(**{name: getattr(position, name) for name in _BIDMP_PARAMS}))
        model.cartesian_, model.position_, model.orientation_ = cartesian, position, orientation
        shape = (position.n_skills, 4)
        goals = check_loaded(arrays["skill_goal_orientations_"], "skill_goal_orientations_", shape)
        starts = check_loaded(
            arrays["skill_start_orientations_"], "skill_start_orientations_", shape
        )
        for name, values in (
            ("skill_goal_orientations_", goals),
            ("skill_start_orientations_", starts),
        ):
            if np.any(np.abs(np.linalg.norm(values, axis=1) - 1.0) > 1e-6):
                raise ValueError(f"member {name} does not hold unit quaternions")
        model.skill_goal_orientations_, model.skill_start_orientations_ = goals, starts
        if "skill_start_logs_" in arrays:
            model.skill_start_logs_ = check_loaded(
                arrays["skill_start_logs_"], "skill_start_logs_", (position.n_skills, 3)
            )
        else:  # format 3
            model.skill_start_logs_ = np.array(
                [principal_log(s[None], g)[0] for s, g in zip(starts, goals)]
            )
        return model
