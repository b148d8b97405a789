"""What the surface sweep (``surface_sweep.py``) calls: (label, callable, valid arguments that differ
from the common ones) for every public function and class, every estimator's parameters through
``fit``, and every public method of the objects the library hands out."""

from __future__ import annotations

import inspect
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation
from surface_sweep import (
    DEMO,
    PERIODIC,
    PERIODIC_POSES,
    PERIODIC_TIMES,
    POSES,
    QUATS,
    SKIPPED,
    SKIPPED_METHODS,
    TIMES,
    packages_entry_points,
)

import bidmp


class _Wall:
    """A free space for the route planner: the unit square with a wall across its middle (a
    point body, the slack its distance to the wall's box)."""

    lower, upper, tolerance = np.zeros(2), np.ones(2), 1e-3

    def slack(self, q) -> float:
        q = np.asarray(q, dtype=float)
        gap = np.maximum(np.maximum([0.45, 0.0] - q, q - [0.55, 0.7]), 0.0)
        return float(np.linalg.norm(gap)) - 0.01

    def sweep(self, a, b) -> float:
        return float(np.linalg.norm(np.asarray(b, float) - np.asarray(a, float)))


def _route_overrides() -> dict:
    """Valid arguments of the route planner's entry points (bidmp.planning, the arm's routes)."""
    from bidmp.sim import KinematicCell
    from bidmp.sim.robots import PANDA_MODEL

    scenario = bidmp.tasks.load("nut-unscrewing")
    cell = KinematicCell(scenario.scene)
    plan = cell.plan(DEMO / 4.0 + [0.0, 0.0, 40.0])
    return {
        "bidmp.planning.plan_route": {"space": _Wall(), "start": [0.2, 0.2], "goals": [0.8, 0.2]},
        "bidmp.planning.segment_free": {"space": _Wall(), "a": [0.2, 0.2], "b": [0.3, 0.8]},
        "bidmp.planning.time_path": {
            "waypoints": DEMO[::10] / 100.0,
            "velocity": [2.0, 2.0, 2.0],
            "acceleration": [10.0, 10.0, 10.0],
            "jerk": [5000.0, 5000.0, 5000.0],
        },
        "bidmp.planning.tool_route": {
            "scene": scenario.scene,
            "start": [-80.0, -120.0, 200.0],
            "goal": scenario.targets["12"],
            "approach_height": 28.5,
            "exclude": scenario.scene.target_parts("12", scenario.targets["12"]),
        },
        "bidmp.scene.PoseChecker": {"scene": scenario.scene, "chosen": np.arange(3), "margin": 1.0},
        "bidmp.sim.ArmGeometry": {
            "robot": PANDA_MODEL,
            "tool_radius": 0.0125,
            "tool_length": 0.1,
            "base": [0.0, -0.45, 0.0],
            "yaw": 90.0,
        },
        "bidmp.sim.supports_routes": {"cell": cell},
        "bidmp.sim.reach": {"cell": bidmp.sim.RobotCell(scenario.scene), "point": [0.0, 0.0, 50.0]},
        "bidmp.sim.needlessly_slow": {"cell": cell, "plan": plan},
    }


def _capacity_overrides(tmp: Path) -> dict:
    """The capacity sweep's records and writers: a two-cell result (one memory, the library)."""
    from bidmp.experiments import CapacityResult, CapacityRow

    numbers = {"weights": 10, "normal_equations": 6}
    row = {"acc": 0.5, "bwt": -0.1, "mean_dtw": 3.0, "map_errors": [0.1, 0.2]}
    memory = CapacityRow("bidmp-continual", 8, 0, numbers=numbers, **row)
    library = CapacityRow("map-library", None, None, numbers={"maps": 12}, **row)
    result = CapacityResult(["a", "b"], [memory, library])
    return {
        "bidmp.experiments.CapacityRow": {
            "method": "bidmp-continual",
            "nodes": 8,
            "seed": 0,
            "numbers": numbers,
            **row,
        },
        "bidmp.experiments.CapacityResult": {"tasks": ["a", "b"], "rows": [memory, library]},
        "bidmp.experiments.write_capacity": {"result": result, "out": tmp / "capacity"},
        "bidmp.plotting.plot_clfd_capacity": {"path": tmp / "capacity.png", "result": result},
    }


