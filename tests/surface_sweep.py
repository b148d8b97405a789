"""The public-surface sweep: every function and class of every package's ``__all__`` (docs/api.md),
every public method of the objects the library hands out (fitted estimators, scenes and their
checkers, steppers, goal systems, integrators, contracts, repairers, job specs, robot cells, view
layers), and every estimator's parameters through ``fit`` — each called with valid arguments except
one (or two: the pairs), which gets a nasty value: wrong types, NaN/inf, overflowing numbers, empty,
ragged, 0-d and 3-D arrays, millions of broadcast rows, data nested thousands deep, paths to
devices, pipes, system files and URLs.

The outcome of one call is one of the classes of :data:`CLASSES`:

``result``          it returned finite numbers (or a documented inf);
``refused``         a ``ValueError``/``TypeError`` in one line of at most 300 characters that names
                    the argument it refuses (by name, or a path by the path);
``unnamed refusal`` a refusal that names none of the arguments changed;
``raw text``        a refusal in NumPy's, SciPy's, pybullet's or Python's own words
                    (:data:`RAW_TEXT`): the input was not checked;
``long message``    a refusal over 300 characters or over several lines;
``internal error``  any other exception (``IndexError``, ``KeyError``, ``RecursionError``, ...);
``silent NaN/inf``  it returned NaN or inf without a word;
``leaked warning``  it warned (a warning is not a refusal: a caller cannot catch it as one);
``hang``            it ran over :data:`MAX_SECONDS`;
``accepted a bool`` it returned a result for True (or booleans) given where a point or an array
                    of numbers goes (:data:`MUST_REFUSE`): NumPy reads True as 1.0, a silently
                    wrong answer.

The nasty values' families: wrong types; NaN/inf; tiny positive floats (1e-300, 5e-324: a loop
count or a step derived from a division by one runs for ever); huge finite values (1e300, and
arrays scaled by it: squares and norms overflow); scalars and bools where arrays and points go;
empty, ragged, 0-d and 3-D arrays; millions of broadcast rows; data nested thousands deep; paths
to devices, pipes, system files and URLs; damaged copies of a data folder (a file truncated,
emptied or garbled: :func:`surface_targets.damaged_copies`).

Everything but ``result`` and ``refused`` is a defect. ``tests/test_fuzz_surface.py`` runs a seeded
sample in CI and everything with ``BIDMP_FUZZ=full`` (``make fuzz``).
"""

from __future__ import annotations

import contextlib
import dataclasses
import importlib
import inspect
import itertools
import os
import re
import signal
import threading
import warnings
from collections import Counter
from pathlib import Path

import api_reference  # tools/: the documented packages, listed once
import numpy as np

import bidmp
from bidmp._api import Estimator

