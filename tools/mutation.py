"""Mutation testing of the checks that guard the robot and judge success (``make mutation``).

For each judging function named in :data:`TARGETS`, every small realistic bug is planted one at a
time — a comparison made strict or loose, ``==`` turned ``!=``, ``+`` for ``-``, ``*`` for ``/``, a
constant changed, an ``abs`` or a sign dropped, ``and`` for ``or``, ``min`` for ``max``, ``all`` for
``any`` — and, where checks are assembled into the verdict a robot acts on, the bugs people make
there, written by hand in :data:`SEMANTIC` (a wrong frame, a dropped argument, a stale verdict:
a text of the function replaced by another); the tests that cover the function run against
each. A mutant the tests fail on is
*killed*; one they pass is a *survivor*, and each survivor is either killed by a new test or shown
to be an equivalent mutant in :data:`EQUIVALENT` (with the reason). The result is
``docs/mutation.md``: the score per area and per function, and every survivor (the outcomes kept in
``docs/mutation.json``).

Why a small tool of our own: mutmut 3 copies the project and runs the whole suite once per file
to map tests, then mutates whole files (argument checks and messages included); cosmic-ray needs
a session database and a configuration per module. Here the mutants are confined to the judging
logic (input checks are swept by ``tests/surface_sweep.py``; messages and logging are not
judged), and each mutant costs one ``fork`` of a process that has already imported bidmp, its
dependencies and pytest: the mutated function's code object is swapped into the live function, so
every reference to it (``from x import f`` included) runs the mutant.

What is not mutated: docstrings, ``raise`` statements, the ``if`` tests whose body only raises and
the calls of validation helpers (``check_*``, ``as_*``: input validation), f-strings and
``logger`` calls.

Usage::

    python tools/mutation.py                    # every area, 2 workers, writes docs/mutation.md
    python tools/mutation.py --area similarity  # one area again (the others' outcomes kept)
    python tools/mutation.py --list             # the mutants, not run
    python tools/mutation.py --report           # docs/mutation.md again from docs/mutation.json
"""

from __future__ import annotations

import argparse
import ast
import contextlib
import copy
import importlib
import importlib.util
import io
import json
import os
import signal
import sys
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TESTS = ROOT / "tests"


@dataclass(frozen=True)
class Target:
    """An area: the judging functions of one module and the tests that cover them."""

    area: str
    module: str
    functions: tuple[str, ...]
    tests: tuple[str, ...]
    # run numba kernels as plain Python (their mutants are in the Python source)
    pure_python: bool = False


TARGETS = (
    Target(
        "scene clearance",
        "bidmp.scene.clearance",
        (
            "Clearance.collision_free",
            "Clearance.clear",
            "Clearance.collision_part",
            "Scene._minimum",
            "Scene._clearance",
            "Scene._clearance_oriented",
            "Scene._oriented_bounds",
            "_solid_frames",
            "_sweep",
            "_nearest_to_its_clearance",
        ),
        ("tests/test_oracles.py", "tests/scene/test_geometry.py"),
    ),
    Target(
        "scene distances (culling bounds)",
        "bidmp.scene.distances",
        (
            "_cylinder_box_bounds",
            "_densify",
            "_box_distance",
            "_Distances.tool_to",
            "_Distances._witnessed",
        ),
        ("tests/test_oracles.py", "tests/scene/test_geometry.py"),
    ),
    Target(
        "scene checker",
        "bidmp.scene.checker",
        ("SceneChecker.__call__", "SceneChecker.segments_free", "SceneChecker._move_free"),
        (
            "tests/test_oracles.py",
            "tests/scene/test_geometry.py",
            "tests/extension/test_roadmap.py",
        ),
    ),
    Target(
        "FCI judge (the robot's own limits)",
        "bidmp.sim.fci",
        (
            "FCILimits.velocity_bounds",
            "judge_commands",
            "judge_cartesian",
            "_at_rest_around",
            "_bound",
            "match_joint_names",
        ),
        ("tests/sim/test_fci.py", "tests/sim/test_fci_cartesian.py"),
    ),
    Target(
        "the contract asks the arm's FCI",
        "bidmp.sim.backend",
        ("JointLimits.reflex", "JointLimits.__post_init__"),
        ("tests/sim/test_fci.py", "tests/sim/test_joint_limits_fci.py"),
    ),
    Target(
        "verdict assembly: a simulated target (commands and measured joints)",
        "bidmp.sim.report",
        ("SimTarget.task_success", "SimTarget.reason", "_judged"),
        (
            "tests/sim/test_sim_limits_measured.py",
            "tests/sim/test_refusals.py::test_a_pose_target_is_measured_at_its_position",
            "tests/sim/test_sim.py::test_closed_loop_pauses_for_a_held_joint_and_still_engages",
            "tests/test_oracles.py",
        ),
    ),
    Target(
        "verify's exit status",
        "bidmp.cli.verify",
        ("_cmd_verify", "_verdict", "_through_libfranka"),
        ("tests/sim/test_fci.py", "tests/sim/test_libfranka.py"),
    ),
    Target(
        "limit checks and measurement",
        "bidmp.tasks.contract",
        (
            "_fractions",
            "command_peaks",
            "CommandPeaks.within",
            "Verdict.reached",
            "Verdict.clear",
            "Verdict.within_limits",
            "Verdict.ok",
            "Verdict.failed",
        ),
        (
            "tests/test_oracles.py",
            "tests/tasks/test_contract.py",
            "tests/sim/test_sim_limits.py",
            "tests/sim/test_fci.py",
        ),
    ),
    Target(
        "simulator: measured peaks and the 1 kHz command generator",
        "bidmp.sim.limits",
        (
            "_worst",
            "_windowed_acceleration",
            "_measured_peaks",
            "_measured_breach",
            "_RateLimiter.__call__",
        ),
        (
            "tests/test_oracles.py",
            "tests/sim/test_sim_limits.py",
            "tests/sim/test_sim_limits_measured.py",
        ),
    ),
    Target(
        "rhythmic limits",
        "bidmp.primitives.rhythmic",
        # The refusals. RhythmicStepper._limited_constant is a planner (a conservative bound
        # that picks a time constant), not a check: its output is judged by the measured peaks
        # of test_limits_refuse_a_setting_and_set_the_transition, which a planted removal of
        # the lengthening fails.
        ("RhythmicStepper._check_setting", "_check_rhythm_limits"),
        ("tests/primitives/test_rhythmic_limits.py",),
    ),
    Target(
        "engagement",
        "bidmp.tasks.metrics",
        ("endpoint_error", "final_approach_mask", "approach_error", "axis_deviation"),
        ("tests/test_oracles.py", "tests/tasks/test_engagement.py", "tests/tasks/test_contract.py"),
    ),
    Target(
        "job success criteria",
        "bidmp.sim.job_report",
        ("in_bin", "in_slot", "JobTarget.contacts", "JobTarget.within_limits", "JobReport.removed"),
        ("tests/test_oracles.py",),
    ),
    Target(
        "job: a cycle's verdict", "bidmp.sim.job", ("_finish", "_why"), ("tests/test_oracles.py",)
    ),
    # Where checks are assembled into the verdict a robot acts on: operator flips and the
    # hand-planted bugs of SEMANTIC (a wrong frame, a dropped argument, a stale verdict).
    Target(
        "verdict assembly: the contract",
        "bidmp.tasks.contract",
        ("Contract.judge",),
        (
            "tests/tasks/test_verdict_assembly.py",
            "tests/sim/test_fci.py",
            "tests/test_oracles.py",
            "tests/tasks/test_contract.py",
            "tests/tasks/test_engagement.py",
        ),
    ),
    Target(
        "verdict assembly: evaluation",
        "bidmp.tasks.evaluation",
        ("_repaired", "_failed_targets"),
        (
            "tests/tasks/test_evaluation_assembly.py",
            "tests/tasks/test_tilted_user_cells.py::test_every_target_of_a_cell_with_a_tilted_bracket_is_a_task_success",
            "tests/test_oracles.py",
            "tests/tasks/test_user_cells.py",
            "tests/tasks/test_evaluation.py",
        ),
    ),
    Target(
        "verdict assembly: a repair accepted",
        "bidmp.tasks.repair",
        ("Repairer.repair", "Repairer._try", "Repairer._judge", "Repairer._final"),
        (
            "tests/tasks/test_repair_acceptance.py",
            "tests/tasks/test_tilted_user_cells.py::test_every_target_of_a_cell_with_a_tilted_bracket_is_a_task_success",
            "tests/tasks/test_evaluation_assembly.py",
            "tests/tasks/test_user_cells.py",
        ),
    ),
    Target(
        "verdict assembly: what the simulator executes",
        "bidmp.sim.execution",
        ("_refusal", "_executable", "execution_settings"),
        (
            "tests/sim/test_refusals.py",
            "tests/sim/test_one_pipeline.py::test_simulate_refuses_motions_the_contract_did_not_judge_and_repair",
            "tests/sim/test_one_pipeline.py::test_what_the_simulator_repairs_follows_the_scenarios_approach",
            "tests/sim/test_link_repairs.py::test_an_evaluation_without_the_links_check_is_not_what_the_simulator_runs",
        ),
    ),
    Target(
        "verdict assembly: what the simulator runs",
        "bidmp.sim.run",
        ("_run_one", "_touch_reason", "_arm_routed"),
        (
            "tests/sim/test_refusals.py",
            "tests/sim/test_arm_touch.py",
            "tests/sim/test_one_pipeline.py::test_simulate_refuses_motions_the_contract_did_not_judge_and_repair",
            "tests/sim/test_one_pipeline.py::test_what_the_simulator_repairs_follows_the_scenarios_approach",
            "tests/sim/test_backends.py",
        ),
    ),
    Target(
        "job: verdicts, refusals and removed",
        "bidmp.sim.job",
        # _finish and _why: the area above ("a cycle's verdict"); its planted bugs are here
        ("_checked", "_leave", "_engaged", "_reach"),
        (
            "tests/test_oracles.py",
            "tests/sim/test_refusals.py",
            "tests/sim/test_backends.py",
            "tests/sim/test_job.py::test_a_socket_2_mm_off_the_axis_does_not_engage_and_is_not_counted",
        ),
    ),
    Target(
        "job: plans refused before they run",
        "bidmp.sim.job_world",
        ("_refused_plan", "_move", "_judged_by", "_routed"),
        (
            "tests/sim/test_refusals.py",
            "tests/sim/test_arm_touch.py",
            "tests/sim/test_rocking_job.py",
            "tests/sim/test_backends.py",
            "tests/sim/test_job.py::test_a_socket_2_mm_off_the_axis_does_not_engage_and_is_not_counted",
        ),
    ),
    Target(
        "routes: a segment's test and the planner's route",
        "bidmp.planning.rrt",
        # (the partial shortcuts choose which free route, not whether it is free: every segment
        # they change is tested by _Tester.segment, which is here)
        ("_advance", "_Tester.free", "_Tester.segment", "plan_route"),
        ("tests/planning/test_rrt.py",),
    ),
    Target(
        "routes: the tool's route",
        "bidmp.planning.tool",
        (
            "tool_route",
            "_descent",
            "_rounded",
            "_ToolSpace.slack",
            "_ToolSpace.sweep",
            "_ToolSpace.segment",
            "_Turn.matrix",
        ),
        ("tests/planning/test_tool_route.py",),
    ),
    Target(
        "routes: the pose checker",
        "bidmp.scene.checker",
        ("PoseChecker.slack",),
        ("tests/planning/test_tool_route.py",),
    ),
    Target(
        "routes: time-optimal timing",
        "bidmp.planning.timing",
        # (_jerk_limited shapes the time law, how fast it goes; _stretched keeps every peak within
        # the limits, whatever the law, and reports them: it and the rates it reads are here)
        ("_rates", "_stretched", "_slower.__call__", "TimedPath.__call__"),
        ("tests/planning/test_path_timing.py",),
    ),
    Target(
        "routes: the arm's distances",
        "bidmp.sim.arm_geometry",
        (
            "ArmSpace.__init__",
            "ArmSpace.slack",
            "ArmSpace._bounds",
            "ArmSpace._distances",
            "ArmSpace.sweep",
            "ArmGeometry._reach",
        ),
        ("tests/sim/test_arm_routes.py",),
    ),
    Target(
        "routes: the arm's route",
        "bidmp.sim.routes",
        ("needlessly_slow", "_first_unsafe", "_approach_goals", "_solutions", "judged_route"),
        ("tests/sim/test_arm_routes.py", "tests/sim/test_link_repairs.py"),
    ),
    Target(
        "exit statuses",
        "bidmp.cli.common",
        ("judged_methods",),
        (
            "tests/sim/test_sim.py::test_the_committed_nut_task_run_meets_its_acceptance",
            "tests/cli/test_cli.py",
        ),
    ),
    Target(
        "similarity (Fréchet, normaliser)",
        "bidmp.extension.similarity",
        (
            "_frechet_rows",
            "frechet_distance_reference",
            "_frechet_anti_diagonals",
            "_frechet_distance",
            "polyline_length",
            "_length",
            "frechet_similarity",
            "_frechet_similarity",
        ),
        ("tests/test_oracles.py", "tests/extension/test_similarity.py"),
        pure_python=True,
    ),
    Target(
        "similarity template",
        "bidmp.extension.roadmap",
        ("template", "_template", "_minimal_rotation"),
        ("tests/test_oracles.py", "tests/extension/test_roadmap.py"),
    ),
    Target(
        "segmentation",
        "bidmp.extension.segmentation",
        (
            "curvature",
            "_curvature",
            "_alternating_extrema",
            "_prune_persistence",
            "_prune_paper",
            "segment",
            "_segment",
            "choose_piece",
            "_choose_piece",
        ),
        ("tests/test_oracles.py", "tests/extension/test_segmentation.py"),
    ),
    Target(
        "BLS",
        "bidmp.incremental.bls",
        (
            "_with_bias",
            "_affine",
            "_mapped_features",
            "_enhancement_block",
            "BLS.hidden",
            "BLS.fit",
        ),
        ("tests/test_oracles.py", "tests/incremental/test_bls.py"),
    ),
    Target(
        "Bi-DMP skill selection",
        "bidmp.incremental.bidmp",
        ("BiDMP.select_skill",),
        ("tests/test_oracles.py", "tests/incremental/test_incremental.py"),
    ),
    Target(
        "goal systems",
        "bidmp.primitives.goals",
        (
            "_smoothstep",
            "_goal_share",
            "_goal_gate",
            "DelayedGoal.on_grid",
            "_SteppedGoal.follow",
            "DelayedGoal._next",
        ),
        (
            "tests/test_oracles.py",
            "tests/primitives/test_dmp.py",
            "tests/primitives/test_approach.py",
        ),
    ),
    Target(
        "units and speeds a robot can run",
        "bidmp._units",
        ("check_reach", "check_speed"),
        ("tests/test_oracles.py",),
    ),
    Target(
        "bags: header stamp order", "bidmp.io.bags", ("_stamp_order",), ("tests/test_oracles.py",)
    ),
    Target(
        "phase stopping",
        "bidmp.primitives.coupling",
        ("PhaseStopping.__call__", "PhaseStopping.slowdown"),
        ("tests/test_oracles.py", "tests/primitives/test_primitives.py"),
    ),
    Target(
        "the settings a DMP runs with",
        "bidmp.primitives.dmp",
        ("DMP.settings",),
        ("tests/primitives/test_system.py",),
    ),
    Target(
        "CLFD: the protocol's success figures",
        "bidmp.experiments.clfd.metrics",
        ("accuracy_matrix", "continual_metrics", "orientation_error", "demonstration_errors"),
        ("tests/experiments/test_clfd.py",),
    ),
    # The wiring around the checks, planted from outside (issue 66): each result computed and
    # handed on must be used. Planted bugs only (SEMANTIC, the areas "wiring: ..."); the record of
    # the campaign that found them: docs/results/planted_wiring.md.
    Target(
        "wiring: a simulated target's row",
        "bidmp.sim.report",
        (),
        (
            "tests/sim/test_measure_wiring.py",
            "tests/tasks/test_contract_wiring.py",
            "tests/sim/test_sim_limits_measured.py",
            "tests/sim/test_backends.py",
        ),
    ),
    Target(
        "wiring: what simulate hands each motion",
        "bidmp.sim.run",
        (),
        (
            "tests/sim/test_run_wiring.py",
            "tests/sim/test_measure_wiring.py",
            "tests/sim/test_backends.py",
            "tests/sim/test_pace.py",
        ),
    ),
    Target(
        "wiring: the motions the simulator executes",
        "bidmp.sim.execution",
        (),
        ("tests/sim/test_execution_wiring.py", "tests/sim/test_link_repairs.py"),
    ),
    Target(
        "wiring: the job's cycle",
        "bidmp.sim.job",
        (),
        ("tests/sim/test_job_wiring.py", "tests/sim/test_refusals.py", "tests/test_oracles.py"),
    ),
    Target(
        "wiring: the job's moves",
        "bidmp.sim.job_world",
        (),
        ("tests/sim/test_job_wiring.py", "tests/sim/test_refusals.py"),
    ),
    Target(
        "wiring: what the contract is handed",
        "bidmp.tasks.contract",
        (),
        ("tests/tasks/test_contract_wiring.py", "tests/sim/test_fci.py"),
    ),
    Target(
        "wiring: the evaluation's repairs",
        "bidmp.tasks.evaluation",
        (),
        ("tests/tasks/test_repairs_wiring.py", "tests/sim/test_link_repairs.py"),
    ),
    Target(
        "wiring: bidmp verify's files",
        "bidmp.cli.verify",
        (),
        ("tests/cli/test_verify_wiring.py", "tests/sim/test_fci.py"),
    ),
    Target(
        "wiring: bidmp job's exit status",
        "bidmp.cli.job",
        (),
        ("tests/sim/test_job_wiring.py", "tests/sim/test_backends.py"),
    ),
    Target(
        "wiring: the job's phases and command files",
        "bidmp.sim.job_report",
        (),
        ("tests/sim/test_job_wiring.py", "tests/sim/test_backends.py"),
    ),
    Target("wiring: a bag's rows", "bidmp.io.bags", (), ("tests/io/test_bags.py",)),
    Target(
        "wiring: a recording's units",
        "bidmp.io.recordings",
        (),
        ("tests/io/test_conventions.py", "tests/io/test_bags.py", "tests/io/test_loggers.py"),
    ),
    Target(
        "wiring: a recording's time column",
        "bidmp.io._columns",
        (),
        ("tests/io/test_loggers.py", "tests/io/test_conventions.py"),
    ),
    Target(
        "wiring: a recording's declared units",
        "bidmp.io._conventions",
        (),
        ("tests/io/test_conventions.py", "tests/io/test_loggers.py"),
    ),
    Target(
        "wiring: via-points",
        "bidmp.primitives.via",
        (),
        ("tests/primitives/test_via_wiring.py", "tests/primitives/test_via.py"),
    ),
)

