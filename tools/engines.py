"""The two physics engines checked against each other (``make engines``): PyBullet and MuJoCo on
the same arms, tasks and random users' cells, with pinocchio as a third opinion on the models.

1. The models: every built-in arm with the scenario's tool, the same URDF text in the three
   libraries; at random joint positions, velocities and accelerations, the tool's mouth by forward
   kinematics (PyBullet's planning copy, MuJoCo's model, pinocchio) and the joint torques by
   rigid-body inverse dynamics (PyBullet's ``calculateInverseDynamics`` with the URDF's inertias,
   MuJoCo's ``mj_inverse`` with the joints' damping and armature off, pinocchio's RNEA).
2. The built-in tasks: ``simulate`` of every method to every target, and the job, on both engines:
   the contract's verdicts (task success, within the limits, the contacts), the tracking errors'
   ratio, the parts removed.
3. The random users' cells of ``tests/tasks/test_random_user_cells.py`` (the same generator): the
   Bi-DMP motion to every target simulated, and the job on the first targets, on both engines.

Writes docs/results/engines.md and docs/results/engines.json. Usage::

    python tools/engines.py [--cells 20] [--samples 200] [--out docs/results]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
ARMS = ("panda", "fr3", "iiwa", "xarm6", "ur5")
FK_TOLERANCE = 1e-6  # m
ID_TOLERANCE = 1e-6  # N m
TRACKING_RATIO = 2.0


# -- 1. the models -------------------------------------------------------------------------------
def _cell(arm: str, backend: str = "mujoco"):
    """An arm with a 0.1 m tool at the origin, no parts (base frame = world frame)."""
    from bidmp.scene import Scene, Tool
    from bidmp.sim.robots import ROBOT_MODELS

    scene = Scene([], Tool(radius=0.02, length=0.1))
    from bidmp.sim.backend import get_backend

    return get_backend(backend)(scene, "m", (0.0, 0.0, 0.0), 0.0, ROBOT_MODELS[arm])


def _urdf(cell) -> str:
    from bidmp.sim.pybullet.world import _tool_urdf

    text = _tool_urdf(cell.model, 0.02, 0.1)
    return text[0] if isinstance(text, tuple) else text


def _pin_q(model, q: np.ndarray) -> np.ndarray:
    """pinocchio's configuration for joint angles ``q`` (a continuous joint is (cos, sin))."""
    out, k = [], 0
    for joint in model.joints[1:]:
        if joint.nq == 2:
            out += [np.cos(q[k]), np.sin(q[k])]
        else:
            out.append(q[k])
        k += 1
    return np.array(out)