MAX_SECONDS = 10.0
CLASSES = (
    "result",
    "refused",
    "unnamed refusal",
    "raw text",
    "long message",
    "internal error",
    "silent NaN/inf",
    "leaked warning",
    "hang",
    "accepted a bool",
)
DEFECTS = CLASSES[2:]
# Nasty values no call may accept: True or booleans where a point or an array of numbers goes.
MUST_REFUSE = {"True as a point", "bools as points"}
# Defects the families of tiny floats and bools found in bidmp.sim (2026-12-07), one in bidmp
# verify and one in the route planner's tool_route that main's own families found, which their
# engineers fix (sim/ and cli/verify.py were not this change's to touch, tool_route's message is
# changing where it is written): (entry point, argument, nasty value). A call that hits one is
# counted as a "known defect", not failed; the full sweep lists them.
KNOWN_DEFECTS: set = set()  # (label, argument, nasty) of defects known and not yet fixed: none
# the packages documented in docs/api.md, but the command line (its functions parse argv)
PACKAGES = tuple(name for name in api_reference.PACKAGES if name != "bidmp.cli")
# Whole experiments and runs (their own tests run them with valid scenarios; one swapped argument
# would only repeat the scenario checks the scenario sweep makes), the registry's mutators, and
# records the library fills in and hands out (users read them; their methods are swept on real
# instances below).
SKIPPED = {
    "evaluate",
    "simulate",
    "run_job",
    "run_figures",
    "run_table4",
    "run_table5",
    "lasa_generalisation",
    "lasa_incremental",
    "compare_prm",
    "forgetting_runs",
    "run_cell",
    "register",
    "unregister",
    "register_backend",
    "bidmp.experiments.lasa",  # the whole LASA benchmark (its own tests run a small one)
    "run_clfd",  # the whole CLFD protocol (tests/experiments/test_clfd.py runs three tasks)
    "write_clfd",
    "ClfdResult",
    "ClfdRow",
    "ClfdTask",
    "ClfdMethod",  # the base of the methods (each swept as itself)
    "ProDMPBasis",  # made by prodmp_basis (swept), handed out as ProDMP.basis_ (swept as one)
    "register_kind",  # changes the process's model kinds (tests/test_registry.py registers one)
    "write_report",
    "write_sim_report",
    "write_job_report",
    "write_job_commands",  # (its wrong objects swept in surface_targets._wrong_objects)
    "write_results",
    "Report",
    "FrequencyEstimate",
    "RhythmicStepper",  # handed out by RhythmicDMP.stepper(), swept as an instance
    "MethodResult",
    "SimReport",
    "SimTarget",
    "SimMethod",
    "JobReport",
    "JobTarget",
    "JobPhase",
    "Table4",
    "Table5",
    "Figures",
    "BenchmarkResult",
    "GeneralisationResult",
    "IncrementalResult",
    "PRMComparison",
    "Segmentation",
    "Clearance",
    "PrepareInfo",
    "ExtendedDemonstration",
    "Piece",
    "RoadmapResult",
    "ForgettingResult",
    "Part",
    "Solid",
    "Scenario",
    "Verdict",
    "CommandPeaks",
    "FCILimits",  # the FCI's published tables (FCI_LIMITS), pinned by tests/sim/test_fci.py
    "FCIVerdict",
    "CartesianLimits",  # (FCI_LIMITS' Cartesian rows, pinned by tests/sim/test_fci_cartesian.py)
    # streams through a real robot client and server in real time (make franka-check runs them;
    # tests/sim/test_libfranka.py refuses their bad input without them)
    "stream_fr3",
    "LibfrankaOutcome",
    "Repaired",
    "Attempt",
    "MotionPlan",
    "Execution",
    # routes handed out by the planners, and a whole route of the arm (tests/sim/test_arm_routes.py
    # plans them, its refusals swept below through the planner's own entry points)
    "Route",
    "ToolRoute",
    "TimedPath",
    "ArmRoute",
    "arm_route",
    "judged_route",
    "ArmSpace",  # made by ArmGeometry.space (swept), its methods swept on one
    "Recording",
    "AvoidanceCase",
    "ViewLayers",
    "Limits",
    "Method",
    "SimulatorBackend",
    "CouplingTerm",
    "TimedMotion",
    "plot_generalisation",
    "plot_extension",
    "plot_prm_comparison",
    "plot_incremental",
    "plot_targets_top_view",
    "plot_error_vs_distance",
    "plot_scenario_3d",
    "plot_lasa_benchmark",
    "plot_clfd",
    "layers_from_report",
    "add_robot_motions",
    # scikit-learn's metadata routing and parameters, inherited and tested by scikit-learn:
    "set_fit_request",
    "get_metadata_routing",
    "get_params",
    "set_params",
    # dataclass/namedtuple plumbing:
    "count",
    "index",
}
# Methods swept on instances whose valid call needs a live world or a long run: the robot cell's
# execution (its own tests run it; a stepper or plan per call would take seconds).
SKIPPED_METHODS = {
    "RobotCell.execute",
    "RobotCell.execute_closed_loop",
    "RobotCell.load_robot",
    "RobotCell.close",
    "MujocoCell.execute",
    "MujocoCell.execute_closed_loop",
    "MujocoCell.load_robot",
    "MujocoCell.close",
    "KinematicCell.execute_closed_loop",
    "KinematicCell.load_robot",
    "KinematicCell.close",
    "Repairer.repair",
    "Method.fit",
    "Task.shared_model",
    "Task.fitted_dmp",
}
DOCUMENTED_INF = {"bidmp.tasks.approach_error", "bidmp.tasks.axis_deviation"}
# Documented non-finite values inside results: (record, field) — no final approach: inf; no part:
# an infinite clearance; a part without a stand-off: inf; a skill not yet learned: NaN.
DOCUMENTED_FIELDS = {
    ("ForgettingResult", "errors"),
    ("ExtendedDemonstration", "similarity"),
    ("Verdict", "approach_error"),
    ("Verdict", "axis_deviation"),
    ("Clearance", "distance"),
}
DOCUMENTED_ANY = {"Proximity.near"}  # its stand-offs are inf for parts without one

