"""What the job computes at each step is handed on: every move's commands reach its verdict,
each nut ends where its own drop put it (a bin cell of its own, read where it lies), every motion
of every target is written as a command file with the arm's own joint units, and a phase's
contacts (the arm's and a carried part's) reach it in the scene's unit, against the arm's own
limits. Several of everything: two tilted nuts on the ideal arm (its six joints, metres and
radians), two units, two arms. Expected values from the job's own numbers (the bin, the tool)
and closed forms, not from the code under test."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from bidmp import sim
from bidmp.sim.backend import JointLimits
from bidmp.sim.job_report import _phase, write_job_commands
from bidmp.sim.robots import PANDA
from bidmp.tasks import scenarios

SIX = JointLimits(
    lower=(-3.0,) * 6,
    upper=(3.0,) * 6,
    velocity=(1.0, 1.2, 1.4, 1.6, 1.8, 2.0),
    acceleration=(2.0, 2.5, 3.0, 3.0, 3.0, 3.0),
)


@pytest.fixture(scope="module")
def tilted_job():
    """The tilted pack with the flat task's job, nuts 3 and 4 on the ideal arm, recorded."""
    spec = json.loads(scenarios.builtin_text("nut-unscrewing-tilted"))
    spec["job"] = json.loads(scenarios.builtin_text("nut-unscrewing"))["job"]
    scenario = scenarios.from_dict(spec)
    return scenario, sim.run_job(scenario, targets=["3", "4"], backend="kinematic", record=True)


def test_every_move_of_every_target_is_judged_with_its_own_commands(tilted_job):
    scenario, report = tilted_job
    assert [target.label for target in report.targets] == ["3", "4"]
    for target in report.targets:
        assert target.removed, target.reason
        moved = [phase for phase in target.phases if phase.commands is not None]
        assert [phase.name for phase in moved] == ["approach", "unscrew", "retract", "drop"]
        for phase in moved:
            # the verdict took the commands: their peaks, from rest to rest, within the limits
            assert phase.verdict is not None and phase.verdict.limits is not None, phase.name
            assert phase.verdict.limits.within and phase.ok
            assert phase.peaks[0] == pytest.approx(phase.verdict.limits.velocity)
        # the approach of a pose target: the tool's frames judged too, turned onto the nut's axis
        approach = moved[0].verdict
        assert approach.engaged is True and approach.aligned is True
        assert approach.axis_deviation <= scenario.alignment_threshold
        # the drop is judged in the job's scene: the bin's walls are the parts nearest to it
        drop = moved[-1].verdict.clearance
        assert drop.part.startswith("bin"), drop.part


def test_each_nut_ends_in_a_bin_cell_of_its_own(tilted_job):
    """Where a nut lies is read after it fell (not where it started), inside the bin's walls
    (the job's bin: its floor's centre and inner size), and two nuts dropped one after the
    other lie a socket's width apart (the drop grid's cells), not on one another."""
    scenario, report = tilted_job
    floor, inner = (np.asarray(v, dtype=float) for v in scenario.job.bin)
    ends = []
    for target in report.targets:
        end = np.asarray(target.final_position, dtype=float)
        start = np.asarray(scenario.targets[target.label][:3], dtype=float)
        assert np.all(np.abs(end[:2] - floor[:2]) <= inner[:2] / 2.0), end
        assert floor[2] <= end[2] <= floor[2] + inner[2], end
        assert np.linalg.norm(end - start) > 50.0  # (it moved from its stud to the bin)
        ends.append(end)
    assert np.linalg.norm(ends[0][:2] - ends[1][:2]) >= scenario.scene.tool.radius