# Bugs people make where checks are assembled into a verdict, planted by hand beside the operator
# flips: (area, function, the source text as written, what replaces it, the bug in words). Each is
# one exact, unique text in the function's source (a test checks they still are).
SEMANTIC: tuple[tuple[str, str, str, str, str], ...] = (
    # -- routes: what keeps a planned route clear
    (
        "routes: a segment's test and the planner's route",
        "_advance",
        "travelled = min(travelled + max(slack, tolerance) / sweep, 1.0)",
        "travelled = min(travelled + 2.0 * max(slack, tolerance) / sweep, 1.0)",
        "a unit applied twice: the body advanced twice the distance it may move untouched",
    ),
    (
        "routes: the tool's route",
        "tool_route",
        "checker = scene.pose_checker(exclude, margin=margin + tolerance)",
        "checker = scene.pose_checker(exclude, margin=margin)",
        "the advancement's least step not added to the margin: the swept tool grazes inside it",
    ),
    (
        "routes: the tool's route",
        "_descent",
        "slack = space.slack(space.state(point, 1.0))",
        "slack = space.slack(space.state(point, 0.0))",
        "a wrong frame: the final descent tested with the start's frame, not the target's",
    ),
    (
        "routes: the arm's distances",
        "ArmSpace.__init__",
        "keep = required",
        "keep = min(links, required)",
        "the tool judged by the links' clearance: a route keeps 0.5 mm from a post, not the margin",
    ),
    (
        "routes: the arm's distances",
        "ArmSpace.__init__",
        "inverse @ (np.asarray(solid.centre, dtype=float) * unit - arm.base),",
        "inverse @ (np.asarray(solid.centre, dtype=float) - arm.base),",
        "a unit dropped: the parts placed in scene units as if they were metres",
    ),
    (
        "routes: the arm's route",
        "_approach_goals",
        "if blocked is None:",
        "if True:",
        "a check dropped: the final approach's links not tested before a goal is taken",
    ),
    # -- the settings a DMP runs with: resolved once per change, never stale
    (
        "the settings a DMP runs with",
        "DMP.settings",
        "key = (_limits_version(), raw, tuple(map(type, raw)))",
        "key = (0, raw, tuple(map(type, raw)))",
        "a verdict not re-judged: settings checked against limits since lowered are served again",
    ),
    (
        "the settings a DMP runs with",
        "DMP.settings",
        "key = (_limits_version(), raw, tuple(map(type, raw)))",
        "key = (_limits_version(), raw, ())",
        "equal is not the same: alpha = True (== 1) served the settings resolved for 1",
    ),
    (
        "the settings a DMP runs with",
        "DMP.settings",
        "raw = self._raw_params() + (self.tau,)",
        "raw = self._raw_params()",
        "a dropped argument: a changed tau served the settings of the old one",
    ),
    (
        "the settings a DMP runs with",
        "DMP.settings",
        "settings = _SHARED_SETTINGS.get((type(self), key)) if shared else None",
        "settings = _SHARED_SETTINGS.get((DMP, key)) if shared else None",
        "a wrong class: a subclass served the settings DMP resolved for its parameters",
    ),
    (
        "the settings a DMP runs with",
        "DMP.settings",
        "shared = self.canonical_system is None and self.forcing_basis is None",
        "shared = self.forcing_basis is None",
        "a verdict not re-judged: a user's own phase (it may change) shared between models",
    ),
    # -- the CLFD protocol's success figures
    (
        "CLFD: the protocol's success figures",
        "continual_metrics",
        "np.diag(matrix)[below[1]]",
        "np.diag(matrix)[below[0]]",
        "a wrong index: BWT against the later task's own accuracy, not the earlier one's",
    ),
    (
        "CLFD: the protocol's success figures",
        "orientation_error",
        "np.abs(np.sum(true * predicted, axis=1))",
        "np.sum(true * predicted, axis=1)",
        "the quaternion's sign taken as a turn: q and -q a full turn apart",
    ),
    (
        "CLFD: the protocol's success figures",
        "demonstration_errors",
        "r, d = (r[:, :-4], d[:, :-4]) if pose else (r, d)",
        "r, d = (r[:, :-3], d[:, :-3]) if pose else (r, d)",
        "a unit applied twice: a quaternion's x counted as a position",
    ),
    # -- the contract's verdict
    (
        "verdict assembly: the contract",
        "Contract.judge",
        "position, goal, self.approach_height, axis, rise=mm(ENGAGE_RISE_MM, self.units)",
        "position, goal, self.approach_height, None, rise=mm(ENGAGE_RISE_MM, self.units)",
        "a dropped argument: the engagement measured along world z, not the target's axis",
    ),
    (
        "verdict assembly: the contract",
        "Contract.judge",
        "clearance if applies else None,",
        "None,",
        "the clearance dropped from the verdict (contacts alone decide)",
    ),
    (
        "verdict assembly: the contract",
        "Contract.judge",
        "dict(contacts or {}),",
        "{},",
        "the simulator's contacts dropped from the verdict",
    ),
    (
        "verdict assembly: the contract",
        "Contract.judge",
        "clearance = self.scene.clearance(position, exclude=exclude, orientations=orientations)",
        "clearance = self.scene.clearance(position, exclude=exclude)",
        "a wrong frame: a tilted tool's clearance judged as if it pointed down",
    ),
    # -- evaluation: repaired motions and their verdicts
    (
        "verdict assembly: evaluation",
        "_repaired",
        "verdicts.update({label: fixed.verdict for label, fixed in repairs.items() if fixed.how})",
        "pass",
        "a verdict not re-judged: a repaired motion keeps the verdict of the motion it replaced",
    ),
    (
        "verdict assembly: evaluation",
        "_repaired",
        "rollouts[label] = fixed.motion",
        "pass",
        "a repair's motion judged but not kept: the unrepaired motion is reported and executed",
    ),
    (
        "verdict assembly: evaluation",
        "_repaired",
        "axis=scenario.target_axis(label),",
        "axis=None,",
        "a dropped argument: repairs planned along world z whatever the target's axis",
    ),
    # -- a repair's motion accepted
    (
        "verdict assembly: a repair accepted",
        "Repairer._judge",
        "orientations=turns,",
        "orientations=None,",
        "a wrong frame: a repaired pose motion judged with the tool upright (no alignment, no tilt)",
    ),
    (
        "verdict assembly: a repair accepted",
        "Repairer._final",
        "if not planned.ok or self.planning.scene.margin == self.contract.scene.margin:",
        "if True:",
        "a verdict not re-judged: the planning contract's verdict reported as the contract's",
    ),
    (
        "verdict assembly: a repair accepted",
        "Repairer.repair",
        "ok = final.ok and planned.ok",
        "ok = planned.ok",
        "a verdict not re-judged: a repair accepted on the planning contract alone",
    ),
    (
        "verdict assembly: a repair accepted",
        "Repairer._try",
        "verdict = self._judge(self.planning, motion, query)",
        "verdict = self._judge(self._widened(widen), motion, query)",
        "a stale contract: an extension judged by the margin widened to plan it, not the one it must keep",
    ),
    # -- what the simulator executes
    (
        "verdict assembly: what the simulator executes",
        "_refusal",
        "if verdict.ok:",
        "if verdict.reached:",
        "a partial verdict: only the end point decides whether a motion may run",
    ),
    (
        "verdict assembly: what the simulator executes",
        "_executable",
        "if settings != wanted:",
        "if settings['geometry'] != wanted['geometry']:",
        "a stale verdict accepted: a report judged without repairs is executed",
    ),
    (
        "verdict assembly: what the simulator runs",
        "_run_one",
        "run = cell.execute(plan, job.exclude, setup.hold, job.frames)",
        "run = cell.execute(plan, [], setup.hold, job.frames)",
        "a dropped argument: the target's own parts counted as collisions",
    ),
    # -- the job
    (
        "job: plans refused before they run",
        "_refused_plan",
        "if verdict.ok and not over and touch is None:",
        "if verdict.reached and not over and touch is None:",
        "a partial verdict: a plan through a part is sent because it ends on target",
    ),
    (
        "job: plans refused before they run",
        "_refused_plan",
        "touch = _arm_touch(world, plan, exclude, carried) if verdict.ok and not over else None",
        "touch = None",
        "a check dropped: the arm's links not checked before the motion is sent",
    ),
    (
        "verdict assembly: what the simulator runs",
        "_touch_reason",
        "touched = None if touch is None else touch(plan, job.exclude)",
        "touched = None",
        "a check dropped: the arm's links not checked before the motion is sent",
    ),
    (
        "job: plans refused before they run",
        "_refused_plan",
        "clearance = _clearance(world, planned, exclude, carried, orientations, support)",
        "clearance = _clearance(world, planned, exclude, None, orientations, support)",
        "a dropped argument: the carried part's clearance not judged before it moves",
    ),
    (
        "job: plans refused before they run",
        "_judged_by",
        'contract = world.contract if move.name == "approach" else _transfer_contract(world.contract)',
        "contract = _transfer_contract(world.contract)",
        "the approach judged without its engagement",
    ),
    (
        "job: verdicts, refusals and removed",
        "_leave",
        "axis = axis / np.linalg.norm(axis)",
        "axis = np.array([0.0, 0.0, 1.0])",
        "a wrong frame: the tool leaves along world z, not the part's axis",
    ),
    (
        "job: verdicts, refusals and removed",
        "_finish",
        "record.removed = all(phase.ok for phase in record.phases)",
        "record.removed = record.phases[-1].ok",
        "a stale verdict: removed judged on the last phase only",
    ),
    (
        "job: verdicts, refusals and removed",
        "_engaged",
        "offset = tcp - part.centre0",
        "offset = tcp - np.asarray(target, dtype=float)[:3]",
        "a wrong frame: engagement measured from the target the skill went to, not the part",
    ),
    # -- exit statuses
    (
        "exit statuses",
        "judged_methods",
        "return [name for name in methods if get(name).repairs] or methods",
        "return methods",
        "the exit status judged on the baselines too",
    ),
    # -- the wiring, planted from outside (docs/results/planted_wiring.md): a result computed and
    # dropped, a neighbour's field or row, another arm's tables, a unit applied twice or not at
    # all, an argument not passed on, a list cut to its first element
    (
        "wiring: a simulated target's row",
        "_measure",
        "commanded_error=float(np.linalg.norm(plan.points[-1] / unit - target)),",
        "commanded_error=float(np.linalg.norm(run.tcp[-1] / unit - target)),",
        "from outside: the measured end reported as the commanded one",
    ),
    (
        "wiring: a simulated target's row",
        "_measure",
        "measured_error=verdict.end_error,",
        "measured_error=float(np.linalg.norm(plan.points[-1] / unit - target)),",
        "from outside: the commanded end reported as the measured one",
    ),
    (
        "wiring: a simulated target's row",
        "_measure",
        "within_limits=sent.within and not breach,",
        "within_limits=sent.within,",
        "from outside: the measured joints' breach computed, not used in within_limits",
    ),
    (
        "wiring: a simulated target's row",
        "_measure",
        "measured = _measured_peaks(run.joint_velocities, SIM_STEP * RECORD_EVERY, limits)",
        "measured = _measured_peaks(run.joint_velocities, SIM_STEP * RECORD_EVERY, PANDA)",
        "from outside: another arm's tables: measured peaks against the Panda's limits",
    ),
    (
        "wiring: a simulated target's row",
        "_measure",
        "tracking_error=float(np.max(np.linalg.norm(run.tcp - run.commanded_tcp, axis=1)) / unit),",
        "tracking_error=float(np.max(np.linalg.norm(run.tcp - run.commanded_tcp, axis=1))),",
        "from outside: a unit not applied: tracking error in metres",
    ),
    (
        "wiring: a simulated target's row",
        "_judged",
        "commands=run.commands,",
        "commands=None,",
        "from outside: the commands not handed to the contract",
    ),
    (
        "wiring: a simulated target's row",
        "_judged",
        "contacts={k: v / unit for k, v in run.contacts.items()},",
        "contacts=dict(run.contacts),",
        "from outside: a unit not applied: contact depths in metres",
    ),
    (
        "wiring: a simulated target's row",
        "_judged",
        "axis=task.axes.get(label),",
        "axis=None,",
        "from outside: a dropped argument: a tilted target's engagement along world z",
    ),
    (
        "wiring: a simulated target's row",
        "_judged",
        "breach = _measured_breach(run.joint_velocities, SIM_STEP * RECORD_EVERY, limits, run.disturbed)",
        "breach = _measured_breach(run.joint_velocities, SIM_STEP * RECORD_EVERY, PANDA, run.disturbed)",
        "from outside: another arm's tables: the measured breach against the Panda's",
    ),
    (
        "wiring: a simulated target's row",
        "_SimTask.of",
        "axes = {label: scenario.target_axis(label) for label in labels}",
        "axes = {label: scenario.target_axis(labels[0]) for label in labels}",
        "from outside: a neighbour's row: every target judged along the first target's axis",
    ),
    (
        "wiring: a simulated target's row",
        "_SimTask.of",
        "scenario.alignment_threshold if scenario.is_pose else None,",
        "None,",
        "from outside: the alignment threshold dropped: a pose scenario's tool axis never judged",
    ),
    (
        "wiring: a simulated target's row",
        "SimMethod.end_successes",
        "t.measured_error <= self.threshold",
        "t.commanded_error <= self.threshold",
        "from outside: the wrong field: end successes counted on the commanded end",
    ),
    (
        "wiring: a simulated target's row",
        "_SimTask.contract",
        "self.alignment_threshold,\n            limits,",
        "self.alignment_threshold,\n            None,",
        "from outside: the arm's limits not passed on: the commands never judged",
    ),
    (
        "wiring: what simulate hands each motion",
        "_run_jobs",
        'contract = setup.task.contract(getattr(cell, "scene", None), cell.limits)',
        'contract = setup.task.contract(getattr(cell, "scene", None), PANDA_MODEL.limits)',
        "from outside: another arm's tables: every arm judged by the Panda's limits",
    ),
    (
        "wiring: what simulate hands each motion",
        "_run_one",
        "measured.repair = repair",
        "measured.repair = job.repair",
        "from outside: the arm route taken, not reported",
    ),
    (
        "wiring: what simulate hands each motion",
        "_run_one",
        "target = target + np.asarray(update.offset)",
        "target = target",
        "from outside: a result dropped: judged at the target before the perception update",
    ),
    (
        "wiring: what simulate hands each motion",
        "_run_one",
        "measured.commanded_penetration = _commanded_penetration(cell, run, job)",
        "measured.commanded_penetration = None",
        "from outside: a result computed, not kept",
    ),
    (
        "wiring: what simulate hands each motion",
        "_run_one",
        "_slowed(plan, _paced_duration(job.rollout, None, setup.pace))",
        "_slowed(plan, _paced_duration(job.rollout, None, None))",
        "from outside: an argument not passed on: the demonstration's pace",
    ),
    (
        "wiring: what simulate hands each motion",
        "_jobs",
        "scenario.scene.target_parts(label, scenario.targets[label]),",
        "scenario.scene.target_parts(labels[0], scenario.targets[labels[0]]),",
        "from outside: a neighbour's row: the first target's parts excluded for every target",
    ),
    (
        "wiring: what simulate hands each motion",
        "_jobs",
        "else report.methods[method].orientations[label],",
        "else report.methods[method].orientations[labels[0]],",
        "from outside: a neighbour's row: the first target's tool frames",
    ),
    (
        "wiring: what simulate hands each motion",
        "_jobs",
        "repair=report.methods[method].repaired_at(label),",
        "repair=report.methods[method].repaired_at(labels[0]),",
        "from outside: a neighbour's row: the first target's repair reported",
    ),
    (
        "wiring: what simulate hands each motion",
        "simulate",
        "else _refusal(report, job.method, job.label)",
        "else _refusal(report, methods[0], job.label)",
        "from outside: another method's verdict decides whether a motion runs",
    ),
    (
        "wiring: what simulate hands each motion",
        "_sim_report",
        "{label: by_key[(method, label)][0] for label in labels},",
        "{label: by_key[(methods[0], label)][0] for label in labels},",
        "from outside: a neighbour's row: every method reported with the first method's results",
    ),
    (
        "wiring: what simulate hands each motion",
        "_sim_report",
        'limits = arm.limits if ours else getattr(backend, "limits", None)',
        'limits = PANDA_MODEL.limits if ours else getattr(backend, "limits", None)',
        "from outside: another arm's tables reported",
    ),
    (
        "wiring: what simulate hands each motion",
        "_commanded_penetration",
        "clearance = scene.clearance(run.commanded_tcp / cell.unit, exclude=job.exclude)",
        "clearance = scene.clearance(run.tcp / cell.unit, exclude=job.exclude)",
        "from outside: the wrong field: the measured path as the commanded one",
    ),
    (
        "wiring: what simulate hands each motion",
        "_arm_routed",
        "axis=axis,",
        "axis=None,",
        "from outside: a dropped argument: the arm's route descends along world z",
    ),
    (
        "wiring: what simulate hands each motion",
        "_setup",
        "pace=scenario.pace,",
        "pace=None,",
        "from outside: an argument not passed on: the pace to the workers",
    ),
    (
        "wiring: the motions the simulator executes",
        "execution_settings",
        '"allowance": mm(TRACKING_ALLOWANCE_MM, scenario.units),',
        '"allowance": TRACKING_ALLOWANCE_MM,',
        "from outside: a unit not applied: the tracking allowance 0.5 scene units",
    ),
    (
        "wiring: the motions the simulator executes",
        "_links_check",
        "exclude = tuple(scenario.scene.target_parts(label, scenario.targets[label][:3]))",
        "exclude = tuple(scenario.scene.target_parts(scenario.labels[0], scenario.targets[scenario.labels[0]][:3]))",
        "from outside: a neighbour's row: the first target's parts excluded",
    ),
    (
        "wiring: the motions the simulator executes",
        "_links_check",
        "arm = ArmGeometry(robot, tool.radius * unit, tool.length * unit, base * unit, yaw)",
        "arm = ArmGeometry(robot, tool.radius * unit, tool.length * unit, base, yaw)",
        "from outside: a unit not applied: the arm's base in scene units as metres",
    ),
    (
        "wiring: the motions the simulator executes",
        "_links_check",
        "motion[picked, 3:7] if motion.shape[1] >= 7 else np.repeat(down[None], picked.size, 0)",
        "np.repeat(down[None], picked.size, 0)",
        "from outside: a wrong frame: a tilted tool's links checked pointing down",
    ),
    (
        "wiring: the motions the simulator executes",
        "_refusal",
        "verdict = report.methods[method].verdicts[label]",
        "verdict = next(iter(report.methods[method].verdicts.values()))",
        "from outside: a neighbour's row: the first target's verdict",
    ),
    (
        "wiring: the job's cycle",
        "run_job",
        "stuck = _leave(world, label, target, axis, record)",
        "_leave(world, label, target, axis, record)",
        "from outside: a failed leave not stopping the job",
    ),
    (
        "wiring: the job's cycle",
        "run_job",
        "target, axis = scenario.targets[label], scenario.target_axis(label)",
        "target, axis = scenario.targets[label], scenario.target_axis(labels[0])",
        "from outside: a neighbour's row: every target's axis the first's",
    ),
    (
        "wiring: the job's cycle",
        "_lift_cycle",
        "world.placed += record.removed",
        "world.placed += 1",
        "from outside: a slot used up by a part not placed",
    ),
    (
        "wiring: the job's cycle",
        "_lift_cycle",
        "world.gone.append(label)",
        "pass",
        "from outside: a part taken away still in the way",
    ),
    (
        "wiring: the job's cycle",
        "_drop",
        "world.dropped += 1",
        "pass",
        "from outside: every nut dropped at one point of the bin",
    ),
    (
        "wiring: the job's cycle",
        "_reach",
        "exclude = world.scenario.scene.target_parts(label, target[:3]) + world.gone",
        "exclude = world.scenario.scene.target_parts(label, target[:3])",
        "from outside: the parts taken away counted against later steps",
    ),
    (
        "wiring: the job's cycle",
        "_engaged",
        "along = abs(float(np.dot(tcp - np.asarray(target, dtype=float)[:3], part.axis)))",
        "along = abs(float(np.dot(tcp - np.asarray(target, dtype=float)[:3], [0.0, 0.0, 1.0])))",
        "from outside: a wrong frame: engagement height along world z",
    ),
    (
        "wiring: the job's cycle",
        "_unscrew",
        "if part.rise < rise - 0.1 * spec.play:",
        "if False:",
        "from outside: the nut's rise measured, not checked",
    ),
    (
        "wiring: the job's cycle",
        "_finish",
        "record.final_position = part.pose()[0]",
        "record.final_position = part.centre0",
        "from outside: the wrong field: where the part started reported as where it ended",
    ),
    (
        "wiring: the job's cycle",
        "_job_world",
        "contract = dataclasses.replace(Contract.of(scenario, cell.limits), scene=scene)",
        "contract = Contract.of(scenario, cell.limits)",
        "from outside: the job's scene (bin, rack) not passed on to the contract",
    ),
    (
        "wiring: the job's cycle",
        "_job_world",
        "contract = dataclasses.replace(Contract.of(scenario, cell.limits), scene=scene)",
        "contract = dataclasses.replace(Contract.of(scenario, None), scene=scene)",
        "from outside: the arm's limits not passed on: the job's commands never judged",
    ),
    (
        "wiring: the job's cycle",
        "_approach",
        "arm=_links_check(world, exclude),",
        "arm=None,",
        "from outside: the links' check not passed to the repairs",
    ),
    (
        "wiring: the job's cycle",
        "_leave",
        'held = world.held if world.held is not None and world.held.state == "held" else None',
        "held = None",
        "from outside: the held part not judged on the way out",
    ),
    (
        "wiring: the job's cycle",
        "_checked",
        "if not phase.ok:",
        "if False:",
        "from outside: a failed phase not stopping the cycle",
    ),
    (
        "wiring: the job's cycle",
        "_place",
        "goal = np.asarray(slot, dtype=float) + (world.tcp - bottom) + [0.0, 0.0, world.spec.play]",
        "goal = np.asarray(slot, dtype=float) + [0.0, 0.0, world.spec.play]",
        "from outside: a frame not applied: the tool sent to the slot, not the part's bottom",
    ),
    (
        "wiring: the job's moves",
        "_move",
        "world.q = run.joints[-1]",
        "world.q = run.joints[0]",
        "from outside: the wrong row: the joints at the start kept as now",
    ),
    (
        "wiring: the job's moves",
        "_move",
        "executed[-1] if target is None else np.asarray(target)[:3],",
        "executed[-1],",
        "from outside: the target not passed on: the executed end judged against itself",
    ),
    (
        "wiring: the job's moves",
        "_move",
        "axis=axis,",
        "axis=None,",
        "from outside: a dropped argument: the approach judged along world z",
    ),
    (
        "wiring: the job's moves",
        "_move",
        "orientations=tool_frames,",
        "orientations=None,",
        "from outside: a dropped argument: the tool frames not judged",
    ),
    (
        "wiring: the job's moves",
        "_move",
        "contacts=phase.contacts,",
        "contacts={},",
        "from outside: the simulator's contacts dropped from the job's verdict",
    ),
    (
        "wiring: the job's moves",
        "_move",
        "commands=run.commands,",
        "commands=None,",
        "from outside: the job's commands not handed to the contract",
    ),
    (
        "wiring: the job's moves",
        "_move",
        "world.clock += phase.seconds",
        "pass",
        "from outside: the job's clock not advanced",
    ),
    (
        "wiring: the job's moves",
        "_move",
        "phase.ok = phase.verdict.ok",
        "phase.ok = phase.verdict.reached",
        "from outside: a partial verdict: a phase ok on its end point",
    ),
    (
        "wiring: the job's moves",
        "_move",
        "clearance=clearance,",
        "clearance=None,",
        "from outside: the carried part's clearance computed, not used",
    ),
    (
        "wiring: the job's moves",
        "_routed",
        "orientation=target[3:7] if approach and target.shape[0] >= 7 else None,",
        "orientation=None,",
        "from outside: a dropped argument: the route's tool frame at a tilted target",
    ),
    (
        "wiring: the job's moves",
        "_routed",
        "margin=world.scene.margin + mm(TRACKING_ALLOWANCE_MM, scenario.units),",
        "margin=world.scene.margin + TRACKING_ALLOWANCE_MM,",
        "from outside: a unit not applied: the allowance 0.5 scene units",
    ),
    (
        "wiring: the job's moves",
        "_body",
        "return part.solid.moved(centre, rotation.as_matrix()), centre - world.tcp",
        "return part.solid.moved(centre, rotation.as_matrix()), centre",
        "from outside: a frame not applied: the carried part's offset as its position",
    ),
    (
        "wiring: the job's moves",
        "_clear_transfer",
        "goal = np.concatenate([goal[:3], _DOWN.as_quat()])",
        "goal = np.concatenate([goal[:3], world.orientation().as_quat()])",
        "from outside: a wrong frame: a pose transfer ends tilted",
    ),
    (
        "wiring: the job's moves",
        "_transfer",
        "path = start + np.linalg.norm(wanted) / np.linalg.norm(demonstrated) * turn.apply(",
        "path = start + turn.apply(",
        "from outside: a scale dropped: the learned shape turned, not scaled",
    ),
    (
        "wiring: the job's moves",
        "_refused_plan",
        "orientations=orientations if world.pose else None,",
        "orientations=None,",
        "from outside: a dropped argument: a tilted plan judged with the tool upright",
    ),
    (
        "wiring: the job's moves",
        "_arm_touch",
        "return touch(plan, list(exclude) + ([label] if label else []))",
        "return touch(plan, list(exclude))",
        "from outside: the carried part counted as a touch of the arm",
    ),
    (
        "wiring: what the contract is handed",
        "Contract.judge",
        "peaks = replace(peaks, reflex=reflex(commands))",
        "reflex(commands)",
        "from outside: a raised FCI reflex computed, not failing the limits",
    ),
    (
        "wiring: what the contract is handed",
        "Contract.of",
        "scenario.alignment_threshold if scenario.is_pose else None,",
        "None,",
        "from outside: the alignment threshold not passed on",
    ),
    (
        "wiring: what the contract is handed",
        "Contract.judge",
        "peaks = command_peaks(commands, self.limits, dt)",
        "peaks = command_peaks(commands, self.limits)",
        "from outside: an argument not passed on: the commands' period",
    ),
    (
        "wiring: what the contract is handed",
        "Contract.judge",
        "self.approach_height,\n                    axis,",
        "self.approach_height,\n                    None,",
        "from outside: a dropped argument: the tool's alignment judged against world z",
    ),
    (
        "wiring: the evaluation's repairs",
        "_repaired",
        "failed = [label for label in labels if label in failed or blocked.get(label)]",
        "failed = [label for label in labels if label in failed]",
        "from outside: the links' check computed, not used",
    ),
    (
        "wiring: the evaluation's repairs",
        "_repaired",
        "exclude=scene.target_parts(label, scenario.targets[label]),",
        "exclude=scene.target_parts(failed[0], scenario.targets[failed[0]]),",
        "from outside: a neighbour's row: the first failed target's parts excluded",
    ),
    (
        "wiring: the evaluation's repairs",
        "_repaired",
        "label: np.hstack([path, outcome.orientations[label]])",
        "label: np.hstack([path, outcome.orientations[labels[0]]])",
        "from outside: a neighbour's row: the first target's tool frames",
    ),
    (
        "wiring: bidmp verify's files",
        "_verdict",
        "return judge_commands(commands, robot), len(commands), commands",
        'return judge_commands(commands, "fr3"), len(commands), commands',
        "from outside: another arm's tables: every motion judged by the FR3's",
    ),
    (
        "wiring: bidmp verify's files",
        "_verdict",
        "commands = recording.values[:, match_joint_names(recording.names, robot)]",
        "commands = recording.values[:, sorted(match_joint_names(recording.names, robot))]",
        "from outside: the joint order computed, not used",
    ),
    (
        "wiring: bidmp verify's files",
        "_cmd_verify",
        "_refuse_mixed_runs(args.motion)",
        "_refuse_mixed_runs(args.motion[:1])",
        "from outside: a list truncated: only the first file checked against its run",
    ),
    (
        "wiring: bidmp verify's files",
        "_cmd_verify",
        "rejected = sum(not verdict.ok for _, (verdict, _, _) in verdicts)",
        "rejected = int(not verdicts[-1][1][0].ok)",
        "from outside: the exit status on the last file only",
    ),
    (
        "wiring: bidmp job's exit status",
        "run_job_command",
        "code = EXIT_OK if report.removed == len(report.targets) else EXIT_TARGETS_FAILED",
        "code = EXIT_OK if report.removed else EXIT_TARGETS_FAILED",
        "from outside: exit 0 when any part was removed",
    ),
    (
        "wiring: bidmp job's exit status",
        "run_job_command",
        "targets=labels,",
        "targets=None,",
        "from outside: an argument not passed on: the targets",
    ),
    (
        "wiring: the job's phases and command files",
        "write_job_commands",
        "for phase in target.phases:",
        "for phase in target.phases[:1]:",
        "from outside: a list truncated: only each target's first motion written",
    ),
    (
        "wiring: the job's phases and command files",
        "write_job_commands",
        'units = tuple(report.joint_units) or ("rad",) * len(names)',
        'units = ("rad",) * len(names)',
        "from outside: the arm's joint units dropped",
    ),
    (
        "wiring: the job's phases and command files",
        "_phase",
        "contacts = {label: depth / cell.unit for label, depth in run.contacts.items()}",
        "contacts = dict(run.contacts)",
        "from outside: a unit not applied: the job's contact depths in metres",
    ),
    (
        "wiring: the job's phases and command files",
        "_phase",
        "for label, depth in (carried_contacts or {}).items():",
        "for label, depth in {}.items():",
        "from outside: the carried part's contacts dropped",
    ),
    (
        "wiring: a bag's rows",
        "read_bag",
        "values = values[order]",
        "values = values",
        "from outside: the stamp order computed, not applied to the values",
    ),
    (
        "wiring: a bag's rows",
        "_joint_row",
        "positions[[column[name] for name in chosen]].tolist()",
        "positions[: len(chosen)].tolist()",
        "from outside: the joints picked by position, not by name",
    ),
    (
        "wiring: a bag's rows",
        "_joint_row",
        "chosen = names or (available if joints is True else list(joints))",
        "chosen = available if joints is True else list(joints)",
        "from outside: the first message's names not carried to the next",
    ),
    (
        "wiring: a recording's units",
        "read_recording",
        "positions = np.radians(positions)  # joints are read in radians",
        "positions = positions",
        "from outside: a unit not applied: joints in degrees read as radians",
    ),
    (
        "wiring: a recording's units",
        "_units",
        "return declared or layout.units",
        "return layout.units",
        "from outside: the declared unit dropped",
    ),
    (
        "wiring: a recording's time column",
        "times_in_seconds",
        "return (seconds - seconds[0]) + fraction / 1e9 + seconds[0]",
        "return seconds",
        "from outside: a neighbour field dropped: a ROS stamp's nanoseconds",
    ),
    (
        "wiring: a recording's time column",
        "times_in_seconds",
        "stamps = values[:, layout.time[0]] / layout.time_divisor",
        "stamps = values[:, layout.time[0]]",
        "from outside: a unit not applied: ms stamps read as seconds",
    ),
    (
        "wiring: a recording's units",
        "_quaternions",
        'Rotation.from_euler(euler, rotation, degrees=angles == "deg")',
        "Rotation.from_euler(euler, rotation, degrees=False)",
        "from outside: a unit not applied: Euler degrees read as radians",
    ),
    (
        "wiring: a recording's declared units",
        "_units_named",
        'return (units.pop() if units else chosen.units), ""',
        'return chosen.units, ""',
        "from outside: the joints' named unit dropped",
    ),
    (
        "wiring: a recording's declared units",
        "_declared_time",
        "return _TIME_DIVISORS[unit], True",
        "return scale, True",
        "from outside: the declared time unit not used",
    ),
    (
        "wiring: via-points",
        "_via_increment",
        "for k, (low, share) in enumerate(between):",
        "for k, (low, share) in enumerate(between[:1]):",
        "from outside: a list truncated: the goal and start responses added to the first via-point only",
    ),
    (
        "wiring: via-points",
        "_via_increment",
        "change = np.linalg.lstsq(response, points - baseline, rcond=None)[0]",
        "change = np.linalg.lstsq(response, points - baseline[0], rcond=None)[0]",
        "from outside: the wrong row: every via-point against the first one's baseline",
    ),
    (
        "wiring: via-points",
        "_via_increment",
        "used = min(int(np.ceil(times.max() / dt)) + 2, phase.shape[0])",
        "used = min(int(np.ceil(times[0] / dt)) + 2, phase.shape[0])",
        "from outside: after the first via-point, not the last",
    ),
    (
        "wiring: via-points",
        "_via_trajectory",
        'system.start if start is None else as_point(start, system.n_dims, "start"),',
        "system.start,",
        "from outside: an argument not passed on: a given start ignored by the via solve",
    ),
    (
        "wiring: via-points",
        "_via_trajectory",
        "request.forcing_increment,",
        "None,",
        "from outside: an argument not passed on: a caller's forcing increment left out of the via solve",
    ),
    (
        "wiring: via-points",
        "_check_end",
        "corners = np.vstack([ends[0], ends[1], points])",
        "corners = np.vstack([ends[0], ends[1], points[:1]])",
        "from outside: a list truncated: the motion's reach from the first via-point only",
    ),
    (
        "wiring: via-points",
        "_via_increment",
        "[goal_response[low + 1], start_response[low + 1]]",
        "[goal_response[low], start_response[low]]",
        "from outside: the neighbour sample not interpolated",
    ),
)