# NumPy's, SciPy's, pybullet's and Python's own wording: a refusal in these words did not check its input.
RAW_TEXT = (
    "could not convert",
    "unsupported operand",
    "not subscriptable",
    "has no len",
    "truth value of an array",
    "could not be broadcast",
    "object too deep",
    "is not callable",
    "invalid literal",
    "SeedSequence",
    "expected non-negative integer",
    "did not converge",
    "not supported between instances",
    "argument must be",
    "index out of",
    "too many indices",
    "cannot convert",
    "object is not",
    "object has no attribute",
    "setting an array element",
    "inhomogeneous",
    "only integer scalar",
    "ambiguous",
    "must be real number, not",
    "got an unexpected keyword",
    "missing 1 required",
    "positional argument",
    "QH6",
    "qhull",
    "Qhull",
    "b3Printf",
    "pybullet.error",
    "required argument is not",
    "maximum recursion",
    "cannot reshape",
    "operands could not",
    "zero-size array",
    "Cannot cast",
    "ufunc",
    "dtype('",
)

DEMO = np.column_stack(
    [np.linspace(0, 100, 60), 30 * np.sin(np.linspace(0, 3, 60)), np.linspace(80, 0, 60)]
)
TIMES = np.linspace(0.0, 1.2, 60)
QUATS = np.tile([0.0, 0.0, 0.0, 1.0], (60, 1))
POSES = np.hstack([DEMO, QUATS])
PERIODIC_TIMES = np.arange(400) / 100.0
PERIODIC = np.column_stack(
    [20 * np.sin(2 * np.pi * PERIODIC_TIMES), 10 * np.cos(4 * np.pi * PERIODIC_TIMES)]
)
_ROCKING = 0.3 * np.sin(2 * np.pi * PERIODIC_TIMES)
PERIODIC_POSES = np.column_stack(
    [
        PERIODIC,
        5 * np.sin(2 * np.pi * PERIODIC_TIMES + 1.0),
        np.zeros_like(_ROCKING),
        np.sin(_ROCKING / 2),
        np.zeros_like(_ROCKING),
        np.cos(_ROCKING / 2),
    ]
)


class _Hang(Exception):
    pass


def _nested_list(depth: int):
    value: list = [0.0]
    for _ in range(depth):
        value = [value]
    return value


def _nested_dict(depth: int):
    value: dict = {"a": 1.0}
    for _ in range(depth):
        value = {"a": value}
    return value


def generic_nasty(tmp: Path) -> list:
    """(label, value) pairs any argument may get."""
    return [
        ("None", None),
        ("True", True),
        ("long text", "x" * 10_000),
        ("object", object()),
        ("complex", DEMO + 1j),
        ("NaN array", np.full((60, 3), np.nan)),
        ("inf", np.inf),
        ("-inf", -np.inf),
        ("NaN", float("nan")),
        ("-1", -1),
        ("0", 0),
        ("2**40", 2**40),
        ("10**400", 10**400),
        ("1e308", 1e308),
        ("empty", np.empty((0, 3))),
        ("3-D array", np.zeros((2, 60, 3))),
        ("ragged", [[1.0, 2.0], [3.0]]),
        ("0-d array", np.array(5.0)),
        ("1j", 1j),
        ("1e-300", 1e-300),
        ("5e-324", 5e-324),
        ("1e300", 1e300),
        ("negative array", -DEMO * 1e300),
        ("a directory", tmp),
        ("empty text", ""),
        ("list nested 5000 deep", _nested_list(5000)),
        ("dict nested 5000 deep", _nested_dict(5000)),
        ("float labels", np.arange(7.0)),
    ]


WRITER = re.compile(
    r"(save|write|atomic|plot_|keyframe)", re.IGNORECASE
)  # labels of callables that write files