def test_every_motion_is_written_with_the_arms_own_joints_and_units(tilted_job, tmp_path):
    """Four motions a nut (approach, unscrew, retract, drop), two nuts: eight files, in order,
    each the commands of its phase; the ideal arm's carriage in metres and wrist in radians
    said on the first line (not '# units: rad')."""
    _, report = tilted_job
    files = write_job_commands(report, tmp_path)
    moved = [
        (target.label, phase)
        for target in report.targets
        for phase in target.phases
        if phase.commands is not None
    ]
    assert len(files) == len(moved) == 8
    units = dict(zip(report.joint_names, report.joint_units))
    assert set(units.values()) == {"m", "rad"}
    for path, (label, phase) in zip(files, moved):
        assert path.name.endswith(f"_{label}_{phase.name}.csv")
        first, header = path.read_text().splitlines()[:2]
        assert first == "# joint units: " + ", ".join(f"{n} {u}" for n, u in units.items())
        assert header == "t," + ",".join(report.joint_names)
        values = np.loadtxt(path, delimiter=",", skiprows=2)
        np.testing.assert_array_equal(values[:, 1:], phase.commands)


@pytest.mark.parametrize("limits", [SIX, PANDA], ids=["six-joint", "panda"])
@pytest.mark.parametrize("metres", [1e-3, 1.0], ids=["mm", "m"])
def test_a_phases_contacts_and_peaks_reach_it_in_the_scenes_unit_and_the_arms_limits(
    metres, limits
):
    """The arm's contacts (metres, from the backend) in the scene's unit, a carried part's
    (scene units already) beside them, the deeper of the two where both touched a part; the
    commands' peak against this arm's velocity limit (a minimum-jerk stroke: 1.875 A/T)."""
    tau = np.linspace(0.0, 1.0, 1501)[:, None]
    q0 = 0.5 * (np.asarray(limits.lower) + np.asarray(limits.upper))
    commands = np.repeat(q0[None], tau.shape[0], axis=0)
    commands[:, 0] += 0.5 * (10 * tau[:, 0] ** 3 - 15 * tau[:, 0] ** 4 + 6 * tau[:, 0] ** 5)
    run = SimpleNamespace(
        commands=commands,
        joint_velocities=np.zeros((200, limits.n_joints)),
        contacts={"post": 0.002, "bin": 0.0005},
    )
    plan = SimpleNamespace(duration=1.5)
    cell = SimpleNamespace(limits=limits, unit=metres)
    mm = 1e-3 / metres  # scene units per millimetre
    carried = {"post": 1.0 * mm, "plate": 0.7 * mm}
    phase = _phase("drop", run, plan, cell, carried)
    assert phase.contacts == {
        "post": pytest.approx(2.0 * mm),
        "bin": pytest.approx(0.5 * mm),
        "plate": pytest.approx(0.7 * mm),
    }
    assert not phase.ok
    assert phase.peaks[0] == pytest.approx(1.875 * 0.5 / 1.5 / limits.velocity[0], rel=1e-2)
    clear = _phase("drop", SimpleNamespace(**{**vars(run), "contacts": {}}), plan, cell, {})
    assert clear.ok and clear.contacts == {}


def test_the_job_commands_status_counts_every_target_it_was_given(tmp_path, capsys):
    """``bidmp job``'s run on two targets of its three, nut "b" 2 mm off the target the skill goes
    to (it does not engage): the report has the two targets asked for, one removed, and the exit
    status says a target failed (3), not that one was removed."""
    from bidmp.cli.common import EXIT_TARGETS_FAILED
    from bidmp.cli.job import run_job_command

    scenario = _off_axis()
    out = tmp_path / "job"
    out.mkdir()
    written = run_job_command(
        scenario, out, targets=["b", "a"], pictures=False, backend="kinematic", commands=True
    )
    capsys.readouterr()
    results = json.loads((out / "job_results.json").read_text())
    assert sorted(row["target"] for row in results["targets"]) == ["a", "b"]
    assert written.code == EXIT_TARGETS_FAILED
    assert len(written.commands) >= 4  # a's approach, unscrew, retract, drop (b's approach too)