# Survivors shown equivalent: (module, function, the mutated line's text, mutation) -> why no test
# can tell the mutant from the original.
_FAST_PATH = (
    "a fast path's guard: both branches give the same value (the slow one validates a "
    "float64 vector and returns it unchanged)"
)
_BOUND = (
    "cost only: branch and bound returns the least exact distance over every pair whose lower bound "
    "is below the best found so far; this changes which further pairs are evaluated, or the seed it "
    "starts from, not that minimum (a tie keeps the same distance)"
)
_CLEARANCE = "bidmp.scene.clearance"
KNOWN_CLEARANCE = (
    "found = self._try(how, query, shortfall, "
    "verdict.clearance if motion is out.motion and how == 'lift' else None)"
)
EQUIVALENT: dict[tuple[str, str, str, str], str] = {
    # -- the settings a DMP runs with: no parameter value that cannot be a dict key resolves (an
    # array, a list: each field's check refuses it), so the unshared branch's flag is never read
    (
        "bidmp.primitives.dmp",
        "DMP.settings",
        "shared, settings = (False, None)",
        "False -> True",
    ): "every unhashable parameter value is refused by the resolution that follows, before the "
    "shared cache would store it",
    # -- the CLFD protocol's figures: n of a matrix that is not square and 2-D is never used (the
    # next line refuses it); a zero training time's floor only has to make t0 / t huge
    **{
        ("bidmp.experiments.clfd.metrics", "continual_metrics", line, "0 -> 1"): "shape[0] and "
        "shape[1] are equal for the square 2-D matrix the next statement lets through, and n of "
        "any other matrix is never used (that statement refuses it)"
        for line in ("n = matrix.shape[0] if matrix.ndim == 2 else 0",)
    },
    (
        "bidmp.experiments.clfd.metrics",
        "continual_metrics",
        "te = float(min(1.0, np.mean(times[0] / np.maximum(times, 1e-12))))",
        "1e-12 -> 2e-12",
    ): "a zero time's floor: t0 / 1e-12 and t0 / 2e-12 are both far above 1, which min caps",
    # -- the measured joints: a measured velocity or a 10 ms acceleration equal to its bound to the
    # last bit is not a motion the simulator produces
    **{
        ("bidmp.sim.limits", "_measured_breach", line, "> -> >="): "differs only where a "
        "measured value equals its bound to the last bit"
        for line in (
            "over = np.abs(velocities) > np.asarray(limits.velocity, dtype=float) + "
            "MEASURED_VELOCITY_NOISE",
            "over = (np.abs(acceleration) > np.asarray(limits.acceleration, dtype=float)) & "
            "counted[:, None]",
        )
    },
    # -- the FCI judge: a difference of 1 kHz commands equal to a limit to its last bit (the
    # comparisons' edges) is not a motion anyone sends; a breach lies strictly beyond its bound
    **{
        ("bidmp.sim.fci", "judge_commands", line, change): "differs only where a difference of "
        "commands equals the limit to its last bit (the position edges are tested: a joint held "
        "exactly at its stop is accepted)"
        for line, change in (
            ("too_fast = (velocity < lowest) | (velocity > highest)", "< -> <="),
            ("too_fast = (velocity < lowest) | (velocity > highest)", "> -> >="),
            (
                "velocity_jump = np.abs(acceleration) > np.asarray(limits.acceleration)",
                "> -> >=",
            ),
            ("acceleration_jump = np.abs(jerk) > np.asarray(limits.jerk)", "> -> >="),
        )
    },
    (
        "bidmp.sim.fci",
        "judge_cartesian",
        "rows = np.flatnonzero(values[quantity] > bounds[quantity])",
        "> -> >=",
    ): "differs only where a Cartesian difference equals its limit to the last bit",
    **{
        ("bidmp.sim.fci", "_bound", line, "< -> <="): "called for a breach, which lies strictly "
        "beyond its bound: the value never equals the lower one"
        for line in (
            "return limits.lower[joint] if value < limits.lower[joint] else limits.upper[joint]",
            "return float(lowest[joint] if value < lowest[joint] else highest[joint])",
        )
    },
    (
        "bidmp.cli.verify",
        "_verdict",
        "if steps.size and np.max(np.abs(steps - COMMAND_PERIOD_S)) > 1e-06:",  # (as parsed)
        "> -> >=",
    ): "differs only where a step is off 1 ms by exactly 1e-6 s to the last bit (1.5e-6 off is "
    "tested refused)",
    (
        "bidmp.sim.job_world",
        "_refused_plan",
        "planned = np.asarray(path, dtype=float)[:, :3]",
        "3 -> 4",
    ): "a move's path is positions (n, 3) for pose jobs too (its frames come apart, as "
    "orientations): [:, :4] of three columns is [:, :3]",
    (
        "bidmp.sim.job_world",
        "_judged_by",
        "return (contract, np.asarray(goal, dtype=float)[:3])",
        "3 -> 4",
    ): "the goal goes only to Contract.judge, which keeps as many of its values as the path has "
    "positions (three): a pose target's fourth value is dropped there (a pose job's test runs it)",
    (
        "bidmp.sim.job_world",
        "_move",
        "phase.verdict = contract.judge(executed, executed[-1] if target is None else "
        "np.asarray(target)[:3], label=name, axis=axis, exclude=exclude, orientations=tool_frames, "
        "commands=run.commands, contacts=phase.contacts, clearance=clearance)",
        "3 -> 4",
    ): "Contract.judge keeps as many of the target's values as the path has positions (three): "
    "a pose target's fourth value is dropped there (a pose job's test runs it)",
    (
        "bidmp.sim.job_world",
        "_refused_plan",
        "touch = _arm_touch(world, plan, exclude, carried) if verdict.ok and (not over) else None",
        "and -> or",
    ): "cost only: the arm is also checked for a plan already refused, and the touch is read only "
    "when the verdict holds and no peak is over",
    (
        "bidmp.sim.job_world",
        "_judged_by",
        "goal = np.asarray(move.path, dtype=float)[-1] if move.target is None else move.target",
        "drop -",
    ): "a move without a target is a two-point line (its second point is its end) or the rock, "
    "which ends where it starts and whose first step moves micrometres",
    (
        "bidmp.sim.job_world",
        "_move",
        "world.q = run.joints[-1]",
        "1 -> 2",
    ): "every move ends held at rest for the settling time (backend.SETTLE): the last two "
    "recorded samples are the same joints but for the physics' residual (micrometres), and they "
    "only seed the next plan's inverse kinematics",
    (
        "bidmp.sim.job_world",
        "_move",
        "phase.verdict = contract.judge(executed, executed[-1] if target is None else "
        "np.asarray(target)[:3], label=name, axis=axis, exclude=exclude, "
        "orientations=tool_frames, commands=run.commands, contacts=phase.contacts, "
        "clearance=clearance)",
        "1 -> 2",
    ): "a straight move's end is where the arm came to rest, held for the settling time: the last "
    "two recorded samples are the same point but for the physics' residual (micrometres)",
    (
        "bidmp.sim.job",
        "_reach",
        "exclude = world.scenario.scene.target_parts(label, target[:3]) + world.gone",
        "3 -> 4",
    ): "a job's targets are parts of their own (job_targets, and movable_part refuses any other): "
    "target_parts returns [label] without reading the point",
    (
        "bidmp.tasks.contract",
        "Contract.judge",
        "aligned = bool(deviation <= self.alignment_threshold)",
        "<= -> <",
    ): "differs only for a tool exactly at the alignment threshold, to the last bit",
    (
        "bidmp.tasks.contract",
        "Contract.judge",
        "position = path[:, :3] if path.shape[1] >= 3 else path",
        ">= -> >",
    ): "for a path of exactly 3 columns both branches give the path itself; 2 and 7 columns "
    "take the same branch either way",
    (
        "bidmp.tasks.contract",
        "Contract.judge",
        "position = path[:, :3] if path.shape[1] >= 3 else path",
        "3 -> 4",
    ): "the comparison's 3 made 4: a 3-column path then takes the other branch, which gives the "
    "path itself, as [:, :3] does (the slice's 3 made 4 is killed: a pose path's test)",
    (
        "bidmp.sim.job_world",
        "_refused_plan",
        "over = [kind for kind, peak in zip(('velocity', 'acceleration', 'jerk'), peaks) if peak > 1.0]",
        "> -> >=",
    ): "differs only for a plan whose peak is exactly the limit, to the last bit (plans are timed "
    "to 0.9 of it)",
    **{
        (
            "bidmp.sim.job",
            "_engaged",
            "if across > tolerance or along > world.scenario.success_threshold:",
            "> -> >=",
        ): "differs only for a tool exactly at the tolerance or the threshold, to the last bit"
    },
    (
        "bidmp.sim.job",
        "_leave",
        "near = across <= 2.0 * float(world.scene.tool.radius) + world.scene.margin",
        "<= -> <",
    ): "differs only for a tool exactly two radii and the margin off the part's axis, to the last bit",
    (
        "bidmp.sim.job",
        "_leave",
        "axis = np.array([0.0, 0.0, 1.0]) if axis is None else np.asarray(axis, dtype=float)",
        "1.0 -> 2.0",
    ): "the default axis is normalised on the next line: (0, 0, 2) gives the same direction",
    (
        "bidmp.sim.job",
        "_leave",
        "axis = axis / np.linalg.norm(axis)",
        "/ -> *",
    ): "a target's axis is a unit vector already (a rotation of one, or the default): dividing "
    "and multiplying by its norm of 1 give the same bits",
    # -- a repair accepted: the clearance handed to the lift is the one it would compute
    **{
        ("bidmp.tasks.repair", "Repairer.repair", KNOWN_CLEARANCE, change): "the method's own "
        "motion's clearance is handed to the lift only to save computing it again: the lift's "
        "first round runs that same motion (same model, goal, start and skill) and computes the "
        "same clearance when it is not handed one; the other repairs ignore it"
        for change in ("and -> or", "is -> is not", "== -> !=")
    },
    (
        "bidmp.tasks.repair",
        "Repairer.repair",
        "ok = final.ok and planned.ok",
        "planted: a verdict not re-judged: a repair accepted on the planning contract alone",
    ): "the planning contract is the contract with its margin widened by the allowance (never "
    "narrower while the margin is below the tool's radius), judged on the same motion with the "
    "same target, axis, parts and carried part: its verdict can only be stricter, so the "
    "contract's own re-judgement (kept, as the verdict the report shows) cannot change `ok`; "
    "which verdict is reported is tested (a planted _final bug that reports the planning's is killed)",
    (
        "bidmp.tasks.repair",
        "Repairer.repair",
        "ok = final.ok and planned.ok",
        "and -> or",
    ): "the contract's verdict is the planning's own wherever the planning refuses (_final), and "
    "the planning contract is the stricter one otherwise: final.ok or planned.ok is planned.ok, as "
    "final.ok and planned.ok is",
    (
        "bidmp.tasks.repair",
        "Repairer._final",
        "if not planned.ok or self.planning.scene.margin == self.contract.scene.margin:",
        "or -> and",
    ): "cost only: the contract judges again a motion the planning refused (a verdict never used: "
    "the repair is not kept and its note is the planning's reason) or one it judged under the "
    "same margin (the same verdict)",
    (
        "bidmp.tasks.repair",
        "Repairer._try",
        "attempts = _WIDENINGS if how == 'margin' else 1",
        "1 -> 2",
    ): "a second planning only follows a failed verdict of a margin repair (the loop returns at "
    "once for any other): an extension's second attempt never runs",
    (
        "bidmp.tasks.repair",
        "Repairer._judge",
        "if clearance is None and contract.scene is not None and carried:",
        "and -> or",
    ): "the same clearance, at another cost: with no carried part the clearance taken is the "
    "tool's own, the one the contract takes itself; one handed in (a lift's) is the same "
    "motion's, taken with the same carried part on the same scene; with no scene there is no "
    "contract that would judge it (a Repairer refuses a contract without a scene)",
    (
        "bidmp.tasks.evaluation",
        "_failed_targets",
        "return [label for label, error in zip(labels, errors) if error > scenario.success_threshold]",
        "> -> >=",
    ): "differs only for a plain DMP's end exactly at the threshold, to the last bit",
    (
        "bidmp._units",
        "check_speed",
        "hint = f'; in degrees it would be {np.radians(peak_speed):.3g} rad/s: convert it to "
        "radians' if peak_speed > fastest and np.radians(peak_speed) <= fastest else ''",
        "> -> >=",
    ): "a peak of exactly the fastest joint speed returned as plausible two lines above: this "
    "hint is never built for it",
    **{
        (
            "bidmp.primitives.coupling",
            "PhaseStopping.slowdown",
            "if not (type(y) is np.ndarray and y.dtype == np.float64 and (y.ndim == 1)):",
            mutation,
        ): _FAST_PATH
        for mutation in ("drop not", "and -> or", "is -> is not", "== -> !=", "1 -> 2")
    },
    (
        _CLEARANCE,
        "Clearance.clear",
        "return self.collision_free if self.margin <= 0.0 else not self.distance < self.margin",
        "<= -> <",
    ): "at a margin of exactly 0 both branches are `not distance < 0`",
    **{
        (_CLEARANCE, "Scene._minimum", text, mutation): _BOUND
        for text, mutation in (
            ("row, col = divmod(int(np.argmin(bounds)), bounds.shape[1])", "argmin -> argmax"),
            ("rows, cols = np.nonzero((bounds < best) | (bounds <= 0.0))", "< -> <="),
            ("rows, cols = np.nonzero((bounds < best) | (bounds <= 0.0))", "0.0 -> 1.0"),
            ("if bounds[row, col] > 0.0 and bounds[row, col] >= best:", "0.0 -> 1.0"),
            ("if bounds[row, col] > 0.0 and bounds[row, col] >= best:", ">= -> >"),
            ("if distance < best:", "< -> <="),
        )
    },
    **{
        (_CLEARANCE, "Scene._clearance", text, mutation): _BOUND
        for text, mutation in (
            ("row = int(np.argmin(at_samples))", "argmin -> argmax"),
            ("col = int(np.argmin(first))", "argmin -> argmax"),
            (
                "swept_lower = np.minimum(points[:-1], points[1:]) - [radius, radius, 0.0]",
                "0.0 -> 1.0",
            ),
        )
    },
    **{
        (
            _CLEARANCE,
            "Scene._clearance",
            "dense = _densify(points, step, np.flatnonzero((near < best) | (near <= 0.0)))",
            mutation,
        ): "cost only: more segments are placed densely; the minimum over them is the same"
        for mutation in ("< -> <=", "0.0 -> 1.0")
    },
    (
        _CLEARANCE,
        "_sweep",
        "turn = 2.0 * np.arccos(np.clip(np.abs(np.sum(quaternions[1:] * quaternions[:-1], axis=1)), "
        "0.0, 1.0))",
        "2.0 -> 4.0",
    ): "cost only: twice the turn, twice the placements a turning tool needs",
    (
        _CLEARANCE,
        "_sweep",
        "turn = 2.0 * np.arccos(np.clip(np.abs(np.sum(quaternions[1:] * quaternions[:-1], axis=1)), "
        "0.0, 1.0))",
        "drop abs()",
    ): "the quaternions are made continuous first (q · q' >= 0): abs changes nothing",
    (
        "bidmp.scene.distances",
        "_Distances._witnessed",
        "return abs(apart - distance) <= _ON_SHAPE * max(distance, 1.0) and "
        "_on_shape(a, pose_a, first) and _on_shape(b, pose_b, second)",
        "<= -> <",
    ): "differs only when coal's points are apart by exactly the tolerance more or less than its distance",
    (
        "bidmp.scene.checker",
        "SceneChecker.__call__",
        "if free[index] and engine.tool_to(points[index], int(self.chosen[col])) < margin:",
        "< -> <=",
    ): "differs only for a placement exactly at the margin, to the last bit",
    (
        "bidmp.scene.checker",
        "SceneChecker.segments_free",
        "near = np.flatnonzero(np.all((hi >= lower.min(axis=0)) & (lo <= upper.max(axis=0)), axis=1))",
        "all -> any",
    ): "cost only: more moves are candidates; each is then checked exactly",
    (
        "bidmp.scene.checker",
        "SceneChecker.segments_free",
        "touching = np.all((hi[near, None] >= lower[None]) & (lo[near, None] <= upper[None]), axis=2)",
        "all -> any",
    ): "cost only: more parts are candidates for a move; each pair is then checked exactly",
    **{
        (
            "bidmp.scene.checker",
            "SceneChecker.segments_free",
            text,
            mutation,
        ): "differs only where the move's box exactly touches a part's box: the tool is then at least touching "
        "distance away, which is free either way"
        for text in (
            "near = np.flatnonzero(np.all((hi >= lower.min(axis=0)) & (lo <= upper.max(axis=0)), axis=1))",
            "touching = np.all((hi[near, None] >= lower[None]) & (lo[near, None] <= upper[None]), axis=2)",
        )
        for mutation in ("<= -> <", ">= -> >")
    },
    **{
        (
            "bidmp.scene.checker",
            "SceneChecker._move_free",
            "resolution = 1e-09 * max(length, 1.0)",
            mutation,
        ): "the least advance while grazing the margin (1e-9 of the move): it changes how long a graze is followed "
        "before it is called a contact, not the answer for a move that keeps clear of the margin or crosses it"
        for mutation in ("* -> /", "1e-09 -> 2e-09", "max -> min", "1.0 -> 2.0")
    },
    (
        "bidmp.scene.checker",
        "SceneChecker._move_free",
        "if distance < margin:",
        "< -> <=",
    ): "differs only for a placement exactly at the margin, to the last bit",
    (
        "bidmp.tasks.metrics",
        "final_approach_mask",
        "heights = _as_bounded_array(heights, 'heights', max_ndim=1).reshape(-1)",
        "1 -> 2",
    ): "NumPy takes any negative size in reshape as 'the rest': reshape(-2) is reshape(-1)",
    (
        "bidmp.extension.similarity",
        "_frechet_anti_diagonals",
        "i = np.arange(max(0, s - m + 1), min(n, s + 1))",
        "1 -> 2",
    ): "one more cell per anti-diagonal, just off the table (j = -1): it derives only from other such "
    "cells, which are infinite from the start, so it is infinite and never wins a minimum",
    (
        "bidmp.extension.roadmap",
        "_template",
        "lam = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(piece, axis=0), axis=1))])",
        "0.0 -> 1.0",
    ): "changes the first sample's λ alone, and the first sample is set to seg afterwards",
    (
        "bidmp.extension.roadmap",
        "_template",
        "if chord_length <= 1e-12 * max(np.abs(piece).max(), 1.0):",
        "<= -> <",
    ): "the threshold is at least 1e-12: the two differ only for a chord exactly that long",
    **{
        (
            "bidmp.extension.roadmap",
            "_template",
            "if chord_length <= 1e-12 * max(np.abs(piece).max(), 1.0):",
            mutation,
        ): "a rounding-level threshold doubled (a closed piece's chord is 0 or rounding; an open one's is not "
        "within a factor 2 of 1e-12 of its size)"
        for mutation in ("1e-12 -> 2e-12", "1.0 -> 2.0")
    },
    (
        "bidmp.extension.roadmap",
        "_template",
        "degenerate = (np.abs(chord) < _DEGENERATE_AXIS * chord_length) | ~(np.abs(factors) <= _MAX_AXIS_FACTOR)",
        "< -> <=",
    ): "differs only for an axis whose chord is exactly 1e-3 of the chord's length",
    (
        "bidmp.extension.roadmap",
        "_template",
        "scaled = seg + np.where(degenerate, 0.0, factors) * (piece - seg)",
        "0.0 -> 1.0",
    ): "the degenerate axes' scaled values are replaced by their ramps on the next line",
    **{
        (
            "bidmp.extension.roadmap",
            "_minimal_rotation",
            "cos = float(np.clip(u @ v, -1.0, 1.0))",
            mutation,
        ): "|u · v| rounds past 1 only for parallel chords, where sin is below 1e-12 and the branch on the sign "
        "of cos (not its value) decides"
        for mutation in ("1.0 -> 2.0",)
    },
    **{
        (
            "bidmp.extension.roadmap",
            "_minimal_rotation",
            "if sin < 1e-12:",
            mutation,
        ): "chords parallel to within 1e-12 rad: the general formula gives the same rotation to 1e-12"
        for mutation in ("< -> <=", "1e-12 -> 2e-12")
    },
    (
        "bidmp.extension.roadmap",
        "_minimal_rotation",
        "if cos > 0:",
        "> -> >=",
    ): "reached only when sin < 1e-12, where cos is ±1, never 0",
    **{
        (
            "bidmp.extension.segmentation",
            "_curvature",
            "if window <= 3 or np.max(np.ptp(y, axis=0)) <= 1e-12 * float(np.max(np.abs(y))):",
            mutation,
        ): why
        for mutation, why in (
            ("3 -> 4", "the window is odd: at most 3 and at most 4 are the same windows"),
            (
                "<= -> <",
                "differs only for a curve resting at the origin, whose speed floor gives "
                "zero curvature too",
            ),
        )
    },
    (
        "bidmp.extension.segmentation",
        "_curvature",
        "if window <= 3 or np.max(np.ptp(y, axis=0)) <= 1e-12 * float(np.max(np.abs(y))):",
        "1e-12 -> 2e-12",
    ): "the rounding scale of a still curve doubled: a still curve's spread is exactly 0 or rounding-level",
    **{
        (
            "bidmp.extension.segmentation",
            "_curvature",
            "floor = 1e-12 * max(float(np.max(speed)), np.finfo(float).tiny)",
            mutation,
        ): "the speed floor's scale: speeds where the curve does not advance are rounding-level (1e-16 of the "
        "peak), far below either floor, and moving samples far above"
        for mutation in ("* -> /", "1e-12 -> 2e-12")
    },
    (
        "bidmp.extension.segmentation",
        "_curvature",
        "kappa[speed <= floor] = 0.0",
        "<= -> <",
    ): "differs only for a speed exactly at the floor",
    **{
        (
            "bidmp.extension.segmentation",
            "_curvature",
            "if window > 3:",
            mutation,
        ): "the second window is at least 5 whenever this line is reached (a curve of fewer than 5 samples "
        "returned above)"
        for mutation in ("> -> >=", "3 -> 4")
    },
    (
        "bidmp.extension.segmentation",
        "_alternating_extrema",
        "if nonzero.size == 0:",
        "0 -> 1",
    ): "a single non-zero slope fills the whole segment with one sign: no change, no extremum, the same empty answer",
    (
        "bidmp.extension.segmentation",
        "_alternating_extrema",
        "kind = 1 if filled[index - 1] > 0 else -1",
        "> -> >=",
    ): "filled slopes are ±1, never 0",
    **{
        (
            "bidmp.extension.segmentation",
            "_alternating_extrema",
            "while start > 0 and slope[start - 1] == 0:",
            mutation,
        ): "the walk back over a plateau never reaches the first slope: a plateau from the segment's start takes "
        "its filled sign from the slope after it, so no change ends it"
        for mutation in ("> -> >=", "0 -> 1")
    },
    (
        "bidmp.extension.segmentation",
        "_prune_persistence",
        "left = np.arange(-1, count - 1)",
        "- -> +",
    ): "two more entries past the last extremum, never read: the links are read at extrema 0 .. count - 1",
    (
        "bidmp.extension.segmentation",
        "_prune_persistence",
        "right = np.arange(1, count + 1)",
        "1 -> 2",
    ): "(as arange(1, count + 2)) one more entry past the last extremum, never read",
    (
        "bidmp.incremental.bls",
        "_mapped_features",
        "weights = np.ascontiguousarray(mapping_weights.transpose(1, 0, 2).reshape(mapping_weights.shape[1], -1))",
        "1 -> 2",
    ): "(as reshape(..., -2)) NumPy takes any negative size in reshape as 'the rest'",
    (
        "bidmp.incremental.bls",
        "_enhancement_block",
        "weights = np.ascontiguousarray(_orthonormal(_rng(seed, 1, block), Z.shape[1] + 1, n_nodes))",
        "1 -> 2",
    ): "(as _rng(seed, 2, block)) another seeded stream no other matrix draws from: an equally valid draw, "
    "as reproducible from the seed",
    (
        _CLEARANCE,
        "Scene._clearance_oriented",
        "dense_q /= np.linalg.norm(dense_q, axis=1, keepdims=True)",
        "/= -> *=",
    ): "the quaternions go to Rotation.from_quat alone, which normalises them itself",
    (
        _CLEARANCE,
        "Scene._clearance_oriented",
        "extent = _cylinder_extent(axes, self.tool.radius, self.tool.length / 2.0)",
        "/ -> *",
    ): "cost only: boxes four times too tall bound the distances from below all the same",
    (
        "bidmp.extension.segmentation",
        "_prune_paper",
        "if types[position] == 1 and types[position + 1] == -1:",
        "and -> or",
    ): "the extrema alternate, so a maximum is always followed by a minimum: either half implies the other",
    (
        "bidmp.incremental.bls",
        "BLS.fit",
        "F = (F - F_low) / np.where(F_span > 0, F_span, 1.0)",
        "1.0 -> 2.0",
    ): "the divisor of a constant projection, whose numerator F - F_low is 0 either way",
    (
        "bidmp.primitives.goals",
        "_goal_share",
        "closing = s > end - width",
        "> -> >=",
    ): "at s = end - width both formulas give σ (the share is continuous there)",
    (
        "bidmp.primitives.goals",
        "_goal_share",
        "share[s >= end] = 1.0",
        ">= -> >",
    ): "at s = end the closing formula gives 1 - (1 - σ) S(0) = 1",
    (
        "bidmp.primitives.goals",
        "DelayedGoal.on_grid",
        "return phase_grid(phase.shape[0], step or 1.0, tau, self.rate, exact=exact)",
        "1.0 -> 2.0",
    ): "a step of 0 passes only for one sample, whose gate is 1 whatever the step",
    (
        "bidmp.extension.segmentation",
        "_segment",
        "if np.max(interior) * total < 1e-06:",
        "< -> <=",
    ): "differs only for a curve whose κ·L is exactly 1e-6",
    (
        "bidmp.extension.segmentation",
        "_segment",
        "original = np.clip(np.searchsorted(s, positions), 1, n_samples - 1)",
        "- -> +",
    ): "the upper bound is never reached: a kept point lies within the path, so searchsorted gives at "
    "most n_samples - 1",
    (
        "bidmp.extension.segmentation",
        "_segment",
        "nearer_left = positions - s[original - 1] < s[original] - positions",
        "< -> <=",
    ): "differs only for a point exactly halfway in arc length between two samples",
    (
        _CLEARANCE,
        "Scene._clearance",
        "first = _cylinder_box_bounds(points[row:row + 1], radius, length, lower, upper)[0]",
        "1 -> 2",
    ): "the bounds of rows row and row + 1, of which [0] is read: the same row's",
    **{
        (
            _CLEARANCE,
            "Scene._clearance",
            "if points.shape[0] > 1:",
            mutation,
        ): "a one-point path: the placements to add are none either way, and the seed (the exact distance at "
        "that point) is the answer"
        for mutation in ("> -> >=", "0 -> 1")
    },
    # -- routes: ties and derivatives nobody reads
    (
        "bidmp.scene.checker",
        "PoseChecker.slack",
        "if bounds[order[0]] > far:",
        "> -> >=",
    ): "differs only where the least bound equals far to the last bit (then the bound, a lower "
    "bound, is returned either way or the exact value, which is not below it)",
    (
        "bidmp.scene.checker",
        "PoseChecker.slack",
        "if bounds[col] >= best:",
        ">= -> >",
    ): "a part whose bound ties the best so far: its exact slack is not below its bound, so the "
    "least is the same whether it is computed or skipped",
    (
        "bidmp.scene.checker",
        "PoseChecker.slack",
        "if best < 0.0 and far == 0.0:",
        "< -> <=",
    ): "differs only where a part's signed distance equals its clearance to the last bit",
    (
        "bidmp.planning.timing",
        "_rates",
        "s = np.clip(law(t), 0.0, 1.0)",
        "1.0 -> 2.0",
    ): "every law ends at 1 (TOPP-RA's path parameter, a smoothed or slowed copy of it): the clip "
    "at 1 only absorbs rounding",
    **{
        ("bidmp.planning.timing", "_stretched", line, change): "one derivative more computed "
        "than the limits read (the peaks zip the limits, None for an absent jerk limit)"
        for line, change in (
            ("rates = _rates(geometric, law, t, 3 if limits[2] is not None else 2)", "3 -> 4"),
            ("rates = _rates(geometric, law, t, 3 if limits[2] is not None else 2)", "2 -> 3"),
        )
    },
    (
        "bidmp.planning.timing",
        "_stretched",
        "if stretch > 1.0:",
        "> -> >=",
    ): "a stretch of exactly 1 slows the law by a factor of 1: the same law",
    (
        "bidmp.planning.timing",
        "TimedPath.__call__",
        "t = np.clip(np.asarray(u, dtype=float), 0.0, 1.0) * self.duration",
        "1.0 -> 2.0",
    ): "past its end the time law holds its last value (its own clip, and _rates clips s to 1): "
    "the motion is held at its end either way (tests/planning/test_path_timing.py checks it)",
}


