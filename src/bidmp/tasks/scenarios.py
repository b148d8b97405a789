"""Scenario files: a task as JSON, validated strictly, with built-in scenarios.

A scenario names the targets (labelled points), the demonstration and which target it shows, the
success threshold, the DMP parameters and how Bi-DMP extends the skill. Unknown keys, wrong types,
missing targets, or a demonstrated label that is not a target are errors naming the key.

Keys (units: millimetres for the battery scenarios)::

    name                 str, required
    description          str
    units                str, default "mm"
    targets              {label: [x, y(, z)]}, required, at least one
    demonstrated         label of the demonstrated target, required
    demonstration        exactly one of {"minimum_jerk": {"via", "n_steps", "noise", "seed"}},
                         {"points": [[x, y(, z)], ...]} (at least 10) or {"file": "demo.csv"}
                         (relative to the scenario file, and inside its folder unless
                         ``allow_outside_files``), read as ``bidmp fit`` reads it, with its
                         options beside: "columns" (as --columns: roles and conventions,
                         time=ms, decimal=comma, euler=xyz, angles=deg, gaps=drop) and "units"
                         (the file's length unit, as --units); converted to the scenario's unit
    success_threshold    end-point error for success, default 1.75
    approach_height      height band above a target for the approach error, default 28.5;
                         null turns the approach metric off
    alignment_threshold  pose scenarios (targets and demonstration x, y, z, qx, qy, qz, qw):
                         the largest angle in degrees between the tool's axis and the target's
                         over the approach height, default 2
    dmp                  DMP parameters (alpha, beta, K, alpha_phase, tau, n_kernels, regression,
                         widths, derivatives)
    bidmp                Bi-DMP parameters (n_windows, n_mapped, n_enhance, increments, shrink, reg,
                         seed, derivatives)
    extension            extended-demonstration options of bidmp.extend_demonstration (approach
                         "keep" (default) or "paper", eps_frac, method, n_samples, sigma_rel,
                         n_neighbours, n_compare, n_iter, rho, schedule, scaling, compare,
                         select, denom)
    extension_target     "centre_of_failed" (default), a target label, or a point
    extensions           list of {"target": as extension_target, "from": "demonstration" |
                         "previous"}: chained extended demonstrations (overrides extension_target)
    demonstrations       {label: demonstration}: further demonstrations learned directly by Bi-DMP
                         (several operators); a target with the same label uses it as reference
    methods              subset of dmp, dmp-converged, bidmp, bidmp-latest, gmm, tpgmm
    seed                 int in [0, 2**32), default 0 (G-PRM and the baselines)
    robot                {"base": [x, y, z], "yaw": degrees}: where bidmp sim puts the Panda
    pace                 "demonstration" (default): the simulator and the job run a motion no
                         faster than the demonstration's peak tool speed (a "file" recording with
                         time stamps), slower where the arm's limits ask; "limits": at the arm's
                         limits alone (faster than demonstrated, on request)
    scene                geometry of the work cell: tool and parts (see bidmp.scene); with it
                         the evaluation reports clearance, collisions and task success, and the
                         extensions (approach "keep") are grown around the parts. A stage of
                         "extensions" with "in_scene": false is grown without it (a skill of an
                         earlier task, before these parts were there).

Loading validates everything ``evaluate`` will need, so a scenario that loads also runs: the DMP
is fitted on the demonstration (unstable integration, oversized settings and degenerate
demonstrations are refused), rolled out to every target, and the Bi-DMP and extension options
are checked.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import os
from dataclasses import dataclass, field
from importlib import resources
from numbers import Integral
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .._checks import check_bool, check_limit, check_path, get_limits, short_token
from ..demonstrations.datasets import minimum_jerk
from ..io.strict_json import load_json
from ..scene.clearance import Scene
from ..scene.parts import SceneError
from ._scenario_fields import (
    ScenarioError,
    _demonstration,
    _fail,
    _number,
    _point,
    _pose_points,
    _robot,
    _shown,
)
from .options import BiDMPOptions, DMPOptions, ExtensionStage, RobotOptions

if TYPE_CHECKING:
    from ..extension import ExtensionOptions
    from .jobs import JobSpec

__all__ = [
    "Scenario",
    "ScenarioError",
    "METHODS",
    "load",
    "resolve",
    "builtin_names",
    "builtin_text",
    "from_dict",
    "check_robot",
]

# The methods a scenario runs when it names none (any registered method may be named: bidmp.tasks.methods).
METHODS = ("dmp", "dmp-converged", "bidmp", "bidmp-latest", "gmm", "tpgmm")
POSE_DIMS = 7  # x, y, z, qx, qy, qz, qw
_KEYS = {
    "name",
    "description",
    "units",
    "targets",
    "demonstrated",
    "demonstration",
    "success_threshold",
    "approach_height",
    "dmp",
    "bidmp",
    "extension",
    "extension_target",
    "extensions",
    "demonstrations",
    "methods",
    "seed",
    "scene",
    "robot",
    "alignment_threshold",
    "job",
    "pace",
}
_DMP_KEYS = {
    "alpha",
    "beta",
    "K",
    "alpha_phase",
    "tau",
    "n_kernels",
    "regression",
    "widths",
    "derivatives",
    "protocol",
    "keep_approach",
    "goal_rate",
}
_BIDMP_KEYS = {
    "n_windows",
    "n_mapped",
    "n_enhance",
    "increments",
    "shrink",
    "reg",
    "seed",
    "derivatives",
}
_EXTENSION_KEYS = {
    "approach",
    "eps_frac",
    "method",
    "n_samples",
    "sigma_rel",
    "n_neighbours",
    "n_compare",
    "n_iter",
    "rho",
    "schedule",
    "scaling",
    "compare",
    "select",
    "denom",
}


@dataclass
class Scenario:
    """A validated scenario. ``spec`` is the JSON form (``to_dict``); arrays are resolved."""

    name: str
    targets: dict[str, np.ndarray]
    demonstrated: str
    demonstration: np.ndarray
    success_threshold: float
    approach_height: float | None
    dmp: DMPOptions
    bidmp: BiDMPOptions
    extension: ExtensionOptions
    extensions: list[ExtensionStage]
    demonstrations: dict[str, np.ndarray]
    methods: list[str]
    seed: int
    units: str = "mm"
    description: str = ""
    spec: dict = field(default_factory=dict, repr=False)
    scene: Scene | None = None
    # degrees: a pose scenario's tool axis vs the target's over the approach
    alignment_threshold: float = 2.0
    robot: RobotOptions = field(default_factory=RobotOptions)  # the arm and where it stands
    job: JobSpec | None = None  # the task sequence bidmp job runs
    base_dir: str = "."  # where "file" demonstrations were read from
    # The demonstration's peak tool speed (units/s) that executed motions keep: the simulator and
    # the job slow a motion down to it, never up (None: no time stamps, or "pace": "limits").
    pace: float | None = None

    @property
    def labels(self) -> list[str]:
        return list(self.targets)

    @property
    def is_pose(self) -> bool:
        """Whether targets and demonstration are poses (x, y, z, qx, qy, qz, qw)."""
        return self.demonstration.shape[1] == POSE_DIMS

    def _check_label(self, label) -> None:
        if not isinstance(label, str):
            raise TypeError(
                f"label must be a target's label (a string), got {type(label).__name__}"
            )
        if label not in self.targets:
            raise ValueError(
                f"label {short_token(label, 20)} is not a target of scenario {short_token(self.name, 30)}"
            )

    def target_axis(self, label: str) -> np.ndarray | None:
        """A pose target's axis, pointing out of it (the tool comes in along minus it); None for
        position targets (the evaluation then uses +z)."""
        self._check_label(label)
        if not self.is_pose:
            return None
        from scipy.spatial.transform import Rotation

        return -Rotation.from_quat(self.targets[label][3:]).apply([0.0, 0.0, 1.0])

    @property
    def target_array(self) -> np.ndarray:
        return np.stack(list(self.targets.values()))

    @property
    def extension_arguments(self) -> dict:
        """The keyword arguments of :func:`bidmp.extend_demonstration` that ``extension`` stands
        for: ``eps_frac``, ``method``, ``approach`` and ``roadmap`` (a
        :class:`bidmp.extension.RoadmapOptions`)."""
        return self.extension.arguments

    def to_dict(self) -> dict:
        """The scenario as JSON-ready data (round-trips through :func:`from_dict`)."""
        return copy.deepcopy(self.spec)

    @property
    def protocol(self) -> str:
        """The DMP protocol of the scenario's skills ("robot", the default, or "paper")."""
        return self.dmp.protocol_name

    def replace(self, **changes) -> Scenario:
        """This scenario with keys of its file changed (``scenario.replace(extension={...})``),
        checked as a file's are: the parameter objects (``dmp``, ``bidmp``, ``extension``) each by
        what takes it, any other key by reading the whole changed file again; a
        :class:`ScenarioError` names the first bad one. The scenario itself is unchanged."""
        unknown = sorted(set(changes) - _KEYS)
        if unknown:
            _fail(self.name, unknown[0], f"unknown key (known: {', '.join(sorted(_KEYS))})")
        spec = copy.deepcopy(self.spec)
        spec.update(copy.deepcopy(changes))
        if set(changes) <= {"dmp", "bidmp", "extension"}:
            objects = _parameter_objects(spec, self.name)
            if "dmp" in changes:
                _check_runs(self.name, self.demonstration, self.targets, objects["dmp"])
            return dataclasses.replace(self, spec=spec, **{key: objects[key] for key in changes})
        return from_dict(spec, source=self.name, base_dir=self.base_dir, allow_outside_files=True)

    def with_robot_protocol(self) -> Scenario:
        """The scenario with its DMP on the robot protocol (its kernels and regression kept), or itself
        when it is on it. What a robot runs: the paper's protocol stops at a fixed horizon while still
        moving (an arm that stops there overshoots), and sends a motion from any start but the
        demonstrated one off at 6 m/s."""
        if self.protocol == "robot":
            return self
        kept = {k: v for k, v in self.spec["dmp"].items() if k in ("n_kernels", "regression")}
        return self.replace(dmp={"protocol": "robot", **kept})

    def reference(self, label: str) -> np.ndarray:
        """A reference demonstration to target ``label`` "produced by the same generator"
        (the paper's protocol): its own demonstration if one is given, else the demonstration generator with
        its via points moved by the target offset, else the demonstration translated."""
        self._check_label(label)
        if label in self.demonstrations:
            return self.demonstrations[label]
        offset = self.targets[label] - self.targets[self.demonstrated]
        if self.is_pose:  # positions moved, orientations kept (only positions are compared)
            moved = self.demonstration.copy()
            moved[:, :3] += offset[:3]
            return moved
        generator = self.spec["demonstration"].get("minimum_jerk")
        if generator is not None:
            via = np.asarray(generator["via"], dtype=float) + offset
            return minimum_jerk(
                via,
                generator.get("n_steps", 200),
                generator.get("noise", 0.0),
                generator.get("seed", 0),
            )
        return self.demonstration + offset


