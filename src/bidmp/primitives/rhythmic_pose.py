"""Rhythmic pose DMPs: positions and orientations on one rhythm.

The orientation is taken on the log map about its mean orientation: ``e = Log(q ⊗ q̄⁻¹)``, kept
continuous along the recording (:func:`~bidmp.primitives.continuous_log`), so a wrist that rocks
through more than half a turn, or ratchets round, keeps its turns. Positions and rotation vectors
are one 6-D rhythm (one frequency, one phase) learned by a :class:`RhythmicDMP`; each part is
scaled by its own RMS about its mean first, so a motion in mm and one in radians weigh alike in
the frequency estimate. Back on the sphere: ``q = Exp(e) ⊗ q̄``, the angular velocity
``ω = J_l(e) ė`` (world frame, ``J_l`` the left Jacobian of SO(3)).

Layer 1: the package's own math.
"""

from __future__ import annotations

import numpy as np

from .._api import Estimator
from .._checks import check_real
from .._state import state_reader
from .._threads import single_threaded
from .._units import check_units
from .cartesian import as_poses
from .pose_timing import PoseTrajectory
from .rhythmic import RhythmicDMP
from .so3 import _left_jacobian, continuous_log, orientation_from_log

__all__ = ["RhythmicPoseDMP", "mean_orientation"]


def mean_orientation(q) -> np.ndarray:
    """The chordal mean of unit quaternions (n, 4) (x, y, z, w): the principal eigenvector of
    ``Σ q qᵀ`` (sign-free), with ``w ≥ 0``."""
    from .so3 import as_quaternions

    q = as_quaternions(q, "q")
    _, vectors = np.linalg.eigh(q.T @ q)
    mean = vectors[:, -1]
    return mean if mean[3] >= 0.0 else -mean