def _package_overrides(tmp: Path) -> dict:
    """Valid arguments of package functions that differ from the common ones."""
    from bidmp.extension import segment
    from bidmp.incremental import truncated_svd
    from bidmp.io import save_model, save_poses, save_trajectory
    from bidmp.scene import Tool

    csv, poses, model = tmp / "demo.csv", tmp / "poses.csv", tmp / "model.npz"
    save_trajectory(DEMO, csv, TIMES)
    save_poses(POSES, poses, TIMES)
    save_model(bidmp.DMP(n_kernels=10).fit(DEMO), model)
    layers = tmp / "layers.npz"
    from bidmp.plotting import ViewLayers, save_layers

    save_layers(layers, ViewLayers(title="x", units="mm", demonstration=DEMO))
    from bidmp.io import write_bag

    bag = write_bag(tmp / "poses_bag", TIMES, DEMO / 1000.0, kind="pose")
    from bidmp.io import run_folder

    run = tmp / "run"  # a run folder of one file
    with run_folder(run, "bidmp surface") as writing:
        (writing.path / "view.html").write_text("<p>run</p>")
    readers = {
        f"bidmp.io.{name}": {"path": csv}
        for name in (
            "load_trajectory",
            "read_trajectory",
            "declared_units",
            "is_joint_recording",
            "read_recording",
            "recording_kind",
        )
    }
    rng = np.random.default_rng(3)
    A, E = rng.normal(size=(30, 5)), rng.normal(size=(30, 2))
    U, sv, V, _ = truncated_svd(A)
    dmp = bidmp.DMP(n_kernels=10).fit(DEMO)
    joint = {
        "lower": -np.ones(7),
        "upper": np.ones(7),
        "velocity": np.ones(7),
        "acceleration": np.ones(7),
    }
    scenario = bidmp.tasks.load("nut-unscrewing")
    joints = np.zeros((60, 7))
    pose_stepper = bidmp.CartesianDMP(bidmp.DMP(n_kernels=10)).fit(POSES, TIMES).stepper()
    return {
        **readers,
        **_route_overrides(),
        "bidmp.io.read_poses": {"path": poses},
        "bidmp.load": {"path": model},
        "bidmp.Scene": {"tool": Tool(5.0, 50.0)},
        "bidmp.save": {"model": dmp, "path": tmp / "saved.npz"},
        **_capacity_overrides(tmp),
        "bidmp.primitives.as_motion_limits": {"limits": {"max_velocity": 1.0}},
        "bidmp.forgetting": {"dmp": dmp},
        "bidmp.incremental.block_pinv_update": {"A": A, "A_pinv": np.linalg.pinv(A), "E": E},
        "bidmp.incremental.svd_update": {"U": U, "s": sv, "V": V, "E": E},
        "bidmp.incremental.pose_forgetting": {
            "cartesian": bidmp.CartesianDMP(bidmp.DMP(n_kernels=10)).fit(POSES),
            "demonstrations": [POSES, POSES + [0.0, 30.0, 0.0, 0.0, 0.0, 0.0, 0.0]],
        },
        "bidmp.sim.JointLimits": joint,
        "bidmp.sim.robot_placement": {"scenario": scenario},
        "bidmp.sim.robot_model": {"spec": {"model": "xarm6"}},
        "bidmp.sim.judge_commands": {"q": _fr3_stream(), "robot": "fr3"},
        "bidmp.experiments.swept_error_area": {
            "trajectory": np.eye(3)[:, :2],
            "reference": np.eye(3)[:, :2] + 1,
        },
        "bidmp.experiments.ContinualBLS": {"n_basis": 20, "n_nodes": 8, "capacity": 3},
        "bidmp.primitives.prodmp_basis": {"n_basis": 6, "dt": 0.02},
        "bidmp.primitives.PrimitiveKind": {
            "name": "Toy",
            "path": "bidmp.primitives.promp:ProMP",
            "family": "several",
        },
        "bidmp.primitives.model_class": {"name": "DMP"},
        "bidmp.primitives.kind_of": {"model": bidmp.DMP(n_kernels=10)},
        "bidmp.experiments.BiDMPLibrary": {"n_kernels": 20, "seed": 1},
        "bidmp.experiments.TangentChart": {"reference": np.array([1.0, 0.0, 0.0, 0.0])},
        "bidmp.experiments.demonstration_errors": {
            "reproduced": np.tile(np.linspace(0.0, 1.0, 5)[:, None], (1, 1, 2)),
            "demonstrations": np.tile(np.linspace(0.0, 1.0, 5)[:, None], (1, 1, 2)) + 0.5,
            "metrics": ("dtw", "frechet"),
        },
        "bidmp.experiments.FineTune": {"n_kernels": 20},
        "bidmp.experiments.ProMPLibrary": {"n_basis": 10},
        "bidmp.experiments.orientation_error": {
            "true": np.tile([1.0, 0.0, 0.0, 0.0], (5, 1)),
            "predicted": np.tile([0.0, 1.0, 0.0, 0.0], (5, 1)),
        },
        "bidmp.experiments.accuracy_matrix": {
            "errors": [[np.array([1.0, 3.0])]],
            "threshold": 2.0,
        },
        "bidmp.experiments.continual_metrics": {
            "matrix": np.ones((2, 2)),
            "sizes": [1, 2],
            "times": [1.0, 1.0],
        },
        "bidmp.experiments.clfd_tasks": {"dataset": "lasa"},
        "bidmp.experiments.DMPLibrary": {"n_kernels": 20},
        "bidmp.sim.judge_cartesian": {
            "positions": np.linspace([0.4, 0.0, 0.5], [0.41, 0.0, 0.5], 50),
            "quaternions": np.tile([0.0, 0.0, 0.0, 1.0], (50, 1)),
            "robot": "fr3",
        },
        "bidmp.sim.match_joint_names": {
            "names": [f"fr3_joint{i}" for i in range(1, 8)],
            "robot": "fr3",
        },
        "bidmp.sim.job_targets": {"scenario": scenario},
        "bidmp.sim.target_labels": {"scenario": scenario, "targets": ["1", "3"]},
        "bidmp.sim.execution_report": {"scenario": scenario, "methods": ["dmp"]},
        "bidmp.sim.execution_settings": {"scenario": scenario},
        "bidmp.sim.in_bin": {
            "centre": [1.0, 2.0, 5.0],
            "floor": [0.0, 0.0, 0.0],
            "inner": [60.0, 60.0, 40.0],
        },
        "bidmp.sim.in_slot": {
            "centre": [1.0, 0.0, 20.0],
            "slot": [0.0, 0.0, 0.0],
            "height": 40.0,
            "off_tolerance": 2.0,
            "height_tolerance": 1.0,
        },
        "bidmp.sim.inverse_kinematics": {"points": np.array([[0.45, -0.1, 0.3], [0.5, 0.0, 0.3]])},
        "bidmp.sim.joint_names": {"robot": "panda"},
        "bidmp.io.start_stamp": {"origin": "2026-12-03T14:00:00Z"},
        "bidmp.io.json_number": {"value": 1.23456},
        "bidmp.extension.check_extension_options": {"n_iter": 5},
        "bidmp.experiments.check_lasa_options": {
            "shapes": ["Sshape"],
            "methods": ["dmp-paper"],
            "demos": "first3",
            "every": 10,
        },
        "bidmp.primitives.drop_repeated_stamps": {"y": DEMO, "t": TIMES},
        "bidmp.primitives.GaussianBasis": {"size": 10},
        "bidmp.primitives.VonMisesBasis": {"size": 10},
        "bidmp.tasks.RockSpec": {"recording": "rocking_cell"},
        "bidmp.primitives.promp_basis": {"phase": np.linspace(0.0, 1.0, 30), "n_basis": 8},
        "bidmp.primitives.condition_gaussian": {
            "mean": np.zeros(3),
            "cov": np.eye(3),
            "H": np.ones((3, 1)),
            "y": np.ones(1),
            "noise": np.zeros((1, 1)),
        },
        "bidmp.plotting.plot_distribution": {
            "path": tmp / "distribution.png",
            "demonstrations": [DEMO[:, :2], DEMO[::2, :2]],
            "mean": DEMO[:, :2],
            "std": np.ones((60, 2)),
        },
        "bidmp.plotting.plot_rhythm": {
            "path": tmp / "rhythm.png",
            "recording": PERIODIC,
            "t": PERIODIC_TIMES,
            "trajectory": bidmp.primitives.RhythmicDMP(n_kernels=12)
            .fit(PERIODIC, PERIODIC_TIMES)
            .trajectory(1.0, dt=0.01),
            "frequency": 1.0,
        },
        "bidmp.primitives.AdaptiveOscillator": {"frequency": 1.0},
        "bidmp.primitives.estimate_frequency": {"y": PERIODIC, "t": PERIODIC_TIMES},
        "bidmp.primitives.harmonic_fit": {
            "y": PERIODIC,
            "t": PERIODIC_TIMES,
            "frequency": 1.0,
            "n_harmonics": 3,
        },
        "bidmp.primitives.ExponentialPhase": {"rate": 4.0},
        "bidmp.sim.require_simulator": {},
        "bidmp.sim.picture_frames": {"pictured": {("dmp", "1"), ("bidmp", "12")}},
        "bidmp.sim.RobotCell": {"scene": scenario.scene},
        "bidmp.sim.MujocoCell": {"scene": scenario.scene},
        "bidmp.sim.KinematicCell": {"scene": scenario.scene},
        "bidmp.sim.plan_path": {
            "cell": bidmp.sim.KinematicCell(scenario.scene),
            "path": scenario.demonstration[::20],
        },
        "bidmp.io.load_model": {"path": model},
        "bidmp.plotting.plot_segmentation": {"points": segment(DEMO).points},
        "bidmp.plotting.load_layers": {"path": layers},
        "bidmp.plotting.save_layers": {
            "path": tmp / "l2.npz",
            "layers": ViewLayers("x", "mm", DEMO),
        },
        "bidmp.plotting.write_view": {
            "path": tmp / "v.html",
            "layers": ViewLayers("x", "mm", DEMO),
        },
        "bidmp.plotting.view_figure": {"layers": ViewLayers("x", "mm", DEMO)},
        "bidmp.plotting.solid_layer": {"solid": scenario.scene.solids[0]},
        "bidmp.plotting.solid_mesh": {
            "kind": "box",
            "centre": np.zeros(3),
            "rotation": np.eye(3),
            "params": (5.0, 5.0, 5.0),
        },
        "bidmp.plotting.plot_trajectories": {"path": tmp / "p.png"},
        "bidmp.plotting.plot_rollout": {"path": tmp / "r.png", "trajectory": dmp.trajectory()},
        "bidmp.plotting.plot_recordings": {
            "path": tmp / "rec.png",
            "recordings": [("demo", DEMO, TIMES, *bidmp.prepare(DEMO, TIMES), None)],
        },
        "bidmp.io.save_poses": {"poses": POSES, "path": tmp / "p.csv"},
        "bidmp.io.save_trajectory": {"path": tmp / "t.csv"},
        "bidmp.io.write_bag": {
            "path": tmp / "b.bag",
            "t": TIMES,
            "values": joints,
            "kind": "joints",
            "names": [f"j{i}" for i in range(7)],
        },
        "bidmp.io.read_bag": {"path": bag},
        "bidmp.io.is_bag": {"path": bag},
        "bidmp.io.atomic_write": {"path": tmp / "a.bin"},
        "bidmp.io.run_folder": {"out": tmp / "run2", "command": "bidmp surface"},
        "bidmp.io.RunFolder": {
            "out": tmp / "run2",
            "final": tmp / "run2",
            "path": tmp / ".run2.new",
            "command": "bidmp surface",
            "earlier": None,
        },
        "bidmp.io.RunManifest": {"run": "0" * 32, "command": "bidmp surface", "bidmp": "0.6.0"},
        "bidmp.io.check_run_files": {"paths": [run / "view.html", csv]},
        "bidmp.io.read_manifest": {"folder": run},
        "bidmp.io.update_manifest": {"folder": run, "name": "view.html"},
        "bidmp.io.load_json": {"data": '{"a": 1}'},
        "bidmp.primitives.as_poses": {"poses": POSES},
        **{
            f"bidmp.primitives.{name}": {"goal": QUATS[-1]}
            for name in (
                "principal_log",
                "continuous_log",
                "orientation_error",
                "orientation_from_log",
            )
        },
        "bidmp.primitives.DMPSettings": dmp.settings().as_dict(),
        "bidmp.primitives.DMPSystem": {
            "settings": dmp.settings(),
            "weights": dmp.weights_,
            "start": dmp.start_,
            "goal": dmp.goal_,
            "n_samples": dmp.n_steps_,
            "duration": dmp.duration_,
            "centres": dmp.centres_,
            "widths": dmp.widths_,
            "goal_gate": dmp.goal_gate_,
        },
        "bidmp.primitives.DMPStepper": {
            "dmp": dmp,
            "goal": DEMO[-1],
            "start": DEMO[0],
            "duration": 1.0,
            "coupling": 0.0,
            "start_velocity": None,
            "forcing_increment": None,
        },
        "bidmp.primitives.PoseStepper": {
            "position": pose_stepper.position,
            "orientation": pose_stepper.orientation,
            "goal_orientation": np.array([0.0, 0.0, 0.0, 1.0]),
        },
        "bidmp.primitives.ProgressGate": {
            "training_phase": np.linspace(1.0, 0.05, 60),
            "gate": np.linspace(0.0, 1.0, 60),
        },
        "bidmp.primitives.ApproachGate": {
            "training_phase": np.linspace(1.0, 0.05, 60),
            "gate": np.linspace(0.0, 1.0, 60),
        },
        "bidmp.primitives.StepIntegrator": {"alpha": 25.0, "beta": 6.25, "tau": 1.0, "exact": True},
        "bidmp.primitives.time_scale": {"trajectory": dmp.trajectory(), "max_velocity": 100.0},
        "bidmp.time_scale": {"trajectory": dmp.trajectory(), "max_velocity": 100.0},
        "bidmp.primitives.scale_factor": {"trajectory": dmp.trajectory(), "max_velocity": 100.0},
        "bidmp.primitives.on_uniform_time": {"y": DEMO, "t": TIMES},
        "bidmp.extension.extend_pose_demonstration": {
            "poses": POSES,
            "new_target": POSES[-1] + [150.0, 0, 0, 0, 0, 0, 0],
        },
        "bidmp.incremental.sparse_autoencoder": {
            "F": rng.normal(size=(40, 6)),
            "target": rng.normal(size=(40, 3)),
        },
        "bidmp.tasks.carried_clearance": {"scene": scenario.scene, "path": DEMO, "exclude": ()},
        "bidmp.tasks.carried_depth": {
            "carried": (scenario.scene.solids[0], np.array([0.0, 0.0, -3.0]))
        },
        "bidmp.tasks.check_robot": {"robot": {"model": "iiwa", "base": [0.0, -400.0, 0.0]}},
        "bidmp.tasks.Contract": {"threshold": 1.75},
        "bidmp.tasks.command_peaks": {"commands": np.zeros((50, 7)), "limits": _panda_limits()},
        "bidmp.tasks.parse_job": {"data": scenario.spec.get("job"), "source": "fuzz"},
        "bidmp.tasks.tour": {"points": DEMO[::6], "start": DEMO[0]},
        "bidmp.tasks.JobSpec": {
            "kind": "unscrew",
            "steps": ("approach", "engage", "unscrew", "retract", "drop"),
            "bin": (np.zeros(3), np.array([70.0, 70.0, 40.0])),
        },
        "bidmp.tasks.from_dict": {"data": scenario.spec},
        "bidmp.tasks.resolve": {"scenario": "nut-unscrewing", "name": "scenario"},
        "bidmp.tasks.Repairer": {
            "contract": bidmp.tasks.Contract.of(scenario),
            "demonstration": scenario.demonstration,
        },
        "bidmp.tasks.methods.get": {"name": "dmp"},
        "bidmp.tasks.methods.Task": {"demonstration": DEMO, "goals": DEMO[-2:]},
        "bidmp.tasks.final_approach_mask": {"heights": np.linspace(50.0, 0.0, 60), "height": 20.0},
        "bidmp.experiments.random_case": {"seed": 3},
        "bidmp.experiments.cell_key": {"shape": "Sshape", "demo": 0},
        "bidmp.experiments.summary_rows": {"rows": [], "metric": "rmse"},
        "bidmp.experiments.summary_markdown": {"rows": [], "protocol": {}},
        "bidmp.scene.SceneChecker": {"scene": scenario.scene, "chosen": np.arange(3)},
        "bidmp.scene.Proximity": {"scene": scenario.scene},
        "bidmp.scene.random_field": {
            "rng": np.random.default_rng(0),
            "start": DEMO[0],
            "goal": DEMO[-1],
            "tool": {"radius": 5.0, "length": 50.0},
            "margin": 1.0,
        },
        "bidmp.SceneAvoidance": {"scene": scenario.scene},
        "bidmp.Tool": {"radius": 5.0, "length": 50.0},
        "bidmp.demonstrations.kinesthetic_recording": {"via": DEMO[[0, 30, 59]]},
        "bidmp.demonstrations.recording": {"name": "operator1_nut3"},
        "bidmp.demonstrations.recording_path": {"name": "operator1_nut3"},
        "bidmp.demonstrations.prepare_poses": {"poses": POSES, "t": TIMES},
        "bidmp.prepare": {"y": DEMO, "t": TIMES},
        "bidmp.sim.Hold": {"joint": 2, "start": 0.5},
        "bidmp.sim.GoalUpdate": {"time": 0.5, "offset": (0.0, 0.0, 1.0)},
        "bidmp.sim.RobotModel": {
            "name": "x",
            "urdf": "franka_panda/panda.urdf",
            "flange": "panda_link8",
            "limits": _panda_limits(),
            "rest": (0.0,) * 7,
            "effort": (87.0,) * 7,
        },
    }