def _extension_target(value, source, key, targets, n_dims):
    if value == "centre_of_failed":
        return value
    if isinstance(value, str):
        if value not in targets:
            _fail(source, key, f"{value!r} is neither 'centre_of_failed' nor a target label")
        return value
    return _point(value, source, key, n_dims).tolist()


def _parameters(data, key, known, source, make):
    """A parameter object (``dmp``, ``bidmp``, ``extension``): known names only, made (and
    checked) by ``make(params)``; a refusal becomes the file's :class:`ScenarioError`."""
    params = data.get(key, {})
    if not isinstance(params, dict):
        _fail(source, key, "expected an object of parameters")
    if key == "dmp" and "fit" in params:
        _fail(source, "dmp.fit", 'renamed to \'regression\' ("lwr" or "ridge")')
    bad = sorted(set(params) - known)
    if bad:
        _fail(source, f"{key}.{bad[0]}", f"unknown parameter (known: {', '.join(sorted(known))})")
    try:
        return make(dict(params))
    except (TypeError, ValueError) as exc:
        _fail(source, key, str(exc))


def _parameter_objects(data: dict, source: str) -> dict:
    """The parameter objects of a scenario file (``dmp``, ``bidmp``, ``extension``), each checked
    by what takes it (a DMP's, a Bi-DMP's, an extension's own checks)."""
    from ..extension import ExtensionOptions

    return {
        "dmp": _parameters(data, "dmp", _DMP_KEYS, source, DMPOptions.from_flat),
        "bidmp": _parameters(data, "bidmp", _BIDMP_KEYS, source, BiDMPOptions.from_flat),
        "extension": _parameters(
            data, "extension", _EXTENSION_KEYS, source, ExtensionOptions.from_flat
        ),
    }