# -- the mutants ------------------------------------------------------------------------------------
_COMPARE = {
    ast.Lt: ast.LtE,
    ast.LtE: ast.Lt,
    ast.Gt: ast.GtE,
    ast.GtE: ast.Gt,
    ast.Eq: ast.NotEq,
    ast.NotEq: ast.Eq,
    ast.Is: ast.IsNot,
    ast.IsNot: ast.Is,
    ast.In: ast.NotIn,
    ast.NotIn: ast.In,
}
_BINARY = {
    ast.Add: ast.Sub,
    ast.Sub: ast.Add,
    ast.Mult: ast.Div,
    ast.Div: ast.Mult,
    ast.Pow: ast.Mult,
    ast.FloorDiv: ast.Mult,
    ast.Mod: ast.FloorDiv,
}
_SWAPPED_NAMES = {
    "min": "max",
    "max": "min",
    "minimum": "maximum",
    "maximum": "minimum",
    "argmin": "argmax",
    "argmax": "argmin",
    "all": "any",
    "any": "all",
    "amin": "amax",
    "amax": "amin",
    "nanmin": "nanmax",
    "nanmax": "nanmin",
}
_SYMBOL = {
    ast.Lt: "<",
    ast.LtE: "<=",
    ast.Gt: ">",
    ast.GtE: ">=",
    ast.Eq: "==",
    ast.NotEq: "!=",
    ast.Is: "is",
    ast.IsNot: "is not",
    ast.In: "in",
    ast.NotIn: "not in",
    ast.Add: "+",
    ast.Sub: "-",
    ast.Mult: "*",
    ast.Div: "/",
    ast.Pow: "**",
    ast.FloorDiv: "//",
    ast.Mod: "%",
    ast.And: "and",
    ast.Or: "or",
}