def _fr3_stream() -> np.ndarray:
    """A smooth 1 kHz rest-to-rest joint move of the FR3 (200 commands), within its limits."""
    s = np.linspace(0.0, 1.0, 200)[:, None]
    start = np.array([0.0, -0.4, 0.0, -2.0, 0.0, 1.9, 0.8])
    return start + 0.01 * (10 * s**3 - 15 * s**4 + 6 * s**5)


def _panda_limits():
    from bidmp.sim.robots import PANDA

    return PANDA


def _fitting(cls, fit_args: tuple):
    """A function of ``cls``'s parameters that builds the estimator and fits it to ``fit_args``:
    where scikit-learn's conventions validate parameters."""

    def fit(**params):
        return cls(**params).fit(*fit_args)

    fit.__signature__ = inspect.signature(cls)
    return fit


def phase_args_rhythmic() -> dict:
    return {"n_steps": 60, "step": 0.01, "tau": 1.0, "samples": np.arange(5.0), "span": 1.1}


def _estimators():
    from bidmp.baselines import TPGMM, GMMRegressor
    from bidmp.incremental import BLS

    rng = np.random.default_rng(1)
    return [
        ("DMP", bidmp.DMP, (DEMO, TIMES)),
        ("CartesianDMP", bidmp.CartesianDMP, (POSES, TIMES)),
        ("BiDMP", bidmp.BiDMP, (DEMO,)),
        ("CartesianBiDMP", bidmp.CartesianBiDMP, (POSES, TIMES)),
        ("BLS", BLS, (rng.normal(size=(40, 3)), rng.normal(size=(40, 2)))),
        ("GMMRegressor", GMMRegressor, (DEMO,)),
        ("TPGMM", TPGMM, (DEMO,)),
        ("RhythmicDMP", bidmp.primitives.RhythmicDMP, (PERIODIC, PERIODIC_TIMES)),
        ("RhythmicPoseDMP", bidmp.primitives.RhythmicPoseDMP, (PERIODIC_POSES, PERIODIC_TIMES)),
        ("ProMP", bidmp.primitives.ProMP, ([DEMO, DEMO[::-1]],)),
        ("ProDMP", bidmp.primitives.ProDMP, ([DEMO, DEMO[::-1]],)),
        ("MultiDMP", bidmp.primitives.MultiDMP, ([DEMO, DEMO * 1.1],)),
    ]