def check_robot(robot: dict | None, base_dir=".") -> dict:
    """A scenario's ``"robot"`` object checked as a scenario file's is (``base``, ``yaw``, a built-in
    ``model``, or its own ``urdf`` with ``flange``, ``limits``, ``rest``, ``effort``), a relative
    ``urdf`` resolved in ``base_dir`` (anywhere: the folder rule applies when a file loads);
    ``ScenarioError`` names the first bad key."""
    if robot is not None and not isinstance(robot, dict):
        raise TypeError(
            f'robot must be a scenario\'s "robot" object (a dict) or None, got {type(robot).__name__}'
        )
    return _robot({"robot": robot or {}}, "robot", base_dir, allow_outside=True)


def from_dict(
    data,
    source: str = "<dict>",
    base_dir: str | os.PathLike = ".",
    *,
    allow_outside_files: bool = False,
) -> Scenario:
    """Validate scenario data (as parsed from JSON) and build a :class:`Scenario`.

    ``"file"`` demonstrations are read relative to ``base_dir`` and must lie inside it (after
    resolving ``..`` and symlinks) unless ``allow_outside_files`` is true.
    """
    if not isinstance(source, str):
        raise TypeError(
            f"source must be a string naming the scenario's origin, got {type(source).__name__}"
        )
    source = short_token(source, 40)[1:-1]
    base_dir = str(check_path(base_dir, "base_dir"))
    allow_outside_files = check_bool(allow_outside_files, "allow_outside_files")
    units = _check_top_level(data, source)
    demonstration, pace = _demonstration(
        data["demonstration"], source, "demonstration", base_dir, allow_outside_files, units
    )
    pace = _pace(data, source, pace)
    n_dims = demonstration.shape[1]
    if n_dims == POSE_DIMS:
        demonstration = _pose_points(demonstration, source, "demonstration", generated=True)
    targets, demonstrated = _targets(data, source, n_dims)
    threshold = _number(
        data.get("success_threshold", 1.75), source, "success_threshold", positive=True
    )
    alignment = _number(
        data.get("alignment_threshold", 2.0), source, "alignment_threshold", positive=True
    )
    approach = data.get("approach_height", 28.5)
    approach = (
        None if approach is None else _number(approach, source, "approach_height", positive=True)
    )

    objects = _parameter_objects(data, source)
    dmp, bidmp, extension = objects["dmp"], objects["bidmp"], objects["extension"]
    extensions = _extensions(data, source, targets, n_dims)
    demonstrations = _further_demonstrations(
        data, source, base_dir, allow_outside_files, units, n_dims
    )
    methods = _methods(data, source, n_dims)
    seed = data.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, Integral) or not 0 <= seed < 2**32:
        _fail(source, "seed", f"expected an integer in [0, 2**32), got {_shown(seed)}")
    scene = _scene(data, source, targets, n_dims)
    robot = RobotOptions(**_robot(data, source, base_dir, allow_outside_files))
    from .jobs import parse_job

    job = parse_job(data, source)
    if job is not None and scene is None:
        _fail(source, "job", 'a job runs in the simulator: the scenario needs a "scene"')
    _check_runs(source, demonstration, targets, dmp)
    return Scenario(
        name=data["name"],
        targets=targets,
        demonstrated=demonstrated,
        demonstration=demonstration,
        success_threshold=threshold,
        approach_height=approach,
        dmp=dmp,
        bidmp=bidmp,
        extension=extension,
        extensions=extensions,
        demonstrations=demonstrations,
        methods=list(dict.fromkeys(methods)),
        seed=int(seed),
        units=data.get("units", "mm"),
        description=data.get("description", ""),
        spec=copy.deepcopy(data),
        scene=scene,
        robot=robot,
        base_dir=str(base_dir),
        alignment_threshold=alignment,
        job=job,
        pace=pace,
    )