def _only_raises(body) -> bool:
    return all(isinstance(statement, ast.Raise) for statement in body)


def _skipped(node) -> bool:
    """Input validation, messages and logging: not the judging logic."""
    if isinstance(node, (ast.Raise, ast.JoinedStr, ast.Assert)):
        return True
    if isinstance(node, ast.If) and _only_raises(node.body) and not node.orelse:
        return True
    if (
        isinstance(node, ast.Expr)
        and isinstance(node.value, ast.Constant)
        and isinstance(node.value.value, str)
    ):
        return True  # a docstring
    if isinstance(node, ast.Call):
        name = _call_name(node) or ""
        if name.startswith(("check_", "as_", "_check", "_as_")):  # a validation helper's arguments
            return True
        if isinstance(node.func, ast.Attribute) and isinstance(node.func.value, ast.Name):
            return node.func.value.id in ("logger", "logging", "warnings")
    return False


def _walk(node):
    """The nodes of a function in a fixed order, without the skipped subtrees."""
    yield node
    for child in ast.iter_child_nodes(node):
        if not _skipped(child):
            yield from _walk(child)


def _call_name(node: ast.Call) -> str | None:
    if isinstance(node.func, ast.Name):
        return node.func.id
    if isinstance(node.func, ast.Attribute):
        return node.func.attr
    return None


