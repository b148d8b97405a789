"""Movement primitives: arrays in, arrays out — no files, no scenarios, no CLI.

Where things live (the field's split, as in movement_primitives and dmpbbo):

* ``canonical`` — the phase as a component (the ``CanonicalSystem`` protocol; the exponential
  phase);
* ``forcing`` — the basis as a component (the ``Basis`` protocol; Gaussian kernels), LWR/ridge
  weights, the forcing target;
* ``goals`` — goal systems (the paper's phase gate, a delayed goal, the robot protocol's progress
  gate): small objects a DMP composes;
* ``integrate`` — the fast LTI path (filters and outer products) and the step integrator;
* ``coupling`` — coupling terms ``coupling(t, y, yd, phase) -> acceleration`` for the step
  integrator (phase stopping is one); ``avoidance`` — steering round a scene's parts;
* ``via`` — exact via-points (least-norm weight change); ``goal_shift`` — goals moved mid-motion;
* ``dmp`` — :class:`DMP`, the estimator that composes them; ``stepper`` — its control-loop stepper;
* ``cartesian``, ``so3``, ``pose_timing`` — pose DMPs on unit quaternions;
* ``multi`` — a DMP from several demonstrations, with their spread; ``promp`` — probabilistic
  movement primitives from several demonstrations, exact
  conditioning; ``prodmp`` — probabilistic DMPs: the DMP's solution in closed form, batched
  rollouts in one product, a ProMP's conditioning (``prodmp_responses``: its precomputed basis);
* ``rhythmic`` — periodic DMPs and their modulation while running; ``frequency`` — a periodic
  recording's frequency, steady part and spread; ``oscillator`` — adaptive frequency oscillators;
* ``timing`` — timed trajectories and time scaling to limits; ``limits`` — :class:`MotionLimits`,
  the caps a motion runs within;
* ``interface`` — the one call every point-to-point kind answers (:class:`MotionPrimitive`) and
  the probabilistic kinds' own (:class:`ProbabilisticPrimitive`).

Layer 1 (the math): imports only ``bidmp._checks`` and the other private helpers of the package
root, never ``tasks``, ``io``, ``sim`` or ``cli``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import exports

# The public names: imported on first use (bidmp._lazy reads this block), seen by type checkers.
if TYPE_CHECKING:
    from .approach import straight_tail_start
    from .avoidance import AvoidanceError, SceneAvoidance
    from .canonical import CanonicalSystem, ExponentialPhase, RhythmicPhase, phase_grid
    from .cartesian import (
        CartesianDMP,
        PoseModel,
        PoseStepper,
        PoseTrajectory,
        angle_between,
        as_poses,
        as_quaternions,
        continuous_quaternions,
        orientation_error,
    )
    from .coupling import ConstantAcceleration, CouplingTerm, PhaseStopping
    from .dmp import DMP, PROTOCOLS
    from .forcing import (
        Basis,
        GaussianBasis,
        VonMisesBasis,
        basis_functions,
        kernel_centres,
        kernel_widths,
    )
    from .frequency import FrequencyEstimate, estimate_frequency, harmonic_fit
    from .goals import ApproachGate, DelayedGoal, PhaseGate, ProgressGate
    from .integrate import StepIntegrator
    from .interface import MotionPrimitive, ProbabilisticPrimitive
    from .limits import MotionLimits, as_motion_limits
    from .multi import MultiDMP
    from .oscillator import AdaptiveOscillator
    from .prodmp import ProDMP, ProDMPBasis, prodmp_basis
    from .promp import ProMP, condition_gaussian, promp_basis
    from .registry import MODEL_KINDS, PrimitiveKind, kind_of, model_class, register_kind
    from .rhythmic import RhythmicDMP, RhythmicStepper
    from .rhythmic_pose import RhythmicPoseDMP, mean_orientation
    from .settings import (
        ROBOT_ALPHA,
        ROBOT_ALPHA_PHASE,
        ROBOT_KERNELS,
        ROBOT_SETTLE,
        DMPSettings,
    )
    from .so3 import continuous_log, orientation_from_log, principal_log
    from .stepper import DMPStepper
    from .system import DMPSystem
    from .timing import (
        TimedMotion,
        Trajectory,
        check_timestamps,
        drop_repeated_stamps,
        on_uniform_time,
        scale_factor,
        time_scale,
        uniform_time,
    )
__getattr__, __dir__ = exports(__name__, __file__, globals())