def derived_nasty(valid, tmp: Path, writer: bool = True) -> list:
    """(label, value) pairs made from an argument's valid value: the right shape gone wrong
    (``writer``: the callable writes its path argument: no system file is offered it)."""
    out = []
    if isinstance(valid, np.ndarray) and valid.ndim >= 1 and valid.dtype.kind == "f" and valid.size:
        width = valid.shape[-1]
        row = valid.reshape(-1, width)[:1]
        out.append(("2 M broadcast rows", np.broadcast_to(row, (2_000_000, width))))
        if width == 4:
            out.append(("50 M broadcast rows", np.broadcast_to(row, (50_000_000, 4))))
        one = valid.copy()
        one.flat[min(3, one.size - 1)] = np.nan
        out.append(("one NaN", one))
        one = valid.copy()
        one.flat[0] = -np.inf
        out.append(("one -inf", one))
        out.append(("int64", np.round(valid).astype(np.int64)))
        # tiny positive floats: a motion of 1e-300 is no motion, a step of 1e-300 none either
        out.append(("all 1e-300", np.full(valid.shape, 1e-300)))
        out.append(("one row", valid.reshape(-1, width)[:1]))
        out.append(("a scalar", 2.5))
        out.append(("True as a point", True))
        out.append(("bools as points", valid != 0))
        out.append(("times 1e300", valid * 1e300))
        out.append(("times 1e-300", valid * 1e-300))
        if valid.ndim == 2:
            out.append(("transposed", np.ascontiguousarray(valid.T)))
    if isinstance(valid, (str, Path)) and (isinstance(valid, Path) or "/" in str(valid)):
        fifo = tmp / "a-fifo"
        if not fifo.exists():
            os.mkfifo(fifo)
        if (
            writer
        ):  # never a system file: the sweep may run as root, and writing is what a writer does
            system = tmp / "system" / "passwd"
            system.parent.mkdir(exist_ok=True)
            system.write_text("root:x:0:0:root:/root:/bin/bash\n")
            out += [
                ("a system-like file", system),
                ("a FIFO", fifo),
                ("file:// URL", f"file://{tmp}/url.out"),
                ("missing folder", tmp / "missing" / "x.out"),
            ]
        else:
            out += [
                ("/etc/passwd", "/etc/passwd"),
                ("/dev/zero", "/dev/zero"),
                ("a FIFO", fifo),
                ("file:// URL", "file:///etc/passwd"),
                ("missing file", tmp / "missing" / "x.csv"),
            ]
    if isinstance(valid, dict):
        out += [("unknown key", {**valid, "bogus-key": 1.0}), ("list of the dict", [valid])]
    if isinstance(valid, (int, float)) and not isinstance(valid, bool):
        # (1e-300 and 5e-324 are every argument's: generic_nasty)
        out += [
            ("NaN", float("nan")),
            ("-inf", -np.inf),
            ("-1e-300", -1e-300),
            ("times 1e300", valid * 1e300),
        ]
    return out