def _off_axis():
    """The nut job on three nuts, "b" 2 mm off the target the skill goes to (it does not
    engage), the targets visited in the order given."""
    spec = json.loads(scenarios.builtin_text("nut-unscrewing"))
    spec["targets"] = {"3": [0, 0, 0], "a": [60, 0, 0], "b": [120, 0, 0]}
    spec["scene"]["parts"] = [spec["scene"]["parts"][0]] + [
        {
            "type": "nut",
            "label": label,
            "at": [x + dx, 0, -2],
            "across_flats": 13,
            "height": 6.5,
            "stud": {"radius": 4, "above": 10},
        }
        for label, x, dx in (("3", 0, 0), ("a", 60, 0), ("b", 120, 2.0))
    ]
    spec["job"]["order"] = "listed"
    return scenarios.from_dict(spec)


def test_a_leave_that_cannot_run_stops_every_target_after_it(monkeypatch):
    """Nut "b" first: it does not engage, and the tool cannot leave it (the arm refuses the move
    up its axis): nothing else moves — "a" and "3" are rows saying why, with no phases."""
    from bidmp.sim import SimError
    from bidmp.sim import job as job_module

    real = job_module._straight

    def straight(world, direction, length, exclude, name, part=None, **options):
        if name == "leave":
            raise SimError("joint 5 would leave its limits")
        return real(world, direction, length, exclude, name, part, **options)

    monkeypatch.setattr(job_module, "_straight", straight)
    report = sim.run_job(_off_axis(), targets=["b", "a", "3"], backend="kinematic")
    rows = {target.label: target for target in report.targets}
    assert [target.label for target in report.targets] == ["b", "a", "3"]
    assert not rows["b"].removed and rows["b"].phases[-1].name == "leave"
    for label in ("a", "3"):
        assert not rows[label].phases and not rows[label].removed
        assert rows[label].reason.startswith("not attempted: after target b failed")
        assert "joint 5 would leave its limits" in rows[label].reason


def test_a_part_not_placed_leaves_its_rack_slot_to_the_next(tmp_path):
    """Cells B1, B2, B9 taken out in that order, B1's cell 3 mm off the target the skill goes to
    (the gripper does not take it): B2 stands in the rack's first slot and B9 in its second —
    the slots of the parts placed, not of the parts tried."""
    spec = json.loads(scenarios.builtin_text("cell-removal"))
    others = [label for label in spec["scene"]["targets"] if label != "B1"]
    cell = spec["scene"]["parts"][0]
    spec["scene"]["parts"] = [
        {**cell, "at_targets": others},
        {"type": "cell", "label": "B1", "at": [0, 0, 0], "size": cell["size"]},
    ]
    spec["targets"]["B1"] = [3, 0, 30]
    cells = scenarios.from_dict(spec)
    report = sim.run_job(cells, targets=["B1", "B2", "B9"], backend="kinematic")
    rows = {target.label: target for target in report.targets}
    assert not rows["B1"].removed and rows["B1"].reason.startswith("grasp:")
    first, step = (np.asarray(v, dtype=float) for v in cells.job.rack[:2])
    for index, label in enumerate(["B2", "B9"]):
        assert rows[label].removed, rows[label].reason
        slot = first + index * step
        assert np.linalg.norm(rows[label].final_position[:2] - slot[:2]) <= 5.0, (label, slot)
        # standing on the shelf: its centre half its height over the slot's floor
        part = next(s for s in cells.scene.solids if s.label == label)
        height = float(part.upper[2] - part.lower[2])
        assert rows[label].final_position[2] == pytest.approx(slot[2] + height / 2, abs=1.0)


@pytest.mark.parametrize("tilt", [(50.0, "x"), (60.0, "y")])
def test_engagement_height_is_measured_along_the_parts_own_axis(tilt):
    """A nut tilted 50 or 60 degrees: the tool 2.5 mm up the nut's axis from the target is off its
    height (threshold 1.75 mm) though only 1.6 or 1.25 mm above it in world z; 1.2 mm up it is
    on. Distances along the axis computed here."""
    from scipy.spatial.transform import Rotation

    from bidmp.sim import job as job_module

    angle, about = tilt
    axis = Rotation.from_euler(about, angle, degrees=True).apply([0.0, 0.0, 1.0])
    target = np.array([10.0, -20.0, 40.0])
    part = SimpleNamespace(centre0=target - 3.0 * axis, axis=axis)

    def engaged(tcp) -> bool:
        world = SimpleNamespace(
            tcp=np.asarray(tcp, dtype=float),
            spec=SimpleNamespace(engage_tolerance=1.0),
            scenario=SimpleNamespace(success_threshold=1.75, units="mm"),
        )
        return job_module._engaged(world, part, target)[0]

    assert abs(2.5 * axis[2]) <= 1.75  # in world z the far one would pass
    assert not engaged(target + 2.5 * axis) and not engaged(target - 2.5 * axis)
    assert engaged(target + 1.2 * axis) and engaged(target)


