"""The 3-D viewer: a scenario's result as one self-contained HTML file a browser opens offline and
turns — demonstration, segmentation points, extended demonstrations, each method's rollouts, the
scene's parts and, for simulation runs, the robot's motion with a time slider.

Why plotly: it writes one HTML file with plotly.js inside (no network, no CDN, no server), the
layers toggle from the legend, and animation frames with a slider carry the robot's motion.
``viser`` needs a live Python server for its viewer; ``rerun-sdk`` is a 170 MB wheel whose
recordings need its own viewer. (Measured: plotly 6.3.1 is a 9.8 MB wheel plus
narwhals; viser 1.1.1 a 3.6 MB wheel plus websockets, trimesh, msgspec, rich, imageio and more.)

The layers are kept beside the HTML as ``view_layers.npz`` (arrays, ``allow_pickle=False``) with
JSON metadata inside it, so that ``bidmp view RESULTS_DIR`` rebuilds the file without rerunning.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._checks import (
    as_point,
    as_rotation,
    as_trajectory,
    as_vector,
    check_choice,
    check_int,
    check_path,
    printable,
    require_extra,
    short_token,
)
from ..io.atomic import atomic_write
from ..io.strict_json import load_json

__all__ = [
    "ViewLayers",
    "layers_from_report",
    "add_robot_motions",
    "solid_layer",
    "solid_mesh",
    "view_figure",
    "write_view",
    "save_layers",
    "load_layers",
    "VIEW_FORMAT",
]

VIEW_FORMAT = 1  # of view_layers.npz
_COLOURS = {
    "dmp": "#1f77b4",
    "dmp-converged": "#17becf",
    "bidmp": "#d62728",
    "bidmp-latest": "#bcbd22",
    "gmm": "#9467bd",
    "tpgmm": "#8c564b",
}
FAILED = "#d62728"  # a failed target: red, crossed
# amber: a motion that breaks the contract, and the part it came too close to (not the robot
# joints' dark orange)
WARNING = "#ffc000"


@dataclass
class ViewLayers:
    """What the viewer shows (positions (n, 3) in ``units``; times in s).

    ``rollouts`` maps method -> target label -> (T, 3); ``solids`` are the scene's convex parts as
    ``{"label", "kind", "centre", "rotation", "params"}``; ``robot`` maps a motion's name
    ("bidmp -> 11") to ``{"times": (F,), "links": (F, L, 3)}``: the arm's joint origins from
    base to tool tip, sampled along the simulated motion. ``failures`` maps method -> target
    label -> ``{"reason": str, "part": str or None, "point": [x, y, z] or None}`` for the rollouts
    that break the motion contract (the part it came too close to, and where). ``bands`` maps
    method -> target label -> (T,) the radius of the rollout's ±2σ band (units) for the methods
    that learn a spread (``promp``, ``dmp-multi``): drawn as a translucent tube round the rollout.
    """

    title: str
    units: str
    demonstration: np.ndarray
    targets: dict = field(default_factory=dict)
    segmentation: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    extended: list = field(default_factory=list)
    rollouts: dict = field(default_factory=dict)
    solids: list = field(default_factory=list)
    robot: dict = field(default_factory=dict)
    failures: dict = field(default_factory=dict)
    bands: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        """Check every layer where it is given (a viewer built from bad layers failed deep in
        the drawing with an IndexError); paths and points become positions (n, 3) / (3,)."""
        for name in ("title", "units"):
            if not isinstance(getattr(self, name), str) or len(getattr(self, name)) > 500:
                raise TypeError(f"{name} must be text, got {type(getattr(self, name)).__name__}")
        self.demonstration = _layer_path(self.demonstration, "demonstration")
        self.targets = {
            label: _layer_point(point, f"targets[{label!r}]")
            for label, point in _labelled_layer(self.targets, "targets").items()
        }
        self.segmentation = _layer_path(self.segmentation, "segmentation", empty=True)
        if not isinstance(self.extended, (list, tuple)):
            raise TypeError(f"extended must be a list of paths, got {type(self.extended).__name__}")
        self.extended = [_layer_path(p, f"extended[{i}]") for i, p in enumerate(self.extended)]
        self.rollouts = {
            method: {
                label: _layer_path(path, f"rollouts[{method!r}][{label!r}]")
                for label, path in _labelled_layer(paths, f"rollouts[{method!r}]").items()
            }
            for method, paths in _labelled_layer(self.rollouts, "rollouts").items()
        }
        self.bands = {
            method: {
                label: _layer_radius(radius, f"bands[{method!r}][{label!r}]")
                for label, radius in _labelled_layer(radii, f"bands[{method!r}]").items()
            }
            for method, radii in _labelled_layer(self.bands, "bands").items()
        }
        if not isinstance(self.solids, (list, tuple)) or not all(
            isinstance(solid, dict) for solid in self.solids
        ):
            raise TypeError("solids must be a list of solid layers (solid_layer gives them)")
        _labelled_layer(self.robot, "robot")
        self.failures = _checked_failures(_labelled_layer(self.failures, "failures"))


def _labelled_layer(value, name: str) -> dict:
    """A layer keyed by labels: a dict whose keys are text."""
    if not isinstance(value, dict):
        raise TypeError(f"{name} must be a dict keyed by label, got {type(value).__name__}")
    for key in value:
        if not isinstance(key, str):
            raise TypeError(f"{name}: a label must be text, got {type(key).__name__}")
    return value


def _layer_path(points, name: str, empty: bool = False) -> np.ndarray:
    """A path (n, 2+) of finite numbers as positions (n, 3) (2-D: z = 0; poses: x, y, z)."""
    array = as_trajectory(points, name, min_points=0 if empty else 1, allow_static=True)
    if array.shape[1] < 2:
        raise ValueError(f"{name} must be positions (n, 2 or 3) or poses, got {array.shape}")
    return _xyz(array)


def _layer_point(point, name: str) -> np.ndarray:
    """A target: 2 or 3 coordinates or a pose (7,), as its position (3,)."""
    array = as_vector(point, name)
    if array.shape[0] not in (2, 3, 7):
        raise ValueError(
            f"{name} must be a point (x, y[, z]) or a pose (7,), got {array.shape[0]} values"
        )
    return _xyz(array[None, : min(array.shape[0], 3)])[0]


def _layer_radius(radius, name: str) -> np.ndarray:
    """A band's radius along its rollout (T,), units: finite, >= 0."""
    array = as_vector(radius, name, min_length=1)
    if np.any(array < 0.0):
        raise ValueError(f"{name} must be >= 0 (a band's radius)")
    return array


