"""Timed pose motion: :class:`PoseTrajectory` (the pose counterpart of :class:`bidmp.Trajectory`),
the timed rollout of a pose skill's two parts, and :class:`PoseStepper` for a control loop.
Public through :mod:`bidmp.primitives`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .._checks import as_point, as_vector, check_members
from .goal_shift import _GoalShifts
from .so3 import (
    _left_jacobian,
    _quaternion_rows,
    as_quaternions,
    orientation_from_log,
    principal_log,
)
from .timing import TimedMotion, _Rollout, _validate_motion

__all__ = ["PoseTrajectory", "PoseStepper"]


@dataclass(frozen=True)
class PoseTrajectory(TimedMotion):
    """A timed pose trajectory, the pose counterpart of :class:`bidmp.Trajectory` (lengths in
    ``units``, angles in rad, time in s).

    Attributes
    ----------
    t : (n,)
    y, yd, ydd : (n, 3)
        Position, velocity, acceleration (as :class:`bidmp.Trajectory`).
    q : (n, 4)
        Unit quaternions (x, y, z, w).
    omega, omega_dot : (n, 3)
        Angular velocity and acceleration, world frame (rad/s, rad/s²).
    """

    t: np.ndarray
    y: np.ndarray
    yd: np.ndarray
    ydd: np.ndarray
    q: np.ndarray
    omega: np.ndarray
    omega_dot: np.ndarray
    units: str = ""

    def __post_init__(self) -> None:
        _validate_motion(
            self,
            "PoseTrajectory",
            (("y", 3), ("yd", 3), ("ydd", 3), ("q", 4), ("omega", 3), ("omega_dot", 3)),
        )

    @property
    def poses(self) -> np.ndarray:
        """(n, 7): x, y, z, qx, qy, qz, qw."""
        return np.hstack([self.y, self.q])

    def columns(self) -> tuple[list[str], np.ndarray]:
        """Column names ``t, x, y, z, qx, qy, qz, qw, vx, vy, vz, wx, wy, wz, ax, ay, az, dwx, dwy,
        dwz`` and the matching (n, 20) array: the layout of timed pose CSV files."""
        header = [
            "t",
            "x",
            "y",
            "z",
            "qx",
            "qy",
            "qz",
            "qw",
            "vx",
            "vy",
            "vz",
            "wx",
            "wy",
            "wz",
            "ax",
            "ay",
            "az",
            "dwx",
            "dwy",
            "dwz",
        ]
        return header, np.column_stack(
            [self.t, self.y, self.q, self.yd, self.omega, self.ydd, self.omega_dot]
        )

    def peak_angular_speed(self) -> float:
        """Largest ‖omega‖ (rad/s)."""
        return float(np.max(np.linalg.norm(self.omega, axis=1)))


_JACOBIAN_STEP = 1e-7  # s: the left Jacobian's change along ė, by a forward difference


def _angular_rates(e: np.ndarray, ed: np.ndarray, edd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World-frame angular velocity ``ω = J_l(e) ė`` and acceleration ``ω̇ = J_l(e) ë + (d/dt J_l) ė``
    (n, 3) from the orientation log and its derivatives."""
    jacobian = _left_jacobian(e)
    omega = np.einsum("nij,nj->ni", jacobian, ed)
    change = (_left_jacobian(e + ed * _JACOBIAN_STEP) - jacobian) / _JACOBIAN_STEP
    omega_dot = np.einsum("nij,nj->ni", jacobian, edd) + np.einsum("nij,nj->ni", change, ed)
    return omega, omega_dot


def _pose_trajectory(
    parts: tuple, ends: tuple, request: _Rollout, increments: tuple, units
) -> PoseTrajectory:
    """The timed pose rollout of two ``parts`` (position DMP or Bi-DMP skill, orientation
    likewise) from ``ends`` = (goal position, start position, goal quaternion, start orientation
    error) with the parts' forcing ``increments``; ``request``: duration, dt, limits, coupling
    terms (on the position part; both parts then run the step integrator), ``via`` = (position
    via-points, orientation-error via-points) or None, ``via_until`` as :meth:`bidmp.DMP.trajectory`
    for both."""
    position_model, orientation_model = parts
    goal_p, start_p, goal_q, start_e = ends
    position_increment, orientation_increment = increments
    duration, dt, limits, coupling = request.duration, request.dt, request.limits, request.coupling
    vias, via_until = request.via, request.via_until
    position_via, error_via = (None, None) if vias is None else vias
    position = position_model.trajectory(
        goal_p,
        start=start_p,
        duration=duration,
        dt=dt,
        limits=limits,
        forcing_increment=position_increment,
        coupling=coupling,
        via=position_via,
        via_until=via_until,
    )
    # the orientation follows the motion time the position's limits chose
    if limits and vias is None:
        duration = position.t[-1] / position_model.settings().settle
    error = orientation_model.trajectory(
        np.zeros(3),
        start=start_e,
        duration=duration,
        dt=dt,
        forcing_increment=orientation_increment,
        coupling=None if coupling is None else [],
        via=error_via,
        via_until=None if error_via is None else via_until,
    )
    n = min(len(position.t), len(error.t))
    orientation = orientation_from_log(error.y[:n], goal_q)
    omega, omega_dot = _angular_rates(error.y[:n], error.yd[:n], error.ydd[:n])
    return PoseTrajectory(
        position.t[:n],
        position.y[:n],
        position.yd[:n],
        position.ydd[:n],
        orientation,
        omega,
        omega_dot,
        units,
    )