def _instances(tmp: Path):
    """(owner, instance, valid arguments of its methods) for the objects the library hands out;
    a model's ``from_state`` gets the model-file form its own ``to_state`` gives."""
    for owner, instance, args in _plain_instances(tmp):
        if hasattr(instance, "to_state"):
            meta, arrays = instance.to_state()
            args = {**args, "meta": meta, "arrays": arrays}
        yield owner, instance, args


def _plain_instances(tmp: Path):
    from bidmp.baselines import TPGMM, GMMRegressor
    from bidmp.incremental import BLS
    from bidmp.primitives import (
        ConstantAcceleration,
        DelayedGoal,
        ExponentialPhase,
        GaussianBasis,
        PhaseGate,
        PhaseStopping,
        StepIntegrator,
    )
    from bidmp.scene import Proximity, Scene
    from bidmp.tasks import Contract, Repairer, methods

    rng = np.random.default_rng(2)
    dmp = bidmp.DMP(n_kernels=20).fit(DEMO, TIMES, units="mm")
    pose = bidmp.CartesianDMP(bidmp.DMP(n_kernels=20)).fit(POSES, TIMES)
    model = bidmp.BiDMP(bidmp.DMP(n_kernels=20).fit(DEMO)).learn(DEMO + [0.0, 40.0, 0.0])
    pose_model = (
        bidmp.CartesianBiDMP().fit(POSES, TIMES).learn(POSES + [0.0, 40.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    )
    scene = Scene.from_dict(
        {
            "tool": {"radius": 5.0, "length": 50.0},
            "margin": 1.0,
            "parts": [
                {
                    "type": "cylinder",
                    "label": "post",
                    "at": [200.0, 0.0, 0.0],
                    "radius": 5.0,
                    "height": 50.0,
                },
                {
                    "type": "box",
                    "label": "beam",
                    "at": [50.0, 0.0, 120.0],
                    "size": [10.0, 80.0, 10.0],
                },
            ],
        }
    )
    scenario = bidmp.tasks.load("nut-unscrewing")
    contract = Contract.of(scenario)
    X = rng.normal(size=(40, 3))
    bls = BLS().fit(X, rng.normal(size=(40, 2)))
    task = methods.Task(demonstration=DEMO, goals=DEMO[-2:])
    dmp_method = methods.get("dmp")
    method_model, _ = dmp_method.fit(task)
    goal_args = {
        "gate": 0.5,
        "phase": 0.5,
        "step": 0.01,
        "tau": 1.0,
        "exact": True,
        "n_train": 60,
        "dt": 0.01,
    }
    yield (
        "DMP",
        dmp,
        {
            "phase": np.linspace(1.0, 0.05, 60),
            "goals": DEMO[-1] + np.zeros((3, 3)),
            "y": DEMO,
            "forcing_target:y": dmp.training_trajectory(DEMO),
        },
    )
    yield "CartesianDMP", pose, {"goal": POSES[-1], "start": POSES[0]}
    yield (
        "BiDMP",
        model,
        {
            "goal": DEMO[-1] + [0.0, 40.0, 0.0],
            "y_dn": DEMO + [0.0, 20.0, 0.0],
            "forcing_increment": np.zeros((model.dmp.n_train_, 3)),
            "phase": np.linspace(1.0, 0.05, 60),
        },
    )
    yield (
        "CartesianBiDMP",
        pose_model,
        {"goal": POSES[-1], "start": POSES[0], "poses": POSES + [0.0, 20.0, 0.0, 0, 0, 0, 0]},
    )
    yield "BLS", bls, {"X": X, "n": 5}
    yield "GMMRegressor", GMMRegressor(n_components=3).fit(DEMO), {"goal": None}
    yield "TPGMM", TPGMM(n_components=3).fit(DEMO), {"goal": DEMO[-1] + 5.0}
    yield (
        "Scene",
        scene,
        {
            "part": "post",
            "label": "post",
            "tool": bidmp.Tool(4.0, 40.0),
            "targets": {"post": [200.0, 0.0, 50.0]},
            "solid": scene.solids[0],
            "data": scene.to_dict(),
            "trajectory": DEMO,
            "offset": np.zeros(3),
        },
    )
    yield "SceneChecker", scene.checker(), {"a": DEMO[:-1], "b": DEMO[1:]}
    yield (
        "PoseChecker",
        scene.pose_checker(margin=2.0),
        {"point": DEMO[5], "rotation": Rotation.from_euler("x", 170, degrees=True).as_matrix()},
    )
    from bidmp.sim import ArmGeometry
    from bidmp.sim.robots import PANDA_MODEL

    arm = ArmGeometry(PANDA_MODEL, 0.0125, 0.1, [0.0, -0.45, 0.0], 90.0)
    rest = np.array(PANDA_MODEL.rest)
    yield (
        "ArmGeometry",
        arm,
        {
            "q": rest,
            "point": [0.0, 0.0, 0.3],
            "frame": [1.0, 0.0, 0.0, 0.0],
            "seed": rest,
            "scene": scenario.scene,
            "unit": 1e-3,
            "margin": 0.003,
        },
    )
    yield (
        "ArmSpace",
        arm.space(scenario.scene, 1e-3, margin=0.003),
        {"q": rest, "a": rest, "b": rest + 0.1},
    )
    yield "Proximity", Proximity(scene), {"point": DEMO[5], "within": 20.0}
    yield "Solid", scene.solids[0], {"centre": np.zeros(3), "rotation": np.eye(3)}
    yield (
        "SceneAvoidance",
        bidmp.SceneAvoidance(scene),
        {"stepper": dmp.stepper(), "trajectory": dmp.trajectory()},
    )
    yield "DMPStepper", dmp.stepper(), {"dt": 0.01, "goal": DEMO[-1] + 5.0}
    yield (
        "DMPSystem",
        dmp.system_,
        {"goal": DEMO[-1] + 5.0, "goals": DEMO[-3:], "phase": [0.2, 0.5], "tau": 1.5, "step": 0.01},
    )
    yield "DMPSettings", dmp.settings(), {"tau": 1.5, "estimator": bidmp.DMP(n_kernels=10)}
    yield "PoseStepper", pose.stepper(), {"dt": 0.01, "pose": POSES[-1]}
    yield "Trajectory", dmp.trajectory(), {}
    yield "PoseTrajectory", pose.trajectory(), {}
    from bidmp.primitives import AdaptiveOscillator, RhythmicDMP, RhythmicPhase, VonMisesBasis

    rhythmic = RhythmicDMP(n_kernels=12).fit(PERIODIC, PERIODIC_TIMES)
    rhythm_args = {"cycles": 1.0, "dt": 0.01, "phase": np.linspace(0.0, 6.0, 7)}
    yield "RhythmicDMP", rhythmic, rhythm_args
    promp = bidmp.primitives.ProMP(n_basis=8).fit([DEMO, DEMO * 1.05, DEMO[::-1]])
    yield (
        "ProMP",
        promp,
        {"phase": [0.0, 1.0], "y": DEMO[[0, -1]], "n_samples": 3, "dt": 0.05},
    )
    prodmp = bidmp.primitives.ProDMP(n_basis=8).fit([DEMO, DEMO * 1.05, DEMO[::-1]])
    yield (
        "ProDMP",
        prodmp,
        {
            "start": DEMO[0],
            "goal": DEMO[-1],
            "starts": DEMO[:2],
            "goals": DEMO[-2:],
            "times": [0.0, 0.5],
            "values": DEMO[[5]],
            "end": DEMO[-1],
            "condition:times": [0.5],
            "cov": 0.0,
        },
    )
    yield "ProDMPBasis", prodmp.basis_, {"times": [0.0, 0.5], "start_time": 0.0}
    multi = bidmp.primitives.MultiDMP(bidmp.DMP(n_kernels=10)).fit([DEMO, DEMO * 1.05])
    yield "MultiDMP", multi, {"goal": DEMO[-1] + 5.0, "n_samples": 2}
    pose_rhythm = bidmp.primitives.RhythmicPoseDMP(n_kernels=12).fit(PERIODIC_POSES, PERIODIC_TIMES)
    yield "RhythmicPoseDMP", pose_rhythm, {"cycles": 1.0, "dt": 0.01, "anchor": [1.0, 2.0, 3.0]}
    yield (
        "RhythmicStepper",
        rhythmic.stepper(),
        {"dt": 0.01, "frequency": 1.2, "amplitude": 0.5, "anchor": [1.0, 2.0]},
    )
    yield "AdaptiveOscillator", AdaptiveOscillator(1.0, 2), {"y": [1.0, 2.0], "dt": 0.01}
    yield "RhythmicPhase", RhythmicPhase(), {**phase_args_rhythmic(), "phase": 0.5}
    yield (
        "VonMisesBasis",
        VonMisesBasis(10),
        {
            "canonical": RhythmicPhase(),
            "n_steps": 60,
            "step": 0.01,
            "phase": np.linspace(0.0, 6.0, 20),
            "row:phase": 0.5,
            "centres": VonMisesBasis(10).place(RhythmicPhase(), 1, 1.0)[0],
            "widths": VonMisesBasis(10).place(RhythmicPhase(), 1, 1.0)[1],
        },
    )
    yield "PhaseGate", PhaseGate(2.0), goal_args
    yield "DelayedGoal", DelayedGoal(2.0), goal_args
    phase_args = {"n_steps": 60, "step": 0.01, "tau": 1.0, "samples": np.arange(5.0), "span": 1.1}
    yield (
        "ExponentialPhase",
        ExponentialPhase(4.0, exact=False),
        {**phase_args, "phase": 0.5, "as_phase:phase": [0.5, 0.2]},
    )
    yield (
        "GaussianBasis",
        GaussianBasis(10),
        {
            "canonical": ExponentialPhase(4.0),
            "n_steps": 60,
            "step": 0.01,
            "phase": np.linspace(1.0, 0.05, 20),
            "row:phase": 0.5,
            "centres": dmp.centres_,
            "widths": dmp.widths_,
        },
    )
    yield (
        "ProgressGate",
        dmp.goal_system(),
        {**goal_args, "on_grid:phase": np.linspace(1.0, 0.05, 60), "n_train": dmp.n_train_},
    )
    yield (
        "StepIntegrator",
        StepIntegrator(25.0, 6.25, 1.0, True),
        {"y": np.zeros(3), "z": np.zeros(3)},
    )
    yield "PhaseStopping", PhaseStopping(0.5), {"y": DEMO[0], "y_measured": DEMO[0] + 1.0}
    yield "ConstantAcceleration", ConstantAcceleration(np.ones(3)), {}
    yield (
        "Contract",
        contract,
        {
            "path": scenario.demonstration,
            "target": scenario.targets["3"],
            "label": "3",
            "scenario": scenario,
        },
    )
    yield (
        "Repairer",
        Repairer(contract, scenario.demonstration),
        {"goal": scenario.targets["3"], "axis": None, "exclude": ["3"], "model": dmp},
    )
    yield "JobSpec", scenario.job, {"index": 1}
    yield "Scenario", scenario, {"label": "3"}
    yield (
        "Method",
        dmp_method,
        {
            "model": method_model,
            "goal": DEMO[-1] + 5.0,
            "goals": DEMO[-1] + np.zeros((3, 3)),
            "duration": 1.0,
            "coupling": 0.0,
            "kinds": (bidmp.DMP,),
            "what": "a fitted DMP",
        },
    )
    yield "Task", task, {}
    from bidmp.extension import extend_demonstration

    yield (
        "ExtendedDemonstration",
        extend_demonstration(DEMO, DEMO[-1] + [150.0, 0.0, 0.0], seed=0),
        {"dmp": dmp},
    )
    from bidmp.sim import KinematicCell

    ideal = KinematicCell(scenario.scene)
    rest = np.array(ideal.rest)
    yield (
        "KinematicCell",
        ideal,
        {
            "q": rest,
            "point_m": ideal.fk(rest),
            "seed": rest,
            "path": scenario.demonstration[::20],
            "plan": ideal.plan(scenario.demonstration[::20]),
            "t": 0.5,
            "focus": np.zeros(3),
            "width": 64,
            "height": 48,
            "solids": [],
            "label": "1",
            "mass": 0.005,
            "seconds": 0.1,
        },
    )
    try:
        from bidmp.sim import RobotCell
    except ImportError:
        return
    cell = RobotCell(scenario.scene)
    q = np.array(cell.model.rest, dtype=float)
    yield (
        "RobotCell",
        cell,
        {
            "q": q,
            "point_m": np.array([0.1, -0.1, 0.2]),
            "seed": q,
            "path": scenario.demonstration[::20],
            "plan": cell.plan(scenario.demonstration[::20]),
            "exclude": [],
            "t": 0.5,
            "focus": np.zeros(3),
            "width": 64,
            "height": 48,
            "solids": [],
            "label": "1",
            "mass": 0.005,
            "seconds": 0.01,
        },
    )


def _only(function, names: tuple, fixed: dict):
    """``function`` called with ``fixed`` and the arguments ``names`` alone (what the sweep
    changes): its signature is theirs."""

    def call(**given):
        return function(**fixed, **given)

    call.__signature__ = inspect.Signature(
        [inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY) for name in names]
    )
    return call


def _wrong_objects(tmp: Path):
    """The writers', plots' and viewer's object arguments (reports, results, layers), each swept
    with wrong objects alone (the sweep's nasty values: None, object(), text, arrays, nested
    data ...): a wrong object is refused by name before anything is drawn or written. Their valid
    calls draw and write; their own tests make them."""
    from bidmp import experiments, plotting, sim, tasks
    from bidmp.plotting import viewer

    out = tmp / "wrong-objects"
    layers = viewer.ViewLayers(title="t", units="mm", demonstration=np.zeros((2, 3)))
    report = sim.SimReport(None, {}, np.zeros(3), 0.0, False)  # an empty simulation: no motions
    cases = [
        ("write_report", tasks.write_report, ("report",), {"out": out}),
        ("write_sim_report", sim.write_sim_report, ("report",), {"out": out}),
        ("write_job_report", sim.write_job_report, ("report",), {"out": out}),
        (
            "write_job_commands",
            sim.write_job_commands,
            ("report",),
            {"folder": out / "commands", "joint_names": ["j1"]},
        ),
        ("write_results", experiments.write_results, ("result",), {"name": "x", "out": out}),
        ("plot_generalisation", plotting.plot_generalisation, ("result",), {"path": out / "a.png"}),
        ("plot_extension", plotting.plot_extension, ("extension",), {"path": out / "b.png"}),
        ("plot_prm_comparison", plotting.plot_prm_comparison, ("comparisons",), {"path": out / "c.png"}),
        ("plot_incremental", plotting.plot_incremental, ("results",), {"path": out / "d.png"}),
        ("plot_targets_top_view", plotting.plot_targets_top_view, ("report",), {"path": out / "e.png"}),
        ("plot_error_vs_distance", plotting.plot_error_vs_distance, ("report",), {"path": out / "f.png"}),
        ("plot_scenario_3d", plotting.plot_scenario_3d, ("report",), {"path": out / "g.png"}),
        ("layers_from_report", plotting.layers_from_report, ("report",), {}),
        ("add_robot_motions", plotting.add_robot_motions, ("sim_report",), {"layers": layers}),
        ("add_robot_motions", plotting.add_robot_motions, ("layers",), {"sim_report": report}),
        ("view_figure", viewer.view_figure, ("layers",), {}),
        ("write_view", viewer.write_view, ("layers",), {"path": out / "v.html"}),
        ("save_layers", viewer.save_layers, ("layers",), {"path": out / "v.npz"}),
    ]  # fmt: skip
    for name, function, names, fixed in cases:
        yield f"{name}(wrong {names[0]})", _only(function, names, fixed), dict.fromkeys(names)


def _use(estimator):
    """What a fitted estimator of each kind is used for, as a call of no arguments."""
    for method, args in (
        ("rollout", ()),
        ("predict", (np.random.default_rng(1).normal(size=(5, 3)),)),
        ("trajectory", (1.0,)),
        ("mean", ()),
    ):
        if hasattr(estimator, method):
            bound = getattr(estimator, method)
            return lambda: bound(*args)
    raise AssertionError(type(estimator).__name__)


def _after_set_params(cls, fit_args: tuple):
    """A function of ``cls``'s parameters that sets them on an estimator *already fitted* with its
    defaults and uses it without fitting again (``set_params`` is how scikit-learn's tools change
    a fitted estimator): every parameter is checked where it is used, not only in ``fit``."""
    import copy

    fitted = cls().fit(*fit_args)

    def use(**params):
        estimator = copy.deepcopy(fitted)
        estimator.set_params(**params)
        return _use(estimator)()

    use.__signature__ = inspect.signature(cls)
    return use


def targets(tmp: Path):
    """(label, callable, valid arguments) of everything the sweep calls."""
    overrides = _package_overrides(tmp)
    for label, function in packages_entry_points():
        yield label, function, overrides.get(label, {})
    for owner, cls, fit_args in _estimators():
        yield f"{owner}(...).fit", _fitting(cls, fit_args), {}
        yield f"{owner}.set_params(...) then used", _after_set_params(cls, fit_args), {}
    yield from _wrong_objects(tmp)
    yield from _hostile_urdfs(tmp)
    yield from _damaged_data(tmp)
    yield from odd_inputs(tmp)
    for owner, instance, special in _instances(tmp):
        for name, member in inspect.getmembers(type(instance)):
            label = f"{owner}.{name}"
            if (
                name.startswith("_")
                or not callable(member)
                or isinstance(member, type)
                or name in SKIPPED
                or label in SKIPPED_METHODS
                or name in ("fit", "learn", "set_params")
            ):
                continue
            # "method:argument" keys give one method's argument a value of its own
            own = {key: value for key, value in special.items() if ":" not in key}
            own.update(
                {
                    key.split(":", 1)[1]: value
                    for key, value in special.items()
                    if key.startswith(f"{name}:")
                }
            )
            yield label, getattr(instance, name), own


_ARM = Path(__file__).resolve().parent / "data" / "tm5_like" / "tm5_like.urdf"


def hostile_urdfs(folder: Path, seed: int = 0, mutations: int = 24) -> list:
    """(label, path) of robot files with one defect each, written into ``folder``: the planted
    ones of tests/sim/test_hostile_urdf.py and more a file may carry (XML entities that expand or
    read a file, nesting 100 000 deep, bytes that are no text, an empty file, a joint without a
    child, an unknown joint type, limits upside down, a zero axis, a mesh linked to a system file
    or a FIFO, 20 000 links), then ``mutations`` random ones (seeded): a number replaced by NaN,
    1e308, -1e308 or text, a line dropped, a tag cut short."""
    import os
    import random

    text = _ARM.read_text()
    folder.mkdir(parents=True, exist_ok=True)
    for mesh in _ARM.parent.iterdir():
        if mesh.suffix.lower() in (".stl", ".obj", ".dae") and not (folder / mesh.name).exists():
            (folder / mesh.name).write_bytes(mesh.read_bytes())
    cases = {
        "billion laughs": text.replace(
            "<robot",
            '<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">'
            '<!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;"><!ENTITY d "&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;">'
            '<!ENTITY e "&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;"><!ENTITY f "&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;">'
            "]>\n<robot",
            1,
        ).replace('name="base_link"', 'name="&f;"', 1),
        "external entity": text.replace(
            "<robot", '<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n<robot', 1
        ).replace('name="link2"', 'name="&x;"', 1),
        "nested 100 000 deep": text.replace(
            "</robot>", "<a>" * 100_000 + "</a>" * 100_000 + "</robot>"
        ),
        "empty file": "",
        "not XML": "solid arm\nendsolid\n",
        "no child": text.replace('<child link="link2"/>', "", 1),
        "unknown joint type": text.replace('type="revolute"', 'type="teleport"', 1),
        "limits upside down": text.replace('lower="-', 'upper="-', 1),
        "zero axis": text.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>', 1),
        "20 000 links": text.replace(
            "</robot>", "".join(f'<link name="extra{i}"/>' for i in range(20_000)) + "</robot>"
        ),
    }
    out = []
    for label, body in cases.items():
        path = folder / f"{label.replace(' ', '_')}.urdf"
        path.write_text(body)
        out.append((f"URDF: {label}", path))
    binary = folder / "binary.urdf"
    binary.write_bytes(b"\xff\xfe\x00<robot>\x00\x9c")
    out.append(("URDF: no text", binary))
    meshes = []
    link = folder / "passwd.stl"
    if not link.exists():
        link.symlink_to("/etc/passwd")
    meshes.append(("mesh linked to a system file", "passwd.stl"))
    fifo = folder / "pipe.stl"
    if not fifo.exists():
        os.mkfifo(fifo)
    meshes.append(("mesh a FIFO", "pipe.stl"))
    for label, name in meshes:
        path = folder / f"{label.replace(' ', '_')}.urdf"
        path.write_text(
            text.replace(
                '<cylinder radius="0.06" length="0.145200"/>', f'<mesh filename="{name}"/>', 1
            )
        )
        out.append((f"URDF: {label}", path))
    rng = random.Random(seed)
    numbers = [m for m in __import__("re").finditer(r"-?[0-9]+\.?[0-9]*(e-?[0-9]+)?", text)]
    lines = text.splitlines()
    for index in range(mutations):
        kind = rng.choice(["number", "line", "tag"])
        if kind == "number":
            m = rng.choice(numbers)
            body = (
                text[: m.start()]
                + rng.choice(["nan", "1e308", "-1e308", "abc", "inf"])
                + text[m.end() :]
            )
        elif kind == "line":
            drop = rng.randrange(len(lines))
            body = "\n".join(lines[:drop] + lines[drop + 1 :])
        else:
            cut = rng.randrange(len(text))
            body = text[:cut]
        path = folder / f"mutation{index}.urdf"
        path.write_text(body)
        out.append((f"URDF: random {kind} #{index}", path))
    return out


def _hostile_urdfs(tmp: Path):
    """``robot_model`` of a user's arm whose URDF is hostile (:func:`hostile_urdfs`): refused in
    one line naming the file, or an arm whose limits and rest are finite."""
    from bidmp.sim import robot_model

    folder = tmp / "hostile-urdfs"
    hostile = hostile_urdfs(folder)
    limits = {
        "lower": [-3.0] * 6,
        "upper": [3.0] * 6,
        "velocity": [3.0] * 6,
        "acceleration": [10.0] * 6,
        "jerk": [500.0] * 6,
    }

    def arm(urdf):
        urdf = str(urdf) if isinstance(urdf, Path) else urdf  # (anything else as given)
        model = robot_model({"urdf": urdf, "flange": "flange", "limits": limits}, folder)
        return {"rest": model.rest, "lower": model.limits.lower}

    arm.__signature__ = inspect.Signature(
        [inspect.Parameter("urdf", inspect.Parameter.KEYWORD_ONLY)]
    )
    yield "robot_model(hostile URDFs)", arm, {"urdf": _ARM, "nasty:urdf": hostile}


def damaged_copies(source: Path, folder: Path, damages: list) -> list:
    """(label, path) of copies of the data folder ``source`` in ``folder``, each with one file
    damaged as ``damages`` say — (label, file relative to the folder, its new content: bytes, or
    a function of the old bytes). The other files are linked, not copied."""
    import os
    import shutil

    out = []
    for index, (label, relative, content) in enumerate(damages):
        copy = folder / f"copy{index}"
        if not copy.exists():
            shutil.copytree(source, copy, copy_function=os.symlink)
            target = copy / relative
            old = target.read_bytes()
            target.unlink()
            target.write_bytes(content(old) if callable(content) else content)
        out.append((f"damaged copy: {label}", copy))
    return out


def _damaged_data(tmp: Path):
    """The CLFD loader reading damaged copies of its data folder (a file truncated, emptied,
    garbled, its member gone): refused in one line naming the file; the intact copy reads."""
    import io
    import os
    import shutil

    from bidmp.experiments.clfd import clfd_tasks
    from bidmp.experiments.clfd import data as clfd_data

    def npz(**arrays) -> bytes:
        out = io.BytesIO()
        np.savez(out, **arrays)
        return out.getvalue()

    lasa, pose = "LASA/lasa_numpy/task_x3_y3.npz", "robottasks/pos_ori/openbox.npy"
    damages = [
        ("npz truncated", lasa, lambda old: old[: len(old) // 2]),
        ("npz emptied", lasa, b""),
        ("npz garbled", lasa, bytes(range(256)) * 8),
        ("npz without t", lasa, npz(pos=np.zeros((7, 50, 2)))),
        ("npy truncated", pose, lambda old: old[:1000]),
        ("npy emptied", pose, b""),
        ("sequence garbled", "LASA/lasa_numpy_sequence_all.txt", b"\xff\xfe\x00 ../x"),
        ("names garbled", "LASA/lasa_names.json", b"{not json"),
    ]
    folder = tmp / "clfd-copies"
    intact = folder / "intact"
    if not intact.exists():
        shutil.copytree(clfd_data.DATA, intact, copy_function=os.symlink)

    def both(folder):
        return {
            dataset: len(clfd_tasks(dataset, folder=folder)) for dataset in ("lasa", "robottasks")
        }

    both.__signature__ = inspect.Signature(
        [inspect.Parameter("folder", inspect.Parameter.KEYWORD_ONLY)]
    )
    damaged = damaged_copies(clfd_data.DATA, folder, damages)
    yield "clfd_tasks(damaged copies)", both, {"folder": intact, "nasty:folder": damaged}


# -- the "nothing silently wrong" campaign's input families ------------------------------------------
# Each reader below is wrapped with what every file of its family must give: read to the numbers
# written, or refused saying why. A file read wrong, read where it must be refused, or refused
# where it reads raises AssertionError: the sweep's internal error, a defect.


def _key(value):
    """An odd input as the expectations name it: a path's text, a list of names as a tuple."""
    if isinstance(value, (str, Path)):
        return str(value)
    if isinstance(value, (list, tuple)) and all(isinstance(item, str) for item in value):
        return tuple(value)
    return None


def _judged(function, argument: str, expected: dict, fixed: dict | None = None):
    """``function`` of ``argument`` alone (``fixed`` besides): for an input ``expected`` names,
    ("reads", check) or ("refused", words the refusal holds) is enforced (module comment)."""
    fixed = fixed or {}

    def call(**given):
        want = expected.get(_key(given[argument]))
        try:
            result = function(**fixed, **given)
        except (ValueError, TypeError) as exc:
            if want is not None and want[0] == "reads":
                raise AssertionError(f"refused an input that reads: {exc}") from None
            if want is not None and want[1] not in str(exc):
                raise AssertionError(f"refused without saying {want[1]!r}: {exc}") from None
            raise
        if want is not None:
            assert want[0] == "reads", f"{_key(given[argument])}: read, but it must be refused"
            want[1](result)
        return result

    call.__signature__ = inspect.Signature(
        [inspect.Parameter(argument, inspect.Parameter.KEYWORD_ONLY)]
    )
    return call


def _reads(values, names=None, repeated=()):
    """The check of a recording that must read: these numbers (and names, dropped stamps)."""

    def check(recording):
        np.testing.assert_array_equal(recording.values, values)
        assert names is None or list(recording.names) == list(names), recording.names
        assert tuple(recording.repeated) == tuple(repeated), recording.repeated

    return check


_STAMP0 = 1_700_000_000_000_000_000


def _joint_bag(path: Path, ros: int, storage: str, messages) -> Path:
    """A ``/joint_states`` bag written by rosbags: (stamp ns, names, positions) per message."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC if ros == 1 else Stores.ROS2_HUMBLE)
    if ros == 1:
        from rosbags.rosbag1 import Writer

        writer, serialize = Writer(path), store.serialize_ros1
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer

        plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
        writer, serialize = Writer(path, version=9, storage_plugin=plugin), store.serialize_cdr
    types = store.types
    with writer:
        connection = writer.add_connection(
            "/joint_states", "sensor_msgs/msg/JointState", typestore=store
        )
        for ns, names, positions in messages:
            header = types["std_msgs/msg/Header"](
                **({"seq": 0} if ros == 1 else {}),
                stamp=types["builtin_interfaces/msg/Time"](
                    sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000
                ),
                frame_id="",
            )
            message = types["sensor_msgs/msg/JointState"](
                header=header,
                name=list(names),
                position=np.asarray(positions, dtype=float),
                velocity=np.zeros(0),
                effort=np.zeros(0),
            )
            writer.write(connection, ns, serialize(message, connection.msgtype))
    return path


def odd_bags(folder: Path) -> tuple[list, dict]:
    """(label, path) of joint-state bags as drivers and loggers get them wrong or odd, in ROS 1,
    ROS 2 MCAP and ROS 2 SQLite, and what ``read_bag(path, joints=True)`` must give for each."""
    folder.mkdir(parents=True, exist_ok=True)
    names = ["j0", "j1", "j2"]
    q = np.column_stack([np.linspace(0.0, 0.4, 12) * k for k in (1.0, -2.0, 3.0)]) + 0.1
    stamps = [_STAMP0 + 4_000_000 * k for k in range(12)]
    rng = np.random.default_rng(5)
    shuffled = [np.arange(3)] + [rng.permutation(3) for _ in range(11)]

    def plain(change=None):
        rows = [[ns, list(names), row.copy()] for ns, row in zip(stamps, q)]
        if change is not None:
            change(rows)
        return rows

    def at(index, names_there=None, positions=None):
        def change(rows):
            if names_there is not None:
                rows[index][1] = names_there
            if positions is not None:
                rows[index][2] = np.asarray(positions, dtype=float)

        return change

    tiny = np.arange(1.0, 13.0)[:, None] * np.array([1e-300, 2e-300, 5e-324])
    cases = {
        "joint order changing": (
            [
                (ns, [names[k] for k in order], row[order])
                for ns, row, order in zip(stamps, q, shuffled)
            ],
            ("reads", _reads(q, names)),
        ),
        "tiny positions (1e-300)": (
            [(ns, names, row) for ns, row in zip(stamps, tiny)],
            ("reads", _reads(tiny, names)),
        ),
        "short positions": (plain(at(6, positions=[0.1, 0.2])), ("refused", "2 positions")),
        "more positions than names": (
            plain(at(3, positions=[0.1, 0.2, 0.3, 0.4])),
            ("refused", "4 positions"),
        ),
        "NaN position": (plain(at(8, positions=[0.1, np.nan, 0.3])), ("refused", "NaN in j1")),
        "inf position": (plain(at(2, positions=[np.inf, 0.2, 0.3])), ("refused", "inf in j0")),
        "a joint named twice": (
            plain(at(5, names_there=["j0", "j1", "j0"])),
            ("refused", "twice"),
        ),
        "a joint missing later": (
            plain(at(9, names_there=["j0", "j1", "j9"])),
            ("refused", "no joint(s) j2"),
        ),
    }
    out, expected = [], {}
    for ros, storage, suffix in ((1, "", ".bag"), (2, "mcap", ""), (2, "sqlite3", "")):
        kind = "ROS 1" if ros == 1 else f"ROS 2 {storage}"
        for label, (messages, want) in cases.items():
            path = folder / f"{len(out)}{suffix}"
            if not path.exists():
                _joint_bag(path, ros, storage, messages)
            out.append((f"bag ({kind}): {label}", path))
            expected[str(path)] = want
    return out, expected


def _csv(path: Path, header: str, rows, first_lines=()) -> Path:
    path.write_text(
        "".join(f"{line}\n" for line in first_lines)
        + header
        + "\n"
        + "".join(",".join(repr(float(v)) for v in row) + "\n" for row in rows)
    )
    return path


def odd_recordings(folder: Path) -> tuple[list, dict]:
    """(label, path) of CSVs with a unit line, a name twice, gaps, tiny numbers or a repeated
    stamp, and what ``read_recording(path)`` must give for each."""
    folder.mkdir(parents=True, exist_ok=True)
    t = np.arange(30) * 0.01
    q = np.column_stack([np.linspace(0.0, 0.3, 30) * k for k in (1.0, -1.0)]) + 0.2
    joints = np.column_stack([t, q])
    tiny = np.column_stack([t, np.arange(1.0, 31.0)[:, None] * np.array([1e-300, 3e-300])])
    xyz = np.column_stack([t, q, q[:, 0] * 2.0])
    repeated = joints.copy()
    repeated[11, 0] = repeated[10, 0]
    gap = joints.copy()
    gap[7, 2] = np.nan
    cases = {
        "joints declared in m": ("t,j1,j2", joints, ["# units: m"], ("refused", "a length")),
        "joints declared in mm": ("t,j1,j2", joints, ["# units: mm"], ("refused", "a length")),
        "an unknown unit": ("t,j1,j2", joints, ["# units: furlong"], ("refused", "must be one of")),
        "joints declared in rad": ("t,j1,j2", joints, ["# units: rad"], ("reads", _reads(q))),
        "a joint named twice": ("t,j1,j1", joints, [], ("refused", "2 times")),
        "x named twice": ("t,x,y,x", xyz, [], ("refused", "2 times")),
        "x beside X(mm)": ("t,x,y,X(mm)", xyz, [], ("refused", "2 times")),
        "a NaN joint": ("t,j1,j2", gap, [], ("refused", "NaN")),
        "tiny joints (1e-300)": ("t,j1,j2", tiny, [], ("reads", _reads(tiny[:, 1:]))),
        "tiny positions (1e-300)": ("t,x,y", tiny, [], ("refused", "barely moves")),
        "still joints": (
            "t,j1,j2",
            np.column_stack([t, np.full((30, 2), 0.5)]),
            [],
            ("reads", _reads(np.full((30, 2), 0.5))),
        ),
        "a repeated stamp": (
            "t,j1,j2",
            repeated,
            [],
            ("reads", _reads(np.delete(q, 11, axis=0), repeated=((12, float(t[10])),))),
        ),
    }
    out, expected = [], {}
    for label, (header, rows, first, want) in cases.items():
        path = _csv(folder / f"{len(out)}.csv", header, rows, first)
        out.append((f"CSV: {label}", path))
        expected[str(path)] = want
    return out, expected


def odd_command_files(folder: Path) -> tuple[list, dict]:
    """(label, path) of 1 kHz FR3 joint-command files, and what ``bidmp verify`` must say."""
    folder.mkdir(parents=True, exist_ok=True)
    names = [f"fr3_joint{i}" for i in range(1, 8)]
    q = _fr3_stream()
    t = np.arange(len(q)) * 1e-3
    header = "t," + ",".join(names)
    repeated, gap = t.copy(), t.copy()
    repeated[100] = repeated[99]
    gap[120:] += 1e-3
    tiny = q[0] + np.arange(len(q))[:, None] * 1e-300  # (q[0] + 1e-300 is q[0]: a still stream)
    cases = {
        "declared in m": (header, t, q, ["# units: m"], ("refused", "a length")),
        "an unknown unit": (header, t, q, ["# units: furlong"], ("refused", "must be one of")),
        "a joint named twice": (
            header + ",fr3_joint1",
            t,
            np.column_stack([q, q[:, 0]]),
            [],
            ("refused", "2 times"),
        ),
        "still": (header, t, np.tile(q[0], (len(q), 1)), [], ("reads", "accepted")),
        "tiny steps (1e-300)": (header, t, tiny, [], ("reads", "accepted")),
        "a repeated stamp": (header, repeated, q, [], ("refused", "data row 101 repeats")),
        "a 2 ms gap": (header, gap, q, [], ("refused", "data rows 120 and 121 are 2 ms apart")),
    }
    out, expected = [], {}
    for label, (head, times, values, first, want) in cases.items():
        path = _csv(folder / f"{len(out)}.csv", head, np.column_stack([times, values]), first)
        out.append((f"commands: {label}", path))
        expected[str(path)] = want if want[0] == "refused" else ("reads", lambda code: None)
    return out, expected


def _verify(motion):
    """``bidmp verify MOTION --robot fr3`` as a call: exit 2's line raised as the ValueError it
    reports, any other exit returned (0 accepted, 3 rejected by the FCI's limits)."""
    import contextlib
    import io

    from bidmp.cli import main

    if not isinstance(motion, (str, Path)):  # a command line holds text: nothing else reaches it
        raise TypeError(f"motion must be a file name, got {type(motion).__name__}")
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(["verify", str(motion), "--robot", "fr3"])
        except SystemExit as exc:  # argparse's usage error (a name that reads as an option)
            code = exc.code
    lines = err.getvalue().strip().splitlines()[-1:] if code == 2 else []
    if code == 2:
        raise ValueError(lines[0] if lines else "verify: exit 2 without a line")
    assert code == 0 or code == 3, code
    return code


def odd_inputs(tmp: Path):
    """The input families that found the campaign's defects (odd bags, names twice, unit lines,
    tiny positive floats, repeated stamps), each reader judged on what each file must give."""
    from bidmp.io import read_bag, read_recording
    from bidmp.sim import match_joint_names

    # short folders and names: a refusal quotes the path, and the sweep's one line is 300 characters
    bags, bag_expected = odd_bags(tmp / "ob")
    yield (
        "read_bag(odd joint bags)",
        _judged(read_bag, "path", bag_expected, {"joints": True}),
        {"path": bags[0][1], "nasty:path": bags},
    )
    recordings, recording_expected = odd_recordings(tmp / "or")
    yield (
        "read_recording(odd CSVs)",
        _judged(read_recording, "path", recording_expected),
        {"path": recordings[3][1], "nasty:path": recordings},
    )
    commands, command_expected = odd_command_files(tmp / "oc")
    expected = {str(path): want for path, want in command_expected.items()}
    yield (
        "bidmp verify(odd command files)",
        _judged(_verify, "motion", expected),
        {"motion": commands[3][1], "nasty:motion": commands},
    )
    names = [f"fr3_joint{i}" for i in range(1, 8)]
    twice = [
        ("a name twice", [*names, "fr3_joint3"]),
        ("one name for another", [*names[:6], "fr3_joint1"]),
    ]
    yield (
        "match_joint_names(names twice)",
        _judged(
            match_joint_names,
            "names",
            {tuple(value): ("refused", "named 2 times") for _, value in twice},
            {"robot": "fr3"},
        ),
        {"names": names, "nasty:names": twice},
    )