def _pace(data, source: str, demonstrated: float | None) -> float | None:
    """The ``"pace"`` key: "demonstration" (default) keeps the demonstration's peak tool speed
    ``demonstrated`` (None for one without time stamps: then only the arm's limits time a
    motion), "limits" times every motion at the arm's limits alone (faster, on request)."""
    pace = data.get("pace", "demonstration")
    if pace not in ("demonstration", "limits"):
        _fail(source, "pace", f'expected "demonstration" or "limits", got {_shown(pace)}')
    if pace == "limits":
        return None
    if "pace" in data and demonstrated is None:
        _fail(
            source,
            "pace",
            '"demonstration" needs a demonstration with time stamps (a "file" recording); '
            'this one has none: drop the key, or say "limits"',
        )
    return demonstrated


def _check_top_level(data, source: str) -> str:
    """The top-level object, its keys, name, description and units; returns the units."""
    if not isinstance(data, dict):
        raise ScenarioError(f"scenario {source}: expected a JSON object at the top level")
    unknown = sorted(set(data) - _KEYS)
    if unknown:
        _fail(
            source,
            short_token(unknown[0], 30)[1:-1],
            f"unknown key (known: {', '.join(sorted(_KEYS))})",
        )
    for key in ("name", "targets", "demonstrated", "demonstration"):
        if key not in data:
            _fail(source, key, "missing (required)")
    if not isinstance(data["name"], str) or not data["name"]:
        _fail(source, "name", "expected a non-empty string")
    for key in ("description", "units"):
        if key in data and not isinstance(data[key], str):
            _fail(source, key, "expected a string")
    from .._units import UNITS

    units = data.get("units", "mm")
    if units not in UNITS:
        _fail(source, "units", f"expected one of {', '.join(UNITS)}, got {_shown(units)}")

    from .._units import UNITS

    units = data.get("units", "mm")
    if units not in UNITS:
        _fail(source, "units", f"expected one of {', '.join(UNITS)}, got {_shown(units)}")
    return units