def valid_arguments(tmp: Path) -> dict:
    """A valid value per argument name (those not given keep their defaults)."""
    from bidmp.extension import segment
    from bidmp.primitives import kernel_centres, kernel_widths

    centres = kernel_centres(10, 100, 0.01)
    rng = np.random.default_rng(0)
    return {
        "y": DEMO,
        "demo": DEMO,
        "demonstration": DEMO,
        "trajectory": DEMO,
        "reference": DEMO,
        "a": DEMO,
        "b": DEMO[::-1],
        "tra_imi": DEMO[20:45],
        "piece": DEMO[20:45],
        "points": DEMO,
        "positions": DEMO,
        "curve": DEMO,
        "path": tmp / "file.csv",
        "via": DEMO[[0, 30, 59]],
        "t": TIMES,
        "stamps": TIMES,
        "goal": DEMO[-1] + 10,
        "target": DEMO[-1],
        "new_target": DEMO[-1] + [150.0, 0.0, 0.0],
        "start": DEMO[0],
        "point": DEMO[5],
        "dt": 0.01,
        "n_steps": 50,
        "n_kernels": 10,
        "seed": 0,
        "alpha": 25.0,
        "beta": 6.25,
        "K": 625.0,
        "tau": 1.0,
        "alpha_phase": 1.0,
        "height": 20.0,
        "q": QUATS,
        "p": QUATS,
        "quaternions": QUATS,
        "poses": POSES,
        "phase": np.linspace(1.0, 0.05, 60),
        "centres": centres,
        "widths": kernel_widths(centres),
        "span": 0.99,
        "name": "Sshape",
        "path_or_name": "nut-unscrewing",
        "noise": 0.1,
        "segmentation_points": segment(DEMO).points,
        "orientations": QUATS,
        "n_samples": 60,
        "data": {"a": 1},
        "source": "fuzz",
        "r": np.zeros((5, 3)),
        "error": np.zeros((5, 3)),
        "nodes": DEMO[::6],
        "F": rng.normal(size=(40, 6)),
        "A": rng.normal(size=(30, 5)),
        "X": rng.normal(size=(30, 4)),
        "Y": rng.normal(size=(30, 2)),
        "shape": "Sshape",
        "metric": "rmse",
        "rows": [],
        "recordings": [DEMO, DEMO * 1.1],
        "parts": [],
        "radius": 10.0,
        "length": 100.0,
        "label": "post",
        "yd": np.gradient(DEMO, TIMES, axis=0),
        "ydd": np.zeros_like(DEMO),
        "omega": np.zeros((60, 3)),
        "omega_dot": np.zeros((60, 3)),
        "rate": 1.0,
        "training_phase": np.linspace(1.0, 0.05, 60),
        "gate": np.linspace(0.0, 1.0, 60),
        "exact": True,
        "gain": 0.5,
        "acceleration": np.ones(3),
        "joint": 2,
        "heights": np.linspace(50.0, 0.0, 60),
        "goals": DEMO[-1] + np.array([[0.0, 0.0, 0.0], [10.0, 5.0, 0.0]]),
        "part": "post",
        "targets": {"post": [200.0, 0.0, 50.0]},
        "demonstrations": [DEMO, DEMO + [0.0, 30.0, 0.0]],
        "weights": np.array([0.5, 0.5]),
        "means": np.array([[0.0, 0.0], [1.0, 1.0]]),
        "value_mm": 2.0,
        "units": "mm",
        "covariances": np.array([np.eye(2), np.eye(2)]),
        "index": 1,
        "step": 0.01,
        "n_train": 60,
        "n_motion": 60,
        "within": 20.0,
        "distance": 20.0,
        "exclude": (),
        "width": 64,
        "height_px": 48,
        "kind": "box",
        "centre": np.zeros(3),
        "rotation": np.eye(3),
        "params": (10.0, 10.0, 10.0),
        "u_now": np.zeros(3),
        "u_next": np.zeros(3),
        "z": np.zeros(3),
        "y_measured": DEMO[0],
        "n": 5,
        "threshold": 1.75,
        "offset": np.zeros(3),
        "duration": 1.0,
        "blend": 0.2,
    }


def sweep_calls(tmp: Path, rng: np.random.Generator, pair_budget: int, source=None):
    """Every (label, swapped names, nasty labels, thunk, argument names) of the sweep: each argument
    of each callable with each nasty value, then ``pair_budget`` pairs drawn by ``rng``
    (``source(tmp)``: the (label, callable, valid arguments) to sweep; default all of them)."""
    from surface_targets import targets  # the callables and their valid arguments

    common = valid_arguments(tmp)
    generic = generic_nasty(tmp)
    singles, pair_pool = [], []
    for label, function, special in (source or targets)(tmp):
        try:
            signature = inspect.signature(function)
        except (TypeError, ValueError):
            continue
        parameters = [
            p
            for p in signature.parameters.values()
            if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
        ]
        extra = {key[6:]: value for key, value in special.items() if key.startswith("nasty:")}
        special = {key: value for key, value in special.items() if not key.startswith("nasty:")}
        valid = {**common, **special}
        required = [p.name for p in parameters if p.default is inspect.Parameter.empty]
        if any(name not in valid for name in required):
            yield label, (), ("uncovered",), None, []
            continue
        names = [p.name for p in parameters]
        # The required arguments, and the optional ones the callable's own valid values name.
        base = {name: valid[name] for name in names if name in required or name in special}
        writer = bool(WRITER.search(label))
        options = {
            name: generic
            + derived_nasty(_shaped_like(valid.get(name), parameters[index]), tmp, writer)
            + extra.get(name, [])
            for index, name in enumerate(names)
        }
        if inspect.isclass(function) and issubclass(function, Estimator):
            # an estimator's constructor only stores (scikit-learn's convention): what it is given
            # is judged by its fit and its set_params (their own targets)
            options = {
                name: [(lab, value) for lab, value in values if lab not in MUST_REFUSE]
                for name, values in options.items()
            }
        for name in names:
            for nasty_label, value in options[name]:
                singles.append(
                    (label, (name,), (nasty_label,), function, base, {name: value}, names)
                )
        for first, second in itertools.combinations(names, 2):
            pair_pool.append((label, function, base, names, first, second, options))
    yield from (_call(*single) for single in singles)
    if pair_pool and pair_budget:
        for index in rng.choice(len(pair_pool), size=pair_budget, replace=True):
            label, function, base, names, first, second, options = pair_pool[int(index)]
            a = options[first][int(rng.integers(len(options[first])))]
            b = options[second][int(rng.integers(len(options[second])))]
            yield _call(
                label,
                (first, second),
                (a[0], b[0]),
                function,
                base,
                {first: a[1], second: b[1]},
                names,
            )