def _xyz(points) -> np.ndarray:
    """Positions (n, 3) of a path (poses: their first three columns; 2-D: z = 0)."""
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] < 2:
        raise ValueError(f"expected a path (n, 2+), got shape {points.shape}")
    if points.shape[1] == 2:
        return np.column_stack([points, np.zeros(len(points))])
    return points[:, :3]


def layers_from_report(report) -> ViewLayers:
    """The layers of a finished evaluation (:func:`bidmp.evaluate`)."""
    from .._checks import check_members

    check_members(
        report,
        ("scenario", "methods", "extensions", "fitted"),
        "report",
        "a bidmp.tasks.Report (bidmp.evaluate)",
    )
    scenario = report.scenario
    points = [
        _xyz(e.demonstration)[e.segmentation_points]
        for e in report.extensions
        if len(e.segmentation_points)
    ]
    solids = [] if scenario.scene is None else [solid_layer(s) for s in scenario.scene.solids]
    return ViewLayers(
        title=scenario.name,
        units=scenario.units,
        demonstration=_xyz(scenario.demonstration),
        targets={
            label: _xyz(np.atleast_2d(target))[0] for label, target in scenario.targets.items()
        },
        segmentation=np.vstack(points) if points else np.zeros((0, 3)),
        extended=[_xyz(e.complete) for e in report.extensions]
        + [_xyz(t) for t in scenario.demonstrations.values()],
        rollouts={
            name: {label: _xyz(r) for label, r in result.rollouts.items()}
            for name, result in report.methods.items()
        },
        solids=solids,
        failures={
            name: failed
            for name, result in report.methods.items()
            if (failed := _failures(result))  # each method's failing motions, judged once
        },
        bands=_bands(report),
    )


