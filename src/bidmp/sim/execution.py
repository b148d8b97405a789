"""What the simulator executes: one evaluation of the scenario, every motion judged by the motion
contract and repaired where it breaks it — or where the arm's links would touch a part the tool
passes clear of, which starts the same repairs as the tool's own contact — with room for the arm's
tracking; and why a motion of it is not sent to the arm.

The links are checked on the arm's own model (:class:`bidmp.sim.arm_geometry.ArmGeometry`: its
URDF in pinocchio, the parts in coal) along the motion's inverse kinematics from where the arm
starts, without a simulator's world: the evaluation runs before any world is built. A point the
inverse kinematics does not follow is not the links' business here (the simulator gives that
motion the arm's own route).
"""

from __future__ import annotations

import logging

import numpy as np

from .._checks import as_labels, check_kind
from .._units import length_text, mm

__all__ = ["execution_report", "execution_settings", "TRACKING_ALLOWANCE_MM"]

logger = logging.getLogger(__name__)

# mm the repairs add to the margin they plan for: the simulated arm's tool strays up to 0.3 mm from
# its command (open loop, the nut task), so a motion planned at the margin could run inside it.
TRACKING_ALLOWANCE_MM = 0.5
_SPACING_MM = 5.0  # the links are checked at inverse kinematics samples this far apart (the plans')


def execution_settings(scenario) -> dict:
    """How :func:`simulate` judges and repairs the motions it executes (the ``settings`` of the
    :class:`~bidmp.tasks.evaluation.Report` it runs): the scene's geometry checked, the motions
    that break the contract repaired (unless the scenario takes the paper's approach), the
    repairs planned with :data:`TRACKING_ALLOWANCE_MM` of room for the arm's tracking, and
    whether the arm's links start repairs too (an arm modelled from its URDF, with the planner's
    extra installed)."""
    from ..tasks.scenarios import Scenario

    check_kind(scenario, Scenario, "scenario", "a bidmp Scenario (bidmp.tasks.load)")
    repair = scenario.scene is not None and scenario.extension.approach == "keep"
    settings = {
        "geometry": scenario.scene is not None,
        "repair": repair,
        "allowance": mm(TRACKING_ALLOWANCE_MM, scenario.units),
    }
    if repair and _links_modelled():
        settings["arm"] = True
    return settings


def _links_modelled() -> bool:
    """Whether the arm's links can be modelled here (PyBullet's data for the built-in arms, and
    the planner's extra for their model)."""
    import importlib.util

    return all(
        importlib.util.find_spec(name) is not None for name in ("pinocchio", "pybullet_data")
    )


def execution_report(scenario, methods=("dmp", "bidmp")):
    """The evaluation whose motions :func:`simulate` executes: every motion judged by the
    contract and repaired where it breaks it (or where the arm's links would touch a part), with
    room for the arm's tracking. Evaluate once and hand it to several :func:`simulate` calls
    (``report=``); a report judged any other way (``evaluate(geometry=False)``, no repairs) is
    refused there, so that what runs on the arm is always what this judged and repaired,
    whatever else a caller asks for (pictures, the viewer, a subset of the targets, workers, the
    backend)."""
    from ..tasks import scenarios as scenario_module
    from ..tasks.evaluation import evaluate

    scenario = scenario_module.resolve(scenario)
    settings = execution_settings(scenario)
    return evaluate(
        scenario,
        as_labels(methods, "methods"),
        repair=settings["repair"],
        allowance=settings["allowance"],
        arm=_links_check(scenario) if settings.get("arm") else None,  # (the report says so)
    )


def _no_links(motion, label: str) -> str:
    """The check of an arm whose links cannot be modelled: nothing to say (the simulator's own
    refusal of such an arm says why)."""
    return ""