class RhythmicPoseDMP(Estimator):
    """A rhythmic DMP of poses (x, y, z, qx, qy, qz, qw): the position and the orientation's log
    about its mean orientation on one rhythm.

    Parameters
    ----------
    n_kernels, alpha, concentration, n_harmonics, ridge
        As :class:`RhythmicDMP`.

    Attributes
    ----------
    rhythm_ : RhythmicDMP
        The 6-D rhythm (scaled positions and rotation vectors).
    mean_orientation_ : array (4,)
        The orientation the rhythm rocks about.
    frequency_ : float
        Hz.
    """

    # the rhythm's parameters: what each may be is the rhythmic DMP's
    _parameter_constraints = RhythmicDMP._parameter_constraints

    def __init__(
        self,
        n_kernels: int = 50,
        alpha: float = 25.0,
        concentration: float | None = None,
        n_harmonics: int | None = None,
        ridge: float = 1e-8,
    ) -> None:
        self.n_kernels = n_kernels
        self.alpha = alpha
        self.concentration = concentration
        self.n_harmonics = n_harmonics
        self.ridge = ridge

    @single_threaded  # small dense algebra: idle BLAS threads only steal the core
    def fit(self, poses, t, units: str | None = None) -> RhythmicPoseDMP:
        """Learn from a pose recording (T, 7) at stamps ``t`` (s) of at least 2 periods."""
        self._check_constraints()
        positions, quaternions = as_poses(poses, "poses", min_points=8)
        units = "" if units is None else check_units(units)
        mean = mean_orientation(quaternions)
        log = continuous_log(quaternions, mean)
        scales = []
        for part in (positions, log):
            rms = float(np.sqrt(np.mean(np.sum((part - part.mean(axis=0)) ** 2, axis=1))))
            scales.append(rms if rms > 0.0 else 1.0)
        stacked = np.hstack([positions / scales[0], log / scales[1]])
        rhythm = RhythmicDMP(
            n_kernels=self.n_kernels,
            alpha=self.alpha,
            concentration=self.concentration,
            n_harmonics=self.n_harmonics,
            ridge=self.ridge,
        ).fit(stacked, t)
        self.rhythm_ = rhythm
        self.mean_orientation_ = mean
        self.scales_ = np.array(scales)
        self.frequency_ = rhythm.frequency_
        self.estimate_ = rhythm.estimate_
        self.units_ = units
        return self

    def check_fitted(self) -> None:
        """Raise :class:`bidmp.NotFittedError`, saying what to do, unless the model is fitted."""
        if "rhythm_" not in self.__dict__:
            from .._checks import NotFittedError

            raise NotFittedError("this RhythmicPoseDMP is not fitted yet: call fit(poses, t) first")

    def trajectory(
        self,
        cycles: float = 1.0,
        *,
        dt: float = 0.001,
        frequency: float | None = None,
        amplitude: float = 1.0,
        anchor=None,
    ) -> PoseTrajectory:
        """``cycles`` periods on the limit cycle every ``dt`` s; ``anchor`` (3,) moves the position
        part's centre (units), the orientation rocks about its mean orientation."""
        self.check_fitted()
        amplitude = check_real(amplitude, "amplitude", nonnegative=True, maximum=1e6)
        if anchor is not None:
            from .._checks import as_point

            anchor = np.concatenate(
                [as_point(anchor, 3, "anchor") / self.scales_[0], self.rhythm_.anchor_[3:]]
            )
        motion = self.rhythm_.trajectory(
            cycles, dt=dt, frequency=frequency, amplitude=amplitude, anchor=anchor
        )
        position_scale, rotation_scale = self.scales_
        error = motion.y[:, 3:] * rotation_scale
        error_rate = motion.yd[:, 3:] * rotation_scale
        error_acceleration = motion.ydd[:, 3:] * rotation_scale
        jacobians = _left_jacobian(error)
        omega = np.einsum("nij,nj->ni", jacobians, error_rate)
        # dω/dt = J_l(e) ë + (dJ_l/dt) ė: the second term by central differences of J_l
        # (it vanishes for a rotation about one fixed axis).
        jacobian_rate = np.gradient(jacobians, motion.t, axis=0)
        omega_dot = np.einsum("nij,nj->ni", jacobians, error_acceleration) + np.einsum(
            "nij,nj->ni", jacobian_rate, error_rate
        )
        return PoseTrajectory(
            motion.t,
            motion.y[:, :3] * position_scale,
            motion.yd[:, :3] * position_scale,
            motion.ydd[:, :3] * position_scale,
            orientation_from_log(error, self.mean_orientation_),
            omega,
            omega_dot,
            self.units_,
        )

    # -- persistence (used by bidmp.io) -----------------------------------------------------
    def to_state(self) -> tuple[dict, dict]:
        """The model-file form of the fitted model, ``(meta, arrays)``: its parameters and scalars
        as a JSON-able dict, its learned arrays by name (:func:`bidmp.io.save_model` writes the two
        into one ``.npz``; no pickle). Raises :class:`bidmp.NotFittedError` before ``fit``."""
        self.check_fitted()
        state, arrays = self.rhythm_.to_state()
        arrays = {f"rhythm/{name}": value for name, value in arrays.items()}
        arrays["mean_orientation_"] = self.mean_orientation_
        arrays["scales_"] = self.scales_
        return {"params": self.get_params(), "rhythm": state, "units": self.units_}, arrays

    @classmethod
    @state_reader
    def from_state(cls, meta: dict, arrays) -> RhythmicPoseDMP:
        """The fitted model :meth:`to_state` described: ``meta`` as written, ``arrays`` a mapping of
        name to array, each read when needed and checked for dtype, shape and finiteness
        (:func:`bidmp.io.load_model` calls it; a bad file raises, naming the member)."""
        from .._checks import check_loaded
        from .._state import Prefixed

        model = cls(**meta["params"])
        rhythm = RhythmicDMP.from_state(meta["rhythm"], Prefixed(arrays, "rhythm/"))
        if rhythm.n_dims_ != 6:
            raise ValueError(f"member rhythm.weights_ has {rhythm.n_dims_} columns, expected 6")
        model.rhythm_ = rhythm
        mean = check_loaded(arrays["mean_orientation_"], "mean_orientation_", (4,))
        if not 0.5 < np.linalg.norm(mean) < 2.0:
            raise ValueError("member mean_orientation_ is not a unit quaternion")
        model.mean_orientation_ = mean / np.linalg.norm(mean)
        model.scales_ = check_loaded(arrays["scales_"], "scales_", (2,), positive=True)
        model.frequency_ = rhythm.frequency_
        model.estimate_ = rhythm.estimate_
        model.units_ = "" if not meta["units"] else check_units(meta["units"])
        return model