def _targets(data, source: str, n_dims: int) -> tuple[dict, str]:
    """The targets (label -> point or pose) and the demonstrated one's label."""
    if not isinstance(data["targets"], dict) or not data["targets"]:
        _fail(source, "targets", "expected a non-empty object {label: [x, y, z]}")
    if len(data["targets"]) > get_limits().max_targets:
        _fail(
            source,
            "targets",
            f"{len(data['targets']):,} targets exceed the limit max_targets = {get_limits().max_targets:,}",
        )
    for label, point in data["targets"].items():
        if n_dims == 3 and isinstance(point, list) and len(point) == POSE_DIMS:
            _fail(
                source,
                f"targets.{label}",
                "is a pose (x, y, z, qx, qy, qz, qw) but the demonstration has positions only: a "
                "pose target needs a pose demonstration (a pose recording file, or generated "
                "poses) to learn the tool's orientation from",
            )
    targets = {
        str(label): _point(point, source, f"targets.{label}", n_dims)
        for label, point in data["targets"].items()
    }
    if n_dims == POSE_DIMS:
        targets = {
            label: _pose_points(point[None], source, f"targets.{label}", generated=False)[0]
            for label, point in targets.items()
        }
    demonstrated = data["demonstrated"]
    if not isinstance(demonstrated, str) or demonstrated not in targets:
        _fail(
            source,
            "demonstrated",
            f"{_shown(demonstrated)} is not among the targets ({', '.join(list(targets)[:10])}"
            f"{', …' if len(targets) > 10 else ''})",
        )

    return targets, demonstrated