def _bands(report) -> dict:
    """The ±2σ radius (norm of the standard deviation, twice) along each rollout of the methods
    whose model carries a spread: a ProMP conditioned on the rollout's start and goal, a DMP from
    several demonstrations (its exact standard deviation along the rollout)."""
    from ..primitives.multi import MultiDMP
    from ..primitives.promp import ProMP

    out = {}
    for name, result in report.methods.items():
        model = report.fitted.get(name)
        radii = {}
        for label, rollout in result.rollouts.items():
            goal = np.asarray(rollout[-1], dtype=float)
            if isinstance(model, MultiDMP):
                spread = model.std(goal, n_steps=len(rollout))
            elif isinstance(model, tuple) and model and isinstance(model[0], ProMP):
                promp, start = model[0], model[1]
                conditioned = promp.condition([0.0, 1.0], np.stack([start, goal]), 0.0)
                spread = np.sqrt(conditioned.var(n_steps=len(rollout)))
            else:
                break
            radii[label] = 2.0 * np.linalg.norm(spread, axis=1)
        if radii:
            out[name] = radii
    return out


def _failures(result) -> dict:
    """The rollouts of one method that break the contract: why, and the part they came too close to."""
    failed = {}
    for label in result.rollouts:
        if result.task_success_at(label):
            continue
        clearance = result.clearance_at(label)
        close = clearance is not None and not clearance.clear and clearance.point is not None
        failed[label] = {
            "reason": result.reason_at(label) or "breaks the motion contract",
            "part": clearance.part if close else None,
            "point": _xyz(np.atleast_2d(clearance.point))[0].tolist() if close else None,
        }
    return failed


def solid_layer(solid) -> dict:
    """A scene solid (:class:`bidmp.scene.parts.Solid`) as the viewer draws it."""
    from ..scene import Solid

    if not isinstance(solid, Solid):
        raise TypeError(f"solid must be a bidmp.scene.Solid, got {type(solid).__name__}")
    return {
        "label": solid.label,
        "kind": solid.kind,
        "centre": np.asarray(solid.centre, float).tolist(),
        "rotation": np.asarray(solid.rotation, float).tolist(),
        "params": [np.asarray(v, float).tolist() if np.ndim(v) else float(v) for v in solid.params],
    }


def add_robot_motions(layers: ViewLayers, sim_report) -> ViewLayers:
    """Add the arm's motions a simulation recorded (``SimReport.motions``), in scene units, and
    the targets the arm failed (``SimReport.methods``: what it did, judged by the contract) to
    ``failures`` where the evaluation had not failed them already."""
    from .._checks import check_kind, check_members

    check_kind(layers, ViewLayers, "layers", "bidmp.plotting.viewer.ViewLayers")
    check_members(sim_report, ("motions",), "sim_report", "a bidmp.sim.SimReport or JobReport")
    for (method, label), motion in sim_report.motions.items():
        layers.robot[f"{method} -> {label}"] = {
            "times": np.asarray(motion["times"], float),
            "links": np.asarray(motion["links"], float),
        }
    methods = getattr(sim_report, "methods", None)
    threshold = getattr(getattr(sim_report, "scenario", None), "success_threshold", None)
    for method, result in (methods or {}).items():
        for label, target in getattr(result, "targets", {}).items():
            if threshold is None or target.task_success(threshold):
                continue
            layers.failures.setdefault(method, {}).setdefault(
                label,
                {
                    "reason": f"on the arm: {target.reason or 'not a task success'}",
                    "part": None,
                    "point": None,
                },
            )
    return layers


