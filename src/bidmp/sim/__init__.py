"""Simulation: a scenario's motions executed on a simulated robot, measured.

* ``backend`` — the simulator backend protocol (``load_robot``, ``ik``, ``fk``, ``execute``,
  ``contacts``, ``render``) and the types it exchanges; a new simulator or robot is a subpackage
  beside ``pybullet`` that implements it;
* ``pybullet`` — the first backend: a serial arm of six or more joints in PyBullet, the Franka
  Panda by default, the KUKA iiwa, the xArm6, a UR5-class arm or your URDF (world, robot, IK,
  planning, execution, rendering, one module each);
* ``mujoco`` — the second: the same arms and cells in MuJoCo (``bidmp[mujoco]``), the same plans
  and control law, for checking one engine against the other (``make engines``);
* ``run`` — :func:`simulate`: every method's motion to every target, in worker processes;
* ``job``, ``job_report`` — :func:`run_job`: a scenario's whole task sequence (approach, unscrew, drop, ...), measured;
* ``kinematics`` — an arm's inverse kinematics without a task (joint goals, JointTrajectory output);
* ``fci`` — the Franka Control Interface's own limits (Panda, FR3) judging 1 kHz joint commands;
* ``libfranka`` — the same commands streamed through libfranka to franka-sim, a simulated FR3 (a
  side environment of their own, ``make franka``; ``_franka_side.py`` is what runs there);
* ``routes``, ``arm_geometry`` — the arm's complete fallback: a route planned in joint space over
  its links and tool against the cell, ending in the final approach, timed to its limits;
* ``report`` — the results, apart from any backend, and their files.

Layer 3 (the application): imports the math, ``io`` and ``tasks``; never ``cli``. PyBullet is an
extra (``bidmp[sim]``), imported when a world is built.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import exports

# The public names: imported on first use (bidmp._lazy reads this block), seen by type checkers.
if TYPE_CHECKING:
    from .arm_geometry import ArmGeometry, ArmSpace
    from .backend import (
        Execution,
        GoalUpdate,
        Hold,
        JointLimits,
        MotionPlan,
        MovablePart,
        SimError,
        SimulatorBackend,
        backend_names,
        get_backend,
        register_backend,
        require_simulator,
    )
    from .execution import TRACKING_ALLOWANCE_MM, execution_report, execution_settings
    from .fci import (
        FCI_LIMITS,
        CartesianLimits,
        FCILimits,
        FCIVerdict,
        judge_cartesian,
        judge_commands,
        match_joint_names,
    )
    from .job import JobInternalError, job_targets, run_job
    from .job_report import (
        JobPhase,
        JobReport,
        JobTarget,
        in_bin,
        in_slot,
        write_job_commands,
        write_job_report,
    )
    from .kinematic import KinematicCell
    from .kinematics import inverse_kinematics, joint_names
    from .libfranka import (
        LibfrankaOutcome,
        SideEnvironmentError,
        franka_side_environment,
        stream_fr3,
    )
    from .mujoco.cell import MujocoCell
    from .planning import plan_path
    from .pybullet.cell import RobotCell
    from .report import SimMethod, SimReport, SimTarget, picture_frames, write_sim_report
    from .robots import (
        FR3,
        IIWA,
        PANDA,
        ROBOT_MODELS,
        UR5,
        XARM6,
        RobotModel,
        robot_model,
        robot_placement,
    )
    from .routes import (
        DROP_CONE_DEG,
        SLOW,
        ArmRoute,
        arm_route,
        judged_route,
        needlessly_slow,
        reach,
        supports_routes,
    )
    from .run import simulate, target_labels
__getattr__, __dir__ = exports(__name__, __file__, globals())
