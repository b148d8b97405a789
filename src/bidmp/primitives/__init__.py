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
* ``timing`` — timed trajectories and time scaling to limits.

Layer 1 (the math): imports only ``bidmp._checks`` and the other private helpers of the package
root, never ``tasks``, ``io``, ``sim`` or ``cli``.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "DMP": "dmp",
    "PROTOCOLS": "dmp",
    "phase_grid": "canonical",
    "CanonicalSystem": "canonical",
    "ExponentialPhase": "canonical",
    "Basis": "forcing",
    "GaussianBasis": "forcing",
    "kernel_centres": "forcing",
    "kernel_widths": "forcing",
    "basis_functions": "forcing",
    "PhaseGate": "goals",
    "DelayedGoal": "goals",
    "ProgressGate": "goals",
    "StepIntegrator": "integrate",
    "CouplingTerm": "coupling",
    "PhaseStopping": "coupling",
    "ConstantAcceleration": "coupling",
    "SceneAvoidance": "avoidance",
    "AvoidanceError": "avoidance",
    "DMPStepper": "stepper",
    "Trajectory": "timing",
    "TimedMotion": "timing",
    "check_timestamps": "timing",
    "uniform_time": "timing",
    "drop_repeated_stamps": "timing",
    "scale_factor": "timing",
    "time_scale": "timing",
    "ROBOT_ALPHA": "protocols",
    "ROBOT_KERNELS": "protocols",
    "ROBOT_ALPHA_PHASE": "protocols",
    "ROBOT_SETTLE": "protocols",
    "CartesianDMP": "cartesian",
    "PoseStepper": "cartesian",
    "PoseTrajectory": "cartesian",
    "as_quaternions": "cartesian",
    "as_poses": "cartesian",
    "continuous_quaternions": "cartesian",
    "orientation_error": "cartesian",
    "angle_between": "cartesian",
    "principal_log": "so3",
    "continuous_log": "so3",
    "orientation_from_log": "so3",
    "ApproachGate": "goals",
    "straight_tail_start": "approach",
    "PoseModel": "cartesian",
    "on_uniform_time": "timing",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