def solid_mesh(
    kind: str, centre, rotation, params, sides: int = 24
) -> tuple[np.ndarray, np.ndarray]:
    """A triangle mesh of a scene solid: vertices (n, 3) and faces (m, 3) (vertex indices).

    Boxes: 8 corners; cylinders: ``sides`` around each cap; convex: the hull of its vertices
    (scipy's Qhull)."""
    from scipy.spatial import ConvexHull

    kind = check_choice(kind, "kind", ("box", "cylinder", "convex"))
    centre, rotation = as_point(centre, 3, "centre"), as_rotation(rotation, "rotation")
    sides = check_int(sides, "sides", minimum=3, maximum=1024)
    if (
        not isinstance(params, (tuple, list, np.ndarray))
        or getattr(params, "ndim", 1) == 0
        or len(params) == 0
    ):
        raise TypeError(
            f"params must be the solid's parameters (a tuple), got {type(params).__name__}"
        )
    if kind == "box":
        half = as_vector(params, "params", length=3, positive=True) / 2.0
        local = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
    elif kind == "cylinder":
        radius, height = as_vector(params, "params", length=2, positive=True)
        angles = np.linspace(0.0, 2.0 * np.pi, sides, endpoint=False)
        ring = np.column_stack([radius * np.cos(angles), radius * np.sin(angles)])
        local = np.vstack(
            [np.column_stack([ring, np.full(sides, z)]) for z in (-height / 2, height / 2)]
        )
    else:
        local = as_trajectory(params[0], "params[0]", min_points=4)
        if local.shape[1] != 3 or np.linalg.matrix_rank(local - local.mean(axis=0)) < 3:
            raise ValueError(
                "params[0] must be the convex solid's vertices (n, 3), spanning a volume"
            )
    vertices = local @ rotation.T + centre
    return vertices, ConvexHull(vertices).simplices  # every solid here is convex


def _path(go, points, name, colour, group, show, **line):
    return go.Scatter3d(
        x=points[:, 0],
        y=points[:, 1],
        z=points[:, 2],
        mode="lines",
        name=name,
        legendgroup=group,
        showlegend=show,
        line={"color": colour, **line},
        hoverinfo="name",
    )


def _static_traces(go, layers: ViewLayers) -> list:
    """Every layer but the robot: paths, points and the parts' meshes, one legend entry each."""
    traces = [
        _path(go, layers.demonstration, "demonstration", "black", "demonstration", True, width=7)
    ]
    if len(layers.segmentation):
        s = layers.segmentation
        traces.append(
            go.Scatter3d(
                x=s[:, 0],
                y=s[:, 1],
                z=s[:, 2],
                mode="markers",
                name="segmentation points",
                marker={"symbol": "diamond", "size": 5, "color": "black"},
            )
        )
    for index, path in enumerate(layers.extended):
        traces.append(
            _path(go, path, "extended demonstrations", "goldenrod", "extended", index == 0, width=5)
        )
    close_parts = {}
    for method, paths in layers.rollouts.items():
        failures = layers.failures.get(method, {})
        shown = [label for label in paths if label not in failures]
        for label, path in paths.items():
            visible = True if method in ("bidmp", "dmp") else "legendonly"
            if label in failures:
                failure = failures[label]
                trace = _path(
                    go,
                    path,
                    f"{method}: breaks the contract",
                    WARNING,
                    f"{method} failing",
                    label == next(iter(failures)),
                    width=5,
                    dash="dash",
                )
                trace.update(visible=visible, hovertext=f"{method} -> {label}: {failure['reason']}")
                traces.append(trace)
                if failure.get("point") is not None:
                    point = np.asarray(failure["point"], dtype=float)
                    traces.append(
                        go.Scatter3d(
                            x=[point[0]],
                            y=[point[1]],
                            z=[point[2]],
                            mode="markers+text",
                            legendgroup=f"{method} failing",
                            showlegend=False,
                            visible=visible,
                            text=[f"{label}: too close to {failure['part']}"],
                            marker={"symbol": "x", "size": 6, "color": WARNING},
                            hovertext=failure["reason"],
                            hoverinfo="text",
                        )
                    )
                    close_parts.setdefault(failure["part"], []).append(f"{method} -> {label}")
                continue
            trace = _path(
                go,
                path,
                f"{method} rollouts",
                _COLOURS.get(method, "#2ca02c"),
                method,
                label == shown[0],
                width=2,
            )
            trace.update(visible=visible, hovertext=f"{method} -> {label}")
            traces.append(trace)
    for method, radii in layers.bands.items():
        for index, (label, radius) in enumerate(radii.items()):
            path = layers.rollouts.get(method, {}).get(label)
            if path is None or len(path) < 2:
                continue
            vertices, faces = _tube(_xyz(path), np.asarray(radius, dtype=float))
            traces.append(
                go.Mesh3d(
                    x=vertices[:, 0],
                    y=vertices[:, 1],
                    z=vertices[:, 2],
                    i=faces[:, 0],
                    j=faces[:, 1],
                    k=faces[:, 2],
                    color=_COLOURS.get(method, "#2ca02c"),
                    opacity=0.18,
                    name=f"{method} ±2σ band",
                    legendgroup=f"{method} band",
                    showlegend=index == 0,
                    visible="legendonly",
                    hovertext=f"{method} -> {label}: ±2σ up to {float(np.max(radius)):.3g}",
                    hoverinfo="text",
                )
            )
    traces += _target_traces(go, layers)
    first_close = True
    for index, solid in enumerate(layers.solids):
        vertices, faces = solid_mesh(
            solid["kind"], solid["centre"], solid["rotation"], solid["params"]
        )
        mesh = {
            "x": vertices[:, 0],
            "y": vertices[:, 1],
            "z": vertices[:, 2],
            "i": faces[:, 0],
            "j": faces[:, 1],
            "k": faces[:, 2],
            "hoverinfo": "text",
        }
        # a part a failing motion came too close to: in the warning colour
        if solid["label"] in close_parts:
            traces.append(
                go.Mesh3d(
                    **mesh,
                    color=WARNING,
                    opacity=0.7,
                    name="parts motions came too close to",
                    legendgroup="too close",
                    showlegend=first_close,
                    hovertext=f"{solid['label']}: too close for {', '.join(close_parts[solid['label']])}",
                )
            )
            first_close = False
            continue
        traces.append(
            go.Mesh3d(
                **mesh,
                color="lightsteelblue",
                opacity=0.35,
                name="scene parts",
                legendgroup="scene",
                showlegend=index == 0,
                hovertext=solid["label"],
            )
        )
    return traces