def _bracket(angle: float = 20.0):
    """The two-post cell as pose targets, the tool down, and nut "B" on a bracket turned
    ``angle`` degrees about x (as tests/tasks/test_tilted_user_cells.py builds it, mm, the
    scenario's own arm): two targets whose axes differ."""
    from pathlib import Path

    from scipy.spatial.transform import Rotation

    data = json.loads((Path(__file__).resolve().parents[1] / "data" / "two_posts.json").read_text())
    down = Rotation.from_euler("x", 180.0, degrees=True)
    tilt = Rotation.from_euler("xyz", [angle, 0.0, 0.0], degrees=True)
    stand, size = np.array([-50.0, 60.0, 12.0]), np.array([40.0, 30.0, 30.0])
    data["targets"] = {label: [*p, *down.as_quat()] for label, p in data["targets"].items()}
    base = stand + tilt.apply([0.0, 0.0, size[2]])
    data["targets"]["B"] = [*(base + tilt.apply([0.0, 0.0, 2.0])), *(tilt * down).as_quat()]
    via = data["demonstration"]["minimum_jerk"]["via"]
    data["demonstration"]["minimum_jerk"]["via"] = [[*p, *down.as_quat()] for p in via]
    scene = data["scene"]
    scene["parts"][1]["at_targets"] = [label for label in data["targets"] if label != "B"]
    nut = {k: v for k, v in scene["parts"][1].items() if k not in ("at_targets", "offset")}
    turn = [angle, 0.0, 0.0]
    scene["parts"] += [
        {
            "type": "box",
            "label": "bracket",
            "at": stand.tolist(),
            "size": size.tolist(),
            "rotation": turn,
        },
        {**nut, "label": "B", "at": base.tolist(), "rotation": turn},
    ]
    scene["standoff"]["bracket"] = scene["standoff"]["plate"]
    data["methods"] = ["dmp", "bidmp"]
    data["job"]["order"] = "listed"
    return scenarios.from_dict(data)


def test_each_target_of_a_job_is_worked_along_its_own_axis():
    """An upright nut first, then nut B on a bracket tilted 20 degrees: B's approach is judged
    and its nut unscrewed along B's own axis (the tool's path over the approach within the
    threshold of it, from B's frame here), not the first target's."""
    from scipy.spatial.transform import Rotation

    cell = _bracket()
    report = sim.run_job(cell, targets=["2", "B"], backend="kinematic", record=True)
    rows = {target.label: target for target in report.targets}
    for label in ("2", "B"):
        assert rows[label].removed, (label, rows[label].reason)
    pose = np.asarray(cell.targets["B"], dtype=float)
    axis = -Rotation.from_quat(pose[3:]).apply([0.0, 0.0, 1.0])
    assert np.degrees(np.arccos(axis[2])) == pytest.approx(20.0, abs=1e-6)
    unscrew = next(phase for phase in rows["B"].phases if phase.name == "unscrew")
    rise = unscrew.path[-1] - unscrew.path[0]
    assert np.degrees(np.arccos(rise @ axis / np.linalg.norm(rise))) < 2.0