def _extensions(data, source: str, targets: dict, n_dims: int) -> list[ExtensionStage]:
    """The extension stages: ``extensions`` as given, or one to ``extension_target``."""
    if "extensions" in data:
        if not isinstance(data["extensions"], list) or not data["extensions"]:
            _fail(source, "extensions", "expected a non-empty list of {target, from}")
        extensions = []
        for index, stage in enumerate(data["extensions"]):
            key = f"extensions[{index}]"
            if (
                not isinstance(stage, dict)
                or set(stage) - {"target", "from", "in_scene"}
                or "target" not in stage
            ):
                _fail(
                    source,
                    key,
                    'expected {"target": ..., "from": "demonstration" | "previous", "in_scene": true | false}',
                )
            origin = stage.get("from", "demonstration" if index == 0 else "previous")
            if origin not in ("demonstration", "previous") or (index == 0 and origin == "previous"):
                _fail(
                    source,
                    f"{key}.from",
                    f"expected 'demonstration'{' or previous' if index else ''}, got {json.dumps(origin)}",
                )
            in_scene = stage.get("in_scene", True)
            if not isinstance(in_scene, bool):
                _fail(source, f"{key}.in_scene", f"expected true or false, got {_shown(in_scene)}")
            extensions.append(
                ExtensionStage(
                    _extension_target(stage["target"], source, f"{key}.target", targets, n_dims),
                    origin,
                    in_scene,
                )
            )
        check_limit(len(extensions), "max_targets", "the number of extensions")
        return extensions
    else:
        target = _extension_target(
            data.get("extension_target", "centre_of_failed"),
            source,
            "extension_target",
            targets,
            n_dims,
        )
        return [ExtensionStage(target)]


def _further_demonstrations(
    data, source: str, base_dir, allow_outside_files: bool, units: str, n_dims: int
) -> dict:
    """The operators' further demonstrations (label -> trajectory)."""
    extra = data.get("demonstrations", {})
    if not isinstance(extra, dict):
        _fail(source, "demonstrations", "expected an object {label: demonstration}")
    demonstrations = {}
    check_limit(len(extra), "max_targets", "the number of further demonstrations")
    for label, spec in extra.items():
        trajectory, _ = _demonstration(
            spec, source, f"demonstrations.{label}", base_dir, allow_outside_files, units
        )
        if trajectory.shape[1] != n_dims:
            _fail(
                source,
                f"demonstrations.{label}",
                f"has D = {trajectory.shape[1]}, the demonstration has D = {n_dims}",
            )
        demonstrations[str(label)] = trajectory

    return demonstrations


def _methods(data, source: str, n_dims: int) -> list[str]:
    """The methods the scenario runs, each known to the registry (and learning poses for poses)."""
    methods = data.get("methods", list(METHODS))
    if not isinstance(methods, list) or not methods or not all(isinstance(m, str) for m in methods):
        _fail(source, "methods", "expected a non-empty list of method names")
    from . import methods as registry

    for method in methods:
        if method not in registry.names():
            _fail(
                source,
                "methods",
                f"unknown method {short_token(method, 20)} (known: {', '.join(registry.names())})",
            )
        if n_dims == POSE_DIMS and not registry.get(method).poses:
            _fail(
                source,
                "methods",
                f"{method} does not learn poses; a pose scenario runs "
                f"{', '.join(registry.names(poses=True))}",
            )
    return methods


def _scene(data, source: str, targets: dict, n_dims: int):
    """The scene (parts and tool), or None."""
    if "scene" not in data:
        return None
    if n_dims not in (3, POSE_DIMS):
        _fail(source, "scene", f"needs 3-D positions or poses (D = 7), these have D = {n_dims}")
    try:
        # A scenario's units are known: its margin defaults to 3 mm in them (bidmp.scene.clearance).
        return Scene.from_dict(data["scene"], targets, units=data.get("units", "mm"))
    except SceneError as exc:
        raise ScenarioError(f"scenario {source}: {exc}") from None
    except ImportError as exc:
        raise type(exc)(f"scenario {source}: {exc}") from None