def _target_traces(go, layers: ViewLayers) -> list:
    """The targets: green dots, and a failed one (any method's motion to it breaks the contract)
    a red cross labelled ``✗`` with the methods and reasons on hover."""
    failed: dict = {}
    for method, failures in layers.failures.items():
        for label, failure in failures.items():
            failed.setdefault(label, []).append(f"{method}: {failure['reason']}")
    traces = []
    for kind, labels in (
        ("ok", [label for label in layers.targets if label not in failed]),
        ("failed", [label for label in layers.targets if label in failed]),
    ):
        if not labels:
            continue
        t = np.array([layers.targets[label] for label in labels])
        bad = kind == "failed"
        traces.append(
            go.Scatter3d(
                x=t[:, 0],
                y=t[:, 1],
                z=t[:, 2],
                mode="markers+text",
                name="failed targets" if bad else "targets",
                text=[f"{label} ✗" if bad else label for label in labels],
                textfont={"color": FAILED} if bad else None,
                marker={"size": 7, "color": FAILED, "symbol": "x"}
                if bad
                else {"size": 3, "color": "green"},
                hovertext=[
                    f"{label} failed: " + "; ".join(failed[label]) if bad else label
                    for label in labels
                ],
                hoverinfo="text",
            )
        )
    return traces


def _robot_frames(go, layers: ViewLayers, first: int) -> tuple[list, list, list]:
    """The arm as a thick line through its joints: its first pose as a trace (index ``first``),
    one animation frame per recorded sample of every motion, and the slider's steps."""
    frames, steps, trace = [], [], []
    for name, motion in layers.robot.items():
        for time, links in zip(motion["times"], motion["links"]):
            key = f"{name} @ {time:.2f} s"
            data = _path(go, links, "robot (joint to joint)", "#9a9a9a", "robot", True, width=14)
            data.update(mode="lines+markers", marker={"size": 5, "color": "darkorange"})
            if not trace:
                trace.append(data)
            frames.append(go.Frame(name=key, data=[data], traces=[first]))
            steps.append(
                {
                    "label": key,
                    "method": "animate",
                    "args": [
                        [key],
                        {
                            "mode": "immediate",
                            "frame": {"duration": 0, "redraw": True},
                            "transition": {"duration": 0},
                        },
                    ],
                }
            )
    return trace, frames, steps