def _links_check(scenario):
    """``check(motion, label) -> str``: why the arm's links cannot run ``motion`` to target
    ``label`` (module docstring; "" when they can; always "" for an arm whose links cannot be
    modelled)."""
    from ..planning import segment_free
    from .arm_geometry import ArmGeometry
    from .robots import IK_TOLERANCE, RobotModel, _unit_of, robot_model, robot_placement

    robot = robot_model(scenario.robot, scenario.base_dir)
    if not isinstance(robot, RobotModel):
        return _no_links
    unit = _unit_of(scenario.units)
    base, yaw = robot_placement(scenario)
    tool = scenario.scene.tool
    try:
        arm = ArmGeometry(robot, tool.radius * unit, tool.length * unit, base * unit, yaw)
    except ValueError as exc:  # an arm the simulator refuses itself, in its own words
        logger.info("the arm's links are not checked: %s", exc)
        return _no_links
    lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    seeds = [np.asarray(robot.rest, dtype=float)]
    draws = np.random.default_rng(scenario.seed).uniform(-1.0, 1.0, (8, lower.size))
    seeds += list(0.5 * (lower + upper) + draws * np.minimum(0.5 * (upper - lower), np.pi))
    down = np.array([1.0, 0.0, 0.0, 0.0])
    spaces = {}

    def follow(motion: np.ndarray):
        """The joints along ``motion`` (every :data:`_SPACING_MM`), or None where the inverse
        kinematics does not follow it."""
        path = motion[:, :3] * unit
        steps = np.linalg.norm(np.diff(path, axis=0), axis=1)
        along = np.concatenate([[0.0], np.cumsum(steps)])
        count = max(int(np.ceil(along[-1] / (_SPACING_MM * 1e-3))), 1) + 1
        picked = np.unique(
            np.searchsorted(along, np.linspace(0.0, along[-1], count)).clip(0, len(path) - 1)
        )
        frames = (
            motion[picked, 3:7] if motion.shape[1] >= 7 else np.repeat(down[None], picked.size, 0)
        )
        joints = []
        for index, frame in zip(picked, frames):
            starts = [joints[-1]] if joints else seeds
            for start in starts:
                q, error = arm.solve_ik(path[index], frame, start, iterations=60)
                if error <= IK_TOLERANCE:
                    joints.append(q)
                    break
            else:
                return None
        return np.array(joints)

    def check(motion, label: str) -> str:
        motion = np.asarray(motion, dtype=float)
        joints = follow(motion)
        if joints is None:
            return ""
        exclude = tuple(scenario.scene.target_parts(label, scenario.targets[label][:3]))
        if exclude not in spaces:  # touching: within a tenth of a millimetre, as the simulator's
            spaces[exclude] = arm.space(scenario.scene, unit, exclude=list(exclude), margin=0.0)
        space = spaces[exclude]
        for a, b in zip(joints[:-1], joints[1:]):
            if not segment_free(space, a, b):
                part, depth = space.nearest(b)
                return (
                    f"a link would touch {part} "
                    f"({length_text(max(-depth, 0.0) / unit, scenario.units)} deep)"
                )
        return ""

    return check


def _executable(scenario, methods, report):
    """``report`` if its motions may be executed for ``scenario`` and ``methods`` (else a
    ValueError saying why), or a new :func:`execution_report` when it is None."""
    if report is None:
        return execution_report(scenario, methods)
    settings = getattr(report, "settings", None)
    if not isinstance(settings, dict) or not hasattr(report, "methods"):
        raise TypeError(
            f"report must be a bidmp evaluation Report (bidmp.sim.execution_report), got "
            f"{type(report).__name__}"
        )
    wanted = execution_settings(scenario)
    if report.scenario.name != scenario.name or report.scenario.units != scenario.units:
        raise ValueError(
            f"report: an evaluation of scenario {report.scenario.name!r} "
            f"({report.scenario.units}), not of {scenario.name!r} ({scenario.units})"
        )
    if settings != wanted:

        def said(values: dict) -> str:
            return ", ".join(f"{key}={value!r}" for key, value in values.items())

        raise ValueError(
            f"report: judged with {said(settings)}; the simulator executes only motions judged "
            f"and repaired with {said(wanted)} (allowance in {scenario.units}): pass "
            "bidmp.sim.execution_report(scenario, methods), or no report"
        )
    missing = [name for name in methods if name not in report.methods]
    if missing:
        raise ValueError(f"report: has no motions of {', '.join(missing)}")
    return report


def _refusal(report, method: str, label: str) -> str:
    """Why the evaluation's motion of ``method`` to ``label`` is not sent to the arm ("" when it
    may be): the contract, after every repair, still refuses it. The arm runs nothing the
    contract refused; the row keeps the reason, and no simulated time is spent on it."""
    verdict = report.methods[method].verdicts[label]
    if verdict.ok:
        return ""
    return f"not run: the contract refuses its planned motion: {verdict.reason()}"