class _MadeUpCell:
    """An arm that runs every plan ending ``miss`` (m) off it, touching ``touch`` (label -> m):
    what a move of the job is judged on comes from here (SI units, as a backend's)."""

    unit = 1e-3

    def __init__(self, limits, miss, touch):
        self.limits, self.miss, self.touch = limits, np.asarray(miss, dtype=float), touch

    def plan(self, path, label, fractions=None, seed=None, orientations=None, **_):
        points = np.asarray(path, dtype=float)[:, :3] * self.unit
        return SimpleNamespace(
            points=points,
            duration=1.5,
            peak_velocity=0.2,
            peak_acceleration=0.2,
            peak_jerk=0.2,
            orientations=orientations,
        )

    def execute(self, plan, exclude, on_record=None):
        q0 = 0.5 * (np.asarray(self.limits.lower) + np.asarray(self.limits.upper))
        self.joints = q0 + np.array([[0.0], [0.1], [0.2]])  # where the arm starts, passes, ends
        tcp = np.linspace(plan.points[0], plan.points[-1] + self.miss, 200)
        tau = np.linspace(0.0, 1.0, 1501)[:, None]
        commands = np.repeat(q0[None], tau.shape[0], axis=0)
        commands[:, 0] += 0.5 * (10 * tau[:, 0] ** 3 - 15 * tau[:, 0] ** 4 + 6 * tau[:, 0] ** 5)
        return SimpleNamespace(
            tcp=tcp,
            tcp_orientation=None,
            joints=self.joints,
            commands=commands,
            contacts=dict(self.touch),
            joint_velocities=np.zeros((200, self.limits.n_joints)),
        )


@pytest.mark.parametrize("limits", [SIX, PANDA], ids=["six-joint", "panda"])
def test_a_moves_verdict_is_on_what_the_arm_did_against_its_target(limits):
    """A drop to two points over the bin that the arm runs 0.5 mm off its target and clear, then
    3 mm off, then on target touching a post 2 mm deep: the first keeps the contract, the second
    misses its target (the move's target, not the end it reached), the third touched; each
    verdict took the commands (peaks against this arm's limits), the phase's ok is the
    verdict's, and the joints the next move starts from are the ones this move ended at."""
    from bidmp.sim.job_world import _Move, _move
    from bidmp.tasks.contract import Contract

    nuts = scenarios.load("nut-unscrewing")
    contract = Contract.of(nuts, limits)
    for miss, touch, ok in (
        ([0.0005, 0.0, 0.0], {}, True),
        ([0.003, 0.0, 0.0], {}, False),
        ([0.0, 0.0, 0.0], {"post": 0.002}, False),
    ):
        cell = _MadeUpCell(limits, miss, touch)
        world = SimpleNamespace(
            spec=SimpleNamespace(kind="pick"),  # (not an unscrew: no retract)
            cell=cell,
            scenario=nuts,
            contract=contract,
            scene=contract.scene,
            pose=False,
            q=np.zeros(limits.n_joints),
            label="3",
            motion=None,
            record=False,
            clock=0.0,
            planned=None,
            tcp=np.array([150.0, -60.0, 120.0]),
        )
        target = np.array([270.0, -20.0, 60.0])
        path = np.linspace(world.tcp, target, 40)
        phase = _move(world, _Move(path, None, ["3"], "drop", target=target))
        verdict = phase.verdict
        assert phase.ok is verdict.ok is ok, (miss, touch, verdict.reason())
        assert verdict.end_error == pytest.approx(np.linalg.norm(miss) * 1e3, abs=1e-9)
        assert verdict.contacts == {
            label: pytest.approx(depth * 1e3) for label, depth in touch.items()
        }
        assert verdict.limits is not None
        assert verdict.limits.velocity == pytest.approx(
            1.875 * 0.5 / 1.5 / limits.velocity[0], rel=1e-2
        )
        # the next move starts where this one left the arm
        np.testing.assert_array_equal(world.q, cell.joints[-1])