class PoseStepper:
    """Steps a :class:`CartesianDMP`'s two parts together; the position part's phase stopping
    paces the orientation part too, so the two stay on the same motion time.

    ``step(dt, y_measured=None)`` returns what :meth:`bidmp.primitives.stepper.DMPStepper.step` returns, for a
    pose: ``(pose (7,), velocity (6,), acceleration (6,))`` with the velocity ``[vx, vy, vz, wx,
    wy, wz]`` (units/s, rad/s, world frame) and the acceleration likewise (units/s², rad/s²).
    """

    def __init__(self, position, orientation, goal_orientation):
        # (what a step reads of each; a pose DMP's stepper() makes them)
        self.position = check_members(
            position, ("step", "set_goal", "time", "y"), "position", "the position's DMPStepper"
        )
        self.orientation = check_members(
            orientation, ("step", "y"), "orientation", "the orientation's DMPStepper (its log)"
        )
        goal = _quaternion_rows(goal_orientation, "goal_orientation")  # (its values as given)
        if goal.shape[0] != 1:
            raise ValueError(f"goal_orientation must be one quaternion (4,), got {goal.shape[0]}")
        self.goal_orientation = goal[0]
        self._turns = _GoalShifts(3)  # rotation vectors δ of the goal frame, blended in turn

    def set_goal_pose(
        self, pose, *, limits: dict | None = None, blend: float | None = None
    ) -> float:
        """Move the goal to ``pose`` (7,) mid-motion: the position as
        :meth:`bidmp.primitives.stepper.DMPStepper.set_goal`, the orientation by turning the goal
        frame ``Exp(s(t) δ) ⊗ goal`` over the same blend (``δ`` the principal rotation from the
        current goal orientation to the new one, ``s`` the same smoothstep), so the tool arrives
        at rest in the new pose. ``limits`` as there (on the position). Returns the blend (s)."""
        pose = as_point(pose, 7, "pose")
        new_q = as_quaternions(pose[3:], "pose's quaternion")[0]
        blend = self.position.set_goal(pose[:3], limits=limits, blend=blend)
        current = self._goal_now(np.inf)[0]
        delta = principal_log(new_q[None], current)[0]
        self._turns.add(delta, self.position.time, float(blend))
        return blend

    def _goal_now(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The goal frame (4,) at motion time ``t`` and its angular velocity and acceleration
        (world frame, rad/s, rad/s²)."""
        goal, omega, omega_dot = self.goal_orientation, np.zeros(3), np.zeros(3)
        for delta, share, rate, rate_rate in self._turns.profiles(t):
            # goal ← A ⊗ goal with A = Exp(s δ), whose axis is fixed in the world: ω_A = ṡ δ, and
            # ω = ω_A + R_A ω, ω̇ = ω̇_A + R_A ω̇ + ω_A × R_A ω.
            turn = Rotation.from_rotvec(share * delta)
            goal = orientation_from_log((share * delta)[None], goal)[0]
            carried = turn.apply(omega)
            omega_dot = rate_rate * delta + turn.apply(omega_dot) + np.cross(rate * delta, carried)
            omega = rate * delta + carried
        return goal, omega, omega_dot

    @property
    def time(self) -> float:
        return self.position.time

    @property
    def y(self) -> np.ndarray:
        return np.concatenate(
            [
                self.position.y,
                orientation_from_log(
                    self.orientation.y[None], self._goal_now(self.position.time)[0]
                )[0],
            ]
        )

    def step(self, dt: float, y_measured=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Command pose, velocity and acceleration now; advance ``dt`` s (less while the measured
        position lags)."""
        before = self.position.time
        if y_measured is not None:
            y_measured = as_vector(y_measured, "y_measured")
            if y_measured.shape[0] not in (3, 7):
                raise ValueError(
                    f"y_measured must be a position (3,) or a pose (7,), got {y_measured.shape[0]} values"
                )
        y, yd, ydd = self.position.step(dt, None if y_measured is None else y_measured[:3])
        advanced = self.position.time - before
        e, ed, edd = self.orientation.step(max(advanced, 1e-6))
        pace = advanced / dt if dt > 0 else 1.0
        omega, omega_dot = _angular_rates(e[None], ed[None], edd[None])
        omega, omega_dot = omega[0], omega_dot[0]
        if not self._turns:
            q = orientation_from_log(e[None], self.goal_orientation)[0]
        else:  # q = Exp(e) ⊗ G(t): ω = ω_e + R(e) ω_G, ω̇ = ω̇_e + R(e) ω̇_G + ω_e × R(e) ω_G
            goal, turn, turn_rate = self._goal_now(before)
            q = orientation_from_log(e[None], goal)[0]
            rotation = Rotation.from_rotvec(e).as_matrix()
            omega_dot = omega_dot + rotation @ turn_rate + np.cross(omega, rotation @ turn)
            omega = omega + rotation @ turn
        return (
            np.concatenate([y, q]),
            np.concatenate([yd, omega * pace]),
            np.concatenate([ydd, omega_dot * pace**2]),
        )