def model_check(arm: str, samples: int, seed: int) -> dict:
    """The largest differences of forward kinematics (m) and inverse dynamics (N m) between the
    three libraries on ``arm``, over ``samples`` random states."""
    import mujoco
    import pinocchio as pin
    import pybullet as p

    cell = _cell(arm)
    rng = np.random.default_rng(seed)
    text = _urdf(cell)
    pin_model = pin.buildModelFromXML(text)
    pin_data = pin_model.createData()
    tcp_frame = pin_model.getFrameId("tcp")
    m = cell.m
    mj_model = m.__copy__()
    n = len(cell.arm)
    mj_model.dof_damping[:] = 0.0
    mj_model.dof_armature[:] = 0.0
    mj_model.dof_frictionloss[:] = 0.0
    mj_data = mujoco.MjData(mj_model)
    # PyBullet with the URDF's inertias (what pinocchio and MuJoCo read), and as the backend
    # loads it (no flag: Bullet puts a box's inertia round each link's collision shape)
    client = p.connect(p.DIRECT)
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "arm.urdf"
        path.write_text(text)
        body = p.loadURDF(
            str(path),
            useFixedBase=True,
            flags=p.URDF_USE_INERTIA_FROM_FILE,
            physicsClientId=client,
        )
        default = p.loadURDF(str(path), [2.0, 0.0, 0.0], useFixedBase=True, physicsClientId=client)
    p.setGravity(0, 0, -9.81, physicsClientId=client)
    lower, upper = np.array(cell.limits.lower), np.array(cell.limits.upper)
    velocity = np.array(cell.limits.velocity)
    acceleration = np.array(cell.limits.acceleration)
    fk = {"mujoco-pybullet": 0.0, "pinocchio-pybullet": 0.0, "mujoco-pinocchio": 0.0}
    inverse = {
        "mujoco-pinocchio": 0.0,
        "pybullet-pinocchio": 0.0,
        "pybullet as loaded-pinocchio": 0.0,
    }
    worst_joint = {}
    for _ in range(samples):
        q = rng.uniform(np.maximum(lower, -np.pi), np.minimum(upper, np.pi))
        qd = rng.uniform(-velocity, velocity)
        qdd = rng.uniform(-acceleration, acceleration)
        bullet = cell.forward(q)
        ours = cell.model_fk(q)
        pq = _pin_q(pin_model, q)
        pin.framesForwardKinematics(pin_model, pin_data, pq)
        third = np.array(pin_data.oMf[tcp_frame].translation)
        for key, (a, b) in {
            "mujoco-pybullet": (ours, bullet),
            "pinocchio-pybullet": (third, bullet),
            "mujoco-pinocchio": (ours, third),
        }.items():
            fk[key] = max(fk[key], float(np.max(np.abs(a - b))))
        tau_pin = np.array(pin.rnea(pin_model, pin_data, pq, qd, qdd))
        mj_data.qpos[:n], mj_data.qvel[:n], mj_data.qacc[:n] = q, qd, qdd
        mujoco.mj_inverse(mj_model, mj_data)
        tau_mj = mj_data.qfrc_inverse[:n].copy()
        tau_pb = np.array(
            p.calculateInverseDynamics(
                body, q.tolist(), qd.tolist(), qdd.tolist(), physicsClientId=client
            )
        )
        tau_default = np.array(
            p.calculateInverseDynamics(
                default, q.tolist(), qd.tolist(), qdd.tolist(), physicsClientId=client
            )
        )
        for key, value in {
            "mujoco-pinocchio": tau_mj,
            "pybullet-pinocchio": tau_pb,
            "pybullet as loaded-pinocchio": tau_default,
        }.items():
            gap = np.abs(value - tau_pin)
            if float(np.max(gap)) > inverse[key]:
                inverse[key] = float(np.max(gap))
                worst_joint[key] = int(np.argmax(gap)) + 1
    p.disconnect(client)
    cell.close()
    balanced = _balanced_links(text)
    return {
        "arm": arm,
        "samples": samples,
        "fk_m": fk,
        "id_Nm": inverse,
        "id_worst_joint": worst_joint,
        "balanced": balanced,
    }