def test_a_step_that_breaks_the_contract_ends_its_cycle_and_the_job_goes_on(monkeypatch):
    """Nut 3's retract sent sideways into a stud (refused from its plan): nut 3's cycle ends
    there — no drop after it, not removed, the retract named — and nut 4 is still worked and
    removed."""
    from bidmp.sim import job as job_module

    original = job_module._straight

    def sideways(world, direction, length, exclude, name, part=None, **options):
        if name == "retract" and world.label == "3":
            direction, length = np.array([1.0, 0.0, 0.0]), 30.0
        return original(world, direction, length, exclude, name, part, **options)

    monkeypatch.setattr(job_module, "_straight", sideways)
    spec = json.loads(scenarios.builtin_text("nut-unscrewing"))
    spec["job"]["order"] = "listed"
    report = sim.run_job(scenarios.from_dict(spec), targets=["3", "4"], backend="kinematic")
    rows = {target.label: target for target in report.targets}
    names = [phase.name for phase in rows["3"].phases]
    assert names[:4] == ["approach", "engage", "unscrew", "retract"] and "drop" not in names
    assert not rows["3"].removed and rows["3"].reason.startswith("retract")
    assert rows["4"].removed, rows["4"].reason


def test_a_carried_parts_clearance_reaches_the_moves_verdict():
    """A move over the studs of nuts 4 and 5 carrying nut 3 5 mm under the tool's mouth, planned
    with the carried nut's bottom 1.5 mm over the margin above the studs' tops (the tool's mouth
    8 mm higher): it runs. Executed sagging towards its end (2.5 mm over stud 4, 5 mm over stud
    5), the carried nut comes inside the margin while the tool stays clear: the verdict on what
    the arm did fails for the carried nut; run as planned it keeps the contract."""
    from scipy.spatial.transform import Rotation

    from bidmp.sim.job_world import _Move, _move
    from bidmp.tasks.contract import Contract

    nuts = scenarios.load("nut-unscrewing")
    scene = nuts.scene
    stud = next(s for s in scene.solids if s.label == "4/stud")
    nut = next(s for s in scene.solids if s.label == "3")
    below = (
        5.0 + float(nut.upper[2] - nut.lower[2]) / 2.0
    )  # the carried nut's bottom under the mouth
    mouth_z = float(stud.upper[2]) + scene.margin + 1.5 + below
    path = np.column_stack([np.linspace(0.0, 60.0, 61), np.zeros(61), np.full(61, mouth_z)])
    offset = np.array([0.0, 0.0, -5.0])
    for sag, clear in ((0.0, True), (0.005, False)):
        carried = SimpleNamespace(
            label="3",
            solid=nut,
            pose=lambda: (path[0] + offset, Rotation.identity()),
            contacts=lambda touched, ignore=(): None,
        )
        world = SimpleNamespace(
            spec=SimpleNamespace(kind="pick"),  # (not an unscrew: no retract)
            cell=_MadeUpCell(SIX, [0.0, 0.0, -sag], {}),
            scenario=nuts,
            contract=Contract.of(nuts, SIX),
            scene=scene,
            pose=False,
            q=np.zeros(6),
            label="3",
            motion=None,
            record=False,
            clock=0.0,
            planned=None,
            tcp=path[0],
        )
        phase = _move(world, _Move(path, None, ["3"], "retract", carried=carried))
        assert phase.seconds > 0.0  # it ran (the plan kept the contract)
        assert phase.ok is clear, phase.verdict.reason()
        if not clear:
            assert phase.verdict.clearance.part.endswith("/stud"), phase.verdict.clearance.part


def test_a_tilted_tools_plan_is_judged_with_its_frames():
    """The tilted pack: the socket's planned descent down nut 4's axis, turned onto it, keeps the
    contract before it runs; the same path with the tool held upright would cut into the tilted
    plate (its rim 12.5 mm out), and is refused."""
    from scipy.spatial.transform import Rotation

    from bidmp.sim.job_world import _Move, _refused_plan, _transfer_contract
    from bidmp.tasks.contract import Contract

    tilted = scenarios.load("nut-unscrewing-tilted")
    pose = np.asarray(tilted.targets["4"], dtype=float)
    axis = -Rotation.from_quat(pose[3:7]).apply([0.0, 0.0, 1.0])
    path = pose[:3] + np.linspace(40.0, 0.0, 30)[:, None] * axis
    contract = _transfer_contract(Contract.of(tilted))
    calm = SimpleNamespace(peak_velocity=0.5, peak_acceleration=0.5, peak_jerk=0.5)
    upright = Rotation.from_quat([1.0, 0.0, 0.0, 0.0]).as_quat()
    for frame, runs in ((pose[3:7], True), (upright, False)):
        frames = np.repeat(np.asarray(frame)[None], len(path), axis=0)
        world = SimpleNamespace(scene=tilted.scene, pose=True, tcp=path[0], cell=None)
        move = _Move(path, None, ["4"], "drop", orientations=frames)
        refused = _refused_plan(world, calm, contract, move, path[-1])
        assert (refused is None) is runs, None if refused is None else refused.note
        if not runs:
            assert "plate" in refused.note


