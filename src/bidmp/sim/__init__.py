"""Simulation: a scenario's motions executed on a simulated robot, measured.

* ``backend`` — the simulator backend protocol (``load_robot``, ``ik``, ``fk``, ``execute``,
  ``contacts``, ``render``) and the types it exchanges; a new simulator or robot is a subpackage
  beside ``pybullet`` that implements it;
* ``pybullet`` — the first backend: a serial arm of six or more joints in PyBullet, the Franka
  Panda by default, the KUKA iiwa, the xArm6, a UR5-class arm or your URDF (world, robot, IK, planning, execution, rendering, one module each);
* ``run`` — :func:`simulate`: every method's motion to every target, in worker processes;
* ``job``, ``job_report`` — :func:`run_job`: a scenario's whole task sequence (approach, unscrew, drop, ...), measured;
* ``kinematics`` — an arm's inverse kinematics without a task (joint goals, JointTrajectory output);
* ``report`` — the results, apart from any backend, and their files.

Layer 3 (the application): imports the math, ``io`` and ``tasks``; never ``cli``. PyBullet is an
extra (``bidmp[sim]``), imported when a world is built.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "simulate": "run",
    "target_labels": "run",
    "run_job": "job",
    "job_targets": "job",
    "JobReport": "job_report",
    "JobTarget": "job_report",
    "JobPhase": "job_report",
    "write_job_report": "job_report",
    "in_bin": "job_report",
    "in_slot": "job_report",
    "inverse_kinematics": "kinematics",
    "joint_names": "kinematics",
    "require_simulator": "backend",
    "MovablePart": "backend",
    "backend_names": "backend",
    "get_backend": "backend",
    "register_backend": "backend",
    "KinematicCell": "kinematic",
    "plan_path": "planning",
    "SimulatorBackend": "backend",
    "SimError": "backend",
    "JointLimits": "backend",
    "Hold": "backend",
    "GoalUpdate": "backend",
    "MotionPlan": "backend",
    "Execution": "backend",
    "RobotCell": "pybullet.cell",
    "PANDA": "robots",
    "IIWA": "robots",
    "XARM6": "robots",
    "UR5": "robots",
    "RobotModel": "robots",
    "ROBOT_MODELS": "robots",
    "robot_model": "robots",
    "robot_placement": "robots",
    "SimTarget": "report",
    "SimMethod": "report",
    "SimReport": "report",
    "write_sim_report": "report",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