def _balanced_links(text: str) -> list:
    """The links whose inertia tensor breaks the triangle inequality (MuJoCo's balanceinertia
    changes them; pinocchio and PyBullet take them as written)."""
    import xml.etree.ElementTree as ElementTree

    out = []
    for link in ElementTree.fromstring(text).iter("link"):
        inertia = link.find("inertial/inertia")
        if inertia is None:
            continue
        values = {k: float(inertia.get(k, 0.0)) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")}
        tensor = np.array(
            [
                [values["ixx"], values["ixy"], values["ixz"]],
                [values["ixy"], values["iyy"], values["iyz"]],
                [values["ixz"], values["iyz"], values["izz"]],
            ]
        )
        a, b, c = np.linalg.eigvalsh(tensor)
        if a + b < c - 1e-12:
            out.append(link.get("name"))
    return out


# -- 2. and 3. runs on both engines ------------------------------------------------------------------
def _sim_outcomes(scenario, methods, backend: str, targets=None) -> dict:
    from bidmp import sim

    report = sim.simulate(scenario, methods, targets=targets, workers=1, backend=backend)
    out = {}
    threshold = scenario.success_threshold
    for method, result in report.methods.items():
        for label, target in result.targets.items():
            out[f"{method}/{label}"] = {
                "ran": bool(target.ran),
                "success": bool(target.task_success(threshold)) if target.ran else False,
                "within_limits": bool(getattr(target, "within_limits", True)),
                "contacts": sorted(target.contacts) if target.contacts else [],
                "tracking_mm": float(target.tracking_error)
                if target.ran and target.tracking_error is not None
                else None,
                "reason": target.reason,
            }
    return out


def _job_outcomes(scenario, backend: str, targets=None) -> dict:
    from bidmp import sim

    report = sim.run_job(scenario, targets=targets, backend=backend)
    return {
        record.label: {
            "removed": bool(record.removed),
            "contacts": sorted(
                {c for phase in record.phases for c in (getattr(phase, "contacts", None) or ())}
            ),
            "reason": record.reason,
        }
        for record in report.targets
    }


def compare(name: str, scenario, methods, job_targets="all", sim_targets=None) -> dict:
    """Both engines on ``scenario``: the simulated motions and the job, and where they differ."""
    started = time.process_time()
    sims = {b: _sim_outcomes(scenario, methods, b, sim_targets) for b in ("pybullet", "mujoco")}
    jobs = {}
    if scenario.job is not None and job_targets is not None:
        targets = None if job_targets == "all" else job_targets
        jobs = {b: _job_outcomes(scenario, b, targets) for b in ("pybullet", "mujoco")}
    differences, ratios = [], []
    for key, bullet in sims["pybullet"].items():
        ours = sims["mujoco"][key]
        for field in ("ran", "success", "within_limits", "contacts"):
            if bullet[field] != ours[field]:
                differences.append(
                    f"sim {key}: {field} {bullet[field]} (PyBullet) / {ours[field]} (MuJoCo)"
                )
        a, b = bullet["tracking_mm"], ours["tracking_mm"]
        if a is not None and b is not None and min(a, b) > 0:
            ratios.append(max(a, b) / min(a, b))
            if max(a, b) / min(a, b) > TRACKING_RATIO and max(a, b) > 0.05:
                differences.append(f"sim {key}: tracking {a:.3f} / {b:.3f} mm")
    for label, bullet in jobs.get("pybullet", {}).items():
        ours = jobs["mujoco"][label]
        for field in ("removed", "contacts"):
            if bullet[field] != ours[field]:
                differences.append(
                    f"job {label}: {field} {bullet[field]} (PyBullet) / {ours[field]} (MuJoCo)"
                )
    removed = {b: sum(r["removed"] for r in jobs[b].values()) for b in jobs}
    return {
        "name": name,
        "robot": _arm_name(scenario),
        "motions": len(sims["pybullet"]),
        "successes": {b: sum(o["success"] for o in sims[b].values()) for b in sims},
        "tracking_ratio_max": max(ratios) if ratios else None,
        "tracking_mm": {
            b: [o["tracking_mm"] for o in sims[b].values() if o["tracking_mm"] is not None]
            for b in sims
        },
        "job_targets": len(jobs.get("pybullet", {})),
        "removed": removed,
        "differences": differences,
        "cpu_s": time.process_time() - started,
    }


def _arm_name(scenario) -> str:
    from bidmp.sim import robot_model

    return robot_model(scenario.robot, scenario.base_dir).name


def _user_cells(count: int):
    sys.path.insert(0, str(ROOT / "tests" / "tasks"))
    from test_random_user_cells import user_cell

    from bidmp.tasks import scenarios

    made, seed = [], 0
    while len(made) < count and seed < 10 * count:
        spec = user_cell(seed)
        seed += 1
        try:
            made.append((spec["name"], scenarios.from_dict(spec)))
        except scenarios.ScenarioError:  # drawn overlapping: refused (the tests' own rule)
            continue
    return made


# -- the report ------------------------------------------------------------------------------------
def _table_models(rows) -> list[str]:
    lines = [
        "| arm | FK MuJoCo-PyBullet m | FK pinocchio-PyBullet m | ID MuJoCo-pinocchio N m | "
        "ID PyBullet-pinocchio N m | ID PyBullet as the backend loads it N m | links MuJoCo rebalanced |",
        "|---|---|---|---|---|---|---|",
    ]
    loaded = "pybullet as loaded-pinocchio"
    for r in rows:
        fk, inv = r["fk_m"], r["id_Nm"]
        lines.append(
            f"| {r['arm']} | {fk['mujoco-pybullet']:.1e} | {fk['pinocchio-pybullet']:.1e} | "
            f"{inv['mujoco-pinocchio']:.1e} | {inv['pybullet-pinocchio']:.1e} | "
            f"{inv[loaded]:.2g} (joint {r['id_worst_joint'].get(loaded, '-')}) | "
            f"{', '.join(r['balanced']) or '-'} |"
        )
    return lines


def _table_runs(rows) -> list[str]:
    lines = [
        "| cell | arm | motions | successes PyBullet / MuJoCo | tracking mm PyBullet (median) | "
        "MuJoCo (median) | largest ratio | job targets | removed PyBullet / MuJoCo | differences |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        tp, tm = r["tracking_mm"]["pybullet"], r["tracking_mm"]["mujoco"]
        scale = r.get("mm_per_unit", 1.0)  # "tracking_mm" holds scene units: in mm here
        med = lambda v, scale=scale: f"{np.median(v) * scale:.3f}" if v else "-"  # noqa: E731
        ratio = "-" if r["tracking_ratio_max"] is None else f"{r['tracking_ratio_max']:.2f}"
        removed = (
            f"{r['removed'].get('pybullet', '-')} / {r['removed'].get('mujoco', '-')}"
            if r["job_targets"]
            else "-"
        )
        lines.append(
            f"| {r['name']} | {r['robot']} | {r['motions']} | {r['successes']['pybullet']} / "
            f"{r['successes']['mujoco']} | {med(tp)} | {med(tm)} | {ratio} | {r['job_targets']} | "
            f"{removed} | {len(r['differences'])} |"
        )
    return lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=20)
    parser.add_argument("--samples", type=int, default=200)
    parser.add_argument("--job-targets", type=int, default=2, help="job targets per cell")
    parser.add_argument(
        "--part",
        choices=("all", "models", "builtin", "cells", "report"),
        default="all",
        help="one part only, into engines-PART.json beside the report (make engines runs the "
        "built-in tasks and the cells in two processes, then 'report' writes engines.md)",
    )
    parser.add_argument("--out", default=str(ROOT / "docs" / "results"))
    args = parser.parse_args(argv)
    out = Path(args.out)
    parts = ("models", "builtin", "cells") if args.part in ("all", "report") else (args.part,)
    results = {}
    for part in parts:
        if args.part == "report":
            results[part] = json.loads((out / f"engines-{part}.json").read_text())
            continue
        started = time.perf_counter()
        results[part] = {"rows": RUNS[part](args), "seconds": time.perf_counter() - started}
        _write(out / f"engines-{part}.json", json.dumps(results[part], indent=1) + "\n")
    if args.part == "report":  # rows written before the arm was named: named again
        _name_arms(results)
    if set(results) == {"models", "builtin", "cells"}:
        _write(out / "engines.md", "\n".join(_report(results)) + "\n")
        print(f"wrote {out / 'engines.md'}")
    return 0


def _write(path: Path, text: str) -> None:
    from bidmp.io import atomic_write

    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_write(path, "w") as stream:
        stream.write(text)


def _models(args) -> list:
    return [model_check(arm, args.samples, seed) for seed, arm in enumerate(ARMS)]


def _builtin(args) -> list:
    """Every built-in task with a scene: the Bi-DMP motion to every target on both engines; the
    job on every target of the nut task and on the first ``--job-targets`` of the others."""
    from bidmp.tasks import scenarios

    rows = []
    for name in scenarios.builtin_names():
        scenario = scenarios.load(name)
        if scenario.scene is None:
            continue
        from bidmp.sim.job import job_targets

        labels = job_targets(scenario) if scenario.job is not None else []
        jobs = "all" if name == "nut-unscrewing" else labels[: args.job_targets]
        row = compare(name, scenario, ["bidmp"], job_targets=jobs)
        print(name, row["successes"], row["removed"], row["differences"][:5], flush=True)
        rows.append(row)
    return rows


def _cells(args) -> list:
    rows = []
    for name, scenario in _user_cells(args.cells):
        labels = list(scenario.targets)
        row = compare(name, scenario, ["bidmp"], job_targets=labels[: args.job_targets])
        print(name, row["successes"], row["removed"], row["differences"][:5], flush=True)
        rows.append(row)
    return rows


RUNS = {"models": _models, "builtin": _builtin, "cells": _cells}
_MM = {"mm": 1.0, "cm": 10.0, "m": 1000.0}


def _name_arms(results) -> None:
    """Each run's arm by its model's name (the scenario's robot options were written instead)."""
    from bidmp.tasks import scenarios

    cells = dict(_user_cells(len(results["cells"]["rows"])))
    for row in results["builtin"]["rows"]:
        row["robot"] = _arm_name(scenarios.load(row["name"]))
        row["mm_per_unit"] = _MM[scenarios.load(row["name"]).units]
    for row in results["cells"]["rows"]:
        row["robot"] = _arm_name(cells[row["name"]])
        row["mm_per_unit"] = _MM[cells[row["name"]].units]


def _report(results) -> list[str]:
    models, builtin, cells = (results[k]["rows"] for k in ("models", "builtin", "cells"))
    seconds = sum(results[k]["seconds"] for k in results)
    fk_worst = max(max(r["fk_m"].values()) for r in models)
    id_worst = {r["arm"]: r["id_Nm"]["mujoco-pinocchio"] for r in models}
    differences = [
        d for row in builtin + cells for d in (f"{row['name']}: {x}" for x in row["differences"])
    ]
    ratios = [
        r["tracking_ratio_max"] for r in builtin + cells if r["tracking_ratio_max"] is not None
    ]
    lines = [
        "# PyBullet and MuJoCo checked against each other",
        "",
        "`make engines` (tools/engines.py): the same URDFs, tasks and random users' cells on both "
        "engines, pinocchio as a third opinion on the models. Written by the tool; "
        f"{seconds:.0f} s of runs here (load average {os.getloadavg()[0]:.1f} when written).",
        "",
        "Both engines are sent the same joint commands: the MuJoCo backend plans on the PyBullet "
        "backend's kinematic copy of the arm, so the contract's verdicts on the commanded streams "
        "are the same by construction (a closed-loop stepper's commands follow the measured tool, "
        "and a job's next motion starts where the last ended: those differ with the physics). What "
        "the comparison measures is the physics: tracking, contacts, the parts' falls.",
        "",
        "## The models",
        "",
        f"Forward kinematics of the tool's mouth: at most {fk_worst:.1e} m between any two of the "
        f"three (tolerance {FK_TOLERANCE:g} m). Rigid-body inverse dynamics on the URDF's own "
        "inertial parameters, MuJoCo against pinocchio: "
        + ", ".join(f"{arm} {value:.1e}" for arm, value in id_worst.items())
        + f" N m (tolerance {ID_TOLERANCE:g} N m).",
        "",
        *_table_models(models),
        "",
        "Where they differ, and why:",
        "",
        "- *PyBullet as the backend loads it*: `loadURDF` without `URDF_USE_INERTIA_FROM_FILE` puts "
        "a box's inertia round each link's collision shape in place of the URDF's tensors; the "
        "masses and centres agree (gravity torques match) but acceleration torques do not. Loaded "
        "with the flag, PyBullet agrees with pinocchio and MuJoCo to rounding.",
        "- *Links MuJoCo rebalanced* (the xArm6's `link2` and `link3`): an inertia tensor breaking "
        "the triangle inequality (A + B >= C) is not a body's. Each library does its own thing "
        "with it: MuJoCo refuses it unless `balanceinertia` repairs it (the MuJoCo backend "
        "compiles with it on), PyBullet sets it to zero ('Bad inertia tensor properties, setting "
        "inertia to zero'), pinocchio takes it as written: three models of that arm, whose "
        "inverse dynamics differ by up to a few tenths of a N m. The URDF's numbers are the "
        "error; tracking and verdicts on that arm agree all the same (below).",
        "- The massless links (the Panda's `panda_link8`: mass 0, inertia 0.1 kg m² in "
        "pybullet_data's URDF; the tool's mouth): MuJoCo's default for a URDF fuses a link on a "
        "fixed joint into its parent and drops a massless one's inertia as it does: measured, "
        "the Panda's inverse dynamics then differ from pinocchio's by up to 3.3 N m (gravity "
        'torques alike to 3e-14). The MuJoCo backend compiles with `fusestatic="false"`: '
        "nothing is fused, nothing dropped (the table above).",
        "",
        "## The built-in tasks",
        "",
        "The Bi-DMP motion to every target simulated; the job on all 14 nuts of the nut task, on "
        "the first two targets of the others.",
        "",
        *_table_runs(builtin),
        "",
        f"## {len(cells)} random users' cells",
        "",
        "The Bi-DMP motion to every target simulated, the job on the first two targets "
        "(tests/tasks/test_random_user_cells.py's generator, seeds from 0, refused cells skipped).",
        "",
        *_table_runs(cells),
        "",
        "## Verdict",
        "",
        f"Largest tracking ratio between the engines: {max(ratios):.2f} (bound {TRACKING_RATIO:g})."
        if ratios
        else "No tracking errors to compare.",
        f"Differences in verdicts, contacts or parts removed: {len(differences)}.",
        "",
        *(f"- {d}" for d in differences),
    ]
    return lines


if __name__ == "__main__":
    sys.exit(main())