def view_figure(layers: ViewLayers):
    """A plotly figure of ``layers``: every layer a legend entry (click to hide), the robot's
    motions on a time slider with play and pause."""
    if not isinstance(layers, ViewLayers):
        raise TypeError(f"layers must be a bidmp ViewLayers, got {type(layers).__name__}")
    require_extra("plotly", "view", "the 3-D viewer")
    import plotly.graph_objects as go

    traces = _static_traces(go, layers)
    robot, frames, steps = _robot_frames(go, layers, len(traces))
    unit = f" [{layers.units}]" if layers.units else ""
    figure = go.Figure(data=traces + robot, frames=frames)
    figure.update_layout(
        title=f"{layers.title}: drag to turn, scroll to zoom, click a legend entry to hide it",
        scene={
            "xaxis_title": "x" + unit,
            "yaxis_title": "y" + unit,
            "zaxis_title": "z" + unit,
            "aspectmode": "data",
        },
        legend={"itemsizing": "constant"},
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
        height=800,
    )
    if frames:
        figure.update_layout(
            # Tick labels hidden (one per 40 ms would overlap); the current one is shown above.
            sliders=[
                {
                    "steps": steps,
                    "currentvalue": {"prefix": "robot: ", "font": {"color": "#333333"}},
                    "font": {"color": "rgba(0,0,0,0)"},
                    "x": 0.12,
                    "len": 0.86,
                    "pad": {"t": 10},
                }
            ],
            updatemenus=[
                {
                    "type": "buttons",
                    "showactive": False,
                    "direction": "right",
                    "x": 0.0,
                    "y": 0.0,
                    "xanchor": "left",
                    "yanchor": "top",
                    "pad": {"t": 20},
                    "buttons": [
                        {
                            "label": "play",
                            "method": "animate",
                            "args": [
                                None,
                                {"frame": {"duration": 40, "redraw": True}, "fromcurrent": True},
                            ],
                        },
                        {
                            "label": "pause",
                            "method": "animate",
                            "args": [
                                [None],
                                {"mode": "immediate", "frame": {"duration": 0, "redraw": False}},
                            ],
                        },
                    ],
                }
            ],
        )
    return figure