def _set_op(new):
    """A mutation that gives a binary, augmented or boolean operation the operator ``new``."""

    def apply(n):
        n.op = new()
        return n

    return apply


def _variants(node) -> list[tuple[str, callable]]:
    """The mutations of one node: (description, apply(node) -> replacement node)."""
    out = []
    if isinstance(node, ast.Compare):
        for index, op in enumerate(node.ops):
            if type(op) in _COMPARE:
                new = _COMPARE[type(op)]

                def apply(n, index=index, new=new):
                    n.ops[index] = new()
                    return n

                out.append((f"{_SYMBOL[type(op)]} -> {_SYMBOL[new]}", apply))
    elif isinstance(node, (ast.BinOp, ast.AugAssign)) and type(node.op) in _BINARY:
        new, equals = _BINARY[type(node.op)], "=" if isinstance(node, ast.AugAssign) else ""
        out.append((f"{_SYMBOL[type(node.op)]}{equals} -> {_SYMBOL[new]}{equals}", _set_op(new)))
    elif isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.Not)):
        out.append(
            ("drop " + ("-" if isinstance(node.op, ast.USub) else "not"), lambda n: n.operand)
        )
    elif isinstance(node, ast.BoolOp):
        new = ast.Or if isinstance(node.op, ast.And) else ast.And
        out.append((f"{_SYMBOL[type(node.op)]} -> {_SYMBOL[new]}", _set_op(new)))
    elif isinstance(node, ast.Constant) and isinstance(node.value, bool):
        out.append((f"{node.value} -> {not node.value}", lambda n: ast.Constant(not n.value)))
    elif (
        isinstance(node, ast.Constant)
        and isinstance(node.value, (int, float))
        and not isinstance(node.value, bool)
    ):
        value = node.value
        changed = value + 1 if isinstance(value, int) else (value * 2.0 if value != 0.0 else 1.0)
        out.append((f"{value!r} -> {changed!r}", lambda n, changed=changed: ast.Constant(changed)))
    elif isinstance(node, ast.Call):
        name = _call_name(node)
        if name in ("abs", "fabs", "absolute") and len(node.args) == 1:
            out.append((f"drop {name}()", lambda n: n.args[0]))
        elif name in _SWAPPED_NAMES:
            new = _SWAPPED_NAMES[name]

            def apply(n, new=new):
                if isinstance(n.func, ast.Name):
                    n.func = ast.Name(new, ast.Load())
                else:
                    n.func.attr = new
                return n

            out.append((f"{name} -> {new}", apply))
    return out