def _check_runs(source: str, demonstration: np.ndarray, targets: dict, options: DMPOptions) -> None:
    """What ``evaluate`` does first, so that a scenario that loads also runs: fit the DMP on
    the demonstration and roll it out to every target (about a millisecond)."""
    from ..primitives.dmp import DMP

    dmp_params = options.arguments
    try:
        if demonstration.shape[1] == POSE_DIMS:
            from ..primitives.cartesian import CartesianDMP

            model = CartesianDMP(DMP(**dmp_params)).fit(demonstration)
            for goal in targets.values():
                model.rollout(goal)
        else:
            DMP(**dmp_params).fit(demonstration).rollout_many(np.stack(list(targets.values())))
    except (TypeError, ValueError) as exc:
        _fail(source, "dmp", f"the DMP cannot run on this demonstration: {exc}")


# ---------------------------------------------------------------------------------------------
# Built-ins and loading
# ---------------------------------------------------------------------------------------------
def _builtin_dir():
    return resources.files("bidmp").joinpath("data", "scenarios")


def builtin_names() -> list[str]:
    """Names of the built-in scenarios (nut-unscrewing, nut-unscrewing-tilted, cell-removal, pick-and-place)."""
    return sorted(
        entry.name[:-5] for entry in _builtin_dir().iterdir() if entry.name.endswith(".json")
    )


def builtin_text(name: str) -> str:
    """The JSON text of a built-in scenario (for ``bidmp scenario show NAME > my.json``)."""
    if not isinstance(name, str):
        raise TypeError(
            f"name must be a built-in scenario's name (a string), got {type(name).__name__}"
        )
    if name not in builtin_names():
        raise ScenarioError(
            f"name: unknown built-in scenario {short_token(name)}; built-ins: {', '.join(builtin_names())}"
        )
    return _builtin_dir().joinpath(f"{name}.json").read_text(encoding="utf-8")


def resolve(scenario, name: str = "scenario") -> Scenario:
    """``scenario`` as a :class:`Scenario`: one given, or loaded from a file or a built-in name
    (:func:`load`); anything else a TypeError naming the argument ``name``."""
    if not isinstance(name, str) or not name.isidentifier() or len(name) > 64:
        raise TypeError("name must be the argument's name (a short identifier)")
    if isinstance(scenario, Scenario):
        return scenario
    if not isinstance(scenario, (str, os.PathLike)):
        raise TypeError(
            f"{name} must be a bidmp Scenario, a scenario file or a built-in name, got "
            f"{type(scenario).__name__}"
        )
    check_path(scenario, name)  # (a bad path named as the caller's argument)
    return load(scenario)


def load(path_or_name: str | os.PathLike, *, allow_outside_files: bool = False) -> Scenario:
    """Load a scenario from a JSON file, or a built-in by name, and validate it completely.

    ``allow_outside_files``: let ``"file"`` demonstrations name files outside the scenario's
    folder (absolute paths, ``..``, symlinks out of it); off by default.
    """
    if not isinstance(path_or_name, (str, os.PathLike)):
        raise TypeError(
            f"path_or_name must be a file name or a built-in name, got {type(path_or_name).__name__}"
        )
    check_path(path_or_name, "path_or_name")
    text_name = str(path_or_name)
    if not text_name.endswith(".json") and text_name in builtin_names():
        return from_dict(json.loads(builtin_text(text_name)), source=f"built-in {text_name}")
    path = Path(path_or_name)
    if path.exists() and not path.is_file():  # a folder, a FIFO, a device: opening it could block
        raise ScenarioError(
            f"scenario {path}: not a regular file (a folder, pipe, device or socket)"
        )
    if not path.is_file():
        raise ScenarioError(
            f"scenario {path}: no such file, and not a built-in scenario ({', '.join(builtin_names())})"
        )
    try:
        check_limit(path.stat().st_size, "max_json_bytes", f"the size of scenario {path} in bytes")
        data = load_json(path.read_bytes(), f"scenario {path}")
    except (OSError, ValueError) as exc:
        raise ScenarioError(
            str(exc) if str(exc).startswith("scenario") else f"scenario {path}: {exc}"
        ) from None
    return from_dict(
        data, source=str(path), base_dir=path.parent, allow_outside_files=allow_outside_files
    )