def test_a_pose_transfer_starts_from_the_tool_frame_and_ends_upright():
    """A transfer of a pose job (over the bin, a slot): from the tool's frame now (tilted 30
    degrees) to the goal with the tool pointing down — what the repairs are asked for."""
    from scipy.spatial.transform import Rotation

    from bidmp.sim.job_world import _clear_transfer

    tilt = Rotation.from_euler("x", 30.0, degrees=True) * Rotation.from_quat([1.0, 0.0, 0.0, 0.0])
    asked = {}

    class Recorder:
        def repair(self, model, goal, label, start=None, **given):
            asked.update(goal=np.asarray(goal), start=np.asarray(start))
            motion = np.hstack([np.linspace(start[:3], goal[:3], 5), np.tile(goal[3:], (5, 1))])
            return SimpleNamespace(ok=True, how="", motion=motion)

    world = SimpleNamespace(
        spec=SimpleNamespace(kind="pick"),  # (not an unscrew: no retract)
        tcp=np.array([10.0, 20.0, 30.0]),
        pose=True,
        orientation=lambda: tilt,
        transfers=Recorder(),
        model=None,
    )
    path, fractions, turns, note = _clear_transfer(world, np.array([250.0, -20.0, 60.0]), ["3"])
    np.testing.assert_allclose(asked["start"], [10.0, 20.0, 30.0, *tilt.as_quat()])
    down = Rotation.from_quat(asked["goal"][3:7]).apply([0.0, 0.0, 1.0])
    np.testing.assert_allclose(down, [0.0, 0.0, -1.0], atol=1e-12)  # the tool's z points down
    np.testing.assert_allclose(asked["goal"][:3], [250.0, -20.0, 60.0])
    assert turns.shape == (5, 4) and path.shape == (5, 3) and fractions[-1] == 1.0


@pytest.mark.parametrize("units", ["mm", "m"])
def test_the_arms_own_route_is_asked_for_the_targets_frame_and_the_margin_with_room(
    units, monkeypatch
):
    """What a move hands the arm's route planner (a recorder in its place): the approach to a
    tilted nut asks for the nut's frame and axis; every route keeps the scene's margin plus
    0.5 mm of room for the arm's tracking, in the scenario's unit (mm and m)."""
    from test_execution_wiring import _posts

    from bidmp.sim import routes
    from bidmp.sim.backend import SimError
    from bidmp.sim.job_world import _Move, _routed

    asked = []

    def recorder(cell, q, target, **given):
        asked.append((np.asarray(target), given))
        raise SimError("recorded")

    monkeypatch.setattr(routes, "arm_route", recorder)
    tilted = scenarios.load("nut-unscrewing-tilted")
    cells = [(tilted, "4", 1e-3), (_posts(units), "6", {"mm": 1e-3, "m": 1.0}[units])]
    for scenario, label, metres in cells:
        pose = np.asarray(scenario.targets[label], dtype=float)
        axis = scenario.target_axis(label)
        world = SimpleNamespace(
            spec=SimpleNamespace(kind="pick"),  # (not an unscrew: no retract)
            cell=SimpleNamespace(unit=metres),
            scenario=scenario,
            scene=scenario.scene,
            q=np.zeros(7),
            label=label,
            pose=scenario.is_pose,
        )
        path = np.linspace(pose[:3] + [0.0, 0.0, 50e-3 / metres], pose[:3], 10)  # 50 mm up
        move = _Move(path, None, [label], "approach", target=pose, axis=axis)
        plan, why = _routed(world, move, None, pose[:3])
        assert plan is None and why == "recorded"
        target, given = asked[-1]
        np.testing.assert_allclose(target, pose[:3])
        mm = 1e-3 / metres
        assert given["margin"] == pytest.approx(scenario.scene.margin + 0.5 * mm, rel=1e-12)
        if scenario.is_pose:
            np.testing.assert_allclose(given["orientation"], pose[3:7])
            np.testing.assert_allclose(given["axis"], axis)
        else:
            assert given["orientation"] is None


