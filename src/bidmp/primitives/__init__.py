"""Movement primitives: arrays in, arrays out — no files, no scenarios, no CLI.

Where things live (the field's split, as in movement_primitives and dmpbbo):

* ``canonical`` — the phase and its grid;
* ``forcing`` — kernels, LWR/ridge weights, the forcing target;
* ``goals`` — goal systems (the paper's phase gate, a delayed goal, the robot protocol's progress
  gate): small objects a DMP composes;
* ``integrate`` — the fast LTI path (filters and outer products) and the step integrator;
* ``coupling`` — coupling terms ``coupling(t, y, yd, phase) -> acceleration`` for the step
  integrator (phase stopping is one);
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
    "phase_decay": "canonical",
    "check_phase_span": "canonical",
    "MIN_TRAINING_PHASE_LOG": "canonical",
    "kernel_centres": "forcing",
    "kernel_widths": "forcing",
    "basis_functions": "forcing",
    "basis_row": "forcing",
    "forcing_target": "forcing",
    "regress": "forcing",
    "LOG_PSI_FLOOR": "forcing",
    "GOAL_BLEND": "goals",
    "smoothstep": "goals",
    "smoothstep_derivatives": "goals",
    "goal_share": "goals",
    "goal_gate": "goals",
    "euler_progress_gate": "goals",
    "arclength_progress": "goals",
    "PhaseGate": "goals",
    "DelayedGoal": "goals",
    "ProgressGate": "goals",
    "euler_spectral_radius": "integrate",
    "check_euler_stable": "integrate",
    "check_integration": "integrate",
    "euler_responses": "integrate",
    "foh_step": "integrate",
    "exact_responses": "integrate",
    "exact_state": "integrate",
    "unit_responses": "integrate",
    "affine_rollouts": "integrate",
    "StepIntegrator": "integrate",
    "CouplingTerm": "coupling",
    "PhaseStopping": "coupling",
    "ConstantAcceleration": "coupling",
    "as_couplings": "coupling",
    "DMPStepper": "stepper",
    "Trajectory": "timing",
    "TimedMotion": "timing",
    "check_timestamps": "timing",
    "drop_duplicate_stamps": "timing",
    "uniform_time": "timing",
    "scale_factor": "timing",
    "time_scale": "timing",
    "Params": "protocols",
    "resolve_params": "protocols",
    "with_rest": "protocols",
    "ROBOT_ALPHA": "protocols",
    "ROBOT_KERNELS": "protocols",
    "ROBOT_ALPHA_PHASE": "protocols",
    "ROBOT_SETTLE": "protocols",
    "GAIN_RANGE": "protocols",
    "TAU_RANGE": "protocols",
    "rest_started": "rest",
    "REST_BLEND_SHARE": "rest",
    "REST_BLEND_MAX": "rest",
    "CartesianDMP": "cartesian",
    "PoseStepper": "cartesian",
    "PoseTrajectory": "cartesian",
    "as_quaternions": "cartesian",
    "as_poses": "cartesian",
    "continuous_quaternions": "cartesian",
    "orientation_error": "cartesian",
    "left_jacobian": "cartesian",
    "angle_between": "cartesian",
    "principal_log": "so3",
    "continuous_log": "so3",
    "nearest_turn": "so3",
    "orientation_from_log": "so3",
    "pose_trajectory": "pose_timing",
    "timed_trajectory": "timed",
    "coupled_trajectory": "timed",
    "limited_trajectory": "timed",
    "time_grid": "timed",
    "exact_rates": "timed",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