@dataclass
class Mutant:
    target: Target
    function: str
    index: int  # the node's position in _walk(function)
    variant: int
    line: int
    description: str
    text: str = ""  # the mutated statement (statement_text)
    outcome: str = ""
    seconds: float = 0.0
    replacement: str | None = None  # a hand-planted bug: ``text`` replaced by this

    @property
    def key(self) -> tuple[str, str, str, str]:
        return (self.target.module, self.function, self.text, self.description)


def _source_tree(module: str) -> tuple[Path, ast.Module]:
    spec = importlib.util.find_spec(module)
    path = Path(spec.origin)
    return path, ast.parse(path.read_text(encoding="utf-8"), filename=str(path))


def _function_node(tree: ast.Module, qualname: str):
    scope = tree
    for part in qualname.split("."):
        found = next(
            (
                node
                for node in ast.iter_child_nodes(scope)
                if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))
                and node.name == part
            ),
            None,
        )
        if found is None:
            raise SystemExit(f"mutation: {qualname} not found")
        scope = found
    return scope


def _points(function: ast.FunctionDef) -> list:
    """The nodes of ``function``'s body that may be mutated, in a fixed order (a mutant is an index
    into this list, so the parent that lists it and the child that plants it agree)."""
    body = function.body[1:] if ast.get_docstring(function) else function.body
    return [inner for statement in body if not _skipped(statement) for inner in _walk(statement)]


def statement_text(function: ast.FunctionDef, inner: ast.AST) -> str:
    """The statement of ``function`` that holds ``inner``, as ``ast.unparse`` writes it (a compound
    statement by its header): the same however the source is formatted, so the survivors shown
    equivalent keep their keys when a formatter reflows a line."""
    holder = None
    for statement in ast.walk(function):
        if (
            isinstance(statement, ast.stmt)
            and statement is not function
            and any(n is inner for n in ast.walk(statement))
        ):
            holder = statement  # ast.walk is breadth first: the last one found is the innermost
    if holder is None:
        return ast.unparse(inner)
    headers = {
        ast.If: lambda s: f"if {ast.unparse(s.test)}:",
        ast.While: lambda s: f"while {ast.unparse(s.test)}:",
        ast.For: lambda s: f"for {ast.unparse(s.target)} in {ast.unparse(s.iter)}:",
        ast.With: lambda s: f"with {', '.join(ast.unparse(item) for item in s.items)}:",
    }
    for kind, header in headers.items():
        if isinstance(holder, kind):
            return header(holder)
    return ast.unparse(holder)


def _function_source(target: Target, function: str) -> tuple[str, int, int]:
    """The module's source, and where ``function``'s text starts and ends in it."""
    path, tree = _source_tree(target.module)
    node = _function_node(tree, function)
    source = path.read_text(encoding="utf-8")
    lines = source.splitlines(keepends=True)
    start = sum(len(line) for line in lines[: node.lineno - 1])
    end = sum(len(line) for line in lines[: node.end_lineno])
    return source, start, end