def _tube(path: np.ndarray, radius: np.ndarray, sides: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """A tube mesh round ``path`` (n, 3) of ``radius`` (n,): rings of ``sides`` vertices in the
    plane across the path's tangent, consecutive rings joined by triangles."""
    tangent = np.gradient(path, axis=0)
    tangent /= np.maximum(np.linalg.norm(tangent, axis=1, keepdims=True), 1e-300)
    helper = np.where(np.abs(tangent[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    first = np.cross(tangent, helper)
    first /= np.maximum(np.linalg.norm(first, axis=1, keepdims=True), 1e-300)
    second = np.cross(tangent, first)
    angles = np.linspace(0.0, 2.0 * np.pi, sides, endpoint=False)
    ring = (
        np.cos(angles)[None, :, None] * first[:, None]
        + np.sin(angles)[None, :, None] * second[:, None]
    )
    vertices = (path[:, None, :] + radius[:, None, None] * ring).reshape(-1, 3)
    faces = []
    for i in range(len(path) - 1):
        for k in range(sides):
            a, b = i * sides + k, i * sides + (k + 1) % sides
            c, d = a + sides, b + sides
            faces += [(a, b, c), (b, d, c)]
    return vertices, np.array(faces, dtype=int)


def write_view(path, layers: ViewLayers) -> Path:
    """Write the viewer as one HTML file (plotly.js inside: opens offline); returns its path."""
    path = check_path(path)
    html = view_figure(layers).to_html(include_plotlyjs=True, full_html=True, auto_play=False)
    with atomic_write(path, "w") as handle:
        handle.write(html)
    return path


_META_MAX_BYTES = 16 << 20


def save_layers(path, layers: ViewLayers) -> Path:
    """Store ``layers`` as ``.npz`` (arrays only) with their JSON metadata and a format version."""
    path = check_path(path)
    _check_layers(layers)
    arrays = {"demonstration": layers.demonstration, "segmentation": layers.segmentation}
    arrays.update({f"extended_{i}": p for i, p in enumerate(layers.extended)})
    rollouts = {}
    for m, (method, paths) in enumerate(layers.rollouts.items()):
        for r, (label, trajectory) in enumerate(paths.items()):
            arrays[f"rollout_{m}_{r}"] = trajectory
            rollouts.setdefault(method, []).append([label, f"rollout_{m}_{r}"])
    bands = {}
    for m, (method, radii) in enumerate(layers.bands.items()):
        for r, (label, radius) in enumerate(radii.items()):
            arrays[f"band_{m}_{r}"] = radius
            bands.setdefault(method, []).append([label, f"band_{m}_{r}"])
    robot = {}
    for k, (name, motion) in enumerate(layers.robot.items()):
        arrays[f"robot_times_{k}"], arrays[f"robot_links_{k}"] = motion["times"], motion["links"]
        robot[name] = k
    meta = {
        "format": VIEW_FORMAT,
        "kind": "bidmp-view",
        "title": layers.title,
        "units": layers.units,
        "targets": {label: np.asarray(t, float).tolist() for label, t in layers.targets.items()},
        "n_extended": len(layers.extended),
        "rollouts": rollouts,
        "solids": layers.solids,
        "robot": robot,
        "failures": layers.failures,
        "bands": bands,
    }
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    with atomic_write(path, "wb") as handle:
        np.savez_compressed(handle, **{k: np.asarray(v) for k, v in arrays.items()})
    return path


def _check_layers(layers) -> None:
    if not isinstance(layers, ViewLayers):
        raise TypeError(f"layers must be bidmp.plotting.ViewLayers, got {type(layers).__name__}")


def _json_bytes(shape, dtype) -> None:
    if dtype != np.uint8 or len(shape) != 1 or shape[0] > _META_MAX_BYTES:
        raise ValueError("its metadata member is not UTF-8 JSON bytes")


def _checked_failures(failures) -> dict:
    """A view file's failures, each entry of the shape :class:`ViewLayers` documents."""
    if not isinstance(failures, dict) or not all(
        isinstance(entries, dict) for entries in failures.values()
    ):
        raise ValueError("its failures are not a mapping of method -> label -> failure")
    for entries in failures.values():
        for failure in entries.values():
            if not isinstance(failure, dict) or not isinstance(failure.get("reason"), str):
                raise ValueError("a failure has no reason")
            point = failure.get("point")
            if point is not None and (
                not isinstance(point, list)
                or len(point) != 3
                or not all(isinstance(v, (int, float)) for v in point)
            ):
                raise ValueError("a failure's point is not three numbers")
    return failures


def load_layers(path) -> ViewLayers:
    """Read layers written by :func:`save_layers`; a foreign or broken file is named as such."""
    from ..io._npy import read_npz

    path = check_path(path)
    try:
        with read_npz(path, "bidmp view file") as data:
            meta = load_json(data.read("meta", _json_bytes).tobytes(), f"{path} metadata")
            if not isinstance(meta, dict) or meta.get("kind") != "bidmp-view":
                raise ValueError("it is not a bidmp view file")
            if meta.get("format") != VIEW_FORMAT:
                raise ValueError(
                    f"its format {short_token(meta.get('format'))} is not {VIEW_FORMAT}"
                )
            # absent in files of bidmp 0.5
            return ViewLayers(
                title=meta["title"],
                units=meta["units"],
                demonstration=data["demonstration"],
                targets={label: np.asarray(t) for label, t in meta["targets"].items()},
                segmentation=data["segmentation"],
                extended=[data[f"extended_{i}"] for i in range(meta["n_extended"])],
                rollouts={
                    method: {label: data[key] for label, key in pairs}
                    for method, pairs in meta["rollouts"].items()
                },
                solids=meta["solids"],
                robot={
                    name: {"times": data[f"robot_times_{k}"], "links": data[f"robot_links_{k}"]}
                    for name, k in meta["robot"].items()
                },
                failures=_checked_failures(meta.get("failures", {})),
                bands={
                    method: {label: data[key] for label, key in pairs}
                    for method, pairs in meta.get("bands", {}).items()  # absent before 0.6
                },
            )
    except (KeyError, ValueError, TypeError, AttributeError) as exc:
        raise ValueError(
            f"{path}: cannot read a bidmp view ({printable(str(exc))[:120]})"
        ) from None