@pytest.mark.parametrize("reach", [80.0, 230.0])
def test_a_similarity_transfer_is_the_skills_shape_turned_and_scaled_onto_the_move(reach):
    """``transfer: "similarity"``: the plain DMP's reproduction (an arc 100 mm from end to end,
    rising 30 mm) turned and scaled to run from the tool's place to a goal ``reach`` mm away,
    high over the nut cell: it starts at the tool, ends at the goal, and its rise scales with
    the reach (30 mm x reach / 100)."""
    from bidmp.sim.job_world import _transfer

    nuts = scenarios.load("nut-unscrewing")
    s = np.linspace(0.0, 1.0, 101)
    shape = np.column_stack([100.0 * s, np.zeros_like(s), 30.0 * np.sin(np.pi * s)])
    reproduction = SimpleNamespace(y=shape + [5.0, 5.0, 5.0], t=np.linspace(0.0, 2.0, 101))
    world = SimpleNamespace(
        spec=SimpleNamespace(transfer="similarity"),
        pose=False,
        model=SimpleNamespace(trajectory=lambda skill: reproduction),
        tcp=np.array([0.0, -60.0, 150.0]),
        scene=nuts.scene,
        scenario=nuts,
    )
    goal = world.tcp + [reach, 0.0, 0.0]
    path, fractions, turns, note = _transfer(world, goal, ["3"])
    np.testing.assert_allclose(path[0], world.tcp, atol=1e-9)
    np.testing.assert_allclose(path[-1], goal, atol=1e-9)
    rise = float(np.max(np.linalg.norm(np.cross(path - world.tcp, [1.0, 0.0, 0.0]), axis=1)))
    assert rise == pytest.approx(30.0 * reach / 100.0, rel=1e-6)
    assert turns is None and fractions[-1] == 1.0


def test_a_tilted_approachs_plan_is_judged_for_its_alignment_before_it_runs():
    """The approach down nut 4's tilted axis: planned with the tool on the axis it runs; planned
    with the tool 5 degrees off it (alignment threshold 2) it is refused before it runs."""
    from scipy.spatial.transform import Rotation

    from bidmp.sim.job_world import _Move, _refused_plan
    from bidmp.tasks.contract import Contract

    tilted = scenarios.load("nut-unscrewing-tilted")
    pose = np.asarray(tilted.targets["4"], dtype=float)
    axis = -Rotation.from_quat(pose[3:7]).apply([0.0, 0.0, 1.0])
    path = pose[:3] + np.linspace(40.0, 0.0, 30)[:, None] * axis
    contract = Contract.of(tilted)
    calm = SimpleNamespace(peak_velocity=0.5, peak_acceleration=0.5, peak_jerk=0.5)
    off = Rotation.from_rotvec(
        np.radians(5.0)
        * np.cross(axis, [0.0, 1.0, 0.0])
        / np.linalg.norm(np.cross(axis, [0.0, 1.0, 0.0]))
    )
    for frame, runs in (
        (Rotation.from_quat(pose[3:7]), True),
        (off * Rotation.from_quat(pose[3:7]), False),
    ):
        frames = np.repeat(frame.as_quat()[None], len(path), axis=0)
        world = SimpleNamespace(scene=tilted.scene, pose=True, tcp=path[0], cell=None)
        move = _Move(path, None, ["4"], "approach", orientations=frames, target=pose, axis=axis)
        refused = _refused_plan(world, calm, contract, move, pose[:3])
        assert (refused is None) is runs, None if refused is None else refused.note
        if not runs:
            assert refused.verdict is not None and refused.verdict.aligned is False