def _shaped_like(valid, parameter: inspect.Parameter):
    """The value an argument's derived nasty values are made from: its common valid value, but
    none for a flag (a parameter whose default or annotation is a bool: a ``poses`` flag is not
    the poses array the common ``poses`` is)."""
    if isinstance(parameter.default, bool) or "bool" in str(parameter.annotation):
        return None
    return valid


def _call(label, swapped, nasty_labels, function, base, changes, names):
    kwargs = {**base, **changes}
    return label, swapped, nasty_labels, (lambda: function(**kwargs)), names, changes


# Arguments whose refusals name them by the document they hold: a scene's keys under "scene", a
# scenario's under "scenario", a robot's under "robot" (as in a scenario file, where these arrive from).
ALIASES = {
    "Scene.from_dict": {"data": "scene"},
    "bidmp.tasks.from_dict": {"data": "scenario"},
    "bidmp.io.load_json": {"data": "fuzz"},  # a JSON document is named by its source
    "bidmp.tasks.parse_job": {"data": "job"},
    "bidmp.sim.robot_model": {"spec": "robot"},
}


def names_argument(message: str, changes: dict, label: str = "") -> bool:
    """Whether ``message`` names one of the changed arguments: by its name used as a name (a
    one-letter name followed by what is said of it), a path by the path, or a document argument by
    what it holds (:data:`ALIASES`)."""
    aliases = ALIASES.get(label, {})
    for name, value in changes.items():
        if name in aliases and re.search(rf"(?<![\w]){aliases[name]}(?![\w])", message):
            return True
        if isinstance(value, (str, os.PathLike)) and len(os.fspath(value)) > 2:
            text = os.fsdecode(os.fspath(value))
            if text in message or text[-40:] in message or os.path.basename(text) in message:
                return True
        escaped = re.escape(name)
        if len(name) > 2:
            if re.search(rf"(?<![\w]){escaped}(?![\w])", message):
                return True
        elif re.search(
            rf"(?:^|[\s(`'\".]){escaped}(?:\s+(?:must|has|is|are|contains|needs|holds|of|with|should|and|"
            rf"gives|takes|would|was|were|can|cannot|does|lies|barely|implies|rows?|columns?|values?|"
            rf"\(|[/*+<>=-])|[:=\[,)'\"`.]|$)",
            message,
        ):
            return True
    return False


def check_finite(value, where: str = "result", depth: int = 0) -> None:
    """Assert ``value`` (arrays, floats, sequences and dataclasses of them, 20 levels deep) holds no NaN/inf."""
    if depth > 20:
        return
    if isinstance(value, np.ndarray) and value.dtype.kind in "fc":
        assert np.all(np.isfinite(value)), f"{where} contains NaN/inf"
    elif isinstance(value, float):
        assert np.isfinite(value), f"{where} is {value}"
    elif isinstance(value, (tuple, list)) and len(value) < 1000:
        for index, item in enumerate(value):
            check_finite(item, f"{where}[{index}]", depth + 1)
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        for field in dataclasses.fields(value):
            if (type(value).__name__, field.name) not in DOCUMENTED_FIELDS:
                check_finite(getattr(value, field.name), f"{where}.{field.name}", depth + 1)