def semantic_mutants(target: Target) -> list[Mutant]:
    """The hand-planted bugs of :data:`SEMANTIC` in ``target``'s functions (each text found once
    in its function: else the tool stops, naming it)."""
    out = []
    for area, function, text, replacement, bug in SEMANTIC:
        if area != target.area:
            continue
        source, start, end = _function_source(target, function)
        count = source[start:end].count(text)
        if count != 1:
            raise SystemExit(
                f"mutation: {target.module}.{function}: the planted bug's text is found {count} "
                f"times, not once: {text!r}"
            )
        line = (
            source[:start].count("\n")
            + source[start:end][: source[start:end].index(text)].count("\n")
            + 1
        )
        out.append(
            Mutant(target, function, -1, -1, line, f"planted: {bug}", text, replacement=replacement)
        )
    return out


def mutants(target: Target) -> list[Mutant]:
    out = semantic_mutants(target)
    path, tree = _source_tree(target.module)
    for function in target.functions:
        node = _function_node(tree, function)
        for index, inner in enumerate(_points(node)):
            for variant, (description, _) in enumerate(_variants(inner)):
                out.append(
                    Mutant(
                        target,
                        function,
                        index,
                        variant,
                        inner.lineno,
                        description,
                        statement_text(node, inner),
                    )
                )
    return out


def _planted_code(mutant: Mutant):
    """A hand-planted bug's code object: the module compiled with the one text replaced in the
    function's source."""
    source, start, end = _function_source(mutant.target, mutant.function)
    changed = (
        source[:start] + source[start:end].replace(mutant.text, mutant.replacement) + source[end:]
    )
    path, _ = _source_tree(mutant.target.module)
    return _code_of(compile(changed, str(path), "exec"), mutant.function)


def _code_of(code, qualname: str):
    """The code object of ``qualname`` inside a module's compiled ``code``."""
    wanted = qualname.split(".")[-1]
    stack = [code]
    while stack:
        current = stack.pop()
        if current.co_qualname == qualname or (
            current.co_name == wanted and current.co_qualname.endswith(qualname)
        ):
            return current
        stack.extend(const for const in current.co_consts if hasattr(const, "co_code"))
    raise SystemExit(f"mutation: no code object for {qualname}")


def _mutated_code(mutant: Mutant):
    """The mutated function's code object, compiled from the module with the one node changed."""
    if mutant.replacement is not None:
        return _planted_code(mutant)
    path, tree = _source_tree(mutant.target.module)
    node = _function_node(tree, mutant.function)
    chosen = _points(node)[mutant.index]
    _, apply = _variants(chosen)[mutant.variant]
    replacement = apply(copy.copy(chosen) if isinstance(chosen, ast.Call) else chosen)
    if replacement is not chosen:
        for parent in ast.walk(node):
            for name, value in ast.iter_fields(parent):
                if value is chosen:
                    setattr(parent, name, replacement)
                elif isinstance(value, list):
                    for position, item in enumerate(value):
                        if item is chosen:
                            value[position] = replacement
    ast.fix_missing_locations(tree)
    return _code_of(compile(tree, str(path), "exec"), mutant.function)


def _live_function(module, qualname: str):
    """The function object whose code runs for ``qualname`` (through properties and decorators)."""
    owner, *rest = qualname.split(".")
    value = getattr(module, owner)
    for part in rest:
        value = vars(value)[part] if isinstance(value, type) else getattr(value, part)
    if isinstance(value, property):
        value = value.fget
    if isinstance(value, (staticmethod, classmethod)):
        value = value.__func__
    while getattr(value, "__code__", None) is None or value.__code__.co_qualname != qualname:
        value = value.__wrapped__
    return value


def _run_child(target: Target, mutant: Mutant | None) -> int:
    """In a forked child: plant the mutant (None: the original), run the target's tests quietly,
    return pytest's exit code."""
    import pytest

    if mutant is not None:
        function = _live_function(importlib.import_module(target.module), mutant.function)
        function.__code__ = _mutated_code(mutant)
    if target.pure_python:
        from bidmp.extension import similarity

        similarity._kernel_state.update(
            {"Fréchet": similarity._frechet_rows, "DTW": similarity._dtw_rows}
        )
    sink = io.StringIO()
    with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):
        return pytest.main(
            [*target.tests, "-x", "-q", "-p", "no:cacheprovider", "-p", "no:xdist", "--no-header"]
        )


def _fork(target: Target, mutant: Mutant | None) -> int:
    pid = os.fork()
    if pid == 0:  # the child
        code = 3
        try:
            os.setpgid(0, 0)
            code = int(_run_child(target, mutant))
        except BaseException:  # noqa: BLE001 - a mutant may break anything; the exit code says it
            code = 4
        finally:
            os._exit(code)
    return pid


def run(selected: list[Mutant], workers: int, timeout_of: dict) -> None:
    """Run the mutants ``workers`` at a time; set each one's outcome."""
    pending, running = list(selected), {}
    done = 0
    while pending or running:
        while pending and len(running) < workers:
            mutant = pending.pop(0)
            running[_fork(mutant.target, mutant)] = (mutant, time.monotonic())
        time.sleep(0.02)
        for pid, (mutant, began) in list(running.items()):
            finished, status = os.waitpid(pid, os.WNOHANG)
            elapsed = time.monotonic() - began
            if finished == 0 and elapsed < timeout_of[mutant.target.area]:
                continue
            if finished == 0:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
                mutant.outcome = "killed (timeout)"
            else:
                code = os.waitstatus_to_exitcode(status)
                mutant.outcome = (
                    "survived"
                    if code == 0
                    else ("killed" if code == 1 else f"killed (exit {code})")
                )
            mutant.seconds = elapsed
            del running[pid]
            done += 1
            if mutant.outcome == "survived":
                print(
                    f"  survived: {mutant.target.module}:{mutant.line} {mutant.function}: {mutant.description}",
                    flush=True,
                )
    return None


def baseline(target: Target) -> float:
    """The covering tests' time on the unmutated code; they must pass."""
    began = time.monotonic()
    pid = _fork(target, None)
    _, status = os.waitpid(pid, 0)
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        raise SystemExit(
            f"mutation: the tests of {target.area} fail on the unmutated code (exit {code}): "
            f"{' '.join(target.tests)}"
        )
    return time.monotonic() - began


def report(selected: list[Mutant], seconds: float) -> str:
    lines = [
        "# Mutation testing of the checks that guard the robot",
        "",
        "Written by `make mutation` (`python tools/mutation.py`); do not edit. Each mutant is one small "
        "bug planted in one judging function (a comparison made strict or loose, an operator or a constant "
        "changed, an `abs`, a sign or a `not` dropped, `and`/`or`, `min`/`max`, `all`/`any` swapped), "
        "and where checks are assembled into a verdict also the bugs people make, planted by hand "
        "(`planted:` — a wrong frame, a dropped argument, a stale verdict); the "
        "tests that cover the area run against it. Input validation (`raise`, the `if` tests that only "
        "raise, the calls of `check_*`/`as_*` helpers), messages and logging are not mutated: the surface "
        "sweep (`make fuzz`) covers them. The score is the share killed of the mutants that can be killed: "
        "an equivalent mutant (listed below with its reason) returns what the original returns — at "
        "another cost, or differing only on an exact floating-point tie that rounding decides.",
        "",
        "| area | module | functions | mutants | killed | equivalent | survived | score |",
        "|---|---|---|---:|---:|---:|---:|---:|",
    ]
    survivors = []
    for target in TARGETS:
        own = [m for m in selected if m.target is target]
        if not own:
            continue
        killed = sum(m.outcome.startswith("killed") for m in own)
        equivalent = [m for m in own if m.outcome == "survived" and m.key in EQUIVALENT]
        survived = [m for m in own if m.outcome == "survived" and m.key not in EQUIVALENT]
        survivors += survived + equivalent
        # The standard score: killed among the mutants that can be killed (equivalent ones cannot).
        score = killed / max(len(own) - len(equivalent), 1)
        lines.append(
            f"| {target.area} | `{target.module}` | {len(target.functions)} | {len(own)} | {killed} | "
            f"{len(equivalent)} | {len(survived)} | {100 * score:.1f} % |"
        )
    total = len(selected)
    killed = sum(m.outcome.startswith("killed") for m in selected)
    lines += [
        "",
        f"{total} mutants, {killed} killed by the tests, in {seconds / 60:.1f} min on 2 workers.",
        "",
    ]
    lines += [
        "## Score per function",
        "",
        "Planted: the hand-written bugs of `SEMANTIC` (a wrong frame, a dropped argument, a stale "
        "verdict) among the function's mutants.",
        "",
        "| area | function | mutants | planted | killed | equivalent | survived | score |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for target in TARGETS:
        for function in dict.fromkeys(
            [*target.functions, *(m.function for m in selected if m.target is target)]
        ):
            own = [m for m in selected if m.target is target and m.function == function]
            if not own:
                continue
            killed = sum(m.outcome.startswith("killed") for m in own)
            equivalent = sum(m.outcome == "survived" and m.key in EQUIVALENT for m in own)
            planted = sum(m.description.startswith("planted: ") for m in own)
            score = killed / max(len(own) - equivalent, 1)
            lines.append(
                f"| {target.area} | `{function}` | {len(own)} | {planted} | {killed} | {equivalent} | "
                f"{len(own) - killed - equivalent} | {100 * score:.1f} % |"
            )
    lines += ["", "## Survivors", ""]
    if not survivors:
        lines.append("None.")
    for mutant in survivors:
        why = EQUIVALENT.get(mutant.key)
        verdict = f"equivalent: {why}" if why else "**not killed**"
        lines.append(
            f"- `{mutant.target.module}:{mutant.line}` `{mutant.function}`: `{mutant.description}` — {verdict}"
        )
    lines += ["", "## Functions mutated", ""]
    for target in TARGETS:
        lines.append(
            f"- {target.area}: "
            + ", ".join(f"`{name}`" for name in target.functions)
            + " — tests: "
            + ", ".join(f"`{Path(test).name}`" for test in target.tests)
        )
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--area", action="append", help="only this area (repeatable; a prefix is enough)"
    )
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--list", action="store_true", help="list the mutants without running them")
    parser.add_argument("--out", default=str(ROOT / "docs" / "mutation.md"))
    parser.add_argument(
        "--report",
        action="store_true",
        help="only rewrite the report from the kept outcomes (after marking equivalents)",
    )
    args = parser.parse_args(argv)
    if args.report:
        report_again(Path(args.out))
        print(f"wrote {args.out}")
        return 0
    os.chdir(ROOT)
    os.environ.setdefault("OPENBLAS_CORETYPE", "Haswell")
    sys.path.insert(0, str(TESTS))
    targets = [t for t in TARGETS if not args.area or any(t.area.startswith(a) for a in args.area)]
    selected = [m for target in targets for m in mutants(target)]
    if args.list:
        for m in selected:
            print(f"{m.target.area}: {m.target.module}:{m.line} {m.function}: {m.description}")
        print(f"{len(selected)} mutants")
        return 0
    import pytest  # noqa: F401

    import bidmp  # noqa: F401 - imported once here; every child is a fork of this process

    for target in targets:
        importlib.import_module(target.module)
    timeout_of, area_seconds = {}, {}
    for target in targets:
        began = time.monotonic()
        seconds = baseline(target)
        timeout_of[target.area] = 3.0 * seconds + 20.0
        own = [m for m in selected if m.target is target]
        print(f"{target.area}: {len(own)} mutants, tests {seconds:.1f} s", flush=True)
        run(own, args.workers, timeout_of)
        killed = sum(m.outcome.startswith("killed") for m in own)
        area_seconds[target.area] = round(time.monotonic() - began, 1)
        print(f"{target.area}: {killed}/{len(own)} killed", flush=True)
    rows = [
        {
            "area": m.target.area,
            "module": m.target.module,
            "function": m.function,
            "line": m.line,
            "text": m.text,
            "mutation": m.description,
            "outcome": m.outcome,
        }
        for m in selected
    ]
    kept = Path(args.out).with_suffix(".json")
    if args.area and kept.exists():  # the areas run again replace theirs; the others are kept
        previous = json.loads(kept.read_text(encoding="utf-8"))
        rows = [row for row in previous["mutants"] if row["area"] not in area_seconds] + rows
        area_seconds = {**previous["area_seconds"], **area_seconds}
    _write(kept, json.dumps({"area_seconds": area_seconds, "mutants": rows}, indent=1) + "\n")
    report_again(Path(args.out))
    print(f"wrote {args.out}")
    return 0


def _write(path: Path, text: str) -> None:
    partial = path.with_name(path.name + ".partial")
    partial.write_text(text, encoding="utf-8")
    partial.replace(path)


def report_again(out: Path) -> None:
    """docs/mutation.md from the outcomes a run kept (docs/mutation.json) and today's
    :data:`EQUIVALENT`: a survivor shown equivalent after the run needs no new run."""
    kept = json.loads(out.with_suffix(".json").read_text(encoding="utf-8"))
    by_area = {target.area: target for target in TARGETS}
    selected = [
        Mutant(
            by_area[m["area"]],
            m["function"],
            0,
            0,
            m["line"],
            m["mutation"],
            m["text"],
            m["outcome"],
        )
        for m in kept["mutants"]
        if m["area"] in by_area
    ]
    _write(out, report(selected, sum(kept["area_seconds"].values())))


if __name__ == "__main__":
    raise SystemExit(main())