def classify(call, changes: dict, allow_inf: bool = False, label: str = "") -> str:
    """One call under the contract: its outcome class (:data:`CLASSES`)."""
    previous = None
    if threading.current_thread() is threading.main_thread():

        def alarm(*_):
            raise _Hang

        previous = signal.signal(signal.SIGALRM, alarm)
        signal.setitimer(signal.ITIMER_REAL, MAX_SECONDS)
    try:
        with warnings.catch_warnings(record=True) as caught, contextlib.redirect_stdout(None):
            warnings.simplefilter("always")
            # Documented: quaternions off unit length are normalised, and the caller is told.
            warnings.filterwarnings("ignore", message=".*not of unit length.*normalised")
            try:
                result = call()
                if inspect.isgenerator(result):  # a lazy result is used: drawn in full
                    result = [item for item in result]
            except _Hang:
                return "hang"
            except (ValueError, TypeError) as exc:
                message = str(exc)
                if "\n" in message or len(message) > 300:
                    return "long message"
                if any(pattern in message for pattern in RAW_TEXT):
                    return "raw text"
                return "refused" if names_argument(message, changes, label) else "unnamed refusal"
            except Exception:  # noqa: BLE001 - the class being counted
                return "internal error"
            finally:
                import matplotlib.pyplot as plt

                plt.close("all")
        if caught:
            return "leaked warning"
        try:
            if (
                not (allow_inf and isinstance(result, float) and result == np.inf)
                and label not in DOCUMENTED_ANY
            ):
                check_finite(result)
        except AssertionError:
            return "silent NaN/inf"
        return "result"
    finally:
        if previous is not None:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, previous)


def _system_files() -> dict:
    """Size and modification time of the system files a reader is offered (a writer never is)."""
    return {
        path: (os.stat(path).st_size, os.stat(path).st_mtime_ns)
        for path in ("/etc/passwd", "/dev/zero")
    }


KNOWN_FOUND: list = []  # the known defects the last run met (KNOWN_DEFECTS), described


def run(chosen) -> tuple[Counter, list]:
    """Outcome counts per ``label: class`` and the defects' descriptions of the calls ``chosen``."""
    before = _system_files()
    try:
        return _run(chosen)
    finally:
        assert _system_files() == before, (
            "the sweep changed a system file: a writer was offered one"
        )


def _run(chosen) -> tuple[Counter, list]:
    outcomes, defects = Counter(), []
    known_defects = KNOWN_FOUND
    known_defects.clear()
    with bidmp.set_limits(max_array_bytes=256 << 20):
        trail = os.environ.get(
            "BIDMP_FUZZ_TRAIL"
        )  # a file naming each call before it runs (a crash's culprit)
        for label, swapped, nasty_labels, thunk, _, changes in chosen:
            if trail:
                with open(trail, "a", encoding="utf-8") as handle:
                    handle.write(f"{label} {swapped} {nasty_labels}\n")
            kind = classify(thunk, changes, label in DOCUMENTED_INF, label)
            if kind == "result" and MUST_REFUSE.intersection(nasty_labels):
                kind = "accepted a bool"
            outcomes[f"{label}: {kind}"] += 1
            if kind in DEFECTS:
                described = ", ".join(f"{n}={v}" for n, v in zip(swapped, nasty_labels))
                known = any((label, n, v) in KNOWN_DEFECTS for n, v in zip(swapped, nasty_labels))
                (known_defects if known else defects).append(f"{label}({described}): {kind}")
    return outcomes, defects


def packages_entry_points():
    """(label, callable) for every public function and class of :data:`PACKAGES`."""
    seen = set()
    for package in PACKAGES:
        module = importlib.import_module(package)
        for name in module.__all__:
            value = getattr(module, name)
            if (
                name in SKIPPED
                or f"{package}.{name}" in SKIPPED
                or inspect.ismodule(value)
                or not callable(value)
                or id(value) in seen
            ):
                continue
            if inspect.isclass(value) and issubclass(value, BaseException):
                continue
            seen.add(id(value))
            yield f"{package}.{name}", value
